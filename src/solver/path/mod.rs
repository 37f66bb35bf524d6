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
#[cfg_attr(not(feature = "avian3d"), allow(dead_code))]
mod space;
mod substep;

#[cfg_attr(not(feature = "avian2d"), allow(unused_imports))]
pub(crate) use plane::{PlaneBody, PlaneVelocity, PlaneWire, turn_offset};
#[cfg(test)]
use plane::{along_curve, on_curve, past_end, turned_with_curve};
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
    type V: Coordinates;
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
}

/// A body's velocity: its centre's, and its spin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BodyVelocity<B: JointBody> {
    /// `ċ`.
    pub linear: B::V,
    /// `ω` (`θ̇` in the plane).
    pub spin: B::Turn,
}

impl<B: JointBody> Default for BodyVelocity<B> {
    fn default() -> Self {
        Self {
            linear: B::V::ZERO,
            spin: B::Turn::default(),
        }
    }
}

impl<B: JointBody> BodyVelocity<B> {
    /// The velocity changed by the generalized impulse `(p, τ)`.
    fn kicked(self, body: &B, (p, tau): (B::V, B::Turn)) -> Self {
        Self {
            linear: self.linear + body.inverse_mass(p),
            spin: self.spin + body.inverse_inertia(tau),
        }
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.linear.is_finite() && self.spin.finite()
    }
}

/// One row of a body's constraint: its value and its gradient with
/// respect to the centre of mass and the orientation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BodyRow<B: JointBody> {
    /// `C`.
    pub value: f64,
    /// `∂C/∂c`.
    pub along_centre: B::V,
    /// `∂C/∂θ` (in space, for a rotation vector `δθ` applied on the left).
    pub along_angle: B::Turn,
}

impl<B: JointBody> Default for BodyRow<B> {
    fn default() -> Self {
        Self {
            value: 0.0,
            along_centre: B::V::ZERO,
            along_angle: B::Turn::default(),
        }
    }
}

impl<B: JointBody> BodyRow<B> {
    /// A row of value `value` whose gradient is the direction `d` at the
    /// anchor of `body`: `∂C/∂c = d`, `∂C/∂θ = (a − c) × d`.
    pub fn at_anchor(body: &B, value: f64, d: B::V) -> Self {
        Self {
            value,
            along_centre: d,
            along_angle: B::moment(body.lever(), d),
        }
    }

    /// `Ċ = J q̇` at the velocity `v`.
    pub fn rate(&self, v: BodyVelocity<B>) -> f64 {
        self.along_centre.dot(v.linear) + self.along_angle.dot(v.spin)
    }

    /// `Jᵢ M⁻¹ Jⱼᵀ`: how far this row moves as `other`'s multiplier does.
    fn coupling(&self, other: &Self, body: &B) -> f64 {
        self.along_centre.dot(body.inverse_mass(other.along_centre))
            + self
                .along_angle
                .dot(body.inverse_inertia(other.along_angle))
    }
}

/// The rows of one joint, at most as many as the body has coordinates;
/// and how the wire bends at the anchor they were taken at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rows<B: JointBody> {
    rows: [BodyRow<B>; MAX_ROWS],
    len: usize,
    bend: Bend<B::V>,
}

/// How a wire bends at an anchor: its unit tangent there and how fast
/// that turns along it (the curvature), for [`turns_a_corner`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Bend<V> {
    /// The unit tangent.
    pub tangent: V,
    /// The curvature, 1/m.
    pub curvature: f64,
}

impl<B: JointBody> Default for Rows<B> {
    fn default() -> Self {
        Self {
            rows: [BodyRow::default(); MAX_ROWS],
            len: 0,
            bend: Bend {
                tangent: B::V::ZERO,
                curvature: 0.0,
            },
        }
    }
}

impl<B: JointBody> Rows<B> {
    /// No rows yet, on a wire that bends as `bend` says.
    pub fn bending(bend: Bend<B::V>) -> Self {
        Self {
            bend,
            ..Self::default()
        }
    }

