//! [`ClockPlugin`]: the [`SimClock`] and the fixed timestep.

use bevy::prelude::*;

use super::schedule::WireBeadSystems;
use crate::dynamics::SimParams;

/// Simulated time since the last [`Restart`](crate::Restart): steps taken
/// and seconds. Advanced in
/// [`WireBeadSystems::Prepare`](crate::WireBeadSystems::Prepare), after the
/// wires are placed, so during a step it already reads the time the step
/// reaches.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Resource)]
pub struct SimClock {
    /// Steps since the last restart.
    pub steps: u64,
    /// Seconds since the last restart.
    pub time: f64,
}

/// Keeps the [`SimClock`] and sets `Time<Fixed>` to the applied timestep
/// at startup.
#[derive(Default)]
pub struct ClockPlugin;

impl Plugin for ClockPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SimClock>()
            .register_type::<SimClock>()
            .add_systems(Startup, apply_timestep)
            .add_systems(FixedUpdate, advance_clock.in_set(WireBeadSystems::Prepare));
    }
}

/// Sets `Time<Fixed>` to the applied timestep.
fn apply_timestep(params: Res<SimParams>, mut time: ResMut<Time<Fixed>>) {
    time.set_timestep_seconds(params.timestep);
}

/// Advances the clock by one step.
pub(crate) fn advance_clock(params: Res<SimParams>, mut clock: ResMut<SimClock>) {
    clock.steps += 1;
    clock.time += params.timestep;
}
