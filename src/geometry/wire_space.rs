//! [`WireSpace`]: what a wire is in the plane and in space, for the rows
//! of an island: its shape, where it sits and how it moves. A curve
//! ([`WireShape`]) placed by a [`Pose`] on a [`PosePath`](super::PosePath) in the plane; a
//! surface or one of a curve's two rows ([`SpaceRow`]) placed by a
//! [`Pose3`] on a [`SpacePath`](super::SpacePath) in space.

use std::fmt::Debug;
use std::sync::Arc;

use bevy::math::{DVec2, DVec3};

use super::{
    Coordinates, Geometry, HistoryPose, ImplicitSurface, Placement, PlanePose, Pose, Pose3,
    SpaceCurve, SpaceMotion, SpacePose, Twist, WireMotion, WireShape,
};
use crate::validate::ParamError;

/// The coordinates with the wires that live in them.
pub trait WireSpace: Coordinates {
    /// A wire row's shape in its local frame: a curve ([`WireShape`]) in
    /// the plane, a surface or one row of a curve ([`SpaceRow`]) in
    /// space.
    type Shape: Clone + Debug + Send + Sync + 'static;
    /// Where a wire sits: [`Pose`] or [`Pose3`].
    type Pose: Placement<Self> + Copy + Debug + Default + PartialEq + Send + Sync + 'static;
    /// A pose as a wire's [`History`](super::History) keeps it: [`PlanePose`] or
    /// [`SpacePose`].
    type Kept: HistoryPose<Pose = Self::Pose, Coords = Self> + Send + Sync + 'static;
    /// A wire's prescribed motion: [`WireMotion`] or [`SpaceMotion`].
    type Motion: Copy + Debug + PartialEq + Send + Sync + 'static;
    /// Whether `motion`'s numbers are valid.
    fn validate_motion(motion: &Self::Motion) -> Result<(), ParamError>;
    /// Whether `motion` moves a wire at all.
    fn motion_moves(motion: &Self::Motion) -> bool;
    /// The pose at `t` of a wire moving by `motion` about `base`, and its
    /// twist, exact.
    fn motion_at(motion: &Self::Motion, base: Self::Pose, t: f64) -> (Self::Pose, Twist<Self>);
    /// `shape`'s geometry at the local point `p`, its nearest point looked
    /// for near the parameter `hint` where there is one (see
    /// [`ImplicitCurve::parameter`](super::ImplicitCurve::parameter)).
    fn shape_geometry(shape: &Self::Shape, p: Self, hint: Option<f64>) -> Geometry<Self>;
    /// `shape`'s characteristic length.
    fn shape_scale(shape: &Self::Shape) -> f64;
    /// Whether `shape` ends (an open curve; see
    /// [`ImplicitCurve::has_ends`](super::ImplicitCurve::has_ends) and
    /// [`SpaceCurve::has_ends`](super::SpaceCurve::has_ends)).
    fn shape_has_ends(shape: &Self::Shape) -> bool;
    /// Whether `shape` is the second row of a curve in space, which its
    /// first row speaks for (a bead leaves both at once).
    fn shape_second_row(shape: &Self::Shape) -> bool;
    /// How far past an end of `shape` the point nearest the local point
    /// `p` lies, looked for near the parameter `hint` (see
    /// [`ImplicitCurve::past_end`](super::ImplicitCurve::past_end)):
    /// zero or less on the curve, −∞ for a shape with no end.
    fn shape_past_end(shape: &Self::Shape, p: Self, hint: f64) -> f64;
    /// `shape`'s own parameter at the local point `p`, near `hint` (NaN
    /// where it has none).
    fn shape_parameter(shape: &Self::Shape, p: Self, hint: f64) -> f64;
    /// The direction along the wire of normal `normal` that a bead at rest
    /// on it is held in while static friction holds it (the unit tangent
    /// in the plane); none in space, where a surface's tangents are a plane.
    fn stick_axis(normal: Self) -> Option<Self>;
}

/// One constraint row of a wire in space: a surface's, or one of a
/// curve's two. Shared, so an island's rows clone it cheaply. A bead on a
/// curve takes both of [`SpaceRow::curve`]'s rows.
#[derive(Clone)]
pub enum SpaceRow {
    /// A surface: its one row.
    Surface(Arc<dyn ImplicitSurface + Send + Sync>),
    /// A curve and which of its two rows (0 or 1).
    Curve {
        /// The curve.
        curve: Arc<dyn SpaceCurve + Send + Sync>,
        /// Its row: 0 or 1.
        row: usize,
    },
}

impl SpaceRow {
    /// A surface's row.
    pub fn surface(surface: impl ImplicitSurface + Send + Sync + 'static) -> Self {
        Self::Surface(Arc::new(surface))
    }

    /// A curve's two rows.
    pub fn curve(curve: impl SpaceCurve + Send + Sync + 'static) -> [Self; 2] {
        let curve: Arc<dyn SpaceCurve + Send + Sync> = Arc::new(curve);
        Self::curve_rows(&curve)
    }

    /// The two rows of a shared curve.
    pub fn curve_rows(curve: &Arc<dyn SpaceCurve + Send + Sync>) -> [Self; 2] {
        [0, 1].map(|row| Self::Curve {
            curve: curve.clone(),
            row,
        })
    }
}

