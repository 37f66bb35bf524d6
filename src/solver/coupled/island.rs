//! [`Island`]: beads joined by constraints and springs, stepped together by
//! every method of [`Method`], eqs. (10)–(12).

use bevy::math::DVec2;

use super::constraint::{RowKind, SpringLink};
use super::normal::{Factored, LuWork, NormalMatrix};
use crate::geometry::{
    Friction, ImplicitCurve, Near, Placed, Pose, PosePath, Side, Twist, WireShape,
};
use crate::solver::contact::ContactEvent;
use crate::solver::method::Method;
use crate::solver::projection::{
    NEWTON_ACCEPT, NEWTON_MAX_ITERATIONS, NEWTON_TOLERANCE, energy_scale, kinetic_scale,
};
use crate::solver::settings::{Gains, StepSettings};
use crate::solver::solve::SolveError;
use crate::solver::state::{BeadState, LinearForce};

/// How far off a one-sided wire, on the side it pushes toward, a bead must
/// start (in units of the wire's scale) to start in flight.
pub const OFF_THE_WIRE: f64 = 1e-9;

/// How many times a step may be halved when its Newton solve finds no
/// root: at most 2⁶ = 64 substeps.
pub const MAX_HALVINGS: u32 = 6;

/// After this many steps in a row that needed no more halvings than they
/// started with, a step tries one halving fewer.
pub const CALM_STEPS: u32 = 8;
/// The most exact Newton steps RATTLE's position solve takes before it
/// takes the step as having no root near (and halves it).
pub const EXACT_STEPS: u32 = 8;

/// Why an island cannot be built: a constraint or spring that names a bead
/// it cannot join.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum IslandError {
    /// A bead's mass is not positive and finite.
    #[error("bead {bead} has mass {mass}; a mass must be positive and finite")]
    Mass {
        /// The bead.
        bead: usize,
        /// Its mass.
        mass: f64,
    },
    /// A constraint or spring names a bead the island does not have.
    #[error("{item} names bead {bead}, but there are only {beads} beads")]
    MissingBead {
        /// The constraint or spring, in words.
        item: String,
        /// The index it named.
        bead: usize,
        /// How many beads there are.
        beads: usize,
    },
    /// A constraint or spring joins a bead to itself.
    #[error("{item} joins bead {bead} to itself")]
    SameBead {
        /// The constraint or spring, in words.
        item: String,
        /// The bead.
        bead: usize,
    },
    /// A constraint names the wrong number of beads for its kind.
    #[error("{item} names {got} beads, but it joins {expected}")]
    Arity {
        /// The constraint, in words.
        item: String,
        /// How many its kind joins.
        expected: usize,
        /// How many it named.
        got: usize,
    },
    /// A length, stiffness or damping out of range.
    #[error("{item}: {what} must be {range}, got {value}")]
    Value {
        /// The constraint or spring, in words.
        item: String,
        /// Which value.
        what: &'static str,
        /// What it must be.
        range: &'static str,
        /// What it was.
        value: f64,
    },
    /// faer could not allocate the symbolic factorization.
    #[error("the island's matrix could not be set up (out of memory)")]
    OutOfMemory,
}

/// One constraint row of an island: what it is and the beads it joins
/// (indices into the island's beads).
#[derive(Clone, Debug)]
pub struct IslandRow {
    /// The kind of constraint.
    pub kind: RowKind,
    /// The beads, in the order the kind takes them.
    pub beads: Vec<usize>,
}

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
/// the topology, built once, and what it needs to solve eq. (10) fast (the
/// pattern and symbolic factorization of `J W Jᵀ`). Positions, velocities
/// and forces come with each step.
pub struct Island {
    inverse_mass: Vec<f64>,
    rows: Vec<RowKind>,
    /// Row `r`'s gradient entries are `row_start[r]..row_start[r + 1]`.
    row_start: Vec<usize>,
    /// The bead of each gradient entry.
    entry_bead: Vec<usize>,
    springs: Vec<SpringLink>,
    normal: NormalMatrix,
    /// The path of each wire row that moves (see [`Island::move_wire`]).
    paths: Vec<Option<PosePath>>,
    /// How many rows have a path: with none, a step looks at no path.
    moving: usize,
    /// Each row's side (+1, −1, or 0 for a two-sided row) and restitution
    /// (see [`Island::set_side`]).
    sides: Vec<(f64, f64)>,
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
}

/// The buffers one island's step works in, kept between steps so a step
/// allocates nothing. Also what the last step reported.
#[derive(Default)]
pub struct IslandWork {
    x0: Vec<DVec2>,
    v0: Vec<DVec2>,
    x: Vec<DVec2>,
    v: Vec<DVec2>,
    x_sum: Vec<DVec2>,
    v_sum: Vec<DVec2>,
    force: Vec<DVec2>,
    acceleration: Vec<DVec2>,
    gradient: Vec<DVec2>,
    first_gradient: Vec<DVec2>,
    c: Vec<f64>,
    curvature: Vec<f64>,
    /// Each row's `−∂C/∂t` (the moving wire's `∇C·w`; zero for the rest):
    /// `Ċ = J v − bias`.
    bias: Vec<f64>,
    /// The time the rows are evaluated at.
    time: f64,
    /// The rows set aside: one-sided wires their beads have left.
    inactive: Vec<bool>,
    /// Each wire row's curve parameter where its bead was after the last
    /// step (NaN: unknown), so a self-crossing track keeps it on its branch.
    hints: Vec<f64>,
    /// Where each stick row holds its bead: the line `axis·x = offset`.
    sticks: Vec<Option<(DVec2, f64)>>,
    /// What the last step did to one-sided rows: (row, bead, event).
    events: Vec<(usize, usize, ContactEvent)>,
    rhs: Vec<f64>,
    lambda: Vec<f64>,
    lu: LuWork,
    scratch: Vec<DVec2>,
    factored: Factored,
    reports: Vec<RowReport>,
    bead_forces: Vec<DVec2>,
    substeps: u32,
    /// How many halvings deep the last step's substeps went; the next
    /// step starts there (see [`Island::step`]).
    level: u32,
    /// Steps in a row that went no deeper than they started.
    calm: u32,
    /// The states at the start of a step, restored if it fails.
    start: Vec<BeadState>,
}

