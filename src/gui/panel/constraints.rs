//! The list of rods and pins with each one's drift and multiplier, and
//! the last strikes between beads that touch and of beads on bodies
//! (recorded in `plots`).

use bevy_egui::egui;

use super::view::PanelView;
use crate::ConstraintDiagnostics;

/// The last strikes: which beads (or bead and body), when, how fast they closed, the impulse
/// (and the friction impulse, where a strike rubbed) and whether they
/// bounced apart or stayed in touch.
pub(super) fn strikes_section(ui: &mut egui::Ui, view: &PanelView) {
    if view.strikes.0.is_empty() {
        return;
    }
    let rubbed = view.strikes.0.iter().any(|s| s.friction_impulse > 0.0);
    ui.separator();
    egui::CollapsingHeader::new("Strikes")
        .default_open(true)
        .show(ui, |ui| {
            egui::Grid::new("strikes")
                .num_columns(if rubbed { 5 } else { 4 })
                .striped(true)
                .show(ui, |ui| {
                    ui.strong("");
                    ui.strong("t (s)");
                    ui.strong("closing (m/s)");
                    ui.strong("impulse (N s)");
                    if rubbed {
                        ui.strong("friction (N s)");
                    }
                    ui.end_row();
                    for s in &view.strikes.0 {
                        let how = if s.bounced { "bounced" } else { "stayed" };
                        ui.label(format!("{}–{} {how}", view.name(s.a), view.name(s.b)));
                        ui.monospace(format!("{:.4}", s.time));
                        ui.monospace(format!("{:.4}", s.closing_speed));
                        ui.monospace(format!("{:.4}", s.impulse));
                        if rubbed {
                            ui.monospace(format!("{:.4}", s.friction_impulse));
                        }
                        ui.end_row();
                    }
                });
        });
}

/// How many rods and pins the panel's list shows before it scrolls.
const CONSTRAINT_ROWS_SHOWN: f32 = 6.0;

/// Every rod and pin with its drift `C` and multiplier λ (a rod under
/// tension pulls: λ < 0), under a line naming the largest drift: a list
/// that scrolls past six rows, so a rope's rods leave room for the rest.
pub(super) fn constraints_section(ui: &mut egui::Ui, view: &PanelView) {
    if view.rods.is_empty() && view.pins.is_empty() {
        return;
    }
    let rows: Vec<(String, &ConstraintDiagnostics)> = view
        .rods
        .iter()
        .map(|(rod, d)| {
            let [a, b] = rod.beads().map(|e| view.name(e));
            (format!("rod {a}–{b}"), d)
        })
        .chain(
            view.pins
                .iter()
                .map(|(pin, d)| (format!("pin {}", view.name(pin.bead())), d)),
        )
        .collect();
    ui.separator();
    egui::CollapsingHeader::new(format!("Constraints ({})", rows.len()))
        .id_salt("constraints")
        .default_open(true)
        .show(ui, |ui| {
            if let Some((label, d)) = rows
                .iter()
                .max_by(|a, b| a.1.c.abs().total_cmp(&b.1.c.abs()))
            {
                ui.label(format!("largest drift: |C| = {:.2e} m, {label}", d.c.abs()));
            }
            let row_height =
                ui.text_style_height(&egui::TextStyle::Monospace) + ui.spacing().item_spacing.y;
            egui::ScrollArea::vertical()
                .id_salt("constraint-rows")
                .max_height(row_height * (CONSTRAINT_ROWS_SHOWN + 1.0))
                .show(ui, |ui| {
                    egui::Grid::new("constraints")
                        .num_columns(3)
                        .striped(true)
                        .show(ui, |ui| {
                            ui.strong("");
                            ui.strong("C");
                            ui.strong("λ");
                            ui.end_row();
                            for (label, d) in &rows {
                                ui.label(label);
                                ui.monospace(format!("{:+.2e}", d.c));
                                ui.monospace(format!("{:+.3e}", d.lambda));
                                ui.end_row();
                            }
                        });
                });
        });
}
