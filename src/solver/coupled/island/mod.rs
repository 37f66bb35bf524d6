//! [`Island`]: beads joined by constraints and springs, stepped together by
//! every method of [`Method`](crate::solver::Method), eqs. (12)–(14). One
//! file per piece:
//!
//! | file | what it holds |
//! |---|---|
//! | `mod` | [`Island`] and what may change between steps (wires, axes, sides, friction), [`RowReport`] |
//! | `work` | [`IslandWork<V>`], the buffers a step works in, and [`IslandMark`], what carries into the next step |
//! | `pairs` | two beads in touch: when they touch, part, close, meet slowly or near a step's start |
//! | `build` | [`Island::new`]: the rows and springs checked and laid out, [`IslandRow<V>`], [`IslandError`] |
//! | `rows` | each row's `C`, gradient, `J̇q̇` and bias (eq. 15 for a moving wire), and the products with `J` |
//! | `step` | [`Island::step`]: the step's outline, the rows a fresh island starts with, the Euler steps and the drift check (the lone bead's, bead by bead and row by row), substeps and halvings |
//! | `holding` | which rows a step may hold where it would end violating them: pairs in touch, meetings and landings at `e = 0` taken by the step (time-stepped in a dense island) |
//! | `events` | events located within a step, as a lone bead's are: landings, leaving at an end |
//! | `integrators` | eq. (12) on an island (λ and the accelerations), RK4, RATTLE: each bead by the lone bead's formulas, the multipliers by matrix solves |
//! | `complementarity` | the rows a dense island's step holds, predicted by projected Gauss–Seidel on the linearized contact problem, warm from the last step |
//! | `dense` | a dense island's RATTLE step: positions and velocities each one complementarity problem on slightly compliant rows, solved by chord and projected Newton steps |
//! | `newton` | the Newton position solve (a matrix solve for the multipliers at each step, stopped by the lone bead's test row by row) and its check that the root continues the start |
//! | `projection` | post-stabilization, eq. (13), and the velocity projection |
//! | `contact` | one-sided rows (leaving, landing, bouncing by the lone bead's rule) and friction (sliding, stopping, sticking: the lone bead's friction, with a stick row's multiplier for the pull) |

use bevy::math::DVec2;
use std::sync::Arc;

use super::constraint::{RowKind, SpringLink};
use super::normal::NormalMatrix;
use crate::geometry::{Friction, Side, WirePath, WireSpace};
use crate::solver::state::BeadState;

mod build;
mod complementarity;
mod contact;
mod dense;
mod events;
mod holding;
mod integrators;
mod newton;
mod pairs;
mod projection;
mod rows;
mod step;
mod work;

use super::IslandError;
pub use build::IslandRow;
pub(crate) use pairs::TOUCHING;
pub(crate) use pairs::{
    CONTACT_SLACK, closes, ends_in_touch, meets_near, meets_slowly, opening_rate, pair_gap,
    pair_speeds, parts, step_speed,
};
pub use work::{IslandMark, IslandWork};

/// How far off a one-sided wire, on the side it pushes toward, a bead must
/// start (in units of the wire's scale) to start in flight.
pub const OFF_THE_WIRE: f64 = 1e-9;

/// How many times a step may be halved when its Newton solve finds no
/// root: at most 2⁶ = 64 substeps.
pub const MAX_HALVINGS: u32 = 6;

/// After this many steps in a row that needed no more halvings than they
/// started with, a step tries one halving fewer.
pub const CALM_STEPS: u32 = 8;
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
    paths: Vec<Option<WirePath<V>>>,
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

impl<V: WireSpace> Island<V> {
    /// Moves the wire of row `row` to `pose` (a wire that moves between
    /// steps), and gives it `shape` where one is given (a wire edited in
    /// place); rows of other kinds are left as they are.
    pub fn place_wire(&mut self, row: usize, shape: Option<V::Shape>, pose: V::Pose) {
        if let Some(RowKind::Wire { pose: placed, .. }) = self.rows.get_mut(row) {
            *placed = pose;
            if self.paths[row].take().is_some() {
                self.moving -= 1;
            }
            if let Some(shape) = shape {
                self.reshape(row, shape);
            }
        }
    }

