//! The path job: N carts, each a rigid body of 2 kg held on its own
//! straight horizontal rail (3 m apart, at y = −3 i), set moving along it
//! at 1 m/s, under gravity `(0, −10)` across the rail, dt = 1/60 s, at
//! avian2d's default substeps.
//!
//! - Ours: wirebead's [`PathJoint`] on a [`Wire::line`] at the rail's
//!   height, the cart turned with the rail ([`PathRotation::Turned`]):
//!   the anchor held on the line and the cart's angle to it, as a
//!   prismatic joint holds them.
//! - avian2d: a [`PrismaticJoint`] along x to a static body at the rail's
//!   height (zero compliance, no limits, no motor), the nearest joint
//!   avian has.
//!
//!
//! With `--space`, the same in space against avian3d: ours a
//! `wirebead::avian3d::PathJoint` turned with the rail's frame
//! (`ToPath`) on a straight curve in space (a line in the xy-plane), so
//! that the anchor is held on it and the cart's orientation to it, as
//! avian3d's [`PrismaticJoint`](avian3d::prelude::PrismaticJoint) holds
//! them.
//!
//! Both in one kind of app ([`avian_side::physics_app_with`], ours with
//! wirebead's plugin and the path joint's added), no colliders, sleeping
//! disabled. Measured per run: wall ms per step and ns per cart-step (the
//! `App::update` calls alone), the worst rail error `|y − y_rail|` and
//! the worst turn of a cart over all carts and steps, and how far cart 0
//! went against the 1 m/s × t it was sent.

use std::time::Duration;

use avian2d::prelude::{
    AngularInertia, LinearVelocity, Mass, Position, PrismaticJoint, RigidBody, Rotation,
    SleepingDisabled,
};
use bevy::math::DVec2;
use bevy::prelude::*;
use clap::{Args, ValueEnum};
use wirebead::avian::{PathJoint, PathJointPlugin, PathRotation};
use wirebead::prelude::*;

use crate::avian_side;

/// Magnitude of gravity, m/s², pointing along −y.
const GRAVITY: f64 = 10.0;
/// The timestep, seconds.
const DT: f64 = 1.0 / 60.0;
/// The cart's mass, kg.
const CART_MASS: f32 = 2.0;
/// The distance between neighbouring rails, metres.
const SPACING: f64 = 3.0;
/// The speed each cart is sent along its rail at, m/s.
const SPEED: f64 = 1.0;

/// What holds a cart to its rail.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Holder {
    /// wirebead's `PathJoint` on a line, turned with it.
    Path,
    /// avian2d's `PrismaticJoint` along x to a static body.
    Prismatic,
}

/// Options of the path job.
#[derive(Args, Debug)]
pub struct PathArgs {
    /// Steps of 1/60 s to simulate.
    #[arg(long, default_value_t = 600, value_parser = avian_side::positive)]
    pub steps: usize,
    /// Numbers of carts.
    #[arg(long, value_delimiter = ',', default_values_t = vec![1, 1000])]
    pub sizes: Vec<usize>,
    /// In space, against avian3d, instead of in the plane.
    #[arg(long)]
    pub space: bool,
}

/// One run's measurements.
struct PathRun {
    ms_per_step: f64,
    ns_per_cart_step: f64,
    rail_error: f64,
    turn: f64,
    along_error: f64,
}

/// N carts held by `holder`, stepped `steps` times.
fn run_side(n: usize, holder: Holder, steps: usize) -> PathRun {
    let step = Duration::from_secs_f64(DT);
    let gravity = DVec2::new(0.0, -GRAVITY);
    let mut app = avian_side::physics_app_with(step, None, gravity, None, |app| {
        if holder == Holder::Path {
            let params = SimParams {
                timestep: DT,
                gravity,
                ..SimParams::default()
            };
            app.add_plugins((
                WireBeadPlugin::new(params).expect("valid parameters"),
                PathJointPlugin,
            ));
        }
    });
    let world = app.world_mut();
    let carts: Vec<(Entity, f64)> = (0..n)
        .map(|i| {
            let y = -SPACING * i as f64;
            let cart = world
                .spawn((
                    RigidBody::Dynamic,
                    Position(DVec2::new(0.0, y)),
                    LinearVelocity(DVec2::new(SPEED, 0.0)),
                    Mass(CART_MASS),
                    AngularInertia(0.1),
                    SleepingDisabled,
                ))
                .id();
            match holder {
                Holder::Path => {
                    let rail = world
                        .spawn((Wire::line(), Transform::from_xyz(0.0, y as f32, 0.0)))
                        .id();
                    world
                        .entity_mut(cart)
                        .insert(PathJoint::new(rail).with_rotation(PathRotation::Turned));
                }
                Holder::Prismatic => {
                    let anchor = world
                        .spawn((RigidBody::Static, Position(DVec2::new(0.0, y))))
                        .id();
                    world.spawn(PrismaticJoint::new(anchor, cart).with_slider_axis(DVec2::X));
                }
            }
            (cart, y)
        })
        .collect();
    avian_side::warm_up(&mut app);
    let (mut seconds, mut rail_error, mut turn) = (0.0, 0.0f64, 0.0f64);
    for k in 1..=steps {
        seconds += avian_side::timed_step(&mut app, step, k);
        for &(cart, y) in &carts {
            let position = app.world().get::<Position>(cart).expect("a cart").0;
            let angle = app
                .world()
                .get::<Rotation>(cart)
                .expect("a cart")
                .as_radians();
            rail_error = rail_error.max((position.y - y).abs());
            turn = turn.max(angle.abs());
        }
    }
    let x = app.world().get::<Position>(carts[0].0).expect("a cart").0.x;
    PathRun {
        ms_per_step: seconds * 1e3 / steps as f64,
        ns_per_cart_step: seconds * 1e9 / (n * steps) as f64,
        rail_error,
        turn,
        along_error: (x - SPEED * DT * steps as f64).abs(),
    }
}

