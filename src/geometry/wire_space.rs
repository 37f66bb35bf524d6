//! [`WireSpace`]: what a wire is in the plane and in space, for the rows
//! of an island: its shape, where it sits and how it moves. A curve
//! ([`WireShape`]) placed by a [`Pose`] on a [`PosePath`] in the plane; a
//! surface or one of a curve's two rows ([`SpaceWire`]) placed by a
//! [`Pose3`] on a [`SpacePath`] in space.

use std::fmt::Debug;
use std::sync::Arc;

use bevy::math::{DVec2, DVec3};

use super::{
    Coordinates, Geometry, ImplicitSurface, Placement, Pose, Pose3, PosePath, SpaceCurve,
    SpacePath, Twist, WireShape,
};

/// The coordinates with the wires that live in them.
pub trait WireSpace: Coordinates {
    /// A wire row's shape in its local frame: a curve ([`WireShape`]) in
    /// the plane, a surface or one row of a curve ([`SpaceWire`]) in
    /// space.
    type Shape: Clone + Debug + Send + Sync + 'static;
    /// Where a wire sits: [`Pose`] or [`Pose3`].
    type Pose: Placement<Self> + Copy + Debug + Default + PartialEq + Send + Sync + 'static;
    /// Where a wire is over time: [`PosePath`] or [`SpacePath`].
    type Path: Copy + Debug + PartialEq + Send + Sync + 'static;
    /// The pose and twist of `path` at `t`.
    fn path_at(path: &Self::Path, t: f64) -> (Self::Pose, Twist<Self>);
    /// The pose of `path` if it does not move.
    fn path_fixed(path: &Self::Path) -> Option<Self::Pose>;
    /// `shape`'s geometry at the local point `p`, its nearest point looked
    /// for near the parameter `hint` where there is one (see
    /// [`ImplicitCurve::parameter`](super::ImplicitCurve::parameter)).
    fn shape_geometry(shape: &Self::Shape, p: Self, hint: Option<f64>) -> Geometry<Self>;
    /// `shape`'s characteristic length.
    fn shape_scale(shape: &Self::Shape) -> f64;
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
/// curve takes both of [`SpaceWire::curve`]'s rows.
#[derive(Clone)]
pub enum SpaceWire {
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

impl SpaceWire {
    /// A surface's row.
    pub fn surface(surface: impl ImplicitSurface + Send + Sync + 'static) -> Self {
        Self::Surface(Arc::new(surface))
    }

    /// A curve's two rows.
    pub fn curve(curve: impl SpaceCurve + Send + Sync + 'static) -> [Self; 2] {
        let curve: Arc<dyn SpaceCurve + Send + Sync> = Arc::new(curve);
        [0, 1].map(|row| Self::Curve {
            curve: curve.clone(),
            row,
        })
    }
}

impl Debug for SpaceWire {
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
    type Path = PosePath;
    #[inline]
    fn path_at(path: &PosePath, t: f64) -> (Pose, Twist) {
        path.at(t)
    }
    fn path_fixed(path: &PosePath) -> Option<Pose> {
        path.fixed()
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
    fn shape_parameter(shape: &WireShape, p: Self, hint: f64) -> f64 {
        shape.curve().parameter(p, hint)
    }
    fn stick_axis(normal: Self) -> Option<Self> {
        Some(DVec2::new(-normal.y, normal.x).normalize_or_zero())
    }
}

impl WireSpace for DVec3 {
    type Shape = SpaceWire;
    type Pose = Pose3;
    type Path = SpacePath;
    #[inline]
    fn path_at(path: &SpacePath, t: f64) -> (Pose3, Twist<DVec3>) {
        path.at(t)
    }
    fn path_fixed(path: &SpacePath) -> Option<Pose3> {
        path.fixed()
    }
    #[inline]
    fn shape_geometry(shape: &SpaceWire, p: Self, hint: Option<f64>) -> Geometry<DVec3> {
        match shape {
            SpaceWire::Surface(surface) => surface.geometry(p),
            SpaceWire::Curve { curve, row } => {
                curve.rows(p, hint.unwrap_or(f64::NAN))[(*row).min(1)]
            }
        }
    }
    fn shape_scale(shape: &SpaceWire) -> f64 {
        match shape {
            SpaceWire::Surface(surface) => surface.scale(),
            SpaceWire::Curve { curve, .. } => curve.scale(),
        }
    }
    fn shape_parameter(shape: &SpaceWire, p: Self, hint: f64) -> f64 {
        match shape {
            SpaceWire::Surface(_) => f64::NAN,
            SpaceWire::Curve { curve, .. } => curve.parameter(p, hint),
        }
    }
    fn stick_axis(_normal: Self) -> Option<Self> {
        None
    }
}
