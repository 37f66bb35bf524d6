//! A rigid body held on a wire by a point of its own (a path joint), in
//! the plane, as pure functions of the body's state (docs/method.md,
//! "Rigid bodies on wires"). The body's centre of mass `c` and angle `θ`
//! are its coordinates `q`; its anchor `a = c + R(θ) r` (`r` the anchor's
//! arm from the centre of mass in the body's frame) is held on the curve,
//! and where the body turns with the wire, `θ` is held at the wire's
//! direction at the anchor plus the offset it had when the joint began.
//!
//! A physics engine's substep moves the body freely; the joint then puts
//! it back as RATTLE does a bead (Andersen 1983): the positions along the
//! rows' gradients where the substep began, solved by Newton's method to
//! rounding ([`project`]), and the velocity onto the rows' tangent space
//! where it ends ([`project_velocity`]). A motor or friction is one more
//! row of the position step, along the wire, whose multiplier is bounded
//! ([`project_driven`]).

use bevy::math::{DMat3, DVec2, DVec3};

use crate::geometry::ImplicitCurve;

/// A rigid body in the plane as the joint sees it: where it is, where its
/// anchor is on it, and how hard it is to move.
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

impl PlaneBody {
    /// The anchor, world frame.
    pub fn anchor(&self) -> DVec2 {
        if self.arm == DVec2::ZERO {
            // Held at its centre of mass, as a cart often is: no turn to take.
            return self.centre;
        }
        self.centre + DVec2::from_angle(self.angle).rotate(self.arm)
    }

    /// The body moved by the multipliers `lambda` along `rows`:
    /// `c + W Σ λᵢ ∂Cᵢ/∂c`, `θ + Σ λᵢ ∂Cᵢ/∂θ / I`.
    pub fn moved(&self, rows: &Rows, lambda: DVec3) -> PlaneBody {
        let mut body = *self;
        for (row, l) in rows.iter().zip(lambda.to_array()) {
            body.centre += row.along_centre * self.inverse_mass * l;
            body.angle += row.along_angle * self.inverse_inertia * l;
        }
        body
    }
}

/// A body's velocity: its centre's, and its spin (counter-clockwise).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct PlaneVelocity {
    /// `ċ`.
    pub linear: DVec2,
    /// `θ̇`.
    pub spin: f64,
}

impl PlaneVelocity {
    /// The velocity changed by the impulses `impulse` along `rows`.
    fn kicked(self, body: &PlaneBody, rows: &Rows, impulse: DVec3) -> PlaneVelocity {
        let mut v = self;
        for (row, i) in rows.iter().zip(impulse.to_array()) {
            v.linear += row.along_centre * body.inverse_mass * i;
            v.spin += row.along_angle * body.inverse_inertia * i;
        }
        v
    }
}

/// One row of a body's constraint: its value and its gradient with
/// respect to the centre of mass and the angle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct BodyRow {
    /// `C`.
    pub value: f64,
    /// `∂C/∂c`.
    pub along_centre: DVec2,
    /// `∂C/∂θ`.
    pub along_angle: f64,
}

impl BodyRow {
    /// `Ċ = J q̇` at the velocity `v`.
    pub fn rate(&self, v: PlaneVelocity) -> f64 {
        self.along_centre.dot(v.linear) + self.along_angle * v.spin
    }

    /// `Jᵢ M⁻¹ Jⱼᵀ`: how far this row moves as `other`'s multiplier does.
    fn coupling(&self, other: &BodyRow, body: &PlaneBody) -> f64 {
        (self.along_centre * body.inverse_mass).dot(other.along_centre)
            + self.along_angle * other.along_angle * body.inverse_inertia
    }
}

/// The rows of one joint: at most three, a body in the plane having three
/// coordinates; and how the wire bends at the anchor they were taken at.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Rows {
    rows: [BodyRow; 3],
    len: usize,
    bend: Bend,
}

/// How a wire bends at an anchor: its unit normal there and how fast
/// that turns along it (`|∇ψ|`, the curvature), for [`turns_a_corner`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Bend {
    normal: DVec2,
    curvature: f64,
}

impl Rows {
    /// Adds `row`; a fourth row is dropped (three fix the body).
    pub fn push(&mut self, row: BodyRow) {
        if self.len < 3 {
            self.rows[self.len] = row;
            self.len += 1;
        }
    }

    /// How many rows there are.
    pub fn len(&self) -> usize {
        self.len
    }

    /// The rows.
    pub fn iter(&self) -> impl Iterator<Item = &BodyRow> {
        self.rows[..self.len].iter()
    }

