//! Which rows an island's step may hold where it would end violating
//! them: contact rows whose beads touch where it starts, meetings at
//! `e = 0` taken by the step (slow, near its start, or every one in an
//! island that time-steps), and landings on one-sided wires taken at the
//! step's end or, time-stepped, held from its start (see
//! [`Island::step_at`]).

use crate::geometry::WireSpace;

use super::{Island, IslandMark, IslandWork, OFF_THE_WIRE, TOUCHING};
use super::{closes, meets_near, meets_slowly, step_speed};
use crate::solver::contact::ContactEvent;
use crate::solver::settings::StepSettings;
use crate::solver::state::{BeadState, LinearForce};

impl<V: WireSpace> Island<V> {
    /// Reports as landed at the step's end each one-sided wire row whose
    /// bead was in flight where the step began (set aside in `mark`) or
    /// left at its start, and that the step held
    /// ([`Island::time_steps`]), with the speed it closed on its wire at
    /// `start`.
    pub(super) fn report_stepped_landings(
        &self,
        (time, end): (f64, f64),
        start: &[BeadState<V>],
        states: &[BeadState<V>],
        mark: &IslandMark<V>,
        work: &mut IslandWork<V>,
    ) {
        for r in 0..self.rows() {
            let event = |landing: bool| {
                work.events.iter().any(|&(row, _, event)| {
                    row == r && matches!(event, ContactEvent::Landed { .. }) == landing
                })
            };
            // Set aside where the step began, or left at its start, and
            // held at its end with no landing reported.
            let landed = work.landing_slowly.get(r) == Some(&true)
                && work.touching.get(r) == Some(&true)
                && work.holds(r)
                && (!mark.holds(r) || event(false))
                && !event(true);
            if !landed {
                continue;
            }
            self.report_landed_at_end(r, (time, end), (start, states), work);
        }
    }

    /// Reports the bead of one-sided wire row `r` landed at the step's
    /// `end` where it is in `states`, with the speed it closed on its wire
    /// at the step's `start` (at `time`): a landing the step took rather
    /// than located.
    pub(super) fn report_landed_at_end(
        &self,
        r: usize,
        (time, end): (f64, f64),
        (start, states): (&[BeadState<V>], &[BeadState<V>]),
        work: &mut IslandWork<V>,
    ) {
        let bead = self.entry_bead[self.row_start[r]];
        let normal_speed = self
            .wire_gap(r, start, time)
            .map_or(0.0, |(_, rate)| rate.abs());
        work.events.push((
            r,
            bead,
            ContactEvent::Landed {
                time: end,
                position: states[bead].position,
                normal_speed,
                bounced: false,
            },
        ));
    }

    /// The rows set aside that the step may hold (`work.touching`) and
    /// that it leaves violated at `work.x` at `time`: contact rows whose
    /// beads overlap by more than [`TOUCHING`] of their reach, and, in an
    /// island that time-steps ([`Island::time_steps`]), one-sided wire
    /// rows whose beads end on or behind their wires. Those the step
    /// holds and is taken again with.
    pub(super) fn overlapping(&self, work: &IslandWork<V>, time: f64) -> Vec<usize> {
        (0..self.rows())
            .filter(|&r| {
                work.inactive[r]
                    && work.touching.get(r) == Some(&true)
                    && match self.contact_gap(r, &work.x) {
                        Some((gap, reach)) => gap < -TOUCHING * reach,
                        None => self.in_front(r, &work.x, time).is_some_and(|c| c <= 0.0),
                    }
            })
            .collect()
    }

    /// Holds the rows [`Island::overlapping`] finds at `work.time`.
    /// Whether there were any.
    pub(super) fn hold_overlapping(&self, work: &mut IslandWork<V>) -> bool {
        let more = self.overlapping(work, work.time);
        for &r in &more {
            work.inactive[r] = false;
        }
        !more.is_empty()
    }

