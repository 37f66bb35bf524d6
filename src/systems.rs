//! Every system of the plugin, public so a game can order its own systems
//! against them. They only move data between the ECS and [`crate::solver`].

use std::sync::{Mutex, PoisonError};

use bevy::ecs::change_detection::{ContiguousMut, Tick};
use bevy::ecs::storage::SparseSet;
use bevy::ecs::system::{SystemChangeTick, SystemParam};
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::tasks::ComputeTaskPool;

use crate::components::{
    Bead, BeadDiagnostics, Diverged, DivergenceReason, DragTarget, OnWire, PendingWire, Wire,
    WirePose,
};
use crate::params::{PendingBead, PendingParams, SimParams};
use crate::plugin::{BeadDiverged, ParallelStep, Restart, SimClock};
use crate::solver::{self, LinearForce, StepConfig};
use crate::wire::{ImplicitCurve, Placed, Pose, WireShape};

/// Runs `f` on every item of `query`: on the compute task pool when the
/// query has at least `parallel.threshold` items, in this thread otherwise.
/// The count is the iterator's upper bound: exact under archetype filters
/// (`Without`), the matched tables' rows under `Changed`.
macro_rules! for_each_bead {
    ($query:expr, $parallel:expr, $f:expr) => {{
        let f = $f;
        if $query.iter().size_hint().1.unwrap_or(usize::MAX) >= $parallel.threshold {
            $query.par_iter_mut().for_each(f);
        } else {
            $query.iter_mut().for_each(f);
        }
    }};
}

/// Divergences found inside a (possibly parallel) loop, reported after it.
#[derive(Default)]
pub struct Found(Mutex<Vec<(Entity, DivergenceReason, f64)>>);

impl Found {
    fn push(&self, bead: Entity, reason: DivergenceReason, time: f64) {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push((bead, reason, time));
    }

    fn report(&mut self, divergences: &mut Divergences) {
        let found = self.0.get_mut().unwrap_or_else(PoisonError::into_inner);
        for (bead, reason, time) in found.drain(..) {
            divergences.report(bead, reason, time);
        }
    }
}

/// The diagnostics of a bead's current state on `curve`.
pub fn diagnose(
    curve: &dyn ImplicitCurve,
    bead: &Bead,
    gravity: bevy::math::DVec2,
) -> BeadDiagnostics {
    let (c, c_dot) = solver::drift(curve, bead.state());
    let (kinetic, potential) = solver::energy(bead.mass(), gravity, bead.state());
    BeadDiagnostics {
        c,
        c_dot,
        lambda: bead.lambda,
        kinetic,
        potential,
        ..default()
    }
}

/// Marks beads diverged: inserts [`Diverged`], sends [`BeadDiverged`] and
/// logs a warning.
#[derive(SystemParam)]
pub struct Divergences<'w, 's> {
    commands: Commands<'w, 's>,
    messages: MessageWriter<'w, BeadDiverged>,
}

impl Divergences<'_, '_> {
    /// Reports that `bead` stopped at simulated time `time`.
    pub fn report(&mut self, bead: Entity, reason: DivergenceReason, time: f64) {
        warn!(
            "wirebead: bead {bead} diverged at t = {time:.4} s: {reason}; press Space (send Restart) to recover"
        );
        self.commands.entity(bead).try_insert(Diverged {
            reason: reason.clone(),
            time,
        });
        self.messages.write(BeadDiverged { bead, reason });
    }
}

/// Sets `Time<Fixed>` to the applied timestep at startup.
pub fn apply_timestep(params: Res<SimParams>, mut time: ResMut<Time<Fixed>>) {
    time.set_timestep_seconds(params.timestep);
}

