//! A rigid body held on a wire by a point of its own (a path joint), in
//! the plane and in space, as pure functions of the body's state
//! (docs/method.md, "Rigid bodies on wires"). The body's centre of mass
//! `c` and its orientation are its coordinates `q`; its anchor
//! `a = c + R r` (`r` the anchor's arm from the centre of mass in the
//! body's frame) is held on the wire, and where the body turns with the
//! wire, its orientation is held to the wire's frame at the anchor as it
//! was when the joint began.
//!
//! A physics engine's substep moves the body freely; the joint then puts
//! it back as RATTLE does a bead (Andersen 1983): the positions along the
//! rows' gradients where the substep began, solved by Newton's method to
//! rounding ([`project`]), and the velocity onto the rows' tangent space
//! where it ends ([`project_velocity`]). A motor or friction is one more
//! row of the position step, along the wire, whose multiplier is bounded
//! ([`project_driven`]). Every formula here serves both dimensions: a
//! body is a [`JointBody`] (three coordinates in the plane, six in
//! space) and a wire a [`JointWire`] giving its rows at a body; the rows
//! of each dimension are in `plane` and `space`, the substep's course in
//! `substep`.

use std::fmt::Debug;
use std::ops::{Add, Mul, Neg, Sub};

use bevy::math::DVec3;

use crate::geometry::Coordinates;
use crate::lane::Vector;

#[cfg_attr(not(feature = "avian2d"), allow(dead_code))]
mod plane;
mod rows;
#[cfg_attr(not(feature = "avian3d"), allow(dead_code))]
mod space;
mod substep;

#[cfg_attr(not(feature = "avian2d"), allow(unused_imports))]
pub(crate) use plane::{PlaneBody, PlaneVelocity, PlaneWire, turn_offset};
#[cfg(test)]
use plane::{along_curve, on_curve, past_end, turned_with_curve};
use rows::{Bend, solve};
pub(crate) use rows::{BodyRow, BodyVelocity, Held, Impulse, Rows};
#[cfg_attr(not(feature = "avian3d"), allow(unused_imports))]
pub(crate) use space::{Alignment, SpaceBody, SpaceTurn, SpaceWireAt};
pub use substep::PathMotor;
#[cfg_attr(
    not(any(feature = "avian2d", feature = "avian3d")),
    allow(unused_imports)
)]
pub(crate) use substep::{JointState, Law, Substep, velocity_on_wire};

/// The most rows a joint holds: a body in space has six coordinates.
const MAX_ROWS: usize = 6;

/// The multipliers of a joint's rows, zero past the last row.
pub(crate) type Multipliers = [f64; MAX_ROWS];

/// A change of a body's orientation: an angle in the plane
/// (counter-clockwise), a rotation vector in space (its axis and angle,
/// world frame).
pub(crate) trait Turn:
    Copy
    + Debug
    + Default
    + PartialEq
    + Send
    + Sync
    + Add<Output = Self>
    + Sub<Output = Self>
    + Neg<Output = Self>
    + Mul<f64, Output = Self>
{
    /// `a · b`.
    fn dot(self, other: Self) -> f64;
    /// Whether every component is finite.
    fn finite(self) -> bool;
}

