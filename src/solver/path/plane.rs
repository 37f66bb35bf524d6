//! A path joint's rows in the plane: the body's centre of mass and angle
//! `θ` are its three coordinates; its anchor is held on an implicit curve
//! and, where the body turns with the wire, `θ` is held at the curve's
//! tangent angle at the anchor plus the offset it had when the joint
//! began.

use bevy::math::DVec2;

use super::{Bend, BodyRow, BodyVelocity, JointBody, JointWire, Rows};
use crate::geometry::{ImplicitCurve, Placed, Pose};

/// A rigid body in the plane as the joint sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PlaneBody {
    /// The centre of mass, world frame.
    pub centre: DVec2,
    /// The body's angle, counter-clockwise.
    pub angle: f64,
    /// The anchor from the centre of mass, in the body's frame.
    pub arm: DVec2,
    /// `1 / m` along each axis (0 along an axis the body does not move
    /// along, as an engine's locked axes).
    pub inverse_mass: DVec2,
    /// `1 / I` about the centre of mass (0 for a body that does not turn).
    pub inverse_inertia: f64,
}

impl JointBody for PlaneBody {
    type V = DVec2;
    type Turn = f64;
    const COORDINATES: usize = 3;

    fn centre(&self) -> DVec2 {
        self.centre
    }

    fn anchor(&self) -> DVec2 {
        if self.arm == DVec2::ZERO {
            // Held at its centre of mass, as a cart often is: no turn to take.
            return self.centre;
        }
        self.centre + DVec2::from_angle(self.angle).rotate(self.arm)
    }

    fn moment(r: DVec2, d: DVec2) -> f64 {
        r.perp_dot(d)
    }

    fn inverse_mass(&self, p: DVec2) -> DVec2 {
        p * self.inverse_mass
    }

    fn inverse_inertia(&self, tau: f64) -> f64 {
        tau * self.inverse_inertia
    }

    fn displaced(&self, linear: DVec2, turn: f64) -> Self {
        Self {
            centre: self.centre + linear,
            angle: self.angle + turn,
            ..*self
        }
    }

    fn carry(&self, was: &Self, p: DVec2, d: DVec2) -> (DVec2, DVec2) {
        let turn = DVec2::from_angle(self.angle - was.angle);
        (self.centre + turn.rotate(p - was.centre), turn.rotate(d))
    }
}

/// A body's velocity in the plane.
pub(crate) type PlaneVelocity = BodyVelocity<PlaneBody>;

/// `v` turned a quarter counter-clockwise.
fn perp(v: DVec2) -> DVec2 {
    DVec2::new(-v.y, v.x)
}

/// A curve in the plane as a joint holds a body on it: the curve where it
/// is, the offset of the body's angle from its tangent where the body
/// turns with it, and which way the wire's own direction runs (±1, see
/// [`along_curve`]).
pub(crate) struct PlaneWire<'a, C: ImplicitCurve + ?Sized> {
    /// The curve, placed.
    pub curve: Placed<'a, C>,
    /// The body's angle less the tangent's, where it turns with the wire.
    pub turned: Option<f64>,
    /// `±1`: the sign of the wire's own direction against `∇C⊥`.
    pub travel: f64,
}

impl<C: ImplicitCurve + ?Sized> JointWire<PlaneBody> for PlaneWire<'_, C> {
    fn carried_by(&self, carrier: Option<&PlaneBody>) -> Self {
        // A carrier's arm is its origin from its centre of mass: its
        // anchor is its origin.
        let pose = match carrier {
            Some(carrier) => Pose::new(carrier.anchor(), carrier.angle).compose(&self.curve.pose),
            None => self.curve.pose,
        };
        Self {
            curve: Placed {
                curve: self.curve.curve,
                pose,
            },
            turned: self.turned,
            travel: self.travel,
        }
    }

    fn held(&self, body: &PlaneBody) -> Option<Rows<PlaneBody>> {
        held(&self.curve, body, self.turned)
    }

    fn past_end(&self, body: &PlaneBody) -> Option<BodyRow<PlaneBody>> {
        past_end(&self.curve, body)
    }

    fn along(&self, body: &PlaneBody) -> Option<BodyRow<PlaneBody>> {
        along_curve(&self.curve, body, self.travel)
    }

    fn to_world(&self, local: DVec2) -> DVec2 {
        self.curve.pose.to_world(local)
    }

    fn scale(&self) -> f64 {
        self.curve.scale()
    }
}

/// The curve's unit normal at `p`, or `None` at a singular point.
fn unit_normal(curve: &impl ImplicitCurve, p: DVec2) -> Option<DVec2> {
    let geometry = curve.geometry(p);
    let length = geometry.normal.length();
    (length > 0.0 && length.is_finite() && geometry.c.is_finite()).then(|| geometry.normal / length)
}

/// The curve at a body's anchor, evaluated once for every row that needs
/// it: the distance `C / |∇C|`, the unit normal and `∇ψ = H t / |∇C|`,
/// the gradient of the tangent's angle `ψ` (see [`turned_with_curve`]).
struct AtAnchor {
    distance: f64,
    normal: DVec2,
    turn_gradient: DVec2,
}

