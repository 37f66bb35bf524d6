//! The windowed scene (feature `gui`): wires drawn with gizmos, beads as
//! meshes the mouse can drag, trails and force arrows, an egui panel with
//! every parameter and live plots, and automation for screenshots.
//!
//! | plugin | what it adds |
//! |---|---|
//! | [`WireBeadGuiPlugin`] | everything below plus [`crate::ScenePresetPlugin`] and [`crate::KeyboardControlsPlugin`] |
//! | [`SceneRenderPlugin`] | camera framing, wire gizmos, bead meshes, trails, force arrows |
//! | [`SpaceViewPlugin`] | the 3D view of scenes in space: orbit camera, wires as lines and translucent surfaces, beads as spheres to drag |
//! | [`BeadDragPlugin`] | mesh picking: drag a bead with the mouse (the assignment's spring) |
//! | [`BodyViewPlugin`] | avian's rigid bodies (features `avian2d`, `avian3d`) drawn, and dragged by the point taken |
//! | [`PanelPlugin`] | the egui panel and plots |
//! | [`AutomationPlugin`] | run N frames, screenshot, reports, exit status |
//!
//! Add [`WireBeadGuiPlugin`] after `DefaultPlugins` and
//! [`WireBeadPlugin`](crate::WireBeadPlugin); it adds `EguiPlugin` and
//! `MeshPickingPlugin` if they are missing.

pub mod automation;
pub mod bodies;
pub mod drag;
pub mod ghost;
pub mod panel;
pub mod render;
pub mod space;

use bevy::picking::mesh_picking::MeshPickingPlugin;
use bevy::prelude::*;
use bevy_egui::{EguiGlobalSettings, EguiPlugin};

pub use automation::{
    AutomationPlugin, BodyReport, FrameReport, GhostBeadReport, PlotReport, TimelineReport,
};
pub use bodies::BodyViewPlugin;
pub use drag::BeadDragPlugin;
pub use panel::{PanelPlugin, PresetCatalog};
pub use render::{SceneCamera, SceneRenderPlugin, SceneStyle};
pub use space::{SpaceCamera, SpaceViewPlugin};

use crate::controls::KeyboardControlsPlugin;
use crate::plugin::TimelinePlugin;
use crate::preset::{ExportPlugin, ScenePresetPlugin};
use ghost::GhostViewPlugin;

/// The whole interactive scene on top of the simulation.
#[derive(Default)]
pub struct WireBeadGuiPlugin;

impl Plugin for WireBeadGuiPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<EguiPlugin>() {
            app.add_plugins(EguiPlugin::default());
        }
        // The panel lives on the plane's camera, which stays on in both
        // views (the space camera is off for scenes in the plane); it is
        // given the panel's context itself.
        match app.world_mut().get_resource_mut::<EguiGlobalSettings>() {
            Some(mut settings) => settings.auto_create_primary_context = false,
            None => {
                app.insert_resource(EguiGlobalSettings {
                    auto_create_primary_context: false,
                    ..default()
                });
            }
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
        if !app.is_plugin_added::<TimelinePlugin>() {
            app.add_plugins(TimelinePlugin);
        }
        if !app.is_plugin_added::<ExportPlugin>() {
            app.add_plugins(ExportPlugin);
        }
        app.add_plugins((
            GhostViewPlugin,
            SceneRenderPlugin,
            SpaceViewPlugin,
            BeadDragPlugin,
            BodyViewPlugin,
            PanelPlugin,
        ));
    }
}
