//! [`Island`]: beads joined by constraints and springs, stepped together by
//! every method of [`Method`](crate::solver::Method), eqs. (12)–(14). One
//! file per piece:
//!
//! | file | what it holds |
//! |---|---|
//! | `mod` | [`Island`] and what may change between steps (wires, axes, sides, friction), [`IslandWork<V>`], [`RowReport`] |
//! | `build` | [`Island::new`]: the rows and springs checked and laid out, [`IslandRow<V>`], [`IslandError`] |
//! | `rows` | each row's `C`, gradient, `J̇q̇` and bias (eq. 15 for a moving wire), and the products with `J` |
//! | `step` | [`Island::step`]: the step's outline, the rows a fresh island starts with, the Euler steps and the drift check (the lone bead's, bead by bead and row by row), substeps and halvings |
//! | `holding` | which rows a step may hold where it would end violating them: pairs in touch, meetings and landings at `e = 0` taken by the step (time-stepped in a dense island) |
//! | `events` | events located within a step, as a lone bead's are: landings, leaving at an end |
//! | `integrators` | eq. (12) on an island (λ and the accelerations), RK4, RATTLE: each bead by the lone bead's formulas, the multipliers by matrix solves |
//! | `complementarity` | the rows a dense island's step holds, predicted by projected Gauss–Seidel on the linearized contact problem, warm from the last step |
//! | `newton` | the Newton position solve (a matrix solve for the multipliers at each step, stopped by the lone bead's test row by row) and its check that the root continues the start |
//! | `projection` | post-stabilization, eq. (13), and the velocity projection |
//! | `contact` | one-sided rows (leaving, landing, bouncing by the lone bead's rule) and friction (sliding, stopping, sticking: the lone bead's friction, with a stick row's multiplier for the pull) |

use bevy::math::DVec2;
use std::sync::Arc;

use super::constraint::{RowKind, SpringLink};
use super::normal::{Factored, LuWork, NormalMatrix};
use crate::geometry::{Friction, Side, WireSpace};
use crate::solver::contact::ContactEvent;
use crate::solver::state::BeadState;

mod build;
mod complementarity;
mod contact;
mod events;
mod holding;
mod integrators;
mod newton;
mod projection;
mod rows;
mod step;

pub use build::{IslandError, IslandRow};

/// How far off a one-sided wire, on the side it pushes toward, a bead must
/// start (in units of the wire's scale) to start in flight.
pub const OFF_THE_WIRE: f64 = 1e-9;

/// How many times a step may be halved when its Newton solve finds no
/// root: at most 2⁶ = 64 substeps.
pub const MAX_HALVINGS: u32 = 6;

/// After this many steps in a row that needed no more halvings than they
/// started with, a step tries one halving fewer.
pub const CALM_STEPS: u32 = 8;
/// Two beads whose gap is at most this fraction of their radii touch.
pub const TOUCHING: f64 = 1e-10;

/// A contact row's beads part where their gap opens faster than this
/// fraction of their reach (the two radii) plus their speeds, per second:
/// slower is rounding, and the row holds on (see [`Island::set_contact`]).
pub const OPENING: f64 = 1e-9;

/// Whether a pair in touch whose gap opens at `rate`, of `reach` (the two
/// radii) and `speeds` (the sum of its beads' speeds), parts (see
/// [`OPENING`]).
pub(crate) fn parts(rate: f64, reach: f64, speeds: f64) -> bool {
    rate > OPENING * (reach + speeds)
}

/// How fast the gap between beads `a` and `b` opens (negative: closes),
/// along the line between their centres, and the sum of their speeds.
pub(crate) fn opening_rate<V: crate::geometry::Coordinates>(
    a: &BeadState<V>,
    b: &BeadState<V>,
) -> (f64, f64) {
    let d = b.position - a.position;
    let rate = d.dot(b.velocity - a.velocity) / d.dot(d).sqrt();
    let speeds = a.velocity.dot(a.velocity).sqrt() + b.velocity.dot(b.velocity).sqrt();
    (rate, speeds)
}

