//! [`LoneStep`]: what the step of a bead riding a wire alone needs of each
//! dimension: the shapes it steps on (a curve in the plane, a surface in
//! space), the circles or spheres it batches, and the concrete track each
//! shape is solved on.

use std::sync::Arc;

use bevy::math::{DVec2, DVec3};

use crate::dynamics::Dimension;
use crate::geometry::{
    FixedTrack, ImplicitSurface, MovingSurface, MovingTrack, Near, Placed, PlacedSurface, Pose,
    Pose3, PosePath, SpacePath, SpaceShape, Track, WirePath, WireShape,
};
use crate::lane::LaneSpace;

/// Something to run on a wire's track, whatever its concrete type: a
/// generic closure.
pub(crate) trait OnTrack<V: Dimension, R> {
    /// Runs on `track`.
    fn run<T: Track<V> + ?Sized>(self, track: &T) -> R;
}

/// A dimension whose beads may ride a wire alone, each stepped by itself:
/// the plane's on any curve, space's on a surface (a bead on a curve in
/// space, two rows, steps in an island).
pub(crate) trait LoneStep: Dimension + LaneSpace {
    /// The shape of a wire a bead rides alone: [`WireShape`] in the plane,
    /// a surface in space.
    type Lone: Send + Sync;
    /// The shape a bead alone on `wire` rides, if it takes the lone step.
    fn lone_shape(wire: &Self::Wire) -> Option<Self::Lone>;
    /// The radius of a plain circle or sphere about the local origin: the
    /// batched step's wires.
    fn round(shape: &Self::Lone) -> Option<f64>;
    /// Whether the shape finds its nearest point near where the bead was
    /// (a traced curve), so that it steps with that hint.
    fn traced(shape: &Self::Lone) -> bool;
    /// The shape's own parameter at the local point `p`, near `hint` (NaN
    /// where it has none): the hint of the next step.
    fn parameter(shape: &Self::Lone, p: Self, hint: f64) -> f64;
    /// Runs `f` on the shape resting at `pose`, as its concrete type.
    fn fixed<R>(shape: &Self::Lone, pose: Self::Pose, f: impl OnTrack<Self, R>) -> R;
    /// Runs `f` on the shape moving along `path`, as its concrete type.
    fn moving<R>(shape: &Self::Lone, path: &WirePath<Self>, f: impl OnTrack<Self, R>) -> R;
    /// Runs `f` on the shape along `path`, its nearest point looked for
    /// near the parameter `hint` where it has one.
    fn near<R>(shape: &Self::Lone, path: &WirePath<Self>, hint: f64, f: impl OnTrack<Self, R>)
    -> R;
    /// Runs `f` on the shape along `path`: resting where the path does
    /// not move, moving otherwise.
    #[inline(always)]
    fn on_path<R>(shape: &Self::Lone, path: &WirePath<Self>, f: impl OnTrack<Self, R>) -> R {
        match path.fixed() {
            Some(pose) => Self::fixed(shape, pose, f),
            None => Self::moving(shape, path, f),
        }
    }
}

/// Runs `$body` with `$curve` bound to the shape's concrete curve, so the
/// solver is inlined for each built-in shape.
macro_rules! with_curve {
    ($shape:expr, $curve:ident => $body:expr) => {
        match $shape {
            WireShape::Circle($curve) => $body,
            WireShape::Ellipse($curve) => $body,
            WireShape::Line($curve) => $body,
            WireShape::Parabola($curve) => $body,
            WireShape::Sine($curve) => $body,
            WireShape::Cycloid($curve) => $body,
            WireShape::Spline($curve) => $body,
            WireShape::Custom(custom) => {
                let $curve = custom.as_ref();
                $body
            }
        }
    };
}

impl LoneStep for DVec2 {
    type Lone = WireShape;
    #[inline]
    fn lone_shape(wire: &Self::Wire) -> Option<WireShape> {
        Some(wire.shape().clone())
    }
    #[inline]
    fn round(shape: &WireShape) -> Option<f64> {
        match shape {
            WireShape::Circle(circle) => Some(circle.radius),
            _ => None,
        }
    }
    #[inline]
    fn traced(shape: &WireShape) -> bool {
        shape.is_traced()
    }
    fn parameter(shape: &WireShape, p: Self, hint: f64) -> f64 {
        shape.curve().parameter(p, hint)
    }
    #[inline(always)]
    fn fixed<R>(shape: &WireShape, pose: Pose, f: impl OnTrack<Self, R>) -> R {
        with_curve!(shape, curve => f.run(&FixedTrack(&Placed { curve, pose })))
    }
    #[inline(always)]
    fn moving<R>(shape: &WireShape, path: &PosePath, f: impl OnTrack<Self, R>) -> R {
        with_curve!(shape, curve => f.run(&MovingTrack { curve, path }))
    }
    fn near<R>(shape: &WireShape, path: &PosePath, hint: f64, f: impl OnTrack<Self, R>) -> R {
        let curve = &Near {
            curve: shape.curve(),
            hint,
        };
        match path.fixed() {
            Some(pose) => f.run(&FixedTrack(&Placed { curve, pose })),
            None => f.run(&MovingTrack { curve, path }),
        }
    }
}

/// A surface shared with its wire.
type SharedSurface = Arc<dyn ImplicitSurface + Send + Sync>;

impl LoneStep for DVec3 {
    type Lone = SharedSurface;
    #[inline]
    fn lone_shape(wire: &Self::Wire) -> Option<SharedSurface> {
        match wire.shape() {
            SpaceShape::Surface(surface) => Some(surface.clone()),
            SpaceShape::Curve(_) => None,
        }
    }
    #[inline]
    fn round(surface: &SharedSurface) -> Option<f64> {
        surface.sphere_radius()
    }
    #[inline]
    fn traced(_: &SharedSurface) -> bool {
        false
    }
    fn parameter(_: &SharedSurface, _: Self, _: f64) -> f64 {
        f64::NAN
    }
    #[inline(always)]
    fn fixed<R>(surface: &SharedSurface, pose: Pose3, f: impl OnTrack<Self, R>) -> R {
        let surface = surface.as_ref();
        f.run(&FixedTrack(&PlacedSurface { surface, pose }))
    }
    #[inline(always)]
    fn moving<R>(surface: &SharedSurface, path: &SpacePath, f: impl OnTrack<Self, R>) -> R {
        let surface = surface.as_ref();
        f.run(&MovingSurface { surface, path })
    }
    fn near<R>(surface: &SharedSurface, path: &SpacePath, _: f64, f: impl OnTrack<Self, R>) -> R {
        Self::on_path(surface, path, f)
    }
}
