//! The selected bead in space: its mass and start in three components
//! (edited for the next restart, as in the plane), its wire (a spinning
//! wire's ω edited live), and its `C`, `Ċ`, λ and energy.

use bevy::prelude::*;
use bevy_egui::egui;

use super::keyboard::number_field;
use super::params::{Edit, RowValues, bead_start_editor, keep_bead_edit, value_rows};
use super::view::PanelView;
use crate::PrescribedMotion;
use crate::geometry::{SpaceMotion, SpaceShape};

/// The selected bead in space, if one is selected.
pub(super) fn space_bead_section(
    ui: &mut egui::Ui,
    view: &PanelView,
    commands: &mut Commands,
) -> Edit {
    let (entity, bead, diagnostics, on_wire, pending, _) =
        view.selected.0.and_then(|e| view.space_beads.get(e).ok())?;
    let (before, draft) = bead_start_editor(ui, "space-bead", bead, pending);
    let mut outcome = keep_bead_edit(commands, entity, before, draft);
    if let Some(on_wire) = on_wire
        && let Ok((wire, motion)) = view.space_wires.get(on_wire.0)
    {
        ui.strong("Wire");
        ui.label(match wire.shape() {
            SpaceShape::Curve(_) => "a curve: two rows, the offset along two normals",
            SpaceShape::Surface(_) => "a surface: one row, its value",
        });
        let surface = wire.surface();
        if surface.side.sign() != 0.0 {
            ui.label(format!(
                "pushes one way ({} side), restitution {:.2}",
                surface.side.name(),
                surface.restitution
            ));
        }
        match motion.map(PrescribedMotion::motion) {
            Some(SpaceMotion::Spin {
                angular_velocity,
                axis,
            }) => {
                let mut omega = angular_velocity;
                ui.horizontal(|ui| {
                    ui.label("spins at ω");
                    number_field(ui, &mut omega, "spins at ω", |d| {
                        d.speed(0.05).suffix(" rad/s").max_decimals(3)
                    });
                });
                ui.label(format!(
                    "about ({:.2}, {:.2}, {:.2}); a change applies at once",
                    axis.x, axis.y, axis.z
                ));
                if omega != angular_velocity {
                    let spin = SpaceMotion::Spin {
                        angular_velocity: omega,
                        axis,
                    };
                    outcome = Some(PrescribedMotion::in_space(spin).map(|motion| {
                        commands.entity(on_wire.0).insert(motion);
                    }));
                }
            }
            Some(SpaceMotion::Oscillate(o)) => {
                ui.label(format!(
                    "oscillates by ({:.2}, {:.2}, {:.2}) at {:.2} Hz",
                    o.amplitude.x, o.amplitude.y, o.amplitude.z, o.frequency
                ));
            }
            Some(SpaceMotion::Fixed) | None => {}
        }
    }
    ui.separator();
    egui::Grid::new("space-values")
        .num_columns(4)
        .show(ui, |ui| {
            let row = diagnostics.map(|d| RowValues {
                wire: on_wire.map(|_| [d.c, d.c_dot, d.lambda]),
                energy: d.energy(),
                from_start: view
                    .space_positions
                    .get(entity)
                    .ok()
                    .map(|x| (x.0 - bead.initial_position).length()),
            });
            value_rows(ui, row, &view.clock);
        });
    outcome
}
