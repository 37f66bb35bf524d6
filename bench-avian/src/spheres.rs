//! The spheres job: N spherical pendulums in space, ours against avian3d.
//!
//! Each pendulum is a bead of 1 kg on a sphere of radius 0.8 m about its
//! own anchor, the anchors 3 m apart along x, under gravity `(0, −10, 0)`,
//! dt = 1/60 s. It starts as a conical pendulum: 60° from the downward
//! vertical, moving horizontally at the speed that keeps it on its circle,
//! `v = √(g r sin θ tan θ)`. The exact motion keeps its height, so the
//! height's change measures the error of the method as well as the energy
//! does.
//!
//! - Ours: the plugin, a [`SpaceWire`] sphere with a `Transform` at the
//!   anchor and a [`SpaceBead`] on it with [`OnWire`], each of our methods,
//!   in an app with bevy's default executors on the process-wide pools, as
//!   the circle job's apps are. One `App::update`, one step.
//! - avian3d: a dynamic body (mass 1, no collider, sleeping disabled) on a
//!   [`DistanceJoint`] with `min = max = 0.8` and zero compliance to a
//!   static anchor body, at avian's default substeps, built and stepped by
//!   [`avian_side::space::physics_app`] and
//!   [`avian_side::space::timed_step`].
//!
//! Measured per run: wall ns per bead-step (the `App::update` calls alone),
//! the worst radial error `| |x − anchor| − r |` over all pendulums and
//! steps, and pendulum 0's energy change per unit mass and largest height
//! change over the run.

use std::time::{Duration, Instant};

use avian3d::prelude::{
    AngularInertia, DistanceJoint, LinearVelocity, Mass, Position, RigidBody, SleepingDisabled,
};
use bevy::app::App;
use bevy::math::DVec3;
use bevy::prelude::*;
use clap::Args;
use wirebead::geometry::Sphere;
use wirebead::headless::{Headless, space_bead_state};
use wirebead::prelude::*;
use wirebead::solver::BeadState;
use wirebead::{SpaceBead, SpaceWire};

use crate::avian_side;

/// Magnitude of gravity, m/s², pointing along −y.
const GRAVITY: f64 = 10.0;
/// The sphere's radius (the joint's length), metres.
const RADIUS: f64 = 0.8;
/// The start's angle from the downward vertical, degrees.
const CONE_DEGREES: f64 = 60.0;
/// The timestep, seconds.
const DT: f64 = 1.0 / 60.0;
/// The distance between neighbouring anchors along x, metres.
const SPACING: f64 = 3.0;

/// Options of the spheres job.
#[derive(Args, Debug)]
pub struct SpheresArgs {
    /// Steps of 1/60 s to simulate.
    #[arg(long, default_value_t = 600, value_parser = avian_side::positive)]
    steps: usize,
    /// Numbers of pendulums to time, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,10000", value_parser = avian_side::positive)]
    sizes: Vec<usize>,
}

/// A pendulum's start relative to its anchor: on the cone, moving along +z
/// at the conical pendulum's speed.
fn start() -> BeadState<DVec3> {
    let theta = CONE_DEGREES.to_radians();
    let speed = (GRAVITY * RADIUS * theta.sin() * theta.tan()).sqrt();
    BeadState {
        position: DVec3::new(RADIUS * theta.sin(), -RADIUS * theta.cos(), 0.0),
        velocity: DVec3::new(0.0, 0.0, speed),
    }
}

/// Anchor `i`.
fn anchor(i: usize) -> DVec3 {
    DVec3::new(SPACING * i as f64, 0.0, 0.0)
}

/// Energy per unit mass of a bead at `offset` from its anchor moving with
/// `velocity`.
fn energy(offset: DVec3, velocity: DVec3) -> f64 {
    0.5 * velocity.length_squared() + GRAVITY * offset.y
}

/// What one run measured.
struct Measured {
    /// Pendulum 0's energy change per unit mass, J/kg.
    energy_change: f64,
    /// Pendulum 0's largest height change, metres.
    height_change: f64,
    /// The worst radial error over every pendulum and step, metres.
    radial: f64,
    /// Wall ns per bead-step.
    ns: f64,
}

/// Follows the pendulums of one run: the worst radial error over all of
/// them, pendulum 0's energy and height.
struct Tracker {
    e0: f64,
    height_change: f64,
    radial: f64,
}

impl Tracker {
    fn new() -> Self {
        let s = start();
        Self {
            e0: energy(s.position, s.velocity),
            height_change: 0.0,
            radial: 0.0,
        }
    }

    /// Pendulum `i`'s state `(offset, velocity)` after a step.
    fn see(&mut self, i: usize, offset: DVec3, velocity: DVec3) {
        let _ = velocity;
        self.radial = self.radial.max((offset.length() - RADIUS).abs());
        if i == 0 {
            let change = (offset.y - start().position.y).abs();
            self.height_change = self.height_change.max(change);
        }
    }

    fn finish(self, last: (DVec3, DVec3), seconds: f64, bead_steps: usize) -> Measured {
        Measured {
            energy_change: energy(last.0, last.1) - self.e0,
            height_change: self.height_change,
            radial: self.radial,
            ns: seconds * 1e9 / bead_steps as f64,
        }
    }
}

