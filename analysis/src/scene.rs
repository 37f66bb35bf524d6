//! Any scene file, in the plane or in space, headless: `simulate --scene`
//! (every bead's state each step, the energy and the largest constraint
//! error) and `compare --scene` (every method on the scene).

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use bevy::prelude::{Entity, FixedLast, Mut, Query, QueryState, Resource, World};
use wirebead::geometry::Coordinates;
use wirebead::headless::{Headless, idle, run_steps, runs_bodies};
use wirebead::preset::table;
pub use wirebead::preset::table::{Measure, Scene, SceneRow, SceneRun, SceneSpace};
use wirebead::{
    BeadPosition, BeadVelocity, Diverged, Method, ParamError, SceneFile, ScenePreset, SimClock,
    SimParams, WireBeadPlugin, WireContact,
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

#[derive(Resource)]
struct Recorder<V: SceneSpace> {
    beads: Vec<Entity>,
    /// The dynamic and kinematic bodies, in the file's order.
    bodies: Vec<Entity>,
    measure: Measure<V>,
    rows: Vec<SceneRow<V>>,
    stopped: bool,
}

impl<V: SceneSpace> Recorder<V> {
    fn record(&mut self, t: f64, beads: &Query<BeadRecord<V>>, world: &World) {
        if self.stopped {
            return;
        }
        let mut bodies = Vec::with_capacity(self.bodies.len());
        for &body in &self.bodies {
            match V::body(world, body) {
                Some(state) => bodies.push(state),
                None => {
                    self.stopped = true;
                    return;
                }
            }
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
        self.rows.push(self.measure.row(t, (x, v, on), bodies));
    }
}

/// What the recorder reads of a bead.
type BeadRecord<V> = (
    &'static BeadPosition<V>,
    &'static BeadVelocity<V>,
    Option<&'static WireContact>,
    Option<&'static Diverged>,
);

fn record_scene<V: SceneSpace>(world: &mut World, beads: &mut QueryState<BeadRecord<V>>) {
    let time = world.resource::<SimClock>().time;
    world.resource_scope(|world, mut recorder: Mut<Recorder<V>>| {
        let query = beads.query(world);
        recorder.record(time, &query, world);
    });
}

/// A headless app running `preset` with `params` (with avian's physics
/// where it has bodies), its beads and its recorded bodies in the file's
/// order; an error in words for a scene with bodies in a build without
/// the avian of its dimension.
fn scene_app<S: Scene>(
    preset: &S,
    params: SimParams,
) -> AnalysisResult<(bevy::app::App, Vec<Entity>, Vec<Entity>)> {
    let plugin = WireBeadPlugin::new(params)?;
    let mut headless = Headless::new(plugin).single_threaded();
    let named = preset.body_names();
    if !named.is_empty() {
        let in_space = S::V::DIMENSION == 3;
        if !runs_bodies(in_space) {
            let feature = if in_space { "avian3d" } else { "avian2d" };
            return Err(format!(
                "scene {:?} has rigid bodies, which this build of the tool cannot run: build it with --features {feature}",
                preset.name()
            )
            .into());
        }
        headless = headless.bodies(in_space);
    }
    let mut app = headless.build();
    let (beads, bodies) = preset.spawn_recorded(&mut app.world_mut().commands());
    app.world_mut().flush();
    // One update with no step: the islands are built and their initial
    // velocities projected onto their constraints, so row 0 is the state
    // the first step starts from.
    idle(&mut app);
    Ok((app, beads, bodies))
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
    let (mut app, beads, bodies) = scene_app(preset, params)?;
    app.insert_resource(Recorder {
        beads: beads.clone(),
        bodies,
        measure,
        rows: Vec::new(),
        stopped: false,
    })
    // When the whole step is done: the plugin's, and avian's after it.
    .add_systems(FixedLast, record_scene::<S::V>);
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
    let body_names = preset.body_names().into_iter();
    Ok(SceneRun {
        names: preset.bead_names(),
        body_names: body_names
            .filter_map(|(n, recorded)| recorded.then_some(n))
            .collect(),
        rows,
        diverged,
    })
}

/// Writes a scene run as CSV to `path` (the columns of
/// [`write_scene_csv`](wirebead::preset::table::write_scene_csv)).
pub fn write_scene_csv<V: SceneSpace>(path: &Path, run: &SceneRun<V>) -> AnalysisResult<()> {
    let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    table::write_scene_csv(file, run).map_err(|e| format!("{}: {e}", path.display()))?;
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
    let (mut app, ..) = scene_app(preset, params)?;
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
