//! Automation for scripts and CI: run a number of frames, freeze the scene,
//! save a screenshot with a report of where everything is on screen, write a
//! "ready" report once the scene runs (so a script can find a bead to drag),
//! and exit with status 0, or non-zero if anything failed.

use std::path::PathBuf;

use bevy::ecs::system::SystemParam;
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};

mod report;

use report::write_report;
pub use report::{
    BeadReport, BodyReport, DragReport, FrameReport, GhostBeadReport, PlotReport, SpaceBeadReport,
    TimelineReport, WireReport,
};

use crate::debug_render::{Riding, carried_transform, hatch_point, wire_points};
use crate::geometry::Placed;
use crate::ghost::Ghosts;
use crate::gui::bodies::BodyVisual;
use crate::gui::ghost::ghost_beads;
use crate::gui::panel::{FocusTrail, PhasePlotFrame, PlotsShown};
use crate::gui::render::{FramedView, SceneCamera, hatch_length};
use crate::gui::space::{SpaceCamera, WireDrawing};
use crate::plugin::Timeline;
use crate::preset::ActivePreset;
use crate::{
    BeadParams, BeadPosition, BeadVelocity, Diverged, GrabPoint, Pin, Rod, SimClock, SpringAnchor,
    Wire, WireContact, pose_of,
};

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
    /// End the run as soon as a file appears here: 20 frames later, with
    /// the screenshot and reports as at the end of `frames`, which stays
    /// the longest the run takes. A script that drives the window ends it
    /// when its keys and drags are done rather than after frames enough
    /// for the slowest machine.
    pub finish_when: Option<PathBuf>,
}