impl AtAnchor {
    /// `None` at a singular point.
    fn new(curve: &impl ImplicitCurve, body: &PlaneBody) -> Option<Self> {
        let geometry = curve.geometry(body.anchor());
        let length = geometry.normal.length();
        if !(length > 0.0 && length.is_finite() && geometry.c.is_finite()) {
            return None;
        }
        let normal = geometry.normal / length;
        // The tangent turns as the normal does: dψ = N⊥ · dN / |N|² with
        // dN = H dx, so ∇ψ = H N⊥ / |N|² = H t / |N|.
        Some(Self {
            distance: geometry.c / length,
            normal,
            turn_gradient: geometry.hessian * perp(normal) / length,
        })
    }

    /// The on-the-curve row (see [`on_curve`]).
    fn on_curve(&self, body: &PlaneBody) -> BodyRow<PlaneBody> {
        BodyRow::at_anchor(body, self.distance, self.normal)
    }

    /// The turned-with-the-curve row (see [`turned_with_curve`]).
    fn turned(&self, body: &PlaneBody, offset: f64) -> BodyRow<PlaneBody> {
        let tangent = perp(self.normal);
        // ψ depends on the anchor, which moves with the centre and turns
        // about it: ∂a/∂c = I, ∂a/∂θ = (a − c)⊥.
        let turn = BodyRow::at_anchor(body, 0.0, self.turn_gradient);
        BodyRow {
            value: wrap(body.angle - tangent.y.atan2(tangent.x) - offset),
            along_centre: -turn.along_centre,
            along_angle: 1.0 - turn.along_angle,
        }
    }
}

/// The anchor's distance from the curve to first order, `C(a) / |∇C(a)|`
/// (zero exactly on the curve), as a row of the body: its gradient is the
/// curve's unit normal at the anchor along the centre, and that normal's
/// moment about the centre along the angle. `None` at a singular point.
#[cfg(test)]
pub(crate) fn on_curve(curve: &impl ImplicitCurve, body: &PlaneBody) -> Option<BodyRow<PlaneBody>> {
    Some(AtAnchor::new(curve, body)?.on_curve(body))
}

/// The rows a joint holds at `body`, the curve evaluated once: the anchor
/// on the curve and, where `offset` is given, the body's angle turned
/// with it (see [`turned_with_curve`]). `None` at a singular point.
pub(crate) fn held(
    curve: &impl ImplicitCurve,
    body: &PlaneBody,
    offset: Option<f64>,
) -> Option<Rows<PlaneBody>> {
    let at = AtAnchor::new(curve, body)?;
    let mut rows = Rows::bending(Bend {
        tangent: perp(at.normal),
        curvature: at.turn_gradient.length(),
    });
    rows.push(at.on_curve(body));
    if let Some(offset) = offset {
        rows.push(at.turned(body, offset));
    }
    Some(rows)
}

/// The anchor's motion along the curve as a row of the body (its value
/// zero): the curve's unit tangent `t = travel ∇C⊥ / |∇C|` at the anchor
/// along the centre, its moment about the centre along the angle. `travel`
/// (±1) says which way the wire's own direction runs. `None` at a
/// singular point.
pub(crate) fn along_curve(
    curve: &impl ImplicitCurve,
    body: &PlaneBody,
    travel: f64,
) -> Option<BodyRow<PlaneBody>> {
    let normal = unit_normal(curve, body.anchor())?;
    Some(BodyRow::at_anchor(body, 0.0, travel * perp(normal)))
}

/// How far past an end of an open curve the anchor is, along the end's
/// tangent (zero or less: on the curve between its ends), as a row of
/// the body whose gradient points out past that end. `None` for a curve
/// with no end, or at a singular point.
pub(crate) fn past_end(curve: &impl ImplicitCurve, body: &PlaneBody) -> Option<BodyRow<PlaneBody>> {
    if !curve.has_ends() {
        return None;
    }
    let anchor = body.anchor();
    let value = curve.past_end(anchor);
    let normal = unit_normal(curve, anchor)?;
    // Which way is out: past an end the curve goes on along its tangent,
    // so `past_end` grows by the step along it, one way or the other.
    let tangent = perp(normal);
    let step = 1e-6 * curve.scale();
    let out = if curve.past_end(anchor + step * tangent) >= curve.past_end(anchor - step * tangent)
    {
        tangent
    } else {
        -tangent
    };
    value
        .is_finite()
        .then(|| BodyRow::at_anchor(body, value, out))
}

/// The body's angle less the curve's tangent angle at the anchor and
/// `offset`, wrapped into `(−π, π]`, as a row of the body: `ψ = atan2(t)`
/// with the tangent `t = ∇C⊥ / |∇C|` turns as the anchor moves, with
/// `∇ψ = H t / |∇C|` (`H` the Hessian of `C`). `None` at a singular point.
#[cfg(test)]
pub(crate) fn turned_with_curve(
    curve: &impl ImplicitCurve,
    body: &PlaneBody,
    offset: f64,
) -> Option<BodyRow<PlaneBody>> {
    Some(AtAnchor::new(curve, body)?.turned(body, offset))
}

/// The tangent angle at the anchor that a body turned with the curve keeps
/// its own angle from: `θ − ψ`, wrapped. `None` at a singular point.
pub(crate) fn turn_offset(curve: &impl ImplicitCurve, body: &PlaneBody) -> Option<f64> {
    Some(AtAnchor::new(curve, body)?.turned(body, 0.0).value)
}

/// `angle` wrapped into `(−π, π]`.
fn wrap(angle: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let wrapped = angle.rem_euclid(TAU);
    if wrapped > PI { wrapped - TAU } else { wrapped }
}
