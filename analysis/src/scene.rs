//! Any scene file, headless: `simulate --scene` (every bead's state each
//! step, the energy and the largest constraint error) and
//! `compare --scene` (every method on the scene).

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use bevy::math::DVec2;
use bevy::prelude::{Entity, FixedUpdate, IntoScheduleConfigs, Query, Res, ResMut, Resource};
use wirebead::geometry::{ImplicitCurve, Placed, Pose, WireMotion, WireShape};
use wirebead::headless::{Headless, idle, run_steps};
use wirebead::{
    BeadPosition, BeadVelocity, Diverged, Method, ParamError, SceneLink, ScenePreset, SimClock,
    SimParams, WireBeadPlugin, WireBeadSystems, WireContact,
};

use crate::AnalysisResult;

/// A scene file read and checked; the error names the file.
pub fn load_scene(path: &Path) -> AnalysisResult<ScenePreset> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    ScenePreset::from_ron(&text).map_err(|e| format!("{}: {e}", path.display()).into())
}

/// One constraint to measure, with beads as indices in the file's order.
#[derive(Clone, Debug)]
enum Check {
    /// A bead on a wire resting at the pose, moving by the motion.
    Wire(usize, WireShape, Pose, WireMotion),
    Rod(usize, usize, f64),
    Pin(usize, DVec2),
}

/// What a scene's rows are measured against: its constraints, springs and
/// masses.
#[derive(Clone, Debug)]
struct Measure {
    checks: Vec<Check>,
    springs: Vec<(usize, usize, f64, f64)>,
    masses: Vec<f64>,
    gravity: DVec2,
}

impl Measure {
    fn new(preset: &ScenePreset) -> Result<Self, String> {
        let mut checks = Vec::new();
        let mut bead = 0;
        for wire in &preset.wires {
            let pose = Pose::new(wire.position, wire.angle_degrees.to_radians());
            for _ in &wire.beads {
                checks.push(Check::Wire(bead, wire.shape.clone(), pose, wire.motion));
                bead += 1;
            }
        }
        let mut springs = Vec::new();
        for link in preset.links().map_err(|e| e.to_string())? {
            match link {
                SceneLink::Rod { a, b, length } => checks.push(Check::Rod(a, b, length)),
                SceneLink::Pin { bead, at } => checks.push(Check::Pin(bead, at)),
                SceneLink::Spring { a, b, spring } => {
                    springs.push((a, b, spring.rest_length, spring.stiffness))
                }
            }
        }
        Ok(Self {
            checks,
            springs,
            masses: preset.all_beads().map(|b| b.mass).collect(),
            gravity: preset.params.gravity,
        })
    }

    /// The largest `|C|` at time `t` of every constraint, wires included
    /// (a bead in flight off its wire left out).
    fn max_abs_c(&self, t: f64, x: &[DVec2], on: &[bool]) -> f64 {
        self.checks
            .iter()
            .map(|check| match check {
                Check::Wire(b, _, _, _) if !on[*b] => 0.0,
                Check::Wire(b, shape, pose, motion) => Placed {
                    curve: shape.curve(),
                    pose: motion.at(*pose, t).0,
                }
                .value(x[*b])
                .abs(),
                Check::Rod(a, b, length) => ((x[*a] - x[*b]).length() - length).abs(),
                Check::Pin(b, at) => (x[*b] - *at).length(),
            })
            .fold(0.0, f64::max)
    }

    /// Kinetic plus gravitational energy of every bead.
    fn energy(&self, x: &[DVec2], v: &[DVec2]) -> f64 {
        self.masses
            .iter()
            .zip(x.iter().zip(v))
            .map(|(m, (x, v))| 0.5 * m * v.length_squared() - m * self.gravity.dot(*x))
            .sum()
    }

    /// The energy stored in the springs.
    fn spring_energy(&self, x: &[DVec2]) -> f64 {
        self.springs
            .iter()
            .map(|&(a, b, rest, k)| {
                let stretch = (x[a] - x[b]).length() - rest;
                0.5 * k * stretch * stretch
            })
            .sum()
    }
}

