//! Each row of an island evaluated at a state: `C`, its gradient, `J̇q̇` and
//! the bias of a moving wire (eq. 15), and the products with `J` and
//! `W Jᵀ` that the solves are made of.

use bevy::math::DVec2;

use super::{Island, IslandWork, OFF_THE_WIRE, opening_rate, pair_gap, parts};
use crate::geometry::{Placement, Twist, WireSpace, placed_geometry};
use crate::solver::coupled::constraint::RowKind;
use crate::solver::state::{BeadState, LinearForce};
use crate::solver::wire_normal::along;

impl<V: WireSpace> Island<V> {
    /// Wire row `r` where its bead is in `states` at `time`, whether the
    /// row is held or not (zero for a row of another kind).
    pub(super) fn wire_row(&self, r: usize, states: &[BeadState<V>], time: f64) -> RowAt<V> {
        self.wire_row_near(r, states, time, f64::NAN)
    }

    /// [`Island::wire_row`], the bead's nearest point on its wire searched
    /// near the curve parameter `hint` (anywhere where it is NaN).
    pub(super) fn wire_row_near(
        &self,
        r: usize,
        states: &[BeadState<V>],
        time: f64,
        hint: f64,
    ) -> RowAt<V> {
        self.entry_bead
            .get(self.row_start[r])
            .and_then(|&bead| states.get(bead))
            .and_then(|s| self.wire_row_at(r, s.position, time, hint))
            .unwrap_or_default()
    }

    /// Wire row `r` with its bead at `position` at `time`, searched near
    /// `hint`; none for a row of another kind.
    fn wire_row_at(&self, r: usize, position: V, time: f64, hint: f64) -> Option<RowAt<V>> {
        let (shape, pose, twist) = self.wire_at(r, time)?;
        let g = placed_geometry(&pose, position, |local| {
            V::shape_geometry(shape, local, Some(hint))
        });
        Some(RowAt {
            c: g.c,
            normal: g.normal,
            wire: twist.velocity_at(position),
        })
    }

    /// Whether wire row `r`'s bead, at `at`, is behind its one-sided wire
    /// at `time` by more than rounding ([`OFF_THE_WIRE`] of its scale):
    /// one that catches beads does not land it from there.
    pub(super) fn behind_at(&self, r: usize, at: V, time: f64) -> bool {
        self.wire_row_at(r, at, time, f64::NAN)
            .is_some_and(|row| self.sides[r].0 * row.c < -OFF_THE_WIRE * self.rows[r].scale())
    }

    /// How far wire row `r`'s bead at `x` is in front of its wire at
    /// `time`: `side · C`, negative behind a one-sided wire (the row's own
    /// units); none for a row of another kind.
    pub(super) fn in_front(&self, r: usize, x: &[V], time: f64) -> Option<f64> {
        let at = *x.get(*self.entry_bead.get(self.row_start[r])?)?;
        Some(self.sides[r].0 * self.wire_row_at(r, at, time, f64::NAN)?.c)
    }

    /// How far wire row `r`'s bead in `states` is in front of its wire at
    /// `time`, in metres along the wire's normal (negative behind a
    /// one-sided wire), and how fast that grows (negative: it closes);
    /// none for a row of another kind or where the normal vanishes.
    pub(super) fn wire_gap(
        &self,
        r: usize,
        states: &[BeadState<V>],
        time: f64,
    ) -> Option<(f64, f64)> {
        let state = states.get(*self.entry_bead.get(self.row_start[r])?)?;
        let row = self.wire_row_at(r, state.position, time, f64::NAN)?;
        let length = row.normal.dot(row.normal).sqrt();
        if length.is_nan() || length <= 0.0 {
            return None;
        }
        let side = self.sides[r].0;
        let rate = side * row.normal.dot(state.velocity - row.wire) / length;
        Some((side * row.c / length, rate))
    }

