//! The carts job: N pendulums on carts, N independent islands of two beads.
//!
//! Each pendulum is a cart of 2 kg held to its own horizontal rail at
//! y = -3 i and a bob of 1 kg on a rigid rod of 1 m to the cart, released
//! from rest 30° from the vertical below the cart, under gravity `(0, -10)`,
//! dt = 1/60 s.
//!
//! - Ours: the plugin, as the `carts` function of `benches/chain.rs`
//!   builds it (a [`Wire::line`] with a `Transform` at the rail's height,
//!   the cart on it with [`OnWire`], the bob joined by a [`Rod`]), RATTLE,
//!   but in an app with bevy's default executors on the process-wide
//!   pools, as the circle job's apps are, and gravity 10 rather than 9.81
//!   so both sides run the same problem. One `App::update`, one step.
//! - avian2d: the cart is a dynamic body (mass 2) on a rail, the bob a
//!   dynamic body (mass 1, rotation locked) on a [`DistanceJoint`] with
//!   `min = max = 1` and zero compliance, anchors at the body centres.
//!   The rail is either a [`PrismaticJoint`] along x to a static body at
//!   the rail's height (zero compliance, no limits: it holds the cart's
//!   offset across the axis and its angle), or [`LockedAxes`] locking the
//!   cart's y translation and rotation (`--rail locked`). No colliders,
//!   sleeping disabled, built and stepped by [`avian_side::physics_app`]
//!   and [`avian_side::timed_step`], at avian's default substeps and at
//!   each count of `--substeps`.
//!
//! Measured per run: wall ns per bead-step (the `App::update` calls alone,
//! over 2 N × steps, the first step, which builds our islands, included),
//! the worst rod error `| |x_bob - x_cart| - 1 |` and rail error
//! `|y_cart - y_rail|` over all pendulums and steps, and the energy change
//! of pendulum 0 (kinetic plus potential of cart and bob, J).

use std::time::{Duration, Instant};

use avian2d::prelude::{
    AngularInertia, DistanceJoint, LinearVelocity, LockedAxes, Mass, Position, PrismaticJoint,
    RigidBody, SleepingDisabled,
};
use bevy::app::App;
use bevy::math::DVec2;
use bevy::prelude::*;
use clap::{Args, ValueEnum};
use wirebead::SimClock;
use wirebead::headless::{Headless, bead_state};
use wirebead::prelude::*;
use wirebead::solver::BeadState;

use crate::avian_side;

/// Magnitude of gravity, m/s², pointing along -y.
const GRAVITY: f64 = 10.0;
/// The timestep, seconds.
const DT: f64 = 1.0 / 60.0;
/// The cart's mass, kg.
const CART_MASS: f64 = 2.0;
/// The bob's mass, kg.
const BOB_MASS: f64 = 1.0;
/// The rod's length, metres.
const ROD: f64 = 1.0;
/// The distance between neighbouring rails, metres.
const SPACING: f64 = 3.0;

/// How the avian2d cart is held to its rail.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Rail {
    /// A `PrismaticJoint` along x to a static body at the rail's height.
    Prismatic,
    /// `LockedAxes` locking the cart's y translation and its rotation.
    Locked,
}

/// Options of the carts job.
#[derive(Args, Debug)]
pub struct CartsArgs {
    /// Steps of 1/60 s to simulate.
    #[arg(long, default_value_t = 600, value_parser = avian_side::positive)]
    pub steps: usize,
    /// Numbers of pendulums N, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1000,10000", value_parser = avian_side::positive)]
    pub sizes: Vec<usize>,
    /// avian2d substep counts to run besides its default, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "50", value_parser = clap::value_parser!(u32).range(1..))]
    pub substeps: Vec<u32>,
    /// How avian2d holds a cart to its rail.
    #[arg(long, value_enum, default_value_t = Rail::Prismatic)]
    pub rail: Rail,
}

/// One pendulum's bodies (ours: beads; avian: rigid bodies).
struct Pendulum {
    /// The cart.
    cart: Entity,
    /// The bob.
    bob: Entity,
    /// The height of the cart's rail, metres.
    rail_y: f64,
}

/// What one run measured.
struct CartsRun {
    /// The table's first column.
    name: String,
    /// avian2d's substep count, or `None` for ours.
    avian_substeps: Option<u32>,
    /// Wall nanoseconds per bead-step in the `App::update` calls.
    ns_per_bead_step: f64,
    /// Worst `| |x_bob - x_cart| - 1 |` over all pendulums and steps, m.
    max_rod_error: f64,
    /// Worst `|y_cart - y_rail|` over all pendulums and steps, m.
    max_rail_error: f64,
    /// Pendulum 0's energy at the end minus at the release, J.
    energy_change: f64,
    /// The first step's time, failures, in words.
    note: String,
}

