//! Keyboard controls: Space restarts (applying pending edits), P pauses and
//! resumes, N advances one step while paused, B steps back one recorded
//! step (with a [`TimelinePlugin`](crate::plugin::TimelinePlugin)), `[` and `]` slow the run
//! down to 1/20 of real time and back up to it ([`SPEEDS`]), R reverses
//! every bead's velocity (run backwards: RATTLE retraces its path). No rendering
//! needed: the controls read `ButtonInput<KeyCode>`, so headless tests
//! press keys too.

use bevy::input::InputSystems;
use bevy::math::DVec3;
use bevy::prelude::*;

use crate::BeadVelocity;
use crate::plugin::{Restart, TimelineSeek, WireBeadSystems};

/// The keys the controls listen to.
#[derive(Resource, Clone, Debug, PartialEq, Eq)]
pub struct ControlKeys {
    /// Start or restart the run, applying pending edits.
    pub restart: KeyCode,
    /// Pause or resume.
    pub pause: KeyCode,
    /// Advance one fixed step while paused.
    pub step: KeyCode,
    /// Go back one recorded step (see [`Timeline`](crate::plugin::Timeline)),
    /// pausing the run.
    pub back: KeyCode,
    /// Run slower (the next of [`SPEEDS`] down).
    pub slower: KeyCode,
    /// Run faster (the next of [`SPEEDS`] up, to real time).
    pub faster: KeyCode,
    /// Reverse every bead's velocity: the run goes backwards.
    pub reverse: KeyCode,
    /// Export the recorded run as CSV (see
    /// [`ExportPlugin`](crate::preset::ExportPlugin)).
    pub export_csv: KeyCode,
    /// Save the scene, its edits included, as a scene file.
    pub save_scene: KeyCode,
    /// Save the panel's plots, as shown, as a PNG.
    pub save_plots: KeyCode,
    /// Add a ghost copy of the scene with another method (see
    /// [`GhostPlugin`](crate::ghost::GhostPlugin)).
    pub ghost: KeyCode,
    /// Turn presentation mode on or off ([`Presentation`]).
    pub present: KeyCode,
}

/// Presentation mode, for a classroom's projector: the window's text
/// larger and the plots in a column of their own beside the scene.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Presentation(pub bool);

/// The speeds the run may go at, as fractions of real time: slow motion
/// from 1/20 up to real time.
pub const SPEEDS: [f64; 5] = [0.05, 0.1, 0.2, 0.5, 1.0];

/// The speed of [`SPEEDS`] next to `speed`: the next slower, or the next
/// faster, staying within them (a speed between two goes to the nearer
/// one in that direction).
pub fn next_speed(speed: f64, faster: bool) -> f64 {
    if faster {
        SPEEDS
            .iter()
            .copied()
            .find(|&s| s > speed * (1.0 + 1e-9))
            .unwrap_or(SPEEDS[SPEEDS.len() - 1])
    } else {
        SPEEDS
            .iter()
            .rev()
            .copied()
            .find(|&s| s < speed * (1.0 - 1e-9))
            .unwrap_or(SPEEDS[0])
    }
}

/// A speed as the panel and the help line show it: `1×`, `1/2×`, `1/20×`.
pub fn speed_label(speed: f64) -> String {
    if speed >= 1.0 - 1e-9 {
        "1×".to_owned()
    } else {
        format!("1/{}×", (1.0 / speed).round())
    }
}

impl Default for ControlKeys {
    fn default() -> Self {
        Self {
            restart: KeyCode::Space,
            pause: KeyCode::KeyP,
            step: KeyCode::KeyN,
            back: KeyCode::KeyB,
            slower: KeyCode::BracketLeft,
            faster: KeyCode::BracketRight,
            reverse: KeyCode::KeyR,
            export_csv: KeyCode::KeyE,
            save_scene: KeyCode::KeyS,
            save_plots: KeyCode::KeyI,
            ghost: KeyCode::KeyG,
            present: KeyCode::F5,
        }
    }
}

impl ControlKeys {
    /// A one-line description for an on-screen help line.
    pub fn help(&self) -> String {
        format!(
            "{}: restart and apply edits · {}: pause/resume · {} and {}: one step back, forward · {} and {}: slower, faster · {}: run backwards · {}, {}, {}: export CSV, scene, plots · {}: add a ghost · {}: presentation · Tab, Esc: into the panel, out · drag a bead or pull it with the arrows",
            key_name(self.restart),
            key_name(self.pause),
            key_name(self.back),
            key_name(self.step),
            key_name(self.slower),
            key_name(self.faster),
            key_name(self.reverse),
            key_name(self.export_csv),
            key_name(self.save_scene),
            key_name(self.save_plots),
            key_name(self.ghost),
            key_name(self.present)
        )
    }
}

/// A key as the help line names it: `P`, `Space`, `[`.
pub(crate) fn key_name(key: KeyCode) -> String {
    match key {
        KeyCode::BracketLeft => "[".to_owned(),
        KeyCode::BracketRight => "]".to_owned(),
        _ => {
            let name = format!("{key:?}");
            name.strip_prefix("Key").map(str::to_owned).unwrap_or(name)
        }
    }
}

/// Fixed steps requested while paused, run by [`run_requested_steps`].
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepRequests(pub u32);