    /// Marks the contact rows the step may hold where it would leave their
    /// beads overlapping: those whose beads touch at `states` (the step's
    /// start) and do not close within the step ([`closes`]), and, for a
    /// step that keeps its rows on their constraints (RATTLE, or one that
    /// projects), those whose beads meet slowly or near the step's start
    /// at `e = 0` ([`Island::slow_meeting`]). A pair in touch that closes,
    /// or one apart that meets later and faster, is the touch
    /// settlement's to strike.
    pub(super) fn touching(
        &self,
        states: &[BeadState<V>],
        forces: &[LinearForce<V>],
        settings: &StepSettings,
        whole: f64,
        work: &mut IslandWork<V>,
    ) {
        work.touching.clear();
        if !self.contacts.contains(&true) || states.len() != self.beads() {
            return;
        }
        let exact = settings.method.ends_on_constraints();
        // A dense island time-steps every meeting at `e = 0`.
        let stepped = exact && self.time_steps();
        let dt = settings.dt;
        work.x.clear();
        work.x.extend(states.iter().map(|s| s.position));
        for r in 0..self.rows() {
            let (Some((gap, reach)), Some((rate, _, speeds))) =
                (self.contact_gap(r, &work.x), self.opening(r, states))
            else {
                work.touching.push(false);
                continue;
            };
            let holds = (gap <= TOUCHING * reach && !closes(rate, reach, speeds, dt))
                || (stepped && self.sides[r].1 == 0.0)
                || (exact && self.slow_meeting(r, (gap, rate), states, forces, (dt, whole)));
            work.touching.push(holds);
        }
    }

    /// The rows set aside at `states` (at `time`) that an island which
    /// time-steps ([`Island::time_steps`]) holds from the step's start
    /// before its first pass: those of restitution 0 it may hold
    /// (`work.touching`) whose
    /// gap, closing at its rate now and at the speed a step of `dt` of
    /// the forces gives, would close within the step. Holding them at
    /// once, rather than each where a pass finds it overlapping, saves a
    /// pass for every layer of a pile a landing stops; the position solve
    /// lets go of those whose multipliers then pull
    /// ([`Island::let_go_pulling`]).
    pub(super) fn closing_within(
        &self,
        time: f64,
        states: &[BeadState<V>],
        forces: &[LinearForce<V>],
        dt: f64,
        work: &mut IslandWork<V>,
    ) -> Vec<usize> {
        if states.len() != self.beads() || forces.len() != self.beads() {
            return Vec::new();
        }
        work.x.clear();
        work.x.extend(states.iter().map(|s| s.position));
        let work = &*work;
        let push = |i: usize| forces[i].at(states[i].position) * self.inverse_mass[i];
        (0..self.rows())
            .filter(|&r| {
                self.sides[r].1 == 0.0
                    && work.inactive.get(r) == Some(&true)
                    && work.touching.get(r) == Some(&true)
            })
            .filter(|&r| {
                let (gap, rate, slow) = match self.contact_pair(r) {
                    Some((a, b, _)) => {
                        let (Some((gap, _)), Some((rate, ..))) =
                            (self.contact_gap(r, &work.x), self.opening(r, states))
                        else {
                            return false;
                        };
                        (gap, rate, step_speed([push(a), push(b)], dt))
                    }
                    None => {
                        let bead = self.entry_bead[self.row_start[r]];
                        let Some((gap, rate)) = self.wire_gap(r, states, time) else {
                            return false;
                        };
                        (gap, rate, step_speed([push(bead), V::ZERO], dt))
                    }
                };
                gap + (rate - slow) * dt <= 0.0
            })
            .collect()
    }

    /// Whether contact row `r`'s beads, `gap` apart and opening at `rate`
    /// where they are in `states`, meet within a step of `dt` (a part of
    /// one of `whole`) no faster than a whole step's forces move them
    /// (each bead's `|f| / m` times `whole`, summed), where the pair's
    /// restitution is 0 (see [`Island::set_contact_restitution`] and
    /// [`meets_slowly`]), or meets within [`NEAR_MEETING`](super::NEAR_MEETING) of the step's
    /// start ([`meets_near`]). Such a pair is not struck at
    /// the instant it meets: the step holds its row, as it does a pair
    /// pressed together, so that it ends the step in touch (the pair
    /// meets within the step, a plastic impact spread over it). A pile
    /// settling at `e = 0` so takes its countless slow meetings within
    /// its steps, where cutting the step at each would not end
    /// (inelastic collapse), as it takes the meetings across gaps of a
    /// hair by which its beads pass their momentum on; a strike faster
    /// than its forces and later in the step is still located at its
    /// instant.
    fn slow_meeting(
        &self,
        r: usize,
        (gap, rate): (f64, f64),
        states: &[BeadState<V>],
        forces: &[LinearForce<V>],
        (dt, whole): (f64, f64),
    ) -> bool {
        let Some((a, b, _)) = self.contact_pair(r) else {
            return false;
        };
        let push = |i: usize| match (forces.get(i), states.get(i)) {
            (Some(force), Some(state)) => force.at(state.position) * self.inverse_mass[i],
            _ => V::ZERO,
        };
        let slow = step_speed([push(a), push(b)], whole);
        let restitution = self.sides[r].1;
        (meets_slowly(restitution, -rate, slow) && gap <= 2.0 * slow * dt)
            || meets_near(restitution, gap, -rate, whole)
    }

