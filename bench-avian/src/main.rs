//! wirebead against avian2d on one job: a bead on a circle of radius 0.8
//! under |g| = 10, released from rest at 90°, dt = 1/60, 10 s.
//!
//! ```text
//! cargo run --release -p wirebead-vs-avian
//! ```
//!
//! Prints a markdown table: energy change, max radial error and period
//! error of each of our methods and of avian2d (a
//! body on a `DistanceJoint` to a static anchor), and the wall time per
//! bead-step at N = 1 and N = 10,000 pendulums.

#![warn(missing_docs)]

mod avian_side;

use std::time::{Duration, Instant};

use bevy::math::DVec2;
use bevy::prelude::*;
use clap::Parser;
use wirebead::headless::Headless;
use wirebead::prelude::*;
use wirebead::reference::{pendulum_period, period_from_crossings};

const RADIUS: f64 = 0.8;
const GRAVITY: f64 = 10.0;

#[derive(Parser, Debug)]
#[command(about = "wirebead against avian2d on a bead on a circle")]
struct Args {
    /// Steps of 1/60 s to simulate.
    #[arg(long, default_value_t = 600)]
    steps: usize,
    /// Pendulums in the timing run.
    #[arg(long, default_value_t = 10_000)]
    many: usize,
}

/// What one run measured.
struct Row {
    name: String,
    energy_change: f64,
    max_radial_error: f64,
    period_error: Option<f64>,
    ns_one: f64,
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
    let energy = |b: &Bead| 0.5 * b.velocity.length_squared() + GRAVITY * b.position.y;
    let e0 = energy(app.world().get::<Bead>(first).expect("bead"));
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
        let bead = app.world().get::<Bead>(first).expect("bead");
        let clock = app.world().resource::<SimClock>();
        assert_eq!(
            clock.steps as usize,
            samples.len() + 1,
            "one step per update"
        );
        max_radial = max_radial.max((bead.position.length() - RADIUS).abs());
        samples.push((clock.time, bead.position.x));
    }
    let bead = app.world().get::<Bead>(first).expect("bead");
    (
        energy(bead) - e0,
        max_radial,
        period_from_crossings(&samples),
        seconds,
    )
}

fn main() {
    let args = Args::parse();
    // Both sides share Bevy's global task pools: a compute thread per core.
    wirebead::plugin::compute_on_all_cores().create_default_pools();
    let dt = 1.0 / 60.0;
    let exact = pendulum_period(RADIUS, GRAVITY, std::f64::consts::FRAC_PI_2);
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