/// A wire's shape in space: a surface, one row on each bead it holds, or
/// a curve, two.
#[derive(Clone)]
pub enum SpaceShape {
    /// A surface `C(x) = 0`.
    Surface(Arc<dyn ImplicitSurface + Send + Sync>),
    /// A curve.
    Curve(Arc<dyn SpaceCurve + Send + Sync>),
}

impl SpaceShape {
    /// A surface.
    pub fn surface(surface: impl ImplicitSurface + Send + Sync + 'static) -> Self {
        Self::Surface(Arc::new(surface))
    }

    /// A curve.
    pub fn curve(curve: impl SpaceCurve + Send + Sync + 'static) -> Self {
        Self::Curve(Arc::new(curve))
    }

    /// The rows it puts on each bead it holds: one or two.
    pub fn rows(&self) -> Vec<SpaceRow> {
        match self {
            Self::Surface(surface) => vec![SpaceRow::Surface(surface.clone())],
            Self::Curve(curve) => SpaceRow::curve_rows(curve).to_vec(),
        }
    }

    /// Its characteristic length.
    pub fn scale(&self) -> f64 {
        match self {
            Self::Surface(surface) => surface.scale(),
            Self::Curve(curve) => curve.scale(),
        }
    }
}

impl Debug for SpaceShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Surface(_) => f.write_str("Surface(..)"),
            Self::Curve(_) => f.write_str("Curve(..)"),
        }
    }
}

impl Debug for SpaceRow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Surface(_) => f.write_str("Surface(..)"),
            Self::Curve { row, .. } => write!(f, "Curve {{ row: {row} }}"),
        }
    }
}

impl WireSpace for DVec2 {
    type Shape = WireShape;
    type Pose = Pose;
    type Kept = PlanePose;
    type Motion = WireMotion;
    fn validate_motion(motion: &WireMotion) -> Result<(), ParamError> {
        motion.validate()
    }
    fn motion_moves(motion: &WireMotion) -> bool {
        motion.moves()
    }
    #[inline]
    fn motion_at(motion: &WireMotion, base: Pose, t: f64) -> (Pose, Twist) {
        motion.at(base, t)
    }
    #[inline]
    fn shape_geometry(shape: &WireShape, p: Self, hint: Option<f64>) -> Geometry {
        match hint {
            Some(hint) => shape.curve().geometry_near(p, hint),
            None => shape.curve().geometry(p),
        }
    }
    fn shape_scale(shape: &WireShape) -> f64 {
        shape.curve().scale()
    }
    fn shape_has_ends(shape: &WireShape) -> bool {
        shape.curve().has_ends()
    }
    fn shape_second_row(_shape: &WireShape) -> bool {
        false
    }
    fn shape_past_end(shape: &WireShape, p: Self, hint: f64) -> f64 {
        shape.curve().past_end_near(p, hint)
    }
    fn shape_parameter(shape: &WireShape, p: Self, hint: f64) -> f64 {
        shape.curve().parameter(p, hint)
    }
    fn stick_axis(normal: Self) -> Option<Self> {
        Some(DVec2::new(-normal.y, normal.x).normalize_or_zero())
    }
}

impl WireSpace for DVec3 {
    type Shape = SpaceRow;
    type Pose = Pose3;
    type Kept = SpacePose;
    type Motion = SpaceMotion;
    fn validate_motion(motion: &SpaceMotion) -> Result<(), ParamError> {
        motion.validate()
    }
    fn motion_moves(motion: &SpaceMotion) -> bool {
        motion.moves()
    }
    #[inline]
    fn motion_at(motion: &SpaceMotion, base: Pose3, t: f64) -> (Pose3, Twist<DVec3>) {
        motion.at(base, t)
    }
    #[inline]
    fn shape_geometry(shape: &SpaceRow, p: Self, hint: Option<f64>) -> Geometry<DVec3> {
        match shape {
            SpaceRow::Surface(surface) => surface.geometry(p),
            SpaceRow::Curve { curve, row } => {
                curve.rows(p, hint.unwrap_or(f64::NAN))[(*row).min(1)]
            }
        }
    }
    fn shape_scale(shape: &SpaceRow) -> f64 {
        match shape {
            SpaceRow::Surface(surface) => surface.scale(),
            SpaceRow::Curve { curve, .. } => curve.scale(),
        }
    }
    fn shape_has_ends(shape: &SpaceRow) -> bool {
        match shape {
            SpaceRow::Surface(_) => false,
            SpaceRow::Curve { curve, .. } => curve.has_ends(),
        }
    }
    fn shape_past_end(shape: &SpaceRow, p: Self, hint: f64) -> f64 {
        match shape {
            SpaceRow::Surface(_) => f64::NEG_INFINITY,
            SpaceRow::Curve { curve, .. } => curve.past_end(p, hint),
        }
    }
    fn shape_second_row(shape: &SpaceRow) -> bool {
        matches!(shape, SpaceRow::Curve { row: 1, .. })
    }
    fn shape_parameter(shape: &SpaceRow, p: Self, hint: f64) -> f64 {
        match shape {
            SpaceRow::Surface(_) => f64::NAN,
            SpaceRow::Curve { curve, .. } => curve.parameter(p, hint),
        }
    }
    fn stick_axis(_normal: Self) -> Option<Self> {
        None
    }
}
