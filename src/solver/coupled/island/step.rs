//! [`Island::step`]: the outline of an island's step, the Euler steps and
//! the divergence check, and the substeps a step is halved into where its
//! Newton solve finds no root.

use crate::geometry::WireSpace;

use super::integrators::Stage;
use super::projection::Restore;
use super::{
    CALM_STEPS, CONTACT_PASSES, Island, IslandWork, MAX_HALVINGS, OFF_THE_WIRE, RoughRow, TOUCHING,
};
use super::{closes, meets_near, meets_slowly, step_speed};
use crate::solver::contact::locate;
use crate::solver::euler::{explicit_euler_lanes, semi_implicit_euler_lanes};
use crate::solver::method::Method;
use crate::solver::settings::StepSettings;
use crate::solver::solve::SolveError;
use crate::solver::state::{BeadState, LinearForce};
use crate::solver::step::drift_check;

/// A step as [`Island::cut_within`] takes it again: where and when it
/// started, its forces and settings, the substep level it started at, and
/// the rows the event may happen on.
struct Flight<'a, V> {
    time: f64,
    start: &'a [BeadState<V>],
    forces: &'a [LinearForce<V>],
    settings: &'a StepSettings,
    level: u32,
    calm: u32,
    rows: &'a [usize],
    /// The one-sided rows a bead may land on ([`Island::above`]).
    above: &'a [usize],
}

/// What [`Island::cut_within`] cuts a step at.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Cut {
    /// A bead in flight crosses its one-sided wire: it lands.
    Landing,
    /// A bead passes an end of its wire: it leaves it.
    End,
}

impl<V: WireSpace> Island<V> {
    /// One step of every bead of the island under `settings`: `states`
    /// (one per bead) advance, `forces` (one per bead, gravity included)
    /// are the external forces. On an error the states are left as they
    /// were. What the step reports of each row is in
    /// [`IslandWork<V>::rows`].
    ///
    /// Where a Newton solve (RATTLE's positions, projection) finds no
    /// root, as when a rope's free end whips round faster than a step can
    /// follow, that part of the step and the rest of it are taken in
    /// substeps of half the length, halved again if need be, down to
    /// 2⁶ = 64 substeps. The next step starts as finely as this
    /// one ended, and tries one halving fewer after eight steps
    /// that needed no more, so a long rope does not fail its way down to
    /// the same level every step; [`IslandWork<V>::substeps`] says how many
    /// the last step took.
    pub fn step(
        &self,
        states: &mut [BeadState<V>],
        forces: &[LinearForce<V>],
        settings: &StepSettings,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        self.step_at(0.0, states, forces, settings, work)
    }

    /// [`Island::step`] for a step that starts at time `time`: the time
    /// at which wires on a path (see [`Island::move_wire`]) are placed.
    ///
    /// A contact row set aside whose beads touched at the step's start
    /// and that the step leaves overlapping by more than [`TOUCHING`] of
    /// their reach is held and the step taken again from its start, so a
    /// pile pressing on itself settles within the step (RATTLE does the
    /// same within its position solve first, and a post-stabilizing step
    /// within its projection, where a pass costs less). A row held is not
    /// let go by the step taken again, so the passes end: at most 16 more
    /// than the island has rows. A step that keeps its rows on their
    /// constraints (RATTLE, or one that projects) holds in the same way
    /// a row whose beads meet slowly at `e = 0`, or within
    /// [`NEAR_MEETING`](super::NEAR_MEETING) of the step's start
    /// ([`Island::set_contact_restitution`]): they end the step in touch.
    /// A bead in flight that reaches a one-sided wire of restitution 0 no
    /// faster than the step's forces move it lands at the step's end, not
    /// at its instant.
    pub fn step_at(
        &self,
        time: f64,
        states: &mut [BeadState<V>],
        forces: &[LinearForce<V>],
        settings: &StepSettings,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        self.step_part(time, states, forces, settings, settings.dt, work)
    }

