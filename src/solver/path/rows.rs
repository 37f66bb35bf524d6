//! A joint's rows as plain values: a body's velocity, the bodies a joint
//! moves ([`Held`]: the body it holds and the carrier of its wire), one
//! row's value and gradient ([`BodyRow`]), a joint's rows together
//! ([`Rows`]) and the small dense solve of their matrix.

use super::{JointBody, MAX_ROWS, Multipliers, Turn};
use crate::geometry::{Coordinates, Twist};
use crate::lane::Vector;
use crate::solver::RowReport;

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
    pub(super) fn kicked(self, body: &B, (p, tau): (B::V, B::Turn)) -> Self {
        Self {
            linear: self.linear + body.inverse_mass(p),
            spin: self.spin + body.inverse_inertia(tau),
        }
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.linear.is_finite() && self.spin.finite()
    }

    /// The velocity a body whose centre is at `at` would have riding
    /// rigidly with a wire the game moves by `twist`.
    pub fn riding(twist: &Twist<B::V>, at: B::V) -> Self {
        Self {
            linear: twist.velocity_at(at),
            spin: twist.angular_velocity,
        }
    }

    /// The velocity a body whose centre is at `at` would have riding
    /// rigidly with one whose centre is at `centre` and that moves at
    /// `self`: `v + ω × (at − centre)`, the same spin.
    pub fn carried_to(self, centre: B::V, at: B::V) -> Self {
        Self {
            linear: self.linear + B::V::turn(self.spin, at - centre),
            spin: self.spin,
        }
    }
}

/// What a joint moves: the body it holds and, where its wire rides a
/// body of its own (the carrier, say a door the wire is fixed to), that
/// body too; or their velocities, or the impulses given them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Held<T> {
    /// The body the joint holds (its velocity, its impulse).
    pub body: T,
    /// The body its wire rides, if any (its velocity, its impulse).
    pub carrier: Option<T>,
}

impl<T> Held<T> {
    /// The body alone, on a wire that rides no body.
    pub fn alone(body: T) -> Self {
        Self {
            body,
            carrier: None,
        }
    }
}

impl<B: JointBody> Held<B> {
    /// The bodies moved by the multipliers `lambda` along `rows`: each by
    /// its own part of `Gᵀ λ`.
    pub(super) fn moved(&self, rows: &Rows<B>, lambda: &Multipliers) -> Self {
        let impulse = rows.impulse(lambda);
        Self {
            body: self.body.moved(impulse.body),
            carrier: match (self.carrier, impulse.carrier) {
                (Some(carrier), Some(push)) => Some(carrier.moved(push)),
                (carrier, _) => carrier,
            },
        }
    }
}

impl<B: JointBody> Held<BodyVelocity<B>> {
    /// The velocities changed by the impulses `impulse`.
    pub(super) fn kicked(self, bodies: &Held<B>, impulse: &Held<Impulse<B>>) -> Self {
        Self {
            body: self.body.kicked(&bodies.body, impulse.body),
            carrier: match (self.carrier, bodies.carrier, impulse.carrier) {
                (Some(v), Some(carrier), Some(push)) => Some(v.kicked(&carrier, push)),
                (v, _, _) => v,
            },
        }
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.body.is_finite() && self.carrier.is_none_or(|v| v.is_finite())
    }
}