/// A pair in touch closes (and strikes at once) where it closes faster
/// than this fraction of its two beads' speeds: slower is rounding.
const CLOSING: f64 = 1e-9;

/// Whether a pair in touch whose gap opens at `rate`, of `reach` and
/// `speeds` as in [`parts`], closes: faster than [`CLOSING`] of its
/// speeds, and by more than what counts as touching ([`TOUCHING`] of its
/// reach) within a step of `dt`. A pair that closes is the touch
/// settlement's to strike; one that does not and presses is held.
pub(crate) fn closes(rate: f64, reach: f64, speeds: f64, dt: f64) -> bool {
    -rate > CLOSING * speeds && -rate * dt > TOUCHING * reach
}

/// How many times a wire's residual a held contact row's may be where a
/// Newton solve stalls and takes it: 4e-10 of the two radii instead of
/// [`NEWTON_ACCEPT`](crate::solver::newton::NEWTON_ACCEPT)'s 1e-10. Beads
/// jammed among others can hold more contact rows than they can meet
/// exactly at once, and there exact Newton steps stall a little above
/// 1e-10 of the radii however short the step.
pub(crate) const CONTACT_SLACK: f64 = 4.0;

/// Whether a contact row's beads `gap` apart, of `reach` (the two radii),
/// end a step in touch: within what a Newton solve takes of a held
/// contact row ([`CONTACT_SLACK`] times
/// [`NEWTON_ACCEPT`](crate::solver::newton::NEWTON_ACCEPT) of the reach).
pub(crate) fn ends_in_touch(gap: f64, reach: f64) -> bool {
    gap.abs() <= CONTACT_SLACK * crate::solver::newton::NEWTON_ACCEPT * reach
}

/// Whether a pair of restitution `restitution` whose gap closes at
/// `closing` (m/s) meets slowly: at `e = 0`, no faster than `moved`, the
/// speed one whole step's forces give its two beads (each `|f| / m`
/// times the step, summed). Such a meeting is the island's step to hold,
/// not the touch settlement's to strike at its instant (see
/// [`Island::step_at`]).
pub(crate) fn meets_slowly(restitution: f64, closing: f64, moved: f64) -> bool {
    restitution == 0.0 && closing <= moved
}

/// The part of a step within which a pair at `e = 0` that meets is
/// taken by the step rather than struck at its instant: 1/16. Such a
/// pair, `gap` apart and closing at `v`, meets within `gap / v ≤ dt / 16`
/// of the step's start; its body's step holds its contact row where the
/// pair would end overlapping (see [`Island::step_at`]).
pub const NEAR_MEETING: f64 = 1.0 / 16.0;

/// Whether a pair of restitution `restitution`, `gap` apart and closing
/// at `closing` (m/s), meets near the start of a step of `dt` (or of a
/// part of it, `dt` still the whole step's): at `e = 0`, within
/// [`NEAR_MEETING`] of `dt`. Its body's step holds
/// its row (a plastic impact over the step: for two free beads on a line
/// exactly the one at its instant, elsewhere apart from it by the
/// constraint force over the `gap / v` before it), so a pile whose beads
/// pass their momentum on across gaps of a hair does not cut its step at
/// each (inelastic collapse).
pub(crate) fn meets_near(restitution: f64, gap: f64, closing: f64, dt: f64) -> bool {
    restitution == 0.0 && closing > 0.0 && gap <= NEAR_MEETING * closing * dt
}

/// The speed a step of `dt` gives two beads under `pushes` (each bead's
/// acceleration from its forces, `f / m`): `(|p_a| + |p_b|) dt`, the
/// `moved` of [`meets_slowly`].
pub(crate) fn step_speed<V: crate::geometry::Coordinates>(pushes: [V; 2], dt: f64) -> f64 {
    pushes.iter().map(|p| p.dot(*p).sqrt()).sum::<f64>() * dt
}

/// How many contact rows make an island dense: from this many up it
/// time-steps its meetings at `e = 0` ([`Island::time_steps`]).
pub(crate) const DENSE_CONTACTS: usize = 8;

