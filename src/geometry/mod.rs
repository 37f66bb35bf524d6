//! Wire shapes as implicit curves `C(x) = 0`, and where they sit.
//!
//! The constraint solver needs three things of a wire at a point `x`: the
//! constraint value `C(x)`, its gradient `N = ∇C(x)` (the direction the
//! constraint force acts along) and its Hessian `H(x)` (which gives
//! `Ṅ = H ẋ`, the curvature term of [eq. (3)](crate::solver#the-constraint-force)).
//! [`ImplicitCurve`] is that contract; the built-in shapes implement it, one
//! file each, and a game can implement it for its own curve.
//!
//! Every built-in `C` is scaled so that `|∇C| = 1` on the circle and close to 1
//! on the other shapes near the wire, which makes `C` read as a distance in
//! world units and keeps the Baumgarte gains α and β meaning the same thing on
//! every shape.
//!
//! Shapes are written in the wire's local frame; [`Pose`] places them in the
//! plane (translation and rotation) and [`Placed`] evaluates a shape in world
//! coordinates: `C_w(x) = C(Rᵀ(x - o))`, `∇C_w = R ∇C`, `H_w = R H Rᵀ`.
//!
//! This module knows nothing of the ECS: plain values and `bevy_math` only.

mod circle;
mod coordinates;
mod cycloid;
mod ellipse;
mod frames;
mod history;
mod line;
mod motion;
mod parabola;
mod path;
mod pose;
mod shape;
mod sine;
mod space;
mod spline;
mod surface;
mod traced;
mod twist;
mod wire_space;

use bevy::math::{DMat2, DVec2};

pub use circle::Circle;
pub(crate) use circle::round_geometry;
pub use coordinates::Coordinates;
pub use cycloid::{Cycloid, CycloidArch};
pub use ellipse::Ellipse;
pub use history::{History, HistoryPose, PlanePose, PoseHistory, SpaceHistory, SpacePose};
pub use line::Line;
pub use motion::{FixedTrack, Oscillate, Rough, Spin, Track, WireMotion};
pub use parabola::Parabola;
pub use path::{MovingSurface, MovingTrack, PosePath, SpacePath, WirePath};
pub use pose::{Placed, PlacedSurface, Placement, Pose, Pose3};
pub(crate) use pose::{not_placeable, placed_geometry};
pub use shape::{WireKind, WireShape};
pub use sine::Sine;
pub use space::{
    Cone, CurveFrame, Cylinder, Extruded, Flat, Helicoid, Helix, ImplicitSurface, OnPlane, Plane,
    SpaceCurve, SpaceMotion, Sphere, Torus,
};
pub use spline::{CubicPath, Spline, SplineKind, SplineSpec};
pub use surface::{Friction, Side, Surface};
pub use traced::{Parametric, Traced};
pub use twist::Twist;
pub use wire_space::{SpaceRow, SpaceShape, WireSpace};

/// The value, gradient and Hessian of a constraint at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry<V: Coordinates = DVec2> {
    /// The constraint value `C(x)`: zero on the wire.
    pub c: f64,
    /// The gradient `N = ∇C(x)`.
    pub normal: V,
    /// The Hessian `H(x)` of `C`, so that `Ṅ = H ẋ`.
    pub hessian: V::Hessian,
}

/// A curve in the plane given implicitly by `C(x) = 0`.
///
/// Implement this to put beads on a wire of your own shape. `value`,
/// `gradient` and `hessian` must agree (the gradient of `value`, the Jacobian
/// of `gradient`); the solver divides by `|∇C|²`, so a point where the
/// gradient vanishes is a singular point and is reported as such.
pub trait ImplicitCurve {
    /// `C(x)`.
    fn value(&self, p: DVec2) -> f64;
    /// `∇C(x)`.
    fn gradient(&self, p: DVec2) -> DVec2;
    /// The Hessian of `C` at `x`.
    fn hessian(&self, p: DVec2) -> DMat2;
    /// A characteristic length (a circle's radius): drift is reported
    /// relative to it and solver tolerances scale with it.
    fn scale(&self) -> f64 {
        1.0
    }
    /// Whether the curve ends (an open spline or cycloid): a lone bead
    /// that passes an end leaves the wire.
    fn has_ends(&self) -> bool {
        false
    }
    /// How far past an end of an open curve the point of the curve nearest
    /// `p` lies, along the end's tangent (zero or less: on the curve;
    /// −∞ for a curve with no end).
    fn past_end(&self, _p: DVec2) -> f64 {
        f64::NEG_INFINITY
    }
    /// Which way the curve's own direction runs against its unit tangent
    /// `∇C⊥ / |∇C|` (`⊥` a quarter turn counter-clockwise): `−1` unless
    /// overridden (a line's +x, a graph's growing x, a spline's or a
    /// cycloid's parameter: the positive side of `C` on the left), `1` for
    /// a circle and an ellipse (counter-clockwise, their gradient pointing
    /// out). A motor drives a body along it; a curve in space drawn from
    /// this one ([`OnPlane`]) runs its frame's tangent along it.
    fn travel(&self) -> f64 {
        -1.0
    }
    /// The curve's own parameter at the point nearest `p`, searched near
    /// `hint` (NaN: anywhere); NaN for a curve with no parameter. A
    /// parametric curve that crosses itself uses it to stay on the branch a
    /// bead is on (see [`Near`]).
    fn parameter(&self, _p: DVec2, _hint: f64) -> f64 {
        f64::NAN
    }
    /// [`ImplicitCurve::geometry`] with the nearest point searched near the
    /// parameter `hint`.
    fn geometry_near(&self, p: DVec2, _hint: f64) -> Geometry {
        self.geometry(p)
    }
    /// [`ImplicitCurve::past_end`] with the nearest point searched near the
    /// parameter `hint`.
    fn past_end_near(&self, p: DVec2, _hint: f64) -> f64 {
        self.past_end(p)
    }
    /// All three at once; override when they share work.
    fn geometry(&self, p: DVec2) -> Geometry {
        Geometry {
            c: self.value(p),
            normal: self.gradient(p),
            hessian: self.hessian(p),
        }
    }
}

