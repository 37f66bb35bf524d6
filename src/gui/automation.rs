//! Automation for scripts and CI: run a number of frames, freeze the scene,
//! save a screenshot with a report of where everything is on screen, write a
//! "ready" report once the scene runs (so a script can find a bead to drag),
//! and exit with status 0, or non-zero if anything failed.

use std::path::PathBuf;

use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use serde::{Deserialize, Serialize};

use crate::components::{Bead, Diverged, DragTarget, Wire};
use crate::gui::render::{FramedView, SceneCamera, wire_points};
use crate::preset::ActivePreset;
use crate::wire::Pose;

/// Where one bead is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BeadReport {
    /// Simulated position.
    pub world: [f64; 2],
    /// Window position in physical pixels, from the top left.
    pub pixel: [f32; 2],
    /// The drawn radius in physical pixels.
    pub radius_px: f32,
    /// Why it diverged, if it did.
    pub diverged: Option<String>,
}

/// Where one wire is drawn.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WireReport {
    /// Its shape's name.
    pub shape: String,
    /// Points on the simulated wire, in physical pixels (only those inside
    /// the window).
    pub pixels: Vec<[f32; 2]>,
}

/// What a mouse drag did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DragReport {
    /// The bead's position when the drag began.
    pub bead_start: [f64; 2],
    /// The last drag target (where the cursor was released).
    pub target: [f64; 2],
    /// The distance from the bead's start to that target.
    pub start_distance: f64,
    /// The bead's closest approach to that target while dragged.
    pub closest_distance: f64,
}

/// A report of one frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FrameReport {
    /// The frame number.
    pub frame: u32,
    /// The window size in physical pixels.
    pub window: [u32; 2],
    /// The beads.
    pub beads: Vec<BeadReport>,
    /// The wires.
    pub wires: Vec<WireReport>,
    /// The drag seen so far, if any.
    pub drag: Option<DragReport>,
    /// The preset running.
    pub preset: Option<String>,
    /// The last scene-file error.
    pub preset_error: Option<String>,
    /// Mean wall-clock frame time in milliseconds after the first 30 frames.
    pub mean_frame_ms: f64,
}

/// Run `frames` frames, optionally screenshot, report and exit.
#[derive(Clone, Debug, Default)]
pub struct AutomationPlugin {
    /// Exit after this many frames.
    pub frames: Option<u32>,
    /// Save a screenshot (PNG) here 10 frames before the end, and its
    /// [`FrameReport`] beside it (same path, `.ron`).
    pub screenshot: Option<PathBuf>,
    /// Write a [`FrameReport`] here once the scene has run 30 frames.
    pub ready: Option<PathBuf>,
    /// Write the final [`FrameReport`] here on exit.
    pub report: Option<PathBuf>,
}

#[derive(Resource, Clone, Debug, Default)]
struct AutomationState {
    config: AutomationPlugin,
    frame: u32,
    timed_frames: u32,
    timed_seconds: f64,
    ready_written: bool,
    /// The bead's positions while dragged, and the last drag target.
    drag_path: Vec<DVec2>,
    drag_target: Option<DVec2>,
    failures: Vec<String>,
}

impl Plugin for AutomationPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(AutomationState {
            config: self.clone(),
            ..default()
        })
        .add_systems(Last, automation);
    }
}

