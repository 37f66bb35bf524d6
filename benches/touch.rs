//! The cost of beads that touch: `cargo bench --bench touch`.
//!
//! - `abacus`: 1,000 beads of radius 0.1 m on 100 rings of radius 1 m,
//!   ten to a ring, with no gravity, each set going at its own speed, so
//!   that they keep striking each other round their rings (elastic,
//!   RATTLE, dt = 1/60 s), against the same beads without radii (they
//!   pass through each other, each stepping alone). Throughput is
//!   bead-steps per second. The plugin as a game gets it: Bevy's
//!   executor, parallel loops from `ParallelStep::default()`. Each also
//!   with the window's [`TimelinePlugin`] recording every step (its 30 s
//!   held to 256 MB), for what the timeline costs.
//! - `pile`: 500 beads of 2 cm poured in rows of 23 into a one-sided bowl
//!   at `e = 0` (`ScenePreset::pile`, RATTLE at 240 Hz), one step at a
//!   time from 0.2 s on, as the pile lands in the bowl and strikes
//!   itself (`pouring`), and from 0.5 s on, the lower rows pressed into
//!   the bowl and those above striking them (`piling`), and from 1 s on,
//!   the pile jammed and settling (`settling`): ten steps each, each
//!   timed once.
//! - `resting`: 10,000 beads of 2 cm in the plane stacked at rest on a
//!   floor in a hundred columns of a hundred, and 10,648 marbles in space
//!   in 22 × 22 columns of 22, every contact pressed or touching: what a
//!   pile at rest costs a step.
//! - `falling`: 10,000 beads of 2 cm in the plane, a hundred rows of a
//!   hundred 10 cm apart across `x ∈ [−5, 5]`, the rows 8 cm apart,
//!   falling in a one-sided bowl of radius 20 m (`plane`), and 10,648
//!   marbles of 2 cm in space, a cube of 22 a side 8 cm apart, falling
//!   in a one-sided sphere of radius 20 m (`space`), each timed over
//!   its first steps, before any lands or two come near: what looking
//!   for beads that may touch costs at that many beads (the broad phase,
//!   each step, over beads a hundred or 22 × 22 deep).

use std::time::Duration;

use bevy::math::DVec2;
use bevy::prelude::*;
use criterion::measurement::WallTime;
use criterion::{
    BenchmarkGroup, BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group,
    criterion_main,
};
use wirebead::headless::Headless;
use wirebead::plugin::{Timeline, TimelinePlugin};
use wirebead::prelude::*;
use wirebead::{BeadRadius, Integrator, SceneFile, ScenePreset, SimClock};

/// Rings in the abacus.
const RINGS: usize = 100;
/// Beads on each ring.
const PER_RING: usize = 10;

/// The abacus, its beads with radii or not, recorded on a timeline or not,
/// stepped once so that its islands are built.
fn abacus(touching: bool, recorded: bool) -> App {
    let params = SimParams {
        gravity: DVec2::ZERO,
        method: Method::new(Integrator::Rattle, None).expect("RATTLE"),
        ..SimParams::default()
    };
    let mut app = Headless::new(WireBeadPlugin::new(params).expect("valid parameters")).build();
    if recorded {
        app.add_plugins(TimelinePlugin);
    }
    let world = app.world_mut();
    for ring in 0..RINGS {
        let centre = DVec2::new(3.0 * (ring % 10) as f64, 3.0 * (ring / 10) as f64);
        let wire = world
            .spawn((
                Wire::circle(1.0).expect("a ring"),
                Transform::from_xyz(centre.x as f32, centre.y as f32, 0.0),
            ))
            .id();
        for k in 0..PER_RING {
            let angle = std::f64::consts::TAU * k as f64 / PER_RING as f64;
            let (along, out) = (
                DVec2::new(-angle.sin(), angle.cos()),
                DVec2::from_angle(angle),
            );
            let speed = ((ring * 7 + k * 3) % 11) as f64 - 5.0;
            let params = BeadParams {
                mass: 1.0 + (k % 3) as f64,
                initial_position: centre + out,
                initial_velocity: along * speed,
            };
            let mut bead = world.spawn((Bead::new(params).expect("a bead"), OnWire(wire)));
            if touching {
                bead.insert(BeadRadius::new(0.1).expect("a radius"));
            }
        }
    }
    app.world_mut().run_schedule(FixedUpdate);
    app
}

