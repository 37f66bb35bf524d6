//! The egui panel: every parameter of the assignment's panel plus gravity, wire
//! shape and size, integrator and stabilization; a marker while edits are
//! pending; live plots of `C`, energy and λ, and of any two quantities
//! against each other (the phase portrait); the last strikes between
//! beads that touch; divergence and scene-file errors in plain words.
//!
//! Edits go through the plugin's validating setters: an invalid value is
//! refused with the plugin's error message and never reaches the
//! simulation.

mod constraints;
mod ghosts;
mod keyboard;
mod params;
mod phase;
mod plots;
mod png;
mod space;
mod timeline;
mod view;
mod window;

use bevy::prelude::*;
use bevy_egui::EguiPrimaryContextPass;

pub use keyboard::{FOCUS_KEPT, FocusTrail};
pub use phase::{PhasePlot, PhasePlotFrame, PlotFrame, Quantity};
pub use plots::{
    HeldBy, PlotHistory, PlotSample, PlotsShown, RecentStrikes, record_history, record_strikes,
};
use png::save_plots;
pub use view::{PanelActions, PanelView};
pub use window::panel;

use crate::gui::drag::SelectedBead;
use crate::{Bead, WireBeadSystems};

/// The presets with rigid bodies the build can run: those of each avian
/// it has (features `avian2d`, `avian3d`).
const WITH_BODIES: &[(&str, &str)] = &[
    #[cfg(feature = "avian2d")]
    (
        "With avian: cart on a hoop",
        "scenes/avian/cart_on_hoop.scene.ron",
    ),
    #[cfg(feature = "avian2d")]
    (
        "With avian: marbles and dominoes",
        "scenes/avian/dominoes.scene.ron",
    ),
    #[cfg(feature = "avian2d")]
    (
        "With avian: beads knocking over crates",
        "scenes/avian/beads_and_crates.scene.ron",
    ),
    #[cfg(feature = "avian3d")]
    (
        "With avian, in space: cart on a loop",
        "scenes/avian/cart_on_loop_in_space.scene.ron",
    ),
    #[cfg(feature = "avian3d")]
    (
        "With avian, in space: coaster train and crates",
        "scenes/avian/coaster_train.scene.ron",
    ),
    #[cfg(feature = "avian3d")]
    (
        "With avian, in space: bead on a hoop on a door",
        "scenes/avian/door.scene.ron",
    ),
];

/// The presets the panel offers: `(label, asset path)`.
#[derive(Resource, Clone, Debug)]
pub struct PresetCatalog(pub Vec<(String, String)>);

impl Default for PresetCatalog {
    fn default() -> Self {
        Self(
            [
                (
                    "The assignment's circle",
                    "scenes/assignment_circle.scene.ron",
                ),
                ("Tilted ellipse", "scenes/ellipse.scene.ron"),
                ("Sine track", "scenes/sine_track.scene.ron"),
                ("Many beads", "scenes/multi_bead.scene.ron"),
                ("Bead at rest", "scenes/resting.scene.ron"),
                ("Pendulum from 60°", "scenes/pendulum.scene.ron"),
                ("Pendulum on a cart", "scenes/pendulum_on_cart.scene.ron"),
                ("Double pendulum", "scenes/double_pendulum.scene.ron"),
                ("Rope on a rail", "scenes/rope.scene.ron"),
                ("Ring of beads on a circle", "scenes/ring.scene.ron"),
                (
                    "Two beads and a spring on a track",
                    "scenes/spring_pair.scene.ron",
                ),
                ("Kapitza pendulum", "scenes/kapitza.scene.ron"),
                ("Bead on a spinning rod", "scenes/spinning_rod.scene.ron"),
                ("Tautochrone race", "scenes/tautochrone.scene.ron"),
                ("Roller coaster", "scenes/roller_coaster.scene.ron"),
                ("Newton's cradle", "scenes/newtons_cradle.scene.ron"),
                ("Air track, elastic", "scenes/air_track.scene.ron"),
                ("Air track, sticky", "scenes/air_track_sticky.scene.ron"),
                ("Abacus", "scenes/abacus.scene.ron"),
                ("Train on a closed track", "scenes/train.scene.ron"),
                ("Hourglass of 300 grains", "scenes/hourglass.scene.ron"),
                (
                    "In space: bead on a rotating hoop",
                    "scenes/rotating_hoop.scene.ron",
                ),
                ("In space: bead on a helix", "scenes/helix.scene.ron"),
                (
                    "In space: spherical pendulum",
                    "scenes/spherical_pendulum.scene.ron",
                ),
                ("In space: bead on a torus", "scenes/torus.scene.ron"),
                (
                    "In space: roller coaster",
                    "scenes/coaster_in_space.scene.ron",
                ),
                (
                    "In space: rope from a pin",
                    "scenes/rope_in_space.scene.ron",
                ),
                ("In space: bead in a bowl", "scenes/bowl.scene.ron"),
                (
                    "In space: marble run of 200",
                    "scenes/marble_run_in_space.scene.ron",
                ),
            ]
            .into_iter()
            .chain(WITH_BODIES.iter().copied())
            .map(|(a, b)| (a.to_owned(), b.to_owned()))
            .collect(),
        )
    }
}

/// The egui panel and plots.
#[derive(Default)]
pub struct PanelPlugin;

impl Plugin for PanelPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<PresetCatalog>()
            .init_resource::<PlotHistory>()
            .init_resource::<crate::plugin::SceneEnergy>()
            .init_resource::<PhasePlot>()
            .init_resource::<PhasePlotFrame>()
            .init_resource::<PlotsShown>()
            .init_resource::<SelectedBead>()
            .init_resource::<RecentStrikes>()
            .add_systems(
                FixedUpdate,
                (record_history, record_strikes).after(WireBeadSystems::Writeback),
            )
            .add_systems(Update, (keep_selection, save_plots))
            .add_systems(
                EguiPrimaryContextPass,
                (panel, keyboard::record_focus).chain(),
            );
        keyboard::build(app);
    }
}

/// Selects the first bead when none (or a despawned one) is selected.
pub fn keep_selection(
    mut selected: ResMut<SelectedBead>,
    beads: Query<Entity, Or<(With<Bead>, With<crate::SpaceBead>)>>,
) {
    if selected.0.is_none_or(|e| !beads.contains(e)) {
        selected.0 = beads.iter().min();
    }
}