/// How many more times than the island has rows a step, a position
/// solve or a velocity projection is taken again for contacts that
/// overlap, pull or close (see [`Island::set_contact`]).
const CONTACT_PASSES: usize = 16;

/// The most exact Newton steps RATTLE's position solve takes before it
/// takes the step as having no root near (and halves it).
pub const EXACT_STEPS: u32 = 8;

/// What a step reports of one row.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RowReport {
    /// The multiplier λ the step applied (for RATTLE the mean of its
    /// position and velocity multipliers).
    pub lambda: f64,
    /// `C` after the step.
    pub c: f64,
    /// `Ċ` after the step.
    pub c_dot: f64,
}

/// Beads joined by constraints (rows) and springs, stepped as one system:
/// the topology, built once, and what it needs to solve eq. (12) fast (the
/// pattern and symbolic factorization of `J W Jᵀ`). Positions, velocities
/// and forces come with each step.
///
/// A clone shares the matrix's pattern and symbolic factorization (they
/// never change) and copies the rest.
#[derive(Clone)]
pub struct Island<V: WireSpace = DVec2> {
    inverse_mass: Vec<f64>,
    rows: Vec<RowKind<V>>,
    /// Row `r`'s gradient entries are `row_start[r]..row_start[r + 1]`.
    row_start: Vec<usize>,
    /// The bead of each gradient entry.
    entry_bead: Vec<usize>,
    springs: Vec<SpringLink>,
    normal: Arc<NormalMatrix>,
    /// The path of each wire row that moves (see [`Island::move_wire`]).
    paths: Vec<Option<V::Path>>,
    /// How many rows have a path: with none, a step looks at no path.
    moving: usize,
    /// Each row's side (+1, −1, or 0 for a two-sided row) and restitution
    /// (see [`Island::set_side`]).
    sides: Vec<(f64, f64)>,
    /// Whether each row is a contact between two beads that touch (see
    /// [`Island::set_contact`]).
    contacts: Vec<bool>,
    /// How many rows are contacts: from [`DENSE_CONTACTS`] up, the island
    /// time-steps its meetings at `e = 0` ([`Island::time_steps`]).
    contact_rows: usize,
    /// Whether each wire row catches its bead rather than holds it from
    /// the start (see [`Island::set_catching`]).
    catching: Vec<bool>,
    /// How many rows are of wires that end: with none, a step looks for
    /// no end.
    ended: usize,
    /// Each wire row's friction, if it has any (see [`Island::set_rough`]).
    rough: Vec<Option<RoughRow>>,
    /// How many rows have friction: with none, the matrices may be factored
    /// in the rows' order, and a step looks at no friction.
    rough_rows: usize,
}

/// Friction and damping along one wire row, and the row that holds its bead
/// still while static friction does.
#[derive(Clone, Copy, Debug)]
struct RoughRow {
    friction: Friction,
    damping: f64,
    /// An axis row, set aside while the bead slides.
    stick: Option<usize>,
    /// The other row of a curve in space on the same bead (see
    /// [`Island::pair_rows`]): the two press and slide as one.
    partner: Option<usize>,
}

