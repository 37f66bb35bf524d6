//! The selected bead's last seconds of drift, energy and λ: recorded each
//! step and plotted with labelled axes; and the last strikes between beads,
//! recorded for the panel's list.

use std::collections::VecDeque;

use bevy::math::DVec3;
use bevy::prelude::*;
use bevy_egui::egui;
use egui_plot::{
    AxisHints, Bar, BarChart, Legend, Line, LineStyle, Plot, PlotPoints, uniform_grid_spacer,
};

use crate::geometry::Coordinates;
use crate::geometry::{ImplicitCurve, Placed};
use crate::ghost::{GhostSample, Ghosts};
use crate::gui::drag::SelectedBead;
use crate::gui::ghost::ghost_colour32;
use crate::plugin::SceneEnergy;
use crate::reference::{AlongWire, along_wire, circle_angle, circle_normal_force};
use crate::{
    BeadDiagnostics, BeadParams, BeadPosition, BeadVelocity, BeadsStruck, Islands, OnWire,
    SimClock, SimParams, Wire, WireShape, pose_of,
};

/// What holds a plotted bead, and so what its drift `C` and λ are.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum HeldBy {
    /// Its wire: `C`, `Ċ` and λ are its wire's.
    #[default]
    Wire,
    /// Rods or pins only, no wire: `C` is the largest drift of its island
    /// ([`IslandReport::drift`](crate::IslandReport::drift)); it has no
    /// λ of its own (the panel lists each rod's).
    Links,
    /// Nothing: a free bead has no `C` or λ.
    Nothing,
}

impl HeldBy {
    /// A bead's hold as its wire says: [`HeldBy::Wire`] on one, else
    /// [`HeldBy::Nothing`] until its island says it is joined to others.
    fn on(wire: Option<&OnWire>) -> Self {
        if wire.is_some() {
            Self::Wire
        } else {
            Self::Nothing
        }
    }
}

/// One plotted sample of the selected bead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlotSample {
    /// Simulated time.
    pub t: f64,
    /// What holds the bead ([`HeldBy`]).
    pub held_by: HeldBy,
    /// Drift `C`: its wire's, or its island's largest.
    pub c: f64,
    /// Its rate `Ċ`.
    pub c_dot: f64,
    /// The bead's own energy, kinetic plus gravitational.
    pub energy: f64,
    /// Whether the bead's own energy is worth a line of its own beside
    /// the scene's: it is joined to no other bead by a rod, pin or
    /// contact, and the scene holds more than it.
    pub own_energy: bool,
    /// The scene's energy ([`SceneEnergy`]): what changes only by
    /// damping, friction, inelastic strikes, drift and a drag.
    pub scene_energy: f64,
    /// λ.
    pub lambda: f64,
    /// Where the bead was (`z` zero in the plane).
    pub position: DVec3,
    /// How fast it moved.
    pub velocity: DVec3,
    /// On a circle in the plane: the angle from its lowest point and its
    /// rate ([`circle_angle`](crate::reference::circle_angle)).
    pub on_circle: Option<(f64, f64)>,
    /// On a wire in the plane: how far along it the bead has come since
    /// the plot began, and how fast ([`along_wire`]).
    pub along: Option<AlongWire>,
    /// The bead's own kinetic energy `½ m |v|²`.
    pub kinetic: f64,
    /// Its own potential energy `−m g·x`.
    pub potential: f64,
    /// On a circle in the plane: the force holding the bead toward the
    /// centre, as simulated and as energy kept from its start says
    /// ([`circle_normal_force`](crate::reference::circle_normal_force)).
    pub normal_force: Option<(f64, f64)>,
}

impl PlotSample {
    /// A sample at time `t` of a bead's diagnostics `d`, at rest at the
    /// origin and on no circle until told where it is.
    fn of<V: Coordinates>(t: f64, d: &BeadDiagnostics<V>) -> Self {
        Self {
            t,
            held_by: HeldBy::Wire,
            c: d.c,
            c_dot: d.c_dot,
            energy: d.energy(),
            own_energy: false,
            scene_energy: d.energy(),
            lambda: d.lambda,
            position: DVec3::ZERO,
            velocity: DVec3::ZERO,
            on_circle: None,
            along: None,
            kinetic: d.kinetic,
            potential: d.potential,
            normal_force: None,
        }
    }
}

/// The last seconds of the selected bead's diagnostics.
#[derive(Resource, Clone, Debug)]
pub struct PlotHistory {
    /// Seconds kept.
    pub seconds: f64,
    /// The samples, oldest first.
    pub samples: VecDeque<PlotSample>,
    /// Where the bead rides a circle in the plane: the size of gravity and
    /// the circle's radius (for the pendulum's separatrix).
    pub circle: Option<(f64, f64)>,
    bead: Option<Entity>,
}

