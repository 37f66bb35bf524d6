//! Every system of the plugin, public so a game can order its own systems
//! against them. They only move data between the ECS and [`crate::solver`].

use std::sync::{Mutex, PoisonError};

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use crate::components::{
    Bead, BeadDiagnostics, Diverged, DivergenceReason, DragTarget, OnWire, PendingWire, Wire,
    WirePose,
};
use crate::params::{PendingBead, PendingParams, SimParams};
use crate::plugin::{BeadDiverged, ParallelStep, Restart};
use crate::solver::{self, LinearForce, SolveError, Solved, StepConfig};
use crate::wire::{ImplicitCurve, Placed, Pose, WireShape};

/// Read access to every wire and its placement for this step.
pub type Wires<'w, 's> = Query<'w, 's, (&'static Wire, &'static WirePose)>;

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
    mut wires: Query<(Entity, &mut Wire, &Transform, Option<&PendingWire>)>,
    mut beads: Query<(
        Entity,
        &mut Bead,
        &mut BeadDiagnostics,
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
    for (entity, mut bead, mut diagnostics, on_wire, edit) in &mut beads {
        let bead_params = edit.map_or(*bead.params(), |p| *p.get());
        bead.reset(bead_params);
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
        commands.entity(entity).remove::<(Diverged, PendingBead)>();
    }
}

/// Prepares the step: places every wire (reads each changed wire
/// `Transform` once, so the beads do not) and starts each bead's force
/// accumulator at its weight `m g` (gravity), with no stiffness. One system,
/// so a multi-threaded executor wakes a thread once for both.
pub fn prepare_step(
    params: Res<SimParams>,
    parallel: Res<ParallelStep>,
    mut wires: Query<(&Transform, &mut WirePose), Changed<Transform>>,
    mut beads: Query<&mut Bead, Without<Diverged>>,
) {
    for (transform, mut pose) in &mut wires {
        *pose = WirePose::from_transform(transform);
    }
    let gravity = params.gravity;
    for_each_bead!(beads, parallel, |mut bead: Mut<Bead>| {
        bead.force = bead.mass() * gravity;
        bead.force_stiffness = 0.0;
    });
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

/// The wire a bead is on and its pose for this step.
pub fn wire_of<'a>(wires: &'a Wires, on: &OnWire) -> Result<(&'a Wire, Pose), DivergenceReason> {
    let (wire, pose) = wires
        .get(on.0)
        .map_err(|_| DivergenceReason::InvalidWire(format!("entity {} has no Wire", on.0)))?;
    let pose = pose
        .get()
        .map_err(|e| DivergenceReason::InvalidWire(e.to_string()))?;
    Ok((wire, pose))
}

/// Eq. 1.9 for one bead: stores λ and `λN`.
fn solve_bead<C: ImplicitCurve + ?Sized>(
    placed: &Placed<C>,
    bead: &mut Bead,
    alpha: f64,
    beta: f64,
) -> Result<(), DivergenceReason> {
    if !bead.state().is_finite() {
        return Err(DivergenceReason::NonFiniteState);
    }
    let force = force_of(bead);
    let solved = solver::solve(placed, bead.state(), &force, bead.mass(), alpha, beta)
        .map_err(DivergenceReason::Solve)?;
    bead.lambda = solved.lambda;
    bead.constraint_force = solved.constraint_force;
    Ok(())
}

/// One step of one bead and its new diagnostics.
fn integrate_bead<C: ImplicitCurve + ?Sized>(
    placed: &Placed<C>,
    bead: &mut Bead,
    diagnostics: &mut BeadDiagnostics,
    params: &SimParams,
) -> Result<(), SolveError> {
    let cfg = step_config(params, bead.mass(), placed.scale());
    let force = force_of(bead);
    let first = Solved {
        lambda: bead.lambda,
        constraint_force: bead.constraint_force,
        acceleration: (bead.force + bead.constraint_force) / bead.mass(),
    };
    let out = solver::integrate(placed, bead.state(), &force, &first, &cfg)?;
    bead.position = out.state.position;
    bead.velocity = out.state.velocity;
    bead.lambda = out.lambda;
    bead.constraint_force = out.constraint_force;
    let (kinetic, potential) = solver::energy(bead.mass(), params.gravity, out.state);
    *diagnostics = BeadDiagnostics {
        c: out.c,
        c_dot: out.c_dot,
        lambda: out.lambda,
        kinetic,
        potential,
        steps: diagnostics.steps + 1,
        time: diagnostics.time + params.timestep,
    };
    Ok(())
}

/// Solves eq. 1.9 for each bead and stores λ and `λN`.
pub fn solve_constraints(
    params: Res<SimParams>,
    parallel: Res<ParallelStep>,
    wires: Wires,
    mut beads: Query<(Entity, &mut Bead, &OnWire, &BeadDiagnostics), Without<Diverged>>,
    mut found: Local<Found>,
    mut divergences: Divergences,
) {
    let (alpha, beta) = step_config(&params, 1.0, 1.0).gains();
    let (wires, found_ref) = (&wires, &*found);
    for_each_bead!(beads, parallel, |(
        entity,
        mut bead,
        on_wire,
        diagnostics,
    ): (
        Entity,
        Mut<Bead>,
        &OnWire,
        &BeadDiagnostics
    )| {
        let result = wire_of(wires, on_wire).and_then(|(wire, pose)| {
            with_curve!(wire.shape(), curve => {
                solve_bead(&Placed { curve, pose }, &mut bead, alpha, beta)
            })
        });
        if let Err(reason) = result {
            found_ref.push(entity, reason, diagnostics.time);
        }
    });
    found.report(&mut divergences);
}

/// Advances each bead one step, checks it, and updates its diagnostics.
pub fn integrate(
    params: Res<SimParams>,
    parallel: Res<ParallelStep>,
    wires: Wires,
    mut beads: Query<(Entity, &mut Bead, &OnWire, &mut BeadDiagnostics), Without<Diverged>>,
    mut found: Local<Found>,
    mut divergences: Divergences,
) {
    let (params, wires, found_ref) = (&*params, &wires, &*found);
    for_each_bead!(beads, parallel, |(
        entity,
        mut bead,
        on_wire,
        mut diagnostics,
    ): (
        Entity,
        Mut<Bead>,
        &OnWire,
        Mut<BeadDiagnostics>
    )| {
        let Ok((wire, pose)) = wire_of(wires, on_wire) else {
            return; // reported by solve_constraints
        };
        let result = with_curve!(wire.shape(), curve => {
            integrate_bead(&Placed { curve, pose }, &mut bead, &mut diagnostics, params)
        });
        if let Err(e) = result {
            let time = diagnostics.time + params.timestep;
            found_ref.push(entity, DivergenceReason::Solve(e), time);
        }
    });
    found.report(&mut divergences);
}

/// Writes each bead's position into its `Transform` (x and y; z is kept).
/// A non-finite position is never written.
pub fn write_transforms(
    parallel: Res<ParallelStep>,
    mut beads: Query<(&Bead, &mut Transform), Changed<Bead>>,
) {
    for_each_bead!(beads, parallel, |(bead, mut transform): (
        &Bead,
        Mut<Transform>
    )| {
        if bead.position.is_finite() {
            transform.translation.x = bead.position.x as f32;
            transform.translation.y = bead.position.y as f32;
        }
    });
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

fn force_of(bead: &Bead) -> LinearForce {
    LinearForce {
        force: bead.force,
        stiffness: bead.force_stiffness,
        at: bead.position,
    }
}
