//! Keyboard controls: Space restarts (applying pending edits), P pauses and
//! resumes, N advances one step while paused. No rendering needed: the
//! controls read `ButtonInput<KeyCode>`, so headless tests press keys too.

use bevy::input::InputSystems;
use bevy::prelude::*;

use crate::plugin::{Restart, WireBeadSystems};

/// The keys the controls listen to.
#[derive(Resource, Clone, Debug, PartialEq, Eq)]
pub struct ControlKeys {
    /// Start or restart the run, applying pending edits.
    pub restart: KeyCode,
    /// Pause or resume.
    pub pause: KeyCode,
    /// Advance one fixed step while paused.
    pub step: KeyCode,
}

impl Default for ControlKeys {
    fn default() -> Self {
        Self {
            restart: KeyCode::Space,
            pause: KeyCode::KeyP,
            step: KeyCode::KeyN,
        }
    }
}

impl ControlKeys {
    /// A one-line description for an on-screen help line.
    pub fn help(&self) -> String {
        format!(
            "{}: restart and apply edits · {}: pause/resume · {}: one step while paused · drag a bead with the mouse",
            key_name(self.restart),
            key_name(self.pause),
            key_name(self.step)
        )
    }
}

fn key_name(key: KeyCode) -> String {
    let name = format!("{key:?}");
    name.strip_prefix("Key").map(str::to_owned).unwrap_or(name)
}

/// Fixed steps requested while paused, run by [`run_requested_steps`].
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepRequests(pub u32);

/// Adds the keyboard controls. Needs [`WireBeadPlugin`](crate::WireBeadPlugin).
#[derive(Default)]
pub struct KeyboardControlsPlugin;

impl Plugin for KeyboardControlsPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<ButtonInput<KeyCode>>()
            .init_resource::<ControlKeys>()
            .init_resource::<StepRequests>()
            .add_systems(
                PreUpdate,
                keyboard_controls
                    .after(InputSystems)
                    .before(WireBeadSystems::Restart),
            )
            .add_systems(Update, run_requested_steps);
    }
}

/// Reads the keys: sends [`Restart`], toggles the pause, requests a step.
pub fn keyboard_controls(
    keys: Res<ButtonInput<KeyCode>>,
    bindings: Res<ControlKeys>,
    mut restarts: MessageWriter<Restart>,
    mut time: ResMut<Time<Virtual>>,
    mut steps: ResMut<StepRequests>,
) {
    if keys.just_pressed(bindings.restart) {
        restarts.write(Restart);
    }
    if keys.just_pressed(bindings.pause) {
        if time.is_paused() {
            time.unpause();
        } else {
            time.pause();
        }
    }
    if keys.just_pressed(bindings.step) && time.is_paused() {
        steps.0 += 1;
    }
}

/// Runs the requested single steps: the whole `FixedUpdate` schedule once
/// each, so a single step is exactly one normal step.
pub fn run_requested_steps(world: &mut World) {
    let n = std::mem::take(&mut world.resource_mut::<StepRequests>().0);
    for _ in 0..n {
        world.run_schedule(FixedUpdate);
    }
}
