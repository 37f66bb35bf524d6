//! [`IslandWork`], the buffers an island's step works in and what it
//! reported, and [`IslandMark`], what of them carries from one step into
//! the next.

use bevy::math::DVec2;

use super::RowReport;
use crate::geometry::WireSpace;
use crate::solver::contact::ContactEvent;
use crate::solver::coupled::normal::{Factored, LuWork};
use crate::solver::state::BeadState;

/// The buffers one island's step works in, kept between steps so a step
/// allocates nothing. Also what the last step reported.
///
/// A clone carries everything a step reads from the last one (see
/// [`IslandMark`]) and what the last step reported, with fresh scratch
/// memory: stepping a clone gives the same numbers, bit for bit, as
/// stepping the original.
#[derive(Clone, Default)]
pub struct IslandWork<V: WireSpace = DVec2> {
    pub(super) x0: Vec<V>,
    pub(super) v0: Vec<V>,
    pub(super) x: Vec<V>,
    pub(super) v: Vec<V>,
    pub(super) x_sum: Vec<V>,
    pub(super) v_sum: Vec<V>,
    pub(super) force: Vec<V>,
    pub(super) acceleration: Vec<V>,
    pub(super) gradient: Vec<V>,
    pub(super) first_gradient: Vec<V>,
    pub(super) c: Vec<f64>,
    pub(super) curvature: Vec<f64>,
    /// Each row's `−∂C/∂t` (the moving wire's `∇C·w`; zero for the rest):
    /// `Ċ = J v − bias`.
    pub(super) bias: Vec<f64>,
    /// The time the rows are evaluated at.
    pub(super) time: f64,
    /// The rows set aside: one-sided wires their beads have left.
    pub(super) inactive: Vec<bool>,
    /// Whether each row starts held, and the multiplier it starts from,
    /// where a fresh work is told (see [`IslandWork::carry`] and
    /// [`IslandWork::carry_row`]).
    pub(super) carried: Vec<Option<(bool, Option<f64>)>>,
    /// The contact rows whose beads touched where the step began without
    /// closing: the step holds them where it would leave them overlapping
    /// (see [`Island::step_at`](super::Island::step_at)).
    pub(super) touching: Vec<bool>,
    /// The rows an island that time-steps holds from the step's start
    /// before its first pass ([`Island::closing_within`](super::Island::closing_within)): set aside where
    /// the step began, so its position solve may let them go again.
    pub(super) stepped_holds: Vec<bool>,
    /// The one-sided wire rows whose beads, in flight where the step
    /// began, reach their wires slowly: the step lands them at its end
    /// instead of at the instant (see [`Island::lands_slowly`](super::Island::lands_slowly)).
    pub(super) landing_slowly: Vec<bool>,
    /// Each wire row's curve parameter where its bead was after the last
    /// step (NaN: unknown), so a self-crossing track keeps it on its branch.
    pub(super) hints: Vec<f64>,
    /// Where each stick row holds its bead: the line `axis·x = offset`.
    pub(super) sticks: Vec<Option<(V, f64)>>,
    /// What the last step did to one-sided rows: (row, bead, event).
    pub(super) events: Vec<(usize, usize, ContactEvent<V>)>,
    pub(super) rhs: Vec<f64>,
    pub(super) lambda: Vec<f64>,
    pub(super) lu: LuWork,
    pub(super) scratch: Vec<V>,
    /// Each bead's `W Jᵀ μ` in a Gauss–Seidel iteration
    /// ([`Island::gauss_seidel`](super::Island::gauss_seidel)).
    pub(super) moved: Vec<V>,
    pub(super) factored: Factored,
    pub(super) reports: Vec<RowReport>,
    /// A dense island's last position and velocity forces of each row
    /// (`2μ/h²`, `2ν/h`), the next step's warm start.
    pub(super) pressing: Vec<(f64, f64)>,
    pub(super) bead_forces: Vec<V>,
    pub(super) substeps: u32,
    /// How many halvings deep the last step's substeps went; the next
    /// step starts there (see [`Island::step`](super::Island::step)).
    pub(super) level: u32,
    /// Steps in a row that went no deeper than they started.
    pub(super) calm: u32,
    /// The states at the start of a step, restored if it fails.
    pub(super) start: Vec<BeadState<V>>,
}

/// What of an island's [`IslandWork`] carries from one step into the
/// next: which rows are set aside, where the beads were along their wires,
/// where friction holds them, how finely the last step was cut. Kept
/// before a step ([`IslandWork::mark`]) so that a part of the step can be
/// taken again from its start ([`IslandWork::rewind`]).
#[derive(Clone, Debug, Default)]
pub struct IslandMark<V: WireSpace = DVec2> {
    pub(super) inactive: Vec<bool>,
    pub(super) hints: Vec<f64>,
    pub(super) sticks: Vec<Option<(V, f64)>>,
    pub(super) level: u32,
    pub(super) calm: u32,
}

impl<V: WireSpace> IslandMark<V> {
    /// Holds contact row `row` from here (its beads press), or sets it
    /// aside (they part), for the steps taken from this mark (see
    /// [`Island::set_contact`](super::Island::set_contact)). Whether the row is held, before.
    pub fn hold(&mut self, row: usize, held: bool) -> Option<bool> {
        let inactive = self.inactive.get_mut(row)?;
        let was = !*inactive;
        *inactive = !held;
        Some(was)
    }

    /// Whether row `row` is held in the steps taken from this mark.
    pub fn holds(&self, row: usize) -> bool {
        !self.inactive.get(row).copied().unwrap_or(false)
    }
}