/// One row of a scene run: after a step, or at t = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneRow {
    /// Time.
    pub t: f64,
    /// Every bead's position, in the file's order.
    pub positions: Vec<DVec2>,
    /// Every bead's velocity.
    pub velocities: Vec<DVec2>,
    /// Whether each bead is held on its wire (false in flight off a
    /// one-sided wire, and for a bead on no wire).
    pub on: Vec<bool>,
    /// Kinetic plus gravitational energy of all beads.
    pub energy: f64,
    /// The energy stored in the springs (not a CSV column; `compare` adds
    /// it to `energy`).
    pub spring_energy: f64,
    /// The largest `|C|` of all constraints, wires included.
    pub max_abs_c: f64,
}

/// What a scene run produced.
#[derive(Clone, Debug, Default)]
pub struct SceneRun {
    /// Every bead's name, in the file's order.
    pub names: Vec<String>,
    /// One row per step from t = 0, up to a divergence.
    pub rows: Vec<SceneRow>,
    /// When a bead diverged, and why, if one did.
    pub diverged: Option<(f64, String)>,
}

#[derive(Resource)]
struct Recorder {
    beads: Vec<Entity>,
    measure: Measure,
    rows: Vec<SceneRow>,
    stopped: bool,
}

impl Recorder {
    fn record(&mut self, t: f64, beads: &Query<BeadRecord>) {
        if self.stopped {
            return;
        }
        let mut x = Vec::with_capacity(self.beads.len());
        let mut v = Vec::with_capacity(self.beads.len());
        let mut on = Vec::with_capacity(self.beads.len());
        for &entity in &self.beads {
            match beads.get(entity) {
                Ok((position, velocity, contact, None)) => {
                    x.push(position.0);
                    v.push(velocity.0);
                    on.push(contact.is_some_and(WireContact::is_on));
                }
                _ => {
                    self.stopped = true;
                    return;
                }
            }
        }
        self.rows.push(SceneRow {
            t,
            energy: self.measure.energy(&x, &v),
            spring_energy: self.measure.spring_energy(&x),
            max_abs_c: self.measure.max_abs_c(t, &x, &on),
            positions: x,
            velocities: v,
            on,
        });
    }
}

/// What the recorder reads of a bead.
type BeadRecord = (
    &'static BeadPosition,
    &'static BeadVelocity,
    Option<&'static WireContact>,
    Option<&'static Diverged>,
);

fn record_scene(clock: Res<SimClock>, beads: Query<BeadRecord>, mut recorder: ResMut<Recorder>) {
    recorder.record(clock.time, &beads);
}

/// A headless app running `preset` with `params`, and its beads in the
/// file's order.
fn scene_app(
    preset: &ScenePreset,
    params: SimParams,
) -> Result<(bevy::app::App, Vec<Entity>), ParamError> {
    let plugin = WireBeadPlugin::new(params)?;
    let mut app = Headless::new(plugin).single_threaded().build();
    let beads = preset.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    // One update with no step: the islands are built and their initial
    // velocities projected onto their constraints, so row 0 is the state
    // the first step starts from.
    idle(&mut app);
    Ok((app, beads))
}

/// Runs `preset` headless for `duration` seconds with `params` (the
/// scene's own, or overridden), a row per step.
pub fn simulate_scene(
    preset: &ScenePreset,
    params: SimParams,
    duration: f64,
) -> AnalysisResult<SceneRun> {
    if !(duration.is_finite() && duration > 0.0) {
        return Err(ParamError::NotPositive {
            name: "duration",
            value: duration,
        }
        .into());
    }
    let steps = (duration / params.timestep).round() as u32;
    let measure = Measure::new(preset)?;
    let (mut app, beads) = scene_app(preset, params)?;
    app.insert_resource(Recorder {
        beads: beads.clone(),
        measure,
        rows: Vec::new(),
        stopped: false,
    })
    .add_systems(FixedUpdate, record_scene.after(WireBeadSystems::Writeback));
    app.world_mut().run_system_cached(record_scene).ok();
    let mut done = 0;
    while done < steps && !app.world().resource::<Recorder>().stopped {
        let batch = (steps - done).min(500);
        run_steps(&mut app, batch);
        done += batch;
    }
    let diverged = beads.iter().find_map(|&b| {
        app.world()
            .get::<Diverged>(b)
            .map(|d| (d.time, d.reason.to_string()))
    });
    let rows = std::mem::take(&mut app.world_mut().resource_mut::<Recorder>().rows);
    Ok(SceneRun {
        names: preset.bead_names(),
        rows,
        diverged,
    })
}

