//! The selected bead's last seconds of drift, energy and λ: recorded each
//! step and plotted with labelled axes; and the last strikes between beads,
//! recorded for the panel's list.

use std::collections::VecDeque;

use bevy::math::DVec3;
use bevy::prelude::*;
use bevy_egui::egui;
use egui_plot::{Line, Plot, PlotPoints};

use crate::gui::drag::SelectedBead;
use crate::{BeadDiagnostics, BeadsStruck, Islands, SimClock};

/// One plotted sample of the selected bead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlotSample {
    /// Simulated time.
    pub t: f64,
    /// Drift `C`.
    pub c: f64,
    /// Energy.
    pub energy: f64,
    /// λ.
    pub lambda: f64,
}

/// The last seconds of the selected bead's diagnostics.
#[derive(Resource, Clone, Debug)]
pub struct PlotHistory {
    /// Seconds kept.
    pub seconds: f64,
    /// The samples, oldest first.
    pub samples: VecDeque<PlotSample>,
    bead: Option<Entity>,
}

impl Default for PlotHistory {
    fn default() -> Self {
        Self {
            seconds: 10.0,
            samples: VecDeque::new(),
            bead: None,
        }
    }
}

/// Appends the selected bead's diagnostics (in the plane or in space) to
/// the plot history; for a bead joined to others, the energy is its
/// island's (a rod does work on each of its beads, not on the two
/// together).
pub fn record_history(
    selected: Res<SelectedBead>,
    clock: Res<SimClock>,
    beads: Query<&BeadDiagnostics>,
    space_beads: Query<&BeadDiagnostics<DVec3>>,
    islands: Res<Islands>,
    space_islands: Res<Islands<DVec3>>,
    mut history: ResMut<PlotHistory>,
) {
    let Some(entity) = selected.0 else { return };
    let plane = beads.get(entity).ok().map(|d| (d.c, d.lambda, d.energy()));
    let space = || {
        let d = space_beads.get(entity).ok()?;
        Some((d.c, d.lambda, d.energy()))
    };
    let Some((c, lambda, own)) = plane.or_else(space) else {
        return;
    };
    let t = clock.time;
    if history.bead != Some(entity) || history.samples.back().is_some_and(|s| s.t > t) {
        history.samples.clear();
        history.bead = Some(entity);
    }
    let energy = islands
        .of(entity)
        .or_else(|| space_islands.of(entity))
        .filter(|island| island.rows > 0)
        .map_or(own, |island| island.energy);
    history.samples.push_back(PlotSample {
        t,
        c,
        energy,
        lambda,
    });
    let horizon = t - history.seconds;
    while history.samples.front().is_some_and(|s| s.t < horizon) {
        history.samples.pop_front();
    }
}

/// A plot of the last seconds with labelled axes: time in seconds, the
/// value (its unit is in the heading above) with tick labels in scientific
/// notation, so that a range of 1e-16 reads as rounding noise and not as a
/// swing.
fn plot(
    ui: &mut egui::Ui,
    id: &str,
    name: &str,
    points: impl Iterator<Item = [f64; 2]>,
    colour: egui::Color32,
) {
    Plot::new(id)
        .height(90.0)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .x_axis_label("t (s)")
        .y_axis_min_width(48.0)
        .y_axis_formatter(|mark, _| format!("{:.1e}", mark.value))
        .show(ui, |plot_ui| {
            plot_ui.line(Line::new(name, points.collect::<PlotPoints>()).color(colour));
        });
}

/// Plots of the selected bead's last seconds, each with its axes labelled.
pub(super) fn plots_section(ui: &mut egui::Ui, history: &PlotHistory) {
    ui.separator();
    let samples = &history.samples;
    for (id, label, unit, colour, value) in [
        (
            "plot-c",
            "drift C",
            "m",
            egui::Color32::LIGHT_BLUE,
            (|s: &PlotSample| s.c) as fn(&PlotSample) -> f64,
        ),
        ("plot-e", "energy E", "J", egui::Color32::LIGHT_GREEN, |s| {
            s.energy
        }),
        ("plot-l", "λ", "N", egui::Color32::GOLD, |s| s.lambda),
    ] {
        ui.label(format!("{label} ({unit})"));
        plot(
            ui,
            id,
            label,
            samples.iter().map(|s| [s.t, value(s)]),
            colour,
        );
    }
}

/// How many of the last strikes the panel lists.
const STRIKES_SHOWN: usize = 6;

/// The last strikes between beads, newest first, for the panel.
#[derive(Resource, Default)]
pub struct RecentStrikes(pub(super) VecDeque<BeadsStruck>);

/// A strike that leaves its pair in touch closing slower than this (m/s)
/// is a resting pair's, not listed: a pile trades such strikes every step.
const RESTING_CLOSING: f64 = 1e-3;

/// Keeps the last six strikes (leaving out resting pairs' closing slower
/// than 1 mm/s); forgets them when the run starts again (the clock went
/// back).
pub fn record_strikes(
    mut struck: MessageReader<BeadsStruck>,
    clock: Res<SimClock>,
    mut recent: ResMut<RecentStrikes>,
) {
    if recent.0.front().is_some_and(|s| s.time > clock.time) {
        recent.0.clear();
    }
    for strike in struck.read() {
        if strike.bounced || strike.closing_speed >= RESTING_CLOSING {
            recent.0.push_front(*strike);
        }
    }
    recent.0.truncate(STRIKES_SHOWN);
}