impl IslandWork {
    /// What the last successful step reported of each row.
    pub fn rows(&self) -> &[RowReport] {
        &self.reports
    }

    /// The constraint force `Σ λ ∇C` on each bead at the end of the last
    /// step (λ as [`IslandWork::rows`] reports it).
    pub fn constraint_forces(&self) -> &[DVec2] {
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

    /// The beads that left or landed on a one-sided row in the last step:
    /// `(row, bead, event)`.
    pub fn events(&self) -> &[(usize, usize, ContactEvent)] {
        &self.events
    }
}

fn describe(r: usize, kind: &RowKind) -> String {
    let what = match kind {
        RowKind::Wire { .. } => "wire",
        RowKind::Rod { .. } => "rod",
        RowKind::Axis { .. } => "pin",
        RowKind::Custom(_) => "custom",
    };
    format!("constraint {r} ({what})")
}

impl Island {
    /// An island of beads of the given masses, joined by `rows` and
    /// `springs`; every index and value is checked.
    pub fn new(
        masses: &[f64],
        rows: Vec<IslandRow>,
        springs: Vec<SpringLink>,
    ) -> Result<Self, IslandError> {
        let beads = masses.len();
        let mut inverse_mass = Vec::with_capacity(beads);
        for (bead, &mass) in masses.iter().enumerate() {
            if !(mass.is_finite() && mass > 0.0) {
                return Err(IslandError::Mass { bead, mass });
            }
            inverse_mass.push(mass.recip());
        }
        let check_beads = |item: &dyn Fn() -> String, named: &[usize]| {
            for (i, &bead) in named.iter().enumerate() {
                if bead >= beads {
                    return Err(IslandError::MissingBead {
                        item: item(),
                        bead,
                        beads,
                    });
                }
                if named[..i].contains(&bead) {
                    return Err(IslandError::SameBead { item: item(), bead });
                }
            }
            Ok(())
        };
        let mut row_start = vec![0];
        let mut entry_bead = Vec::new();
        let mut kinds = Vec::with_capacity(rows.len());
        for (r, row) in rows.into_iter().enumerate() {
            let item = || describe(r, &row.kind);
            let expected = row.kind.arity().unwrap_or(row.beads.len().max(1));
            if row.beads.len() != expected {
                return Err(IslandError::Arity {
                    item: item(),
                    expected,
                    got: row.beads.len(),
                });
            }
            check_beads(&item, &row.beads)?;
            let bad = |what, range, value| IslandError::Value {
                item: item(),
                what,
                range,
                value,
            };
            match &row.kind {
                RowKind::Rod { length } if !(length.is_finite() && *length > 0.0) => {
                    return Err(bad("length", "positive and finite", *length));
                }
                RowKind::Axis { axis, offset } => {
                    let off = (axis.length() - 1.0).abs();
                    if off.is_nan() || off >= 1e-12 {
                        return Err(bad("|axis|", "1", axis.length()));
                    }
                    if !offset.is_finite() {
                        return Err(bad("the point", "finite", *offset));
                    }
                }
                _ => {}
            }
            entry_bead.extend_from_slice(&row.beads);
            row_start.push(entry_bead.len());
            kinds.push(row.kind);
        }
        for (s, spring) in springs.iter().enumerate() {
            let item = || format!("spring {s}");
            check_beads(&item, &[spring.a, spring.b])?;
            for (what, value) in [
                ("rest length", spring.rest_length),
                ("stiffness", spring.stiffness),
                ("damping", spring.damping),
            ] {
                if !(value.is_finite() && value >= 0.0) {
                    return Err(IslandError::Value {
                        item: item(),
                        what,
                        range: "zero or more and finite",
                        value,
                    });
                }
            }
        }
        let normal =
            NormalMatrix::new(&row_start, &entry_bead, beads).ok_or(IslandError::OutOfMemory)?;
        let paths = vec![None; kinds.len()];
        let sides = vec![(0.0, 0.0); kinds.len()];
        let rough = vec![None; kinds.len()];
        Ok(Self {
            inverse_mass,
            rows: kinds,
            row_start,
            entry_bead,
            springs,
            normal,
            paths,
            moving: 0,
            sides,
            rough,
            rough_rows: 0,
        })
    }

