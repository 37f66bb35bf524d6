//! Wire shapes as implicit curves `C(x) = 0`.
//!
//! The constraint solver needs three things of a wire at a point `x`: the
//! constraint value `C(x)`, its gradient `N = ∇C(x)` (the direction the
//! constraint force acts along) and its Hessian `H(x)` (which gives
//! `Ṅ = H ẋ`). [`ImplicitCurve`] is that contract; the built-in shapes
//! implement it and a game can implement it for its own curve.
//!
//! Every built-in `C` is scaled so that `|∇C| = 1` on the circle and close to 1
//! on the other shapes near the wire, which makes `C` read as a distance in
//! world units and keeps the Baumgarte gains α and β meaning the same thing on
//! every shape.
//!
//! Shapes are written in the wire's local frame; [`Pose`] places them in the
//! plane (translation and rotation) and [`Placed`] evaluates a shape in world
//! coordinates: `C_w(x) = C(Rᵀ(x - o))`, `∇C_w = R ∇C`, `H_w = R H Rᵀ`.

use std::f64::consts::TAU;
use std::fmt;
use std::sync::Arc;

use bevy::math::{DMat2, DVec2};
use bevy::prelude::Transform;
use serde::{Deserialize, Serialize};

use crate::params::ParamError;

/// The value, gradient and Hessian of a constraint at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// The constraint value `C(x)`: zero on the wire.
    pub c: f64,
    /// The gradient `N = ∇C(x)`.
    pub normal: DVec2,
    /// The Hessian `H(x)` of `C`, so that `Ṅ = H ẋ`.
    pub hessian: DMat2,
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
    /// All three at once; override when they share work.
    fn geometry(&self, p: DVec2) -> Geometry {
        Geometry {
            c: self.value(p),
            normal: self.gradient(p),
            hessian: self.hessian(p),
        }
    }
}

fn positive(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ParamError::NotPositive { name, value })
    }
}

fn finite(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ParamError::NotFinite { name, value })
    }
}

/// A circle of radius `r` about the local origin: `C = |x| - r`, the seed's
/// wire. Singular at the centre.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Circle {
    /// The radius.
    pub radius: f64,
}

impl ImplicitCurve for Circle {
    fn value(&self, p: DVec2) -> f64 {
        p.length() - self.radius
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.geometry(p).normal
    }
    fn hessian(&self, p: DVec2) -> DMat2 {
        self.geometry(p).hessian
    }
    fn scale(&self) -> f64 {
        self.radius
    }
    #[inline]
    fn geometry(&self, p: DVec2) -> Geometry {
        let len = p.length();
        if len == 0.0 {
            // ∇C is undefined at the centre; a zero normal is reported as singular.
            return Geometry {
                c: -self.radius,
                normal: DVec2::ZERO,
                hessian: DMat2::ZERO,
            };
        }
        let inv = 1.0 / len;
        let n = p * inv;
        // H = (I - n nᵀ) / |x|
        let hessian = DMat2::from_cols(
            DVec2::new(1.0 - n.x * n.x, -n.x * n.y) * inv,
            DVec2::new(-n.x * n.y, 1.0 - n.y * n.y) * inv,
        );
        Geometry {
            c: len - self.radius,
            normal: n,
            hessian,
        }
    }
}

/// An axis-aligned ellipse with semi-axes `a` (local x) and `b` (local y):
/// `C = (ℓ/2)(x²/a² + y²/b² - 1)` with `ℓ = sqrt(ab)`, so that a circle
/// (`a = b`) has `|∇C| = 1` on the wire. Singular at the centre.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ellipse {
    /// Semi-axis along local x.
    pub a: f64,
    /// Semi-axis along local y.
    pub b: f64,
}

impl Ellipse {
    fn ell(&self) -> f64 {
        (self.a * self.b).sqrt()
    }
}

impl ImplicitCurve for Ellipse {
    fn value(&self, p: DVec2) -> f64 {
        0.5 * self.ell() * ((p.x / self.a).powi(2) + (p.y / self.b).powi(2) - 1.0)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.ell() * DVec2::new(p.x / (self.a * self.a), p.y / (self.b * self.b))
    }
    fn hessian(&self, _p: DVec2) -> DMat2 {
        DMat2::from_diagonal(
            self.ell() * DVec2::new(1.0 / (self.a * self.a), 1.0 / (self.b * self.b)),
        )
    }
    fn scale(&self) -> f64 {
        self.ell()
    }
}

/// The infinite straight line along the local x axis: `C = y`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Line;

impl ImplicitCurve for Line {
    fn value(&self, p: DVec2) -> f64 {
        p.y
    }
    fn gradient(&self, _p: DVec2) -> DVec2 {
        DVec2::Y
    }
    fn hessian(&self, _p: DVec2) -> DMat2 {
        DMat2::ZERO
    }
}

/// The parabola `y = x² / (4f)` with focal length `f` (opening up for
/// `f > 0`): `C = y - x²/(4f)`. Its scale is `f`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Parabola {
    /// The focal length: the vertex's radius of curvature is `2f`.
    pub focal_length: f64,
}