/// Handles [`Restart`]: applies the pending wire shapes and parameters and
/// returns every bead to its initial state.
pub fn apply_restart(
    mut restarts: MessageReader<Restart>,
    pending: Res<PendingParams>,
    mut params: ResMut<SimParams>,
    mut time: ResMut<Time<Fixed>>,
    mut clock: ResMut<SimClock>,
    mut wires: Query<(Entity, &mut Wire, &Transform, Option<&PendingWire>)>,
    mut beads: Query<(
        Entity,
        &mut Bead,
        Option<&mut BeadDiagnostics>,
        Option<&OnWire>,
        Option<&PendingBead>,
    )>,
    mut commands: Commands,
) {
    if restarts.read().count() == 0 {
        return;
    }
    for (entity, mut wire, _, edit) in &mut wires {
        if let Some(edit) = edit {
            *wire = edit.wire().clone();
            commands.entity(entity).remove::<PendingWire>();
        }
    }
    *params = pending.get().clone();
    time.set_timestep_seconds(params.timestep);
    let overstep = time.overstep();
    time.discard_overstep(overstep);
    *clock = SimClock::default();
    for (entity, mut bead, diagnostics, on_wire, edit) in &mut beads {
        let bead_params = edit.map_or(*bead.params(), |p| *p.get());
        bead.reset(bead_params);
        commands.entity(entity).remove::<(Diverged, PendingBead)>();
        let Some(mut diagnostics) = diagnostics else {
            continue;
        };
        let wire = on_wire.and_then(|on| wires.get(on.0).ok());
        *diagnostics = match wire.map(|(_, w, t, _)| (w, Pose::from_transform(t))) {
            Some((wire, Ok(pose))) => {
                let placed = Placed {
                    curve: wire.shape().curve(),
                    pose,
                };
                diagnose(&placed, &bead, params.gravity)
            }
            _ => BeadDiagnostics::default(),
        };
    }
}

/// Prepares the step: places every wire (reads each changed wire
/// `Transform` once, so the beads do not) and advances the [`SimClock`].
pub fn prepare_step(
    params: Res<SimParams>,
    mut clock: ResMut<SimClock>,
    mut wires: Query<(&Transform, &mut WirePose), Changed<Transform>>,
) {
    for (transform, mut pose) in &mut wires {
        *pose = WirePose::from_transform(transform);
    }
    clock.steps += 1;
    clock.time += params.timestep;
}

/// Adds the seed's drag spring `k (target - x)` to dragged beads.
pub fn apply_drag(
    params: Res<SimParams>,
    mut beads: Query<(&mut Bead, &DragTarget), Without<Diverged>>,
) {
    for (mut bead, target) in &mut beads {
        bead.add_spring(params.drag_stiffness, target.get());
    }
}

/// Runs `$body` with `$curve` bound to the shape's concrete curve, so the
/// solver is inlined for each built-in shape.
macro_rules! with_curve {
    ($shape:expr, $curve:ident => $body:expr) => {
        match $shape {
            WireShape::Circle($curve) => $body,
            WireShape::Ellipse($curve) => $body,
            WireShape::Line($curve) => $body,
            WireShape::Parabola($curve) => $body,
            WireShape::Sine($curve) => $body,
            WireShape::Custom(custom) => {
                let $curve = custom.as_ref();
                $body
            }
        }
    };
}

/// A wire's shape and pose for the step, or why beads cannot be stepped on
/// it.
type PlacedWire = Result<(WireShape, Pose), DivergenceReason>;

/// Every wire's shape and pose, kept by [`step_beads`] from change
/// detection (a copy made when a wire changes, not each step), so a bead
/// finds its wire with one indexed read instead of a query lookup.
#[derive(Default)]
pub struct WireTable(SparseSet<Entity, (Entity, PlacedWire)>);