/// The buffers one island's step works in, kept between steps so a step
/// allocates nothing. Also what the last step reported.
///
/// A clone carries everything a step reads from the last one (see
/// [`IslandMark`]) and what the last step reported, with fresh scratch
/// memory: stepping a clone gives the same numbers, bit for bit, as
/// stepping the original.
#[derive(Clone, Default)]
pub struct IslandWork<V: WireSpace = DVec2> {
    x0: Vec<V>,
    v0: Vec<V>,
    x: Vec<V>,
    v: Vec<V>,
    x_sum: Vec<V>,
    v_sum: Vec<V>,
    force: Vec<V>,
    acceleration: Vec<V>,
    gradient: Vec<V>,
    first_gradient: Vec<V>,
    c: Vec<f64>,
    curvature: Vec<f64>,
    /// Each row's `−∂C/∂t` (the moving wire's `∇C·w`; zero for the rest):
    /// `Ċ = J v − bias`.
    bias: Vec<f64>,
    /// The time the rows are evaluated at.
    time: f64,
    /// The rows set aside: one-sided wires their beads have left.
    inactive: Vec<bool>,
    /// Whether each row starts held, where a fresh work is told (see
    /// [`IslandWork::carry`]).
    carried: Vec<Option<bool>>,
    /// The contact rows whose beads touched where the step began without
    /// closing: the step holds them where it would leave them overlapping
    /// (see [`Island::step_at`]).
    touching: Vec<bool>,
    /// The rows an island that time-steps holds from the step's start
    /// before its first pass ([`Island::closing_within`]): set aside where
    /// the step began, so its position solve may let them go again.
    stepped_holds: Vec<bool>,
    /// The one-sided wire rows whose beads, in flight where the step
    /// began, reach their wires slowly: the step lands them at its end
    /// instead of at the instant (see [`Island::lands_slowly`]).
    landing_slowly: Vec<bool>,
    /// Each wire row's curve parameter where its bead was after the last
    /// step (NaN: unknown), so a self-crossing track keeps it on its branch.
    hints: Vec<f64>,
    /// Where each stick row holds its bead: the line `axis·x = offset`.
    sticks: Vec<Option<(V, f64)>>,
    /// What the last step did to one-sided rows: (row, bead, event).
    events: Vec<(usize, usize, ContactEvent<V>)>,
    rhs: Vec<f64>,
    lambda: Vec<f64>,
    lu: LuWork,
    scratch: Vec<V>,
    /// Each bead's `W Jᵀ μ` in a Gauss–Seidel iteration
    /// ([`Island::gauss_seidel`]).
    moved: Vec<V>,
    factored: Factored,
    reports: Vec<RowReport>,
    bead_forces: Vec<V>,
    substeps: u32,
    /// How many halvings deep the last step's substeps went; the next
    /// step starts there (see [`Island::step`]).
    level: u32,
    /// Steps in a row that went no deeper than they started.
    calm: u32,
    /// The states at the start of a step, restored if it fails.
    start: Vec<BeadState<V>>,
}

/// What of an island's [`IslandWork`] carries from one step into the
/// next: which rows are set aside, where the beads were along their wires,
/// where friction holds them, how finely the last step was cut. Kept
/// before a step ([`IslandWork::mark`]) so that a part of the step can be
/// taken again from its start ([`IslandWork::rewind`]).
#[derive(Clone, Debug, Default)]
pub struct IslandMark<V: WireSpace = DVec2> {
    inactive: Vec<bool>,
    hints: Vec<f64>,
    sticks: Vec<Option<(V, f64)>>,
    level: u32,
    calm: u32,
}

impl<V: WireSpace> IslandMark<V> {
    /// Holds contact row `row` from here (its beads press), or sets it
    /// aside (they part), for the steps taken from this mark (see
    /// [`Island::set_contact`]). Whether the row is held, before.
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

    /// What the last successful step reported of each row.
    pub fn rows(&self) -> &[RowReport] {
        &self.reports
    }

    /// The constraint force `Σ λ ∇C` on each bead at the end of the last
    /// step (λ as [`IslandWork<V>::rows`] reports it).
    pub fn constraint_forces(&self) -> &[V] {
        &self.bead_forces
    }

    /// How many substeps the last step took: 1, or more where it was
    /// halved (see [`Island::step`]).
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// How many rows the last factorization dropped as redundant.
    pub fn redundant(&self) -> usize {
        self.factored.redundant
    }

    /// Whether row `row` holds its bead: false for a one-sided wire the
    /// bead has left (see [`Island::set_side`]).
    pub fn holds(&self, row: usize) -> bool {
        !self.inactive.get(row).copied().unwrap_or(false)
    }

    /// Starts wire row `row` of a fresh work held (or set aside) whatever
    /// the rule of the island's first step would say: what an island
    /// rebuilt around beads where the last one left them carries over, so
    /// a bead that had left its one-sided wire and is now behind it (on
    /// another wire that caught it) stays off it. A work that has stepped
    /// is not changed.
    pub fn carry(&mut self, row: usize, held: bool) {
        if self.carried.len() <= row {
            self.carried.resize(row + 1, None);
        }
        self.carried[row] = Some(held);
    }

