//! The panel's ghosts: the next ghost's method, Baumgarte constants and
//! timestep, a button (and G) to add it, and the ghosts running, each in
//! its colour with a button to take it away.

use bevy_egui::egui;

use super::keyboard::number_field;
use super::view::{ERROR_RED, PanelActions, PanelView};
use crate::controls::key_name;
use crate::ghost::{GhostRequest, MAX_GHOSTS, default_ghost};
use crate::gui::ghost::ghost_colour32;
use crate::solver::Method;

/// The ghosts section, folded until opened.
pub(super) fn ghosts_section(ui: &mut egui::Ui, view: &PanelView, actions: &mut PanelActions) {
    ui.separator();
    let count = view.ghosts.list.len();
    egui::CollapsingHeader::new(format!("Ghosts ({count})"))
        .id_salt("ghosts")
        .default_open(count > 0)
        .show(ui, |ui| ghosts(ui, view, actions));
}

fn ghosts(ui: &mut egui::Ui, view: &PanelView, actions: &mut PanelActions) {
    let mut draft = actions
        .ghost_draft
        .0
        .unwrap_or_else(|| default_ghost(&view.params));
    egui::Grid::new("ghost-draft")
        .num_columns(2)
        .show(ui, |ui| {
            ui.label("method");
            egui::ComboBox::from_id_salt("ghost-method")
                .selected_text(draft.method.to_string())
                .show_ui(ui, |ui| {
                    for method in Method::ALL {
                        ui.selectable_value(&mut draft.method, method, method.to_string());
                    }
                });
            ui.end_row();
            for (label, value, speed) in [
                ("α", &mut draft.alpha, 1.0),
                ("β", &mut draft.beta, 0.1),
                ("timestep (s)", &mut draft.timestep, 0.0005),
            ] {
                ui.label(label);
                number_field(ui, value, &format!("ghost {label}"), |d| d.speed(speed));
                ui.end_row();
            }
        });
    if actions.ghost_draft.0 != Some(draft) {
        actions.ghost_draft.0 = Some(draft);
    }
    let room = view.ghosts.list.len() < MAX_GHOSTS;
    if ui
        .add_enabled(
            room,
            egui::Button::new(format!("Add ghost ({})", key_name(view.keys.ghost))),
        )
        .clicked()
    {
        actions.ghost_requests.write(GhostRequest::Add(draft));
    }
    for (i, ghost) in view.ghosts.list.iter().enumerate() {
        ui.horizontal(|ui| {
            ui.colored_label(ghost_colour32(ghost.colour), "◯");
            ui.label(ghost.spec.label());
            if ui.small_button("remove").clicked() {
                actions.ghost_requests.write(GhostRequest::Remove(i));
            }
        });
    }
    if let Some(refused) = &view.ghosts.refused {
        ui.colored_label(ERROR_RED, format!("Refused: {refused}."));
    }
}
