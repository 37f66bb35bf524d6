//! The rotating hoop's bifurcation: a bead on a hoop of radius `r`
//! spinning at `ω` about its vertical diameter, run through the plugin
//! from just off the bottom with light damping along the hoop, settles at
//! the bottom while `ω² < g/r` and at `cos θ* = g/(ω² r)` past it (a
//! pitchfork). `bifurcation` sweeps `ω` and plots the angle it settles at
//! against the theory, with a CSV behind the plot.

use std::path::{Path, PathBuf};

use bevy::math::DVec3;
use plotters::prelude::*;
use wirebead::geometry::{Circle as Hoop, Friction, Side};
use wirebead::preset::{
    BeadPreset, RotationPreset, SpaceMotionPreset, SpaceShapePreset, SpaceWirePreset, SpinPreset,
};
use wirebead::{Method, SimParams, SpaceScene};

use crate::AnalysisResult;
use crate::plot::{FIGURE_SIZE, palette, register_font};
use crate::scene::simulate_scene;

/// A sweep of the hoop's spin.
#[derive(Clone, Debug, PartialEq)]
pub struct HoopSweep {
    /// The hoop's radius (m).
    pub radius: f64,
    /// Gravity's magnitude (m/s²).
    pub gravity: f64,
    /// The spins to run (rad/s).
    pub omegas: Vec<f64>,
    /// Viscous damping along the hoop (N·s/m, on a bead of 1 kg).
    pub damping: f64,
    /// The angle from the bottom the bead starts at, at rest on the hoop
    /// (rad).
    pub start: f64,
    /// Simulated seconds per spin; the last tenth is where it settled.
    pub duration: f64,
    /// The step (RATTLE).
    pub dt: f64,
}

impl Default for HoopSweep {
    /// A hoop of 1 m, `g` = 9.81 (so `√(g/r)` = 3.13 rad/s), ω from 0.25
    /// to 8 rad/s in steps of 0.25, damping 1 N·s/m, from 0.05 rad, 30 s
    /// at 2 ms.
    fn default() -> Self {
        Self {
            radius: 1.0,
            gravity: 9.81,
            omegas: (1..=32).map(|i| 0.25 * f64::from(i)).collect(),
            damping: 1.0,
            start: 0.05,
            duration: 30.0,
            dt: 2e-3,
        }
    }
}

/// Where the bead settled at one spin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoopPoint {
    /// The spin (rad/s).
    pub omega: f64,
    /// The mean angle from the bottom over the run's last tenth (rad).
    pub settled: f64,
    /// The theory: 0 below `√(g/r)`, `acos(g/(ω² r))` above (rad).
    pub theory: f64,
    /// How far the angle still swung over the last tenth, max − min
    /// (rad): how settled it is.
    pub swing: f64,
}

/// The angle from the bottom where a bead on a hoop of radius `r`
/// spinning at `omega` rests: 0 while `ω² ≤ g/r`, else `acos(g/(ω² r))`.
pub fn hoop_equilibrium(omega: f64, gravity: f64, radius: f64) -> f64 {
    let c = gravity / (omega * omega * radius);
    if c >= 1.0 { 0.0 } else { c.acos() }
}

impl HoopSweep {
    /// The scene of one spin: the hoop in its xy-plane turning about y,
    /// the bead at rest on it `start` from the bottom.
    pub fn scene(&self, omega: f64) -> SpaceScene {
        let params = SimParams {
            timestep: self.dt,
            gravity: bevy::math::DVec2::new(0.0, -self.gravity),
            method: Method::Rattle,
            ..SimParams::default()
        };
        let (s, c) = self.start.sin_cos();
        SpaceScene {
            name: format!("Hoop at {omega} rad/s"),
            dimension: 3,
            params: wirebead::SpaceParams(params),
            wires: vec![SpaceWirePreset {
                name: String::new(),
                body: String::new(),
                shape: SpaceShapePreset::Circle(Hoop {
                    radius: self.radius,
                }),
                position: DVec3::ZERO,
                rotation: RotationPreset::default(),
                motion: SpaceMotionPreset::Spin(SpinPreset {
                    angular_velocity: omega,
                    axis: DVec3::Y,
                }),
                side: Side::Both,
                restitution: 0.0,
                friction: Friction::NONE,
                damping: self.damping,
                rail: None,
                catches: false,
                sends_back: None,
                beads: vec![BeadPreset {
                    name: "b".to_owned(),
                    mass: 1.0,
                    initial_position: DVec3::new(self.radius * s, -self.radius * c, 0.0),
                    initial_velocity: DVec3::ZERO,
                    radius: 0.0,
                }],
            }],
            beads: Vec::new(),
            constraints: Vec::new(),
            springs: Vec::new(),
            contacts: Default::default(),
            bodies: Vec::new(),
        }
    }