    /// What [`IslandWork::carry`] told row `row` to start as, if anything.
    pub fn carried(&self, row: usize) -> Option<bool> {
        self.carried.get(row).copied().flatten()
    }

    /// The beads that left or landed on a one-sided row in the last step:
    /// `(row, bead, event)`.
    pub fn events(&self) -> &[(usize, usize, ContactEvent<V>)] {
        &self.events
    }
}

impl<V: WireSpace> Island<V> {
    /// Moves the wire of row `row` to `pose` (a wire that moves between
    /// steps), and gives it `shape` where one is given (a wire edited in
    /// place); rows of other kinds are left as they are.
    pub fn place_wire(&mut self, row: usize, shape: Option<V::Shape>, pose: V::Pose) {
        if let Some(RowKind::Wire {
            shape: placed_shape,
            pose: placed,
        }) = self.rows.get_mut(row)
        {
            *placed = pose;
            if self.paths[row].take().is_some() {
                self.moving -= 1;
            }
            if let Some(shape) = shape {
                *placed_shape = shape;
                self.count_ends();
            }
        }
    }

    /// Puts the wire of row `row` on `path`, a wire that moves during the
    /// step: its rows are evaluated where the wire is at each stage's
    /// time, with the terms of eq. (15) (the step's times come from
    /// [`Island::step_at`]). `shape` as for [`Island::place_wire`].
    pub fn move_wire(&mut self, row: usize, shape: Option<V::Shape>, path: V::Path) {
        if let Some(pose) = V::path_fixed(&path) {
            return self.place_wire(row, shape, pose);
        }
        if let Some(RowKind::Wire {
            shape: placed_shape,
            ..
        }) = self.rows.get_mut(row)
        {
            if self.paths[row].replace(path).is_none() {
                self.moving += 1;
            }
            if let Some(shape) = shape {
                *placed_shape = shape;
                self.count_ends();
            }
        }
    }

    /// Counts the rows of wires that end again (a wire's shape changed).
    fn count_ends(&mut self) {
        self.ended = (0..self.rows()).filter(|&r| self.ends(r)).count();
    }

    /// Makes the wire of row `row` one-sided (see
    /// [`Side`](crate::geometry::Side)) with restitution `restitution`:
    /// where λ takes the sign the wire cannot push with at a step's start,
    /// the row is set aside and its bead flies with the rest of the island;
    /// where the bead crosses the wire again within a step, it lands where
    /// it crosses, located as a lone bead's landing is (the island
    /// projected onto it, the bead's normal velocity reversed and scaled
    /// by the restitution, the row kept aside if it bounced), and the step
    /// goes on from there. A leaving falls on a step's start. (Past an
    /// end of an open wire, one-sided or not, the bead leaves at the
    /// instant it passes the end, found within the step, and does not land
    /// on the wire's continuation past the end.)
    pub fn set_side(&mut self, row: usize, side: Side, restitution: f64) {
        if let (Some(RowKind::Wire { .. }), Some(slot)) =
            (self.rows.get(row), self.sides.get_mut(row))
        {
            *slot = (side.sign(), restitution.clamp(0.0, 1.0));
        }
    }

    /// Makes the one-sided wire of row `row` (see [`Island::set_side`])
    /// one that catches its bead rather than one the bead is on: the row
    /// starts held only where the bead starts on the wire (within
    /// 1e-9 of its scale, not past an end), and set aside
    /// wherever else it starts, on either side; the bead lands on it from
    /// the side it pushes toward, never from behind. A track of a marble
    /// run, which every marble may fall onto.
    pub fn set_catching(&mut self, row: usize) {
        if let (Some(RowKind::Wire { .. }), Some(slot)) =
            (self.rows.get(row), self.catching.get_mut(row))
        {
            *slot = true;
        }
    }

