//! Events an island's step locates within it, as a lone bead's are: a
//! flight that crosses its one-sided wire lands where it crosses, a bead
//! that passes an end of its wire leaves it there ([`Island::cut_within`]).

use crate::geometry::WireSpace;

use super::{Island, IslandWork};
use crate::solver::contact::locate;
use crate::solver::settings::StepSettings;
use crate::solver::solve::SolveError;
use crate::solver::state::{BeadState, LinearForce};

/// A step as [`Island::cut_within`] takes it again: where and when it
/// started, its forces and settings, the substep level it started at, and
/// the rows the event may happen on.
pub(super) struct Flight<'a, V> {
    pub(super) time: f64,
    pub(super) start: &'a [BeadState<V>],
    pub(super) forces: &'a [LinearForce<V>],
    pub(super) settings: &'a StepSettings,
    pub(super) level: u32,
    pub(super) calm: u32,
    pub(super) rows: &'a [usize],
    /// The one-sided rows a bead may land on ([`Island::above`]).
    pub(super) above: &'a [usize],
}

/// What [`Island::cut_within`] cuts a step at.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Cut {
    /// A bead in flight crosses its one-sided wire: it lands.
    Landing,
    /// A bead passes an end of its wire: it leaves it.
    End,
}

impl<V: WireSpace> Island<V> {
    /// The one-sided rows set aside that a bead may land on within the
    /// step: those whose bead has not passed an end of the wire, and, on
    /// a wire with ends or one that catches, is not behind it (off it on
    /// the side it pushes toward, or on it). A bead behind a wire with no
    /// end crossed it (it could not go round) and lands; one that went
    /// round an end, or a marble under another track, does not.
    pub(super) fn above(
        &self,
        time: f64,
        states: &[BeadState<V>],
        work: &IslandWork<V>,
    ) -> Vec<usize> {
        if states.len() != self.beads() {
            return Vec::new();
        }
        (0..self.rows())
            .filter(|&r| self.sides[r].0 != 0.0 && work.inactive[r] && !self.contacts[r])
            .filter(|&r| {
                let at = states[self.entry_bead[self.row_start[r]]].position;
                let behind = || self.behind_at(r, at, time);
                let strict = self.catching[r] || self.ends(r);
                !(strict && behind()) && self.past_end(r, states, time, &work.hints) <= 0.0
            })
            .collect()
    }

    /// How far the nearest of `rows` is from crossing its wire at `time`:
    /// the least `side · C` (not positive once one has crossed) of the
    /// rows whose beads have not passed an end.
    pub(super) fn crossing(
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
    pub(super) fn on_the_wire(
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
    pub(super) fn cut_within(
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
}
