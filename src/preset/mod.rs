//! Scene presets: RON files that set the wires, the beads, the links
//! between beads and the parameters, loaded as Bevy assets
//! (`*.scene.ron`).
//!
//! ```ron
//! (
//!     name: "Pendulum on a cart",
//!     params: (integrator: Rattle),
//!     wires: [(shape: Line(()), beads: [(name: "cart", mass: 2.0, initial_position: (0.0, 0.0))])],
//!     beads: [(name: "bob", mass: 1.0, initial_position: (0.0, -1.0))],
//!     constraints: [Rod((a: "cart", b: "bob", length: 1.0))],
//!     springs: [],
//! )
//! ```
//!
//! `beads` outside `wires` are free (on no wire). Links name beads by
//! their `name`; a bead without one is `bead0`, `bead1`, … by its place in
//! the file (the wires' beads in order, then the free ones). A pin is
//! `Pin((bead: "top", at: (0.0, 2.0)))`, a spring
//! `(a: "p", b: "q", rest_length: 1.0, stiffness: 50.0, damping: 0.1)`.
//! `beads`, `constraints` and `springs` may be left out.
//!
//! [`ScenePresetPlugin`] loads the file named by [`ActivePreset`], applies it
//! when it loads and again whenever the file changes (with Bevy's
//! `file_watcher`), and on a malformed file keeps the running scene and
//! records the error in [`ActivePreset::error`].

#[cfg(feature = "avian2d")]
mod bodies_plane;
#[cfg(feature = "avian3d")]
mod bodies_space;
#[cfg(test)]
mod body_tests;
mod error;
mod export;
mod format;
mod hourglass;
mod marble_run;
mod pile;
mod plugin;
mod space;
#[cfg(test)]
mod space_tests;
mod spawn;
pub mod table;
#[cfg(test)]
mod tests;

pub use error::PresetError;
pub(crate) use export::{BeadEdits, WireEdits, edited_scene};
pub use export::{ExportDir, ExportPlugin, LastExport, scene_ron, scene_stem, with_edits};
pub use format::{
    ANCHOR_TOLERANCE, BallShape, BeadPreset, BodyKind, BodyPreset, BodyShape, BoxShape,
    CapsuleShape, ConstraintPreset, ContactsPreset, CouplingPreset, HingePreset, MotorPreset,
    PathPreset, PathRotationPreset, PinPreset, PositionMotorPreset, RodPreset, RotationPreset,
    SceneBody, SceneJoin, SceneLink, ScenePath, ScenePreset, SendBackPreset, SpaceBodyPreset,
    SpringPreset, VelocityMotorPreset, WirePreset, plane_inertia, space_inertia,
};
pub use hourglass::{GRAIN_RADIUS, Hourglass};
pub use marble_run::{MARBLE_BOWL, MarbleRun};
pub use pile::{PILE_RADIUS, Pour};
pub use plugin::{
    ActivePreset, LoadPreset, ScenePresetLoader, ScenePresetPlugin, apply_loaded_preset,
    load_requested_preset, report_preset_errors,
};
pub use space::{
    ConePreset, RailPreset, SpaceMotionPreset, SpaceScene, SpaceShapePreset, SpaceWirePreset,
    SpinPreset,
};
pub use spawn::FromPreset;

use bevy::prelude::*;

/// A scene file of either dimension, as its `dimension` says: in the
/// plane (none, or `2`) or in space (`3`). The asset
/// [`ScenePresetLoader`] loads.
#[derive(Asset, TypePath, Clone, Debug)]
pub enum SceneFile {
    /// A scene in the plane.
    Plane(ScenePreset),
    /// A scene in space.
    Space(SpaceScene),
}

impl SceneFile {
    /// Parses and validates a scene file of either dimension.
    pub fn from_ron(text: &str) -> Result<Self, PresetError> {
        match format::dimension_of(text) {
            2 => ScenePreset::from_ron(text).map(Self::Plane),
            3 => {
                let scene: SpaceScene = format::parse(text)?;
                scene.validate()?;
                Ok(Self::Space(scene))
            }
            other => Err(PresetError::Dimension(other)),
        }
    }

    /// The scene's name.
    pub fn name(&self) -> &str {
        match self {
            Self::Plane(scene) => &scene.name,
            Self::Space(scene) => &scene.name,
        }
    }

    /// The scene's parameters.
    pub fn params(&self) -> &crate::SimParams {
        match self {
            Self::Plane(scene) => &scene.params,
            Self::Space(scene) => &scene.params.0,
        }
    }

    /// Whether the scene is in space.
    pub fn in_space(&self) -> bool {
        matches!(self, Self::Space(_))
    }

    /// Spawns the scene: its wires, beads and links, each marked
    /// [`FromPreset`]; the beads in the file's order.
    pub fn spawn(&self, commands: &mut Commands) -> Vec<Entity> {
        match self {
            Self::Plane(scene) => scene.spawn(commands),
            Self::Space(scene) => scene.spawn(commands),
        }
    }

    /// Spawns the scene as [`spawn`](Self::spawn) does, with its rigid
    /// bodies (in a build with avian): its beads, and the bodies a run
    /// records (dynamic and kinematic), each in the file's order.
    pub fn spawn_recorded(&self, commands: &mut Commands) -> (Vec<Entity>, Vec<Entity>) {
        use table::Scene;
        match self {
            Self::Plane(scene) => scene.spawn_recorded(commands),
            Self::Space(scene) => scene.spawn_recorded(commands),
        }
    }
}
