//! Every system of the plugin, public so a game can order its own systems
//! against them. They only move data between the ECS and [`crate::solver`].

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use crate::components::{
    Bead, BeadDiagnostics, Diverged, DivergenceReason, DragTarget, OnWire, PendingWire, Wire,
};
use crate::params::{PendingBead, PendingParams, SimParams};
use crate::plugin::{BeadDiverged, Restart};
use crate::solver::{self, LinearForce, Solved, StepConfig};
use crate::wire::{ImplicitCurve, Placed, Pose};

/// Read access to every wire and its placement.
pub type Wires<'w, 's> = Query<'w, 's, (&'static Wire, &'static Transform)>;

/// The wire a bead is on, placed in the world.
pub fn placed_wire<'a>(wires: &'a Wires, on: &OnWire) -> Result<Placed<'a>, DivergenceReason> {
    let (wire, transform) = wires
        .get(on.0)
        .map_err(|_| DivergenceReason::InvalidWire(format!("entity {} has no Wire", on.0)))?;
    let pose = Pose::from_transform(transform)
        .map_err(|e| DivergenceReason::InvalidWire(e.to_string()))?;
    Ok(Placed {
        curve: wire.shape().curve(),
        pose,
    })
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

/// Clears each bead's force accumulator.
pub fn clear_forces(mut beads: Query<&mut Bead, Without<Diverged>>) {
    for mut bead in &mut beads {
        bead.force = bevy::math::DVec2::ZERO;
        bead.force_stiffness = 0.0;
    }
}

/// Adds gravity `m g`.
pub fn apply_gravity(params: Res<SimParams>, mut beads: Query<&mut Bead, Without<Diverged>>) {
    for mut bead in &mut beads {
        let weight = bead.mass() * params.gravity;
        bead.add_force(weight);
    }
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

/// Solves eq. 1.9 for each bead and stores λ and `λN`.
pub fn solve_constraints(
    params: Res<SimParams>,
    wires: Wires,
    mut beads: Query<(Entity, &mut Bead, &OnWire, &BeadDiagnostics), Without<Diverged>>,
    mut divergences: Divergences,
) {
    let (alpha, beta) = step_config(&params, 1.0, 1.0).gains();
    for (entity, mut bead, on_wire, diagnostics) in &mut beads {
        let result = placed_wire(&wires, on_wire).and_then(|placed| {
            if !bead.state().is_finite() {
                return Err(DivergenceReason::NonFiniteState);
            }
            let force = force_of(&bead);
            solver::solve(&placed, bead.state(), &force, bead.mass(), alpha, beta)
                .map_err(DivergenceReason::Solve)
        });
        match result {
            Ok(solved) => {
                bead.lambda = solved.lambda;
                bead.constraint_force = solved.constraint_force;
            }
            Err(reason) => divergences.report(entity, reason, diagnostics.time),
        }
    }
}

/// Advances each bead one step, checks it, and updates its diagnostics.
pub fn integrate(
    params: Res<SimParams>,
    wires: Wires,
    mut beads: Query<(Entity, &mut Bead, &OnWire, &mut BeadDiagnostics), Without<Diverged>>,
    mut divergences: Divergences,
) {
    for (entity, mut bead, on_wire, mut diagnostics) in &mut beads {
        let Ok(placed) = placed_wire(&wires, on_wire) else {
            continue; // reported by solve_constraints
        };
        let cfg = step_config(&params, bead.mass(), placed.scale());
        let force = force_of(&bead);
        let first = Solved {
            lambda: bead.lambda,
            constraint_force: bead.constraint_force,
            acceleration: (bead.force + bead.constraint_force) / bead.mass(),
        };
        let time = diagnostics.time + params.timestep;
        match solver::integrate(&placed, bead.state(), &force, &first, &cfg) {
            Ok(out) => {
                bead.position = out.state.position;
                bead.velocity = out.state.velocity;
                bead.lambda = out.lambda;
                bead.constraint_force = out.constraint_force;
                let steps = diagnostics.steps + 1;
                *diagnostics = BeadDiagnostics {
                    steps,
                    time,
                    ..diagnose(&placed, &bead, params.gravity)
                };
            }
            Err(e) => divergences.report(entity, DivergenceReason::Solve(e), time),
        }
    }
}

/// Writes each bead's position into its `Transform` (x and y; z is kept).
/// A non-finite position is never written.
pub fn write_transforms(mut beads: Query<(&Bead, &mut Transform), Changed<Bead>>) {
    for (bead, mut transform) in &mut beads {
        if bead.position.is_finite() {
            transform.translation.x = bead.position.x as f32;
            transform.translation.y = bead.position.y as f32;
        }
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

fn force_of(bead: &Bead) -> LinearForce {
    LinearForce {
        force: bead.force,
        stiffness: bead.force_stiffness,
        at: bead.position,
    }
}
