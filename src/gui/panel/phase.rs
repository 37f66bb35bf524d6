//! A plot of any two of the selected bead's recorded quantities against
//! each other: its phase portrait (on a circle `(θ, θ̇)`, with the
//! pendulum's separatrix), its path `(x, y)`, or any of them against time.

use bevy::math::DVec2;
#[cfg(test)]
use bevy::math::DVec3;
use bevy::prelude::*;
use bevy_egui::egui;
use egui_plot::{Legend, Line, LineStyle, Plot, PlotPoints, Points, uniform_grid_spacer};

use super::plots::{PlotHistory, PlotSample, grid_steps, tick_label};

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
    pub const ALL: [Self; 11] = [
        Self::Time,
        Self::X,
        Self::Y,
        Self::Vx,
        Self::Vy,
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
            Self::Angle => sample.on_circle?.0,
            Self::AngularSpeed => sample.on_circle?.1,
            Self::C => sample.c,
            Self::CDot => sample.c_dot,
            Self::Lambda => sample.lambda,
            Self::Energy => sample.energy,
        })
    }
}

/// The two quantities the phase plot draws, `y` against `x`.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct PhasePlot {
    /// Along the horizontal axis.
    pub x: Quantity,
    /// Along the vertical axis.
    pub y: Quantity,
}

impl Default for PhasePlot {
    /// The phase portrait on a circle, `(θ, θ̇)`.
    fn default() -> Self {
        Self {
            x: Quantity::Angle,
            y: Quantity::AngularSpeed,
        }
    }
}

/// Where a bead at `position` moving at `velocity` is on a circle about
/// `centre` in the plane, under gravity `gravity`: the angle `θ` from the
/// circle's lowest point (positive turning anticlockwise, in `(−π, π]`)
/// and `θ̇`. Measured from straight up where there is no gravity; none at
/// the centre.
pub fn circle_angle(
    centre: DVec2,
    gravity: DVec2,
    position: DVec2,
    velocity: DVec2,
) -> Option<(f64, f64)> {
    let r = position - centre;
    let rr = r.length_squared();
    if !(rr > 0.0 && rr.is_finite()) {
        return None;
    }
    let down = gravity.try_normalize().unwrap_or(DVec2::NEG_Y);
    let angle = down.perp_dot(r).atan2(down.dot(r));
    Some((angle, r.perp_dot(velocity) / rr))
}

/// The pendulum's separatrix on a circle of `radius` under gravity of
/// size `g`: `θ̇ = ±√(2 g / R · (1 + cos θ))`, the motion that just comes
/// to rest at the top, as two branches of `points` points each over
/// `θ ∈ [−π, π]`.
pub fn separatrix(g: f64, radius: f64, points: usize) -> [Vec<[f64; 2]>; 2] {
    let points = points.max(2);
    let upper: Vec<[f64; 2]> = (0..points)
        .map(|k| {
            let theta =
                -std::f64::consts::PI + std::f64::consts::TAU * k as f64 / (points - 1) as f64;
            [
                theta,
                (2.0 * g / radius * (1.0 + theta.cos())).max(0.0).sqrt(),
            ]
        })
        .collect();
    let lower = upper.iter().map(|&[t, w]| [t, -w]).collect();
    [upper, lower]
}

/// The force with which a frictionless circle of `radius` holds a bead
/// of `mass` at angle `theta` from its lowest point, toward its centre,
/// under gravity of size `g`, the bead having started at `start`
/// (`(θ0, θ̇0)`) and been left alone since: energy kept gives
/// `R θ̇² = R θ̇0² + 2 g (cos θ − cos θ0)`, so
/// `N = m (R θ̇0² + g (3 cos θ − 2 cos θ0))`, the pendulum's
/// `m g (3 cos θ − 2 cos θ0)` when let go from rest.
pub fn circle_normal_force(mass: f64, g: f64, radius: f64, start: (f64, f64), theta: f64) -> f64 {
    let (theta0, rate0) = start;
    mass * (radius * rate0 * rate0 + g * (3.0 * theta.cos() - 2.0 * theta0.cos()))
}