/// Exports requested since the last frame: the recorded run as CSV, the
/// scene with its edits as a scene file. Made by the
/// [`ExportPlugin`](crate::preset::ExportPlugin).
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExportRequests {
    /// Requests for the run as CSV.
    pub csv: u32,
    /// Requests for the scene file.
    pub scene: u32,
    /// Requests for the plots as a PNG (made by the window's panel).
    pub plots: u32,
}

/// Ghosts requested by key since the last frame, added by the
/// [`GhostPlugin`](crate::ghost::GhostPlugin) as the panel drafted them.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GhostRequests(pub u32);

/// Reversals of the run requested since the last frame, made by
/// [`reverse_requested`] before the next step.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReverseRequests(pub u32);

/// Adds the keyboard controls. Needs [`WireBeadPlugin`](crate::WireBeadPlugin).
#[derive(Default)]
pub struct KeyboardControlsPlugin;

impl Plugin for KeyboardControlsPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<ButtonInput<KeyCode>>()
            .init_resource::<ControlKeys>()
            .init_resource::<StepRequests>()
            .init_resource::<ReverseRequests>()
            .init_resource::<ExportRequests>()
            .init_resource::<GhostRequests>()
            .init_resource::<Presentation>()
            .add_message::<TimelineSeek>()
            .add_systems(
                PreUpdate,
                (keyboard_controls, reverse_requested)
                    .chain()
                    .after(InputSystems)
                    .before(WireBeadSystems::Restart),
            )
            .add_systems(Update, run_requested_steps);
    }
}

/// Reads the keys: sends [`Restart`], toggles the pause, requests a step,
/// slows the run down or speeds it up, requests a reversal.
pub fn keyboard_controls(
    keys: Res<ButtonInput<KeyCode>>,
    bindings: Res<ControlKeys>,
    mut restarts: MessageWriter<Restart>,
    mut time: ResMut<Time<Virtual>>,
    mut steps: ResMut<StepRequests>,
    mut reversals: ResMut<ReverseRequests>,
    mut seeks: MessageWriter<TimelineSeek>,
    mut exports: ResMut<ExportRequests>,
    mut ghosts: ResMut<GhostRequests>,
    mut presentation: ResMut<Presentation>,
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
    if keys.just_pressed(bindings.back) {
        seeks.write(TimelineSeek::Back);
    }
    if keys.just_pressed(bindings.export_csv) {
        exports.csv += 1;
    }
    if keys.just_pressed(bindings.save_scene) {
        exports.scene += 1;
    }
    if keys.just_pressed(bindings.save_plots) {
        exports.plots += 1;
    }
    if keys.just_pressed(bindings.present) {
        presentation.0 = !presentation.0;
    }
    if keys.just_pressed(bindings.ghost) {
        ghosts.0 += 1;
    }
    if keys.just_pressed(bindings.reverse) {
        reversals.0 += 1;
    }
    for (key, faster) in [(bindings.slower, false), (bindings.faster, true)] {
        if keys.just_pressed(key) {
            let speed = next_speed(time.relative_speed_f64(), faster);
            time.set_relative_speed_f64(speed);
        }
    }
}

/// Makes the requested reversals: each turns every bead's velocity round
/// (in the plane and in space), so the run goes on backwards. A method
/// that is time-reversible (RATTLE) then retraces its path to rounding;
/// one that is not (Euler, Baumgarte) does not, which is the lesson.
pub fn reverse_requested(
    mut requests: ResMut<ReverseRequests>,
    mut beads: Query<&mut BeadVelocity>,
    mut space_beads: Query<&mut BeadVelocity<DVec3>>,
) {
    let n = std::mem::take(&mut requests.0);
    if n.is_multiple_of(2) {
        return;
    }
    for mut v in &mut beads {
        v.0 = -v.0;
    }
    for mut v in &mut space_beads {
        v.0 = -v.0;
    }
}

/// Runs the requested single steps, each as Bevy's fixed loop runs a
/// step: `Time<Fixed>` advanced by one timestep and the whole `FixedMain`
/// schedule (`FixedFirst` to `FixedLast`, avian's step included) run with
/// `Time` the fixed clock, so a single step is exactly one normal step.
pub fn run_requested_steps(world: &mut World) {
    let n = std::mem::take(&mut world.resource_mut::<StepRequests>().0);
    if n == 0 {
        return;
    }
    for _ in 0..n {
        let mut fixed = world.resource_mut::<Time<Fixed>>();
        let timestep = fixed.timestep();
        fixed.advance_by(timestep);
        let now = fixed.as_generic();
        *world.resource_mut::<Time>() = now;
        world.run_schedule(bevy::app::FixedMain);
    }
    let now = world.resource::<Time<Virtual>>().as_generic();
    *world.resource_mut::<Time>() = now;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speeds_step_down_to_a_twentieth_and_up_to_real_time() {
        let mut speed = 1.0;
        let mut down = Vec::new();
        for _ in 0..6 {
            speed = next_speed(speed, false);
            down.push(speed);
        }
        assert_eq!(down, [0.5, 0.2, 0.1, 0.05, 0.05, 0.05]);
        assert_eq!(next_speed(0.05, true), 0.1);
        assert_eq!(next_speed(1.0, true), 1.0);
        assert_eq!(next_speed(0.3, true), 0.5);
        assert_eq!(next_speed(0.3, false), 0.2);
        assert_eq!(speed_label(1.0), "1×");
        assert_eq!(speed_label(0.05), "1/20×");
        assert_eq!(speed_label(0.5), "1/2×");
    }
}