    /// [`Island::step_at`] for a part of a step of `whole` seconds
    /// (`settings` being the part's, [`StepSettings::part`]), as the touch
    /// settlement takes the rest of a step it cut: which pairs meet slowly
    /// (see [`Island::step_at`]) is judged by what the whole step's
    /// forces give them.
    pub fn step_part(
        &self,
        time: f64,
        states: &mut [BeadState<V>],
        forces: &[LinearForce<V>],
        settings: &StepSettings,
        whole: f64,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        self.touching(states, forces, settings, whole, work);
        self.landing_slowly(time, states, forces, (settings.dt, whole), work);
        if !work.touching.contains(&true) {
            // Nothing in touch: no row the step could press to hold.
            return self.step_holding(time, states, forces, settings, &[], work);
        }
        let start = states.to_vec();
        let mark = work.mark();
        let mut hold = Vec::new();
        let passes = self.rows() + CONTACT_PASSES;
        for pass in 1..=passes {
            self.step_holding(time, states, forces, settings, &hold, work)?;
            work.x.clear();
            work.x.extend(states.iter().map(|s| s.position));
            let more = self.overlapping(work);
            if more.is_empty() || pass == passes {
                break;
            }
            hold.extend(more);
            states.copy_from_slice(&start);
            work.rewind(&mark);
        }
        Ok(())
    }

    /// The contact rows set aside whose beads touched where the step
    /// began and overlap at `work.x` by more than [`TOUCHING`] of their
    /// reach: those the step holds and is taken again with.
    pub(super) fn overlapping(&self, work: &IslandWork<V>) -> Vec<usize> {
        (0..self.rows())
            .filter(|&r| {
                work.inactive[r]
                    && work.touching.get(r) == Some(&true)
                    && self
                        .contact_gap(r, &work.x)
                        .is_some_and(|(gap, reach)| gap < -TOUCHING * reach)
            })
            .collect()
    }

    /// Holds the rows [`Island::overlapping`] finds. Whether there were
    /// any.
    pub(super) fn hold_overlapping(&self, work: &mut IslandWork<V>) -> bool {
        let more = self.overlapping(work);
        for &r in &more {
            work.inactive[r] = false;
        }
        !more.is_empty()
    }

    /// One pass of [`Island::step_at`], the contact rows `hold` held from
    /// its start.
    fn step_holding(
        &self,
        time: f64,
        states: &mut [BeadState<V>],
        forces: &[LinearForce<V>],
        settings: &StepSettings,
        hold: &[usize],
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        work.events.clear();
        self.begin(time, states, work);
        let one_sided = self.one_sided();
        let rough = self.is_rough();
        let ends = self.has_ends();
        if one_sided || rough || ends {
            let pushing = settings.method.ends_on_constraints();
            self.leave(time, states, forces, pushing, work)?;
        }
        for &r in hold {
            work.inactive[r] = false;
        }
        let mut resisted = Vec::new();
        let slides = if rough && states.len() == self.beads() && forces.len() == self.beads() {
            resisted.extend_from_slice(forces);
            self.resist(time, states, &mut resisted, work)
        } else {
            Vec::new()
        };
        let forces = if rough { &resisted[..] } else { forces };
        let above = if one_sided {
            self.above(time, states, work)
        } else {
            Vec::new()
        };
        let flying: Vec<usize> = above
            .iter()
            .copied()
            .filter(|&r| self.sides[r].0 * self.wire_row(r, states, time).c > 0.0)
            .filter(|&r| work.landing_slowly.get(r) != Some(&true))
            .collect();
        let ending = if ends {
            (0..self.rows())
                .filter(|&r| self.ends(r) && !work.inactive[r])
                .collect()
        } else {
            Vec::new()
        };
        let start = (!flying.is_empty() || !ending.is_empty())
            .then(|| (states.to_vec(), work.level, work.calm));
        self.substeps(time, states, forces, settings, work)?;
        if let Some((start, level, calm)) = &start {
            let flight = |rows| Flight {
                time,
                start,
                forces,
                settings,
                level: *level,
                calm: *calm,
                rows,
                above: &above,
            };
            let end = time + settings.dt;
            if !ending.is_empty() && self.on_the_wire(end, states, &ending, work) < 0.0 {
                // Past an end within the step: the bead leaves there (a
                // landing the same step makes is taken at its end).
                self.cut_within(&flight(&ending), Cut::End, states, work)?;
            } else if !flying.is_empty() && self.crossing(end, states, &flying, work) <= 0.0 {
                self.cut_within(&flight(&flying), Cut::Landing, states, work)?;
            }
        }
        if one_sided {
            // A landing the located one left (another row, or a bounce
            // that came back), at the step's end.
            self.land(
                time + settings.dt,
                states,
                forces,
                settings.dt,
                &above,
                work,
            )?;
        }
        if rough {
            self.stop(time + settings.dt, states, &slides, work)?;
        }
        self.follow(time + settings.dt, states, work);
        Ok(())
    }

