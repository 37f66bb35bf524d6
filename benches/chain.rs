//! The coupled solve's cost: `cargo bench --bench chain`.
//!
//! - `islands`: N pendulums on carts through the plugin (single-threaded),
//!   each a cart of 2 kg on its own horizontal rail and a 1 kg bob on a rod
//!   of 1 m released 30° from the vertical, RATTLE at 1/60 s: N islands of
//!   two beads. Throughput is bead-steps.
//! - `spheres`: N spherical pendulums in space through the plugin
//!   (single-threaded): a bead of 1 kg on a sphere of 0.8 m each, released
//!   from rest at 90° from the bottom, RATTLE at 1/60 s. Each bead,
//!   alone on its sphere, takes the lone step, eight at a time in the
//!   batched step. Throughput is bead-steps.
//! - `chain`: a rope of N rods hanging from a pin (N + 1 beads of 1 kg,
//!   the first held by the pin's two rows, links of 0.1 m, |g| = 10),
//!   released horizontal, stepped by RATTLE through the pure `Island` (no
//!   ECS), at 1/60 s and at 1/960 s. Each iteration runs the first quarter
//!   second from the release (15 steps at 1/60 s, 240 at 1/960 s), so
//!   every sample does the same work; throughput is rod-steps. At 1/60 s
//!   a long rope's steps are split into substeps where RATTLE's position
//!   solve has no root; at 1/960 s none is, at any N. Before a benchmark
//!   is timed, one run prints the largest relative stretch `max |C| / L`
//!   beside its rounding floor (an ulp of the largest coordinate over `L`:
//!   a rope of N links reaches N·L from the pin, so the floor grows as N),
//!   the substeps the steps took, and the energy change.

use std::hint::black_box;
use std::time::Duration;

