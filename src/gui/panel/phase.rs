//! A plot of any two of the selected bead's recorded quantities against
//! each other: its phase portrait (on a circle `(θ, θ̇)`, with the
//! pendulum's separatrix), its path `(x, y)`, or any of them against time.

#[cfg(test)]
use bevy::math::DVec3;
use bevy::prelude::*;
use bevy_egui::egui;
use egui_plot::{Legend, Line, LineStyle, PlotPoints, Points, uniform_grid_spacer};

use super::plots::{PlotHistory, PlotSample, grid_steps, panel_plot, shown, tick_label};
use crate::reference::separatrix;

/// A quantity of the selected bead that the panel can plot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Simulated time.
    Time,
    /// Position along `x`.
    X,
    /// Position along `y`.
    Y,
    /// Velocity along `x`.
    Vx,
    /// Velocity along `y`.
    Vy,
    /// On a wire in the plane: how far along it, `s`.
    Along,
    /// On a wire in the plane: how fast along it, `ṡ`.
    AlongSpeed,
    /// On a circle: the angle from its lowest point (where gravity pulls).
    Angle,
    /// On a circle: how fast that angle turns.
    AngularSpeed,
    /// The drift `C`.
    C,
    /// Its rate `Ċ`.
    CDot,
    /// The wire's multiplier λ.
    Lambda,
    /// The energy.
    Energy,
}

impl Quantity {
    /// Every quantity, in the order the panel lists them.
    pub const ALL: [Self; 13] = [
        Self::Time,
        Self::X,
        Self::Y,
        Self::Vx,
        Self::Vy,
        Self::Along,
        Self::AlongSpeed,
        Self::Angle,
        Self::AngularSpeed,
        Self::C,
        Self::CDot,
        Self::Lambda,
        Self::Energy,
    ];

    /// Its name and unit, for a menu and an axis.
    pub fn label(self) -> &'static str {
        match self {
            Self::Time => "t (s)",
            Self::X => "x (m)",
            Self::Y => "y (m)",
            Self::Vx => "vx (m/s)",
            Self::Vy => "vy (m/s)",
            Self::Along => "s (m)",
            Self::AlongSpeed => "ds/dt (m/s)",
            Self::Angle => "θ (rad)",
            Self::AngularSpeed => "dθ/dt (rad/s)",
            Self::C => "C (m)",
            Self::CDot => "Ċ (m/s)",
            Self::Lambda => "λ (N)",
            Self::Energy => "E (J)",
        }
    }

    /// Its value in `sample`; none for an angle off a circle.
    pub fn of(self, sample: &PlotSample) -> Option<f64> {
        Some(match self {
            Self::Time => sample.t,
            Self::X => sample.position.x,
            Self::Y => sample.position.y,
            Self::Vx => sample.velocity.x,
            Self::Vy => sample.velocity.y,
            Self::Along => sample.along?.s,
            Self::AlongSpeed => sample.along?.s_dot,
            Self::Angle => sample.on_circle?.0,
            Self::AngularSpeed => sample.on_circle?.1,
            Self::C => sample.c,
            Self::CDot => sample.c_dot,
            Self::Lambda => sample.lambda,
            Self::Energy => sample.energy,
        })
    }
}

/// The two quantities the phase plot draws, `y` against `x`. A bead newly
/// plotted opens on its phase portrait: `(θ, θ̇)` on a circle, `(s, ṡ)`
/// on another wire, `(x, vx)` on none; the menus pick any other two.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct PhasePlot {
    /// Along the horizontal axis.
    pub x: Quantity,
    /// Along the vertical axis.
    pub y: Quantity,
    /// The bead the axes were opened for.
    opened_for: Option<Entity>,
}

impl Default for PhasePlot {
    /// The phase portrait on a circle, `(θ, θ̇)`.
    fn default() -> Self {
        Self {
            x: Quantity::Angle,
            y: Quantity::AngularSpeed,
            opened_for: None,
        }
    }
}