    /// Whether row `r` is a wire's that ends (an open curve): its bead
    /// leaves it past an end.
    pub(super) fn ends(&self, r: usize) -> bool {
        matches!(&self.rows[r], RowKind::Wire { shape, .. } if V::shape_has_ends(shape))
    }

    /// Whether row `r` is the second row of a curve in space (the row
    /// before it the same bead's first), which its first row speaks for:
    /// past an end, a bead leaves both.
    pub(super) fn second_row(&self, r: usize) -> bool {
        r > 0 && matches!(&self.rows[r], RowKind::Wire { shape, .. } if V::shape_second_row(shape))
    }

    /// How far wire row `r`'s bead in `states` is from its wire at
    /// `time`, in the row's units: `|C|`, or for a curve in space the
    /// length of its two rows' offsets.
    pub(super) fn off_wire(&self, r: usize, states: &[BeadState<V>], time: f64) -> f64 {
        let first = if self.second_row(r) { r - 1 } else { r };
        let c = |r: usize| self.wire_row(r, states, time).c;
        let off = c(first).abs();
        if first + 1 < self.rows() && self.second_row(first + 1) {
            off.hypot(c(first + 1))
        } else {
            off
        }
    }

    /// Whether any row is a wire's that ends.
    pub(super) fn has_ends(&self) -> bool {
        self.ended > 0
    }

    /// How far past an end of its wire wire row `r`'s bead is in `states`
    /// at `time`, the nearest point looked for near the row's kept
    /// parameter in `hints`: zero or less on the wire, −∞ for a wire with
    /// no end or a row of another kind.
    pub(super) fn past_end(
        &self,
        r: usize,
        states: &[BeadState<V>],
        time: f64,
        hints: &[f64],
    ) -> f64 {
        // A curve's two rows end as one, where its first row says.
        let r = if self.second_row(r) { r - 1 } else { r };
        let Some((shape, pose, _, state)) = self.wire_and_bead(r, states, time) else {
            return f64::NEG_INFINITY;
        };
        let local = Placement::to_local(&pose, state.position);
        V::shape_past_end(shape, local, hints.get(r).copied().unwrap_or(f64::NAN))
    }

    /// Contact row `r`'s two beads and its reach `r_a + r_b`; none for a
    /// row of another kind.
    pub(super) fn contact_pair(&self, r: usize) -> Option<(usize, usize, f64)> {
        let RowKind::Rod { length } = self.rows[r] else {
            return None;
        };
        let entries = &self.entry_bead[self.row_start[r]..self.row_start[r + 1]];
        self.contacts[r].then(|| (entries[0], entries[1], length))
    }

    /// The gap `|x_a − x_b| − (r_a + r_b)` of contact row `r`'s beads at
    /// positions `x`, and its reach `r_a + r_b`; none for a row of another
    /// kind.
    pub(super) fn contact_gap(&self, r: usize, x: &[V]) -> Option<(f64, f64)> {
        let (a, b, reach) = self.contact_pair(r)?;
        Some((pair_gap(*x.get(a)?, *x.get(b)?, reach), reach))
    }

    /// Whether the beads of contact row `r` part where they are in
    /// `states` (see [`OPENING`](super::OPENING)); none for a row of
    /// another kind.
    pub(super) fn parting(&self, r: usize, states: &[BeadState<V>]) -> Option<bool> {
        let (rate, reach, speeds) = self.opening(r, states)?;
        Some(parts(rate, reach, speeds))
    }

    /// How fast the gap of contact row `r`'s beads opens where they are in
    /// `states` (negative: closes), their reach (the two radii) and the
    /// sum of their speeds; none for a row of another kind.
    pub(super) fn opening(&self, r: usize, states: &[BeadState<V>]) -> Option<(f64, f64, f64)> {
        let (a, b, reach) = self.contact_pair(r)?;
        let (rate, speeds) = opening_rate(states.get(a)?, states.get(b)?);
        Some((rate, reach, speeds))
    }

