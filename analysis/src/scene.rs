//! Any scene file, in the plane or in space, headless: `simulate --scene`
//! (every bead's state each step, the energy and the largest constraint
//! error) and `compare --scene` (every method on the scene).

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use bevy::math::{DVec2, DVec3};
use bevy::prelude::{
    Commands, Entity, FixedUpdate, IntoScheduleConfigs, Query, Res, ResMut, Resource,
};
use wirebead::geometry::{
    ImplicitCurve, Placed, Pose, Pose3, SpaceMotion, SpaceShape, WireMotion, WireShape, WireSpace,
};
use wirebead::headless::{Headless, idle, run_steps};
use wirebead::{
    BeadPosition, BeadVelocity, Dimension, Diverged, Method, ParamError, SceneFile, SceneLink,
    ScenePreset, SimClock, SimParams, SpaceScene, WireBeadPlugin, WireBeadSystems, WireContact,
};

use crate::AnalysisResult;

/// A scene file in the plane, read and checked; the error names the file.
pub fn load_scene(path: &Path) -> AnalysisResult<ScenePreset> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    ScenePreset::from_ron(&text).map_err(|e| format!("{}: {e}", path.display()).into())
}

/// A scene file of either dimension, read and checked; the error names
/// the file.
pub fn load_scene_file(path: &Path) -> AnalysisResult<SceneFile> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    SceneFile::from_ron(&text).map_err(|e| format!("{}: {e}", path.display()).into())
}

/// The plane or space as the tool measures a scene in it: how far a bead
/// is off its wire.
pub trait SceneSpace: Dimension {
    /// A wire as measured: its shape, resting pose and motion.
    type WireCheck: Clone + std::fmt::Debug + Send + Sync + 'static;
    /// `|C|` of a bead at `x` on `wire` at time `t`: in space, over a
    /// curve's two rows, the length of its offset.
    fn drift(wire: &Self::WireCheck, t: f64, x: Self) -> f64;
}

impl SceneSpace for DVec2 {
    type WireCheck = (WireShape, Pose, WireMotion);
    fn drift((shape, pose, motion): &Self::WireCheck, t: f64, x: Self) -> f64 {
        Placed {
            curve: shape.curve(),
            pose: motion.at(*pose, t).0,
        }
        .value(x)
        .abs()
    }
}

impl SceneSpace for DVec3 {
    type WireCheck = (SpaceShape, Pose3, SpaceMotion);
    fn drift((shape, pose, motion): &Self::WireCheck, t: f64, x: Self) -> f64 {
        let local = motion.at(*pose, t).0.to_local(x);
        shape.rows().iter().fold(0.0, |offset, row| {
            offset.hypot(DVec3::shape_geometry(row, local, None).c)
        })
    }
}

/// A scene of either dimension, as the tool runs it.
pub trait Scene {
    /// Its coordinates.
    type V: SceneSpace;
    /// Its parameters.
    fn params(&self) -> &SimParams;
    /// Its name.
    fn name(&self) -> &str;
    /// Each bead's name, in the file's order.
    fn bead_names(&self) -> Vec<String>;
    /// Spawns it; its beads in the file's order.
    fn spawn(&self, commands: &mut Commands) -> Vec<Entity>;
    /// Each bead's wire, mass, and the links.
    fn measure(&self) -> Result<Measure<Self::V>, String>;
}