    /// The rows' values, zero past the last.
    fn values(&self) -> DVec3 {
        DVec3::from_array(std::array::from_fn(|i| {
            if i < self.len {
                self.rows[i].value
            } else {
                0.0
            }
        }))
    }

    /// `J q̇` at `v`, zero past the last row.
    fn rates(&self, v: PlaneVelocity) -> DVec3 {
        DVec3::from_array(std::array::from_fn(|i| {
            if i < self.len {
                self.rows[i].rate(v)
            } else {
                0.0
            }
        }))
    }

    /// `A = J M⁻¹ Gᵀ` for the rows `J` (self) and `G` (`along`), with
    /// `compliance` added to the diagonal and ones where no row is.
    fn matrix(&self, along: &Rows, body: &PlaneBody, compliance: f64) -> DMat3 {
        let column = |j: usize| {
            DVec3::from_array(std::array::from_fn(|i| {
                match (i < self.len, j < along.len) {
                    (true, true) => {
                        self.rows[i].coupling(&along.rows[j], body)
                            + if i == j { compliance } else { 0.0 }
                    }
                    _ if i == j => 1.0,
                    _ => 0.0,
                }
            }))
        };
        DMat3::from_cols(column(0), column(1), column(2))
    }
}

/// `A x = b` for the leading `n` rows and columns of `A` (the rest
/// ignored, zero in `x`), or `None` where they are singular or the answer
/// not finite.
fn solve(a: DMat3, b: DVec3, n: usize) -> Option<DVec3> {
    let x = match n {
        0 => DVec3::ZERO,
        1 => DVec3::new(b.x / a.x_axis.x, 0.0, 0.0),
        2 => {
            let (p, q, r, t) = (a.x_axis.x, a.y_axis.x, a.x_axis.y, a.y_axis.y);
            let det = p * t - q * r;
            let size = p.abs().max(q.abs()).max(r.abs()).max(t.abs());
            if det.is_nan() || det.abs() <= 1e-13 * size * size {
                return None;
            }
            DVec3::new((b.x * t - q * b.y) / det, (p * b.y - r * b.x) / det, 0.0)
        }
        _ => {
            let det = a.determinant();
            let size = a.to_cols_array().iter().fold(0.0f64, |m, x| m.max(x.abs()));
            if det.is_nan() || det.abs() <= 1e-13 * size * size * size {
                return None;
            }
            a.inverse() * b
        }
    };
    x.is_finite().then_some(x)
}

/// `v` turned a quarter counter-clockwise.
fn perp(v: DVec2) -> DVec2 {
    DVec2::new(-v.y, v.x)
}

/// The curve's unit normal at `p`, or `None` at a singular point.
fn unit_normal(curve: &impl ImplicitCurve, p: DVec2) -> Option<(f64, DVec2)> {
    let geometry = curve.geometry(p);
    let length = geometry.normal.length();
    (length > 0.0 && length.is_finite() && geometry.c.is_finite())
        .then(|| (geometry.c / length, geometry.normal / length))
}

/// The curve at a body's anchor, evaluated once for every row that needs
/// it: the anchor, its arm turned a quarter (`(a − c)⊥`), the distance
/// `C / |∇C|`, the unit normal and `∇ψ = H t / |∇C|`, the gradient of the
/// tangent's angle `ψ` (see [`turned_with_curve`]).
struct AtAnchor {
    lever: DVec2,
    distance: f64,
    normal: DVec2,
    turn_gradient: DVec2,
}

impl AtAnchor {
    /// `None` at a singular point.
    fn new(curve: &impl ImplicitCurve, body: &PlaneBody) -> Option<Self> {
        let anchor = body.anchor();
        let geometry = curve.geometry(anchor);
        let length = geometry.normal.length();
        if !(length > 0.0 && length.is_finite() && geometry.c.is_finite()) {
            return None;
        }
        let normal = geometry.normal / length;
        // The tangent turns as the normal does: dψ = N⊥ · dN / |N|² with
        // dN = H dx, so ∇ψ = H N⊥ / |N|² = H t / |N|.
        Some(Self {
            lever: perp(anchor - body.centre),
            distance: geometry.c / length,
            normal,
            turn_gradient: geometry.hessian * perp(normal) / length,
        })
    }

    /// The on-the-curve row (see [`on_curve`]).
    fn on_curve(&self) -> BodyRow {
        BodyRow {
            value: self.distance,
            along_centre: self.normal,
            along_angle: self.normal.dot(self.lever),
        }
    }