/// Where the bob starts relative to its cart: 30° from straight down.
fn swing() -> DVec2 {
    let angle = 30f64.to_radians();
    ROD * DVec2::new(angle.sin(), -angle.cos())
}

/// A pendulum's energy, J, from its cart's and its bob's states.
fn energy(cart: &BeadState, bob: &BeadState) -> f64 {
    let one =
        |s: &BeadState, m: f64| m * (0.5 * s.velocity.length_squared() + GRAVITY * s.position.y);
    one(cart, CART_MASS) + one(bob, BOB_MASS)
}

/// The worst rod and rail errors over `pendulums`, given each one's cart
/// and bob states; infinite where a state is not finite.
fn errors(pendulums: &[Pendulum], state: impl Fn(Entity) -> BeadState, worst: &mut (f64, f64)) {
    for p in pendulums {
        let (cart, bob) = (state(p.cart), state(p.bob));
        let rod = ((bob.position - cart.position).length() - ROD).abs();
        let rail = (cart.position.y - p.rail_y).abs();
        worst.0 = if rod.is_finite() {
            worst.0.max(rod)
        } else {
            f64::INFINITY
        };
        worst.1 = if rail.is_finite() {
            worst.1.max(rail)
        } else {
            f64::INFINITY
        };
    }
}

/// A bead's state in our app.
fn our_state(app: &App, bead: Entity) -> BeadState {
    bead_state(app.world(), bead).expect("a bead")
}

/// Our `n` pendulums on carts through the plugin, for `steps` steps.
fn run_ours(n: usize, steps: usize) -> CartsRun {
    let params = SimParams {
        timestep: DT,
        gravity: DVec2::new(0.0, -GRAVITY),
        method: Method::Rattle,
        ..SimParams::default()
    };
    let mut app = Headless::new(WireBeadPlugin::new(params).expect("valid parameters")).build();
    let world = app.world_mut();
    let pendulums: Vec<Pendulum> = (0..n)
        .map(|i| {
            let y = -SPACING * i as f64;
            let rail = world
                .spawn((Wire::line(), Transform::from_xyz(0.0, y as f32, 0.0)))
                .id();
            let cart = Bead::at_rest(CART_MASS, DVec2::new(0.0, y)).expect("valid cart");
            let cart = world.spawn((cart, OnWire(rail))).id();
            let bob = Bead::at_rest(BOB_MASS, DVec2::new(0.0, y) + swing()).expect("valid bob");
            let bob = world.spawn(bob).id();
            world.spawn(Rod::new(cart, bob, ROD).expect("valid rod"));
            Pendulum {
                cart,
                bob,
                rail_y: y,
            }
        })
        .collect();
    let first = &pendulums[0];
    let e0 = energy(&our_state(&app, first.cart), &our_state(&app, first.bob));
    let (mut worst, mut seconds, mut first_step) = ((0.0, 0.0), 0.0, 0.0);
    for k in 1..=steps {
        let start = Instant::now();
        app.update();
        let elapsed = start.elapsed().as_secs_f64();
        seconds += elapsed;
        if k == 1 {
            first_step = elapsed;
        }
        let clock = app.world().resource::<SimClock>();
        assert_eq!(clock.steps as usize, k, "one step per update");
        errors(&pendulums, |e| our_state(&app, e), &mut worst);
    }

    let mut notes = vec![format!(
        "first step {:.1} ms (it builds the islands)",
        first_step * 1e3
    )];
    let stopped = app
        .world_mut()
        .query_filtered::<(), With<Diverged>>()
        .iter(app.world())
        .count();
    if stopped > 0 {
        notes.push(format!("{stopped} beads stopped"));
    }
    if let Some(diverged) = app.world().get::<Diverged>(first.cart) {
        notes.push(format!(
            "pendulum 0 stopped at t = {:.3} s: {}",
            diverged.time, diverged.reason
        ));
    }
    CartsRun {
        name: "wirebead RATTLE, plugin".to_string(),
        avian_substeps: None,
        ns_per_bead_step: seconds * 1e9 / (2 * n * steps.max(1)) as f64,
        max_rod_error: worst.0,
        max_rail_error: worst.1,
        energy_change: energy(&our_state(&app, first.cart), &our_state(&app, first.bob)) - e0,
        note: notes.join("; "),
    }
}

/// A body's state in an avian app.
fn avian_state(app: &App, body: Entity) -> BeadState {
    let world = app.world();
    BeadState {
        position: world.get::<Position>(body).expect("a Position").0,
        velocity: world.get::<LinearVelocity>(body).expect("a velocity").0,
    }
}