#[derive(Resource, Clone, Debug, Default)]
struct AutomationState {
    config: AutomationPlugin,
    frame: u32,
    timed_frames: u32,
    timed_seconds: f64,
    ready_written: bool,
    /// The bead's positions while dragged, and the last drag target (in
    /// the plane at `z = 0`).
    drag_path: Vec<DVec3>,
    drag_target: Option<DVec3>,
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

/// What a [`FrameReport`] is made from.
#[derive(SystemParam)]
struct ReportView<'w, 's> {
    windows: Query<'w, 's, &'static Window>,
    cameras: Query<'w, 's, (&'static Camera, &'static GlobalTransform), With<SceneCamera>>,
    beads: Query<
        'w,
        's,
        (
            &'static BeadPosition,
            Option<&'static SpringAnchor>,
            Option<&'static Diverged>,
            &'static Transform,
            Option<&'static WireContact>,
            &'static BeadParams,
        ),
    >,
    wires: Query<'w, 's, (&'static Wire, &'static Transform)>,
    space_cameras: Query<'w, 's, (&'static Camera, &'static GlobalTransform), With<SpaceCamera>>,
    space_beads: Query<
        'w,
        's,
        (
            &'static BeadPosition<DVec3>,
            Option<&'static Diverged>,
            &'static Transform,
            Option<&'static SpringAnchor<DVec3>>,
        ),
    >,
    space_wires: Query<'w, 's, (&'static WireDrawing, &'static Transform, Riding)>,
    bodies: Query<'w, 's, (Option<&'static Name>, &'static GlobalTransform), With<BodyVisual>>,
    dragged_bodies: Query<
        'w,
        's,
        (
            &'static GlobalTransform,
            AnyOf<(&'static GrabPoint, &'static GrabPoint<DVec3>)>,
            AnyOf<(&'static SpringAnchor, &'static SpringAnchor<DVec3>)>,
        ),
        With<BodyVisual>,
    >,
    rods: Query<'w, 's, &'static Rod>,
    pins: Query<'w, 's, &'static Pin>,
    transforms: Query<'w, 's, &'static Transform>,
    view: Res<'w, FramedView>,
    active: Res<'w, ActivePreset>,
    timeline: Option<Res<'w, Timeline>>,
    ghosts: Option<Res<'w, Ghosts>>,
    phase: Option<Res<'w, PhasePlotFrame>>,
    plots_shown: Option<Res<'w, PlotsShown>>,
    focus: Option<Res<'w, FocusTrail>>,
    clock: Res<'w, SimClock>,
    states: Query<'w, 's, (Entity, &'static BeadPosition, &'static BeadVelocity)>,
    space_states: Query<
        'w,
        's,
        (
            Entity,
            &'static BeadPosition<DVec3>,
            &'static BeadVelocity<DVec3>,
        ),
    >,
}

impl ReportView<'_, '_> {
    /// Where every bead and wire is on screen now.
    fn report(&self, frame: u32, drag: Option<DragReport>, mean_frame_ms: f64) -> FrameReport {
        let window = self.windows.iter().next();
        let scale = window.map_or(1.0, |w| w.scale_factor());
        let size = window.map_or([0, 0], |w| [w.physical_width(), w.physical_height()]);
        let camera = self.cameras.iter().next();
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
            beads: self
                .beads
                .iter()
                .filter_map(|(bead, _, diverged, transform, contact, params)| {
                    Some(BeadReport {
                        world: bead.to_array(),
                        pixel: to_pixel(bead.0)?,
                        radius_px: transform.scale.x / self.view.size.y.max(1e-9) * size[1] as f32,
                        diverged: diverged.map(|d| d.reason.to_string()),
                        in_flight: contact.is_some_and(|c| !c.is_on()),
                        mass: params.mass,
                    })
                })
                .collect(),
            wires: self
                .wires
                .iter()
                .map(|(wire, transform)| {
                    let pose = pose_of(transform).unwrap_or_default();
                    let points = wire_points(wire.shape(), &pose, None);
                    let side = wire.surface().side.sign();
                    let placed = Placed {
                        curve: wire.shape().curve(),
                        pose,
                    };
                    let length = hatch_length(&self.view);
                    // The middle of a stroke, on either side.
                    let probes = |side: f64| -> Vec<[f32; 2]> {
                        if side == 0.0 {
                            return Vec::new();
                        }
                        points
                            .iter()
                            .map(|&p| 0.5 * (p + hatch_point(&placed, p, side, length)))
                            .filter_map(to_pixel)
                            .filter(in_window)
                            .collect()
                    };
                    WireReport {
                        shape: wire.shape().name().to_owned(),
                        pixels: points
                            .iter()
                            .copied()
                            .filter_map(to_pixel)
                            .filter(in_window)
                            .collect(),
                        closed_side: probes(side),
                        open_side: probes(-side),
                    }
                })
                .collect(),
            rods: self
                .rods
                .iter()
                .filter_map(|rod| {
                    let end = |i: usize| {
                        let (bead, ..) = self.beads.get(rod.beads()[i]).ok()?;
                        to_pixel(bead.0)
                    };
                    Some([end(0)?, end(1)?])
                })
                .collect(),
            pins: self
                .pins
                .iter()
                .filter_map(|pin| to_pixel(pin.locate(&self.transforms)?))
                .collect(),
            space_beads: self.space_beads(scale),
            bodies: self.bodies(scale, &to_pixel),
            space_curves: self.space_curves(scale, in_window),
            drag,
            preset: self.active.running.clone(),
            preset_error: self.active.error.clone(),
            mean_frame_ms,
            timeline: self.timeline_report(),
            ghost_beads: self.ghost_beads(scale, &to_pixel),
            phase_plot: self.phase.as_ref().and_then(|p| p.0).map(|p| PlotReport {
                rect_px: p.rect,
                visible_px: p.visible,
                bounds: p.bounds,
            }),
            plots_shown: self.plots_shown.as_ref().and_then(|p| p.0),
            focus_trail: self.focus.as_ref().map(|f| f.0.clone()).unwrap_or_default(),
        }
    }

    /// Where each ghost bead is drawn.
    fn ghost_beads(
        &self,
        scale: f32,
        to_pixel: &dyn Fn(DVec2) -> Option<[f32; 2]>,
    ) -> Vec<GhostBeadReport> {
        let Some(ghosts) = &self.ghosts else {
            return Vec::new();
        };
        let in_space = self.active.in_space;
        ghost_beads(ghosts, &self.active, &self.transforms)
            .filter_map(|(at, radius, colour)| {
                let (centre, rim) = if in_space {
                    let right = self
                        .space_cameras
                        .iter()
                        .next()
                        .map_or(Vec3::X, |(_, t)| t.right().as_vec3());
                    let centre = self.space_pixel(scale, at.as_vec3())?;
                    let rim = self.space_pixel(scale, at.as_vec3() + right * radius)?;
                    (centre.to_array(), rim.to_array())
                } else {
                    let centre = to_pixel(at.truncate())?;
                    let rim = to_pixel(at.truncate() + DVec2::new(f64::from(radius), 0.0))?;
                    (centre, rim)
                };
                Some(GhostBeadReport {
                    world: at.to_array(),
                    pixel: centre,
                    radius_px: Vec2::from(centre).distance(Vec2::from(rim)),
                    colour,
                })
            })
            .collect()
    }