/// The phase plot's section: a menu for each axis, then the recorded
/// samples of `y` against `x`, the latest marked; on a circle's
/// `(θ, θ̇)` the separatrix too, dashed.
pub(super) fn phase_section(ui: &mut egui::Ui, history: &PlotHistory, choice: &mut PhasePlot) {
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
        ui.label("Nothing to plot: θ and dθ/dt need a bead on a circle; pick other quantities.");
        return;
    }
    let last = points[points.len() - 1];
    let portrait = (choice.x, choice.y) == (Quantity::Angle, Quantity::AngularSpeed);
    Plot::new("plot-phase")
        .height(160.0)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .x_axis_label(choice.x.label())
        .y_axis_label(choice.y.label())
        .y_axis_min_width(48.0)
        .x_grid_spacer(uniform_grid_spacer(|input| grid_steps(input.bounds, false)))
        .y_grid_spacer(uniform_grid_spacer(|input| grid_steps(input.bounds, false)))
        .x_axis_formatter(|mark, _| tick_label(mark.value, mark.step_size))
        .y_axis_formatter(|mark, _| tick_label(mark.value, mark.step_size))
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

    #[test]
    fn the_angle_on_a_circle_is_measured_from_its_lowest_point() {
        let g = DVec2::new(0.0, -9.81);
        let c = DVec2::new(1.0, 2.0);
        let (bottom, _) = circle_angle(c, g, c + DVec2::new(0.0, -0.5), DVec2::X).unwrap();
        assert!(bottom.abs() <= 1e-15);
        let (right, w) =
            circle_angle(c, g, c + DVec2::new(0.5, 0.0), DVec2::new(0.0, 1.0)).unwrap();
        assert!(
            (right - std::f64::consts::FRAC_PI_2).abs() <= 1e-15,
            "{right}"
        );
        assert!((w - 2.0).abs() <= 1e-15, "turns at {w} rad/s");
        let (top, _) = circle_angle(c, g, c + DVec2::new(0.0, 0.5), DVec2::ZERO).unwrap();
        assert!((top.abs() - std::f64::consts::PI).abs() <= 1e-15);
        assert!(circle_angle(c, g, c, DVec2::X).is_none());
    }

    /// On the separatrix the energy per unit mass, `½ R² θ̇² − g R cos θ`,
    /// is the top's at rest, `g R`, to rounding.
    #[test]
    fn the_separatrix_has_the_energy_of_rest_at_the_top() {
        let (g, r) = (9.81, 0.75);
        let [upper, lower] = separatrix(g, r, 61);
        assert_eq!(upper.len(), 61);
        for &[theta, w] in upper.iter().chain(&lower) {
            let energy = 0.5 * r * r * w * w - g * r * theta.cos();
            assert!((energy - g * r).abs() <= 1e-12, "at θ = {theta}: {energy}");
        }
        assert!(upper[30][1] > 0.0 && lower[30][1] < 0.0);
    }

    #[test]
    fn a_bead_going_over_the_top_is_drawn_in_pieces() {
        let axes = (Quantity::Angle, Quantity::AngularSpeed);
        let points = [[3.0, 1.0], [3.1, 1.0], [-3.1, 1.0], [-3.0, 1.0]];
        let pieces = unwrapped(&points, axes);
        assert_eq!(pieces, vec![points[..2].to_vec(), points[2..].to_vec()]);
        let path = unwrapped(&points, (Quantity::X, Quantity::Y));
        assert_eq!(path.len(), 1, "no angle, no cut");
    }

    /// Let go from rest level with the centre, a pendulum's bob pulls on
    /// it with three times its weight at the bottom and nothing where it
    /// started; sent round from the bottom at `v`, the circle holds it
    /// with `m v² / R + m g` there.
    #[test]
    fn the_circle_holds_the_bead_as_energy_kept_says() {
        let (m, g, r) = (2.0, 9.81, 0.5);
        let half_pi = std::f64::consts::FRAC_PI_2;
        assert!((circle_normal_force(m, g, r, (half_pi, 0.0), 0.0) - 3.0 * m * g).abs() <= 1e-12);
        assert!(circle_normal_force(m, g, r, (half_pi, 0.0), half_pi).abs() <= 1e-12);
        let v = 4.0;
        let bottom = circle_normal_force(m, g, r, (0.0, v / r), 0.0);
        assert!(
            (bottom - (m * v * v / r + m * g)).abs() <= 1e-12,
            "{bottom}"
        );
    }

    #[test]
    fn every_quantity_reads_its_own_value() {
        let sample = PlotSample {
            t: 1.0,
            c: 2.0,
            c_dot: 3.0,
            energy: 4.0,
            lambda: 5.0,
            position: DVec3::new(6.0, 7.0, 0.0),
            velocity: DVec3::new(8.0, 9.0, 0.0),
            on_circle: Some((10.0, 11.0)),
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
            [1.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 2.0, 3.0, 5.0, 4.0]
        );
        let off = PlotSample {
            on_circle: None,
            ..sample
        };
        assert_eq!(Quantity::Angle.of(&off), None);
    }
}