use bevy::math::DVec2;
use bevy::prelude::*;
use criterion::{BatchSize, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use wirebead::geometry::Sphere;
use wirebead::headless::Headless;
use wirebead::solver::{BeadState, Island, IslandWork, LinearForce, Method, StepSettings};
use wirebead::{
    Bead, OnWire, ParallelStep, Rod, SimParams, SpaceBead, SpaceWire, Wire, WireBeadPlugin,
};

#[path = "support/rope.rs"]
mod rope;

/// What each iteration runs: the first quarter second after the release.
const SECONDS: f64 = 0.25;
const SIZES: [usize; 5] = [10, 100, 1_000, 10_000, 100_000];
/// The step sizes: the game's 1/60 s, and one at which the rope's RATTLE
/// steps need no substeps over that quarter second.
const STEPS_PER_SECOND: [u32; 2] = [60, 960];

fn settings(per_second: u32) -> StepSettings {
    StepSettings {
        dt: 1.0 / f64::from(per_second),
        method: Method::Rattle,
        alpha: 0.0,
        beta: 0.0,
        drift_bound: 1.0,
    }
}

/// What a run of the first quarter second measured.
struct Measured {
    /// The largest relative stretch `max |C| / L`.
    stretch: f64,
    /// The rounding floor of that stretch: one ulp of the largest
    /// coordinate, over `L`.
    floor: f64,
    /// The most substeps a step took, and their total.
    most: u32,
    total: u32,
}

/// The steps of the first quarter second at `per_second` steps a second.
fn steps(per_second: u32) -> usize {
    (SECONDS * f64::from(per_second)).round() as usize
}

/// The first quarter second from `states` at `per_second` steps a second,
/// with a fresh work (so every iteration starts from whole steps), or the
/// step that failed and why.
fn run(
    island: &Island,
    states: &mut [BeadState],
    forces: &[LinearForce],
    per_second: u32,
) -> Result<Measured, String> {
    let s = settings(per_second);
    let mut work = IslandWork::default();
    let mut m = Measured {
        stretch: 0.0,
        floor: 0.0,
        most: 0,
        total: 0,
    };
    for k in 0..steps(per_second) {
        island
            .step(states, forces, &s, &mut work)
            .map_err(|e| format!("step {k}: {e}"))?;
        m.most = m.most.max(work.substeps());
        m.total += work.substeps();
        m.stretch = m.stretch.max(rope::max_stretch(states));
        let far = states
            .iter()
            .map(|s| s.position.abs().max_element())
            .fold(0.0, f64::max);
        m.floor = m.floor.max(f64::EPSILON * far / rope::LINK);
    }
    Ok(m)
}

fn chain(c: &mut Criterion) {
    let mut group = c.benchmark_group("chain");
    for per_second in STEPS_PER_SECOND {
        let steps = steps(per_second);
        for n in SIZES {
            if per_second > 60 && n < 1_000 {
                // Short ropes need no substeps at 1/60 s already.
                continue;
            }
            group.throughput(Throughput::Elements((n * steps) as u64));
            group.sample_size(10);
            group.warm_up_time(Duration::from_millis(500));
            group.measurement_time(Duration::from_secs(if n >= 10_000 { 20 } else { 5 }));
            let (island, start, forces) = (rope::island(n), rope::released(n), rope::weights(n));
            let name = format!("rattle-1/{per_second}");
            let id = format!("chain/{name}/{n}");
            // The accuracy and substeps, reported once, where the filter
            // selects the benchmark (criterion calls this closure only then).
            let mut reported = false;
            group.bench_function(BenchmarkId::new(name, n), |b| {
                if !reported {
                    reported = true;
                    let mut states = start.clone();
                    match run(&island, &mut states, &forces, per_second) {
                        Ok(m) => eprintln!(
                            "{id}: max |C|/L {:.1e} (rounding floor {:.1e}), substeps {} in {steps} steps (at most {}), energy change {:.3e} J",
                            m.stretch,
                            m.floor,
                            m.total,
                            m.most,
                            rope::energy(&states) - rope::energy(&start)
                        ),
                        Err(why) => eprintln!("{id}: {why}"),
                    }
                }
                b.iter_batched_ref(
                    || start.clone(),
                    |states| black_box(run(&island, states, &forces, per_second)),
                    BatchSize::LargeInput,
                );
            });
        }
    }
    group.finish();
}

/// A single-threaded app stepping with RATTLE at 1/60 s.
fn rattle_app() -> App {
    let params = SimParams {
        method: Method::Rattle,
        ..SimParams::default()
    };
    let plugin = WireBeadPlugin::new(params).expect("valid parameters");
    Headless::new(plugin)
        .single_threaded()
        .parallel(ParallelStep::OFF)
        .build()
}

/// `n` pendulums on carts, each on its own rail 3 m below the last.
fn carts(n: usize) -> App {
    let mut app = rattle_app();
    let world = app.world_mut();
    let swing = DVec2::new(30f64.to_radians().sin(), -30f64.to_radians().cos());
    for i in 0..n {
        let y = -3.0 * i as f64;
        let rail = world
            .spawn((Wire::line(), Transform::from_xyz(0.0, y as f32, 0.0)))
            .id();
        let cart = Bead::at_rest(2.0, DVec2::new(0.0, y)).expect("valid cart");
        let cart = world.spawn((cart, OnWire(rail))).id();
        let bob = Bead::at_rest(1.0, DVec2::new(0.0, y) + swing).expect("valid bob");
        let bob = world.spawn(bob).id();
        world.spawn(Rod::new(cart, bob, 1.0).expect("valid rod"));
    }
    // The first step builds the islands.
    app.world_mut().run_schedule(FixedUpdate);
    app
}

fn islands(c: &mut Criterion) {
    bench_apps(c, "islands", "cart-rattle-1/60", 2, carts);
}

/// `n` spherical pendulums in space, each on its own sphere 3 m from the
/// last.
fn spheres(n: usize) -> App {
    let mut app = rattle_app();
    let world = app.world_mut();
    for i in 0..n {
        let origin = Vec3::new(3.0 * i as f32, 0.0, 0.0);
        let sphere = SpaceWire::surface_of(Sphere { radius: 0.8 });
        let wire = world
            .spawn((sphere, Transform::from_translation(origin)))
            .id();
        let start = origin.as_dvec3() + bevy::math::DVec3::new(0.8, 0.0, 0.0);
        let bead = SpaceBead::at_rest(1.0, start).expect("valid bead");
        world.spawn((bead, OnWire(wire)));
    }
    // The first step fills the wire table.
    app.world_mut().run_schedule(FixedUpdate);
    app
}

fn spheres_in_space(c: &mut Criterion) {
    bench_apps(c, "spheres", "sphere-rattle-1/60", 1, spheres);
}

/// Times one fixed step of the app `make(n)` makes for N = 100, 1,000 and
/// 10,000, `beads` beads to each of the N, in group `group` as `name`.
fn bench_apps(c: &mut Criterion, group: &str, name: &str, beads: u64, make: fn(usize) -> App) {
    let mut group = c.benchmark_group(group);
    for n in [100, 1_000, 10_000] {
        group.throughput(Throughput::Elements(beads * n as u64));
        group.sample_size(10);
        group.warm_up_time(Duration::from_millis(500));
        group.measurement_time(Duration::from_secs(5));
        let mut app = make(n);
        group.bench_function(BenchmarkId::new(name, n), |b| {
            b.iter(|| app.world_mut().run_schedule(FixedUpdate));
        });
    }
    group.finish();
}

criterion_group!(benches, islands, spheres_in_space, chain);
criterion_main!(benches);
