//! [`Restart`] and the [`SimClock`] it resets: applying the pending edits,
//! as the assignment's space bar did.

use bevy::prelude::*;

use super::islands::Islands;

use crate::dynamics::{
    Bead, BeadDiagnostics, Diverged, OnWire, PendingBead, PendingParams, PendingWire, SimParams,
    Wire, pose_of,
};
use crate::geometry::{ImplicitCurve, Placed};
use crate::solver::constraint_state;

/// Restarts the run: applies [`PendingParams`] and every [`PendingBead`],
/// returns each bead to its initial state, clears divergence, and sets
/// `Time<Fixed>` to the timestep. Handled in
/// [`WireBeadSystems::Restart`](crate::WireBeadSystems::Restart), in
/// [`PreUpdate`], so the frame that sends it already steps with the new
/// parameters.
#[derive(Message, Clone, Copy, Debug, Default)]
pub struct Restart;

/// Simulated time since the last [`Restart`]: steps taken and seconds.
/// Advanced in [`WireBeadSystems::Prepare`](crate::WireBeadSystems::Prepare),
/// so during a step it already reads the time the step reaches.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Resource)]
pub struct SimClock {
    /// Steps since the last restart.
    pub steps: u64,
    /// Seconds since the last restart.
    pub time: f64,
}

/// The diagnostics of a bead's current state on `curve`, before any step.
fn diagnose(curve: &dyn ImplicitCurve, bead: &Bead, gravity: bevy::math::DVec2) -> BeadDiagnostics {
    let (c, c_dot) = constraint_state(curve, bead.state());
    let (kinetic, potential) = bead.state().energy(bead.mass(), gravity);
    BeadDiagnostics {
        c,
        c_dot,
        kinetic,
        potential,
        ..default()
    }
}

/// Sets `Time<Fixed>` to the applied timestep at startup.
pub(crate) fn apply_timestep(params: Res<SimParams>, mut time: ResMut<Time<Fixed>>) {
    time.set_timestep_seconds(params.timestep);
}

/// Handles [`Restart`]: applies the pending wire shapes and parameters and
/// returns every bead to its initial state.
pub(crate) fn apply_restart(
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
    mut islands: ResMut<Islands>,
    mut commands: Commands,
) {
    if restarts.read().count() == 0 {
        return;
    }
    // Masses and wire shapes may change: the islands are built afresh.
    islands.mark_dirty();
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
        *diagnostics = match wire.map(|(_, w, t, _)| (w, pose_of(t))) {
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
