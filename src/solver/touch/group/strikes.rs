//! A group's strikes: the pairs that meet at an instant answered (each
//! by its restitution, pairs at `e = 0` pressed all at once), friction
//! along the pairs pressed, and which pairs a body's own step holds.

use super::Group;
use crate::geometry::Coordinates;
use crate::solver::coupled::{meets_slowly, opening_rate, parts, step_speed};
use crate::solver::impact::{Response, Strike, Touch, resolve_impacts, rub};
use crate::solver::solve::SolveError;
use crate::solver::state::BeadState;
use crate::solver::touch::{StruckPair, TOUCHING, TouchBody, TouchError};

impl<V: Coordinates> Group<'_, V> {
    /// Strikes every pair touching now: at `e = 0` those a contact row
    /// joins all at once ([`Group::press`]), the rest pair by pair
    /// (eq. 18).
    pub(super) fn strike<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        struck: &mut Vec<StruckPair>,
    ) -> Result<(), TouchError> {
        self.press(bodies, struck)?;
        // The group's velocities side by side, each body's from its offset.
        let mut offsets = Vec::with_capacity(self.bodies.len());
        let mut velocities = Vec::new();
        for states in &self.now {
            offsets.push(velocities.len());
            velocities.extend(states.iter().map(|s| s.velocity));
        }
        let flat = |group: &Self, i: usize| offsets[group.slot(i)] + group.beads[i].bead;
        let mut touches = Vec::new();
        let mut responses = Vec::new();
        let mut named = Vec::new();
        for &pair in &self.pairs {
            let (a, b) = (self.state(pair.0, false), self.state(pair.1, false));
            let (ta, tb) = (self.beads[pair.0], self.beads[pair.1]);
            let r = ta.radius + tb.radius;
            if self.gap(pair, a.position, b.position) > TOUCHING * r
                || self.held(bodies, pair)
                || self.pressable(bodies, pair)
            {
                continue;
            }
            let (fa, fb) = (flat(self, pair.0), flat(self, pair.1));
            let e = ta.restitution.min(tb.restitution);
            let touch =
                Touch::between((fa, a.position, ta.radius), (fb, b.position, tb.radius), e)?
                    .with_friction(ta.friction.min(tb.friction));
            let n = touch.normal();
            let (sa, sb) = (self.slot(pair.0), self.slot(pair.1));
            let push =
                bodies[self.bodies[sb]].push(tb.bead) - bodies[self.bodies[sa]].push(ta.bead);
            let touch = touch.resting_below(n.dot(push).abs() * self.span.dt);
            let ends = [(sa, ta.bead), (sb, tb.bead)];
            let answer = |d: V| self.answer(bodies, ends, d, &offsets);
            responses.push(Response::answered(&touch, answer)?);
            touches.push(touch);
            named.push(pair);
        }
        let mut strikes = Vec::new();
        resolve_impacts(&touches, &responses, &mut velocities, &mut strikes)?;
        // A pair a strike left in touch is held where a row joins it; a
        // bounce, or a pair that parts, is set aside.
        for (k, &pair) in named.iter().enumerate() {
            let (sa, sb) = (self.slot(pair.0), self.slot(pair.1));
            if sa != sb {
                continue;
            }
            let (ba, bb) = (self.beads[pair.0].bead, self.beads[pair.1].bead);
            let body = &mut bodies[self.bodies[sa]];
            if body.contact(ba, bb).is_none() {
                continue;
            }
            let (va, vb) = (
                velocities[flat(self, pair.0)],
                velocities[flat(self, pair.1)],
            );
            let n = touches[k].normal();
            let reach = self.beads[pair.0].radius + self.beads[pair.1].radius;
            let speeds = va.dot(va).sqrt() + vb.dot(vb).sqrt();
            if parts(n.dot(vb - va), reach, speeds) {
                body.hold(ba, bb, false);
            } else if let Some(last) = strikes.iter().rev().find(|s| s.touch == k) {
                body.hold(ba, bb, !last.bounced);
            }
        }
        for strike in strikes {
            let (a, b) = named[strike.touch];
            struck.push(StruckPair {
                a,
                b,
                time: self.time,
                strike,
            });
        }
        for (states, &offset) in self.now.iter_mut().zip(&offsets) {
            for (k, state) in states.iter_mut().enumerate() {
                state.velocity = velocities[offset + k];
            }
        }
        Ok(())
    }

    /// The answer of the group's velocities (side by side, each body's
    /// from its offset) to a unit impulse `−d` on the first of `ends` and
    /// `+d` on the second (each a body's slot and its bead there).
    pub(super) fn answer<B: TouchBody<V>>(
        &self,
        bodies: &mut [B],
        ends: [(usize, usize); 2],
        d: V,
        offsets: &[usize],
    ) -> Result<Vec<(usize, V)>, SolveError> {
        let mut changes = Vec::new();
        for ((slot, bead), sign) in ends.into_iter().zip([-1.0, 1.0]) {
            let answer =
                bodies[self.bodies[slot]].respond(self.time, &self.now[slot], bead, d * sign)?;
            changes.extend(
                answer
                    .into_iter()
                    .enumerate()
                    .map(|(k, dv)| (offsets[slot] + k, dv)),
            );
        }
        Ok(changes)
    }

    /// Holds every pair in touch now that closes at `e = 0` where a
    /// contact row joins it, and projects each such body's velocities
    /// onto its held rows: an inelastic strike of all of them at once
    /// (Moreau's), which striking pair by pair reaches only in the limit
    /// of infinitely many strikes where the pairs form a pile. Pairs the
    /// projection makes close are held too and the velocities projected
    /// again from where they were; a pair the projection would pull is
    /// let go again, unstruck.
    pub(super) fn press<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        struck: &mut Vec<StruckPair>,
    ) -> Result<(), TouchError> {
        let mut more = self.closing_at_zero(bodies);
        if more.is_empty() {
            return Ok(());
        }
        let mut pressed = Vec::new();
        let mut impulses = vec![Vec::new(); self.bodies.len()];
        let before = self.now.clone();
        // Each pass holds one pair more at least, so the passes end.
        for _ in 0..=self.pairs.len() {
            if more.is_empty() {
                break;
            }
            let mut slots = Vec::new();
            for &(slot, pair, _) in &more {
                let (ba, bb) = (self.beads[pair.0].bead, self.beads[pair.1].bead);
                bodies[self.bodies[slot]].hold(ba, bb, true);
                slots.push(slot);
            }
            slots.sort_unstable();
            slots.dedup();
            for slot in slots {
                let body = &mut bodies[self.bodies[slot]];
                let Some((velocities, pushes)) = body.press(self.time, &before[slot])? else {
                    continue;
                };
                for (state, v) in self.now[slot].iter_mut().zip(velocities) {
                    state.velocity = v;
                }
                impulses[slot] = pushes;
            }
            pressed.append(&mut more);
            more = self.closing_at_zero(bodies);
        }
        for (k, &(slot, pair, closing_speed)) in pressed.iter().enumerate() {
            let (ba, bb) = (self.beads[pair.0].bead, self.beads[pair.1].bead);
            let impulse = impulses[slot]
                .iter()
                .find(|&&(a, b, _)| (a, b) == (ba.min(bb), ba.max(bb)))
                .map_or(0.0, |p| p.2);
            if impulse <= 0.0 {
                bodies[self.bodies[slot]].hold(ba, bb, false);
                continue;
            }
            let friction_impulse = self.rub_pressed(bodies, slot, pair, impulse)?;
            struck.push(StruckPair {
                a: pair.0,
                b: pair.1,
                time: self.time,
                strike: Strike {
                    touch: k,
                    impulse,
                    closing_speed,
                    bounced: false,
                    friction_impulse,
                },
            });
        }
        Ok(())
    }

    /// Rubs a pair the press struck with `impulse` (both beads in the body
    /// in `slot`, their contact held): its slip opposed by at most its
    /// friction times the impulse, answered by the body with the held
    /// rows ([`rub`]). The friction impulse.
    pub(super) fn rub_pressed<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        slot: usize,
        pair: (usize, usize),
        impulse: f64,
    ) -> Result<f64, TouchError> {
        let (ta, tb) = (self.beads[pair.0], self.beads[pair.1]);
        let friction = ta.friction.min(tb.friction);
        if friction <= 0.0 {
            return Ok(0.0);
        }
        let states = &self.now[slot];
        let (xa, xb) = (states[ta.bead].position, states[tb.bead].position);
        let touch = Touch::between((ta.bead, xa, ta.radius), (tb.bead, xb, tb.radius), 0.0)?
            .with_friction(friction);
        let ends = [(slot, ta.bead), (slot, tb.bead)];
        let offsets = vec![0; self.bodies.len()];
        let tangents = touch
            .tangents()
            .into_iter()
            .map(|t| self.answer(bodies, ends, t, &offsets))
            .collect::<Result<_, _>>()?;
        let response = Response::new(&touch, Vec::new()).with_tangents(tangents);
        let mut velocities: Vec<V> = self.now[slot].iter().map(|s| s.velocity).collect();
        let rubbed = rub(&touch, friction * impulse, &response, &mut velocities);
        for (state, v) in self.now[slot].iter_mut().zip(velocities) {
            state.velocity = v;
        }
        Ok(rubbed)
    }

    /// The pairs in touch now, set aside by a contact row of one body,
    /// that close at `e = 0`: `(slot, pair, closing speed)`.
    pub(super) fn closing_at_zero<B: TouchBody<V>>(
        &self,
        bodies: &[B],
    ) -> Vec<(usize, (usize, usize), f64)> {
        let mut closing = Vec::new();
        for &pair in &self.pairs {
            let r = self.beads[pair.0].radius + self.beads[pair.1].radius;
            let (a, b) = (self.state(pair.0, false), self.state(pair.1, false));
            if !self.pressable(bodies, pair)
                || self.held(bodies, pair)
                || self.gap(pair, a.position, b.position) > TOUCHING * r
            {
                continue;
            }
            if let Some(speed) = self.closing(pair) {
                closing.push((self.slot(pair.0), pair, speed));
            }
        }
        closing
    }

    /// Whether pair `(i, j)` strikes at `e = 0` and a contact row of one
    /// body joins it: its strikes are that body's to press
    /// ([`Group::press`]), not pair by pair.
    pub(super) fn pressable<B: TouchBody<V>>(&self, bodies: &[B], (i, j): (usize, usize)) -> bool {
        let (a, b) = (self.beads[i], self.beads[j]);
        let slot = self.slot(i);
        a.restitution.min(b.restitution) == 0.0
            && slot == self.slot(j)
            && bodies[self.bodies[slot]].contact(a.bead, b.bead).is_some()
    }

    /// Whether pair `(i, j)`, its beads at `(a, b)`, meets slowly
    /// ([`meets_slowly`]) where a contact row of one body joins it: that
    /// body's step holds it, where the step would leave it overlapping,
    /// rather than the pair being struck where it meets.
    pub(super) fn meets_slowly<B: TouchBody<V>>(
        &self,
        bodies: &[B],
        (i, j): (usize, usize),
        (a, b): (BeadState<V>, BeadState<V>),
    ) -> bool {
        if !self.pressable(bodies, (i, j)) {
            return false;
        }
        let push = |k: usize| bodies[self.bodies[self.slot(k)]].push(self.beads[k].bead);
        let moved = step_speed([push(i), push(j)], self.span.dt);
        meets_slowly(0.0, -opening_rate(&a, &b).0, moved)
    }

    /// Whether pair `(i, j)`'s body ends its step holding the pair's
    /// contact row, time-stepped ([`TouchBody::ends_held`]).
    pub(super) fn ends_held<B: TouchBody<V>>(&self, bodies: &[B], (i, j): (usize, usize)) -> bool {
        let slot = self.slot(i);
        slot == self.slot(j)
            && bodies[self.bodies[slot]].ends_held(self.beads[i].bead, self.beads[j].bead)
    }

    /// Whether pair `(i, j)`, apart where the step began (gap `g0`) and
    /// where it ends, at `[a0, b0, a1, b1]`, is its body's step to have
    /// kept apart: a contact row of a body that time-steps joins it, and
    /// it came no nearer along its line of centres where the step began
    /// than its gap and half its reach. Such a body's step meets the row
    /// where it ends, so a pair that only turned about each other (whose
    /// straight paths from start to end cut a corner between them) has
    /// met nothing to strike; one that came so much nearer may have
    /// passed through the other within the step, and its instant is
    /// located.
    pub(super) fn stepped_past<B: TouchBody<V>>(
        &self,
        bodies: &[B],
        (i, j): (usize, usize),
        [a0, b0, a1, b1]: [BeadState<V>; 4],
        g0: f64,
    ) -> bool {
        let slot = self.slot(i);
        if !(self.pressable(bodies, (i, j)) && bodies[self.bodies[slot]].time_steps()) {
            return false;
        }
        let d0 = b0.position - a0.position;
        let length = d0.dot(d0).sqrt();
        if length.is_nan() || length <= 0.0 {
            return false;
        }
        let approach = -(d0 / length).dot((b1.position - a1.position) - d0);
        let reach = self.beads[i].radius + self.beads[j].radius;
        approach <= g0 + 0.5 * reach
    }

    /// Whether a contact row holds pair `(i, j)` now: pressed together,
    /// the two answer a strike as one and do not strike each other.
    pub(super) fn held<B: TouchBody<V>>(&self, bodies: &[B], (i, j): (usize, usize)) -> bool {
        let slot = self.slot(i);
        let (a, b) = (self.beads[i].bead, self.beads[j].bead);
        slot == self.slot(j) && bodies[self.bodies[slot]].contact(a, b) == Some(true)
    }
}
