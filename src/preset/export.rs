//! Data out of the window: the run as the CSV `simulate --scene` writes
//! (from the [`Timeline`]), and the scene with its edits as a scene file
//! that loads again.

use std::path::{Path, PathBuf};

use bevy::math::DVec3;
use bevy::prelude::*;

use super::table::write_recorded_csv;
use super::{ActivePreset, SceneFile};
use crate::controls::ExportRequests;
use crate::dynamics::{
    BeadParams, NextBeadParams, NextParams, NextWireShape, OnWire, SimParams, Wire,
};
use crate::geometry::WireShape;
use crate::plugin::Timeline;

/// Writes the run and the scene where [`ExportRequests`] ask, into
/// [`ExportDir`], and says what it wrote in [`LastExport`]. Needs the
/// [`ScenePresetPlugin`](super::ScenePresetPlugin) and a
/// [`TimelinePlugin`](crate::plugin::TimelinePlugin).
#[derive(Default)]
pub struct ExportPlugin;

impl Plugin for ExportPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<ExportDir>()
            .init_resource::<ExportRequests>()
            .init_resource::<LastExport>()
            .add_systems(Update, export_requested);
    }
}

/// Where exports are written: `exports/` under the working directory
/// unless set.
#[derive(Resource, Clone, Debug, PartialEq, Eq)]
pub struct ExportDir(pub PathBuf);

impl Default for ExportDir {
    fn default() -> Self {
        Self(PathBuf::from("exports"))
    }
}

/// What the last export wrote, or why it could not: one line.
#[derive(Resource, Clone, Debug, Default, PartialEq, Eq)]
pub struct LastExport(pub Option<Result<String, String>>);

/// The scene file's name without its extension: `rope` for
/// `scenes/rope.scene.ron`, `scene` where there is none.
pub fn scene_stem(path: &str) -> String {
    let name = Path::new(path)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("");
    let stem = name.strip_suffix(".scene.ron").unwrap_or(name);
    if stem.is_empty() {
        "scene".to_owned()
    } else {
        stem.to_owned()
    }
}

/// `scene` with the run's edits: the parameters `params`, each bead's
/// parameters in the file's order (`beads`; a bead missing keeps the
/// file's), and in the plane each wire's shape where `shapes` has one (by
/// the wire's place in the file).
pub fn with_edits(
    scene: &SceneFile,
    params: &SimParams,
    beads: &[Option<BeadParams>],
    space_beads: &[Option<BeadParams<DVec3>>],
    shapes: &[Option<WireShape>],
) -> SceneFile {
    let mut scene = scene.clone();
    match &mut scene {
        SceneFile::Plane(plane) => {
            plane.params = params.clone();
            for (wire, shape) in plane.wires.iter_mut().zip(shapes) {
                if let Some(shape) = shape {
                    wire.shape = shape.clone();
                }
            }
            let all = plane.wires.iter_mut().flat_map(|w| &mut w.beads);
            for (bead, edit) in all.chain(&mut plane.beads).zip(beads) {
                if let Some(edit) = edit {
                    bead.mass = edit.mass;
                    bead.initial_position = edit.initial_position;
                    bead.initial_velocity = edit.initial_velocity;
                }
            }
        }
        SceneFile::Space(space) => {
            space.params.0 = params.clone();
            let all = space.wires.iter_mut().flat_map(|w| &mut w.beads);
            for (bead, edit) in all.chain(&mut space.beads).zip(space_beads) {
                if let Some(edit) = edit {
                    bead.mass = edit.mass;
                    bead.initial_position = edit.initial_position;
                    bead.initial_velocity = edit.initial_velocity;
                }
            }
        }
    }
    scene
}

/// The scene file's text, as it loads again.
pub fn scene_ron(scene: &SceneFile) -> Result<String, String> {
    let config = ron::ser::PrettyConfig::default();
    match scene {
        SceneFile::Plane(plane) => ron::ser::to_string_pretty(plane, config),
        SceneFile::Space(space) => ron::ser::to_string_pretty(space, config),
    }
    .map_err(|e| e.to_string())
}

/// What the export reads of the beads: their parameters, applied and
/// pending, and their wires.
pub(crate) type BeadEdits = (
    Option<&'static BeadParams>,
    Option<&'static NextBeadParams>,
    Option<&'static BeadParams<DVec3>>,
    Option<&'static NextBeadParams<DVec3>>,
    Option<&'static OnWire>,
);