impl PhasePlot {
    /// The axes of `sample`'s phase portrait: `(θ, θ̇)` on a circle,
    /// `(s, ṡ)` on another wire, `(x, vx)` on none.
    pub fn portrait_of(sample: &PlotSample) -> (Quantity, Quantity) {
        if sample.on_circle.is_some() {
            (Quantity::Angle, Quantity::AngularSpeed)
        } else if sample.along.is_some() {
            (Quantity::Along, Quantity::AlongSpeed)
        } else {
            (Quantity::X, Quantity::Vx)
        }
    }
}

/// Where the phase plot was last drawn: its frame on screen, in physical
/// pixels, and the values at its edges, for scripts that check what it
/// shows.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct PhasePlotFrame(pub Option<PlotFrame>);

/// A plot's frame on screen and the values at its edges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlotFrame {
    /// Left, top, right and bottom, in physical pixels.
    pub rect: [f32; 4],
    /// The part of it the panel shows (the rest scrolled out of view), the
    /// same way.
    pub visible: [f32; 4],
    /// The values at the left and right edges, then at the bottom and the
    /// top.
    pub bounds: [f64; 4],
}

/// The phase plot's section, which folds away: a menu for each axis,
/// then the recorded samples of `y` against `x`, the latest marked; on a
/// circle's `(θ, θ̇)` the separatrix too, dashed.
pub(super) fn phase_section(
    ui: &mut egui::Ui,
    history: &PlotHistory,
    choice: &mut PhasePlot,
    frame: &mut PhasePlotFrame,
) -> Option<egui::Rect> {
    ui.separator();
    let section = egui::CollapsingHeader::new("Phase plot")
        .default_open(true)
        .show(ui, |ui| phase_plot(ui, history, choice));
    let drawn = section.body_returned.flatten();
    if frame.0 != drawn {
        frame.0 = drawn;
    }
    shown(ui, section.body_response?.rect)
}

/// The menus and the plot of [`phase_section`].
fn phase_plot(
    ui: &mut egui::Ui,
    history: &PlotHistory,
    choice: &mut PhasePlot,
) -> Option<PlotFrame> {
    if choice.opened_for != history.bead()
        && let Some(last) = history.samples.back()
    {
        (choice.x, choice.y) = PhasePlot::portrait_of(last);
        choice.opened_for = history.bead();
    }
    ui.horizontal(|ui| {
        ui.label("plot");
        quantity_menu(ui, "phase-y", &mut choice.y);
        ui.label("against");
        quantity_menu(ui, "phase-x", &mut choice.x);
    });
    let points: Vec<[f64; 2]> = history
        .samples
        .iter()
        .filter_map(|s| Some([choice.x.of(s)?, choice.y.of(s)?]))
        .collect();
    if points.is_empty() {
        ui.label(
            "Nothing to plot: θ and dθ/dt need a bead on a circle, s and ds/dt a bead on a wire; pick other quantities.",
        );
        return None;
    }
    let last = points[points.len() - 1];
    let portrait = (choice.x, choice.y) == (Quantity::Angle, Quantity::AngularSpeed);
    let drawn = panel_plot("plot-phase", 160.0, false)
        .x_axis_label(choice.x.label())
        .y_axis_label(choice.y.label())
        .x_grid_spacer(uniform_grid_spacer(|input| grid_steps(input.bounds, false)))
        .x_axis_formatter(|mark, _| tick_label(mark.value, mark.step_size))
        .legend(Legend::default())
        .show(ui, |plot_ui| {
            if let (true, Some((g, radius))) = (portrait, history.circle) {
                for (k, branch) in separatrix(g, radius, 121).into_iter().enumerate() {
                    let name = if k == 0 { "separatrix" } else { "" };
                    plot_ui.line(
                        Line::new(name, PlotPoints::from(branch))
                            .color(egui::Color32::GRAY)
                            .style(LineStyle::dashed_loose()),
                    );
                }
            }
            for (k, piece) in unwrapped(&points, (choice.x, choice.y))
                .into_iter()
                .enumerate()
            {
                let name = if k == 0 { "recorded" } else { "" };
                plot_ui.line(
                    Line::new(name, PlotPoints::from(piece)).color(egui::Color32::LIGHT_BLUE),
                );
            }
            plot_ui.points(
                Points::new("now", vec![last])
                    .radius(3.0)
                    .color(egui::Color32::ORANGE),
            );
        });
    let scale = ui.ctx().pixels_per_point();
    let rect = drawn.transform.frame();
    let bounds = drawn.transform.bounds();
    let edges = |r: egui::Rect| [r.left(), r.top(), r.right(), r.bottom()].map(|v| v * scale);
    Some(PlotFrame {
        rect: edges(*rect),
        visible: edges(rect.intersect(ui.clip_rect())),
        bounds: [
            bounds.min()[0],
            bounds.max()[0],
            bounds.min()[1],
            bounds.max()[1],
        ],
    })
}