/// N carts in space held by `holder`, stepped `steps` times: the rail
/// error is the largest distance across the rail, the turn the largest
/// angle of a cart from where it began.
fn run_space_side(n: usize, holder: Holder, steps: usize) -> PathRun {
    use avian3d::prelude as a3;
    use bevy::math::{DQuat, DVec3};
    use wirebead::SpaceWire;
    use wirebead::avian3d::{PathJoint, PathJointPlugin, PathRotation};
    use wirebead::geometry::{Line, OnPlane};
    let step = Duration::from_secs_f64(DT);
    let gravity = DVec3::new(0.0, -GRAVITY, 0.0);
    let mut app = avian_side::space::physics_app_with(step, None, gravity, None, |app| {
        if holder == Holder::Path {
            let params = SimParams {
                timestep: DT,
                ..SimParams::default()
            };
            app.add_plugins((
                WireBeadPlugin::new(params).expect("valid parameters"),
                PathJointPlugin,
            ));
        }
    });
    let world = app.world_mut();
    let carts: Vec<(Entity, f64)> = (0..n)
        .map(|i| {
            let y = -SPACING * i as f64;
            let cart = world
                .spawn((
                    a3::RigidBody::Dynamic,
                    a3::Position(DVec3::new(0.0, y, 0.0)),
                    a3::LinearVelocity(DVec3::new(SPEED, 0.0, 0.0)),
                    a3::Mass(CART_MASS),
                    a3::AngularInertia::new(Vec3::splat(0.1)),
                    a3::SleepingDisabled,
                ))
                .id();
            match holder {
                Holder::Path => {
                    let rail = world
                        .spawn((
                            SpaceWire::curve(OnPlane(Line)),
                            Transform::from_xyz(0.0, y as f32, 0.0),
                        ))
                        .id();
                    world
                        .entity_mut(cart)
                        .insert(PathJoint::new(rail).with_rotation(PathRotation::ToPath));
                }
                Holder::Prismatic => {
                    let anchor = world
                        .spawn((a3::RigidBody::Static, a3::Position(DVec3::new(0.0, y, 0.0))))
                        .id();
                    world.spawn(a3::PrismaticJoint::new(anchor, cart).with_slider_axis(DVec3::X));
                }
            }
            (cart, y)
        })
        .collect();
    avian_side::space::warm_up(&mut app);
    let (mut seconds, mut rail_error, mut turn) = (0.0, 0.0f64, 0.0f64);
    for k in 1..=steps {
        seconds += avian_side::space::timed_step(&mut app, step, k);
        for &(cart, y) in &carts {
            let position = app.world().get::<a3::Position>(cart).expect("a cart").0;
            let rotation: DQuat = app.world().get::<a3::Rotation>(cart).expect("a cart").0;
            rail_error = rail_error.max((position.y - y).abs().max(position.z.abs()));
            turn = turn.max(rotation.angle_between(DQuat::IDENTITY));
        }
    }
    let x = app
        .world()
        .get::<a3::Position>(carts[0].0)
        .expect("a cart")
        .0
        .x;
    PathRun {
        ms_per_step: seconds * 1e3 / steps as f64,
        ns_per_cart_step: seconds * 1e9 / (n * steps) as f64,
        rail_error,
        turn,
        along_error: (x - SPEED * DT * steps as f64).abs(),
    }
}

/// Runs the path job and prints its table and ratios.
pub fn run(args: &PathArgs) {
    let engine = if args.space { "avian3d" } else { "avian2d" };
    println!(
        "N carts of {CART_MASS} kg, each on its own straight rail ({SPACING} m apart), sent along it at {SPEED} m/s, |g| = {GRAVITY} m/s² across it, dt = 1/60 s, {engine}'s {} substeps, {} steps.\n",
        avian_side::default_substeps(),
        args.steps
    );
    println!(
        "| holder | N | ms per step | ns per cart-step | max rail error (m) | max turn (rad) | cart 0 along, off 1 m/s × t (m) |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut ratios = Vec::new();
    for &n in &args.sizes {
        let mut runs = Vec::new();
        for holder in [Holder::Path, Holder::Prismatic] {
            let run = if args.space {
                run_space_side(n, holder, args.steps)
            } else {
                run_side(n, holder, args.steps)
            };
            let name = match (holder, args.space) {
                (Holder::Path, false) => "wirebead PathJoint (Turned) on a line",
                (Holder::Prismatic, false) => "avian2d 0.7 PrismaticJoint",
                (Holder::Path, true) => "wirebead avian3d PathJoint (ToPath) on a line in space",
                (Holder::Prismatic, true) => "avian3d 0.7 PrismaticJoint",
            };
            println!(
                "| {name} | {n} | {:.3} | {:.0} | {:.2e} | {:.2e} | {:.2e} |",
                run.ms_per_step, run.ns_per_cart_step, run.rail_error, run.turn, run.along_error
            );
            runs.push(run);
        }
        ratios.push((n, runs[0].ns_per_cart_step / runs[1].ns_per_cart_step));
    }
    println!("\nTime per cart-step, path joint / prismatic joint:\n");
    for (n, ratio) in ratios {
        println!("- N = {n}: {ratio:.2}");
    }
}
