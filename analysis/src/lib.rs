//! The analysis tool's library: headless runs through the plugin, their
//! CSV, the assignment's three studies as figures, and every method against the
//! exact pendulum. The binary `wirebead-analysis` is its command line.

use std::error::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use bevy::math::DVec2;
use bevy::prelude::{FixedUpdate, IntoScheduleConfigs, Query, Res, ResMut, Resource, Without};
use indicatif::{ProgressBar, ProgressStyle};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use wirebead::geometry::Circle;
use wirebead::headless::{Headless, idle, run_steps};
use wirebead::reference::{pendulum_period, period_from_crossings, point_on_circle};
use wirebead::solver::{self, BeadState, LinearForce};
use wirebead::{
    Bead, BeadDiagnostics, BeadParams, Diverged, Method, OnWire, ParamError, Restart, SimClock,
    SimParams, Wire, WireBeadPlugin, WireBeadSystems, WireShape,
};

mod scene;

pub use scene::{
    SceneComparison, SceneRow, SceneRun, compare_scene, load_scene, scene_comparison_markdown,
    simulate_scene, write_scene_csv,
};

/// Errors of the analysis: a message naming what failed.
pub type AnalysisResult<T> = Result<T, Box<dyn Error>>;

/// The header of every CSV the analysis writes.
pub const CSV_HEADER: [&str; 9] = ["t", "x", "y", "vx", "vy", "c", "c_dot", "lambda", "energy"];

/// One headless run.
#[derive(Clone, Debug)]
pub struct RunConfig {
    /// The wire (placed at the origin, unrotated).
    pub wire: WireShape,
    /// The shared parameters.
    pub params: SimParams,
    /// The bead.
    pub bead: BeadParams,
    /// Simulated seconds.
    pub duration: f64,
}

/// One row of a run: the state and diagnostics after a step (or at t = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// Time.
    pub t: f64,
    /// Position.
    pub position: DVec2,
    /// Velocity.
    pub velocity: DVec2,
    /// `C`.
    pub c: f64,
    /// `Ċ`.
    pub c_dot: f64,
    /// λ.
    pub lambda: f64,
    /// Kinetic plus potential energy.
    pub energy: f64,
}

/// What a run produced.
#[derive(Clone, Debug, Default)]
pub struct RunOutput {
    /// One row per fixed step, including t = 0.
    pub rows: Vec<Row>,
    /// Why the bead diverged, and when, if it did.
    pub diverged: Option<(f64, String)>,
}

#[derive(Resource, Default)]
struct Rows(Vec<Row>);

fn record_rows(
    beads: Query<(&Bead, &BeadDiagnostics), Without<Diverged>>,
    clock: Res<SimClock>,
    mut rows: ResMut<Rows>,
) {
    for (bead, d) in &beads {
        rows.0.push(Row {
            t: clock.time,
            position: bead.position,
            velocity: bead.velocity,
            c: d.c,
            c_dot: d.c_dot,
            lambda: d.lambda,
            energy: d.energy(),
        });
    }
}

/// Runs one simulation headless through [`WireBeadPlugin`] and returns a row
/// per fixed step. Invalid parameters are refused before anything runs.
pub fn simulate(config: &RunConfig) -> Result<RunOutput, ParamError> {
    let plugin = WireBeadPlugin::new(config.params.clone())?;
    let wire = Wire::new(config.wire.clone())?;
    let bead = Bead::new(config.bead)?;
    if !(config.duration.is_finite() && config.duration > 0.0) {
        return Err(ParamError::NotPositive {
            name: "duration",
            value: config.duration,
        });
    }

    let mut app = Headless::new(plugin).single_threaded().build();
    app.init_resource::<Rows>()
        .add_systems(FixedUpdate, record_rows.after(WireBeadSystems::Writeback));
    let wire = app.world_mut().spawn(wire).id();
    let bead = app.world_mut().spawn((bead, OnWire(wire))).id();
    // A restart fills in the t = 0 diagnostics.
    app.world_mut().write_message(Restart);
    idle(&mut app);
    app.world_mut().run_system_cached(record_rows).ok();

    let steps = (config.duration / config.params.timestep).round() as u32;
    let mut done = 0;
    while done < steps && app.world().get::<Diverged>(bead).is_none() {
        let batch = (steps - done).min(1000);
        run_steps(&mut app, batch);
        done += batch;
    }
    let diverged = app
        .world()
        .get::<Diverged>(bead)
        .map(|d| (d.time, d.reason.to_string()));
    let rows = std::mem::take(&mut app.world_mut().resource_mut::<Rows>().0);
    Ok(RunOutput { rows, diverged })
}

