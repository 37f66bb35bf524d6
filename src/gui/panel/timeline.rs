//! The panel's timeline: the recorded history, a slider to scrub it, a step
//! back and forward, how long a history to keep, and whether the run taken
//! on from a step back is still the recorded one.

use bevy_egui::egui;

use super::keyboard::number_field;
use super::view::{ERROR_RED, PENDING_ORANGE, PanelActions, PanelView};
use crate::controls::key_name;
use crate::plugin::TimelineSeek;

const SAME_GREEN: egui::Color32 = egui::Color32::from_rgb(120, 220, 120);

/// The timeline section, open by default.
pub(super) fn timeline_section(ui: &mut egui::Ui, view: &PanelView, actions: &mut PanelActions) {
    ui.separator();
    egui::CollapsingHeader::new("Timeline")
        .default_open(true)
        .show(ui, |ui| timeline(ui, view, actions));
}

fn timeline(ui: &mut egui::Ui, view: &PanelView, actions: &mut PanelActions) {
    let Some((first, last)) = actions.timeline.span() else {
        ui.label("Nothing recorded yet: the history starts with the first step.");
        return;
    };
    let now = view.clock.steps;
    ui.horizontal(|ui| {
        if ui
            .add_enabled(
                now > first.steps,
                egui::Button::new(format!("◀ Back ({})", key_name(view.keys.back))),
            )
            .clicked()
        {
            actions.seeks.write(TimelineSeek::Back);
        }
        if ui
            .button(format!("Step ({}) ▶", key_name(view.keys.step)))
            .clicked()
        {
            actions.time.pause();
            actions.steps.0 += 1;
        }
        let mut step = now.clamp(first.steps, last.steps);
        let slider = egui::Slider::new(&mut step, first.steps..=last.steps)
            .show_value(false)
            .text("scrub");
        if ui.add_enabled(last.steps > first.steps, slider).changed() {
            actions.seeks.write(TimelineSeek::To(step));
        }
    });
    let timestep = view.params.timestep;
    ui.label(format!(
        "At step {now} (t = {:.4} s). Recorded: {:.3} s to {:.3} s, {} steps, {:.1} MB.",
        view.clock.time,
        first.time,
        last.time,
        last.steps - first.steps,
        actions.timeline.bytes() as f64 / 1e6
    ));
    ui.horizontal(|ui| {
        ui.label("Keep the last");
        let seconds = &mut actions.timeline.seconds;
        number_field(ui, seconds, "seconds kept", |d| {
            d.range(timestep..=3600.0).speed(1.0).suffix(" s")
        });
        ui.label(format!(
            "(up to {:.0} MB)",
            actions.timeline.max_bytes as f64 / 1e6
        ));
    });
    data_out(ui, view, actions);
    let timeline = &actions.timeline;
    if let Some(step) = timeline.departed() {
        ui.colored_label(
            PENDING_ORANGE,
            format!(
                "Run again from the step back, the run changed at step {step} (an edit or the drag): the recording after it was replaced."
            ),
        );
    } else if timeline.matched() > 0 {
        ui.colored_label(
            SAME_GREEN,
            format!(
                "Run again from the step back: {} steps the same as recorded, bit for bit.",
                timeline.matched()
            ),
        );
    } else if let Some(at) = timeline.at() {
        ui.label(format!(
            "{} steps back from the newest. Step or resume to run on from here.",
            last.steps - at.steps
        ));
    }
}

/// The run as CSV and the scene as a file, and what the last export wrote.
fn data_out(ui: &mut egui::Ui, view: &PanelView, actions: &mut PanelActions) {
    ui.horizontal(|ui| {
        if ui
            .button(format!("Export CSV ({})", key_name(view.keys.export_csv)))
            .on_hover_text("The recorded run, as simulate --scene writes it")
            .clicked()
        {
            actions.exports.csv += 1;
        }
        if ui
            .button(format!("Save scene ({})", key_name(view.keys.save_scene)))
            .on_hover_text("The scene with its edits, applied and pending, as a scene file")
            .clicked()
        {
            actions.exports.scene += 1;
        }
        if ui
            .button(format!("Plots PNG ({})", key_name(view.keys.save_plots)))
            .on_hover_text("The plots and the phase plot, as shown")
            .clicked()
        {
            actions.exports.plots += 1;
        }
    });
    match &view.last_export.0 {
        Some(Ok(message)) => {
            ui.label(format!("Exports: {message}."));
        }
        Some(Err(message)) => {
            ui.colored_label(ERROR_RED, format!("Export: {message}."));
        }
        None => {}
    }
}