    /// Where the run is on its timeline, with the beads' states now and as
    /// recorded.
    fn timeline_report(&self) -> Option<TimelineReport> {
        let timeline = self.timeline.as_ref()?;
        let (first, last) = timeline.span()?;
        let step = self.clock.steps;
        let bits = |x: DVec3, v: DVec3| {
            [x.x, x.y, x.z, v.x, v.y, v.z]
                .map(|n| format!("{:016x}", n.to_bits()))
                .join(" ")
        };
        let mut now = Vec::new();
        let mut at_step = Vec::new();
        let mut entities: Vec<Entity> = self.states.iter().map(|(e, ..)| e).collect();
        entities.extend(self.space_states.iter().map(|(e, ..)| e));
        entities.sort_unstable();
        for entity in entities {
            let (x, v, recorded) = match self.states.get(entity) {
                Ok((_, x, v)) => (
                    x.0.extend(0.0),
                    v.0.extend(0.0),
                    timeline
                        .bead(step, entity)
                        .map(|(x, v)| (x.extend(0.0), v.extend(0.0))),
                ),
                Err(_) => {
                    let (_, x, v) = self.space_states.get(entity).ok()?;
                    (x.0, v.0, timeline.space_bead(step, entity))
                }
            };
            now.push(format!("{entity}: {}", bits(x, v)));
            if let Some((x, v)) = recorded {
                at_step.push(format!("{entity}: {}", bits(x, v)));
            }
        }
        Some(TimelineReport {
            step,
            recorded: [first.steps, last.steps],
            stepped_back: timeline.at().is_some(),
            matched: timeline.matched(),
            departed: timeline.departed(),
            now,
            at_step,
        })
    }
}

impl ReportView<'_, '_> {
    /// A point in space in physical pixels through the 3D view's camera.
    fn space_pixel(&self, scale: f32, p: Vec3) -> Option<Vec2> {
        let (camera, transform) = self.space_cameras.iter().next()?;
        Some(camera.world_to_viewport(transform, p).ok()? * scale)
    }

    /// Where each rigid body shows.
    fn bodies(&self, scale: f32, to_pixel: &dyn Fn(DVec2) -> Option<[f32; 2]>) -> Vec<BodyReport> {
        self.bodies
            .iter()
            .filter_map(|(name, transform)| {
                let at = transform.translation();
                let pixel = if self.active.in_space {
                    self.space_pixel(scale, at)?.to_array()
                } else {
                    to_pixel(at.truncate().as_dvec2())?
                };
                Some(BodyReport {
                    name: name.map(|n| n.as_str().to_owned()).unwrap_or_default(),
                    world: at.as_dvec3().to_array(),
                    pixel,
                })
            })
            .collect()
    }

    /// Each body being dragged: the point taken, where it is now, and the
    /// spring's anchor.
    fn dragged_bodies(&self) -> impl Iterator<Item = (DVec3, DVec3)> + '_ {
        self.dragged_bodies
            .iter()
            .filter_map(|(transform, grabs, anchors)| {
                let grab = match grabs {
                    (Some(g), _) => g.get().extend(0.0),
                    (_, Some(g)) => g.get(),
                    _ => return None,
                };
                let target = match anchors {
                    (Some(a), _) => a.get().extend(0.0),
                    (_, Some(a)) => a.get(),
                    _ => return None,
                };
                let at = transform.transform_point(grab.as_vec3()).as_dvec3();
                Some((at, target))
            })
    }

    /// Where each bead in space shows, and how large.
    fn space_beads(&self, scale: f32) -> Vec<SpaceBeadReport> {
        let right = self
            .space_cameras
            .iter()
            .next()
            .map_or(Vec3::X, |(_, t)| t.right().as_vec3());
        self.space_beads
            .iter()
            .filter_map(|(bead, diverged, transform, _)| {
                let at = bead.0.as_vec3();
                let centre = self.space_pixel(scale, at)?;
                let rim = self.space_pixel(scale, at + right * transform.scale.x)?;
                Some(SpaceBeadReport {
                    world: bead.0.to_array(),
                    pixel: centre.to_array(),
                    radius_px: centre.distance(rim),
                    diverged: diverged.map(|d| d.reason.to_string()),
                })
            })
            .collect()
    }

    /// Each curve in space's drawn points inside the window.
    fn space_curves(&self, scale: f32, inside: impl Fn(&[f32; 2]) -> bool) -> Vec<Vec<[f32; 2]>> {
        self.space_wires
            .iter()
            .filter_map(|(drawing, transform, riding)| match drawing {
                WireDrawing::Curve(points) => {
                    let placed = carried_transform(transform, riding, &self.transforms);
                    Some(
                        points
                            .iter()
                            .filter_map(|&p| self.space_pixel(scale, placed.transform_point(p)))
                            .map(|p| p.to_array())
                            .filter(&inside)
                            .collect(),
                    )
                }
                WireDrawing::Surface(_) => None,
            })
            .collect()
    }
}