    /// Runs every spin: where the bead settled, against the theory.
    pub fn run(&self) -> AnalysisResult<Vec<HoopPoint>> {
        let bar = crate::run::progress(self.omegas.len() as u64, "spins");
        let mut points = Vec::with_capacity(self.omegas.len());
        for &omega in &self.omegas {
            let scene = self.scene(omega);
            let run = simulate_scene(&scene, scene.params.0.clone(), self.duration)?;
            if let Some((t, why)) = run.diverged {
                return Err(
                    format!("the hoop at {omega} rad/s diverged at t = {t:.3} s: {why}").into(),
                );
            }
            let tail = &run.rows[run.rows.len() - (run.rows.len() / 10).max(1)..];
            // The angle from the bottom, whichever side the bead took.
            let angles: Vec<f64> = tail
                .iter()
                .map(|row| {
                    let p = row.positions[0];
                    p.x.hypot(p.z).atan2(-p.y)
                })
                .collect();
            let mean = angles.iter().sum::<f64>() / angles.len() as f64;
            let (lo, hi) = angles
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &a| {
                    (lo.min(a), hi.max(a))
                });
            points.push(HoopPoint {
                omega,
                settled: mean,
                theory: hoop_equilibrium(omega, self.gravity, self.radius),
                swing: hi - lo,
            });
            bar.inc(1);
        }
        bar.finish_and_clear();
        Ok(points)
    }
}

/// Runs `sweep` and writes `bifurcation.csv` (`omega,settled_deg,
/// theory_deg,swing_deg`) and `bifurcation.png` into `out_dir`.
pub fn bifurcation(out_dir: &Path, sweep: &HoopSweep) -> AnalysisResult<Vec<PathBuf>> {
    std::fs::create_dir_all(out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let points = sweep.run()?;
    let csv = out_dir.join("bifurcation.csv");
    let mut writer = csv::Writer::from_path(&csv).map_err(|e| format!("{}: {e}", csv.display()))?;
    writer.write_record(["omega", "settled_deg", "theory_deg", "swing_deg"])?;
    for p in &points {
        let row = [p.omega, p.settled, p.theory, p.swing];
        writer.write_record(row.iter().enumerate().map(|(i, v)| {
            if i == 0 {
                format!("{v}")
            } else {
                format!("{:.6}", v.to_degrees())
            }
        }))?;
    }
    writer.flush()?;
    let png = out_dir.join("bifurcation.png");
    plot_bifurcation(&png, sweep, &points)?;
    Ok(vec![csv, png])
}

/// The settled angle against the spin, the theory drawn as a line.
fn plot_bifurcation(path: &Path, sweep: &HoopSweep, points: &[HoopPoint]) -> AnalysisResult<()> {
    register_font();
    let critical = (sweep.gravity / sweep.radius).sqrt();
    let top = points.iter().map(|p| p.omega).fold(critical, f64::max) * 1.05;
    let root = BitMapBackend::new(path, (FIGURE_SIZE.0, FIGURE_SIZE.1 * 3 / 4)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "Bead on a rotating hoop, r = {} m: where it settles",
                sweep.radius
            ),
            ("sans-serif", 24),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..top, 0.0..90.0)?;
    chart
        .configure_mesh()
        .x_desc("spin ω (rad/s)")
        .y_desc("angle from the bottom θ (degrees)")
        .draw()?;
    let theory = (0..=400).map(|i| {
        let omega = top * f64::from(i) / 400.0;
        (
            omega,
            hoop_equilibrium(omega, sweep.gravity, sweep.radius).to_degrees(),
        )
    });
    chart
        .draw_series(LineSeries::new(theory, BLACK.stroke_width(2)))?
        .label("theory: θ* = 0 below √(g/r), cos θ* = g/(ω² r) above")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
    chart
        .draw_series(LineSeries::new(
            [(critical, 0.0), (critical, 90.0)],
            BLACK.mix(0.4).stroke_width(1),
        ))?
        .label(format!("√(g/r) = {critical:.3} rad/s"))
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.4)));
    let colour = palette(1);
    chart
        .draw_series(
            points
                .iter()
                .map(|p| Circle::new((p.omega, p.settled.to_degrees()), 5, colour.filled())),
        )?
        .label("simulated (RATTLE, damped), mean of the last tenth")
        .legend(move |(x, y)| Circle::new((x + 10, y), 5, colour.filled()));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()?;
    root.present()?;
    Ok(())
}