impl ImplicitCurve for Parabola {
    fn value(&self, p: DVec2) -> f64 {
        p.y - p.x * p.x / (4.0 * self.focal_length)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        DVec2::new(-p.x / (2.0 * self.focal_length), 1.0)
    }
    fn hessian(&self, _p: DVec2) -> DMat2 {
        DMat2::from_diagonal(DVec2::new(-1.0 / (2.0 * self.focal_length), 0.0))
    }
    fn scale(&self) -> f64 {
        self.focal_length.abs()
    }
}

/// A sine track `y = A sin(2π x / λ)`: `C = y - A sin(kx)`, `k = 2π/λ`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sine {
    /// The amplitude `A`.
    pub amplitude: f64,
    /// The wavelength `λ`.
    pub wavelength: f64,
}

impl Sine {
    fn k(&self) -> f64 {
        TAU / self.wavelength
    }
}

impl ImplicitCurve for Sine {
    fn value(&self, p: DVec2) -> f64 {
        p.y - self.amplitude * (self.k() * p.x).sin()
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        let k = self.k();
        DVec2::new(-self.amplitude * k * (k * p.x).cos(), 1.0)
    }
    fn hessian(&self, p: DVec2) -> DMat2 {
        let k = self.k();
        DMat2::from_diagonal(DVec2::new(self.amplitude * k * k * (k * p.x).sin(), 0.0))
    }
    fn scale(&self) -> f64 {
        self.wavelength
    }
}

/// One of the built-in shapes, or a curve of the game's own.
#[derive(Clone, Serialize, Deserialize)]
pub enum WireShape {
    /// See [`Circle`].
    Circle(Circle),
    /// See [`Ellipse`].
    Ellipse(Ellipse),
    /// See [`Line`].
    Line(Line),
    /// See [`Parabola`].
    Parabola(Parabola),
    /// See [`Sine`].
    Sine(Sine),
    /// A game's own curve. Not serializable.
    #[serde(skip)]
    Custom(Arc<dyn ImplicitCurve + Send + Sync>),
}

impl fmt::Debug for WireShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Circle(s) => s.fmt(f),
            Self::Ellipse(s) => s.fmt(f),
            Self::Line(s) => s.fmt(f),
            Self::Parabola(s) => s.fmt(f),
            Self::Sine(s) => s.fmt(f),
            Self::Custom(_) => f.write_str("Custom(..)"),
        }
    }
}

impl WireShape {
    /// Checks the shape's dimensions: every length positive and finite
    /// (a sine's amplitude and a parabola's focal length may be negative).
    pub fn validate(&self) -> Result<(), ParamError> {
        match self {
            Self::Circle(c) => positive("radius", c.radius).map(drop),
            Self::Ellipse(e) => {
                positive("semi-axis a", e.a)?;
                positive("semi-axis b", e.b).map(drop)
            }
            Self::Line(_) | Self::Custom(_) => Ok(()),
            Self::Parabola(p) => {
                finite("focal length", p.focal_length)?;
                if p.focal_length == 0.0 {
                    return Err(ParamError::NotPositive {
                        name: "|focal length|",
                        value: p.focal_length,
                    });
                }
                Ok(())
            }
            Self::Sine(s) => {
                finite("amplitude", s.amplitude)?;
                positive("wavelength", s.wavelength).map(drop)
            }
        }
    }

    /// The shape as an [`ImplicitCurve`].
    pub fn curve(&self) -> &dyn ImplicitCurve {
        match self {
            Self::Circle(s) => s,
            Self::Ellipse(s) => s,
            Self::Line(s) => s,
            Self::Parabola(s) => s,
            Self::Sine(s) => s,
            Self::Custom(s) => s.as_ref(),
        }
    }

    /// The lowest point of the wire in its local frame (where a bead hangs
    /// at rest under gravity along local -y); the origin for shapes with no
    /// lowest point.
    pub fn bottom(&self) -> DVec2 {
        match self {
            Self::Circle(c) => DVec2::new(0.0, -c.radius),
            Self::Ellipse(e) => DVec2::new(0.0, -e.b),
            Self::Sine(s) => DVec2::new(-0.25 * s.wavelength, -s.amplitude),
            Self::Line(_) | Self::Parabola(_) | Self::Custom(_) => DVec2::ZERO,
        }
    }

    /// A short lowercase name: `circle`, `ellipse`, `line`, `parabola`,
    /// `sine` or `custom`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Circle(_) => "circle",
            Self::Ellipse(_) => "ellipse",
            Self::Line(_) => "line",
            Self::Parabola(_) => "parabola",
            Self::Sine(_) => "sine",
            Self::Custom(_) => "custom",
        }
    }
}

