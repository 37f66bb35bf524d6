//! Headless runs through the plugin: their configuration, one row of state
//! and diagnostics per step, the CSV they are written to, and their summary.

use std::path::Path;

use bevy::math::DVec2;
use bevy::prelude::{FixedUpdate, IntoScheduleConfigs, Query, Res, ResMut, Resource, Without};
use indicatif::{ProgressBar, ProgressStyle};
use wirebead::headless::{Headless, idle, run_steps};
use wirebead::{
    Bead, BeadDiagnostics, BeadParams, BeadPosition, BeadVelocity, Diverged, OnWire, ParamError,
    Restart, SimClock, SimParams, Wire, WireBeadPlugin, WireBeadSystems, WireShape,
};

use crate::AnalysisResult;

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
    beads: Query<(&BeadPosition, &BeadVelocity, &BeadDiagnostics), Without<Diverged>>,
    clock: Res<SimClock>,
    mut rows: ResMut<Rows>,
) {
    for (position, velocity, d) in &beads {
        rows.0.push(Row {
            t: clock.time,
            position: position.0,
            velocity: velocity.0,
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

pub(crate) fn progress(len: u64, message: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template("{msg:>10} [{bar:40}] {pos}/{len} {wide_msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(message.to_owned());
    bar
}