    /// Marks the one-sided wire rows whose beads are off their wires at
    /// `states` (at `time`) and would land slowly
    /// ([`Island::lands_slowly`]) in a step of `dt`, a part of one of
    /// `whole`; whether a bead is in flight is the step's to say.
    ///
    /// In an island that time-steps (`exact`, a step that keeps its rows
    /// on their constraints, and [`Island::time_steps`]), every such row
    /// of restitution 0 whose bead is not behind its wire (in flight, or
    /// on it and free to leave at the step's start) is marked, and may be
    /// held (`work.touching`): where the step leaves it set aside and
    /// would end it on or behind the wire, the step holds it from its
    /// start and is taken again, so that the bead lands plastically
    /// within the step.
    pub(super) fn landing_slowly(
        &self,
        time: f64,
        states: &[BeadState<V>],
        forces: &[LinearForce<V>],
        (dt, whole): (f64, f64),
        exact: bool,
        work: &mut IslandWork<V>,
    ) {
        let stepped = exact && self.time_steps() && states.len() == self.beads();
        if stepped {
            work.touching.resize(self.rows(), false);
            work.x.clear();
            work.x.extend(states.iter().map(|s| s.position));
        }
        work.landing_slowly.clear();
        for r in 0..self.rows() {
            let (side, restitution) = self.sides[r];
            if side == 0.0 || self.contacts[r] {
                work.landing_slowly.push(false);
                continue;
            }
            // In flight, or on the wire (it may leave at the step's
            // start): not behind it, nor past an end.
            let not_behind = || {
                self.in_front(r, &work.x, time)
                    .is_some_and(|c| c >= -OFF_THE_WIRE * self.rows[r].scale())
                    && self.past_end(r, states, time, &work.hints) <= 0.0
            };
            let by_step = stepped && restitution == 0.0 && not_behind();
            if by_step {
                work.touching[r] = true;
            }
            work.landing_slowly
                .push(by_step || self.lands_slowly(r, time, states, forces, (dt, whole)));
        }
    }

    /// Whether one-sided wire row `r`'s bead, in flight in `states` at
    /// `time`, reaches its wire within a step of `dt` (a part of one of
    /// `whole`) no faster than a whole step's forces move it (`|f| / m`
    /// times `whole`), where the wire's restitution is 0: within twice
    /// that speed times the step of it and closing no faster ([`meets_slowly`],
    /// as for a pair of beads). Such a landing is not located at its
    /// instant: the bead lands at the step's end ([`Island::land`]), moved
    /// back onto its wire by no more than its forces move it in the step.
    /// The beads of a pile settling at `e = 0` in a one-sided bowl leave
    /// it and land again countless times at such speeds, where cutting the
    /// step at each would not end; a landing faster than its forces is
    /// still located at its instant.
    fn lands_slowly(
        &self,
        r: usize,
        time: f64,
        states: &[BeadState<V>],
        forces: &[LinearForce<V>],
        (dt, whole): (f64, f64),
    ) -> bool {
        let restitution = self.sides[r].1;
        let bead = self.entry_bead[self.row_start[r]];
        let (Some(state), Some(force)) = (states.get(bead), forces.get(bead)) else {
            return false;
        };
        let Some((gap, rate)) = self.wire_gap(r, states, time) else {
            return false;
        };
        let closing = -rate;
        let push = force.at(state.position) * self.inverse_mass[bead];
        let slow = step_speed([push, V::ZERO], whole);
        gap > 0.0 && meets_slowly(restitution, closing, slow) && gap <= 2.0 * slow * dt
    }
}
