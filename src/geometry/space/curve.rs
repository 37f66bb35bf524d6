//! Curves in space as wires: [`SpaceCurve`], two constraint rows on a
//! bead, the offset from the curve's nearest point taken along two unit
//! normals of the curve there, at right angles to each other.
//!
//! For a curve traced from a parametrization `γ(s)` ([`Traced`], a
//! [`Spline`] in space), with `s*` the nearest point's parameter,
//! `d = x − γ(s*)`, `t̂` the unit tangent and `n̂₁`, `n̂₂ = t̂ × n̂₁` the
//! rotation-minimizing normals there:
//!
//! ```text
//! Cᵢ = n̂ᵢ·d,   ∇Cᵢ = n̂ᵢ,   Hᵢ = −(n̂ᵢ·γ″) / (|γ′|² − d·γ″) t̂ t̂ᵀ
//! ```
//!
//! the plane's signed distance written for each normal (in the plane there
//! is one normal and this is `−κ/(1 − κC) t̂t̂ᵀ`). Both rows vanish exactly
//! on the curve, so RATTLE and projection hold a bead on it to rounding;
//! on the curve the gradients and the Hessians are exact, so the
//! constraint force bends a bead's path with the curve's curvature
//! exactly. A normal carried without turning about the curve makes the
//! form exact off it too; the sampled normals turn by the double
//! reflection's error (fourth order in the sample spacing), which enters
//! `∇C` only times the offset `|d|`. Which two normals the rows take does
//! not change the constraint: both span the plane across the curve, and
//! the force, the drift and the Baumgarte feedback in it are the same in
//! any basis of it.
//!
//! A planar shape placed in space ([`OnPlane`]) and the [`Helix`] are the
//! intersections of two surfaces whose normals are at right angles on the
//! curve: the shape drawn out of its plane and the plane, the cylinder
//! and the helicoid. Each row is then a surface's own exact form.

use std::f64::consts::TAU;

use bevy::math::{DMat3, DQuat, DVec3};
use serde::{Deserialize, Serialize};

use super::planar::extrude;
use super::{Cylinder, Flat, Helicoid, ImplicitSurface};
use crate::geometry::coordinates::norm;
use crate::geometry::traced::offset_row;
use crate::geometry::{Geometry, ImplicitCurve, Parametric, Spline, Traced};

/// A curve in space: two constraint rows, its offset from the curve along
/// two normals at right angles.
///
/// Implement this to put beads on a curve of one's own: give the rows at a
/// point (each row's value, gradient and Hessian must agree, and the two
/// gradients must not be parallel near the curve). Or implement
/// [`Parametric<DVec3>`](Parametric) and wrap it in a [`Traced`], which
/// finds the nearest point and the normals for you.
pub trait SpaceCurve {
    /// The two rows at `p`, the nearest point looked for near the
    /// parameter `hint` where it is finite (on a curve that crosses
    /// itself, the branch a bead is on).
    fn rows(&self, p: DVec3, hint: f64) -> [Geometry<DVec3>; 2];
    /// A characteristic length: drift is reported relative to it and
    /// solver tolerances scale with it.
    fn scale(&self) -> f64 {
        1.0
    }
    /// The curve's own parameter at its point nearest `p`, near `hint`
    /// (NaN where it has none). An island keeps it as the hint of the next
    /// step.
    fn parameter(&self, _p: DVec3, _hint: f64) -> f64 {
        f64::NAN
    }
    /// The frame of the curve at its point nearest `p`: the unit tangent
    /// along the direction of travel and the first row's normal, `n̂₁`.
    /// From the rows: `t̂ = n̂₁ × n̂₂`.
    fn frame(&self, p: DVec3, hint: f64) -> CurveFrame {
        let [a, b] = self.rows(p, hint);
        let normal = a.normal.normalize_or_zero();
        CurveFrame {
            tangent: normal.cross(b.normal).normalize_or_zero(),
            normal,
        }
    }
    /// How fast [`SpaceCurve::frame`]'s normal turns about the tangent
    /// per metre along the curve, beyond the turn that keeps it at right
    /// angles to the tangent (rad/m): zero for a rotation-minimizing
    /// frame (a traced curve's or a spline's) and for a planar shape's,
    /// whose binormal stays the plane's; a helix's torsion for its normal
    /// out from the axis. A path joint that turns a body with the frame
    /// takes the frame's turn along the curve as `t̂ × κ + twist · t̂`
    /// (`κ` the curvature vector from the rows' Hessians); override it
    /// with `frame` where the frame twists.
    fn twist(&self, _p: DVec3, _hint: f64) -> f64 {
        0.0
    }
    /// Whether the curve ends (an open spline): a bead that passes an end
    /// leaves it there, as on an open curve in the plane.
    fn has_ends(&self) -> bool {
        false
    }
    /// How far past an end along its tangent line the point nearest `p`
    /// lies, looked for near the parameter `hint`: zero or less on the
    /// curve, −∞ for a curve with no end.
    fn past_end(&self, _p: DVec3, _hint: f64) -> f64 {
        f64::NEG_INFINITY
    }
}