/// Writes rows as CSV with [`CSV_HEADER`].
pub fn write_csv(path: &Path, rows: &[Row]) -> AnalysisResult<()> {
    let mut writer =
        csv::Writer::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    writer.write_record(CSV_HEADER)?;
    for r in rows {
        writer.write_record(
            [
                r.t,
                r.position.x,
                r.position.y,
                r.velocity.x,
                r.velocity.y,
                r.c,
                r.c_dot,
                r.lambda,
                r.energy,
            ]
            .map(|v| format!("{v:e}")),
        )?;
    }
    writer.flush()?;
    Ok(())
}

/// Summary numbers of a run on a wire of scale `scale` under gravity `g`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// max |C| / scale.
    pub max_drift: f64,
    /// (E_end - E_0) / (m |g| scale).
    pub final_energy_error: f64,
    /// max |E - E_0| / (m |g| scale).
    pub max_energy_error: f64,
}

/// The summary of a run's rows.
pub fn summarize(rows: &[Row], scale: f64, mass: f64, gravity: f64) -> Summary {
    let e0 = rows.first().map_or(0.0, |r| r.energy);
    let unit = mass * gravity.abs() * scale;
    Summary {
        max_drift: rows.iter().map(|r| r.c.abs()).fold(0.0, f64::max) / scale,
        final_energy_error: rows.last().map_or(0.0, |r| r.energy - e0) / unit,
        max_energy_error: rows
            .iter()
            .map(|r| (r.energy - e0).abs())
            .fold(0.0, f64::max)
            / unit,
    }
}

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The font ships in assets/fonts, so plots never depend on system fonts.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Line colours for up to twelve series.
fn palette(i: usize) -> RGBColor {
    const COLOURS: [RGBColor; 12] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(23, 190, 207),
        RGBColor(188, 189, 34),
        RGBColor(127, 127, 127),
        RGBColor(0, 0, 128),
        RGBColor(0, 0, 0),
    ];
    COLOURS[i % COLOURS.len()]
}

/// The size of every figure, in pixels.
pub const FIGURE_SIZE: (u32, u32) = (900, 800);

/// Plots the wire and each run's path in the plane, like the assignment's figures.
pub fn plot_trajectories(
    path: &Path,
    title: &str,
    wire: &WireShape,
    runs: &[(String, &[Row])],
) -> AnalysisResult<()> {
    register_font();
    let points = runs
        .iter()
        .flat_map(|(_, rows)| rows.iter().map(|r| r.position));
    let wire_points: Vec<DVec2> = (0..=400)
        .filter_map(|i| {
            let a = std::f64::consts::TAU * i as f64 / 400.0;
            match wire {
                WireShape::Circle(c) => Some(DVec2::from_angle(a) * c.radius),
                WireShape::Ellipse(e) => Some(DVec2::new(e.a * a.cos(), e.b * a.sin())),
                _ => None,
            }
        })
        .collect();
    let extent = points
        .chain(wire_points.iter().copied())
        .filter(|p| p.is_finite())
        .fold(1e-3_f64, |m, p| m.max(p.x.abs()).max(p.y.abs()))
        .min(1e3)
        * 1.15;
    let root = BitMapBackend::new(path, FIGURE_SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 26))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(-extent..extent, -extent..extent)?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .draw()?;
    chart
        .draw_series(LineSeries::new(
            wire_points.iter().map(|p| (p.x, p.y)),
            ShapeStyle::from(&BLACK.mix(0.5)).stroke_width(2),
        ))?
        .label("wire")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5)));
    for (i, (label, rows)) in runs.iter().enumerate() {
        let colour = palette(i);
        chart
            .draw_series(LineSeries::new(
                rows.iter().map(|r| {
                    (
                        r.position.x.clamp(-extent, extent),
                        r.position.y.clamp(-extent, extent),
                    )
                }),
                colour.stroke_width(2),
            ))?
            .label(label.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 18))
        .draw()?;
    root.present()?;
    Ok(())
}