    /// Moves the wire of row `row` to `pose` (a wire that moves between
    /// steps), and gives it `shape` where one is given (a wire edited in
    /// place); rows of other kinds are left as they are.
    pub fn place_wire(&mut self, row: usize, shape: Option<WireShape>, pose: Pose) {
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
            }
        }
    }

    /// Puts the wire of row `row` on `path`, a wire that moves during the
    /// step: its rows are evaluated where the wire is at each stage's
    /// time, with the terms of eq. (13) (the step's times come from
    /// [`Island::step_at`]). `shape` as for [`Island::place_wire`].
    pub fn move_wire(&mut self, row: usize, shape: Option<WireShape>, path: PosePath) {
        if let Some(pose) = path.fixed() {
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
            }
        }
    }

    /// Makes the wire of row `row` one-sided (see
    /// [`Side`](crate::geometry::Side)) with restitution `restitution`:
    /// where λ takes the sign the wire cannot push with at a step's start,
    /// the row is set aside and its bead flies with the rest of the island;
    /// where the bead crosses the wire again by a step's end, it lands
    /// there (the island projected onto it, the bead's normal velocity
    /// reversed and scaled by the restitution, the row kept aside if it
    /// bounced). Events fall on step boundaries here, so their timing is
    /// first order in the step (a lone bead's are located within the step).
    pub fn set_side(&mut self, row: usize, side: Side, restitution: f64) {
        if let (Some(RowKind::Wire { .. }), Some(slot)) =
            (self.rows.get(row), self.sides.get_mut(row))
        {
            *slot = (side.sign(), restitution.clamp(0.0, 1.0));
        }
    }

    /// Gives the wire of row `row` Coulomb friction and viscous damping
    /// along it, eq. (14b). `stick` names an axis row of the same bead
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
            let was = slot.replace(RoughRow {
                friction,
                damping: damping.max(0.0),
                stick,
            });
            if was.is_none() {
                self.rough_rows += 1;
            }
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
    pub fn energy(&self, states: &[BeadState], gravity: DVec2) -> f64 {
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

    /// One step of every bead of the island under `settings`: `states`
    /// (one per bead) advance, `forces` (one per bead, gravity included)
    /// are the external forces. On an error the states are left as they
    /// were. What the step reports of each row is in
    /// [`IslandWork::rows`].
    ///
    /// Where a Newton solve (RATTLE's positions, projection) finds no
    /// root, as when a rope's free end whips round faster than a step can
    /// follow, that part of the step and the rest of it are taken in
    /// substeps of half the length, halved again if need be, down to
    /// 2^[`MAX_HALVINGS`] substeps. The next step starts as finely as this
    /// one ended, and tries one halving fewer after [`CALM_STEPS`] steps
    /// that needed no more, so a long rope does not fail its way down to
    /// the same level every step; [`IslandWork::substeps`] says how many
    /// the last step took.
    pub fn step(
        &self,
        states: &mut [BeadState],
        forces: &[LinearForce],
        settings: &StepSettings,
        work: &mut IslandWork,
    ) -> Result<(), SolveError> {
        self.step_at(0.0, states, forces, settings, work)
    }

    /// [`Island::step`] for a step that starts at time `time`: the time
    /// at which wires on a path (see [`Island::move_wire`]) are placed.
    pub fn step_at(
        &self,
        time: f64,
        states: &mut [BeadState],
        forces: &[LinearForce],
        settings: &StepSettings,
        work: &mut IslandWork,
    ) -> Result<(), SolveError> {
        work.events.clear();
        if work.inactive.len() != self.rows() {
            // A fresh island: a bead that starts off a one-sided wire, on
            // the side it pushes toward, starts in flight; stick rows start
            // set aside (a bead slides until friction stops it).
            let whole = states.len() == self.beads();
            work.inactive.clear();
            work.inactive.resize(self.rows(), false);
            for rough in self.rough.iter().flatten() {
                if let Some(s) = rough.stick {
                    work.inactive[s] = true;
                }
            }
            for r in 0..self.rows() {
                let (side, _) = self.sides[r];
                if side != 0.0
                    && whole
                    && side * self.wire_row(r, states, time).c > OFF_THE_WIRE * self.rows[r].scale()
                {
                    work.inactive[r] = true;
                }
            }
            // A bead at rest on a rough wire starts held by static friction.
            for (r, rough) in self.rough.iter().enumerate() {
                let Some(RoughRow { stick: Some(s), .. }) = rough else {
                    continue;
                };
                let bead = self.entry_bead[self.row_start[r]];
                if work.inactive[r] || self.paths[r].is_some() || !whole {
                    continue;
                }
                let row = self.wire_row(r, states, time);
                if states[bead].velocity == row.wire {
                    let axis = row.tangent();
                    self.place_stick(*s, axis, axis.dot(states[bead].position), work);
                }
            }
        }
        let one_sided = self.one_sided();
        let rough = self.is_rough();
        if one_sided || rough {
            self.leave(time, states, forces, work)?;
        }
        let mut resisted = Vec::new();
        let slides = if rough && states.len() == self.beads() && forces.len() == self.beads() {
            resisted.extend_from_slice(forces);
            self.resist(time, states, &mut resisted, work)
        } else {
            Vec::new()
        };
        let forces = if rough { &resisted[..] } else { forces };
        self.substeps(time, states, forces, settings, work)?;
        if one_sided {
            self.land(time + settings.dt, states, forces, settings.dt, work)?;
        }
        if rough {
            self.stop(time + settings.dt, states, &slides, work)?;
        }
        self.follow(time + settings.dt, states, work);
        Ok(())
    }

    /// Eq. (14b) on the island at the step's start (λ from
    /// [`Island::leave`]): releases every stick row whose force passes
    /// static friction, and adds kinetic friction and damping to the force
    /// on each sliding bead. Returns each rough row's bead and its sliding
    /// velocity at the start.
    fn resist(
        &self,
        time: f64,
        states: &[BeadState],
        forces: &mut [LinearForce],
        work: &mut IslandWork,
    ) -> Vec<(usize, usize, DVec2)> {
        let mut slides = Vec::new();
        for (r, rough) in self.rough.iter().enumerate() {
            let Some(rough) = rough else { continue };
            let bead = self.entry_bead[self.row_start[r]];
            if work.inactive[r] {
                // In flight: nothing to rub against, nothing to stick to.
                if let Some(s) = rough.stick {
                    work.inactive[s] = true;
                }
                continue;
            }
            let row = self.wire_row(r, states, time);
            let nn = row.normal.length_squared();
            if nn.is_nan() || nn <= 0.0 {
                continue;
            }
            let press = work.lambda[r].abs() * nn.sqrt();
            let sliding = row.sliding(states[bead].velocity);
            let mut direction = sliding;
            if let Some(s) = rough.stick
                && !work.inactive[s]
            {
                let hold = work.lambda[s];
                if hold.abs() <= rough.friction.static_coefficient * press {
                    continue; // held still
                }
                // It gives way: it slides toward the pull, against λ's push.
                work.inactive[s] = true;
                if let RowKind::Axis { axis, .. } = self.rows[s] {
                    direction = -hold * axis;
                }
            }
            let speed = direction.length();
            if speed > 0.0 {
                forces[bead].force -=
                    (rough.friction.kinetic_coefficient * press / speed) * direction;
            }
            forces[bead].force -= rough.damping * sliding;
            slides.push((r, bead, sliding));
        }
        slides
    }

    /// Where friction stopped a sliding bead during the step (its sliding
    /// velocity reversed), puts its stick row across the wire there and
    /// projects the island's velocities onto the rows with it: the bead
    /// stays put while static friction can hold it.
    fn stop(
        &self,
        time: f64,
        states: &mut [BeadState],
        slides: &[(usize, usize, DVec2)],
        work: &mut IslandWork,
    ) -> Result<(), SolveError> {
        let mut stopped = false;
        for &(r, bead, before) in slides {
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
            let row = self.wire_row(r, states, time);
            let sliding = row.sliding(states[bead].velocity);
            if before != DVec2::ZERO && sliding.dot(before) >= 0.0 {
                continue;
            }
            if before == DVec2::ZERO && sliding == DVec2::ZERO {
                continue;
            }
            let axis = row.tangent();
            self.place_stick(s, axis, axis.dot(states[bead].position), work);
            stopped = true;
        }
        if stopped {
            work.time = time;
            work.x.clear();
            work.x.extend(states.iter().map(|s| s.position));
            work.v.clear();
            work.v.extend(states.iter().map(|s| s.velocity));
            self.evaluate_at_new(work);
            self.project_velocity(work)?;
            for (state, v) in states.iter_mut().zip(&work.v) {
                state.velocity = *v;
            }
        }
        Ok(())
    }

    /// Takes stick row `s` back, as the line `axis·x = offset`.
    fn place_stick(&self, s: usize, axis: DVec2, offset: f64, work: &mut IslandWork) {
        work.inactive[s] = false;
        work.sticks.resize(self.rows(), None);
        work.sticks[s] = Some((axis, offset));
    }

    /// Keeps each wire row's curve parameter where its bead is now (at
    /// `time`), and reports each set-aside row's own `C` and `Ċ`.
    fn follow(&self, time: f64, states: &[BeadState], work: &mut IslandWork) {
        work.hints.resize(self.rows(), f64::NAN);
        for r in 0..self.rows() {
            let (Some((shape, pose, _)), Some(state)) = (
                self.wire_at(r, time),
                states.get(self.entry_bead[self.row_start[r]]),
            ) else {
                continue;
            };
            let local = pose.to_local(state.position);
            work.hints[r] = shape.curve().parameter(local, work.hints[r]);
            if work.inactive.get(r) == Some(&true)
                && let Some(report) = work.reports.get_mut(r)
            {
                let row = self.wire_row(r, states, time);
                report.c = row.c;
                report.c_dot = row.normal.dot(state.velocity - row.wire);
            }
        }
    }

    /// Sets aside every one-sided row whose λ (eq. 10 with no
    /// stabilization) at the step's start has the sign its wire cannot
    /// push with.
    fn leave(
        &self,
        time: f64,
        states: &[BeadState],
        forces: &[LinearForce],
        work: &mut IslandWork,
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
            let (side, _) = self.sides[r];
            if side != 0.0 && !work.inactive[r] && side * work.lambda[r] < 0.0 {
                work.inactive[r] = true;
                let bead = self.entry_bead[self.row_start[r]];
                let position = states[bead].position;
                work.events
                    .push((r, bead, ContactEvent::Left { time, position }));
            }
        }
        Ok(())
    }

    /// Lands every bead whose set-aside one-sided row it crossed during the
    /// step: the island projected onto its rows with that one back, the
    /// bead's velocity across the wire reversed and scaled by the
    /// restitution.
    fn land(
        &self,
        time: f64,
        states: &mut [BeadState],
        forces: &[LinearForce],
        h: f64,
        work: &mut IslandWork,
    ) -> Result<(), SolveError> {
        work.time = time;
        for r in 0..self.rows() {
            let (side, restitution) = self.sides[r];
            if side == 0.0 || !work.inactive[r] {
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
            work.x.clear();
            work.x.extend(states.iter().map(|s| s.position));
            work.v.clear();
            work.v.extend(states.iter().map(|s| s.velocity));
            self.newton(work, Direction::Current)?;
            self.evaluate_at_new(work);
            let nn = normal.length_squared().max(f64::MIN_POSITIVE);
            let across = normal.dot(velocity - wire);
            let normal_speed = across.abs() / nn.sqrt();
            let push =
                (normal.dot(forces[bead].at(position)) * self.inverse_mass[bead]).abs() / nn.sqrt();
            let bounced = restitution > 0.0 && restitution * normal_speed > push * h;
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

    /// Wire row `r` where its bead is in `states` at `time`, whether the
    /// row is held or not (zero for a row of another kind).
    fn wire_row(&self, r: usize, states: &[BeadState], time: f64) -> RowAt {
        let (Some((shape, pose, twist)), Some(state)) = (
            self.wire_at(r, time),
            states.get(self.entry_bead[self.row_start[r]]),
        ) else {
            return RowAt::default();
        };
        let g = Placed {
            curve: shape.curve(),
            pose,
        }
        .geometry(state.position);
        RowAt {
            c: g.c,
            normal: g.normal,
            wire: twist.velocity_at(state.position),
        }
    }

    /// The shape of wire row `r` and where its wire is at `time`, with its
    /// twist; none for a row of another kind.
    fn wire_at(&self, r: usize, time: f64) -> Option<(&WireShape, Pose, Twist)> {
        let RowKind::Wire { shape, pose } = &self.rows[r] else {
            return None;
        };
        let (pose, twist) = match &self.paths[r] {
            Some(path) => path.at(time),
            None => (*pose, Twist::default()),
        };
        Some((shape, pose, twist))
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
        states: &mut [BeadState],
        forces: &[LinearForce],
        settings: &StepSettings,
        work: &mut IslandWork,
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
        states: &mut [BeadState],
        forces: &[LinearForce],
        settings: &StepSettings,
        work: &mut IslandWork,
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
                let semi = matches!(settings.method, Method::SemiImplicitEuler(_));
                for i in 0..n {
                    let (x, v, a) = (work.x0[i], work.v0[i], work.acceleration[i]);
                    let v1 = v + h * a;
                    work.x[i] = x + h * if semi { v1 } else { v };
                    work.v[i] = v1;
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
            let bound = settings.drift_bound * self.rows[r].scale();
            let c = work.c[r];
            if c.is_nan() || c.abs() > bound {
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
        work.bead_forces.resize(n, DVec2::ZERO);
        for (r, report) in work.reports.iter_mut().enumerate() {
            report.c = work.c[r];
            report.c_dot = self.rate(r, &work.gradient, &work.v, &work.bias);
            let entries = self.row_start[r]..self.row_start[r + 1];
            for (&bead, g) in self.entry_bead[entries.clone()]
                .iter()
                .zip(&work.gradient[entries])
            {
                work.bead_forces[bead] += report.lambda * *g;
            }
        }
        for (state, (x, v)) in states.iter_mut().zip(work.x.iter().zip(&work.v)) {
            state.position = *x;
            state.velocity = *v;
        }
        work.substeps += 1;
        Ok(())
    }

    /// Evaluates every row at `(x, v)` at `work.time`: gradients, `C`,
    /// and where `rates`, `J̇q̇` and the bias `−∂C/∂t`, into `out` (without
    /// `rates` those two keep what they held).
    fn evaluate(
        &self,
        x: &[DVec2],
        v: &[DVec2],
        time: f64,
        held: Held<'_>,
        out: Rows<'_>,
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
        gradient.resize(self.entry_bead.len(), DVec2::ZERO);
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
                gradient[range].fill(DVec2::ZERO);
                (c[r], curvature[r], bias[r]) = (0.0, 0.0, 0.0);
                continue;
            }
            if let Some(Some((axis, offset))) = sticks.get(r) {
                // A stick row, placed where its bead stopped.
                let bead = self.entry_bead[range.start];
                gradient[range.start] = *axis;
                (c[r], curvature[r], bias[r]) = (axis.dot(x[bead]) - offset, 0.0, 0.0);
                continue;
            }
            let path = if self.moving > 0 {
                self.paths[r].as_ref()
            } else {
                None
            };
            if let (Some(path), RowKind::Wire { shape, .. }) = (path, kind) {
                // Eq. (13): the wire where it is at `time`, seen from its frame.
                let bead = self.entry_bead[range.start];
                let (p, u) = (x[bead], v[bead]);
                let (pose, twist) = path.at(time);
                let g = Placed {
                    curve: &Near {
                        curve: shape.curve(),
                        hint: hint(r),
                    },
                    pose,
                }
                .geometry(p);
                let w = twist.velocity_at(p);
                let relative = u - w;
                gradient[range.start] = g.normal;
                c[r] = g.c;
                if !rates {
                    continue;
                }
                curvature[r] = relative.dot(g.hessian * relative)
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
    fn evaluate_at_new(&self, work: &mut IslandWork) {
        self.evaluate_work(work, false, work.time, true);
    }

    /// [`Island::evaluate_at_new`] without `J̇q̇` and the bias: what a
    /// position solve's iterations need.
    fn evaluate_positions(&self, work: &mut IslandWork) {
        self.evaluate_work(work, false, work.time, false);
    }

    /// Evaluates the rows at the step's start `work.x0`, `work.v0` into
    /// `work.first_gradient` (and `work.c`, `work.curvature`, `work.bias`).
    fn evaluate_at_start(&self, work: &mut IslandWork, time: f64) {
        self.evaluate_work(work, true, time, true);
    }

    /// [`Island::evaluate`] on the work's state: the start's into
    /// `work.first_gradient`, or the current one into `work.gradient`.
    fn evaluate_work(&self, work: &mut IslandWork, at_start: bool, time: f64, rates: bool) {
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
    fn along(&self, r: usize, gradient: &[DVec2], v: &[DVec2]) -> f64 {
        (self.row_start[r]..self.row_start[r + 1])
            .map(|e| gradient[e].dot(v[self.entry_bead[e]]))
            .sum()
    }

    /// `Ċ_r = Σ g·v − bias` over row `r`'s entries: the rate relative to
    /// a moving wire.
    fn rate(&self, r: usize, gradient: &[DVec2], v: &[DVec2], bias: &[f64]) -> f64 {
        self.along(r, gradient, v) - bias[r]
    }

    /// The applied forces at `(x, v)`: each bead's external force, plus
    /// the springs.
    fn applied(&self, forces: &[LinearForce], x: &[DVec2], v: &[DVec2], out: &mut Vec<DVec2>) {
        out.clear();
        out.extend(forces.iter().zip(x).map(|(f, &p)| f.at(p)));
        for spring in &self.springs {
            let f = spring.force(x, v);
            out[spring.a] += f;
            out[spring.b] -= f;
        }
    }

    /// Adds `W Jᵀ μ` (with `gradient`) to `out`.
    fn push(&self, gradient: &[DVec2], mu: &[f64], out: &mut [DVec2]) {
        for (r, &m) in mu.iter().enumerate() {
            let entries = self.row_start[r]..self.row_start[r + 1];
            for (&bead, g) in self.entry_bead[entries.clone()]
                .iter()
                .zip(&gradient[entries])
            {
                out[bead] += (m * self.inverse_mass[bead]) * *g;
            }
        }
    }

    /// Factors `J W Jᵀ` at the work's current state (`work.gradient` at
    /// `work.x`), or at the step's start (`work.first_gradient` at
    /// `work.x0`); a vanishing row is a singular point, reported at its
    /// first bead's position.
    fn factor(&self, work: &mut IslandWork, at_start: bool) -> Result<(), SolveError> {
        let (gradient, x) = if at_start {
            (&work.first_gradient, &work.x0)
        } else {
            (&work.gradient, &work.x)
        };
        self.normal
            .factor(
                &self.inverse_mass,
                gradient,
                &work.inactive,
                self.natural_order(),
                &mut work.factored,
            )
            .map_err(|r| {
                let p = x[self.entry_bead[self.row_start[r]]];
                SolveError::Singular { x: p.x, y: p.y }
            })
    }

    /// Eq. (10) at a stage `(x, v)`: λ, and the accelerations
    /// `W (Q + Jᵀλ)` into `work.acceleration`, at `work.x, work.v` (set to
    /// `work.x0, work.v0` first at the step's start).
    fn accelerate(
        &self,
        forces: &[LinearForce],
        gains: Gains,
        work: &mut IslandWork,
        stage: Stage,
    ) -> Result<(), SolveError> {
        if stage == Stage::Start {
            work.x.clone_from(&work.x0);
            work.v.clone_from(&work.v0);
        }
        self.evaluate_at_new(work);
        self.applied(forces, &work.x, &work.v, &mut work.force);
        if self.rows() > 0 {
            self.factor(work, false)?;
        }
        work.lambda.clear();
        for r in 0..self.rows() {
            let pushed: f64 = (self.row_start[r]..self.row_start[r + 1])
                .map(|e| {
                    let bead = self.entry_bead[e];
                    work.gradient[e].dot(self.inverse_mass[bead] * work.force[bead])
                })
                .sum();
            let c_dot = self.rate(r, &work.gradient, &work.v, &work.bias);
            work.lambda
                .push(-work.curvature[r] - pushed - gains.alpha * work.c[r] - gains.beta * c_dot);
        }
        self.normal.solve(&mut work.factored, &mut work.lambda);
        work.acceleration.clear();
        work.acceleration.extend(
            work.force
                .iter()
                .zip(&self.inverse_mass)
                .map(|(f, w)| *w * *f),
        );
        self.push(&work.gradient, &work.lambda, &mut work.acceleration);
        Ok(())
    }

    /// Keeps the last solve's λ as the step's report.
    fn keep_lambda(&self, work: &mut IslandWork) {
        work.reports.clear();
        work.reports
            .extend(work.lambda.iter().map(|&lambda| RowReport {
                lambda,
                ..RowReport::default()
            }));
    }

    /// Eq. (7) on the island: four solves of eq. (10); λ reported is the
    /// first stage's.
    fn rk4(
        &self,
        forces: &[LinearForce],
        gains: Gains,
        h: f64,
        work: &mut IslandWork,
    ) -> Result<(), SolveError> {
        self.accelerate(forces, gains, work, Stage::Start)?;
        self.keep_lambda(work);
        let n = self.beads();
        let start = work.time;
        work.x_sum.clone_from(&work.v0);
        work.v_sum.clone_from(&work.acceleration);
        for (weight, advance) in [(2.0, 0.5 * h), (2.0, 0.5 * h), (1.0, h)] {
            // The stage's state from the previous stage's derivative, which
            // is (work.v, work.acceleration).
            for i in 0..n {
                let (dx, dv) = (work.v[i], work.acceleration[i]);
                work.x[i] = work.x0[i] + advance * dx;
                work.v[i] = work.v0[i] + advance * dv;
            }
            work.time = start + advance;
            self.accelerate(forces, gains, work, Stage::Later)?;
            for i in 0..n {
                work.x_sum[i] += weight * work.v[i];
                work.v_sum[i] += weight * work.acceleration[i];
            }
        }
        let sixth = h / 6.0;
        for i in 0..n {
            work.x[i] = work.x0[i] + sixth * work.x_sum[i];
            work.v[i] = work.v0[i] + sixth * work.v_sum[i];
        }
        Ok(())
    }

    /// Newton's method for `C(x + W Jᵀ μ) = 0` from `work.x`, along the
    /// gradients of `direction`: moves `work.x` onto the constraints and
    /// returns with `work.lambda` holding the total μ.
    ///
    /// Along the current gradients (projection) each iteration factors
    /// `J W Jᵀ` afresh. Along the first gradients (RATTLE) the Newton
    /// matrix `J(x) W J₀ᵀ` is not symmetric: one row takes the exact step;
    /// several start as a chord iteration on the factored `J₀ W J₀ᵀ` (no
    /// new factorization, linear convergence at a rate set by how far the
    /// rows turn over the step) and switch to exact Newton steps (LU of
    /// the band or sparse matrix) once the chord stops shrinking `C`
    /// fourfold per iteration. Two exact steps that do not shrink `C`, or
    /// [`EXACT_STEPS`] that do not reach the tolerance, mean no root near:
    /// the step is halved. The iterations evaluate `C` and the gradients
    /// only, not `J̇q̇` or the bias.
    fn newton(&self, work: &mut IslandWork, direction: Direction) -> Result<(), SolveError> {
        let rows = self.rows();
        work.lambda.clear();
        work.lambda.resize(rows, 0.0);
        let mut exact = direction == Direction::First && rows == 1;
        let mut previous = f64::INFINITY;
        let mut rising = 0;
        let mut exacts = 0;
        let mut i = 0;
        loop {
            self.evaluate_positions(work);
            let last = i == NEWTON_MAX_ITERATIONS;
            let tolerance = if last {
                NEWTON_ACCEPT
            } else {
                NEWTON_TOLERANCE
            };
            let mut done = true;
            let mut worst = 0.0f64;
            for r in 0..rows {
                let scale = self.rows[r].scale().max(f64::MIN_POSITIVE);
                let residual = work.c[r].abs();
                worst = worst.max(residual / scale);
                done &= residual <= tolerance * scale;
            }
            // Rounding keeps C from the tolerance where coordinates are
            // large beside a row's scale: stop once it no longer shrinks.
            let stalled = worst <= NEWTON_ACCEPT && worst > 0.5 * previous;
            if done || stalled {
                return self.same_branch(work, direction, worst);
            }
            if last || !worst.is_finite() {
                return Err(SolveError::NoConvergence {
                    iterations: NEWTON_MAX_ITERATIONS,
                    residual: worst,
                });
            }
            if exact && direction == Direction::First && worst >= previous {
                // Exact Newton steps converge fast near a root; two that do
                // not shrink C mean there is none near: halve the step.
                rising += 1;
                if rising == 2 {
                    return Err(SolveError::NoConvergence {
                        iterations: i,
                        residual: worst,
                    });
                }
            } else {
                rising = 0;
            }
            exact |= direction == Direction::First && worst > 0.25 * previous;
            if exact && direction == Direction::First {
                // Exact Newton steps converge quadratically near a root:
                // this many that have not reached it mean there is none near.
                exacts += 1;
                if exacts > EXACT_STEPS {
                    return Err(SolveError::NoConvergence {
                        iterations: i,
                        residual: worst,
                    });
                }
            }
            previous = worst;
            work.rhs.clear();
            work.rhs.extend(work.c.iter().map(|c| -c));
            let along = match direction {
                Direction::First => &work.first_gradient,
                Direction::Current => {
                    self.factor(work, false)?;
                    &work.gradient
                }
            };
            let solved_exactly = exact
                && self.normal.solve_unsymmetric(
                    &self.inverse_mass,
                    &work.gradient,
                    along,
                    &mut work.lu,
                    &mut work.rhs,
                    self.natural_order(),
                );
            if !solved_exactly {
                // A singular Newton matrix (a redundant row): the chord step.
                work.rhs.clear();
                work.rhs.extend(work.c.iter().map(|c| -c));
                self.normal.solve(&mut work.factored, &mut work.rhs);
            }
            for (total, step) in work.lambda.iter_mut().zip(&work.rhs) {
                *total += step;
            }
            self.push(along, &work.rhs, &mut work.x);
            i += 1;
        }
    }

    /// Checks that a Newton solution is the continuation of the start: no
    /// row's gradient may have turned by a right angle or more from the
    /// direction it was moved along (a rod flipped end over end, a bead
    /// carried across its wire's centre). Such a root is refused as no
    /// convergence, so the step is halved.
    fn same_branch(
        &self,
        work: &IslandWork,
        direction: Direction,
        residual: f64,
    ) -> Result<(), SolveError> {
        if direction == Direction::Current {
            return Ok(());
        }
        for r in 0..self.rows() {
            if work.inactive.get(r) == Some(&true) {
                continue;
            }
            let turn: f64 = (self.row_start[r]..self.row_start[r + 1])
                .map(|e| work.gradient[e].dot(work.first_gradient[e]))
                .sum();
            if turn.is_nan() || turn <= 0.0 {
                return Err(SolveError::NoConvergence {
                    iterations: NEWTON_MAX_ITERATIONS,
                    residual,
                });
            }
        }
        Ok(())
    }

    /// Removes the velocity's component off the constraints:
    /// `v ← v − W Jᵀ (J W Jᵀ)⁻¹ J v` at `work.x` (rows evaluated there).
    /// Returns with the multipliers (of `−J v`) in `work.rhs`.
    fn project_velocity(&self, work: &mut IslandWork) -> Result<(), SolveError> {
        if self.rows() == 0 {
            return Ok(());
        }
        self.factor(work, false)?;
        work.rhs.clear();
        for r in 0..self.rows() {
            work.rhs
                .push(-self.rate(r, &work.gradient, &work.v, &work.bias));
        }
        self.normal.solve(&mut work.factored, &mut work.rhs);
        self.push(&work.gradient, &work.rhs, &mut work.v);
        Ok(())
    }

    /// Post-stabilization, eq. (11): Newton steps along the current
    /// gradients bring every `C` to zero and the velocity is projected onto
    /// `J v = 0`; then the velocities are scaled by one factor for the
    /// island (which keeps `J v = 0`). After an Euler step of length `h`
    /// the factor gives the kinetic energy of `v₀ + h P₀ W Q`: the start
    /// velocity plus the step's kick with its part off the constraints at
    /// the start removed (`P₀` the mass-weighted projection onto
    /// `J₀ v = 0`), eq. (9b). After RK4 it keeps the energy of a
    /// conservative island (no spring damping) what it was, eq. (9c).
    fn project(
        &self,
        forces: &[LinearForce],
        restore: Restore,
        work: &mut IslandWork,
    ) -> Result<(), SolveError> {
        self.newton(work, Direction::Current)?;
        self.evaluate_at_new(work);
        self.project_velocity(work)?;
        let kinetic = |v: &[DVec2]| -> f64 {
            v.iter()
                .zip(&self.inverse_mass)
                .map(|(v, w)| 0.5 * v.length_squared() / w)
                .sum()
        };
        let now = kinetic(&work.v);
        let h = match restore {
            Restore::Nothing => return Ok(()),
            Restore::Speed(h) => h,
            Restore::Energy => {
                if self.springs.iter().any(|s| s.damping != 0.0) {
                    return Ok(());
                }
                let potential = |x: &[DVec2]| -> f64 {
                    let applied: f64 = forces.iter().zip(x).map(|(f, x)| f.potential(*x)).sum();
                    applied + self.springs.iter().map(|s| s.energy(x)).sum::<f64>()
                };
                let target = kinetic(&work.v0) + potential(&work.x0) - potential(&work.x);
                let scale = energy_scale(target, now);
                for v in &mut work.v {
                    *v *= scale;
                }
                return Ok(());
            }
        };
        // The applied kick W Q at the start, its part off J₀ removed.
        self.evaluate_at_start(work, work.time - h);
        self.applied(forces, &work.x0, &work.v0, &mut work.force);
        for (f, w) in work.force.iter_mut().zip(&self.inverse_mass) {
            *f *= *w;
        }
        if self.rows() > 0 {
            self.factor(work, true)?;
            work.rhs.clear();
            for r in 0..self.rows() {
                work.rhs
                    .push(-self.along(r, &work.first_gradient, &work.force));
            }
            self.normal.solve(&mut work.factored, &mut work.rhs);
            self.push(&work.first_gradient, &work.rhs, &mut work.force);
        }
        let target: f64 = work
            .v0
            .iter()
            .zip(&work.force)
            .zip(&self.inverse_mass)
            .map(|((v, a), w)| 0.5 * (*v + h * *a).length_squared() / w)
            .sum();
        let scale = kinetic_scale(target, now);
        for v in &mut work.v {
            *v *= scale;
        }
        // The gradients where the step ended, for the report.
        self.evaluate_at_new(work);
        Ok(())
    }

    /// Eq. (8) for an island: SHAKE's position solve (Newton on all of the
    /// island's `C` along `W J₀ᵀ`), then the linear velocity solve.
    fn rattle(
        &self,
        forces: &[LinearForce],
        h: f64,
        work: &mut IslandWork,
    ) -> Result<(), SolveError> {
        let n = self.beads();
        self.evaluate_at_start(work, work.time);
        if self.rows() > 0 {
            self.factor(work, true)?;
        }
        self.applied(forces, &work.x0, &work.v0, &mut work.force);
        work.x.clear();
        work.v.clear();
        for i in 0..n {
            let w = self.inverse_mass[i];
            work.x
                .push(work.x0[i] + h * work.v0[i] + (0.5 * h * h * w) * work.force[i]);
            work.v.push(work.v0[i]);
        }
        work.time += h;
        self.newton(work, Direction::First)?;
        let to_lambda = 2.0 / (h * h);
        work.reports.clear();
        work.reports.extend(work.lambda.iter().map(|&mu| RowReport {
            lambda: 0.5 * to_lambda * mu,
            ..RowReport::default()
        }));
        // v½ and the second half kick, at the new positions.
        for i in 0..n {
            work.v[i] = (work.x[i] - work.x0[i]) / h;
        }
        self.applied(forces, &work.x, &work.v, &mut work.force);
        for i in 0..n {
            work.v[i] += (0.5 * h * self.inverse_mass[i]) * work.force[i];
        }
        self.evaluate_at_new(work);
        self.project_velocity(work)?;
        let to_mu = 2.0 / h;
        for (report, nu) in work.reports.iter_mut().zip(&work.rhs) {
            report.lambda += 0.5 * to_mu * nu;
        }
        Ok(())
    }
}

/// A wire row where its bead is: `C`, `∇C`, and the velocity of the
/// wire's point there.
#[derive(Clone, Copy, Default)]
struct RowAt {
    c: f64,
    normal: DVec2,
    wire: DVec2,
}

impl RowAt {
    /// The part of `velocity`, relative to the wire, along it.
    fn sliding(&self, velocity: DVec2) -> DVec2 {
        let relative = velocity - self.wire;
        let nn = self.normal.length_squared();
        relative - self.normal * (self.normal.dot(relative) / nn)
    }

    /// The unit direction along the wire: a stick row's axis.
    fn tangent(&self) -> DVec2 {
        DVec2::new(-self.normal.y, self.normal.x).normalize_or_zero()
    }
}

/// Which rows [`Island::evaluate`] holds, and where along their curves
/// the wire rows' beads were.
struct Held<'a> {
    inactive: &'a [bool],
    hints: &'a [f64],
    sticks: &'a [Option<(DVec2, f64)>],
}

/// Where [`Island::evaluate`] writes.
struct Rows<'a> {
    gradient: &'a mut Vec<DVec2>,
    c: &'a mut Vec<f64>,
    curvature: &'a mut Vec<f64>,
    bias: &'a mut Vec<f64>,
    scratch: &'a mut Vec<DVec2>,
}

/// How a projection ends (see [`Island::project`]).
#[derive(Clone, Copy, PartialEq)]
enum Restore {
    /// As projected: an island on a moving wire, which does work on it.
    Nothing,
    /// The pre-kick speed after an Euler step of this length, eq. (9b).
    Speed(f64),
    /// The energy of the step's start after RK4, eq. (9c).
    Energy,
}

/// Which state a solve of eq. (10) is at.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Stage {
    /// The step's start, `work.x0, work.v0`.
    Start,
    /// A later stage, `work.x, work.v`.
    Later,
}

/// The gradients a Newton iteration moves along.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Direction {
    /// Those at the step's start (RATTLE), factored before the iteration.
    First,
    /// Those at each iterate (projection), factored at each.
    Current,
}