/// A curve's tangent and first normal at a point, both unit (zero at a
/// singular point).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CurveFrame {
    /// Along the curve, in the direction its parameter grows.
    pub tangent: DVec3,
    /// Across it: the normal of the first row.
    pub normal: DVec3,
}

impl CurveFrame {
    /// The second normal, `t̂ × n̂`.
    pub fn binormal(&self) -> DVec3 {
        self.tangent.cross(self.normal)
    }

    /// The angle about the tangent, from the normal toward the binormal,
    /// that turns the normal as near `up` as it goes.
    pub fn roll_toward(&self, up: DVec3) -> f64 {
        up.dot(self.binormal()).atan2(up.dot(self.normal))
    }

    /// The frame with its normal turned by `roll` about the tangent.
    pub fn rolled(&self, roll: f64) -> Self {
        let (sin, cos) = roll.sin_cos();
        Self {
            tangent: self.tangent,
            normal: self.normal * cos + self.binormal() * sin,
        }
    }

    /// The rotation that turns a model's axes onto the frame, as a rail
    /// carries a cart: its forward (Bevy's `−z`) along the tangent, its up
    /// (`+y`) along the normal. Not finite where the frame is zero.
    pub fn rotation(&self) -> DQuat {
        let back = -self.tangent;
        let up = self.normal;
        DQuat::from_mat3(&DMat3::from_cols(up.cross(back), up, back))
    }
}

/// A planar shape in space: the curve `C(x, y) = 0` of the wire's local
/// xy-plane. Rows: the curve drawn out along `z` ([`Extruded`](super::Extruded)), whose
/// normal lies in the plane, and the plane `z = 0` ([`Flat`]). Its frame's
/// normal is the shape's own, in the plane; its tangent runs the shape's
/// own way ([`ImplicitCurve::travel`]: counter-clockwise round a circle,
/// along +x on a line).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OnPlane<C>(pub C);

impl<C: ImplicitCurve> SpaceCurve for OnPlane<C> {
    fn rows(&self, p: DVec3, hint: f64) -> [Geometry<DVec3>; 2] {
        let curve = extrude(self.0.geometry_near(p.truncate(), hint));
        [curve, Flat.geometry(p)]
    }
    fn scale(&self) -> f64 {
        self.0.scale()
    }
    fn parameter(&self, p: DVec3, hint: f64) -> f64 {
        self.0.parameter(p.truncate(), hint)
    }
    fn frame(&self, p: DVec3, hint: f64) -> CurveFrame {
        let [curve, plane] = self.rows(p, hint);
        let normal = curve.normal.normalize_or_zero();
        // ∇C⊥ = ẑ × n̂ in the plane, turned the shape's own way.
        let tangent = plane.normal.cross(normal).normalize_or_zero() * self.0.travel();
        CurveFrame { tangent, normal }
    }
}

/// The helix about the wire's local `y`-axis: the points
/// `(r cos θ, p θ / 2π, r sin θ)` for every real `θ`, rising `pitch` per
/// turn. Rows: the [`Cylinder`] of its radius and the [`Helicoid`] of its
/// pitch (whose sheets repeat every turn, so the nearest one is the
/// bead's and no branch needs remembering). Its frame's normal points out
/// from the axis; its parameter is `θ`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Helix {
    /// The radius, positive.
    pub radius: f64,
    /// The rise per turn, positive.
    pub pitch: f64,
}

impl SpaceCurve for Helix {
    fn rows(&self, p: DVec3, _hint: f64) -> [Geometry<DVec3>; 2] {
        [
            Cylinder {
                radius: self.radius,
            }
            .geometry(p),
            Helicoid { pitch: self.pitch }.geometry(p),
        ]
    }
    fn scale(&self) -> f64 {
        self.radius
    }
    fn parameter(&self, p: DVec3, _hint: f64) -> f64 {
        let above = Helicoid { pitch: self.pitch }.value(p);
        TAU * (p.y - above) / self.pitch
    }
    fn twist(&self, _p: DVec3, _hint: f64) -> f64 {
        // The torsion of (r cos θ, c θ, r sin θ), c the rise per radian:
        // its normal out from the axis is the principal normal reversed,
        // and turns with the Frenet frame.
        let c = self.pitch / TAU;
        -c / (self.radius * self.radius + c * c)
    }
}

