//! One-sided rows and friction on an island, eqs. (16)–(17): beads that leave a
//! wire, land on it again (or bounce), slide against friction, stop and
//! stick.

use crate::geometry::WireSpace;

use super::integrators::Stage;
use super::rows::RowAt;
use super::{Island, IslandWork, RoughRow};
use crate::solver::contact::{ContactEvent, bounces};
use crate::solver::coupled::constraint::RowKind;
use crate::solver::friction;
use crate::solver::settings::Gains;
use crate::solver::solve::SolveError;
use crate::solver::state::{BeadState, LinearForce};
use crate::solver::wire_normal::{along, usable};

impl<V: WireSpace> Island<V> {
    /// Eq. (17) on the island at the step's start (λ from
    /// [`Island::leave`]): releases every stick row whose force passes
    /// static friction, and adds kinetic friction and damping to the force
    /// on each sliding bead. Returns each rough row's bead, its sliding
    /// velocity at the start, and whether static friction let go of it
    /// this step.
    pub(super) fn resist(
        &self,
        time: f64,
        states: &[BeadState<V>],
        forces: &mut [LinearForce<V>],
        work: &mut IslandWork<V>,
    ) -> Vec<(usize, usize, V, bool)> {
        let mut slides = Vec::new();
        for (r, rough) in self.rough.iter().enumerate() {
            let Some(rough) = rough else { continue };
            if self.contacts[r] {
                if let Some(slide) = self.resist_pair(r, rough, states, forces, work) {
                    slides.push(slide);
                }
                continue;
            }
            let bead = self.entry_bead[self.row_start[r]];
            if work.inactive[r] {
                // In flight: nothing to rub against, nothing to stick to.
                if let Some(s) = rough.stick {
                    work.inactive[s] = true;
                }
                continue;
            }
            let row = self.wire_row(r, states, time);
            let nn = row.normal.dot(row.normal);
            if !usable(nn) {
                continue;
            }
            let mut press = friction::press(work.lambda[r], nn);
            let mut sliding = row.sliding(states[bead].velocity);
            if let Some(p) = rough.partner {
                // A curve in space: the two rows press together and the
                // bead slides along the one tangent left.
                let other = self.wire_row(p, states, time);
                let nn = other.normal.dot(other.normal);
                if !usable(nn) {
                    continue;
                }
                press = press.hypot(friction::press(work.lambda[p], nn));
                sliding = RowAt {
                    wire: V::ZERO,
                    ..other
                }
                .sliding(sliding);
            }
            let mut direction = sliding;
            let mut released = false;
            if let Some(s) = rough.stick
                && !work.inactive[s]
            {
                let hold = work.lambda[s];
                if friction::holds(&rough.friction, hold.abs(), press) {
                    continue; // held still
                }
                // It gives way: it slides toward the pull, against λ's push.
                work.inactive[s] = true;
                released = true;
                if let RowKind::Axis { axis, .. } = self.rows[s] {
                    direction = axis * -hold;
                }
            }
            let speed = direction.dot(direction).sqrt();
            if speed > 0.0 {
                forces[bead].force += friction::kinetic(&rough.friction, press, direction, speed);
            }
            forces[bead].force += friction::damping(rough.damping, sliding);
            slides.push((r, bead, sliding, released));
        }
        slides
    }

    /// [`Island::resist`] for contact row `r` with friction: a pair apart
    /// rubs nothing and holds nothing; a pair its stick row holds stays
    /// held while static friction can; a pair that slips, or at rest
    /// starts to, gets kinetic friction, `μk |λ|` against its slip, on
    /// each bead. Row `r`, the pair's second bead, its slip at the start,
    /// and whether static friction let go of it this step; none where the
    /// stick held or the pair is apart.
    fn resist_pair(
        &self,
        r: usize,
        rough: &RoughRow,
        states: &[BeadState<V>],
        forces: &mut [LinearForce<V>],
        work: &mut IslandWork<V>,
    ) -> Option<(usize, usize, V, bool)> {
        let (a, b, _) = self.contact_pair(r)?;
        if work.inactive[r] {
            if let Some(s) = rough.stick {
                work.inactive[s] = true;
            }
            return None;
        }
        let (n, sliding) = self.pair_slip(r, states)?;
        let press = work.lambda[r].abs();
        // At rest it is rubbed against the way it starts to slip (the
        // pair's accelerations at the step's start, from `leave`).
        let accelerations = (work.acceleration.get(a), work.acceleration.get(b));
        let mut direction = match (sliding == V::ZERO, accelerations) {
            (true, (Some(&aa), Some(&ab))) => along(n, 1.0, ab - aa),
            _ => sliding,
        };
        let mut released = false;
        if let Some(s) = rough.stick
            && !work.inactive[s]
        {
            let hold = work.lambda[s];
            if friction::holds(&rough.friction, hold.abs(), press) {
                return None; // held still
            }
            work.inactive[s] = true;
            released = true;
            if let Some(Some((axis, _))) = work.sticks.get(s) {
                direction = *axis * -hold;
            }
        }
        let speed = direction.dot(direction).sqrt();
        if speed > 0.0 {
            let rub = friction::kinetic(&rough.friction, press, direction, speed);
            forces[b].force += rub;
            forces[a].force -= rub;
        }
        Some((r, b, sliding, released))
    }