fn abacus_group(c: &mut Criterion) {
    let mut group = c.benchmark_group("abacus");
    let n = RINGS * PER_RING;
    group.throughput(Throughput::Elements(n as u64));
    group.sample_size(20);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(4));
    for (name, touching, recorded) in [
        ("touching", true, false),
        ("touching-recorded", true, true),
        ("passing-through", false, false),
        ("passing-through-recorded", false, true),
    ] {
        let mut app = abacus(touching, recorded);
        time_steps(&mut group, &mut app, (name, n));
        if recorded {
            let timeline = app.world().resource::<Timeline>();
            eprintln!(
                "{name}: {} steps kept, {:.0} MB, {:.0} kB a step",
                timeline.len(),
                timeline.bytes() as f64 / 1e6,
                timeline.bytes() as f64 / 1e3 / timeline.len().max(1) as f64
            );
        }
    }
    group.finish();
}

/// Times `app`'s steps in `group` as `(name, beads)`, then checks that no
/// bead stopped.
fn time_steps(
    group: &mut BenchmarkGroup<'_, WallTime>,
    app: &mut App,
    (name, beads): (&str, usize),
) {
    group.bench_function(BenchmarkId::new(name, beads), |b| {
        b.iter(|| app.world_mut().run_schedule(FixedUpdate));
    });
    let world = app.world_mut();
    let stopped = world.query::<&Diverged>().iter(world).count();
    let steps = world.resource::<SimClock>().steps;
    eprintln!("{name}: {steps} steps, {stopped} beads stopped");
    assert_eq!(stopped, 0, "no bead may stop");
}

/// Beads in the pile.
const PILE: usize = 500;
/// Steps poured before the timing starts: 0.2 s at 240 Hz.
const POURED: usize = 48;
/// Steps taken before the second timing: 0.5 s, the lower rows pressed
/// into the bowl and those above striking them.
const PILED: usize = 120;
/// Steps taken before the third timing: 1 s, the pile jammed and
/// settling.
const SETTLING: usize = 240;

fn pile_group(c: &mut Criterion) {
    let preset = ScenePreset::pile(PILE, 23).expect("the pile");
    let mut app = stepped(&SceneFile::Plane(preset), POURED);
    let mut group = step_by_step(c, "pile");
    group.throughput(Throughput::Elements(PILE as u64));
    time_steps(&mut group, &mut app, ("pouring", PILE));
    let taken = app.world().resource::<SimClock>().steps as usize;
    for _ in taken..PILED {
        app.world_mut().run_schedule(FixedUpdate);
    }
    time_steps(&mut group, &mut app, ("piling", PILE));
    let taken = app.world().resource::<SimClock>().steps as usize;
    for _ in taken..SETTLING {
        app.world_mut().run_schedule(FixedUpdate);
    }
    time_steps(&mut group, &mut app, ("settling", PILE));
    group.finish();
}

/// Beads falling in the plane.
const FALLING: usize = 10_000;

/// Marbles to a side of the cube falling in space.
const CUBE: usize = 22;

/// Beads of 2 cm and 1 kg at rest in a one-sided bowl (a circle in the
/// plane, a sphere in space) of radius 20 m, RATTLE at 240 Hz: in the
/// plane [`FALLING`] in rows of a hundred, 10 cm apart across
/// `x ∈ [−5, 5]`, the rows 8 cm apart upward from `y = −19`; in space a
/// cube of [`CUBE`] a side, 8 cm apart, its lowest corner at
/// `(−0.9, −19, −0.9)`.
fn falling_scene(space: bool) -> SceneFile {
    let at = |k: usize| {
        if space {
            let (i, j, l) = (k % CUBE, (k / CUBE) % CUBE, k / (CUBE * CUBE));
            let (x, y, z) = (i as f64, j as f64, l as f64);
            format!(
                "({}, {}, {})",
                -0.9 + 0.08 * x,
                -19.0 + 0.08 * y,
                -0.9 + 0.08 * z
            )
        } else {
            let (i, j) = (k % 100, k / 100);
            format!(
                "({}, {})",
                -5.0 + 0.1 * (i as f64 + 0.5),
                -19.0 + 0.08 * j as f64
            )
        }
    };
    let (beads, dimension, shape) = if space {
        (CUBE * CUBE * CUBE, 3, "Sphere")
    } else {
        (FALLING, 2, "Circle")
    };
    let listed: String = (0..beads)
        .map(|k| {
            format!(
                "(name: \"b{k}\", mass: 1.0, radius: 0.02, initial_position: {}),",
                at(k)
            )
        })
        .collect();
    SceneFile::from_ron(&format!(
        "(name: \"falling\", dimension: {dimension}, \
         params: (timestep: {}, integrator: Rattle), contacts: (restitution: 0.0), \
         wires: [(shape: {shape}((radius: 20.0)), side: Negative, beads: [{listed}])])",
        1.0 / 240.0
    ))
    .expect("the falling beads")
}