    /// Marks the contact rows the step may hold where it would leave their
    /// beads overlapping: those whose beads touch at `states` (the step's
    /// start) and do not close within the step ([`closes`]), and, for a
    /// step that keeps its rows on their constraints (RATTLE, or one that
    /// projects), those whose beads meet slowly or near the step's start
    /// at `e = 0` ([`Island::slow_meeting`]). A pair in touch that closes,
    /// or one apart that meets later and faster, is the touch
    /// settlement's to strike.
    fn touching(
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
                || (exact && self.slow_meeting(r, (gap, rate), states, forces, (dt, whole)));
            work.touching.push(holds);
        }
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
    fn landing_slowly(
        &self,
        time: f64,
        states: &[BeadState<V>],
        forces: &[LinearForce<V>],
        (dt, whole): (f64, f64),
        work: &mut IslandWork<V>,
    ) {
        work.landing_slowly.clear();
        work.landing_slowly.extend((0..self.rows()).map(|r| {
            self.sides[r].0 != 0.0
                && !self.contacts[r]
                && self.lands_slowly(r, time, states, forces, (dt, whole))
        }));
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
        let (side, restitution) = self.sides[r];
        let bead = self.entry_bead[self.row_start[r]];
        let (Some(state), Some(force)) = (states.get(bead), forces.get(bead)) else {
            return false;
        };
        let row = self.wire_row(r, states, time);
        let length = row.normal.dot(row.normal).sqrt();
        if length.is_nan() || length <= 0.0 {
            return false;
        }
        let gap = side * row.c / length;
        let closing = -side * row.normal.dot(state.velocity - row.wire) / length;
        let push = force.at(state.position) * self.inverse_mass[bead];
        let slow = step_speed([push, V::ZERO], whole);
        gap > 0.0 && meets_slowly(restitution, closing, slow) && gap <= 2.0 * slow * dt
    }

    /// The one-sided rows set aside that a bead may land on within the
    /// step: those whose bead has not passed an end of the wire, and, on
    /// a wire with ends or one that catches, is not behind it (off it on
    /// the side it pushes toward, or on it). A bead behind a wire with no
    /// end crossed it (it could not go round) and lands; one that went
    /// round an end, or a marble under another track, does not.
    fn above(&self, time: f64, states: &[BeadState<V>], work: &IslandWork<V>) -> Vec<usize> {
        if states.len() != self.beads() {
            return Vec::new();
        }
        (0..self.rows())
            .filter(|&r| self.sides[r].0 != 0.0 && work.inactive[r] && !self.contacts[r])
            .filter(|&r| {
                let behind = || {
                    self.sides[r].0 * self.wire_row(r, states, time).c
                        < -OFF_THE_WIRE * self.rows[r].scale()
                };
                let strict = self.catching[r] || self.ends(r);
                !(strict && behind()) && self.past_end(r, states, time, &work.hints) <= 0.0
            })
            .collect()
    }

