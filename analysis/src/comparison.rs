//! Every method on the pendulum against its exact period and energy, with
//! the cost of the solver math per step, and the table of it in markdown.

use std::fmt::Write as _;
use std::time::Instant;

use bevy::math::DVec2;
use wirebead::geometry::Circle;
use wirebead::reference::{pendulum_period, period_from_crossings, point_on_circle};
use wirebead::solver::{self, BeadState, LinearForce};
use wirebead::{BeadParams, Method, SimParams, WireShape};

use crate::AnalysisResult;
use crate::run::{RunConfig, progress, simulate, summarize};

/// One row of the comparison table.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// The integrator and its stabilization.
    pub method: Method,
    /// The step.
    pub dt: f64,
    /// (measured - exact) / exact, if at least two periods were seen.
    pub period_error: Option<f64>,
    /// max |C| / r.
    pub max_drift: f64,
    /// max |E - E0| / (m |g| r).
    pub energy_error: f64,
    /// When it diverged, if it did.
    pub diverged: Option<f64>,
    /// Wall-clock nanoseconds per step of the solver math alone.
    pub ns_per_step: f64,
}

/// The pendulum test: release from rest at `theta0_deg` on a vertical
/// circle of radius `radius` under gravity `gravity` (magnitude).
pub fn pendulum_config(
    radius: f64,
    gravity: f64,
    theta0_deg: f64,
    dt: f64,
    duration: f64,
) -> RunConfig {
    RunConfig {
        wire: WireShape::Circle(Circle { radius }),
        params: SimParams {
            timestep: dt,
            gravity: DVec2::new(0.0, -gravity),
            ..SimParams::default()
        },
        bead: BeadParams {
            mass: 1.0,
            initial_position: point_on_circle(radius, theta0_deg.to_radians()),
            initial_velocity: DVec2::ZERO,
        },
        duration,
    }
}

/// Times the solver math alone for one method: nanoseconds per step.
fn time_per_step(config: &RunConfig) -> f64 {
    let curve = config.wire.curve();
    let settings = solver::StepSettings {
        drift_bound: f64::INFINITY,
        ..config.params.step_settings()
    };
    let force = LinearForce::constant(config.bead.mass * config.params.gravity);
    let start = BeadState {
        position: config.bead.initial_position,
        velocity: config.bead.initial_velocity,
    };
    let steps = 20_000;
    let clock = Instant::now();
    let mut state = start;
    for _ in 0..steps {
        state = match solver::step(curve, state, &force, config.bead.mass, &settings) {
            Ok(out) => out.state,
            Err(_) => start,
        };
    }
    std::hint::black_box(state);
    clock.elapsed().as_secs_f64() * 1e9 / f64::from(steps)
}

/// Every method at every step in `dts` on the
/// pendulum test, against the exact period and energy.
pub fn compare(
    radius: f64,
    gravity: f64,
    theta0_deg: f64,
    duration: f64,
    dts: &[f64],
) -> AnalysisResult<Vec<Comparison>> {
    let exact = pendulum_period(radius, gravity, theta0_deg.to_radians());
    let total = (Method::ALL.len() * dts.len()) as u64;
    let bar = progress(total, "compare");
    let mut table = Vec::new();
    for method in Method::ALL {
        for &dt in dts {
            bar.set_message(format!("{method}, dt = {dt:.5}"));
            let mut config = pendulum_config(radius, gravity, theta0_deg, dt, duration);
            config.params.method = method;
            let out = simulate(&config).map_err(|e| format!("{method} at dt = {dt}: {e}"))?;
            let xs: Vec<(f64, f64)> = out.rows.iter().map(|r| (r.t, r.position.x)).collect();
            let summary = summarize(&out.rows, radius, 1.0, gravity);
            table.push(Comparison {
                method,
                dt,
                period_error: out
                    .diverged
                    .is_none()
                    .then(|| period_from_crossings(&xs))
                    .flatten()
                    .map(|p| (p - exact) / exact),
                max_drift: summary.max_drift,
                energy_error: summary.max_energy_error,
                diverged: out.diverged.map(|(t, _)| t),
                ns_per_step: time_per_step(&config),
            });
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(table)
}

/// The comparison as a markdown table.
pub fn comparison_markdown(
    table: &[Comparison],
    radius: f64,
    gravity: f64,
    theta0_deg: f64,
    duration: f64,
) -> String {
    let mut md = format!(
        "# Every method on the pendulum\n\nRelease from rest at θ0 = {theta0_deg}° on a circle of radius {radius} m, |g| = {gravity} m/s², {duration} s simulated. Exact period {:.6} s. Energy error is max abs(E - E0) over the run in units of m·|g|·r; cost is the solver math alone, per step.\n\n| integrator | stabilization | dt (s) | period error | max abs(C)/r | energy error | cost (ns/step) |\n|---|---|---|---|---|---|---|\n",
        pendulum_period(radius, gravity, theta0_deg.to_radians())
    );
    for row in table {
        let period = match (row.diverged, row.period_error) {
            (Some(t), _) => format!("diverged at {t:.2} s"),
            (None, Some(e)) => format!("{e:+.2e}"),
            (None, None) => "—".to_owned(),
        };
        let _ = writeln!(
            md,
            "| {} | {} | {:.5} | {} | {:.2e} | {:.2e} | {:.0} |",
            row.method.integrator(),
            row.method.stabilization().map_or("—", |s| s.name()),
            row.dt,
            period,
            row.max_drift,
            row.energy_error,
            row.ns_per_step
        );
    }
    md
}