impl WireTable {
    /// Takes in the wires that changed or were added since the last call,
    /// and drops the ones whose `Wire` or `WirePose` was removed.
    fn refresh<'a>(
        &mut self,
        removed: impl IntoIterator<Item = Entity>,
        changed: impl IntoIterator<Item = (Entity, &'a Wire, &'a WirePose)>,
    ) {
        for entity in removed {
            if self.0.get(entity).is_some_and(|(e, _)| *e == entity) {
                self.0.remove(entity);
            }
        }
        for (entity, wire, pose) in changed {
            let placed = pose
                .get()
                .map(|pose| (wire.shape().clone(), pose))
                .map_err(|e| DivergenceReason::InvalidWire(e.to_string()));
            self.0.insert(entity, (entity, placed));
        }
    }

    /// The shape and pose of the wire a bead is on.
    fn get(&self, on: &OnWire) -> Result<&(WireShape, Pose), DivergenceReason> {
        match self.0.get(on.0) {
            Some((entity, placed)) if *entity == on.0 => placed.as_ref().map_err(Clone::clone),
            _ => Err(DivergenceReason::InvalidWire(format!(
                "entity {} has no Wire",
                on.0
            ))),
        }
    }
}

/// What stepping a run of beads needs, shared by the threads.
struct StepContext<'a> {
    params: &'a SimParams,
    wires: &'a WireTable,
    found: &'a Found,
    time: f64,
    /// The step's config when it is one [`solver::step_on_circles`] takes.
    batch: Option<StepConfig>,
}

impl StepContext<'_> {
    /// Steps a run of beads stored side by side (`diagnostics`, when
    /// present, lines up with `beads`). Beads on unrotated circles go
    /// through the batched step, [`solver::LANES`] at a time, when the
    /// config allows; the others, and the lanes it hands back, one by one.
    fn step_run(&self, mut run: Run) {
        let mut lanes = solver::CircleLanes::default();
        let mut waiting = [0; solver::LANES];
        let mut queued = 0;
        for i in 0..run.beads.len() {
            let wire = self.wires.get(&run.on_wires[i]);
            if let (Some(cfg), Ok((WireShape::Circle(circle), pose))) = (&self.batch, wire)
                && pose.is_unrotated()
            {
                let bead = &run.beads[i];
                let mass = bead.mass();
                lanes.set(
                    queued,
                    bead.state(),
                    &self.force_on(bead),
                    mass,
                    pose.origin,
                    circle.radius,
                );
                waiting[queued] = i;
                queued += 1;
                if queued == solver::LANES {
                    let bound = self.params.divergence_bound;
                    let outs = solver::step_on_circles(&lanes, cfg, bound);
                    for (lane, &j) in waiting.iter().enumerate() {
                        match outs.lane(lane) {
                            Some(out) => self.finish(run.slot(j), out),
                            None => self.step_one(&mut run, j),
                        }
                    }
                    queued = 0;
                }
                continue;
            }
            self.step_one(&mut run, i);
        }
        for &j in &waiting[..queued] {
            self.step_one(&mut run, j);
        }
    }

    /// Gravity plus the accumulated force, linearized at the bead.
    fn force_on(&self, bead: &Bead) -> LinearForce {
        LinearForce {
            force: bead.force + bead.mass() * self.params.gravity,
            stiffness: bead.force_stiffness,
            at: bead.position,
        }
    }

    /// Bead `i` of `run` through [`solver::step`]; a failure is recorded.
    fn step_one(&self, run: &mut Run, i: usize) {
        let result = match self.wires.get(&run.on_wires[i]) {
            Err(reason) => Err(reason),
            Ok((shape, pose)) => with_curve!(shape, curve => {
                self.step_bead(&Placed { curve, pose: *pose }, &run.beads[i])
            }),
        };
        match result {
            Ok(out) => self.finish(run.slot(i), out),
            Err(reason) => {
                // The bead keeps its state; its `Transform` shows it.
                let slot = run.slot(i);
                if let Some(transform) = slot.transform {
                    place(transform, slot.bead.position);
                }
                self.found.push(run.entities[i], reason, self.time);
            }
        }
    }

    /// Eq. 1.9 and the integrator for one bead.
    fn step_bead<C: ImplicitCurve + ?Sized>(
        &self,
        placed: &Placed<C>,
        bead: &Bead,
    ) -> Result<solver::StepOutput, DivergenceReason> {
        let state = bead.state();
        if !state.is_finite() {
            return Err(DivergenceReason::NonFiniteState);
        }
        let cfg = step_config(self.params, bead.mass(), placed.scale());
        solver::step(placed, state, &self.force_on(bead), &cfg).map_err(DivergenceReason::Solve)
    }

    /// Stores a step's result: the new state, λ, the consumed force, the
    /// diagnostics, the `Transform`'s translation.
    #[inline(always)]
    fn finish(&self, slot: Slot, out: solver::StepOutput) {
        let Slot {
            bead,
            diagnostics,
            transform,
        } = slot;
        bead.position = out.state.position;
        bead.velocity = out.state.velocity;
        bead.lambda = out.lambda;
        bead.force = DVec2::ZERO;
        bead.force_stiffness = 0.0;
        if let Some(diagnostics) = diagnostics {
            let (kinetic, potential) = solver::energy(bead.mass(), self.params.gravity, out.state);
            *diagnostics = BeadDiagnostics {
                c: out.c,
                c_dot: out.c_dot,
                lambda: out.lambda,
                constraint_force: out.constraint_force,
                kinetic,
                potential,
                steps: diagnostics.steps + 1,
                time: diagnostics.time + self.params.timestep,
            };
        }
        if let Some(transform) = transform {
            // A finished step's position is finite: no check.
            transform.translation.x = out.state.position.x as f32;
            transform.translation.y = out.state.position.y as f32;
        }
    }
}