    /// Makes rod row `row` a contact between two beads that touch: one
    /// side (`|x_a − x_b| ≥ length`, the two radii), held only while its
    /// beads press. A contact row starts set aside and is set aside at a
    /// step's start where its beads part ([`OPENING`]); where it pulls is
    /// judged by the step's velocity solve with every contact at once
    /// (RATTLE, or a step that projects: the row is let go there), or by
    /// its λ at the step's start (a step with neither). Where beads apart
    /// meet within a step is the touch settlement's to find
    /// ([`settle_touches`](crate::solver::settle_touches)), which holds
    /// the row ([`IslandMark::hold`]) where a strike leaves the pair in
    /// touch or the step presses a touching pair together; the island's
    /// own step holds a row whose beads touched at its start where the
    /// step would leave them overlapping, and takes it again
    /// ([`Island::step_at`]), so a pile of beads pressing on each other
    /// settles within one step. A held pair does not strike: a strike's
    /// answer ([`Island::respond`]) keeps the held rows, so that beads
    /// pressed together answer as one, while pairs apart strike in turn;
    /// pairs at `e = 0` are struck all at once by [`Island::press`]. Rows
    /// of other kinds are left as they are.
    pub fn set_contact(&mut self, row: usize) {
        if let (Some(RowKind::Rod { .. }), Some(slot), Some(contact)) = (
            self.rows.get(row),
            self.sides.get_mut(row),
            self.contacts.get_mut(row),
        ) {
            *slot = (1.0, 1.0);
            if !*contact {
                self.contact_rows += 1;
            }
            *contact = true;
        }
    }

    /// Whether the island takes its meetings at `e = 0` by time-stepping:
    /// it has at least [`DENSE_CONTACTS`] contact rows (a pile, a train of
    /// marbles, beads in a bowl). Its step holds from its start every
    /// contact row at `e = 0`, and every one-sided wire row of
    /// restitution 0 whose bead is in flight, that the step would end
    /// overlapping or behind its wire, and takes the step again (see
    /// [`Island::step_at`]): the meeting or landing is a plastic impact
    /// spread over the step, not located at its instant. An island with
    /// fewer contact rows (a pair of gliders, a cart on a floor) locates
    /// each at its instant.
    pub(crate) fn time_steps(&self) -> bool {
        self.contact_rows >= DENSE_CONTACTS
    }

    /// Gives contact row `row` its pair's restitution (the two beads'
    /// least; 1 until told). A pair at `e = 0` whose beads meet slowly, or
    /// near the step's start, is held by the step rather than struck where
    /// it meets (see
    /// [`Island::step_at`]). Rows of other kinds are left as they are.
    pub fn set_contact_restitution(&mut self, row: usize, restitution: f64) {
        if self.is_contact(row)
            && let Some(slot) = self.sides.get_mut(row)
        {
            slot.1 = restitution;
        }
    }

    /// Gives contact row `row` Coulomb friction between its two beads,
    /// as [`Island::set_rough`] gives a wire: while the pair is pressed
    /// together their slip across the contact is opposed by `μk |λ|`
    /// (held at its value at the step's start), and where the slip stops
    /// within a step `stick` holds it: a row of the same two beads (any
    /// kind; a rod of the pair's reach will do), placed as
    /// `t·(x_b − x_a) = offset` across the contact where they stopped,
    /// set aside while they slide and let go again when the force it needs
    /// passes `μs |λ|`. A pair in space has no one direction to be held
    /// in: friction slows its slip, and `stick` is not used. Rows that are
    /// not contacts, and a `stick` that does not join the same two beads,
    /// are left as they were.
    pub fn set_contact_friction(&mut self, row: usize, friction: Friction, stick: Option<usize>) {
        let Some((a, b, _)) = self.contact_pair(row) else {
            return;
        };
        let stick = stick.filter(|&s| {
            s < self.rows() && s != row && {
                let entries = &self.entry_bead[self.row_start[s]..self.row_start[s + 1]];
                entries == [a, b] || entries == [b, a]
            }
        });
        if let Some(slot) = self.rough.get_mut(row) {
            let was = slot.replace(RoughRow {
                friction,
                damping: 0.0,
                stick,
                partner: None,
            });
            if was.is_none() {
                self.rough_rows += 1;
            }
        }
    }