impl PlotHistory {
    /// The bead plotted.
    pub fn bead(&self) -> Option<Entity> {
        self.bead
    }
}

impl Default for PlotHistory {
    fn default() -> Self {
        Self {
            seconds: 10.0,
            samples: VecDeque::new(),
            circle: None,
            bead: None,
        }
    }
}

/// What [`record_history`] reads of a bead in the plane: its state, its
/// diagnostics and its wire.
type PlaneBead = (
    &'static BeadPosition,
    &'static BeadVelocity,
    &'static BeadDiagnostics,
    &'static BeadParams,
    Option<&'static OnWire>,
);

/// What [`record_history`] reads of a bead in space.
type SpaceBeadRead = (
    &'static BeadPosition<DVec3>,
    &'static BeadVelocity<DVec3>,
    &'static BeadDiagnostics<DVec3>,
    Option<&'static OnWire>,
);

/// Appends the selected bead's diagnostics (in the plane or in space) to
/// the plot history, with the scene's energy ([`SceneEnergy`]): an
/// island's own jumps as contacts join and part its beads, and a rod does
/// work on each of its beads, not on the two together, so the bead's own
/// is kept only for a bead joined to nothing.
#[allow(clippy::too_many_arguments)]
pub fn record_history(
    selected: Res<SelectedBead>,
    clock: Res<SimClock>,
    params: Res<SimParams>,
    beads: Query<PlaneBead>,
    space_beads: Query<SpaceBeadRead>,
    wires: Query<(&Wire, &Transform)>,
    islands: Res<Islands>,
    space_islands: Res<Islands<DVec3>>,
    scene_energy: Option<Res<SceneEnergy>>,
    mut history: ResMut<PlotHistory>,
) {
    let Some(entity) = selected.0 else { return };
    let g = params.gravity;
    let plane = beads.get(entity).ok().map(|(x, v, d, start, on)| {
        // Its wire's shape and pose, looked up once.
        let wire = on.and_then(|on| {
            let (wire, transform) = wires.get(on.0).ok()?;
            Some((wire.shape(), pose_of(transform).ok()?))
        });
        // On a circle: its centre and radius.
        let circle = wire.and_then(|(shape, pose)| match shape {
            WireShape::Circle(c) => Some((pose.origin, c.radius)),
            _ => None,
        });
        let on_circle = circle.and_then(|(centre, _)| circle_angle(centre, g, x.0, v.0));
        let normal_force = circle
            .zip(on_circle)
            .and_then(|((centre, radius), (theta, _))| {
                let from = circle_angle(centre, g, start.initial_position, start.initial_velocity)?;
                let inward = (centre - x.0).try_normalize()?;
                let expected = circle_normal_force(start.mass, g.length(), radius, from, theta);
                Some((d.constraint_force.dot(inward), expected))
            });
        // The wire's normal where the bead is, for how far along it is.
        let normal = wire.map(|(shape, pose)| {
            let curve = shape.curve();
            Placed { curve, pose }.gradient(x.0)
        });
        let sample = PlotSample {
            held_by: HeldBy::on(on),
            position: x.0.extend(0.0),
            velocity: v.0.extend(0.0),
            on_circle,
            normal_force,
            ..PlotSample::of(clock.time, d)
        };
        (sample, circle.map(|c| c.1), normal)
    });
    let space = || {
        let (x, v, d, on) = space_beads.get(entity).ok()?;
        let sample = PlotSample {
            held_by: HeldBy::on(on),
            position: x.0,
            velocity: v.0,
            ..PlotSample::of(clock.time, d)
        };
        Some((sample, None, None))
    };
    let Some((mut sample, radius, normal)) = plane.or_else(space) else {
        return;
    };
    history.circle = radius.map(|r| (g.length(), r));
    let t = clock.time;
    if history.bead != Some(entity) {
        history.samples.clear();
        history.bead = Some(entity);
    }
    // Back at an earlier time (a restart, a step back): the plots go on
    // from there.
    while history.samples.back().is_some_and(|s| s.t >= t) {
        history.samples.pop_back();
    }
    if let Some(normal) = normal {
        let previous = history.samples.back().and_then(|s| s.along);
        let (x, v) = (sample.position.truncate(), sample.velocity.truncate());
        sample.along = along_wire(previous.as_ref(), x, v, normal);
    }
    let joined = islands
        .of(entity)
        .or_else(|| space_islands.of(entity))
        .filter(|island| island.rows > 0);
    if let Some(island) = joined {
        // A bead held by rods or pins alone: its island's drift.
        if sample.held_by == HeldBy::Nothing {
            sample.held_by = HeldBy::Links;
            sample.c = island.drift;
        }
    }
    // Measured at this time: a sample taken before the first step of a
    // restarted run has the bead's own.
    if let Some(scene) = scene_energy.filter(|e| e.time == t) {
        sample.scene_energy = scene.total;
        let apart = (scene.total - sample.energy).abs() > 1e-12 * scene.total.abs().max(1.0);
        sample.own_energy = joined.is_none() && apart;
    }
    history.samples.push_back(sample);
    let horizon = t - history.seconds;
    while history.samples.front().is_some_and(|s| s.t < horizon) {
        history.samples.pop_front();
    }
}