/// A generalized impulse: through the centre of mass, and about it.
pub(crate) type Impulse<B> = (<B as JointBody>::V, <B as JointBody>::Turn);

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

    /// The row as the carrier of the wire sees it, `offset` its centre
    /// less the body's: a row of a wire that rides a body is a function of
    /// where the held body is against the carrier alone, so moving both
    /// as one rigid body changes it not at all, and its gradient along
    /// the carrier's coordinates is the body's carried across:
    /// `∂C/∂c_B = −∂C/∂c_A`, `∂C/∂θ_B = (c_B − c_A) × ∂C/∂c_A − ∂C/∂θ_A`.
    pub(super) fn carried(&self, offset: B::V) -> Self {
        Self {
            value: self.value,
            along_centre: -self.along_centre,
            along_angle: B::moment(offset, self.along_centre) - self.along_angle,
        }
    }

    /// `Ċ` at the velocities `v` of the held body and of the carrier, the
    /// carrier's centre `offset` from the body's.
    pub(super) fn rate_of(&self, offset: Option<B::V>, v: &Held<BodyVelocity<B>>) -> f64 {
        match (offset, v.carrier) {
            (Some(offset), Some(carrier)) => self.rate(v.body) + self.carried(offset).rate(carrier),
            _ => self.rate(v.body),
        }
    }

    /// `Jᵢ M⁻¹ Jⱼᵀ`: how far this row moves as `other`'s multiplier does.
    pub(super) fn coupling(&self, other: &Self, body: &B) -> f64 {
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
    pub(super) rows: [BodyRow<B>; MAX_ROWS],
    pub(super) len: usize,
    pub(super) bend: Bend<B::V>,
    /// Where the wire rides a body: that body's centre less the held
    /// body's where the rows were taken, which carries each row to it
    /// ([`BodyRow::carried`]).
    pub(super) carrier: Option<B::V>,
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
            carrier: None,
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

    /// Says the rows were taken at `at`: on a wire that rides a body, they
    /// carry to it too. (In place: a joint's rows are too large to copy
    /// about.)
    pub fn ride(&mut self, at: &Held<B>) {
        self.carrier = at.carrier.map(|c| c.centre() - at.body.centre());
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
    pub(super) fn values(&self) -> Multipliers {
        std::array::from_fn(|i| {
            if i < self.len {
                self.rows[i].value
            } else {
                0.0
            }
        })
    }

    /// `J q̇` at the velocities `v`, zero past the last row.
    pub(super) fn rates(&self, v: &Held<BodyVelocity<B>>) -> Multipliers {
        std::array::from_fn(|i| {
            if i < self.len {
                self.rows[i].rate_of(self.carrier, v)
            } else {
                0.0
            }
        })
    }

    /// What the rows say of a body held by them, as a bead's diagnostics
    /// report a wire's row: the row furthest from met (its `C`), its rate
    /// `Ċ` at the velocities `v`, and `λ` of the mean force `force` on the
    /// body's centre along its gradient, `force · ∇C / |∇C|²` (the force
    /// is then `λ ∇C` where it is normal to the wire). All zero with no
    /// rows.
    pub fn report(&self, v: &Held<BodyVelocity<B>>, force: B::V) -> RowReport {
        let Some(row) = self
            .iter()
            .max_by(|a, b| a.value.abs().total_cmp(&b.value.abs()))
        else {
            return RowReport::default();
        };
        let normal = row.along_centre.dot(row.along_centre);
        RowReport {
            c: row.value,
            c_dot: row.rate_of(self.carrier, v),
            lambda: if normal > 0.0 {
                force.dot(row.along_centre) / normal
            } else {
                0.0
            },
        }
    }

    /// `Gᵀ λ`: the generalized impulse of the multipliers `lambda` along
    /// the rows, on the held body and on the carrier. The carrier's is the
    /// body's carried across, `(−p, (c_B − c_A) × p − τ)`, so the pair's
    /// momentum, and its angular momentum about any point, are kept.
    pub fn impulse(&self, lambda: &Multipliers) -> Held<Impulse<B>> {
        let (p, tau) = self
            .iter()
            .zip(lambda)
            .fold((B::V::ZERO, B::Turn::default()), |(p, tau), (row, &l)| {
                (p + row.along_centre * l, tau + row.along_angle * l)
            });
        Held {
            body: (p, tau),
            carrier: self.carrier.map(|offset| (-p, B::moment(offset, p) - tau)),
        }
    }

    /// `A = J M⁻¹ Gᵀ` for the rows `J` (self) and `G` (`along`), with
    /// `compliance` added to the diagonal: the held body's part and, on a
    /// wire that rides a body, the carrier's.
    pub(super) fn matrix(&self, along: &Self, bodies: &Held<B>, compliance: f64) -> Matrix {
        let mut a = [[0.0; MAX_ROWS]; MAX_ROWS];
        let carried = match (self.carrier, along.carrier, bodies.carrier) {
            (Some(here), Some(there), Some(carrier)) => Some((here, there, carrier)),
            _ => None,
        };
        for (i, row) in self.iter().enumerate() {
            for (j, other) in along.iter().enumerate() {
                let mut entry = row.coupling(other, &bodies.body);
                if let Some((here, there, carrier)) = carried {
                    entry += row.carried(here).coupling(&other.carried(there), &carrier);
                }
                a[i][j] = entry + if i == j { compliance } else { 0.0 };
            }
        }
        a
    }
}

/// A square matrix of rows, row-major.
pub(super) type Matrix = [[f64; MAX_ROWS]; MAX_ROWS];

/// `A x = b` for the leading `n` rows and columns of `A` (the rest
/// ignored, zero in `x`), by Gauss elimination with partial pivoting; or
/// `None` where they are singular (a pivot at most 1e-13 of `A`'s largest
/// entry) or the answer not finite. The matrix `J M⁻¹ Gᵀ` of SHAKE's step
/// is not symmetric, so it takes no Cholesky factor.
pub(super) fn solve(mut a: Matrix, b: Multipliers, n: usize) -> Option<Multipliers> {
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