    /// Puts the wire of row `row` on `path`, a wire that moves during the
    /// step: its rows are evaluated where the wire is at each stage's
    /// time, with the terms of eq. (15) (the step's times come from
    /// [`Island::step_at`]). `shape` as for [`Island::place_wire`].
    pub fn move_wire(&mut self, row: usize, shape: Option<V::Shape>, path: WirePath<V>) {
        if let Some(pose) = path.fixed() {
            return self.place_wire(row, shape, pose);
        }
        if matches!(self.rows.get(row), Some(RowKind::Wire { .. })) {
            if self.paths[row].replace(path).is_none() {
                self.moving += 1;
            }
            if let Some(shape) = shape {
                self.reshape(row, shape);
            }
        }
    }

    /// Counts the rows of wires that end (an island built).
    fn count_ends(&mut self) {
        self.ended = (0..self.rows()).filter(|&r| self.ends(r)).count();
    }

    /// Gives the wire of row `row` `shape` and counts the row again among
    /// the rows of wires that end, without looking at the others: a wire
    /// edited in place under ten thousand beads costs a look at each.
    fn reshape(&mut self, row: usize, shape: V::Shape) {
        let was = self.ends(row);
        if let Some(RowKind::Wire {
            shape: placed_shape,
            ..
        }) = self.rows.get_mut(row)
        {
            *placed_shape = shape;
        }
        match (was, self.ends(row)) {
            (false, true) => self.ended += 1,
            (true, false) => self.ended -= 1,
            _ => {}
        }
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
    /// step's start where its beads part (`OPENING`); where it pulls is
    /// judged by the step's velocity solve with every contact at once
    /// (RATTLE, or a step that projects: the row is let go there), or by
    /// its λ at the step's start (a step with neither). Where beads apart
    /// meet within a step is the touch settlement's to find
    /// (`settle_touches`), which holds
    /// the row ([`IslandMark::hold`]) where a strike leaves the pair in
    /// touch or the step presses a touching pair together; the island's
    /// own step holds a row whose beads touched at its start where the
    /// step would leave them overlapping, and takes it again
    /// ([`Island::step_at`]), so a pile of beads pressing on each other
    /// settles within one step. A held pair does not strike: a strike's
    /// answer (`Island::respond`) keeps the held rows, so that beads
    /// pressed together answer as one, while pairs apart strike in turn;
    /// pairs at `e = 0` are struck all at once by `Island::press`. Rows
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

    /// The row that holds row `row`'s bead (or pair) still while static
    /// friction can ([`Island::set_rough`], [`Island::set_contact_friction`]),
    /// if it has one.
    pub(crate) fn stick_row(&self, row: usize) -> Option<usize> {
        self.rough.get(row)?.as_ref()?.stick
    }

    /// Gives the wire of row `row` Coulomb friction and viscous damping
    /// along it, eq. (17). `stick` names an axis row of the same bead
    /// (`RowKind::Axis`, any axis) the island uses to hold the bead still
    /// while static friction can: it is set aside while the bead slides,
    /// placed across the wire where the bead stops, and set aside again
    /// when the force it needs passes `μs |λ∇C|`. Kinetic friction and
    /// damping act as forces held at their value at the step's start. A
    /// bead on a moving wire does not stick in an island (it slides). An
    /// error, and nothing changed, where `row` is not a wire's row or
    /// `stick` not an axis row of its bead.
    pub fn set_rough(
        &mut self,
        row: usize,
        friction: Friction,
        damping: f64,
        stick: Option<usize>,
    ) -> Result<(), IslandError> {
        let rows = self.rows.len();
        if !matches!(self.rows.get(row), Some(RowKind::Wire { .. })) {
            return Err(IslandError::Row {
                what: "the rough row",
                row,
                expected: "a wire's row",
                rows,
            });
        }
        if let Some(s) = stick.filter(|&s| {
            !matches!(self.rows.get(s), Some(RowKind::Axis { .. }))
                || self.entry_bead[self.row_start[s]] != self.entry_bead[self.row_start[row]]
        }) {
            return Err(IslandError::Row {
                what: "the stick row",
                row: s,
                expected: "an axis row of the rough row's bead",
                rows,
            });
        }
        if let Some(slot) = self.rough.get_mut(row) {
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
        Ok(())
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
    /// springs' stored energy; an error if `states` is not one per bead.
    pub fn energy(&self, states: &[BeadState<V>], gravity: V) -> Result<f64, IslandError> {
        if states.len() != self.beads() {
            return Err(IslandError::Length {
                what: "the beads' states",
                given: states.len(),
                beads: self.beads(),
            });
        }
        Ok(self.energy_of(states, gravity))
    }

    /// [`Island::energy`] where `states` is known to be one per bead.
    pub(crate) fn energy_of(&self, states: &[BeadState<V>], gravity: V) -> f64 {
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