    /// Contact row `r`'s unit normal from its first bead to its second,
    /// and the second's slip across it relative to the first, at `states`;
    /// none for a row of another kind or a pair at one point.
    pub(super) fn pair_slip(&self, r: usize, states: &[BeadState<V>]) -> Option<(V, V)> {
        let (a, b, _) = self.contact_pair(r)?;
        let (sa, sb) = (states.get(a)?, states.get(b)?);
        let d = sb.position - sa.position;
        let nn = d.dot(d);
        if !usable(nn) {
            return None;
        }
        let n = d / nn.sqrt();
        Some((n, along(n, 1.0, sb.velocity - sa.velocity)))
    }

    /// Where friction stopped a sliding bead during the step (its sliding
    /// velocity reversed), puts its stick row across the wire there and
    /// projects the island's velocities onto the rows with it: the bead
    /// stays put while static friction can hold it. A pair of beads
    /// pressed together stops in the same way, its stick row placed
    /// across the line between their centres.
    pub(super) fn stop(
        &self,
        time: f64,
        states: &mut [BeadState<V>],
        slides: &[(usize, usize, V, bool)],
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        let mut stopped = false;
        for &(r, bead, before, released) in slides {
            let Some(RoughRow {
                stick: Some(s),
                friction,
                ..
            }) = self.rough[r]
            else {
                continue;
            };
            if work.inactive[r] || self.paths[r].is_some() || !friction.is_some() {
                continue;
            }
            if self.contacts[r] {
                // A pair: held across the contact where its slip reversed.
                let Some((n, sliding)) = self.pair_slip(r, states) else {
                    continue;
                };
                // Its slip reversed, or it was at rest and static
                // friction did not let go of it: held at the step's end.
                let reversed = before != V::ZERO && sliding.dot(before) < 0.0;
                let started = before == V::ZERO && sliding != V::ZERO && !released;
                if reversed || started {
                    stopped |= self.place_pair_stick(s, n, r, states, work);
                }
                continue;
            }
            let row = self.wire_row(r, states, time);
            let partner = self.rough[r]
                .and_then(|rough| rough.partner)
                .map(|p| self.wire_row(p, states, time));
            let mut sliding = row.sliding(states[bead].velocity);
            if let Some(other) = partner {
                sliding = RowAt {
                    wire: V::ZERO,
                    ..other
                }
                .sliding(sliding);
            }
            if before != V::ZERO && sliding.dot(before) >= 0.0 {
                continue;
            }
            // From rest: held at the step's end, unless static friction let
            // go of it at the step's start (it then slides on).
            if before == V::ZERO && (sliding == V::ZERO || released) {
                continue;
            }
            // In space a surface has no one tangent to hold along: the
            // bead is not held still there, friction only slows it. A
            // curve has one, across both its normals.
            let tangent = match partner {
                Some(other) => row.tangent_with(&other),
                None => row.tangent(),
            };
            let Some(axis) = tangent else { continue };
            self.place_stick(s, axis, axis.dot(states[bead].position), work);
            stopped = true;
        }
        if stopped {
            work.time = time;
            work.load(states);
            self.evaluate_at_new(work);
            self.project_velocity(work)?;
            for (state, v) in states.iter_mut().zip(&work.v) {
                state.velocity = *v;
            }
        }
        Ok(())
    }

    /// Puts stick row `s` of contact row `r` across the line between its
    /// beads (of unit normal `n`) where they are in `states`, as
    /// `t·(x_b − x_a)` is there. Whether it could: a pair in space has no
    /// one tangent to be held along.
    pub(super) fn place_pair_stick(
        &self,
        s: usize,
        n: V,
        r: usize,
        states: &[BeadState<V>],
        work: &mut IslandWork<V>,
    ) -> bool {
        let (Some((a, b, _)), Some(axis)) = (self.contact_pair(r), V::stick_axis(n)) else {
            return false;
        };
        let offset = axis.dot(states[b].position - states[a].position);
        self.place_stick(s, axis, offset, work);
        true
    }