/// Writes a scene run as CSV: `t`, then
/// `<name>.x,<name>.y,<name>.vx,<name>.vy,<name>.on` for each bead in the
/// file's order (`on` 1 while held on its wire, 0 in flight off a one-sided
/// wire or on no wire), then `energy,max_abs_c`.
pub fn write_scene_csv(path: &Path, run: &SceneRun) -> AnalysisResult<()> {
    let mut writer =
        csv::Writer::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut header = vec!["t".to_owned()];
    for name in &run.names {
        header.extend(["x", "y", "vx", "vy", "on"].map(|c| format!("{name}.{c}")));
    }
    header.extend(["energy".to_owned(), "max_abs_c".to_owned()]);
    writer.write_record(&header)?;
    for row in &run.rows {
        let mut record = vec![row.t];
        for ((x, v), on) in row.positions.iter().zip(&row.velocities).zip(&row.on) {
            record.extend([x.x, x.y, v.x, v.y, f64::from(u8::from(*on))]);
        }
        record.extend([row.energy, row.max_abs_c]);
        writer.write_record(record.iter().map(|v| format!("{v:e}")))?;
    }
    writer.flush()?;
    Ok(())
}

/// One method on one scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneComparison {
    /// The method.
    pub method: Method,
    /// The step.
    pub dt: f64,
    /// The largest `|C|` of any constraint over the run.
    pub max_abs_c: f64,
    /// max |E − E₀| over the run, E with the springs' energy.
    pub energy_error: f64,
    /// When it diverged, if it did.
    pub diverged: Option<f64>,
    /// Wall-clock microseconds per step of the whole plugin step.
    pub us_per_step: f64,
}

/// Every method at every step in `dts` on `preset`.
pub fn compare_scene(
    preset: &ScenePreset,
    duration: f64,
    dts: &[f64],
) -> AnalysisResult<Vec<SceneComparison>> {
    let mut table = Vec::new();
    for method in Method::ALL {
        for &dt in dts {
            let params = SimParams {
                timestep: dt,
                method,
                ..preset.params.clone()
            };
            let run = simulate_scene(preset, params.clone(), duration)
                .map_err(|e| format!("{method} at dt = {dt}: {e}"))?;
            let total = |r: &SceneRow| r.energy + r.spring_energy;
            let e0 = run.rows.first().map_or(0.0, total);
            table.push(SceneComparison {
                method,
                dt,
                max_abs_c: run.rows.iter().map(|r| r.max_abs_c).fold(0.0, f64::max),
                energy_error: run
                    .rows
                    .iter()
                    .map(|r| (total(r) - e0).abs())
                    .fold(0.0, f64::max),
                diverged: run.diverged.map(|(t, _)| t),
                us_per_step: time_scene(preset, params)?,
            });
        }
    }
    Ok(table)
}

/// Microseconds per step of the plugin on `preset` (no recording), from
/// 300 steps after 30 to warm up.
fn time_scene(preset: &ScenePreset, params: SimParams) -> AnalysisResult<f64> {
    let (mut app, _) = scene_app(preset, params)?;
    run_steps(&mut app, 30);
    let steps = 300;
    let clock = Instant::now();
    run_steps(&mut app, steps);
    Ok(clock.elapsed().as_secs_f64() * 1e6 / f64::from(steps))
}

/// The scene comparison as a markdown table.
pub fn scene_comparison_markdown(
    table: &[SceneComparison],
    preset: &ScenePreset,
    duration: f64,
) -> String {
    let mut md = format!(
        "# Every method on \"{}\"\n\n{} beads, {duration} s simulated. max abs(C) is the largest constraint error of any rod, pin or wire over the run; energy error is max abs(E - E0), E the kinetic, gravitational and spring energy of all beads; cost is the whole plugin step (single-threaded), per step.\n\n| integrator | stabilization | dt (s) | max abs(C) | energy error (J) | cost (µs/step) |\n|---|---|---|---|---|---|\n",
        preset.name,
        preset.all_beads().count(),
    );
    for row in table {
        let stabilization = row
            .method
            .stabilization()
            .map_or("—".to_owned(), |s| s.to_string());
        let (c, e) = match row.diverged {
            Some(t) => (format!("diverged at {t:.3} s"), "—".to_owned()),
            None => (
                format!("{:.2e}", row.max_abs_c),
                format!("{:.2e}", row.energy_error),
            ),
        };
        let _ = writeln!(
            md,
            "| {} | {stabilization} | {:.5} | {c} | {e} | {:.1} |",
            row.method.integrator(),
            row.dt,
            row.us_per_step
        );
    }
    md
}