/// `points` cut into pieces where an angle among `axes` wraps round
/// (jumps by more than π from one sample to the next, as a bead going
/// over the top of its circle does), so no line is drawn across the plot.
pub fn unwrapped(points: &[[f64; 2]], axes: (Quantity, Quantity)) -> Vec<Vec<[f64; 2]>> {
    let angle = [axes.0 == Quantity::Angle, axes.1 == Quantity::Angle];
    let mut pieces: Vec<Vec<[f64; 2]>> = Vec::new();
    let mut last: Option<[f64; 2]> = None;
    for &p in points {
        let wraps = last.is_some_and(|q| {
            (0..2).any(|i| angle[i] && (p[i] - q[i]).abs() > std::f64::consts::PI)
        });
        match pieces.last_mut() {
            Some(piece) if !wraps => piece.push(p),
            _ => pieces.push(vec![p]),
        }
        last = Some(p);
    }
    pieces
}

/// A menu of every quantity, choosing `value`.
fn quantity_menu(ui: &mut egui::Ui, id: &str, value: &mut Quantity) {
    egui::ComboBox::from_id_salt(id)
        .selected_text(value.label())
        .show_ui(ui, |ui| {
            for q in Quantity::ALL {
                ui.selectable_value(value, q, q.label());
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gui::panel::plots::HeldBy;

    #[test]
    fn a_bead_going_over_the_top_is_drawn_in_pieces() {
        let axes = (Quantity::Angle, Quantity::AngularSpeed);
        let points = [[3.0, 1.0], [3.1, 1.0], [-3.1, 1.0], [-3.0, 1.0]];
        let pieces = unwrapped(&points, axes);
        assert_eq!(pieces, vec![points[..2].to_vec(), points[2..].to_vec()]);
        let path = unwrapped(&points, (Quantity::X, Quantity::Y));
        assert_eq!(path.len(), 1, "no angle, no cut");
    }

    #[test]
    fn every_quantity_reads_its_own_value() {
        let sample = PlotSample {
            t: 1.0,
            held_by: HeldBy::Wire,
            c: 2.0,
            c_dot: 3.0,
            energy: 4.0,
            own_energy: false,
            scene_energy: 4.0,
            lambda: 5.0,
            position: DVec3::new(6.0, 7.0, 0.0),
            velocity: DVec3::new(8.0, 9.0, 0.0),
            on_circle: Some((10.0, 11.0)),
            along: Some(crate::reference::AlongWire {
                s: 14.0,
                s_dot: 15.0,
                position: bevy::math::DVec2::ZERO,
                tangent: bevy::math::DVec2::X,
            }),
            kinetic: 12.0,
            potential: 13.0,
            normal_force: None,
        };
        let values: Vec<f64> = Quantity::ALL
            .iter()
            .map(|q| q.of(&sample).unwrap())
            .collect();
        assert_eq!(
            values,
            [
                1.0, 6.0, 7.0, 8.0, 9.0, 14.0, 15.0, 10.0, 11.0, 2.0, 3.0, 5.0, 4.0
            ]
        );
        let off = PlotSample {
            on_circle: None,
            ..sample
        };
        assert_eq!(Quantity::Angle.of(&off), None);
    }
}