/// A run of beads stored side by side: their entities, states and wires,
/// and, when they have them, their diagnostics and transforms.
struct Run<'w> {
    entities: &'w [Entity],
    beads: &'w mut [Bead],
    on_wires: &'w [OnWire],
    diagnostics: Option<&'w mut [BeadDiagnostics]>,
    transforms: Option<&'w mut [Transform]>,
}

/// What one bead's step writes.
struct Slot<'a> {
    bead: &'a mut Bead,
    diagnostics: Option<&'a mut BeadDiagnostics>,
    transform: Option<&'a mut Transform>,
}

impl Run<'_> {
    #[inline(always)]
    fn slot(&mut self, i: usize) -> Slot<'_> {
        Slot {
            bead: &mut self.beads[i],
            diagnostics: self.diagnostics.as_deref_mut().map(|d| &mut d[i]),
            transform: self.transforms.as_deref_mut().map(|t| &mut t[i]),
        }
    }
}

/// The columns of one table of beads, as the step's query hands them out.
type BeadTable<'w> = (
    &'w [Entity],
    ContiguousMut<'w, Bead>,
    &'w [OnWire],
    Option<ContiguousMut<'w, BeadDiagnostics>>,
    Option<ContiguousMut<'w, Transform>>,
);

/// An optional column cut into runs of `n`; `None` for every run if absent
/// (marked changed if present).
fn column_runs<'w, T>(
    column: Option<ContiguousMut<'w, T>>,
    n: usize,
) -> impl Iterator<Item = Option<&'w mut [T]>> {
    column
        .into_iter()
        .flat_map(move |c| ContiguousMut::split(c).0.chunks_mut(n).map(Some))
        .chain(std::iter::repeat_with(|| None))
}

/// Cuts one table's beads into runs: one for a single thread, else about a
/// quarter of each thread's share, so a slow thread does not hold the
/// others up. Marks the beads, diagnostics and transforms changed.
fn split_table<'w>(
    (entities, beads, on_wires, diagnostics, transforms): BeadTable<'w>,
    threads: usize,
) -> Vec<Run<'w>> {
    let runs = if threads > 1 { 4 * threads } else { 1 };
    let n = entities.len().div_ceil(runs).max(1);
    let beads = ContiguousMut::split(beads).0;
    entities
        .chunks(n)
        .zip(beads.chunks_mut(n))
        .zip(on_wires.chunks(n))
        .zip(column_runs(diagnostics, n))
        .zip(column_runs(transforms, n))
        .map(
            |((((entities, beads), on_wires), diagnostics), transforms)| Run {
                entities,
                beads,
                on_wires,
                diagnostics,
                transforms,
            },
        )
        .collect()
}