impl Turn for f64 {
    fn dot(self, other: Self) -> f64 {
        self * other
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Turn for DVec3 {
    fn dot(self, other: Self) -> f64 {
        DVec3::dot(self, other)
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
}

/// A rigid body as a joint sees it: where it is, where its anchor is on
/// it, and how hard it is to move ([`PlaneBody`], [`SpaceBody`]).
pub(crate) trait JointBody: Copy + Debug + PartialEq + Send + Sync {
    /// Its position's coordinates: `DVec2` or `DVec3`.
    type V: Coordinates<Angular = Self::Turn>;
    /// A change of its orientation: `f64` or a `DVec3` rotation vector.
    type Turn: Turn;
    /// How many coordinates it has (3 or 6): as many rows fix it.
    const COORDINATES: usize;
    /// The centre of mass, world frame.
    fn centre(&self) -> Self::V;
    /// The anchor, world frame.
    fn anchor(&self) -> Self::V;
    /// `r × d`: the moment about the centre of mass of `d` acting at the
    /// point `r` from it (in the plane, its counter-clockwise part).
    fn moment(r: Self::V, d: Self::V) -> Self::Turn;
    /// `M⁻¹ p` for an impulse `p` through the centre of mass.
    fn inverse_mass(&self, p: Self::V) -> Self::V;
    /// `I⁻¹ τ` for an angular impulse `τ` about the centre of mass.
    fn inverse_inertia(&self, tau: Self::Turn) -> Self::Turn;
    /// The body with its centre moved by `linear` and turned by `turn`.
    fn displaced(&self, linear: Self::V, turn: Self::Turn) -> Self;
    /// The body moved by the generalized impulse `(p, τ)` (an impulse
    /// times the substep): `c + M⁻¹ p`, turned by `I⁻¹ τ`.
    fn moved(&self, (p, tau): (Self::V, Self::Turn)) -> Self {
        self.displaced(self.inverse_mass(p), self.inverse_inertia(tau))
    }
    /// The moment arm of the anchor: `a − c`.
    fn lever(&self) -> Self::V {
        self.anchor() - self.centre()
    }
    /// The point `p` and the direction `d`, fixed to the body where it was
    /// at `was`, where the body's motion from there to here takes them.
    fn carry(&self, was: &Self, p: Self::V, d: Self::V) -> (Self::V, Self::V);
}

/// The angle between two unit vectors, `2 atan2(|a − b|, |a + b|)`,
/// accurate at every angle.
fn angle_between<V: Coordinates>(a: V, b: V) -> f64 {
    let (d, s) = (a - b, a + b);
    2.0 * d.dot(d).sqrt().atan2(s.dot(s).sqrt())
}

/// How much more a wire may turn between two anchors than its curvature
/// at them says before the turn is a sharp corner, rad.
const CORNER_SLACK: f64 = 0.02;

/// Whether the wire turns a sharp corner between the anchor of `from`
/// and that of `to`, each with the rows taken there: its tangent turns
/// between them by more than twice what its curvature at the two turns
/// it over the distance, and [`CORNER_SLACK`] beside. On a smooth wire
/// the tangent turns by the curvature times the distance, to second
/// order. On a wire that rides a body, the tangent and the anchor are
/// compared in the carrier's frame, so the carrier's own turn is none of
/// the wire's.
pub(crate) fn turns_a_corner<B: JointBody>(
    (from, at_from): (&Held<B>, &Rows<B>),
    (to, at_to): (&Held<B>, &Rows<B>),
) -> bool {
    let (a, b) = (at_from.bend, at_to.bend);
    let (anchor, tangent) = match (from.carrier, to.carrier) {
        (Some(was), Some(now)) => now.carry(&was, from.body.anchor(), a.tangent),
        _ => (from.body.anchor(), a.tangent),
    };
    let turn = angle_between(tangent, b.tangent);
    let moved = to.body.anchor() - anchor;
    let bend = (a.curvature + b.curvature) * moved.dot(moved).sqrt();
    turn > bend + CORNER_SLACK
}

/// A wire as a joint holds a body on it, where the wire is at one
/// instant: the rows it holds, its end, its own direction.
pub(crate) trait JointWire<B: JointBody>: Sized {
    /// The wire where it is while it rides `carrier` (its place then in
    /// the carrier's frame, from the carrier's origin); itself where it
    /// rides nothing.
    fn carried_by(&self, carrier: Option<&B>) -> Self;
    /// The rows the joint holds at `body`: its anchor on the wire and,
    /// as the joint asks, its orientation turned with it. `None` at a
    /// singular point.
    fn held(&self, body: &B) -> Option<Rows<B>>;
    /// How far past an end of an open wire the anchor is along the end's
    /// tangent (zero or less between the ends), as a row whose gradient
    /// points out past that end; `None` for a wire with no end, or at a
    /// singular point.
    fn past_end(&self, body: &B) -> Option<BodyRow<B>>;
    /// The anchor's motion along the wire's own direction (a line's +x, a
    /// circle counter-clockwise, a spline's parameter) as a row of value
    /// zero: the unit tangent at the anchor along the centre, its moment
    /// along the orientation. `None` at a singular point.
    fn along(&self, body: &B) -> Option<BodyRow<B>>;
    /// The wire's point `local` (its own frame) in the world.
    fn to_world(&self, local: B::V) -> B::V;
    /// The wire's characteristic length: tolerances scale with it.
    fn scale(&self) -> f64;
    /// The rows the joint holds at the bodies `at`, the wire where their
    /// carrier has it (see [`JointWire::held`]).
    #[inline]
    fn held_at(&self, at: &Held<B>) -> Option<Rows<B>> {
        self.on(at.carrier.as_ref(), |wire| {
            let mut rows = wire.held(&at.body)?;
            rows.ride(at);
            Some(rows)
        })
    }
    /// `f` of the wire where `carrier` has it: of the wire itself, not
    /// copied, where it rides nothing.
    #[inline]
    fn on<T>(&self, carrier: Option<&B>, f: impl FnOnce(&Self) -> T) -> T {
        match carrier {
            Some(_) => f(&self.carried_by(carrier)),
            None => f(self),
        }
    }
}

/// What [`project`] found: the body on its rows, the multipliers that put
/// it there (`λ`, an impulse times the substep) and whether Newton's
/// method met the tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Projected<B: JointBody> {
    /// The body (and the carrier) moved onto its rows.
    pub body: Held<B>,
    /// `λ`, one per row.
    pub lambda: Multipliers,
    /// The generalized impulse `Gᵀ λ` that moved it, and the carrier's
    /// (times the substep).
    pub impulse: Held<Impulse<B>>,
    /// The rows where the body is, unless that is a singular point.
    pub rows: Option<Rows<B>>,
    /// Whether every row met the tolerance.
    pub converged: bool,
}

/// The most Newton steps [`project`] takes.
const PROJECTION_STEPS: usize = 16;

/// The largest of `|Cᵢ + α̃ λᵢ|`.
fn residual<B: JointBody>(rows: &Rows<B>, compliance: f64, lambda: &Multipliers) -> Multipliers {
    let values = rows.values();
    std::array::from_fn(|i| values[i] + compliance * lambda[i])
}

/// The largest magnitude in `r`.
fn largest(r: &Multipliers) -> f64 {
    r.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// SHAKE's position step for a body the substep moved freely to
/// `predicted`: the multipliers `λ` such that the body moved along the
/// rows' gradients where the substep began, `q = q̃ + M⁻¹ Gᵀ λ` (`G` the
/// rows of `start`; in space the turn applied to the predicted
/// orientation), meets its rows `C(q) + α̃ λ = 0` (`rows_at` gives them,
/// the same rows in the same order; `compliance` is `α̃ = α / h²`), by
/// Newton's method to `tolerance`. Where the wire rides a carrier, the
/// carrier moves too, by its own part of `Gᵀ λ`. `None` where a row is
/// singular or the step is not finite.
pub(crate) fn project<B: JointBody>(
    start: &Rows<B>,
    predicted: Held<B>,
    compliance: f64,
    tolerance: f64,
    rows_at: impl Fn(&Held<B>) -> Option<Rows<B>>,
) -> Option<Projected<B>> {
    let mut lambda = [0.0; MAX_ROWS];
    let mut body = predicted;
    for _ in 0..PROJECTION_STEPS {
        let rows = rows_at(&body)?;
        let r = residual(&rows, compliance, &lambda);
        if largest(&r) <= tolerance {
            return Some(Projected {
                body,
                lambda,
                impulse: start.impulse(&lambda),
                rows: Some(rows),
                converged: true,
            });
        }
        let step = solve(
            rows.matrix(start, &body, compliance),
            r.map(|v| -v),
            rows.len(),
        )?;
        for (l, s) in lambda.iter_mut().zip(step) {
            *l += s;
        }
        body = predicted.moved(start, &lambda);
    }
    let rows = rows_at(&body);
    let converged =
        rows.is_some_and(|rows| largest(&residual(&rows, compliance, &lambda)) <= tolerance);
    Some(Projected {
        body,
        lambda,
        impulse: start.impulse(&lambda),
        rows,
        converged,
    })
}

/// RATTLE's velocity step: the velocities `v` less the part along the
/// rows' gradients that moves them against the wire's own motion `frame`
/// (the velocity the body would have riding rigidly with a wire that
/// moves as the game moves it, along which every row is unchanged; zero
/// for a wire that rides a carrier, whose velocity is in `v`),
/// `v − M⁻¹ Jᵀ (J M⁻¹ Jᵀ)⁻¹ J (v − frame)`; and the generalized impulses
/// that took it off. `None` where the rows are singular.
pub(crate) fn project_velocity<B: JointBody>(
    rows: &Rows<B>,
    bodies: &Held<B>,
    v: Held<BodyVelocity<B>>,
    frame: BodyVelocity<B>,
) -> Option<(Held<BodyVelocity<B>>, Held<Impulse<B>>)> {
    if rows.len() == 0 {
        return Some((v, rows.impulse(&[0.0; MAX_ROWS])));
    }
    let (now, riding) = (rows.rates(&v), rows.rates(&Held::alone(frame)));
    let excess: Multipliers = std::array::from_fn(|i| riding[i] - now[i]);
    let lambda = solve(rows.matrix(rows, bodies, 0.0), excess, rows.len())?;
    let impulse = rows.impulse(&lambda);
    Some((v.kicked(bodies, &impulse), impulse))
}

/// A motor (or friction: a motor holding the anchor where it is on the
/// wire) as one more row of the position step: the anchor's displacement
/// over the substep along the wire's direction `direction` where it began
/// (from `from`) brought to `shift`, by a multiplier of at most `bound`
/// either way (the force limit times the substep squared). On a wire that
/// rides a body, `direction` and `from` are fixed to the carrier as it was
/// where the substep began, and move with it: the displacement is the
/// anchor's against the wire.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Drive<B: JointBody> {
    /// The wire's unit tangent where the substep began, its own way.
    pub direction: B::V,
    /// The anchor where the substep began.
    pub from: B::V,
    /// The displacement along `direction` the drive asks for, m.
    pub shift: f64,
    /// The largest multiplier it gives, `F h²`.
    pub bound: f64,
    /// The carrier of the wire where the substep began, if any.
    pub carrier: Option<B>,
}

impl<B: JointBody> Drive<B> {
    /// The drive's row at `at`: `d · (a − from) − shift`, `d` and `from`
    /// carried with the carrier to where it is.
    pub fn row(&self, at: &Held<B>) -> BodyRow<B> {
        let (from, direction) = match (self.carrier, at.carrier) {
            (Some(was), Some(now)) => now.carry(&was, self.from, self.direction),
            _ => (self.from, self.direction),
        };
        let body = &at.body;
        let value = direction.dot(body.anchor() - from) - self.shift;
        BodyRow::at_anchor(body, value, direction)
    }
}

/// [`project`] with a drive: the rows and the drive met together where
/// the drive's multiplier is within its bound; where it is not, the drive
/// gives its bound (the body moved by it from `predicted` along its
/// gradient at `previous`, where the substep began) and the rows are met
/// beside it. The projection (its impulse the drive's and the rows'
/// together) and the drive's multiplier.
pub(crate) fn project_driven<B: JointBody>(
    start: &Rows<B>,
    previous: &Held<B>,
    drive: &Drive<B>,
    predicted: Held<B>,
    compliance: f64,
    tolerance: f64,
    rows_at: impl Fn(&Held<B>) -> Option<Rows<B>>,
) -> Option<(Projected<B>, f64)> {
    if start.len() >= B::COORDINATES {
        // Held in every coordinate: nothing left to drive.
        return Some((
            project(start, predicted, compliance, tolerance, rows_at)?,
            0.0,
        ));
    }
    let mut both = *start;
    both.push(drive.row(previous));
    let last = start.len();
    let together = project(&both, predicted, compliance, tolerance, |b| {
        let mut rows = rows_at(b)?;
        rows.push(drive.row(b));
        Some(rows)
    })?;
    let multiplier = together.lambda[last];
    if multiplier.abs() <= drive.bound {
        return Some((together, multiplier));
    }
    let bounded = multiplier.clamp(-drive.bound, drive.bound);
    // The drive alone, carried to the carrier as the rows are.
    let mut alone = Rows {
        carrier: start.carrier,
        ..Rows::default()
    };
    alone.push(drive.row(previous));
    let mut lambda = [0.0; MAX_ROWS];
    lambda[0] = bounded;
    let pushing = alone.impulse(&lambda);
    let mut beside = project(
        start,
        predicted.moved(&alone, &lambda),
        compliance,
        tolerance,
        rows_at,
    )?;
    let add = |(p, tau): Impulse<B>, (q, sigma): Impulse<B>| (p + q, tau + sigma);
    beside.impulse = Held {
        body: add(beside.impulse.body, pushing.body),
        carrier: match (beside.impulse.carrier, pushing.carrier) {
            (Some(a), Some(b)) => Some(add(a, b)),
            (a, _) => a,
        },
    };
    Some((beside, bounded))
}

#[cfg(test)]
mod tests;