/// A group that times steps of many beads one at a time: ten samples of
/// one step each, flat.
fn step_by_step<'a>(c: &'a mut Criterion, name: &str) -> BenchmarkGroup<'a, WallTime> {
    let mut group = c.benchmark_group(name);
    group.sampling_mode(SamplingMode::Flat);
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(1));
    group.measurement_time(Duration::from_millis(1));
    group
}

/// `scene` spawned headless, after `steps` steps.
fn stepped(scene: &SceneFile, steps: usize) -> App {
    let plugin = WireBeadPlugin::new(scene.params().clone()).expect("valid parameters");
    let mut app = Headless::new(plugin).build();
    scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    for _ in 0..steps {
        app.world_mut().run_schedule(FixedUpdate);
    }
    app
}

fn falling_group(c: &mut Criterion) {
    let mut group = step_by_step(c, "falling");
    for (name, space) in [("plane", false), ("space", true)] {
        let mut app = stepped(&falling_scene(space), 1);
        let beads = if space { CUBE * CUBE * CUBE } else { FALLING };
        group.throughput(Throughput::Elements(beads as u64));
        time_steps(&mut group, &mut app, (name, beads));
    }
    group.finish();
}

/// Columns of the resting pile in the plane, and its beads to a column.
const RESTING: usize = 100;

/// Columns to a side of the resting pile in space, and its marbles to a
/// column.
const RESTING_CUBE: usize = 22;

/// A pile at rest on a floor (a one-sided line in the plane, a one-sided
/// plane in space, its positive side up): beads of 2 cm and 1 kg stacked
/// in columns, each touching the ones beside it and pressing on the one
/// below (2r apart, to a millionth of a nanometre's gap), [`RESTING`]
/// columns of [`RESTING`] in the plane, [`RESTING_CUBE`] × [`RESTING_CUBE`]
/// columns of [`RESTING_CUBE`] in space, at `e = 0`, RATTLE at 240 Hz.
/// Every bead is the floor's; those above its first layer start off it.
fn resting_scene(space: bool) -> SceneFile {
    let r = 0.02;
    let spacing = 2.0 * r * (1.0 + 1e-12);
    let (n, side) = if space {
        (RESTING_CUBE.pow(3), RESTING_CUBE)
    } else {
        (RESTING * RESTING, RESTING)
    };
    let at = |k: usize| {
        let (i, up) = (k % side, k / side);
        // The floor is the line of the lowest beads' centres.
        let y = spacing * (up % side) as f64;
        if space {
            let l = up / side;
            format!("({}, {y}, {})", spacing * i as f64, spacing * l as f64)
        } else {
            format!("({}, {y})", spacing * i as f64)
        }
    };
    let listed: String = (0..n)
        .map(|k| {
            format!(
                "(name: \"b{k}\", mass: 1.0, radius: {r}, initial_position: {}),",
                at(k)
            )
        })
        .collect();
    let (dimension, floor) = if space {
        (3, "Plane(())")
    } else {
        (2, "Line(())")
    };
    SceneFile::from_ron(&format!(
        "(name: \"resting\", dimension: {dimension}, \
         params: (timestep: {}, integrator: Rattle), contacts: (restitution: 0.0), \
         wires: [(shape: {floor}, side: Positive, beads: [{listed}])])",
        1.0 / 240.0
    ))
    .expect("the resting pile")
}

/// Steps a resting pile takes before it is timed: its gaps of a
/// millionth of a nanometre closed, every contact pressed.
const SETTLED: usize = 5;

fn resting_group(c: &mut Criterion) {
    let mut group = step_by_step(c, "resting");
    for (name, space) in [("plane", false), ("space", true)] {
        let mut app = stepped(&resting_scene(space), SETTLED);
        let beads = if space {
            RESTING_CUBE.pow(3)
        } else {
            RESTING * RESTING
        };
        group.throughput(Throughput::Elements(beads as u64));
        time_steps(&mut group, &mut app, (name, beads));
    }
    group.finish();
}

criterion_group!(
    benches,
    abacus_group,
    pile_group,
    falling_group,
    resting_group
);
criterion_main!(benches);