impl<P: Parametric<DVec3>> SpaceCurve for Traced<P, DVec3> {
    fn rows(&self, p: DVec3, hint: f64) -> [Geometry<DVec3>; 2] {
        let nearest = self.nearest(p, hint);
        let [point, d1, d2] = nearest.at;
        let tangent = d1 / norm(d1);
        let first = self.normal_at(nearest.s, tangent);
        let second = tangent.cross(first);
        let offset = p - point;
        let scale = self.length_scale();
        [
            offset_row(first, offset, d1, d2, scale),
            offset_row(second, offset, d1, d2, scale),
        ]
    }
    fn scale(&self) -> f64 {
        self.length_scale()
    }
    fn parameter(&self, p: DVec3, hint: f64) -> f64 {
        Traced::parameter(self, p, hint)
    }
    fn frame(&self, p: DVec3, hint: f64) -> CurveFrame {
        let nearest = self.nearest(p, hint);
        let d1 = nearest.at[1];
        let tangent = d1 / norm(d1);
        CurveFrame {
            tangent,
            normal: self.normal_at(nearest.s, tangent),
        }
    }
    fn has_ends(&self) -> bool {
        !self.path().closed()
    }
    fn past_end(&self, p: DVec3, hint: f64) -> f64 {
        self.nearest(p, hint).past
    }
}

impl SpaceCurve for Spline<DVec3> {
    fn rows(&self, p: DVec3, hint: f64) -> [Geometry<DVec3>; 2] {
        self.traced().rows(p, hint)
    }
    fn scale(&self) -> f64 {
        SpaceCurve::scale(self.traced())
    }
    fn parameter(&self, p: DVec3, hint: f64) -> f64 {
        SpaceCurve::parameter(self.traced(), p, hint)
    }
    fn frame(&self, p: DVec3, hint: f64) -> CurveFrame {
        self.traced().frame(p, hint)
    }
    fn has_ends(&self) -> bool {
        SpaceCurve::has_ends(self.traced())
    }
    fn past_end(&self, p: DVec3, hint: f64) -> f64 {
        SpaceCurve::past_end(self.traced(), p, hint)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A planar shape in space runs its frame's tangent the shape's own
    /// way, as a motor in the plane drives along it: counter-clockwise
    /// round a circle (at (1, 0, 0): +y), along +x on a line, with the
    /// shape's normal as the frame's.
    #[test]
    fn a_planar_shape_in_space_runs_its_own_way() {
        use crate::geometry::{Circle, Line};
        let circle = OnPlane(Circle { radius: 1.0 }).frame(DVec3::X, f64::NAN);
        assert_eq!(circle.tangent, DVec3::Y);
        assert_eq!(circle.normal, DVec3::X);
        let line = OnPlane(Line).frame(DVec3::ZERO, f64::NAN);
        assert_eq!(line.tangent, DVec3::X);
        assert_eq!(line.normal, DVec3::Y);
    }

    /// The helix of radius `r` and rise `2π c` per turn as a parametrized
    /// curve, `γ(θ) = (r cos θ, c θ, r sin θ)` over two turns.
    struct Parametrized {
        r: f64,
        c: f64,
    }

    impl Parametric<DVec3> for Parametrized {
        fn domain(&self) -> (f64, f64) {
            (0.0, 2.0 * TAU)
        }
        fn closed(&self) -> bool {
            false
        }
        fn eval(&self, s: f64) -> [DVec3; 3] {
            let (sin, cos) = s.sin_cos();
            let r = self.r;
            [
                DVec3::new(r * cos, self.c * s, r * sin),
                DVec3::new(-r * sin, self.c, r * cos),
                DVec3::new(-r * cos, 0.0, -r * sin),
            ]
        }
    }

    /// What the rows ask of a bead moving at `v` along the curve:
    /// `−Σᵢ n̂ᵢ (vᵀHᵢv) / |n̂ᵢ|²`, the acceleration across the curve that
    /// keeps it on, whatever basis the rows take.
    fn across(rows: [Geometry<DVec3>; 2], v: DVec3) -> DVec3 {
        rows.iter()
            .map(|g| -g.normal * (v.dot(g.hessian * v) / g.normal.length_squared()))
            .sum()
    }

    /// A traced helix and the helix of two surfaces hold a bead on the
    /// same curve: at points on it both rows vanish, their normals span the
    /// same plane across the tangent, and both ask the centripetal
    /// acceleration `κ|v|²` towards the axis, `κ = r/(r² + c²)`.
    #[test]
    fn a_traced_helix_asks_what_the_helix_of_two_surfaces_asks() {
        let (r, c) = (1.3, 0.4);
        let traced = Traced::new(Parametrized { r, c });
        let helix = Helix {
            radius: r,
            pitch: TAU * c,
        };
        for theta in [0.3, 2.0, 4.4, 7.9, 11.0] {
            let [p, d1, _] = Parametrized { r, c }.eval(theta);
            let v = d1 * 2.5;
            let rows = traced.rows(p, theta);
            let expected =
                -DVec3::new(p.x, 0.0, p.z).normalize() * (r / (r * r + c * c)) * v.length_squared();
            for g in rows {
                assert!(g.c.abs() < 1e-14 && g.normal.dot(d1).abs() < 1e-13);
            }
            assert!((across(rows, v) - expected).length() < 1e-12);
            assert!((across(helix.rows(p, f64::NAN), v) - expected).length() < 1e-12);
            assert!((traced.parameter(p, theta) - theta).abs() < 1e-12);
            assert!((helix.parameter(p, f64::NAN) - theta).abs() < 1e-12);
        }
    }
}
