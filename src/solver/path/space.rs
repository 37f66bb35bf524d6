//! A path joint's rows in space: the body's centre of mass and
//! orientation `R` are its six coordinates, a turn `δθ` a world rotation
//! vector applied on the left (`R ← exp(δθ) R`, as avian turns a body).
//! Its anchor is held on a curve by the curve's two rows, or on a surface
//! by its one; where the body turns with the wire, an axis `w` of the
//! body (as it lay along the wire's frame when the joint began) is held
//! at right angles to a direction `e` of that frame at the anchor: the
//! row `A = w · e`, whose gradient is
//!
//! ```text
//! ∂A/∂θ = w × e + k (a − c) × t̂,   ∂A/∂c = k t̂,   k = w · (Ω × e)
//! ```
//!
//! with `t̂` the tangent and `Ω` the frame's turn per metre along it (its
//! Darboux vector: `de/ds = Ω × e`), `Ω = t̂ × κ + τ t̂`: the tangent's own
//! turn (`κ` the curvature vector, from the rows' Hessians) and the
//! frame's twist about it ([`SpaceCurve::twist`](crate::geometry::SpaceCurve::twist)). The rows hold `w_t` at right angles to `n̂` and
//! `b̂` (the body turns about the tangent only), and so on for each mode;
//! with `w_n · b̂` too, the body turns with the frame; against the wire's
//! own axes (`Ω = 0`) it keeps its orientation to the wire.

use bevy::math::{DMat3, DQuat, DVec3};

use super::{Bend, BodyRow, JointBody, JointWire, Rows};
use crate::geometry::{Geometry, Pose3, SpaceShape};

/// A rigid body in space as the joint sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SpaceBody {
    /// The centre of mass, world frame.
    pub centre: DVec3,
    /// The body's orientation.
    pub rotation: DQuat,
    /// The anchor from the centre of mass, in the body's frame.
    pub arm: DVec3,
    /// `1 / m` along each world axis (0 along a locked one).
    pub inverse_mass: DVec3,
    /// `I⁻¹` about the centre of mass, world frame.
    pub inverse_inertia: DMat3,
}

impl JointBody for SpaceBody {
    type V = DVec3;
    type Turn = DVec3;
    const COORDINATES: usize = 6;

    fn centre(&self) -> DVec3 {
        self.centre
    }

    fn anchor(&self) -> DVec3 {
        if self.arm == DVec3::ZERO {
            return self.centre;
        }
        self.centre + self.rotation * self.arm
    }

    fn moment(r: DVec3, d: DVec3) -> DVec3 {
        r.cross(d)
    }

    fn inverse_mass(&self, p: DVec3) -> DVec3 {
        p * self.inverse_mass
    }

    fn inverse_inertia(&self, tau: DVec3) -> DVec3 {
        self.inverse_inertia * tau
    }

    fn displaced(&self, linear: DVec3, turn: DVec3) -> Self {
        let rotation = if turn == DVec3::ZERO {
            self.rotation
        } else {
            (DQuat::from_scaled_axis(turn) * self.rotation).normalize()
        };
        Self {
            centre: self.centre + linear,
            rotation,
            ..*self
        }
    }

    fn carry(&self, was: &Self, p: DVec3, d: DVec3) -> (DVec3, DVec3) {
        let turn = self.rotation * was.rotation.inverse();
        (self.centre + turn * (p - was.centre), turn * d)
    }
}

/// How a body held on a curve in space turns with it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SpaceTurn {
    /// About the curve's tangent only.
    AroundTangent,
    /// About its normal only.
    AroundNormal,
    /// About its binormal only.
    AroundBinormal,
    /// With the curve's frame.
    ToPath,
    /// Not at all, against the wire's own axes.
    Fixed,
}

/// How a body turns with its wire, fixed where the joint began: the mode,
/// and the body's axes that lay along the wire's frame then (tangent,
/// normal, binormal; the wire's own axes for [`SpaceTurn::Fixed`]), in the
/// body's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Alignment {
    /// The mode.
    pub turn: SpaceTurn,
    /// `R₀⁻¹ F₀`: the frame's axes as the body's own.
    pub axes: DQuat,
}

impl Alignment {
    /// The body axis and the frame direction (0 tangent, 1 normal, 2
    /// binormal) of each row the mode holds.
    fn pairs(&self) -> &'static [(usize, usize)] {
        match self.turn {
            SpaceTurn::AroundTangent => &[(0, 1), (0, 2)],
            SpaceTurn::AroundNormal => &[(1, 0), (1, 2)],
            SpaceTurn::AroundBinormal => &[(2, 0), (2, 1)],
            SpaceTurn::ToPath | SpaceTurn::Fixed => &[(0, 1), (0, 2), (1, 2)],
        }
    }
}

