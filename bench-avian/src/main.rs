//! wirebead against avian2d on three jobs, one per subcommand:
//!
//! ```text
//! cargo run --release -p wirebead-vs-avian
//! cargo run --release -p wirebead-vs-avian -- circle [--steps 600] [--many 10000] [--warm-up 1]
//! cargo run --release -p wirebead-vs-avian -- rope [--steps 600] [--sizes 10,100,1000] [--substeps 20,50,100,200]
//! cargo run --release -p wirebead-vs-avian -- carts [--steps 600] [--sizes 1000,10000] [--substeps 50] [--rail prismatic|locked]
//! cargo run --release -p wirebead-vs-avian -- spheres [--steps 600] [--sizes 1,10000]
//! cargo run --release -p wirebead-vs-avian -- touch [--dt 0.016667] [--steps 120] [--substeps 50]
//! cargo run --release -p wirebead-vs-avian -- pile [--beads 1000] [--steps 180] [--piles plane|space|both] [--budget 300]
//! cargo run --release -p wirebead-vs-avian -- path [--steps 600] [--sizes 1,1000] [--space]
//! ```
//!
//! - `circle` (the default, also without a subcommand): a bead on a circle
//!   of radius 0.8 under |g| = 10, released from rest at 90°, dt = 1/60,
//!   10 s. Prints a markdown table: energy change, max radial error and
//!   period error of each of our methods and of avian2d (a body on a
//!   `DistanceJoint` to a static anchor), and the wall time per bead-step
//!   at N = 1 and N = 10,000 pendulums.
//! - `rope`: a rope of N rods of 0.1 m hanging from a pin, released
//!   horizontal, our pure `Island` with RATTLE against avian2d's
//!   `DistanceJoint`s at its default 6 substeps and at more (see
//!   [`rope`]). Prints ns per rod-step, max relative stretch and energy
//!   change per run, and the time ratios avian2d / ours.
//! - `carts`: N pendulums on carts, our plugin against avian2d (a
//!   `PrismaticJoint` or `LockedAxes` rail and a `DistanceJoint` rod) at
//!   6 and 50 substeps (see [`carts`]). Prints ns per bead-step, rod and
//!   rail errors and pendulum 0's energy change per run, and the time
//!   ratios avian2d / ours.
//! - `spheres`: N conical pendulums on spheres in space, our plugin with
//!   each method against avian3d (a body on a `DistanceJoint`, see
//!   [`spheres`]). Prints ns per bead-step, energy and height change and
//!   the worst radial error.
//! - `touch`: beads that strike, Newton's cradle and the air track, our
//!   plugin against avian2d's circle colliders with restitution (see
//!   [`touch`]). Prints how many balls the cradle sends out and how high,
//!   the momentum and energy across the strikes, the gliders' velocities
//!   against the formulas, and ns per step.
//! - `pile`: beads poured into a bowl at `e = 0`, in the plane and in
//!   space, our plugin against avian2d's and avian3d's colliders (see
//!   [`pile`]). Prints ms per step as the pile falls, lands and settles,
//!   the worst overlap of two beads and into the bowl, and how the energy
//!   rose.
//! - `path`: N carts on straight rails, each held by our `PathJoint` or by
//!   avian2d's `PrismaticJoint` (see [`path`]); with `--space`, our
//!   avian3d `PathJoint` against avian3d's. Prints ms per step, ns per
//!   cart-step, the rail error and turn, and the time ratio.
//!
//! Every job uses Bevy's process-wide task pools with a compute thread per
//! core, on both sides.

#![warn(missing_docs)]

mod avian_side;
mod carts;
mod path;
mod pile;
mod rope;
mod spheres;
mod touch;

use std::time::Instant;

use bevy::math::DVec2;
use bevy::prelude::*;
use clap::{Args, Parser, Subcommand};
use wirebead::SimClock;
use wirebead::headless::{Headless, bead_state};
use wirebead::prelude::*;
use wirebead::reference::{pendulum_period, period_from_crossings};
use wirebead::solver::BeadState;

/// The circle's radius, metres.
const RADIUS: f64 = 0.8;
/// Magnitude of gravity, m/s², pointing along -y.
const GRAVITY: f64 = 10.0;

