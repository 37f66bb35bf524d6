//! The panel's window: the scene menu, the run buttons and what is pending,
//! diverged or refused, then the sections, and the keys below it all.

use bevy::prelude::*;
use bevy_egui::{EguiContexts, egui};

use super::constraints::{constraints_section, strikes_section};
use super::ghosts::ghosts_section;
use super::params::{Edit, bead_menu, bead_section, solver_section};
use super::phase::phase_section;
use super::plots::plots_section;
use super::space::space_bead_section;
use super::timeline::timeline_section;
use super::view::{ERROR_RED, PENDING_ORANGE, PanelActions, PanelView};
use crate::Restart;
use crate::controls::{ControlKeys, SPEEDS, key_name, speed_label};
use crate::gui::drag::SelectedBead;
use crate::gui::render::PRESENTATION_ZOOM;
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
    // Presentation mode: larger text, and the plots in a column of their
    // own on the left (as in a window too short for them under the
    // panel's settings).
    let presenting = view.presentation.0;
    let zoom = if presenting { PRESENTATION_ZOOM } else { 1.0 };
    if ctx.zoom_factor() != zoom {
        ctx.set_zoom_factor(zoom);
    }
    let (width, height) = view
        .windows
        .iter()
        .next()
        .map_or((1280.0, 800.0), |w| (w.width(), w.height()));
    let (right, left) = view.style.side_widths(presenting, width, height);
    // The plots in a column of their own on the left, or in the panel.
    let beside = left > 0.0;
    help_line(ctx, &view.keys);
    // The window scrolls its content within the screen's height, less the
    // title bar and the margins, so nothing is cut off at the bottom.
    let column = (ctx.content_rect().height() - 80.0).max(200.0);
    let mut outcome: Edit = None;
    let mut plots_at = None;
    egui::Window::new("wirebead")
        .anchor(egui::Align2::RIGHT_TOP, [-6.0, 6.0])
        .fixed_size([right / zoom - 30.0, column])
        .resizable(false)
        .collapsible(true)
        .vscroll(true)
        .show(ctx, |ui| {
            scene_section(ui, &view, &mut actions, refused.as_deref());
            timeline_section(ui, &view, &mut actions);
            if let Some(bead) = bead_menu(ui, &view) {
                actions.commands.insert_resource(SelectedBead(Some(bead)));
            }
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
            if !beside {
                plots_at = plots_and_phase(ui, &view, &mut actions, false);
            }
        });
    // Drawn after the panel: Tab goes through the panel's controls first
    // (each plot's axes are stops of their own).
    if beside {
        egui::Window::new("plots")
            .anchor(egui::Align2::LEFT_TOP, [6.0, 6.0])
            .fixed_size([left / zoom - 30.0, column])
            .resizable(false)
            .collapsible(false)
            .vscroll(true)
            .show(ctx, |ui| {
                plots_at = plots_and_phase(ui, &view, &mut actions, presenting);
            });
    }
    if actions.plots_shown.0 != plots_at {
        actions.plots_shown.0 = plots_at;
    }
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

/// The plots and the phase plot, and where they show on screen (physical
/// pixels: left, top, right, bottom).
/// The phase plot comes first where `phase_first` (in presentation mode).
fn plots_and_phase(
    ui: &mut egui::Ui,
    view: &PanelView,
    actions: &mut PanelActions,
    phase_first: bool,
) -> Option<[f32; 4]> {
    let mut phase = |ui: &mut egui::Ui| {
        phase_section(
            ui,
            &view.history,
            &mut actions.phase,
            &mut actions.phase_frame,
        )
    };
    let (plots, phase) = if phase_first {
        let phase = phase(ui);
        (plots_section(ui, &view.history, &view.ghosts), phase)
    } else {
        let plots = plots_section(ui, &view.history, &view.ghosts);
        (plots, phase(ui))
    };
    let shown = match (plots, phase) {
        (Some(a), Some(b)) => Some(a.union(b)),
        (a, b) => a.or(b),
    };
    let scale = ui.ctx().pixels_per_point();
    shown.map(|r| [r.left(), r.top(), r.right(), r.bottom()].map(|v| v * scale))
}

/// The keys, at the bottom left of the window, over as many lines as the
/// window's width takes.
fn help_line(ctx: &egui::Context, keys: &ControlKeys) {
    let width = ctx.content_rect().width() - 16.0;
    egui::Area::new(egui::Id::new("wirebead-help"))
        .anchor(egui::Align2::LEFT_BOTTOM, [8.0, -8.0])
        .show(ctx, |ui| {
            let help = egui::RichText::new(keys.help()).color(egui::Color32::LIGHT_GRAY);
            ui.set_max_width(width);
            ui.add(egui::Label::new(help).wrap());
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