    /// How far the nearest of `rows` is from crossing its wire at `time`:
    /// the least `side · C` (not positive once one has crossed) of the
    /// rows whose beads have not passed an end.
    fn crossing(
        &self,
        time: f64,
        states: &[BeadState<V>],
        rows: &[usize],
        work: &IslandWork<V>,
    ) -> f64 {
        rows.iter()
            .filter(|&&r| self.past_end(r, states, time, &work.hints) <= 0.0)
            .map(|&r| self.sides[r].0 * self.wire_row(r, states, time).c)
            .fold(f64::INFINITY, f64::min)
    }

    /// How far the bead of the nearest of `rows` is from an end of its
    /// wire at `time`: the least `−past end` (negative once one has passed).
    fn on_the_wire(
        &self,
        time: f64,
        states: &[BeadState<V>],
        rows: &[usize],
        work: &IslandWork<V>,
    ) -> f64 {
        rows.iter()
            .map(|&r| -self.past_end(r, states, time, &work.hints))
            .fold(f64::INFINITY, f64::min)
    }

    /// Sets aside each of `rows` whose bead is at or past an end of its
    /// wire at `time`: the bead leaves the wire there.
    fn leave_at_ends(
        &self,
        time: f64,
        states: &[BeadState<V>],
        rows: &[usize],
        work: &mut IslandWork<V>,
    ) {
        for &r in rows {
            if self.past_end(r, states, time, &work.hints) >= 0.0 {
                work.inactive[r] = true;
                self.report_left(r, time, states, work);
            }
        }
    }

    /// An event within the step located where it happens, as a lone
    /// bead's is ([`locate`]): a flight that crossed a wire lands there
    /// ([`Island::land`]); a bead that passed an end of its wire leaves it
    /// there. The step is taken again to the instant, the event happens,
    /// and the rest of the step follows from there. Each trial step starts
    /// from the same substep level. If a trial step fails, the step is
    /// kept as it was taken whole (to land at its end; a bead past an end
    /// leaves at the next step's start).
    fn cut_within(
        &self,
        flight: &Flight<V>,
        cut: Cut,
        states: &mut [BeadState<V>],
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        let Flight {
            time,
            start,
            forces,
            settings,
            rows,
            ..
        } = *flight;
        let whole = states.to_vec();
        let (level, calm, events) = (work.level, work.calm, work.events.len());
        let inactive = work.inactive.clone();
        let trial = |tau: f64, states: &mut [BeadState<V>], work: &mut IslandWork<V>| {
            states.copy_from_slice(start);
            (work.level, work.calm) = (flight.level, flight.calm);
            self.substeps(time, states, forces, &settings.part(tau), work)
        };
        let measure = |time: f64, states: &[BeadState<V>], work: &IslandWork<V>| match cut {
            Cut::Landing => self.crossing(time, states, rows, work),
            Cut::End => self.on_the_wire(time, states, rows, work),
        };
        let mut probe = start.to_vec();
        let g0 = measure(time, start, work);
        let located = locate(settings.dt, g0, |tau| {
            trial(tau, &mut probe, work)?;
            Ok(measure(time + tau, &probe, work))
        });
        let cut_there = located.and_then(|tau| {
            trial(tau, states, work)?;
            match cut {
                Cut::Landing => {
                    self.land(time + tau, states, forces, settings.dt, flight.above, work)?;
                }
                Cut::End => self.leave_at_ends(time + tau, states, rows, work),
            }
            let rest = settings.dt - tau;
            if rest > 1e-13 * settings.dt {
                self.substeps(time + tau, states, forces, &settings.part(rest), work)?;
            }
            Ok(())
        });
        if cut_there.is_err() {
            states.copy_from_slice(&whole);
            (work.level, work.calm) = (level, calm);
            work.events.truncate(events);
            work.inactive = inactive;
        }
        Ok(())
    }

    /// Sets the rows a fresh `work` starts with at `states` (as its first
    /// step would), so that what it carries can be kept
    /// ([`IslandWork::mark`]) before that step. A work that has stepped is
    /// left as it is.
    pub fn begin(&self, time: f64, states: &[BeadState<V>], work: &mut IslandWork<V>) {
        if work.inactive.len() != self.rows() {
            self.start_rows(time, states, work);
        }
    }