/// The command line: a job, or the circle job's options alone.
#[derive(Parser, Debug)]
#[command(
    about = "wirebead against avian: a bead on a circle, a hanging rope, pendulums on carts, spherical pendulums, beads that strike",
    args_conflicts_with_subcommands = true
)]
struct Cli {
    /// The job to run; the circle job if none is named.
    #[command(subcommand)]
    job: Option<Job>,
    /// The circle job's options, when no job is named.
    #[command(flatten)]
    circle: CircleArgs,
}

/// The jobs.
#[derive(Subcommand, Debug)]
enum Job {
    /// A bead on a circle, released from rest at 90° (the default job).
    Circle(CircleArgs),
    /// A rope of N rods hanging from a pin, released horizontal.
    Rope(rope::RopeArgs),
    /// N pendulums on carts, each cart on its own horizontal rail.
    Carts(carts::CartsArgs),
    /// N spherical pendulums in space, against avian3d.
    Spheres(spheres::SpheresArgs),
    /// Newton's cradle and the air track, against avian2d's colliders.
    Touch(touch::TouchArgs),
    /// Beads poured into a bowl, against avian2d's and avian3d's colliders.
    Pile(pile::PileArgs),
    /// N carts on straight rails: our path joint against avian2d's prismatic joint.
    Path(path::PathArgs),
}

/// Options of the circle job.
#[derive(Args, Debug)]
struct CircleArgs {
    /// Steps of 1/60 s to simulate.
    #[arg(long, default_value_t = 600)]
    steps: usize,
    /// Pendulums in the timing run.
    #[arg(long, default_value_t = 10_000)]
    many: usize,
    /// Untimed runs of the timing run's size before the first timed row, so
    /// that no row pays for the process's start (its allocator's first
    /// growth, the threads' first wake-ups).
    #[arg(long, default_value_t = 1)]
    warm_up: usize,
}

/// What one run measured.
struct Row {
    /// The table's first column.
    name: String,
    /// Energy per unit mass at the end minus at the release, J/kg.
    energy_change: f64,
    /// Worst `| |x - centre| - r |` over the run, metres.
    max_radial_error: f64,
    /// Relative period error, if a period was seen.
    period_error: Option<f64>,
    /// Wall ns per bead-step at N = 1.
    ns_one: f64,
    /// Wall ns per bead-step at N = `--many`.
    ns_many: f64,
}

/// Our plugin with `n` pendulums, each on its own circle 3 m apart, in an
/// app built like avian's: `MinimalPlugins`, one fixed step per update.
fn our_app(n: usize, method: Method, dt: f64) -> (App, Entity) {
    let params = SimParams {
        timestep: dt,
        gravity: DVec2::new(0.0, -GRAVITY),
        method,
        ..SimParams::default()
    };
    let mut app = Headless::new(WireBeadPlugin::new(params).expect("valid parameters")).build();
    let mut first = None;
    for i in 0..n {
        let origin = Vec3::new(3.0 * i as f32, 0.0, 0.0);
        let wire = app
            .world_mut()
            .spawn((
                Wire::circle(RADIUS).expect("radius"),
                Transform::from_translation(origin),
            ))
            .id();
        let start = DVec2::new(f64::from(origin.x) + RADIUS, 0.0);
        let bead = Bead::at_rest(1.0, start).expect("valid bead");
        let id = app.world_mut().spawn((bead, OnWire(wire))).id();
        first.get_or_insert(id);
    }
    (app, first.expect("at least one pendulum"))
}