/// A wire in space as a joint holds a body on it, where the wire is at
/// one instant.
#[derive(Clone, Copy)]
pub(crate) struct SpaceWireAt<'a> {
    /// The wire's shape, local frame.
    pub shape: &'a SpaceShape,
    /// Where it is.
    pub pose: Pose3,
    /// The curve's parameter near the anchor: its branch.
    pub hint: f64,
    /// How the body turns with it, once fixed.
    pub alignment: Option<Alignment>,
}

/// The columns of a rotation as its three axes.
fn axes(rotation: DQuat) -> [DVec3; 3] {
    [
        rotation * DVec3::X,
        rotation * DVec3::Y,
        rotation * DVec3::Z,
    ]
}

impl SpaceWireAt<'_> {
    /// The wire's frame at the point of the curve nearest the local point
    /// `local` (see [`Self::frame_near`]).
    fn local_frame(&self, local: DVec3) -> Option<DQuat> {
        let SpaceShape::Curve(curve) = self.shape else {
            return None;
        };
        self.frame_near(local, &curve.rows(local, self.hint))
    }

    /// The wire's frame at the point of the curve nearest the local point
    /// `local`, whose rows are `rows` (to second order in its distance:
    /// one step back along the rows, so that the frame moves only as the
    /// anchor moves along the curve, whatever the curve's own frame does
    /// off it), as a rotation whose axes are its tangent, normal and
    /// binormal (wire frame); `None` on a surface or at a singular point.
    fn frame_near(&self, local: DVec3, rows: &[Geometry<DVec3>]) -> Option<DQuat> {
        let SpaceShape::Curve(curve) = self.shape else {
            return None;
        };
        let mut foot = local;
        for row in rows {
            let length = row.normal.length_squared();
            if !(length > 0.0 && length.is_finite()) {
                return None;
            }
            foot -= row.normal * (row.c / length);
        }
        let frame = curve.frame(foot, self.hint);
        let (t, n) = (frame.tangent, frame.normal);
        (t != DVec3::ZERO && n != DVec3::ZERO)
            .then(|| DQuat::from_mat3(&DMat3::from_cols(t, n, t.cross(n))).normalize())
            .filter(|q| q.is_finite())
    }

    /// The frame the body turns against at `body`'s anchor, world: the
    /// curve's for a mode that turns with it, the wire's own axes for
    /// [`SpaceTurn::Fixed`]. `None` where there is none (a surface, a
    /// singular point).
    pub fn frame(&self, body: &SpaceBody, turn: SpaceTurn) -> Option<DQuat> {
        if turn == SpaceTurn::Fixed {
            return Some(self.pose.rotation);
        }
        Some(self.pose.rotation * self.local_frame(self.pose.to_local(body.anchor()))?)
    }

    /// The curve's parameter at the body's anchor (NaN on a surface).
    pub fn parameter(&self, body: &SpaceBody) -> f64 {
        match self.shape {
            SpaceShape::Curve(curve) => {
                curve.parameter(self.pose.to_local(body.anchor()), self.hint)
            }
            SpaceShape::Surface(_) => f64::NAN,
        }
    }

    /// The rows that turn the body with the wire (see the module's docs):
    /// against `frame` (world), which turns by `rate` per metre along the
    /// unit tangent `tangent` (world).
    fn turned(
        body: &SpaceBody,
        alignment: &Alignment,
        frame: DQuat,
        (tangent, rate): (DVec3, DVec3),
    ) -> [BodyRow<SpaceBody>; 3] {
        let along = BodyRow::at_anchor(body, 0.0, tangent);
        let body_axes = axes(body.rotation * alignment.axes);
        let frame_axes = axes(frame);
        let mut rows = [BodyRow::default(); 3];
        for (row, &(k, l)) in rows.iter_mut().zip(alignment.pairs()) {
            let (w, e) = (body_axes[k], frame_axes[l]);
            let turning = w.dot(rate.cross(e));
            *row = BodyRow {
                value: w.dot(e),
                along_centre: along.along_centre * turning,
                along_angle: w.cross(e) + along.along_angle * turning,
            };
        }
        rows
    }
}