fn write_report(path: &PathBuf, report: &FrameReport) -> Result<(), String> {
    let text = ron::ser::to_string_pretty(report, ron::ser::PrettyConfig::default())
        .map_err(|e| e.to_string())?;
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

fn automation(
    mut state: ResMut<AutomationState>,
    real: Res<Time<Real>>,
    mut virtual_time: ResMut<Time<Virtual>>,
    windows: Query<&Window>,
    cameras: Query<(&Camera, &GlobalTransform), With<SceneCamera>>,
    beads: Query<(&Bead, Option<&DragTarget>, Option<&Diverged>, &Transform)>,
    wires: Query<(&Wire, &Transform)>,
    view: Res<FramedView>,
    active: Res<ActivePreset>,
    mut exit: MessageWriter<AppExit>,
    mut commands: Commands,
) {
    state.frame += 1;
    let frame = state.frame;
    if frame > 30 {
        state.timed_frames += 1;
        state.timed_seconds += real.delta_secs_f64();
    }
    // Follow a drag.
    for (bead, target, _, _) in &beads {
        if let Some(target) = target {
            state.drag_path.push(bead.position);
            state.drag_target = Some(target.get());
        }
    }
    // Measured against where the cursor ended up.
    let drag = state
        .drag_target
        .zip(state.drag_path.first())
        .map(|(target, start)| DragReport {
            bead_start: start.to_array(),
            target: target.to_array(),
            start_distance: (*start - target).length(),
            closest_distance: state
                .drag_path
                .iter()
                .map(|p| (*p - target).length())
                .fold(f64::INFINITY, f64::min),
        });
    let mean_frame_ms = 1e3 * state.timed_seconds / f64::from(state.timed_frames.max(1));
    let report = || -> FrameReport {
        let window = windows.iter().next();
        let scale = window.map_or(1.0, |w| w.scale_factor());
        let size = window.map_or([0, 0], |w| [w.physical_width(), w.physical_height()]);
        let camera = cameras.iter().next();
        let to_pixel = |p: DVec2| -> Option<[f32; 2]> {
            let (camera, transform) = camera?;
            let px = camera
                .world_to_viewport(transform, p.as_vec2().extend(0.0))
                .ok()?
                * scale;
            Some(px.to_array())
        };
        let in_window = |p: &[f32; 2]| {
            p[0] >= 0.0 && p[1] >= 0.0 && p[0] < size[0] as f32 && p[1] < size[1] as f32
        };
        FrameReport {
            frame,
            window: size,
            beads: beads
                .iter()
                .filter_map(|(bead, _, diverged, transform)| {
                    Some(BeadReport {
                        world: bead.position.to_array(),
                        pixel: to_pixel(bead.position)?,
                        radius_px: transform.scale.x / view.size.y.max(1e-9) * size[1] as f32,
                        diverged: diverged.map(|d| d.reason.to_string()),
                    })
                })
                .collect(),
            wires: wires
                .iter()
                .map(|(wire, transform)| WireReport {
                    shape: wire.shape().name().to_owned(),
                    pixels: wire_points(
                        wire.shape(),
                        &Pose::from_transform(transform).unwrap_or_default(),
                        None,
                    )
                    .into_iter()
                    .filter_map(to_pixel)
                    .filter(in_window)
                    .collect(),
                })
                .collect(),
            drag: drag.clone(),
            preset: active.running.clone(),
            preset_error: active.error.clone(),
            mean_frame_ms,
        }
    };

    if let Some(path) = state.config.ready.clone()
        && !state.ready_written
        && frame >= 30
        && active.running.is_some()
    {
        state.ready_written = true;
        if let Err(e) = write_report(&path, &report()) {
            state.failures.push(e);
        }
    }

    let Some(frames) = state.config.frames else {
        return;
    };
    if let Some(path) = state.config.screenshot.clone() {
        // Freeze the scene so the screenshot and its report agree.
        if frame + 20 == frames {
            virtual_time.pause();
        }
        if frame + 10 == frames {
            let _ = std::fs::remove_file(&path);
            commands
                .spawn(Screenshot::primary_window())
                .observe(save_to_disk(path.clone()));
            if let Err(e) = write_report(&path.with_extension("ron"), &report()) {
                state.failures.push(e);
            }
        }
    }
    if frame < frames {
        return;
    }
    if let Some(path) = &state.config.screenshot
        && !path.exists()
    {
        if frame < frames + 120 {
            return; // the capture may lag a few frames behind
        }
        let failure = format!("the screenshot {} was not saved", path.display());
        state.failures.push(failure);
    }
    if let Some(error) = &active.error {
        let failure = format!("scene file error: {error}");
        state.failures.push(failure);
    }
    if active.running.is_none() && !active.path.is_empty() {
        let failure = format!("the scene preset {} never ran", active.path);
        state.failures.push(failure);
    }
    let last = report();
    if last.beads.is_empty() {
        state
            .failures
            .push("there was no bead in the scene".to_owned());
    }
    if let Some(path) = state.config.report.clone()
        && let Err(e) = write_report(&path, &last)
    {
        state.failures.push(e);
    }
    info!("wirebead: {frame} frames, mean frame time {mean_frame_ms:.2} ms");
    if state.failures.is_empty() {
        exit.write(AppExit::Success);
    } else {
        for failure in &state.failures {
            error!("wirebead: {failure}");
        }
        exit.write(AppExit::error());
    }
    state.config.frames = None;
}