impl Scene for ScenePreset {
    type V = DVec2;
    fn params(&self) -> &SimParams {
        &self.params
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn bead_names(&self) -> Vec<String> {
        ScenePreset::bead_names(self)
    }
    fn spawn(&self, commands: &mut Commands) -> Vec<Entity> {
        ScenePreset::spawn(self, commands)
    }
    fn measure(&self) -> Result<Measure<DVec2>, String> {
        let wires = self.wires.iter().map(|wire| {
            let pose = Pose::new(wire.position, wire.angle_degrees.to_radians());
            ((wire.shape.clone(), pose, wire.motion), wire.beads.len())
        });
        Ok(Measure::new(
            wires,
            self.links().map_err(|e| e.to_string())?,
            self.all_beads().map(|b| b.mass).collect(),
            self.params.gravity,
        ))
    }
}

impl Scene for SpaceScene {
    type V = DVec3;
    fn params(&self) -> &SimParams {
        &self.params.0
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn bead_names(&self) -> Vec<String> {
        SpaceScene::bead_names(self)
    }
    fn spawn(&self, commands: &mut Commands) -> Vec<Entity> {
        SpaceScene::spawn(self, commands)
    }
    fn measure(&self) -> Result<Measure<DVec3>, String> {
        let mut wires = Vec::new();
        for wire in &self.wires {
            let pose = wire.pose().map_err(|e| e.to_string())?;
            let check = (wire.shape.shape(), pose, wire.motion.motion());
            wires.push((check, wire.beads.len()));
        }
        Ok(Measure::new(
            wires.into_iter(),
            self.links().map_err(|e| e.to_string())?,
            self.all_beads().map(|b| b.mass).collect(),
            self.params.0.gravity_in_space(),
        ))
    }
}

/// One constraint to measure, with beads as indices in the file's order.
#[derive(Clone, Debug)]
enum Check<V: SceneSpace> {
    /// A bead on a wire.
    Wire(usize, V::WireCheck),
    Rod(usize, usize, f64),
    Pin(usize, V),
}

/// What a scene's rows are measured against: its constraints, springs and
/// masses.
#[derive(Clone, Debug)]
pub struct Measure<V: SceneSpace> {
    checks: Vec<Check<V>>,
    springs: Vec<(usize, usize, f64, f64)>,
    masses: Vec<f64>,
    gravity: V,
}

/// `|v|`.
fn length<V: SceneSpace>(v: V) -> f64 {
    v.dot(v).sqrt()
}

impl<V: SceneSpace> Measure<V> {
    /// A scene's measure: each wire with its number of beads (the wires'
    /// beads come first in the file's order), the links, every bead's
    /// mass and gravity.
    fn new(
        wires: impl Iterator<Item = (V::WireCheck, usize)>,
        links: Vec<SceneLink<V>>,
        masses: Vec<f64>,
        gravity: V,
    ) -> Self {
        let mut checks = Vec::new();
        let mut bead = 0;
        for (wire, count) in wires {
            for _ in 0..count {
                checks.push(Check::Wire(bead, wire.clone()));
                bead += 1;
            }
        }
        let mut springs = Vec::new();
        for link in links {
            match link {
                SceneLink::Rod { a, b, length } => checks.push(Check::Rod(a, b, length)),
                SceneLink::Pin { bead, at } => checks.push(Check::Pin(bead, at)),
                SceneLink::Spring { a, b, spring } => {
                    springs.push((a, b, spring.rest_length, spring.stiffness))
                }
            }
        }
        Self {
            checks,
            springs,
            masses,
            gravity,
        }
    }

    /// The largest `|C|` at time `t` of every constraint, wires included
    /// (a bead in flight off its wire left out).
    fn max_abs_c(&self, t: f64, x: &[V], on: &[bool]) -> f64 {
        self.checks
            .iter()
            .map(|check| match check {
                Check::Wire(b, _) if !on[*b] => 0.0,
                Check::Wire(b, wire) => V::drift(wire, t, x[*b]),
                Check::Rod(a, b, rod) => (length(x[*a] - x[*b]) - rod).abs(),
                Check::Pin(b, at) => length(x[*b] - *at),
            })
            .fold(0.0, f64::max)
    }

    /// Kinetic plus gravitational energy of every bead.
    fn energy(&self, x: &[V], v: &[V]) -> f64 {
        self.masses
            .iter()
            .zip(x.iter().zip(v))
            .map(|(m, (x, v))| 0.5 * m * v.dot(*v) - m * self.gravity.dot(*x))
            .sum()
    }

