//! The panel's window: the scene menu, the run buttons and what is pending,
//! diverged or refused, then the sections, and the keys below it all.

use bevy::prelude::*;
use bevy_egui::{EguiContexts, egui};

use super::constraints::{constraints_section, strikes_section};
use super::ghosts::ghosts_section;
use super::params::{Edit, bead_section, solver_section};
use super::phase::phase_section;
use super::plots::plots_section;
use super::space::space_bead_section;
use super::timeline::timeline_section;
use super::view::{ERROR_RED, PENDING_ORANGE, PanelActions, PanelView};
use crate::Restart;
use crate::controls::{ControlKeys, SPEEDS, key_name, speed_label};
use crate::preset::LoadPreset;

/// The panel: the scene and run state, the selected bead and its wire, the
/// solver's parameters and the plots, in a window that scrolls when it is
/// taller than the screen.
pub fn panel(
    mut contexts: EguiContexts,
    view: PanelView,
    mut actions: PanelActions,
    mut refused: Local<Option<String>>,
) -> Result {
    let ctx = contexts.ctx_mut()?;
    help_line(ctx, &view.keys);
    // The window scrolls its content within the screen's height, less the
    // title bar and the margins, so nothing is cut off at the bottom.
    let height = (ctx.content_rect().height() - 80.0).max(200.0);
    let mut outcome: Edit = None;
    egui::Window::new("wirebead")
        .anchor(egui::Align2::RIGHT_TOP, [-6.0, 6.0])
        .fixed_size([view.style.panel_width - 30.0, height])
        .resizable(false)
        .collapsible(true)
        .vscroll(true)
        .show(ctx, |ui| {
            scene_section(ui, &view, &mut actions, refused.as_deref());
            timeline_section(ui, &view, &mut actions);
            let bead = bead_section(ui, &view, &mut actions.commands).or(space_bead_section(
                ui,
                &view,
                &mut actions.commands,
            ));
            constraints_section(ui, &view);
            strikes_section(ui, &view);
            let solver = solver_section(ui, &mut actions.pending, view.active.in_space);
            outcome = solver.or(bead);
            ghosts_section(ui, &view, &mut actions);
            let plots = plots_section(ui, &view.history, &view.ghosts);
            let phase = phase_section(
                ui,
                &view.history,
                &mut actions.phase,
                &mut actions.phase_frame,
            );
            let shown = match (plots, phase) {
                (Some(a), Some(b)) => Some(a.union(b)),
                (a, b) => a.or(b),
            };
            let scale = ui.ctx().pixels_per_point();
            let shown =
                shown.map(|r| [r.left(), r.top(), r.right(), r.bottom()].map(|v| v * scale));
            if actions.plots_shown.0 != shown {
                actions.plots_shown.0 = shown;
            }
        });
    match outcome {
        Some(Ok(())) => *refused = None,
        Some(Err(error)) => {
            warn!("wirebead: edit refused: {error}; the previous value was kept");
            *refused = Some(error.to_string());
        }
        None => {}
    }
    Ok(())
}

/// The keys, at the bottom left of the window.
fn help_line(ctx: &egui::Context, keys: &ControlKeys) {
    egui::Area::new(egui::Id::new("wirebead-help"))
        .anchor(egui::Align2::LEFT_BOTTOM, [8.0, -8.0])
        .show(ctx, |ui| {
            let help = egui::RichText::new(keys.help()).color(egui::Color32::LIGHT_GRAY);
            ui.add(egui::Label::new(help).extend());
        });
}

/// The scene menu, its file error, the run buttons, and what is pending,
/// diverged or refused.
fn scene_section(
    ui: &mut egui::Ui,
    view: &PanelView,
    actions: &mut PanelActions,
    refused: Option<&str>,
) {
    ui.horizontal(|ui| {
        ui.label("Scene");
        let current = view.active.running.clone().unwrap_or_else(|| "—".into());
        egui::ComboBox::from_id_salt("preset")
            .selected_text(current)
            .show_ui(ui, |ui| {
                for (label, path) in &view.catalog.0 {
                    if ui
                        .selectable_label(view.active.path == *path, label)
                        .clicked()
                    {
                        actions.loads.write(LoadPreset(path.clone()));
                    }
                }
            });
    });
    if let Some(error) = &view.active.error {
        ui.colored_label(
            ERROR_RED,
            format!("Scene file {error}; the running scene was kept."),
        );
    }
    ui.horizontal(|ui| {
        if ui
            .button(format!("Restart ({:?})", view.keys.restart))
            .clicked()
        {
            actions.restarts.write(Restart);
        }
        let time = &mut actions.time;
        let pause = if time.is_paused() { "Resume" } else { "Pause" };
        if ui.button(pause).clicked() {
            if time.is_paused() {
                time.unpause();
            } else {
                time.pause();
            }
        }
        if ui
            .add_enabled(time.is_paused(), egui::Button::new("Step"))
            .clicked()
        {
            actions.steps.0 += 1;
        }
    });
    // Time: backwards, and slow motion.
    ui.horizontal(|ui| {
        let time = &mut actions.time;
        if ui
            .button(format!("Reverse ({})", key_name(view.keys.reverse)))
            .clicked()
        {
            actions.reversals.0 += 1;
        }
        let speed = time.relative_speed_f64();
        egui::ComboBox::from_id_salt("speed")
            .selected_text(format!("speed {}", speed_label(speed)))
            .show_ui(ui, |ui| {
                for s in SPEEDS.iter().rev() {
                    if ui
                        .selectable_label((s - speed).abs() < 1e-9, speed_label(*s))
                        .clicked()
                    {
                        time.set_relative_speed_f64(*s);
                    }
                }
            });
    });
    let edits_pending = actions.pending.get() != &*view.params
        || !view.pending_beads.is_empty()
        || !view.pending_wires.is_empty();
    if edits_pending {
        ui.colored_label(PENDING_ORANGE, "● Edits pending: press Space to apply");
    }
    let diverged = view.beads.iter().map(|(entity, .., d)| (entity, d));
    let in_space = view.space_beads.iter().map(|(entity, .., d)| (entity, d));
    for (entity, diverged) in diverged.chain(in_space) {
        if let Some(d) = diverged {
            ui.colored_label(
                ERROR_RED,
                format!(
                    "Bead {entity} diverged at t = {:.2} s: {}. Press Space to restart.",
                    d.time, d.reason
                ),
            );
        }
    }
    if let Some(message) = refused {
        ui.colored_label(ERROR_RED, format!("Refused: {message}"));
    }
}