    /// Which rows a fresh island starts with: a bead that starts off a
    /// one-sided wire, on the side it pushes toward (or on either side of
    /// a wire that catches it, see [`Island::set_catching`]), or past an
    /// end of its wire, starts in flight (a row told otherwise by
    /// [`IslandWork::carry`] starts as it was told); a
    /// contact starts set aside;
    /// stick rows start set aside (a bead slides until friction stops it),
    /// but a bead at rest on a rough wire starts held by static friction.
    pub(super) fn start_rows(&self, time: f64, states: &[BeadState<V>], work: &mut IslandWork<V>) {
        let whole = states.len() == self.beads();
        work.inactive.clear();
        work.inactive.resize(self.rows(), false);
        for rough in self.rough.iter().flatten() {
            if let Some(s) = rough.stick {
                work.inactive[s] = true;
            }
        }
        let ends = self.has_ends();
        for r in 0..self.rows() {
            let (side, _) = self.sides[r];
            if !whole || (side == 0.0 && !ends) {
                continue;
            }
            // A contact is held only once its beads press (see
            // `Island::set_contact`).
            let c = || self.wire_row(r, states, time).c;
            let off = OFF_THE_WIRE * self.rows[r].scale();
            let apart = side != 0.0
                && (self.contacts[r] || side * c() > off || (self.catching[r] && c().abs() > off));
            if apart || (ends && self.ends(r) && self.past_end(r, states, time, &work.hints) > 0.0)
            {
                work.inactive[r] = true;
            }
        }
        // What a rebuilt island carries over (see `IslandWork::carry`).
        for (r, carried) in work.carried.iter().enumerate().take(self.rows()) {
            if let (Some(held), false) = (carried, self.contacts[r]) {
                work.inactive[r] = !held;
            }
        }
        // A bead at rest on a rough wire starts held by static friction.
        for (r, rough) in self.rough.iter().enumerate() {
            let Some(RoughRow { stick: Some(s), .. }) = rough else {
                continue;
            };
            let bead = self.entry_bead[self.row_start[r]];
            if work.inactive[r] || self.paths[r].is_some() || !whole || self.contacts[r] {
                continue;
            }
            let row = self.wire_row(r, states, time);
            if states[bead].velocity == row.wire
                && let Some(axis) = row.tangent()
            {
                self.place_stick(*s, axis, axis.dot(states[bead].position), work);
            }
        }
        // A pair with friction touching at rest starts pressed together
        // (rubbing from its first step), held by static friction where
        // it has a stick row.
        if !whole {
            return;
        }
        work.x.clear();
        work.x.extend(states.iter().map(|s| s.position));
        for (r, rough) in self.rough.iter().enumerate() {
            let Some(rough) = rough else { continue };
            let touches = self
                .contact_gap(r, &work.x)
                .is_some_and(|(gap, reach)| gap.abs() <= TOUCHING * reach);
            let Some((n, _)) = self.pair_slip(r, states).filter(|_| touches) else {
                continue;
            };
            let Some((a, b, _)) = self.contact_pair(r) else {
                continue;
            };
            if states[a].velocity != states[b].velocity {
                continue;
            }
            work.inactive[r] = false;
            if let Some(s) = rough.stick {
                self.place_pair_stick(s, n, r, states, work);
            }
        }
    }