/// Steps every bead that has not diverged: solve, integrate, check, update
/// diagnostics (see [`WireBeadSystems::Step`](crate::WireBeadSystems::Step)).
/// Walks the beads table by table as slices, split over the compute task
/// pool from [`ParallelStep::threshold`] beads up.
pub fn step_beads(
    params: Res<SimParams>,
    clock: Res<SimClock>,
    parallel: Res<ParallelStep>,
    mut wires: Local<WireTable>,
    changed: Query<(Entity, &Wire, &WirePose), Or<(Changed<Wire>, Changed<WirePose>)>>,
    mut removed_wires: RemovedComponents<Wire>,
    mut removed_poses: RemovedComponents<WirePose>,
    mut beads: Query<
        (
            Entity,
            &mut Bead,
            &OnWire,
            Option<&mut BeadDiagnostics>,
            Option<&mut Transform>,
        ),
        Without<Diverged>,
    >,
    mut found: Local<Found>,
    mut stepped: ResMut<LastStep>,
    ticks: SystemChangeTick,
    mut divergences: Divergences,
) {
    let removed = removed_wires.read().chain(removed_poses.read());
    wires.refresh(removed, changed);
    let batch = step_config(&params, 1.0, 1.0);
    let ctx = StepContext {
        params: &params,
        wires: &wires,
        found: &found,
        time: clock.time,
        batch: solver::batches(&batch).then_some(batch),
    };
    let count = beads.iter().size_hint().1.unwrap_or(usize::MAX);
    let pool = ComputeTaskPool::try_get().filter(|_| count >= parallel.threshold);
    let threads = pool.map_or(1, |pool| pool.thread_num().max(1));
    let Ok(tables) = beads.contiguous_iter_mut() else {
        error!("wirebead: the bead query is not table-dense; no bead was stepped");
        return;
    };
    let split = |table| split_table(table, threads);
    match pool {
        Some(pool) if threads > 1 => {
            pool.scope(|scope| {
                for run in tables.flat_map(split) {
                    let ctx = &ctx;
                    scope.spawn(async move { ctx.step_run(run) });
                }
            });
        }
        _ => {
            for run in tables.flat_map(split) {
                ctx.step_run(run);
            }
        }
    };
    found.report(&mut divergences);
    stepped.0 = ticks.this_run();
}

/// The change tick of the last run of [`step_beads`]: it wrote the
/// `Transform` of every bead it changed then.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct LastStep(Tick);

/// Writes each bead's position into its `Transform` (x and y; z is kept)
/// where the bead changed other than by the last step (a restart, a
/// game's own edit); [`step_beads`] writes the ones it steps. A non-finite
/// position is never written.
pub fn write_transforms(
    parallel: Res<ParallelStep>,
    stepped: Res<LastStep>,
    mut beads: Query<(Ref<Bead>, &mut Transform), Changed<Bead>>,
) {
    for_each_bead!(beads, parallel, |(bead, mut transform): (
        Ref<Bead>,
        Mut<Transform>
    )| {
        // The step wrote the ones it changed last (without reading them
        // again here).
        if bead.last_changed() != stepped.0 {
            place(&mut transform, bead.position);
        }
    });
}

/// Writes a bead's position into its `Transform` (x and y, rounded to
/// `f32`; z is kept), unless it is not finite.
#[inline(always)]
fn place(transform: &mut Transform, position: DVec2) {
    if position.is_finite() {
        transform.translation.x = position.x as f32;
        transform.translation.y = position.y as f32;
    }
}

fn step_config(params: &SimParams, mass: f64, wire_scale: f64) -> StepConfig {
    StepConfig {
        dt: params.timestep,
        mass,
        alpha: params.alpha,
        beta: params.beta,
        integrator: params.integrator,
        stabilization: params.stabilization,
        drift_bound: params.divergence_bound * wire_scale,
    }
}