/// Where a wire sits in the plane: a translation and a rotation, in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// The local origin in world coordinates.
    pub origin: DVec2,
    /// `(cos θ, sin θ)` of the rotation from local to world.
    pub rotation: DVec2,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    /// No translation, no rotation.
    pub const IDENTITY: Self = Self {
        origin: DVec2::ZERO,
        rotation: DVec2::X,
    };

    /// A pose from an origin and a rotation angle in radians.
    pub fn new(origin: DVec2, angle: f64) -> Self {
        Self {
            origin,
            rotation: DVec2::from_angle(angle),
        }
    }

    /// The in-plane part of a `Transform`: its translation's x and y and its
    /// rotation about z. Returns an error if the transform is not finite.
    pub fn from_transform(transform: &Transform) -> Result<Self, ParamError> {
        let t = transform.translation;
        let axis = transform.rotation * bevy::math::Vec3::X;
        let origin = DVec2::new(f64::from(t.x), f64::from(t.y));
        let rotation = DVec2::new(f64::from(axis.x), f64::from(axis.y));
        if !origin.is_finite() || !rotation.is_finite() || rotation.length_squared() == 0.0 {
            return Err(ParamError::NotFinite {
                name: "wire transform",
                value: f64::NAN,
            });
        }
        Ok(Self {
            origin,
            rotation: rotation.normalize(),
        })
    }

    fn matrix(&self) -> DMat2 {
        let (c, s) = (self.rotation.x, self.rotation.y);
        DMat2::from_cols(DVec2::new(c, s), DVec2::new(-s, c))
    }

    /// A world point in the local frame.
    pub fn to_local(&self, p: DVec2) -> DVec2 {
        self.matrix().transpose() * (p - self.origin)
    }

    /// A local point in world coordinates.
    pub fn to_world(&self, p: DVec2) -> DVec2 {
        self.origin + self.matrix() * p
    }

    /// Whether the pose only translates (the rotation is exactly none).
    pub fn is_unrotated(&self) -> bool {
        self.rotation == DVec2::X
    }

    /// A local direction in world coordinates.
    pub fn rotate(&self, d: DVec2) -> DVec2 {
        self.matrix() * d
    }
}

/// A curve placed in the world by a [`Pose`]: itself an [`ImplicitCurve`] in
/// world coordinates. `C` is the curve's type: `dyn ImplicitCurve` by
/// default, or a concrete shape so the step's loops inline it.
pub struct Placed<'a, C: ImplicitCurve + ?Sized = dyn ImplicitCurve + 'a> {
    /// The curve in its local frame.
    pub curve: &'a C,
    /// Where it sits.
    pub pose: Pose,
}

impl<C: ImplicitCurve + ?Sized> Clone for Placed<'_, C> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<C: ImplicitCurve + ?Sized> Copy for Placed<'_, C> {}

impl<C: ImplicitCurve + ?Sized> ImplicitCurve for Placed<'_, C> {
    fn value(&self, p: DVec2) -> f64 {
        self.curve.value(self.pose.to_local(p))
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.pose.rotate(self.curve.gradient(self.pose.to_local(p)))
    }
    fn hessian(&self, p: DVec2) -> DMat2 {
        let r = self.pose.matrix();
        r * self.curve.hessian(self.pose.to_local(p)) * r.transpose()
    }
    fn scale(&self) -> f64 {
        self.curve.scale()
    }
    #[inline(always)]
    fn geometry(&self, p: DVec2) -> Geometry {
        if self.pose.is_unrotated() {
            // The common case needs no rotation, only the translation.
            self.curve.geometry(p - self.pose.origin)
        } else {
            self.rotated_geometry(p)
        }
    }
}

impl<C: ImplicitCurve + ?Sized> Placed<'_, C> {
    #[inline(never)]
    fn rotated_geometry(&self, p: DVec2) -> Geometry {
        let local = self.curve.geometry(self.pose.to_local(p));
        let r = self.pose.matrix();
        Geometry {
            c: local.c,
            normal: r * local.normal,
            hessian: r * local.hessian * r.transpose(),
        }
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

    #[test]
    fn circle_centre_has_zero_normal_not_nan() {
        let g = Circle { radius: 1.0 }.geometry(DVec2::ZERO);
        assert_eq!(g.normal, DVec2::ZERO);
        assert!(g.hessian.is_finite());
    }

    #[test]
    fn pose_round_trips() {
        let pose = Pose::new(DVec2::new(2.0, -3.0), 1.1);
        let p = DVec2::new(0.25, 4.5);
        let back = pose.to_world(pose.to_local(p));
        assert_relative_eq!(back.x, p.x, epsilon = 1e-14);
        assert_relative_eq!(back.y, p.y, epsilon = 1e-14);
    }

    #[test]
    fn shapes_refuse_bad_dimensions() {
        let err = WireShape::Circle(Circle { radius: 0.0 })
            .validate()
            .unwrap_err();
        assert_eq!(err.to_string(), "radius must be positive and finite, got 0");
        assert!(
            WireShape::Ellipse(Ellipse {
                a: 1.0,
                b: f64::NAN
            })
            .validate()
            .is_err()
        );
        assert!(
            WireShape::Parabola(Parabola { focal_length: 0.0 })
                .validate()
                .is_err()
        );
        assert!(
            WireShape::Sine(Sine {
                amplitude: 1.0,
                wavelength: -1.0
            })
            .validate()
            .is_err()
        );
        assert!(WireShape::Line(Line).validate().is_ok());
    }
}