    /// The step of length `settings.dt` as `2^level` equal substeps, from
    /// the level the last step ended at (one level fewer after
    /// [`CALM_STEPS`] steps that needed no more). Where a substep's Newton
    /// solve finds no root, it and the rest of the step are taken at half
    /// the length, down to 2^[`MAX_HALVINGS`] substeps. On an error the
    /// states are left as they were.
    fn substeps(
        &self,
        time: f64,
        states: &mut [BeadState<V>],
        forces: &[LinearForce<V>],
        settings: &StepSettings,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        let was = work.level.min(MAX_HALVINGS);
        let mut level = if work.calm >= CALM_STEPS {
            was.saturating_sub(1)
        } else {
            was
        };
        let first = level;
        work.substeps = 0;
        work.start.clear();
        work.start.extend_from_slice(states);
        // Progress through the step in its finest substeps.
        let finest = 1u64 << MAX_HALVINGS;
        let mut done = 0u64;
        while done < finest {
            let fraction = (done as f64) / (finest as f64);
            let piece = StepSettings {
                dt: settings.dt / f64::from(1u32 << level),
                ..*settings
            };
            match self.advance(time + fraction * settings.dt, states, forces, &piece, work) {
                Ok(()) => done += finest >> level,
                Err(SolveError::NoConvergence { .. }) if level < MAX_HALVINGS => level += 1,
                Err(error) => {
                    states.copy_from_slice(&work.start);
                    return Err(error);
                }
            }
        }
        work.calm = if level == first && first == was {
            work.calm + 1
        } else {
            0
        };
        work.level = level;
        Ok(())
    }

    /// One step of length `settings.dt`, with no halving.
    fn advance(
        &self,
        time: f64,
        states: &mut [BeadState<V>],
        forces: &[LinearForce<V>],
        settings: &StepSettings,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        let n = self.beads();
        if states.len() != n || forces.len() != n {
            return Err(SolveError::WrongLength {
                beads: n,
                states: states.len(),
                forces: forces.len(),
            });
        }
        if states.iter().any(|s| !s.is_finite()) {
            return Err(SolveError::NonFinite);
        }
        work.x0.clear();
        work.x0.extend(states.iter().map(|s| s.position));
        work.v0.clear();
        work.v0.extend(states.iter().map(|s| s.velocity));
        let h = settings.dt;
        let gains = settings.gains();
        work.time = time;
        match settings.method {
            Method::Rattle => self.rattle(forces, h, work)?,
            Method::ExplicitEuler(_) | Method::SemiImplicitEuler(_) => {
                self.accelerate(forces, gains, work, Stage::Start)?;
                let euler = if matches!(settings.method, Method::SemiImplicitEuler(_)) {
                    semi_implicit_euler_lanes
                } else {
                    explicit_euler_lanes
                };
                for i in 0..n {
                    let (x, v, a) = (work.x0[i], work.v0[i], work.acceleration[i]);
                    (work.x[i], work.v[i]) = euler(x, v, a, h);
                }
                self.keep_lambda(work);
            }
            Method::Rk4(_) => self.rk4(forces, gains, h, work)?,
        }
        if work.x.iter().chain(&work.v).any(|p| !p.is_finite()) {
            return Err(SolveError::NonFinite);
        }
        work.time = time + h;
        self.evaluate_at_new(work);
        for r in 0..self.rows() {
            let c = work.c[r];
            let (bound, within) = drift_check(settings, c, self.rows[r].scale());
            if !within {
                return Err(SolveError::DriftExceeded { c, bound });
            }
        }
        if settings.method.projects() {
            let rough = self.is_rough();
            let restore = if self.moves() {
                // A moving wire does work: there is no energy or speed to keep.
                Restore::Nothing
            } else if settings.method.is_euler() {
                // Friction is in the kick (the forces it is given).
                Restore::Speed(settings.dt)
            } else if rough {
                // Friction takes energy away: none to keep.
                Restore::Nothing
            } else {
                Restore::Energy
            };
            self.project(forces, restore, work)?;
        }
        work.bead_forces.clear();
        work.bead_forces.resize(n, V::ZERO);
        for (r, report) in work.reports.iter_mut().enumerate() {
            report.c = work.c[r];
            report.c_dot = self.rate(r, &work.gradient, &work.v, &work.bias);
            let entries = self.row_start[r]..self.row_start[r + 1];
            for (&bead, g) in self.entry_bead[entries.clone()]
                .iter()
                .zip(&work.gradient[entries])
            {
                work.bead_forces[bead] += *g * report.lambda;
            }
        }
        for (state, (x, v)) in states.iter_mut().zip(work.x.iter().zip(&work.v)) {
            state.position = *x;
            state.velocity = *v;
        }
        work.substeps += 1;
        Ok(())
    }
}