/// The part of the window the panel's plots and phase plot show in, in
/// physical pixels (left, top, right, bottom): what a PNG of the plots
/// holds. None while they are folded away or scrolled out of view.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct PlotsShown(pub Option<[f32; 4]>);

/// A plot of the last seconds with labelled axes: time in seconds, the
/// value (its unit is in the heading above) with tick labels that tell
/// neighbouring ticks apart at any scale ([`tick_label`]), so that a range
/// of 1e-16 reads as rounding noise and not as a swing. On a log scale
/// the points are `log10 |value|` and the ticks whole decades
/// ([`decade_label`]).
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

/// A plot of the panel, `height` points tall and fixed (no drag, zoom or
/// scroll, and no stop for the keyboard's Tab), its value axis with room for its labels, stepped by
/// [`grid_steps`] and labelled by [`tick_label`], or on a log scale in
/// whole decades ([`decade_label`]).
pub(super) fn panel_plot(id: &str, height: f32, log: bool) -> Plot<'static> {
    Plot::new(id)
        .height(height)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .allow_axis_zoom_drag(false)
        .sense(egui::Sense::hover())
        .y_axis_min_width(48.0)
        .y_grid_spacer(uniform_grid_spacer(move |input| {
            grid_steps(input.bounds, log)
        }))
        .y_axis_formatter(move |mark, _| {
            if log {
                decade_label(mark.value)
            } else {
                tick_label(mark.value, mark.step_size)
            }
        })
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

/// How many labelled ticks a plot's value axis aims at.
const LABELLED_TICKS: f64 = 3.5;

/// The three steps of a value axis's grid over `bounds`, finest first:
/// the middle one a 1, 2 or 5 times a power of ten that puts about
/// [`LABELLED_TICKS`] labelled ticks on the axis, a fifth (a quarter for
/// a 2) of it between them, and ten of it. On a log scale (decades) the
/// steps are whole decades.
pub fn grid_steps(bounds: (f64, f64), log: bool) -> [f64; 3] {
    let span = bounds.1 - bounds.0;
    let wanted = if span.is_finite() && span > 0.0 {
        span / LABELLED_TICKS
    } else {
        1.0
    };
    let decade = 10f64.powf(wanted.log10().floor());
    let (step, fine) = [(1.0, 5.0), (2.0, 4.0), (5.0, 5.0), (10.0, 5.0)]
        .into_iter()
        .map(|(m, parts)| (m * decade, parts))
        .find(|&(step, _)| step >= wanted)
        .unwrap_or((10.0 * decade, 5.0));
    if log {
        let step = step.max(1.0).round();
        return [1.0f64.min(step), step, 10.0 * step];
    }
    [step / fine, step, 10.0 * step]
}

/// The smallest magnitude a log scale shows: a drift of exactly zero is
/// drawn here, below every drift rounding leaves.
const LOG_FLOOR: f64 = 1e-20;

/// `log10 |value|`, from [`LOG_FLOOR`] up.
pub fn log_magnitude(value: f64) -> f64 {
    value.abs().max(LOG_FLOOR).log10()
}

/// The label of a tick at `exponent` on a log scale: `1e-16` at a whole
/// decade, none between.
pub fn decade_label(exponent: f64) -> String {
    let whole = exponent.round();
    if (exponent - whole).abs() > 1e-9 {
        return String::new();
    }
    format!("1e{}", whole as i64)
}

