//! The ghosts in the window: each ghost's beads drawn as rings in its own
//! colour, the size of the run's beads, and the panel's selected bead
//! followed in their plots.

use bevy::math::DVec3;
use bevy::prelude::*;

use crate::ghost::{GhostFocus, GhostPlugin, Ghosts};
use crate::gui::drag::SelectedBead;
use crate::preset::ActivePreset;

/// Steps the ghosts ([`GhostPlugin`]) and draws them.
#[derive(Default)]
pub struct GhostViewPlugin;

impl Plugin for GhostViewPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<GhostPlugin>() {
            app.add_plugins(GhostPlugin);
        }
        app.add_systems(Update, (follow_selection, draw_ghosts));
    }
}

/// A ghost's colour for drawing.
pub fn ghost_colour(colour: [f32; 4]) -> Color {
    Color::srgba(colour[0], colour[1], colour[2], colour[3])
}

/// A ghost's colour in the panel, opaque.
pub fn ghost_colour32(colour: [f32; 4]) -> bevy_egui::egui::Color32 {
    let [r, g, b, _] = colour.map(|c| (c * 255.0).round() as u8);
    bevy_egui::egui::Color32::from_rgb(r, g, b)
}

/// The ghosts record the selected bead.
fn follow_selection(selected: Res<SelectedBead>, mut focus: ResMut<GhostFocus>) {
    if focus.0 != selected.0 {
        focus.0 = selected.0;
    }
}

/// Where each ghost bead is drawn and how large: at its position, as large
/// as the run's bead in its place, in the ghost's colour (sRGB and alpha).
pub(crate) fn ghost_beads<'a>(
    ghosts: &'a Ghosts,
    active: &'a ActivePreset,
    radii: &'a Query<&Transform>,
) -> impl Iterator<Item = (DVec3, f32, [f32; 4])> + 'a {
    ghosts.list.iter().flat_map(move |ghost| {
        let colour = ghost.colour;
        ghost
            .positions()
            .into_iter()
            .zip(&active.beads)
            .map(move |(at, &bead)| {
                let radius = radii.get(bead).map_or(0.05, |t| t.scale.x);
                (at, radius, colour)
            })
    })
}

/// Draws every ghost bead as two rings: one at the bead's size and one
/// within it.
fn draw_ghosts(
    ghosts: Res<Ghosts>,
    active: Res<ActivePreset>,
    radii: Query<&Transform>,
    mut gizmos: Gizmos,
) {
    for (at, radius, colour) in ghost_beads(&ghosts, &active, &radii) {
        let colour = ghost_colour(colour);
        if active.in_space {
            let at = Isometry3d::from_translation(at.as_vec3());
            gizmos.sphere(at, radius, colour);
        } else {
            let at = Isometry2d::from_translation(at.truncate().as_vec2());
            gizmos.circle_2d(at, radius, colour);
            gizmos.circle_2d(at, 0.6 * radius, colour);
        }
    }
}