impl AutomationState {
    /// Records the dragged beads' positions and the drag target.
    fn follow_drag(&mut self, dragged: impl Iterator<Item = (DVec3, DVec3)>) {
        for (bead, target) in dragged {
            self.drag_path.push(bead);
            self.drag_target = Some(target);
        }
    }

    /// The drag so far, measured against where the cursor ended up.
    fn drag_report(&self) -> Option<DragReport> {
        let (target, start) = self.drag_target.zip(self.drag_path.first())?;
        Some(DragReport {
            bead_start: start.to_array(),
            target: target.to_array(),
            start_distance: (*start - target).length(),
            closest_distance: self
                .drag_path
                .iter()
                .map(|p| (*p - target).length())
                .fold(f64::INFINITY, f64::min),
        })
    }

    /// The mean frame time after the first 30 frames, in milliseconds.
    fn mean_frame_ms(&self) -> f64 {
        1e3 * self.timed_seconds / f64::from(self.timed_frames.max(1))
    }

    /// What went wrong in the whole run, judged at its last frame.
    fn judge_run(&mut self, active: &ActivePreset, last: &FrameReport) {
        if let Some(error) = &active.error {
            self.failures.push(format!("scene file {error}"));
        }
        if active.running.is_none() && !active.path.is_empty() {
            let failure = format!("the scene preset {} never ran", active.path);
            self.failures.push(failure);
        }
        if last.beads.is_empty() && last.space_beads.is_empty() && last.bodies.is_empty() {
            self.failures
                .push("there was no bead or body in the scene".to_owned());
        }
    }
}

/// Counts frames; writes the ready report, the screenshot with its report
/// and the last report; exits when the frames are done.
fn automation(
    mut state: ResMut<AutomationState>,
    real: Res<Time<Real>>,
    mut virtual_time: ResMut<Time<Virtual>>,
    scene: ReportView,
    mut exit: MessageWriter<AppExit>,
    mut commands: Commands,
) {
    state.frame += 1;
    let frame = state.frame;
    if frame > 30 {
        state.timed_frames += 1;
        state.timed_seconds += real.delta_secs_f64();
    }
    let in_plane = scene
        .beads
        .iter()
        .filter_map(|(bead, target, ..)| Some((bead.0.extend(0.0), target?.get().extend(0.0))));
    let in_space = scene
        .space_beads
        .iter()
        .filter_map(|(bead, _, _, target)| Some((bead.0, target?.get())));
    state.follow_drag(in_plane.chain(in_space).chain(scene.dragged_bodies()));
    let report =
        |state: &AutomationState| scene.report(frame, state.drag_report(), state.mean_frame_ms());

    if let Some(path) = state.config.ready.clone()
        && !state.ready_written
        && frame >= 30
        && scene.active.running.is_some()
    {
        state.ready_written = true;
        if let Err(e) = write_report(&path, &report(&state)) {
            state.failures.push(e);
        }
    }

    let Some(mut frames) = state.config.frames else {
        return;
    };
    if frame + 21 < frames
        && state
            .config
            .finish_when
            .as_ref()
            .is_some_and(|path| path.exists())
    {
        frames = frame + 21;
        state.config.frames = Some(frames);
    }
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
            if let Err(e) = write_report(&path.with_extension("ron"), &report(&state)) {
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
    let last = report(&state);
    state.judge_run(&scene.active, &last);
    if let Some(path) = state.config.report.clone()
        && let Err(e) = write_report(&path, &last)
    {
        state.failures.push(e);
    }
    let mean_frame_ms = state.mean_frame_ms();
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