/// avian2d's `n` pendulums on carts held by `rail`, at `substeps`
/// substeps per step, for `steps` steps of 1/60 s (rounded by bevy to
/// whole nanoseconds).
fn run_avian(n: usize, substeps: u32, rail: Rail, steps: usize) -> CartsRun {
    let step = Duration::from_secs_f64(DT);
    let mut app = avian_side::physics_app(step, None, DVec2::new(0.0, -GRAVITY), Some(substeps));
    let world = app.world_mut();
    let pendulums: Vec<Pendulum> = (0..n)
        .map(|i| {
            let y = -SPACING * i as f64;
            let at = DVec2::new(0.0, y);
            let mut cart = world.spawn((
                RigidBody::Dynamic,
                Position(at),
                LinearVelocity(DVec2::ZERO),
                // avian stores masses as f32; 2 and 1 are exact there.
                Mass(CART_MASS as f32),
                // The joints act at the centres of mass, so they exert no
                // torque; the inertia only has to be finite and non-zero.
                AngularInertia(1.0),
                SleepingDisabled,
            ));
            if rail == Rail::Locked {
                cart.insert(LockedAxes::new().lock_translation_y().lock_rotation());
            }
            let cart = cart.id();
            if rail == Rail::Prismatic {
                let anchor = world.spawn((RigidBody::Static, Position(at))).id();
                world.spawn(PrismaticJoint::new(anchor, cart).with_slider_axis(DVec2::X));
            }
            let bob = world
                .spawn((
                    RigidBody::Dynamic,
                    Position(at + swing()),
                    LinearVelocity(DVec2::ZERO),
                    Mass(BOB_MASS as f32),
                    AngularInertia(1.0),
                    LockedAxes::ROTATION_LOCKED,
                    SleepingDisabled,
                ))
                .id();
            world.spawn(
                DistanceJoint::new(cart, bob)
                    .with_limits(ROD, ROD)
                    .with_compliance(0.0),
            );
            Pendulum {
                cart,
                bob,
                rail_y: y,
            }
        })
        .collect();
    avian_side::warm_up(&mut app);

    let first = &pendulums[0];
    let e0 = energy(
        &avian_state(&app, first.cart),
        &avian_state(&app, first.bob),
    );
    let (mut worst, mut seconds, mut first_step) = ((0.0, 0.0), 0.0, 0.0);
    for k in 1..=steps {
        let elapsed = avian_side::timed_step(&mut app, step, k);
        seconds += elapsed;
        if k == 1 {
            first_step = elapsed;
        }
        errors(&pendulums, |e| avian_state(&app, e), &mut worst);
    }
    let rail_name = match rail {
        Rail::Prismatic => "PrismaticJoint rail",
        Rail::Locked => "LockedAxes rail",
    };
    CartsRun {
        name: format!("avian2d 0.7 {rail_name} + DistanceJoint, {substeps} substeps"),
        avian_substeps: Some(substeps),
        ns_per_bead_step: seconds * 1e9 / (2 * n * steps.max(1)) as f64,
        max_rod_error: worst.0,
        max_rail_error: worst.1,
        energy_change: energy(
            &avian_state(&app, first.cart),
            &avian_state(&app, first.bob),
        ) - e0,
        note: format!("first step {:.1} ms", first_step * 1e3),
    }
}

/// Runs the carts job and prints its table and ratios.
pub fn run(args: &CartsArgs) {
    let counts = avian_side::substep_counts(&args.substeps);
    // (N, ours, avian runs in the order of `counts`)
    let mut results = Vec::new();
    for &n in &args.sizes {
        let ours = run_ours(n, args.steps);
        eprintln!("done: N = {n}, {}", ours.name);
        let mut avian = Vec::new();
        for &k in &counts {
            avian.push(run_avian(n, k, args.rail, args.steps));
            eprintln!("done: N = {n}, avian2d at {k} substeps");
        }
        results.push((n, ours, avian));
    }

    println!(
        "N pendulums on carts: a cart of {CART_MASS} kg on its own horizontal rail ({SPACING} m apart), a bob of {BOB_MASS} kg on a rigid rod of {ROD} m, released from rest 30° from the vertical, |g| = {GRAVITY} m/s², dt = 1/60 s, {} steps.\n",
        args.steps
    );
    println!(
        "| engine/config | N | ns per bead-step | max rod error (m) | max rail error (m) | energy change, pendulum 0 (J) | note |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (n, ours, avian) in &results {
        for r in std::iter::once(ours).chain(avian) {
            println!(
                "| {} | {n} | {:.1} | {:.2e} | {:.2e} | {:+.3e} | {} |",
                r.name,
                r.ns_per_bead_step,
                r.max_rod_error,
                r.max_rail_error,
                r.energy_change,
                r.note.replace('|', "\\|")
            );
        }
    }

    println!("\nTime per bead-step, avian2d / ours:\n");
    for (n, ours, avian) in &results {
        let parts: Vec<String> = avian
            .iter()
            .map(|r| {
                format!(
                    "{} substeps {:.2}×",
                    r.avian_substeps.unwrap_or_default(),
                    r.ns_per_bead_step / ours.ns_per_bead_step
                )
            })
            .collect();
        println!("- N = {n}: {}", parts.join(", "));
    }
}
