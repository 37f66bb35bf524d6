//! The windowed scene (feature `gui`): wires drawn with gizmos, beads as
//! meshes the mouse can drag, trails and force arrows, an egui panel with
//! every parameter and live plots, and automation for screenshots.
//!
//! | plugin | what it adds |
//! |---|---|
//! | [`WireBeadGuiPlugin`] | everything below plus [`crate::ScenePresetPlugin`] and [`crate::KeyboardControlsPlugin`] |
//! | [`SceneRenderPlugin`] | camera framing, wire gizmos, bead meshes, trails, force arrows |
//! | [`BeadDragPlugin`] | mesh picking: drag a bead with the mouse (the assignment's spring) |
//! | [`PanelPlugin`] | the egui panel and plots |
//! | [`AutomationPlugin`] | run N frames, screenshot, reports, exit status |
//!
//! Add [`WireBeadGuiPlugin`] after `DefaultPlugins` and
//! [`WireBeadPlugin`](crate::WireBeadPlugin); it adds `EguiPlugin` and
//! `MeshPickingPlugin` if they are missing.

pub mod automation;
pub mod drag;
pub mod panel;
pub mod render;

use bevy::picking::mesh_picking::MeshPickingPlugin;
use bevy::prelude::*;
use bevy_egui::EguiPlugin;

pub use automation::{AutomationPlugin, FrameReport};
pub use drag::BeadDragPlugin;
pub use panel::{PanelPlugin, PresetCatalog};
pub use render::{SceneCamera, SceneRenderPlugin, SceneStyle};

use crate::controls::KeyboardControlsPlugin;
use crate::preset::ScenePresetPlugin;

/// The whole interactive scene on top of the simulation.
#[derive(Default)]
pub struct WireBeadGuiPlugin;

impl Plugin for WireBeadGuiPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<EguiPlugin>() {
            app.add_plugins(EguiPlugin::default());
        }
        if !app.is_plugin_added::<MeshPickingPlugin>() {
            app.add_plugins(MeshPickingPlugin);
        }
        if !app.is_plugin_added::<ScenePresetPlugin>() {
            app.add_plugins(ScenePresetPlugin);
        }
        if !app.is_plugin_added::<KeyboardControlsPlugin>() {
            app.add_plugins(KeyboardControlsPlugin);
        }
        app.add_plugins((SceneRenderPlugin, BeadDragPlugin, PanelPlugin));
    }
}