    /// The turned-with-the-curve row (see [`turned_with_curve`]).
    fn turned(&self, angle: f64, offset: f64) -> BodyRow {
        let tangent = perp(self.normal);
        // ψ depends on the anchor, which moves with the centre and turns
        // about it: ∂a/∂c = I, ∂a/∂θ = (a − c)⊥.
        BodyRow {
            value: wrap(angle - tangent.y.atan2(tangent.x) - offset),
            along_centre: -self.turn_gradient,
            along_angle: 1.0 - self.turn_gradient.dot(self.lever),
        }
    }
}

/// The anchor's distance from the curve to first order, `C(a) / |∇C(a)|`
/// (zero exactly on the curve), as a row of the body: its gradient is the
/// curve's unit normal at the anchor along the centre, and that normal's
/// moment about the centre along the angle. `None` at a singular point.
#[cfg(test)]
pub(crate) fn on_curve(curve: &impl ImplicitCurve, body: &PlaneBody) -> Option<BodyRow> {
    Some(AtAnchor::new(curve, body)?.on_curve())
}

/// The rows a joint holds at `body`, the curve evaluated once: the anchor
/// on the curve and, where `offset` is given, the body's angle turned
/// with it (see [`turned_with_curve`]). `None` at a singular point.
pub(crate) fn held(
    curve: &impl ImplicitCurve,
    body: &PlaneBody,
    offset: Option<f64>,
) -> Option<Rows> {
    let at = AtAnchor::new(curve, body)?;
    let mut rows = Rows {
        bend: Bend {
            normal: at.normal,
            curvature: at.turn_gradient.length(),
        },
        ..Rows::default()
    };
    rows.push(at.on_curve());
    if let Some(offset) = offset {
        rows.push(at.turned(body.angle, offset));
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
) -> Option<BodyRow> {
    let anchor = body.anchor();
    let (_, normal) = unit_normal(curve, anchor)?;
    let tangent = travel * perp(normal);
    Some(BodyRow {
        value: 0.0,
        along_centre: tangent,
        along_angle: tangent.dot(perp(anchor - body.centre)),
    })
}

/// How far past an end of an open curve the anchor is, along the end's
/// tangent (zero or less: on the curve between its ends), as a row of
/// the body whose gradient points out past that end. `None` for a curve
/// with no end, or at a singular point.
pub(crate) fn past_end(curve: &impl ImplicitCurve, body: &PlaneBody) -> Option<BodyRow> {
    if !curve.has_ends() {
        return None;
    }
    let anchor = body.anchor();
    let value = curve.past_end(anchor);
    let (_, normal) = unit_normal(curve, anchor)?;
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
    value.is_finite().then(|| BodyRow {
        value,
        along_centre: out,
        along_angle: out.dot(perp(anchor - body.centre)),
    })
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
) -> Option<BodyRow> {
    Some(AtAnchor::new(curve, body)?.turned(body.angle, offset))
}

/// The tangent angle at the anchor that a body turned with the curve keeps
/// its own angle from: `θ − ψ`, wrapped. `None` at a singular point.
pub(crate) fn turn_offset(curve: &impl ImplicitCurve, body: &PlaneBody) -> Option<f64> {
    Some(AtAnchor::new(curve, body)?.turned(body.angle, 0.0).value)
}

/// `angle` wrapped into `(−π, π]`.
fn wrap(angle: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let wrapped = angle.rem_euclid(TAU);
    if wrapped > PI { wrapped - TAU } else { wrapped }
}

/// How much more a wire may turn between two anchors than its curvature
/// at them says before the turn is a sharp corner, rad.
const CORNER_SLACK: f64 = 0.02;

/// Whether the wire turns a sharp corner between the anchor of `from`
/// and that of `to`, each with the rows ([`held`]) taken there: its
/// normal turns between them by more than twice what its curvature at the
/// two (`|∇ψ|`) turns it over the distance, and [`CORNER_SLACK`] beside.
/// On a smooth wire the normal turns by the curvature times the distance,
/// to second order.
pub(crate) fn turns_a_corner(
    (from, at_from): (&PlaneBody, &Rows),
    (to, at_to): (&PlaneBody, &Rows),
) -> bool {
    let (a, b) = (at_from.bend, at_to.bend);
    let turn = a.normal.angle_to(b.normal).abs();
    let bend = (a.curvature + b.curvature) * (to.anchor() - from.anchor()).length();
    turn > bend + CORNER_SLACK
}

/// What [`project`] found: the body on its rows, the multipliers that put
/// it there (`λ`, an impulse times the substep) and whether Newton's
/// method met the tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Projected {
    /// The body moved onto its rows.
    pub body: PlaneBody,
    /// `λ`, one per row.
    pub lambda: DVec3,
    /// The rows where the body is, unless that is a singular point.
    pub rows: Option<Rows>,
    /// Whether every row met the tolerance.
    pub converged: bool,
}