    /// Adds `row`; a row past the body's coordinates is dropped (they
    /// fix it already).
    pub fn push(&mut self, row: BodyRow<B>) {
        if self.len < B::COORDINATES {
            self.rows[self.len] = row;
            self.len += 1;
        }
    }

    /// How many rows there are.
    pub fn len(&self) -> usize {
        self.len
    }

    /// The rows.
    pub fn iter(&self) -> impl Iterator<Item = &BodyRow<B>> {
        self.rows[..self.len].iter()
    }

    /// The rows' values, zero past the last.
    fn values(&self) -> Multipliers {
        std::array::from_fn(|i| {
            if i < self.len {
                self.rows[i].value
            } else {
                0.0
            }
        })
    }

    /// `J q̇` at `v`, zero past the last row.
    fn rates(&self, v: BodyVelocity<B>) -> Multipliers {
        std::array::from_fn(|i| {
            if i < self.len {
                self.rows[i].rate(v)
            } else {
                0.0
            }
        })
    }

    /// `Gᵀ λ`: the generalized impulse of the multipliers `lambda` along
    /// the rows.
    pub fn impulse(&self, lambda: &Multipliers) -> (B::V, B::Turn) {
        self.iter()
            .zip(lambda)
            .fold((B::V::ZERO, B::Turn::default()), |(p, tau), (row, &l)| {
                (p + row.along_centre * l, tau + row.along_angle * l)
            })
    }

    /// `A = J M⁻¹ Gᵀ` for the rows `J` (self) and `G` (`along`), with
    /// `compliance` added to the diagonal.
    fn matrix(&self, along: &Self, body: &B, compliance: f64) -> Matrix {
        let mut a = [[0.0; MAX_ROWS]; MAX_ROWS];
        for (i, row) in self.iter().enumerate() {
            for (j, other) in along.iter().enumerate() {
                a[i][j] = row.coupling(other, body) + if i == j { compliance } else { 0.0 };
            }
        }
        a
    }
}

/// A square matrix of rows, row-major.
type Matrix = [[f64; MAX_ROWS]; MAX_ROWS];