/// Draws one line per run (y mapped by `map_y`, points it drops skipped)
/// with a legend.
fn draw_runs<'a, Y: Ranged<ValueType = f64>>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, Cartesian2d<RangedCoordf64, Y>>,
    runs: &[(String, Vec<(f64, f64)>)],
    map_y: impl Fn(f64) -> Option<f64>,
) -> AnalysisResult<()> {
    for (i, (label, series)) in runs.iter().enumerate() {
        let colour = palette(i);
        let points = series.iter().filter_map(|&(t, y)| map_y(y).map(|y| (t, y)));
        chart
            .draw_series(LineSeries::new(points, colour.stroke_width(2)))?
            .label(label.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

/// Plots one quantity of each run against time.
pub fn plot_series(
    path: &Path,
    title: &str,
    y_label: &str,
    runs: &[(String, Vec<(f64, f64)>)],
    log_y: bool,
) -> AnalysisResult<()> {
    register_font();
    let finite = || {
        runs.iter()
            .flat_map(|(_, s)| s.iter())
            .filter(|(t, y)| t.is_finite() && y.is_finite())
    };
    let t_max = finite().map(|(t, _)| *t).fold(1e-9, f64::max);
    let root = BitMapBackend::new(path, (FIGURE_SIZE.0, FIGURE_SIZE.1 / 2)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80);
    if log_y {
        let positive = || finite().map(|(_, y)| y.abs()).filter(|y| *y > 0.0);
        let lo = positive().fold(f64::INFINITY, f64::min).max(1e-18);
        let hi = positive().fold(0.0, f64::max).max(lo * 10.0);
        let mut chart = builder.build_cartesian_2d(0.0..t_max, (lo..hi).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .y_desc(y_label)
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()?;
        draw_runs(&mut chart, runs, |y| (y.abs() > 0.0).then_some(y.abs()))?;
    } else {
        let lo = finite().map(|(_, y)| *y).fold(f64::INFINITY, f64::min);
        let hi = finite().map(|(_, y)| *y).fold(f64::NEG_INFINITY, f64::max);
        let pad = ((hi - lo) * 0.05).max(1e-9);
        let mut chart = builder.build_cartesian_2d(0.0..t_max, (lo - pad)..(hi + pad))?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .y_desc(y_label)
            .draw()?;
        draw_runs(&mut chart, runs, Some)?;
    }
    root.present()?;
    Ok(())
}

/// One run of a study.
#[derive(Clone, Debug)]
pub struct StudyRun {
    /// A short label (`"α = 100"`).
    pub label: String,
    /// The file stem of its CSV (`"alpha_100"`).
    pub stem: String,
    /// The configuration.
    pub config: RunConfig,
}

/// One of the assignment's studies: runs that differ in one parameter.
#[derive(Clone, Debug)]
pub struct Study {
    /// The file stem of its figures (`"alpha"`).
    pub name: String,
    /// The figure title.
    pub title: String,
    /// The runs.
    pub runs: Vec<StudyRun>,
}

/// The assignment's setup: a vertical unit circle, the bead starting at the bottom
/// with a sideways push, semi-implicit Euler with Baumgarte.
pub fn assignment_setup(duration: f64) -> RunConfig {
    RunConfig {
        wire: WireShape::Circle(Circle { radius: 1.0 }),
        params: SimParams::default(),
        bead: BeadParams {
            mass: 1.0,
            initial_position: DVec2::new(0.0, -1.0),
            initial_velocity: DVec2::new(4.0, 0.0),
        },
        duration,
    }
}

/// The assignment's three studies (its Figures 1.1–1.3): α with β fixed, β with α
/// fixed, and the timestep up to the assignment's unstable 0.05 s.
pub fn assignment_studies(duration: f64) -> Vec<Study> {
    let base = assignment_setup(duration);
    let with = |label: String, stem: String, edit: &dyn Fn(&mut SimParams)| {
        let mut config = base.clone();
        edit(&mut config.params);
        StudyRun {
            label,
            stem,
            config,
        }
    };
    vec![
        Study {
            name: "alpha".into(),
            title: "Figure 1.1: spring constant α (β = 10)".into(),
            runs: [0.0, 100.0, 1000.0]
                .map(|a| {
                    with(format!("α = {a}"), format!("alpha_{a}"), &|p| {
                        p.alpha = a;
                        p.beta = 10.0;
                    })
                })
                .into(),
        },
        Study {
            name: "beta".into(),
            title: "Figure 1.2: damping constant β (α = 100)".into(),
            runs: [(2.0, "small"), (20.0, "matched"), (100.0, "too large")]
                .map(|(b, what)| {
                    with(format!("β = {b} ({what})"), format!("beta_{b}"), &|p| {
                        p.alpha = 100.0;
                        p.beta = b;
                    })
                })
                .into(),
        },
        Study {
            name: "timestep".into(),
            title: "Figure 1.3: timestep (α = 100, β = 20)".into(),
            runs: [1.0 / 120.0, 1.0 / 60.0, 0.05]
                .map(|dt| {
                    with(format!("dt = {dt:.4} s"), format!("dt_{dt:.4}"), &|p| {
                        p.timestep = dt
                    })
                })
                .into(),
        },
    ]
}

fn progress(len: u64, message: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template("{msg:>10} [{bar:40}] {pos}/{len} {wide_msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(message.to_owned());
    bar
}

/// Runs the assignment's studies and writes, into `out_dir`, a CSV per run, a
/// trajectory, drift and energy PNG per study, and `summary.md`. Files are
/// written as each run finishes, so a failure leaves the earlier results.
pub fn figures(out_dir: &Path, duration: f64) -> AnalysisResult<Vec<PathBuf>> {
    std::fs::create_dir_all(out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let studies = assignment_studies(duration);
    let total = studies.iter().map(|s| s.runs.len()).sum::<usize>() as u64;
    let bar = progress(total, "figures");
    let mut written = Vec::new();
    let mut summary = String::from(
        "# The assignment's studies\n\nA vertical unit circle, the bead starting at the bottom at 4 m/s, semi-implicit Euler with Baumgarte, |g| = 9.81.\n\n| study | run | max abs(C)/r | final energy error (m·g·r) | diverged |\n|---|---|---|---|---|\n",
    );
    for study in &studies {
        let mut outputs = Vec::new();
        for run in &study.runs {
            bar.set_message(format!("{}: {}", study.name, run.label));
            let out = simulate(&run.config).map_err(|e| format!("run {} failed: {e}", run.stem))?;
            let csv_path = out_dir.join(format!("{}.csv", run.stem));
            write_csv(&csv_path, &out.rows)?;
            written.push(csv_path);
            let s = summarize(
                &out.rows,
                1.0,
                run.config.bead.mass,
                run.config.params.gravity.y,
            );
            let diverged = out.diverged.as_ref().map_or("no".to_owned(), |(t, why)| {
                format!("at t = {t:.2} s: {why}")
            });
            let _ = writeln!(
                summary,
                "| {} | {} | {:.3e} | {:+.3e} | {} |",
                study.name, run.label, s.max_drift, s.final_energy_error, diverged
            );
            outputs.push((run.label.clone(), out));
            bar.inc(1);
        }
        let paths: Vec<(String, &[Row])> = outputs
            .iter()
            .map(|(l, o)| (l.clone(), o.rows.as_slice()))
            .collect();
        let png = out_dir.join(format!("{}_trajectory.png", study.name));
        plot_trajectories(&png, &study.title, &study.runs[0].config.wire, &paths)?;
        written.push(png);
        let drift: Vec<(String, Vec<(f64, f64)>)> = outputs
            .iter()
            .map(|(l, o)| (l.clone(), o.rows.iter().map(|r| (r.t, r.c.abs())).collect()))
            .collect();
        let png = out_dir.join(format!("{}_drift.png", study.name));
        plot_series(
            &png,
            &format!("{}: drift", study.title),
            "|C| (m)",
            &drift,
            true,
        )?;
        written.push(png);
        let energy: Vec<(String, Vec<(f64, f64)>)> = outputs
            .iter()
            .map(|(l, o)| (l.clone(), o.rows.iter().map(|r| (r.t, r.energy)).collect()))
            .collect();
        let png = out_dir.join(format!("{}_energy.png", study.name));
        plot_series(
            &png,
            &format!("{}: energy", study.title),
            "E (J)",
            &energy,
            false,
        )?;
        written.push(png);
        std::fs::write(out_dir.join("summary.md"), &summary)?;
    }
    bar.finish_and_clear();
    written.push(out_dir.join("summary.md"));
    Ok(written)
}

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

/// Plots |period error| against dt on log–log axes, one line per method.
pub fn plot_convergence(path: &Path, table: &[Comparison]) -> AnalysisResult<()> {
    register_font();
    let valid: Vec<&Comparison> = table
        .iter()
        .filter(|r| r.period_error.is_some_and(|e| e != 0.0))
        .collect();
    let (dt_lo, dt_hi) = valid.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), r| {
        (lo.min(r.dt), hi.max(r.dt))
    });
    let errors = || valid.iter().filter_map(|r| r.period_error).map(f64::abs);
    let (e_lo, e_hi) = (
        errors().fold(f64::INFINITY, f64::min),
        errors().fold(0.0, f64::max),
    );
    if valid.is_empty() {
        return Err("no run measured a period".into());
    }
    let root = BitMapBackend::new(path, FIGURE_SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("Period error against timestep", ("sans-serif", 26))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (dt_lo / 1.3..dt_hi * 1.3).log_scale(),
            (e_lo / 3.0..e_hi * 3.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("dt (s)")
        .y_desc("|period error| (relative)")
        .x_label_formatter(&|v| format!("{v:.3}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    let mut i = 0;
    for method in Method::ALL {
        let series: Vec<(f64, f64)> = valid
            .iter()
            .filter(|r| r.method == method)
            .map(|r| (r.dt, r.period_error.unwrap_or(0.0).abs()))
            .collect();
        if series.is_empty() {
            continue;
        }
        let colour = palette(i);
        i += 1;
        chart
            .draw_series(LineSeries::new(series.clone(), colour.stroke_width(2)))?
            .label(method.to_string())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart.draw_series(
            series
                .iter()
                .map(|p| plotters::prelude::Circle::new(*p, 4, colour.filled())),
        )?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()?;
    root.present()?;
    Ok(())
}