    /// Wire row `r`'s wire at `time` (as [`Island::wire_at`]) and its
    /// bead's state in `states`; none for a row of another kind.
    fn wire_and_bead<'a>(
        &'a self,
        r: usize,
        states: &'a [BeadState<V>],
        time: f64,
    ) -> Option<(&'a V::Shape, V::Pose, Twist<V>, &'a BeadState<V>)> {
        let (shape, pose, twist) = self.wire_at(r, time)?;
        let state = states.get(self.entry_bead[self.row_start[r]])?;
        Some((shape, pose, twist, state))
    }

    /// The shape of wire row `r` and where its wire is at `time`, with its
    /// twist; none for a row of another kind.
    fn wire_at(&self, r: usize, time: f64) -> Option<(&V::Shape, V::Pose, Twist<V>)> {
        let RowKind::Wire { shape, pose } = &self.rows[r] else {
            return None;
        };
        let (pose, twist) = match &self.paths[r] {
            Some(path) => path.at(time),
            None => (*pose, Twist::default()),
        };
        Some((shape, pose, twist))
    }

    /// Wire row `r`'s bead's curve parameter in `states` at `time`,
    /// searched near `hint` (anywhere where it is NaN), with the bead;
    /// none for a row of another kind.
    fn along_wire<'a>(
        &'a self,
        r: usize,
        states: &'a [BeadState<V>],
        time: f64,
        hint: f64,
    ) -> Option<(f64, &'a BeadState<V>)> {
        let (shape, pose, _, state) = self.wire_and_bead(r, states, time)?;
        let local = Placement::to_local(&pose, state.position);
        Some((V::shape_parameter(shape, local, hint), state))
    }

    /// Finds the curve parameter of each wire row whose bead's place along
    /// its wire is unknown (an island's first step), by one search of the
    /// whole wire where the bead is at `time`: the step's evaluations then
    /// search only near it, and keep the branch it is on.
    pub(super) fn find_unknown(
        &self,
        time: f64,
        states: &[BeadState<V>],
        work: &mut IslandWork<V>,
    ) {
        work.hints.resize(self.rows(), f64::NAN);
        for r in 0..self.rows() {
            if work.hints[r].is_nan()
                && let Some((hint, _)) = self.along_wire(r, states, time, f64::NAN)
            {
                work.hints[r] = hint;
            }
        }
    }

    /// Keeps each wire row's curve parameter where its bead is now (at
    /// `time`), and reports each set-aside row's own `C` and `Ċ`.
    pub(super) fn follow(&self, time: f64, states: &[BeadState<V>], work: &mut IslandWork<V>) {
        work.hints.resize(self.rows(), f64::NAN);
        for r in 0..self.rows() {
            let Some((hint, state)) = self.along_wire(r, states, time, work.hints[r]) else {
                continue;
            };
            work.hints[r] = hint;
            if work.inactive.get(r) == Some(&true)
                && let Some(report) = work.reports.get_mut(r)
            {
                let row = self.wire_row_near(r, states, time, hint);
                report.c = row.c;
                report.c_dot = row.normal.dot(state.velocity - row.wire);
            }
        }
    }

    /// Evaluates every row at `(x, v)` at `work.time`: gradients, `C`,
    /// and where `rates`, `J̇q̇` and the bias `−∂C/∂t`, into `out` (without
    /// `rates` those two keep what they held).
    fn evaluate(
        &self,
        x: &[V],
        v: &[V],
        time: f64,
        held: Held<'_, V>,
        out: Rows<'_, V>,
        rates: bool,
    ) {
        let Held {
            inactive,
            hints,
            sticks,
        } = held;
        let hint = |r: usize| hints.get(r).copied().unwrap_or(f64::NAN);
        let Rows {
            gradient,
            c,
            curvature,
            bias,
            scratch,
        } = out;
        gradient.resize(self.entry_bead.len(), V::ZERO);
        c.resize(self.rows(), 0.0);
        curvature.resize(self.rows(), 0.0);
        if rates {
            bias.clear();
        }
        bias.resize(self.rows(), 0.0);
        for (r, kind) in self.rows.iter().enumerate() {
            let range = self.row_start[r]..self.row_start[r + 1];
            if inactive.get(r) == Some(&true) {
                // Set aside: no force, no error.
                gradient[range].fill(V::ZERO);
                (c[r], curvature[r], bias[r]) = (0.0, 0.0, 0.0);
                continue;
            }
            if let Some(Some((axis, offset))) = sticks.get(r) {
                // A stick row, placed where its bead stopped: `t·x`, or
                // `t·(x_b − x_a)` for a pair's.
                let beads = &self.entry_bead[range.clone()];
                let value = match *beads {
                    [bead] => {
                        gradient[range.start] = *axis;
                        axis.dot(x[bead])
                    }
                    [a, b] => {
                        gradient[range.start] = -*axis;
                        gradient[range.start + 1] = *axis;
                        axis.dot(x[b] - x[a])
                    }
                    _ => *offset,
                };
                (c[r], curvature[r], bias[r]) = (value - offset, 0.0, 0.0);
                continue;
            }
            let path = if self.moving > 0 {
                self.paths[r].as_ref()
            } else {
                None
            };
            if let (Some(path), RowKind::Wire { shape, .. }) = (path, kind) {
                // Eq. (15): the wire where it is at `time`, seen from its frame.
                let bead = self.entry_bead[range.start];
                let (p, u) = (x[bead], v[bead]);
                let (pose, twist) = path.at(time);
                let g = placed_geometry(&pose, p, |local| {
                    V::shape_geometry(shape, local, Some(hint(r)))
                });
                let w = twist.velocity_at(p);
                let relative = u - w;
                gradient[range.start] = g.normal;
                c[r] = g.c;
                if !rates {
                    continue;
                }
                curvature[r] = relative.dot(V::hessian_times(&g.hessian, relative))
                    - g.normal.dot(twist.acceleration_at(p, relative));
                bias[r] = g.normal.dot(w);
                continue;
            }
            let (value, bend) = kind.evaluate(
                &self.entry_bead[range.clone()],
                x,
                v,
                &mut gradient[range],
                scratch,
                hint(r),
                rates,
            );
            c[r] = value;
            if rates {
                curvature[r] = bend;
            }
        }
    }

    /// Evaluates the rows at the current state `work.x`, `work.v` (where
    /// the step ended, or the stage or Newton iterate being worked on).
    pub(super) fn evaluate_at_new(&self, work: &mut IslandWork<V>) {
        self.evaluate_work(work, false, work.time, true);
    }

    /// [`Island::evaluate_at_new`] without `J̇q̇` and the bias: what a
    /// position solve's iterations need.
    pub(super) fn evaluate_positions(&self, work: &mut IslandWork<V>) {
        self.evaluate_work(work, false, work.time, false);
    }

    /// Evaluates the rows at the step's start `work.x0`, `work.v0` into
    /// `work.first_gradient` (and `work.c`, `work.curvature`, `work.bias`).
    pub(super) fn evaluate_at_start(&self, work: &mut IslandWork<V>, time: f64) {
        self.evaluate_work(work, true, time, true);
    }

    /// [`Island::evaluate`] on the work's state: the start's into
    /// `work.first_gradient`, or the current one into `work.gradient`.
    fn evaluate_work(&self, work: &mut IslandWork<V>, at_start: bool, time: f64, rates: bool) {
        let (x, v, gradient) = if at_start {
            (&work.x0, &work.v0, &mut work.first_gradient)
        } else {
            (&work.x, &work.v, &mut work.gradient)
        };
        self.evaluate(
            x,
            v,
            time,
            Held {
                inactive: &work.inactive,
                hints: &work.hints,
                sticks: &work.sticks,
            },
            Rows {
                gradient,
                c: &mut work.c,
                curvature: &mut work.curvature,
                bias: &mut work.bias,
                scratch: &mut work.scratch,
            },
            rates,
        );
    }

    /// `Σ g·v` over row `r`'s entries (`J v` of one row).
    pub(super) fn along(&self, r: usize, gradient: &[V], v: &[V]) -> f64 {
        (self.row_start[r]..self.row_start[r + 1])
            .map(|e| gradient[e].dot(v[self.entry_bead[e]]))
            .sum()
    }

    /// `Ċ_r = Σ g·v − bias` over row `r`'s entries: the rate relative to
    /// a moving wire.
    pub(super) fn rate(&self, r: usize, gradient: &[V], v: &[V], bias: &[f64]) -> f64 {
        self.along(r, gradient, v) - bias[r]
    }

    /// The applied forces at `(x, v)`: each bead's external force, plus
    /// the springs.
    pub(super) fn applied(&self, forces: &[LinearForce<V>], x: &[V], v: &[V], out: &mut Vec<V>) {
        out.clear();
        out.extend(forces.iter().zip(x).map(|(f, &p)| f.at(p)));
        for spring in &self.springs {
            let f = spring.pull(x, v);
            out[spring.a] += f;
            out[spring.b] -= f;
        }
    }

    /// Adds `W Jᵀ μ` (with `gradient`) to `out`.
    pub(super) fn push(&self, gradient: &[V], mu: &[f64], out: &mut [V]) {
        for (r, &m) in mu.iter().enumerate() {
            if m == 0.0 {
                // A row set aside, or one that moves nothing.
                continue;
            }
            self.move_along(gradient, r, m, out);
        }
    }

    /// Adds `W Jᵣᵀ m` of row `r` alone (with `gradient`) to `out`.
    pub(super) fn move_along(&self, gradient: &[V], r: usize, m: f64, out: &mut [V]) {
        let entries = self.row_start[r]..self.row_start[r + 1];
        for (&bead, g) in self.entry_bead[entries.clone()]
            .iter()
            .zip(&gradient[entries])
        {
            out[bead] += *g * (m * self.inverse_mass[bead]);
        }
    }
}