/// `A x = b` for the leading `n` rows and columns of `A` (the rest
/// ignored, zero in `x`), by Gauss elimination with partial pivoting; or
/// `None` where they are singular (a pivot at most 1e-13 of `A`'s largest
/// entry) or the answer not finite. The matrix `J M⁻¹ Gᵀ` of SHAKE's step
/// is not symmetric, so it takes no Cholesky factor.
fn solve(mut a: Matrix, b: Multipliers, n: usize) -> Option<Multipliers> {
    let mut x = b;
    let size = a[..n]
        .iter()
        .flat_map(|row| row[..n].iter())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    for k in 0..n {
        let pivot = (k..n).max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))?;
        if a[pivot][k].is_nan() || a[pivot][k].abs() <= 1e-13 * size {
            return None;
        }
        a.swap(k, pivot);
        x.swap(k, pivot);
        let (above, below) = a.split_at_mut(k + 1);
        let pivot_row = &above[k];
        for (i, row) in below[..n - k - 1].iter_mut().enumerate() {
            let factor = row[k] / pivot_row[k];
            for (entry, &p) in row[k..n].iter_mut().zip(&pivot_row[k..n]) {
                *entry -= factor * p;
            }
            x[k + 1 + i] -= factor * x[k];
        }
    }
    for k in (0..n).rev() {
        let sum: f64 = (k + 1..n).map(|j| a[k][j] * x[j]).sum();
        x[k] = (x[k] - sum) / a[k][k];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
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
/// order.
pub(crate) fn turns_a_corner<B: JointBody>(
    (from, at_from): (&B, &Rows<B>),
    (to, at_to): (&B, &Rows<B>),
) -> bool {
    let (a, b) = (at_from.bend, at_to.bend);
    let turn = angle_between(a.tangent, b.tangent);
    let moved = to.anchor() - from.anchor();
    let bend = (a.curvature + b.curvature) * moved.dot(moved).sqrt();
    turn > bend + CORNER_SLACK
}

/// A wire as a joint holds a body on it, where the wire is at one
/// instant: the rows it holds, its end, its own direction.
pub(crate) trait JointWire<B: JointBody> {
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
}

/// What [`project`] found: the body on its rows, the multipliers that put
/// it there (`λ`, an impulse times the substep) and whether Newton's
/// method met the tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Projected<B: JointBody> {
    /// The body moved onto its rows.
    pub body: B,
    /// `λ`, one per row.
    pub lambda: Multipliers,
    /// The generalized impulse `Gᵀ λ` that moved it (times the substep).
    pub impulse: (B::V, B::Turn),
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
/// Newton's method to `tolerance`. `None` where a row is singular or the
/// step is not finite.
pub(crate) fn project<B: JointBody>(
    start: &Rows<B>,
    predicted: B,
    compliance: f64,
    tolerance: f64,
    rows_at: impl Fn(&B) -> Option<Rows<B>>,
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
        body = predicted.moved(start.impulse(&lambda));
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

/// RATTLE's velocity step: the velocity `v` less the part along the rows'
/// gradients that moves them against the wire's own motion `frame` (the
/// velocity the body would have riding rigidly with the wire, along which
/// every row is unchanged), `v − M⁻¹ Jᵀ (J M⁻¹ Jᵀ)⁻¹ J (v − frame)`; and
/// the generalized impulse that took it off. `None` where the rows are
/// singular.
pub(crate) fn project_velocity<B: JointBody>(
    rows: &Rows<B>,
    body: &B,
    v: BodyVelocity<B>,
    frame: BodyVelocity<B>,
) -> Option<(BodyVelocity<B>, (B::V, B::Turn))> {
    if rows.len() == 0 {
        return Some((v, (B::V::ZERO, B::Turn::default())));
    }
    let (now, riding) = (rows.rates(v), rows.rates(frame));
    let excess: Multipliers = std::array::from_fn(|i| riding[i] - now[i]);
    let lambda = solve(rows.matrix(rows, body, 0.0), excess, rows.len())?;
    let impulse = rows.impulse(&lambda);
    Some((v.kicked(body, impulse), impulse))
}

/// A motor (or friction: a motor holding the anchor where it is on the
/// wire) as one more row of the position step: the anchor's displacement
/// over the substep along the wire's direction `direction` where it began
/// (from `from`) brought to `shift`, by a multiplier of at most `bound`
/// either way (the force limit times the substep squared).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Drive<V> {
    /// The wire's unit tangent where the substep began, its own way.
    pub direction: V,
    /// The anchor where the substep began.
    pub from: V,
    /// The displacement along `direction` the drive asks for, m.
    pub shift: f64,
    /// The largest multiplier it gives, `F h²`.
    pub bound: f64,
}

impl<V: Coordinates> Drive<V> {
    /// The drive's row at `body`: `d · (a − from) − shift`.
    pub fn row<B: JointBody<V = V>>(&self, body: &B) -> BodyRow<B> {
        let value = self.direction.dot(body.anchor() - self.from) - self.shift;
        BodyRow::at_anchor(body, value, self.direction)
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
    previous: &B,
    drive: &Drive<B::V>,
    predicted: B,
    compliance: f64,
    tolerance: f64,
    rows_at: impl Fn(&B) -> Option<Rows<B>>,
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
    let mut alone = Rows::default();
    alone.push(drive.row(previous));
    let mut lambda = [0.0; MAX_ROWS];
    lambda[0] = bounded;
    let pushing = alone.impulse(&lambda);
    let mut beside = project(
        start,
        predicted.moved(pushing),
        compliance,
        tolerance,
        rows_at,
    )?;
    beside.impulse = (beside.impulse.0 + pushing.0, beside.impulse.1 + pushing.1);
    Some((beside, bounded))
}

#[cfg(test)]
mod tests;