/// The label of an axis tick at `value`, ticks `step` apart: plain
/// decimals (`69.25`, `150`) for values from 1e-3 to 1e5 that need no more
/// than six decimals, else scientific notation (`1.4e-16`), each with just
/// the digits that tell it from the next tick; `0` for a tick within a
/// millionth of a step of zero.
pub fn tick_label(value: f64, step: f64) -> String {
    if !value.is_finite() {
        return format!("{value}");
    }
    let step = step.abs();
    if value == 0.0 || (step > 0.0 && value.abs() < 1e-6 * step) {
        return "0".to_owned();
    }
    // The decade of the step's last digit, and of the value's first.
    let last = if step > 0.0 && step.is_finite() {
        step.log10().floor() as i32
    } else {
        value.abs().log10().floor() as i32 - 2
    };
    let first = value.abs().log10().floor() as i32;
    let decimals = (-last).max(0);
    if (1e-3..1e5).contains(&value.abs()) && decimals <= 6 {
        format!("{value:.*}", decimals as usize)
    } else {
        format!("{value:.*e}", (first - last).clamp(0, 15) as usize)
    }
}

/// Plots of the selected bead's last seconds, each with its axes labelled:
/// a section that folds away.
///
/// Returns the part of the section's body on screen, if any shows.
pub(super) fn plots_section(
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
pub(super) fn shown(ui: &egui::Ui, rect: egui::Rect) -> Option<egui::Rect> {
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

#[cfg(test)]
mod tests {
    use super::{decade_label, grid_steps, log_magnitude, tick_label};

    #[test]
    fn tick_labels_read_at_every_scale() {
        assert_eq!(tick_label(69.25, 0.05), "69.25");
        assert_eq!(tick_label(69.5, 0.5), "69.5");
        assert_eq!(tick_label(150.0, 50.0), "150");
        assert_eq!(tick_label(1.4e-16, 2e-17), "1.4e-16");
        assert_eq!(tick_label(-3e-16, 1e-16), "-3e-16");
        assert_eq!(tick_label(2.5e6, 5e5), "2.5e6");
        assert_eq!(tick_label(0.0, 1e-16), "0");
        assert_eq!(tick_label(1e-25, 1e-16), "0");
    }

    /// The labelled step puts two to four ticks on any span (never closer
    /// than a plot's height allows labels), and their labels tell them
    /// apart.
    #[test]
    fn grid_steps_put_a_few_readable_ticks_on_any_span() {
        for (low, high) in [
            (3.6, 3.7),
            (68.9, 69.4),
            (-1e-16, 3e-16),
            (0.0, 1e2),
            (-5.0, 12.0),
            (1e6, 1.3e6),
        ] {
            let [fine, step, coarse] = grid_steps((low, high), false);
            let first = (low / step).ceil();
            let ticks = (high / step).floor() - first + 1.0;
            assert!(
                (2.0..=4.0).contains(&ticks),
                "{ticks} ticks of {step:e} on [{low}, {high}]"
            );
            assert!(fine < step && step < coarse);
            let labels: Vec<String> = (0..ticks as i64)
                .map(|k| tick_label((first + k as f64) * step, step))
                .collect();
            for pair in labels.windows(2) {
                assert_ne!(pair[0], pair[1], "on [{low}, {high}]");
            }
        }
        assert_eq!(grid_steps((-16.0, -2.0), true)[1], 5.0);
        assert_eq!(grid_steps((-3.0, -2.5), true)[1], 1.0);
        assert!(grid_steps((1.0, 1.0), false)[1].is_finite());
    }

    #[test]
    fn a_log_scale_reads_in_whole_decades() {
        assert_eq!(log_magnitude(-3e-16), 3e-16f64.log10());
        assert_eq!(log_magnitude(0.0), -20.0);
        assert_eq!(decade_label(-16.0), "1e-16");
        assert_eq!(decade_label(2.0), "1e2");
        assert_eq!(decade_label(-15.5), "");
    }

    /// Neighbouring ticks never share a label, and each label reads back
    /// within a tenth of a step of its tick, from steps of 1e-17 to 1e6
    /// and ticks far from zero.
    #[test]
    fn neighbouring_ticks_have_labels_that_tell_them_apart() {
        for exponent in -17..=6 {
            for mantissa in [1.0, 2.0, 5.0] {
                let step = mantissa * 10f64.powi(exponent);
                for offset in [0.0, 7.0, 1234.0, -40.0, 1e6] {
                    let ticks: Vec<f64> = (0..6).map(|k| (offset + k as f64) * step).collect();
                    let labels: Vec<String> = ticks.iter().map(|&t| tick_label(t, step)).collect();
                    for (pair, ticks) in labels.windows(2).zip(ticks.windows(2)) {
                        assert_ne!(pair[0], pair[1], "ticks {ticks:?} at step {step:e}");
                    }
                    for (label, &tick) in labels.iter().zip(&ticks) {
                        let read: f64 = label.parse().expect("a number");
                        assert!(
                            (read - tick).abs() <= 0.1 * step,
                            "{label} for {tick:e} at step {step:e}"
                        );
                    }
                }
            }
        }
    }
}