/// Steps our plugin; returns (energy change, max radial error, period,
/// wall seconds in the stepping loop).
fn run_ours(n: usize, method: Method, dt: f64, steps: usize) -> (f64, f64, Option<f64>, f64) {
    let (mut app, first) = our_app(n, method, dt);
    let energy = |b: BeadState| 0.5 * b.velocity.length_squared() + GRAVITY * b.position.y;
    let e0 = energy(bead_state(app.world(), first).expect("bead"));
    let mut samples = Vec::with_capacity(steps + 1);
    let mut max_radial: f64 = 0.0;
    let mut seconds = 0.0;
    for _ in 0..steps {
        let start = Instant::now();
        app.update();
        seconds += start.elapsed().as_secs_f64();
        if let Some(diverged) = app.world().get::<Diverged>(first) {
            eprintln!(
                "diverged at t = {:.3} s: {}",
                diverged.time, diverged.reason
            );
            return (f64::NAN, f64::NAN, None, seconds);
        }
        let bead = bead_state(app.world(), first).expect("bead");
        let clock = app.world().resource::<SimClock>();
        assert_eq!(
            clock.steps as usize,
            samples.len() + 1,
            "one step per update"
        );
        max_radial = max_radial.max((bead.position.length() - RADIUS).abs());
        samples.push((clock.time, bead.position.x));
    }
    let bead = bead_state(app.world(), first).expect("bead");
    (
        energy(bead) - e0,
        max_radial,
        period_from_crossings(&samples),
        seconds,
    )
}

/// Parses the command line and runs the job it names.
fn main() {
    let cli = Cli::parse();
    // Both sides share Bevy's global task pools: a compute thread per core.
    wirebead::plugin::compute_on_all_cores().create_default_pools();
    match cli.job {
        None => circle(&cli.circle),
        Some(Job::Circle(args)) => circle(&args),
        Some(Job::Rope(args)) => rope::run(&args),
        Some(Job::Carts(args)) => carts::run(&args),
        Some(Job::Spheres(args)) => spheres::run(&args),
        Some(Job::Touch(args)) => touch::run(&args),
        Some(Job::Pile(args)) => pile::run(&args),
        Some(Job::Path(args)) => path::run(&args),
    }
}

/// Runs the circle job and prints its table.
fn circle(args: &CircleArgs) {
    let dt = 1.0 / 60.0;
    let exact = pendulum_period(RADIUS, GRAVITY, std::f64::consts::FRAC_PI_2);
    for _ in 0..args.warm_up {
        run_ours(args.many, Method::ALL[0], dt, args.steps);
    }
    let mut rows = Vec::new();
    for method in Method::ALL {
        let (de, radial, period, one) = run_ours(1, method, dt, args.steps);
        let (.., many) = run_ours(args.many, method, dt, args.steps);
        rows.push(Row {
            name: format!("wirebead {method}"),
            energy_change: de,
            max_radial_error: radial,
            period_error: period.map(|p| (p - exact) / exact),
            ns_one: one * 1e9 / args.steps as f64,
            ns_many: many * 1e9 / (args.steps * args.many) as f64,
        });
        eprintln!("done: {}", rows.last().map_or("", |r| r.name.as_str()));
    }
    let one = avian_side::run_avian(1, dt, args.steps, None);
    let many = avian_side::run_avian(args.many, dt, args.steps, None);
    rows.push(Row {
        name: "avian2d 0.7 DistanceJoint".into(),
        energy_change: one.energy_change,
        max_radial_error: one.max_radial_error,
        period_error: one.period.map(|p| (p - exact) / exact),
        ns_one: one.wall_seconds * 1e9 / one.bead_steps as f64,
        ns_many: many.wall_seconds * 1e9 / many.bead_steps as f64,
    });
    println!(
        "Bead on a circle, r = {RADIUS} m, |g| = {GRAVITY} m/s², released from rest at 90°, dt = 1/60 s, {} steps; exact period {exact:.6} s.\n",
        args.steps
    );
    println!(
        "| method | energy change (J/kg) | max radial error (m) | period error | ns per bead-step, N = 1 | ns per bead-step, N = {} |",
        args.many
    );
    println!("|---|---|---|---|---|---|");
    for r in &rows {
        let period = r
            .period_error
            .map_or_else(|| "no period".to_string(), |e| format!("{e:+.2e}"));
        if r.energy_change.is_nan() {
            println!(
                "| {} | diverged | diverged | diverged | {:.0} | {:.1} |",
                r.name, r.ns_one, r.ns_many
            );
        } else {
            println!(
                "| {} | {:+.3e} | {:.2e} | {} | {:.0} | {:.1} |",
                r.name, r.energy_change, r.max_radial_error, period, r.ns_one, r.ns_many
            );
        }
    }
}