/// Our plugin with `n` pendulums.
fn run_ours(n: usize, method: Method, steps: usize) -> Option<Measured> {
    let params = SimParams {
        timestep: DT,
        gravity: bevy::math::DVec2::new(0.0, -GRAVITY),
        method,
        ..SimParams::default()
    };
    let mut app = Headless::new(WireBeadPlugin::new(params).expect("valid parameters")).build();
    let s = start();
    let beads: Vec<Entity> = (0..n)
        .map(|i| {
            let world = app.world_mut();
            let wire = world
                .spawn((
                    SpaceWire::surface_of(Sphere { radius: RADIUS }),
                    Transform::from_translation(anchor(i).as_vec3()),
                ))
                .id();
            let bead = SpaceBead::new(BeadParams {
                mass: 1.0,
                initial_position: anchor(i) + s.position,
                initial_velocity: s.velocity,
            })
            .expect("valid bead");
            world.spawn((bead, OnWire(wire))).id()
        })
        .collect();
    let state = |app: &App, i: usize| {
        let b = space_bead_state(app.world(), beads[i]).expect("a bead");
        (b.position - anchor(i), b.velocity)
    };
    let mut tracker = Tracker::new();
    let mut seconds = 0.0;
    for _ in 0..steps {
        let begin = Instant::now();
        app.update();
        seconds += begin.elapsed().as_secs_f64();
        if let Some(diverged) = app.world().get::<Diverged>(beads[0]) {
            eprintln!(
                "{method}: diverged at t = {:.3} s: {}",
                diverged.time, diverged.reason
            );
            return None;
        }
        for i in 0..n {
            let (offset, velocity) = state(&app, i);
            tracker.see(i, offset, velocity);
        }
    }
    Some(tracker.finish(state(&app, 0), seconds, n * steps))
}

/// avian3d with `n` pendulums at its default substeps.
fn run_avian(n: usize, steps: usize) -> Measured {
    let step = Duration::from_secs_f64(DT);
    let gravity = DVec3::new(0.0, -GRAVITY, 0.0);
    let mut app = avian_side::space::physics_app(step, None, gravity, None);
    let s = start();
    let beads: Vec<Entity> = (0..n)
        .map(|i| {
            let world = app.world_mut();
            let anchor_body = world.spawn((RigidBody::Static, Position(anchor(i)))).id();
            let bead = world
                .spawn((
                    RigidBody::Dynamic,
                    Position(anchor(i) + s.position),
                    LinearVelocity(s.velocity),
                    Mass(1.0),
                    // The joint acts at the centre of mass, so the inertia
                    // never matters; it only has to be finite and non-zero.
                    AngularInertia::new(Vec3::ONE),
                    SleepingDisabled,
                ))
                .id();
            world.spawn(
                DistanceJoint::new(anchor_body, bead)
                    .with_limits(RADIUS, RADIUS)
                    .with_compliance(0.0),
            );
            bead
        })
        .collect();
    avian_side::space::warm_up(&mut app);
    let state = |app: &App, i: usize| {
        let world = app.world();
        let position = world.get::<Position>(beads[i]).expect("a body").0;
        let velocity = world.get::<LinearVelocity>(beads[i]).expect("a body").0;
        (position - anchor(i), velocity)
    };
    let mut tracker = Tracker::new();
    let mut seconds = 0.0;
    for k in 1..=steps {
        seconds += avian_side::space::timed_step(&mut app, step, k);
        for i in 0..n {
            let (offset, velocity) = state(&app, i);
            tracker.see(i, offset, velocity);
        }
    }
    tracker.finish(state(&app, 0), seconds, n * steps)
}

/// Runs the job and prints its tables.
pub fn run(args: &SpheresArgs) {
    let theta = CONE_DEGREES.to_radians();
    let period = std::f64::consts::TAU * (RADIUS * theta.cos() / GRAVITY).sqrt();
    println!(
        "Conical pendulums on spheres of r = {RADIUS} m, {CONE_DEGREES}° from the vertical, |g| = {GRAVITY} m/s², dt = 1/60 s, {} steps (period {period:.4} s).\n",
        args.steps
    );
    print!("| engine |");
    for n in &args.sizes {
        print!(" ns per bead-step, N = {n} |");
    }
    println!(" energy change (J/kg) | max height change (m) | max radial error (m) |");
    println!("|---|{}---|---|---|", "---:|".repeat(args.sizes.len()));
    let mut ours_best = f64::INFINITY;
    let largest = args.sizes.iter().copied().max().unwrap_or(1);
    for method in Method::ALL {
        let runs: Vec<Option<Measured>> = args
            .sizes
            .iter()
            .map(|&n| run_ours(n, method, args.steps))
            .collect();
        print_row(&format!("wirebead {method}"), &runs);
        if let Some((Some(run), _)) = runs.iter().zip(&args.sizes).find(|(_, n)| **n == largest) {
            ours_best = ours_best.min(run.ns);
        }
    }
    let avian: Vec<Option<Measured>> = args
        .sizes
        .iter()
        .map(|&n| Some(run_avian(n, args.steps)))
        .collect();
    print_row("avian3d 0.7 DistanceJoint", &avian);
    if let Some((Some(run), _)) = avian.iter().zip(&args.sizes).find(|(_, n)| **n == largest) {
        println!(
            "\nAt N = {largest}: avian3d / our fastest method = {:.1}×",
            run.ns / ours_best
        );
    }
}

/// One row: the timings at each size, the accuracy of the first run.
fn print_row(name: &str, runs: &[Option<Measured>]) {
    print!("| {name} |");
    for run in runs {
        match run {
            Some(run) => print!(" {:.1} |", run.ns),
            None => print!(" diverged |"),
        }
    }
    match runs.first() {
        Some(Some(run)) => println!(
            " {:+.3e} | {:.2e} | {:.2e} |",
            run.energy_change, run.height_change, run.radial
        ),
        _ => println!(" diverged | diverged | diverged |"),
    }
}
