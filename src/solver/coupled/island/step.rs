//! [`Island::step`]: the outline of an island's step, the rows it starts
//! with, the Euler steps and the divergence check, and the substeps a
//! step is halved into where its Newton solve finds no root.

use crate::geometry::WireSpace;

use super::events::{Cut, Flight};
use super::integrators::Stage;
use super::projection::Restore;
use super::{
    CALM_STEPS, CONTACT_PASSES, Island, IslandWork, MAX_HALVINGS, OFF_THE_WIRE, RoughRow,
    RowReport, TOUCHING,
};
use crate::solver::euler::Euler;
use crate::solver::method::Method;
use crate::solver::settings::StepSettings;
use crate::solver::solve::SolveError;
use crate::solver::state::{BeadState, LinearForce};
use crate::solver::step::drift_check;

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
    /// and that the step leaves overlapping by more than `TOUCHING` of
    /// their reach is held and the step taken again from its start, so a
    /// pile pressing on itself settles within the step (RATTLE does the
    /// same within its position solve first, and a post-stabilizing step
    /// within its projection, where a pass costs less). A row held is not
    /// let go by the step taken again, so the passes end: at most 16 more
    /// than the island has rows. A step that keeps its rows on their
    /// constraints (RATTLE, or one that projects) holds in the same way
    /// a row whose beads meet slowly at `e = 0`, or within
    /// `NEAR_MEETING` of the step's start
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
    pub(crate) fn step_part(
        &self,
        time: f64,
        states: &mut [BeadState<V>],
        forces: &[LinearForce<V>],
        settings: &StepSettings,
        whole: f64,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        let rattle = settings.method == Method::Rattle;
        if rattle && self.time_steps() && self.has_ends() {
            // Which beads have left a wire that ends decides.
            self.begin(time, states, work);
        }
        if rattle && self.steps_densely(work) {
            return self.step_dense(time, states, forces, settings, work);
        }
        let exact = settings.method.ends_on_constraints();
        work.stepped_holds.clear();
        self.touching(states, forces, settings, whole, work);
        self.landing_slowly(time, states, forces, (settings.dt, whole), exact, work);
        if !work.touching.contains(&true) {
            // Nothing in touch: no row the step could press to hold.
            return self.step_holding(time, states, forces, settings, &[], work);
        }
        let start = states.to_vec();
        let mark = work.mark();
        let mut hold = if exact && self.time_steps() {
            self.closing_within(time, states, forces, settings.dt, work)
        } else {
            Vec::new()
        };
        work.stepped_holds.resize(self.rows(), false);
        for &r in &hold {
            work.stepped_holds[r] = true;
        }
        let passes = self.rows() + CONTACT_PASSES;
        let end = time + settings.dt;
        for pass in 1..=passes {
            self.step_holding(time, states, forces, settings, &hold, work)?;
            work.x.clear();
            work.x.extend(states.iter().map(|s| s.position));
            let more = self.overlapping(work, end);
            if more.is_empty() || pass == passes {
                break;
            }
            hold.extend(more);
            states.copy_from_slice(&start);
            work.rewind(&mark);
        }
        self.report_stepped_landings((time, end), &start, states, &mark, work);
        Ok(())
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

    /// Whether row `r` starts set aside at `states` (every bead's) at
    /// `time`, by the rule of [`Island::start_rows`] before what a rebuilt
    /// island carries: a contact (held only once its beads press, see
    /// [`Island::set_contact`]); a one-sided wire's bead off it on the side
    /// it pushes toward, or on either side of a wire that catches it; a
    /// bead past an end of its wire, or away from a wire that ends (it has
    /// left it). `hints`: the rows' curve parameters, where known.
    pub(crate) fn starts_aside(
        &self,
        r: usize,
        time: f64,
        states: &[BeadState<V>],
        hints: &[f64],
    ) -> bool {
        let side = self.sides[r].0;
        let ends = self.ends(r);
        if states.len() != self.beads() || (side == 0.0 && !ends) {
            return false;
        }
        let c = || self.wire_row(r, states, time).c;
        let off = OFF_THE_WIRE * self.rows[r].scale();
        let apart = side != 0.0
            && (self.contacts[r] || side * c() > off || (self.catching[r] && c().abs() > off));
        let left =
            || self.past_end(r, states, time, hints) > 0.0 || self.off_wire(r, states, time) > off;
        apart || (ends && left())
    }

    /// Sets the rows a fresh `work` starts with at `states` (as its first
    /// step would), so that what it carries can be kept
    /// ([`IslandWork::mark`]) before that step, and finds where along its
    /// wire each bead is that it does not know yet. A work that has
    /// stepped keeps its rows.
    pub(crate) fn begin(&self, time: f64, states: &[BeadState<V>], work: &mut IslandWork<V>) {
        self.find_unknown(time, states, work);
        if work.inactive.len() != self.rows() {
            self.start_rows(time, states, work);
        }
    }

    /// Which rows a fresh island starts with: those
    /// [`Island::starts_aside`] sets aside (a contact, unless told it is
    /// held; a bead off a one-sided wire on the side it pushes toward, or
    /// on either side of a wire that catches it, see
    /// [`Island::set_catching`]; a bead past an end of its wire or away
    /// from a wire that ends, in flight), a row told otherwise by
    /// [`IslandWork::carry`] as it was told; stick rows start set aside (a
    /// bead slides until friction stops it), but a bead at rest on a rough
    /// wire starts held by static friction, and a stick row carried over
    /// as it was carried ([`IslandWork::carry_held`]).
    pub(super) fn start_rows(&self, time: f64, states: &[BeadState<V>], work: &mut IslandWork<V>) {
        let whole = states.len() == self.beads();
        work.inactive.clear();
        work.inactive.resize(self.rows(), false);
        for rough in self.rough.iter().flatten() {
            if let Some(s) = rough.stick {
                work.inactive[s] = true;
            }
        }
        if whole {
            for r in 0..self.rows() {
                if self.starts_aside(r, time, states, &work.hints) {
                    work.inactive[r] = true;
                }
            }
        }
        // What a rebuilt island carries over (see `IslandWork::carry`).
        for (r, carried) in work.carried.iter().enumerate().take(self.rows()) {
            if let Some((held, _)) = carried {
                work.inactive[r] = !held;
            }
        }
        let force = |r: usize| work.carried.get(r).copied().flatten().and_then(|(_, f)| f);
        if (0..self.rows()).any(|r| force(r).is_some()) {
            // The multipliers to start from, as a last step's report.
            let reports = (0..self.rows()).map(|r| RowReport {
                lambda: force(r).unwrap_or(0.0),
                ..RowReport::default()
            });
            work.reports = reports.collect();
        }
        // A bead at rest on a rough wire starts held by static friction.
        for (r, rough) in self.rough.iter().enumerate() {
            let Some(RoughRow { stick: Some(s), .. }) = rough else {
                continue;
            };
            let bead = self.entry_bead[self.row_start[r]];
            let carried = work.carries(*s);
            if work.inactive[r] || self.paths[r].is_some() || !whole || self.contacts[r] || carried
            {
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
            // A stick row a rebuilt island carried is as it was.
            let Some(rough) =
                (*rough).filter(|rough| !rough.stick.is_some_and(|s| work.carries(s)))
            else {
                continue;
            };
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
    pub(super) fn substeps(
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
        match (settings.method, Euler::of(settings.method)) {
            (Method::Rattle, _) => self.rattle(forces, h, work)?,
            (_, Some(euler)) => {
                self.accelerate(forces, gains, work, Stage::Start)?;
                for i in 0..n {
                    let (x, v, a) = (work.x0[i], work.v0[i], work.acceleration[i]);
                    (work.x[i], work.v[i]) = euler.lanes(x, v, a, h);
                }
                self.keep_lambda(work);
            }
            // RK4.
            _ => self.rk4(forces, gains, h, work)?,
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