/// The wires' shapes, applied and pending.
pub(crate) type WireEdits<'w, 's> = Query<'w, 's, (&'static Wire, Option<&'static NextWireShape>)>;

/// Makes the exports asked for.
#[allow(clippy::too_many_arguments)]
fn export_requested(
    mut requests: ResMut<ExportRequests>,
    dir: Res<ExportDir>,
    active: Res<ActivePreset>,
    scenes: Res<Assets<SceneFile>>,
    timeline: Option<Res<Timeline>>,
    pending: Res<NextParams>,
    beads: Query<BeadEdits>,
    wires: WireEdits,
    mut last: ResMut<LastExport>,
) {
    // The plots' PNG is the window's to make.
    let requests = ExportRequests {
        csv: std::mem::take(&mut requests.csv),
        scene: std::mem::take(&mut requests.scene),
        plots: 0,
    };
    if requests == ExportRequests::default() {
        return;
    }
    let outcome = (|| {
        let scene = scenes
            .get(active.handle.id())
            .ok_or("no scene file is running: nothing was written")?;
        std::fs::create_dir_all(&dir.0)
            .map_err(|e| format!("{}: {e}; nothing was written", dir.0.display()))?;
        let stem = scene_stem(&active.path);
        let mut written = Vec::new();
        if requests.csv > 0 {
            let timeline = timeline.as_deref().ok_or("no run is recorded")?;
            let path = dir.0.join(format!("{stem}.csv"));
            let file = std::fs::File::create(&path)
                .map_err(|e| format!("{}: {e}; nothing was written", path.display()))?;
            let entities = (&active.beads[..], &active.bodies[..]);
            let rows = write_recorded_csv(file, scene, entities, timeline)
                .map_err(|e| format!("{}: {e}", path.display()))?;
            written.push(format!("{} ({rows} rows)", path.display()));
        }
        if requests.scene > 0 {
            let edited = edited_scene(scene, &active.beads, pending.get(), true, &beads, &wires);
            let path = dir.0.join(format!("{stem}.scene.ron"));
            let text = scene_ron(&edited)?;
            std::fs::write(&path, text)
                .map_err(|e| format!("{}: {e}; nothing was written", path.display()))?;
            written.push(path.display().to_string());
        }
        Ok(format!("wrote {}", written.join(" and ")))
    })();
    match &outcome {
        Ok(message) => info!("wirebead: {message}"),
        Err(message) => warn!("wirebead: export: {message}"),
    }
    last.0 = Some(outcome);
}

/// The running scene (its beads `order` in the file's order) with
/// `params` and each bead's and wire's edits: those applied, and where
/// `pending` those waiting for a restart too.
pub(crate) fn edited_scene(
    scene: &SceneFile,
    order: &[Entity],
    params: &SimParams,
    pending: bool,
    beads: &Query<BeadEdits>,
    wires: &WireEdits,
) -> SceneFile {
    let edits: Vec<_> = order.iter().map(|&e| beads.get(e).ok()).collect();
    let plane = edits
        .iter()
        .map(|b| {
            let (now, next, ..) = (*b)?;
            next.filter(|_| pending).map(|n| *n.get()).or(now.copied())
        })
        .collect::<Vec<_>>();
    let space = edits
        .iter()
        .map(|b| {
            let (_, _, now, next, _) = (*b)?;
            next.filter(|_| pending).map(|n| *n.get()).or(now.copied())
        })
        .collect::<Vec<_>>();
    // Each wire of the file by its first bead.
    let shapes = match scene {
        SceneFile::Plane(preset) => {
            let mut first = 0;
            preset
                .wires
                .iter()
                .map(|w| {
                    let bead = order.get(first).copied();
                    first += w.beads.len();
                    if w.beads.is_empty() {
                        return None;
                    }
                    let (.., on) = beads.get(bead?).ok()?;
                    let (wire, next) = wires.get(on?.0).ok()?;
                    let next = next.filter(|_| pending);
                    Some(next.map_or_else(|| wire.shape().clone(), |n| n.shape().clone()))
                })
                .collect()
        }
        SceneFile::Space(_) => Vec::new(),
    };
    with_edits(scene, params, &plane, &space, &shapes)
}