impl JointWire<SpaceBody> for SpaceWireAt<'_> {
    fn carried_by(&self, carrier: Option<&SpaceBody>) -> Self {
        // A carrier's arm is its origin from its centre of mass: its
        // anchor is its origin.
        let pose = match carrier {
            Some(carrier) => Pose3 {
                origin: carrier.anchor(),
                rotation: carrier.rotation,
            }
            .compose(&self.pose),
            None => self.pose,
        };
        Self { pose, ..*self }
    }

    fn held(&self, body: &SpaceBody) -> Option<Rows<SpaceBody>> {
        let local = self.pose.to_local(body.anchor());
        // The curve's two rows, or the surface's one.
        let (all, count) = match self.shape {
            SpaceShape::Curve(curve) => (curve.rows(local, self.hint), 2),
            SpaceShape::Surface(surface) => ([surface.geometry(local); 2], 1),
        };
        let geometries = &all[..count];
        let mut units = [(0.0, DVec3::ZERO, 0.0); 2];
        for (unit, g) in units.iter_mut().zip(geometries) {
            let length = g.normal.length();
            if !(length > 0.0 && length.is_finite() && g.c.is_finite()) {
                return None;
            }
            *unit = (g.c / length, g.normal / length, length);
        }
        let units = &units[..count];
        // A curve's tangent, and its curvature vector from the rows'
        // Hessians: κ = −Σ (t̂ᵀ Hᵢ t̂ / |∇Cᵢ|) n̂ᵢ (wire frame).
        let curvature = |tangent: DVec3| -> DVec3 {
            geometries
                .iter()
                .zip(units)
                .map(|(g, &(_, n, length))| -n * tangent.dot(g.hessian * tangent) / length)
                .sum()
        };
        let bend = if let &[(_, a, _), (_, b, _)] = units {
            let tangent = a.cross(b).normalize_or_zero();
            Bend {
                tangent: self.pose.rotate(tangent),
                curvature: curvature(tangent).length(),
            }
        } else {
            Bend::default()
        };
        let mut rows = Rows::bending(bend);
        for &(distance, normal, _) in units {
            rows.push(BodyRow::at_anchor(body, distance, self.pose.rotate(normal)));
        }
        if let Some(alignment) = &self.alignment {
            // The frame, and its turn per metre along the tangent: the
            // tangent's own (t̂ × κ) and the frame's twist about it.
            let (frame, tangent, rate) = match (alignment.turn, self.shape) {
                (SpaceTurn::Fixed, _) => (DQuat::IDENTITY, DVec3::X, DVec3::ZERO),
                (_, SpaceShape::Curve(curve)) => {
                    let frame = self.frame_near(local, geometries)?;
                    let tangent = frame * DVec3::X;
                    let twist = curve.twist(local, self.hint);
                    (
                        frame,
                        tangent,
                        tangent.cross(curvature(tangent)) + twist * tangent,
                    )
                }
                (_, SpaceShape::Surface(_)) => return None,
            };
            let rotate = |v: DVec3| self.pose.rotate(v);
            let turned = Self::turned(
                body,
                alignment,
                self.pose.rotation * frame,
                (rotate(tangent), rotate(rate)),
            );
            for row in &turned[..alignment.pairs().len()] {
                rows.push(*row);
            }
        }
        Some(rows)
    }

    fn past_end(&self, body: &SpaceBody) -> Option<BodyRow<SpaceBody>> {
        let SpaceShape::Curve(curve) = self.shape else {
            return None;
        };
        if !curve.has_ends() {
            return None;
        }
        let local = self.pose.to_local(body.anchor());
        let value = curve.past_end(local, self.hint);
        let tangent = self.local_frame(local)?.mul_vec3(DVec3::X);
        // Which way is out: past an end the curve goes on along its
        // tangent, so `past_end` grows by the step along it.
        let step = 1e-6 * curve.scale();
        let out = if curve.past_end(local + step * tangent, self.hint)
            >= curve.past_end(local - step * tangent, self.hint)
        {
            tangent
        } else {
            -tangent
        };
        value
            .is_finite()
            .then(|| BodyRow::at_anchor(body, value, self.pose.rotate(out)))
    }

    fn along(&self, body: &SpaceBody) -> Option<BodyRow<SpaceBody>> {
        let local = self.pose.to_local(body.anchor());
        let tangent = self.local_frame(local)?.mul_vec3(DVec3::X);
        Some(BodyRow::at_anchor(body, 0.0, self.pose.rotate(tangent)))
    }

    fn to_world(&self, local: DVec3) -> DVec3 {
        self.pose.to_world(local)
    }

    fn scale(&self) -> f64 {
        self.shape.scale()
    }
}