/// A wire row where its bead is: `C`, `∇C`, and the velocity of the
/// wire's point there.
#[derive(Clone, Copy, Default)]
pub(super) struct RowAt<V = DVec2> {
    pub(super) c: f64,
    pub(super) normal: V,
    pub(super) wire: V,
}

impl<V: WireSpace> RowAt<V> {
    /// The part of `velocity`, relative to the wire, along it.
    pub(super) fn sliding(&self, velocity: V) -> V {
        let relative = velocity - self.wire;
        let nn = self.normal.dot(self.normal);
        along(self.normal, nn, relative)
    }

    /// The unit direction along the wire, a stick row's axis (see
    /// [`Coordinates::stick_axis`]).
    pub(super) fn tangent(&self) -> Option<V> {
        V::stick_axis(self.normal)
    }

    /// The unit direction along a curve in space whose other row is
    /// `other`: across both normals.
    pub(super) fn tangent_with(&self, other: &Self) -> Option<V> {
        let t = V::binormal(self.normal, other.normal);
        let size = t.dot(t).sqrt();
        (size > 0.0 && size.is_finite()).then(|| t / size)
    }
}

/// Which rows [`Island::evaluate`] holds, and where along their curves
/// the wire rows' beads were.
struct Held<'a, V> {
    inactive: &'a [bool],
    hints: &'a [f64],
    sticks: &'a [Option<(V, f64)>],
}

/// Where [`Island::evaluate`] writes.
struct Rows<'a, V> {
    gradient: &'a mut Vec<V>,
    c: &'a mut Vec<f64>,
    curvature: &'a mut Vec<f64>,
    bias: &'a mut Vec<f64>,
    scratch: &'a mut Vec<V>,
}