/// The most Newton steps [`project`] takes.
const PROJECTION_STEPS: usize = 16;

/// SHAKE's position step for a body the substep moved freely to
/// `predicted`: the multipliers `λ` such that the body moved along the
/// rows' gradients where the substep began, `q = q̃ + M⁻¹ Gᵀ λ` (`G` the
/// rows of `start`), meets its rows `C(q) + α̃ λ = 0` (`rows_at` gives
/// them, the same rows in the same order; `compliance` is `α̃ = α / h²`),
/// by Newton's method to `tolerance`. `None` where a row is singular or
/// the step is not finite.
pub(crate) fn project(
    start: &Rows,
    predicted: PlaneBody,
    compliance: f64,
    tolerance: f64,
    rows_at: impl Fn(&PlaneBody) -> Option<Rows>,
) -> Option<Projected> {
    let mut lambda = DVec3::ZERO;
    let mut body = predicted;
    for _ in 0..PROJECTION_STEPS {
        let rows = rows_at(&body)?;
        let residual = rows.values() + compliance * lambda;
        if residual.abs().max_element() <= tolerance {
            return Some(Projected {
                body,
                lambda,
                rows: Some(rows),
                converged: true,
            });
        }
        lambda += solve(rows.matrix(start, &body, compliance), -residual, rows.len())?;
        body = predicted.moved(start, lambda);
    }
    let rows = rows_at(&body);
    let converged = rows
        .is_some_and(|rows| (rows.values() + compliance * lambda).abs().max_element() <= tolerance);
    Some(Projected {
        body,
        lambda,
        rows,
        converged,
    })
}

/// RATTLE's velocity step: the velocity `v` less the part along the rows'
/// gradients that moves them against the wire's own motion `frame` (the
/// velocity the body would have riding rigidly with the wire, along which
/// every row is unchanged), `v − M⁻¹ Jᵀ (J M⁻¹ Jᵀ)⁻¹ J (v − frame)`; and
/// the impulses that took it off. `None` where the rows are singular.
pub(crate) fn project_velocity(
    rows: &Rows,
    body: &PlaneBody,
    v: PlaneVelocity,
    frame: PlaneVelocity,
) -> Option<(PlaneVelocity, DVec3)> {
    if rows.len() == 0 {
        return Some((v, DVec3::ZERO));
    }
    let excess = rows.rates(v) - rows.rates(frame);
    let impulse = solve(rows.matrix(rows, body, 0.0), -excess, rows.len())?;
    Some((v.kicked(body, rows, impulse), impulse))
}

/// A motor (or friction: a motor holding the anchor where it is on the
/// wire) as one more row of the position step: the anchor's displacement
/// over the substep along the wire's direction `direction` where it began
/// (from `from`) brought to `shift`, by a multiplier of at most `bound`
/// either way (the force limit times the substep squared).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Drive {
    /// The wire's unit tangent where the substep began, its own way.
    pub direction: DVec2,
    /// The anchor where the substep began.
    pub from: DVec2,
    /// The displacement along `direction` the drive asks for, m.
    pub shift: f64,
    /// The largest multiplier it gives, `F h²`.
    pub bound: f64,
}

impl Drive {
    /// The drive's row at `body`: `d · (a − from) − shift`.
    pub fn row(&self, body: &PlaneBody) -> BodyRow {
        let anchor = body.anchor();
        BodyRow {
            value: self.direction.dot(anchor - self.from) - self.shift,
            along_centre: self.direction,
            along_angle: self.direction.dot(perp(anchor - body.centre)),
        }
    }
}

/// [`project`] with a drive: the rows and the drive met together where
/// the drive's multiplier is within its bound; where it is not, the drive
/// gives its bound (the body moved by it from `predicted` along its
/// gradient at `previous`, where the substep began) and the rows are met
/// beside it. The projection and the drive's multiplier.
pub(crate) fn project_driven(
    start: &Rows,
    previous: &PlaneBody,
    drive: &Drive,
    predicted: PlaneBody,
    compliance: f64,
    tolerance: f64,
    rows_at: impl Fn(&PlaneBody) -> Option<Rows>,
) -> Option<(Projected, f64)> {
    if start.len() >= 3 {
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
    let pushed = predicted.moved(&alone, DVec3::new(bounded, 0.0, 0.0));
    Some((
        project(start, pushed, compliance, tolerance, rows_at)?,
        bounded,
    ))
}

#[cfg(test)]
mod tests;