    /// The energy stored in the springs.
    fn spring_energy(&self, x: &[V]) -> f64 {
        self.springs
            .iter()
            .map(|&(a, b, rest, k)| {
                let stretch = length(x[a] - x[b]) - rest;
                0.5 * k * stretch * stretch
            })
            .sum()
    }
}

/// One row of a scene run: after a step, or at t = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneRow<V = DVec2> {
    /// Time.
    pub t: f64,
    /// Every bead's position, in the file's order.
    pub positions: Vec<V>,
    /// Every bead's velocity.
    pub velocities: Vec<V>,
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
pub struct SceneRun<V = DVec2> {
    /// Every bead's name, in the file's order.
    pub names: Vec<String>,
    /// One row per step from t = 0, up to a divergence.
    pub rows: Vec<SceneRow<V>>,
    /// When a bead diverged, and why, if one did.
    pub diverged: Option<(f64, String)>,
}

#[derive(Resource)]
struct Recorder<V: SceneSpace> {
    beads: Vec<Entity>,
    measure: Measure<V>,
    rows: Vec<SceneRow<V>>,
    stopped: bool,
}

impl<V: SceneSpace> Recorder<V> {
    fn record(&mut self, t: f64, beads: &Query<BeadRecord<V>>) {
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
type BeadRecord<V> = (
    &'static BeadPosition<V>,
    &'static BeadVelocity<V>,
    Option<&'static WireContact>,
    Option<&'static Diverged>,
);

fn record_scene<V: SceneSpace>(
    clock: Res<SimClock>,
    beads: Query<BeadRecord<V>>,
    mut recorder: ResMut<Recorder<V>>,
) {
    recorder.record(clock.time, &beads);
}

/// A headless app running `preset` with `params`, and its beads in the
/// file's order.
fn scene_app<S: Scene>(
    preset: &S,
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
pub fn simulate_scene<S: Scene>(
    preset: &S,
    params: SimParams,
    duration: f64,
) -> AnalysisResult<SceneRun<S::V>> {
    if !(duration.is_finite() && duration > 0.0) {
        return Err(ParamError::NotPositive {
            name: "duration",
            value: duration,
        }
        .into());
    }
    let steps = (duration / params.timestep).round() as u32;
    let measure = preset.measure()?;
    let (mut app, beads) = scene_app(preset, params)?;
    app.insert_resource(Recorder {
        beads: beads.clone(),
        measure,
        rows: Vec::new(),
        stopped: false,
    })
    .add_systems(
        FixedUpdate,
        record_scene::<S::V>.after(WireBeadSystems::Writeback),
    );
    app.world_mut().run_system_cached(record_scene::<S::V>).ok();
    let bar = crate::run::progress(u64::from(steps), "steps");
    let mut done = 0;
    while done < steps && !app.world().resource::<Recorder<S::V>>().stopped {
        let batch = (steps - done).min(10);
        run_steps(&mut app, batch);
        done += batch;
        bar.inc(u64::from(batch));
    }
    bar.finish_and_clear();
    let diverged = beads.iter().find_map(|&b| {
        app.world()
            .get::<Diverged>(b)
            .map(|d| (d.time, d.reason.to_string()))
    });
    let rows = std::mem::take(&mut app.world_mut().resource_mut::<Recorder<S::V>>().rows);
    Ok(SceneRun {
        names: preset.bead_names(),
        rows,
        diverged,
    })
}

/// Writes a scene run as CSV: `t`, then for each bead in the file's order
/// `<name>.x,<name>.y,<name>.vx,<name>.vy,<name>.on` in the plane, or
/// `<name>.x,<name>.y,<name>.z,<name>.vx,<name>.vy,<name>.vz,<name>.on` in
/// space (`on` 1 while held on its wire, 0 in flight off a one-sided wire
/// or on no wire), then `energy,max_abs_c`.
pub fn write_scene_csv<V: SceneSpace>(path: &Path, run: &SceneRun<V>) -> AnalysisResult<()> {
    let mut writer =
        csv::Writer::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let axes = &["x", "y", "z"][..V::DIMENSION];
    let mut header = vec!["t".to_owned()];
    for name in &run.names {
        let columns = axes
            .iter()
            .map(|a| a.to_string())
            .chain(axes.iter().map(|a| format!("v{a}")))
            .chain(["on".to_owned()]);
        header.extend(columns.map(|c| format!("{name}.{c}")));
    }
    header.extend(["energy".to_owned(), "max_abs_c".to_owned()]);
    writer.write_record(&header)?;
    for row in &run.rows {
        let mut record = vec![row.t];
        for ((x, v), on) in row.positions.iter().zip(&row.velocities).zip(&row.on) {
            record.extend(&x.xyz().to_array()[..V::DIMENSION]);
            record.extend(&v.xyz().to_array()[..V::DIMENSION]);
            record.push(f64::from(u8::from(*on)));
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
pub fn compare_scene<S: Scene>(
    preset: &S,
    duration: f64,
    dts: &[f64],
) -> AnalysisResult<Vec<SceneComparison>> {
    let mut table = Vec::new();
    for method in Method::ALL {
        for &dt in dts {
            let params = SimParams {
                timestep: dt,
                method,
                ..preset.params().clone()
            };
            let run = simulate_scene(preset, params.clone(), duration)
                .map_err(|e| format!("{method} at dt = {dt}: {e}"))?;
            let total = |r: &SceneRow<S::V>| r.energy + r.spring_energy;
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
fn time_scene<S: Scene>(preset: &S, params: SimParams) -> AnalysisResult<f64> {
    let (mut app, _) = scene_app(preset, params)?;
    run_steps(&mut app, 30);
    let steps = 300;
    let clock = Instant::now();
    run_steps(&mut app, steps);
    Ok(clock.elapsed().as_secs_f64() * 1e6 / f64::from(steps))
}

/// The scene comparison as a markdown table.
pub fn scene_comparison_markdown<S: Scene>(
    table: &[SceneComparison],
    preset: &S,
    duration: f64,
) -> String {
    let mut md = format!(
        "# Every method on \"{}\"\n\n{} beads, {duration} s simulated. max abs(C) is the largest constraint error of any rod, pin or wire over the run; energy error is max abs(E - E0), E the kinetic, gravitational and spring energy of all beads; cost is the whole plugin step (single-threaded), per step.\n\n| integrator | stabilization | dt (s) | max abs(C) | energy error (J) | cost (µs/step) |\n|---|---|---|---|---|---|\n",
        preset.name(),
        preset.bead_names().len(),
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