    /// Whether row `row` is a contact (see [`Island::set_contact`]).
    pub fn is_contact(&self, row: usize) -> bool {
        self.contacts.get(row).copied().unwrap_or(false)
    }

    /// Gives the wire of row `row` Coulomb friction and viscous damping
    /// along it, eq. (17). `stick` names an axis row of the same bead
    /// (`RowKind::Axis`, any axis) the island uses to hold the bead still
    /// while static friction can: it is set aside while the bead slides,
    /// placed across the wire where the bead stops, and set aside again
    /// when the force it needs passes `μs |λ∇C|`. Kinetic friction and
    /// damping act as forces held at their value at the step's start. A
    /// bead on a moving wire does not stick in an island (it slides).
    pub fn set_rough(
        &mut self,
        row: usize,
        friction: Friction,
        damping: f64,
        stick: Option<usize>,
    ) {
        let stick = stick.filter(|&s| {
            matches!(self.rows.get(s), Some(RowKind::Axis { .. }))
                && self.entry_bead.get(self.row_start[s])
                    == self.entry_bead.get(self.row_start[row])
        });
        if let (Some(RowKind::Wire { .. }), Some(slot)) =
            (self.rows.get(row), self.rough.get_mut(row))
        {
            let partner = slot.and_then(|rough| rough.partner);
            let was = slot.replace(RoughRow {
                friction,
                damping: damping.max(0.0),
                stick,
                partner,
            });
            if was.is_none() {
                self.rough_rows += 1;
            }
        }
    }

    /// Joins wire row `second` to the rough wire row `first` (see
    /// [`Island::set_rough`]) as the two rows of one curve in space on one
    /// bead: the wire presses with their two forces together,
    /// `|λ₁∇C₁ + λ₂∇C₂|`, friction and damping act along the curve's one
    /// tangent, and static friction holds the bead along it. Call after
    /// `set_rough`; rows that are not two wire rows of one bead are left
    /// as they were.
    pub fn pair_rows(&mut self, first: usize, second: usize) {
        let bead = |r: usize| {
            matches!(self.rows.get(r), Some(RowKind::Wire { .. }))
                .then(|| self.entry_bead[self.row_start[r]])
        };
        if first == second || bead(first).is_none() || bead(first) != bead(second) {
            return;
        }
        if let Some(Some(rough)) = self.rough.get_mut(first) {
            rough.partner = Some(second);
        }
    }

    /// Whether the island's matrices may be factored in the order of its
    /// rows (as a band): no friction (see the `normal` module).
    fn natural_order(&self) -> bool {
        !self.is_rough()
    }

    /// Whether a row has friction.
    fn is_rough(&self) -> bool {
        self.rough_rows > 0
    }

    /// Whether a row is one-sided.
    fn one_sided(&self) -> bool {
        self.sides.iter().any(|(side, _)| *side != 0.0)
    }

    /// Whether a row's wire moves.
    fn moves(&self) -> bool {
        self.moving > 0
    }

    /// Moves the line of the axis row `row` (one of a pin's rows) to
    /// `axis·x = offset`; rows of other kinds are left as they are.
    pub fn place_axis(&mut self, row: usize, offset: f64) {
        if let Some(RowKind::Axis { offset: placed, .. }) = self.rows.get_mut(row) {
            *placed = offset;
        }
    }

    /// How many beads.
    pub fn beads(&self) -> usize {
        self.inverse_mass.len()
    }

    /// How many constraint rows.
    pub fn rows(&self) -> usize {
        self.rows.len()
    }

    /// Kinetic plus gravitational energy of the beads in `states`, plus the
    /// springs' stored energy.
    pub fn energy(&self, states: &[BeadState<V>], gravity: V) -> f64 {
        let beads: f64 = states
            .iter()
            .zip(&self.inverse_mass)
            .map(|(s, w)| {
                let (kinetic, potential) = s.energy(w.recip(), gravity);
                kinetic + potential
            })
            .sum();
        let springs: f64 = self
            .springs
            .iter()
            .map(|s| s.stored(states[s.a].position, states[s.b].position))
            .sum();
        beads + springs
    }
}