    /// Takes stick row `s` back, as the line `axis·x = offset`.
    pub(super) fn place_stick(&self, s: usize, axis: V, offset: f64, work: &mut IslandWork<V>) {
        work.inactive[s] = false;
        work.sticks.resize(self.rows(), None);
        work.sticks[s] = Some((axis, offset));
    }

    /// Sets aside every wire row whose bead is past its wire's end, every
    /// one-sided row whose λ (eq. 12 with no
    /// stabilization) at the step's start has the sign its wire cannot
    /// push with, and every contact row whose beads part. A contact row
    /// whose λ would pull is left to the step's velocity solve where it
    /// lets such rows go (`pushing`: RATTLE, and a step that projects):
    /// that solve weighs every contact at once, where λ at the start lets
    /// go of every row that pulls while the others hold.
    pub(super) fn leave(
        &self,
        time: f64,
        states: &[BeadState<V>],
        forces: &[LinearForce<V>],
        pushing: bool,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        if states.len() != self.beads() || forces.len() != self.beads() {
            return Ok(()); // `advance` reports it
        }
        work.x0.clear();
        work.x0.extend(states.iter().map(|s| s.position));
        work.v0.clear();
        work.v0.extend(states.iter().map(|s| s.velocity));
        work.time = time;
        self.accelerate(forces, Gains::NONE, work, Stage::Start)?;
        for r in 0..self.rows() {
            if work.inactive[r] {
                continue;
            }
            let (side, _) = self.sides[r];
            let parts = || self.parting(r, states) == Some(true);
            let pulls = side * work.lambda[r] < 0.0 && !(pushing && self.contacts[r]);
            let off_end = || self.ends(r) && self.past_end(r, states, time, &work.hints) > 0.0;
            if (side != 0.0 && (pulls || parts())) || off_end() {
                work.inactive[r] = true;
                if self.contacts[r] {
                    continue; // a pair parting is no bead leaving its wire
                }
                self.report_left(r, time, states, work);
            }
        }
        Ok(())
    }

    /// Records that wire row `r`'s bead left its wire at `time`, where it
    /// is in `states` (once for a curve in space, by its first row).
    pub(super) fn report_left(
        &self,
        r: usize,
        time: f64,
        states: &[BeadState<V>],
        work: &mut IslandWork<V>,
    ) {
        if self.second_row(r) {
            return; // the curve's first row reported it
        }
        let bead = self.entry_bead[self.row_start[r]];
        let position = states[bead].position;
        work.events
            .push((r, bead, ContactEvent::Left { time, position }));
    }

    /// Lands every bead whose set-aside one-sided row of `rows` it crossed
    /// during the step: the island projected onto its rows with that one
    /// back, the bead's velocity across the wire reversed and scaled by the
    /// restitution.
    pub(super) fn land(
        &self,
        time: f64,
        states: &mut [BeadState<V>],
        forces: &[LinearForce<V>],
        h: f64,
        rows: &[usize],
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        work.time = time;
        for &r in rows {
            let (side, restitution) = self.sides[r];
            if side == 0.0 || !work.inactive[r] || self.contacts[r] {
                // Where beads meet is the touch settlement's to find.
                continue;
            }
            if self.past_end(r, states, time, &work.hints) > 0.0 {
                // Past an end the wire goes on only as far as `C` does.
                continue;
            }
            let bead = self.entry_bead[self.row_start[r]];
            let RowAt { c, normal, wire } = self.wire_row(r, states, time);
            if side * c > 0.0 {
                continue;
            }
            // Back on: onto every held row, then the velocities.
            let BeadState { position, velocity } = states[bead];
            work.inactive[r] = false;
            work.load(states);
            self.newton_holding(work)?;
            self.evaluate_at_new(work);
            let nn = normal.dot(normal).max(f64::MIN_POSITIVE);
            let across = normal.dot(velocity - wire);
            let normal_speed = across.abs() / nn.sqrt();
            let force = forces[bead].at(position);
            let w = self.inverse_mass[bead];
            let bounced = bounces(restitution, normal_speed, normal, force, w, h);
            if bounced {
                work.bias[r] -= restitution * across;
            }
            self.project_velocity(work)?;
            for (state, (x, v)) in states.iter_mut().zip(work.x.iter().zip(&work.v)) {
                state.position = *x;
                state.velocity = *v;
            }
            work.inactive[r] = bounced;
            work.events.push((
                r,
                bead,
                ContactEvent::Landed {
                    time,
                    position: states[bead].position,
                    normal_speed,
                    bounced,
                },
            ));
        }
        Ok(())
    }
}