/// A curve whose nearest points are searched near one parameter: the
/// branch of a self-crossing spline a bead is on, for one step.
pub struct Near<'a, C: ImplicitCurve + ?Sized> {
    /// The curve.
    pub curve: &'a C,
    /// The parameter near which to look.
    pub hint: f64,
}

impl<C: ImplicitCurve + ?Sized> ImplicitCurve for Near<'_, C> {
    fn value(&self, p: DVec2) -> f64 {
        self.geometry(p).c
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.geometry(p).normal
    }
    fn hessian(&self, p: DVec2) -> DMat2 {
        self.geometry(p).hessian
    }
    fn scale(&self) -> f64 {
        self.curve.scale()
    }
    fn has_ends(&self) -> bool {
        self.curve.has_ends()
    }
    fn travel(&self) -> f64 {
        self.curve.travel()
    }
    fn past_end(&self, p: DVec2) -> f64 {
        self.curve.past_end_near(p, self.hint)
    }
    fn parameter(&self, p: DVec2, hint: f64) -> f64 {
        self.curve.parameter(p, hint)
    }
    fn geometry(&self, p: DVec2) -> Geometry {
        self.curve.geometry_near(p, self.hint)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Central differences of `value` and `gradient` agree with the analytic
    /// gradient and Hessian of every built-in shape.
    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let shapes: Vec<Box<dyn ImplicitCurve>> = vec![
            Box::new(Circle { radius: 1.3 }),
            Box::new(Ellipse { a: 2.0, b: 0.7 }),
            Box::new(Line),
            Box::new(Parabola { focal_length: 0.4 }),
            Box::new(Sine {
                amplitude: 0.3,
                wavelength: 1.7,
            }),
        ];
        let pose = Pose::new(DVec2::new(0.3, -1.2), 0.7);
        let h = 1e-6;
        for shape in &shapes {
            let placed = Placed {
                curve: shape.as_ref(),
                pose,
            };
            for p in [
                DVec2::new(0.9, 0.4),
                DVec2::new(-0.6, 1.1),
                DVec2::new(1.5, -0.2),
            ] {
                let g = placed.geometry(p);
                let fd_grad = DVec2::new(
                    (placed.value(p + DVec2::X * h) - placed.value(p - DVec2::X * h)) / (2.0 * h),
                    (placed.value(p + DVec2::Y * h) - placed.value(p - DVec2::Y * h)) / (2.0 * h),
                );
                assert_relative_eq!(g.normal.x, fd_grad.x, epsilon = 1e-7);
                assert_relative_eq!(g.normal.y, fd_grad.y, epsilon = 1e-7);
                let col_x = (placed.gradient(p + DVec2::X * h) - placed.gradient(p - DVec2::X * h))
                    / (2.0 * h);
                let col_y = (placed.gradient(p + DVec2::Y * h) - placed.gradient(p - DVec2::Y * h))
                    / (2.0 * h);
                for (a, b) in [(g.hessian.x_axis, col_x), (g.hessian.y_axis, col_y)] {
                    assert_relative_eq!(a.x, b.x, epsilon = 1e-6);
                    assert_relative_eq!(a.y, b.y, epsilon = 1e-6);
                }
                assert_relative_eq!(g.c, placed.value(p), epsilon = 1e-15);
            }
        }
    }
}
