//! The plots section of the panel: the selected bead's drift, energy, λ
//! and the force holding it on a circle over the last seconds, each
//! ghost's line beside the run's, and its energy now as bars.

use bevy_egui::egui;
use egui_plot::{
    AxisHints, Bar, BarChart, Legend, Line, LineStyle, PlotPoints, uniform_grid_spacer,
};

use super::axes::{grid_steps, log_magnitude, panel_plot};
use super::{HeldBy, PlotHistory, PlotSample};
use crate::ghost::{GhostSample, Ghosts};
use crate::gui::ghost::ghost_colour32;

/// A plot of the last seconds with labelled axes: time in seconds, the
/// value (its unit is in the heading above) with tick labels that tell
/// neighbouring ticks apart at any scale
/// ([`tick_label`](super::axes::tick_label)), so that a range of 1e-16
/// reads as rounding noise and not as a swing. On a log scale the points
/// are `log10 |value|` and the ticks whole decades
/// ([`decade_label`](super::axes::decade_label)).
fn plot(ui: &mut egui::Ui, id: &str, lines: Vec<PlotLine>, log: bool) {
    let legend = lines.len() > 1;
    let plot = panel_plot(id, PLOT_HEIGHT, log)
        .x_axis_label("t (s)")
        .x_grid_spacer(uniform_grid_spacer(|input| grid_steps(input.bounds, false)));
    let plot = if legend {
        plot.legend(Legend::default())
    } else {
        plot
    };
    // On a log scale, whole decades at both ends: a range within one
    // decade still has a labelled tick.
    let (low, high) = lines
        .iter()
        .flat_map(|line| &line.points)
        .map(|&[_, v]| log_magnitude(v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    let plot = if log && low.is_finite() && high.is_finite() {
        plot.include_y(low.floor())
            .include_y(high.ceil().max(low.floor() + 1.0))
    } else {
        plot
    };
    plot.show(ui, |plot_ui| {
        for PlotLine {
            name,
            points,
            colour,
            dashed,
        } in lines
        {
            let points: PlotPoints = if log {
                points.iter().map(|&[t, v]| [t, log_magnitude(v)]).collect()
            } else {
                points.into()
            };
            let line = Line::new(name, points).color(colour);
            plot_ui.line(if dashed {
                line.style(LineStyle::dashed_loose())
            } else {
                line
            });
        }
    });
}

/// One line of a [`plot`]: its name (in the legend where there are
/// several), its points `[t, value]`, its colour and whether it is dashed.
struct PlotLine {
    name: String,
    points: Vec<[f64; 2]>,
    colour: egui::Color32,
    dashed: bool,
}

impl PlotLine {
    /// A solid line.
    fn solid(name: impl Into<String>, points: Vec<[f64; 2]>, colour: egui::Color32) -> Self {
        Self {
            name: name.into(),
            points,
            colour,
            dashed: false,
        }
    }
}

/// How tall a plot is (points): room for three or four labelled ticks.
const PLOT_HEIGHT: f32 = 110.0;

/// Plots of the selected bead's last seconds, each with its axes labelled:
/// a section that folds away.
///
/// Returns the part of the section's body on screen, if any shows.
pub(in crate::gui::panel) fn plots_section(
    ui: &mut egui::Ui,
    history: &PlotHistory,
    ghosts: &Ghosts,
) -> Option<egui::Rect> {
    ui.separator();
    let body = egui::CollapsingHeader::new("Plots")
        .default_open(true)
        .show(ui, |ui| plots(ui, history, ghosts))
        .body_response?;
    shown(ui, body.rect)
}

/// The part of `rect` the panel shows (within its scrolled view), if any.
pub(in crate::gui::panel) fn shown(ui: &egui::Ui, rect: egui::Rect) -> Option<egui::Rect> {
    let visible = rect.intersect(ui.clip_rect());
    (visible.width() > 1.0 && visible.height() > 1.0).then_some(visible)
}

/// The plots of [`plots_section`].
fn plots(ui: &mut egui::Ui, history: &PlotHistory, ghosts: &Ghosts) {
    let samples = &history.samples;
    // Each ghost's line beside the run's, in the ghost's colour.
    let ghost_lines = |value: fn(&GhostSample) -> f64| -> Vec<PlotLine> {
        ghosts
            .list
            .iter()
            .map(|ghost| {
                let points = ghost.samples.iter().map(|s| [s.t, value(s)]).collect();
                PlotLine::solid(
                    format!("ghost: {}", ghost.spec.label()),
                    points,
                    ghost_colour32(ghost.colour),
                )
            })
            .collect()
    };
    let held_by = samples.back().map_or(HeldBy::Wire, |s| s.held_by);
    let (drift, note) = match held_by {
        HeldBy::Wire => (Some("drift |C|"), None),
        HeldBy::Links => (
            Some("drift, largest |C| of its rods and pins"),
            Some("It rides no wire: no λ of its own (each rod's is under Constraints)."),
        ),
        HeldBy::Nothing => (
            None,
            Some("A free bead: no wire, rod or pin, so no drift C or λ."),
        ),
    };
    if let Some(note) = note {
        ui.label(note);
    }
    let lines: [(
        &str,
        Option<&str>,
        &str,
        egui::Color32,
        fn(&PlotSample) -> f64,
        bool,
    ); 3] = [
        (
            "plot-c",
            drift,
            "m, log scale",
            egui::Color32::LIGHT_BLUE,
            |s| s.c,
            true,
        ),
        (
            "plot-e",
            Some("energy E of the scene"),
            "J",
            egui::Color32::LIGHT_GREEN,
            |s| s.scene_energy,
            false,
        ),
        (
            "plot-l",
            (held_by == HeldBy::Wire).then_some("λ"),
            "N",
            egui::Color32::GOLD,
            |s| s.lambda,
            false,
        ),
    ];
    for (id, label, unit, colour, value, log) in lines {
        let Some(label) = label else { continue };
        ui.label(format!("{label} ({unit})"));
        let points = samples.iter().map(|s| [s.t, value(s)]).collect();
        let mut lines = vec![PlotLine::solid(label, points, colour)];
        match id {
            "plot-c" => lines.extend(ghost_lines(|s| s.c)),
            "plot-e" => {
                if samples.back().is_some_and(|s| s.own_energy) {
                    let own = samples.iter().map(|s| [s.t, s.energy]).collect();
                    lines.push(PlotLine::solid("the bead's own", own, egui::Color32::KHAKI));
                }
                lines.extend(ghost_lines(|s| s.energy));
            }
            _ => {}
        }
        plot(ui, id, lines, log);
    }
    // On a circle: the force that holds the bead, against energy kept.
    let held: Vec<(f64, (f64, f64))> = samples
        .iter()
        .filter_map(|s| Some((s.t, s.normal_force?)))
        .collect();
    if !held.is_empty() {
        ui.label("force toward the centre (N), and from energy kept:");
        ui.label("m(R ω0² + g(3 cos θ − 2 cos θ0))");
        let simulated = held.iter().map(|&(t, (n, _))| [t, n]).collect();
        let kept = held.iter().map(|&(t, (_, n))| [t, n]).collect();
        let lines = vec![
            PlotLine::solid("simulated", simulated, egui::Color32::GOLD),
            PlotLine {
                name: "energy kept".to_owned(),
                points: kept,
                colour: egui::Color32::GRAY,
                dashed: true,
            },
        ];
        plot(ui, "plot-n", lines, false);
    }
    if let (Some(first), Some(last)) = (samples.front(), samples.back()) {
        energy_bars(ui, first, last);
    }
}

/// The selected bead's energy now as bars: kinetic, potential and their
/// sum, and how much the scene's energy changed over the plotted seconds:
/// what drift, damping, friction, inelastic strikes or a drag added (up)
/// or removed (down).
fn energy_bars(ui: &mut egui::Ui, first: &PlotSample, last: &PlotSample) {
    let bars = [
        ("kinetic", last.kinetic, egui::Color32::LIGHT_BLUE),
        ("potential", last.potential, egui::Color32::LIGHT_GREEN),
        ("total", last.kinetic + last.potential, egui::Color32::WHITE),
        (
            "change",
            last.scene_energy - first.scene_energy,
            egui::Color32::LIGHT_RED,
        ),
    ];
    ui.label(format!(
        "energy now (J); the scene's change over the last {:.1} s",
        last.t - first.t
    ));
    let chart = BarChart::new(
        "energy",
        bars.iter()
            .enumerate()
            .map(|(k, &(name, value, colour))| {
                Bar::new(k as f64, value).name(name).fill(colour).width(0.6)
            })
            .collect(),
    );
    panel_plot("plot-energy-bars", PLOT_HEIGHT, false)
        .x_grid_spacer(uniform_grid_spacer(|_| [1.0, 1.0, 10.0]))
        .custom_x_axes(vec![
            AxisHints::new_x()
                .label_spacing(20.0..=30.0)
                .formatter(move |mark, _| {
                    let k = mark.value.round();
                    match bars.get(k as usize) {
                        Some(bar) if (mark.value - k).abs() < 1e-9 && k >= 0.0 => bar.0.to_owned(),
                        _ => String::new(),
                    }
                }),
        ])
        .show(ui, |plot_ui| plot_ui.bar_chart(chart));
}