impl<V: WireSpace> IslandWork<V> {
    /// What carries into the next step, as it is now.
    pub fn mark(&self) -> IslandMark<V> {
        IslandMark {
            inactive: self.inactive.clone(),
            hints: self.hints.clone(),
            sticks: self.sticks.clone(),
            level: self.level,
            calm: self.calm,
        }
    }

    /// Back to what `mark` kept, without allocating where the lengths
    /// agree.
    pub fn rewind(&mut self, mark: &IslandMark<V>) {
        self.inactive.clone_from(&mark.inactive);
        self.hints.clone_from(&mark.hints);
        self.sticks.clone_from(&mark.sticks);
        (self.level, self.calm) = (mark.level, mark.calm);
    }

    /// Takes `states` in as the current positions and velocities
    /// (`x`, `v`).
    pub(super) fn load(&mut self, states: &[BeadState<V>]) {
        self.x.clear();
        self.x.extend(states.iter().map(|s| s.position));
        self.v.clear();
        self.v.extend(states.iter().map(|s| s.velocity));
    }

    /// What the last successful step reported of each row; before a
    /// fresh work's first step, the forces it was told to start from
    /// ([`IslandWork::carry_row`]).
    pub fn rows(&self) -> &[RowReport] {
        &self.reports
    }

    /// The constraint force `Σ λ ∇C` on each bead at the end of the last
    /// step (λ as [`IslandWork<V>::rows`] reports it).
    pub fn constraint_forces(&self) -> &[V] {
        &self.bead_forces
    }

    /// How many substeps the last step took: 1, or more where it was
    /// halved (see [`Island::step`](super::Island::step)).
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// How many rows the last factorization dropped as redundant.
    pub fn redundant(&self) -> usize {
        self.factored.redundant
    }

    /// Whether row `row` holds its bead: false for a one-sided wire the
    /// bead has left (see [`Island::set_side`](super::Island::set_side)).
    pub fn holds(&self, row: usize) -> bool {
        !self.inactive.get(row).copied().unwrap_or(false)
    }

    /// Whether row `row` starts as a rebuilt island carried it over
    /// ([`IslandWork::carry_row`]), not by the first step's rule.
    pub(crate) fn carries(&self, row: usize) -> bool {
        self.carried.get(row).is_some_and(Option::is_some)
    }

    /// Starts row `row` of a fresh work held (or set aside) whatever the
    /// rule of the island's first step would say: what an island rebuilt
    /// around beads where the last one left them carries over, so a bead
    /// that had left its one-sided wire and is now behind it (on another
    /// wire that caught it) stays off it, and two beads pressed together
    /// stay pressed. A work that has stepped is not changed.
    pub fn carry(&mut self, row: usize, held: bool) {
        self.tell(row, held, None);
    }

    /// Starts row `row` of a fresh work as row `from_row` of `from` (the
    /// work of the island this one's was rebuilt from) ended its last
    /// step: held or set aside, from its force (a dense island's first
    /// step predicts the rows it holds warm from it, as from its own last
    /// step's), a wire row's bead where it was along its wire. `from` not
    /// yet stepped passes on what it was told to
    /// carry. A work that has stepped is not changed.
    pub fn carry_row(&mut self, row: usize, from: &IslandWork<V>, from_row: usize) {
        let told = from.carried.get(from_row).copied().flatten();
        let (held, force) = if from.inactive.is_empty() {
            match told {
                Some(told) => told,
                None => return,
            }
        } else {
            let force = from.reports.get(from_row).map(|report| report.lambda);
            (from.holds(from_row), force)
        };
        self.tell(row, held, force);
        // A wire row's bead is where it was along its wire.
        if let Some(&hint) = from.hints.get(from_row) {
            if self.hints.len() <= row {
                self.hints.resize(row + 1, f64::NAN);
            }
            self.hints[row] = hint;
        }
    }

    /// [`IslandWork::carry_row`] for row `row` and its stick row (the row
    /// that holds its bead or pair still while static friction can, if
    /// it has one) from `from_row` and its own: a stick row that held
    /// starts held, at the line it held on, with its multiplier; one that
    /// was set aside, or has no line, starts set aside.
    pub(crate) fn carry_held(
        &mut self,
        (row, stick): (usize, Option<usize>),
        from: &IslandWork<V>,
        (from_row, from_stick): (usize, Option<usize>),
    ) {
        self.carry_row(row, from, from_row);
        let (Some(stick), Some(from_stick)) = (stick, from_stick) else {
            return;
        };
        self.carry_row(stick, from, from_stick);
        let line = from.sticks.get(from_stick).copied().flatten();
        match (self.carried(stick), line) {
            (Some(true), Some(line)) => {
                if self.sticks.len() <= stick {
                    self.sticks.resize(stick + 1, None);
                }
                self.sticks[stick] = Some(line);
            }
            (Some(_), _) => self.tell(stick, false, None),
            (None, _) => {}
        }
    }

    /// Row `row` of a fresh work starts held (or set aside) and from the
    /// multiplier `force`, if one is given.
    fn tell(&mut self, row: usize, held: bool, force: Option<f64>) {
        if self.carried.len() <= row {
            self.carried.resize(row + 1, None);
        }
        self.carried[row] = Some((held, force));
    }

    /// What [`IslandWork::carry`] told row `row` to start as, if anything.
    pub fn carried(&self, row: usize) -> Option<bool> {
        self.carried
            .get(row)
            .copied()
            .flatten()
            .map(|(held, _)| held)
    }

    /// The beads that left or landed on a one-sided row in the last step:
    /// `(row, bead, event)`.
    pub fn events(&self) -> &[(usize, usize, ContactEvent<V>)] {
        &self.events
    }
}
