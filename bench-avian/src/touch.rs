//! The touch job: beads that strike, ours against avian2d's colliders.
//!
//! - **Newton's cradle**: five balls of 1 kg and radius 5 cm hanging
//!   touching from pivots 10 cm apart on rods of 1 m, the first released
//!   from 30°, under gravity `(0, -10)`, `--steps` steps of `--dt`.
//!   Ours: the plugin, each ball a bead with a [`BeadRadius`] on a
//!   [`Rod`] to a pinned pivot bead, RATTLE, restitution 1. avian2d: each
//!   ball a dynamic body with a `Collider::circle(0.05)`, `Restitution`
//!   1 (combined by `Max`), no friction, rotation locked, its mass and
//!   inertia its own (`NoAutoMass`), on a `DistanceJoint` (`min = max =
//!   1`, zero compliance) to a static pivot body; default substeps and
//!   each of `--substeps`. The other settings are the `avian_side` app's
//!   (no damping, no sleeping, the transform sync off).
//! - **The air track**: two gliders on a level line, 1 kg (radius 0.1 m)
//!   at 2 m/s toward 3 kg (radius 0.15 m) at −0.5 m/s, 1.5 m apart,
//!   elastic and at restitution 0, no gravity along the track. Ours: the
//!   plugin, each glider a bead with a radius on a [`Wire::line`].
//!   avian2d: two dynamic bodies with circle colliders, their `y` and
//!   rotation locked (`LockedAxes`), no gravity.
//!
//! Measured: the cradle's speed out of the last ball (its fastest over the
//! run) against the first's at the bottom, `sqrt(2 g h)`; the fastest of
//! the other four after the first strike; the last ball's highest point
//! against the release height; the row's momentum along x and its energy
//! across the step of the strikes; the air track's velocities after the
//! strike against the one-dimensional formulas, its momentum and energy
//! change; wall ns per step of the whole scene (the `App::update` calls
//! alone).

use std::time::{Duration, Instant};

use avian2d::prelude::{
    AngularInertia, CoefficientCombine, Collider, DistanceJoint, Friction, LinearVelocity,
    LockedAxes, Mass, NoAutoAngularInertia, NoAutoMass, Position, Restitution as AvianRestitution,
    RigidBody, SleepingDisabled,
};
use bevy::app::App;
use bevy::math::DVec2;
use bevy::prelude::*;
use clap::Args;
use wirebead::headless::{Headless, bead_state};
use wirebead::prelude::*;
use wirebead::{Contacts, Integrator};

use crate::avian_side;

/// Magnitude of gravity, m/s², pointing along -y.
const GRAVITY: f64 = 10.0;
/// The cradle's ball radius, rod length and release angle (degrees).
const BALL: f64 = 0.05;
/// The cradle's rods, metres.
const ROD: f64 = 1.0;
/// The first ball's release angle, degrees.
const RELEASE: f64 = 30.0;
/// The gliders: mass, radius, start, velocity.
const GLIDERS: [(f64, f64, f64, f64); 2] = [(1.0, 0.1, -1.5, 2.0), (3.0, 0.15, 0.0, -0.5)];

/// Options of the touch job.
#[derive(Args, Debug)]
pub struct TouchArgs {
    /// The timestep, seconds.
    #[arg(long, default_value_t = 1.0 / 60.0, value_parser = avian_side::positive_f64)]
    pub dt: f64,
    /// Steps to simulate (the cradle's first ball strikes after about
    /// half a second, the last one is back down after another second).
    #[arg(long, default_value_t = 120, value_parser = avian_side::positive)]
    pub steps: usize,
    /// avian2d substep counts to run besides its default, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "50", value_parser = clap::value_parser!(u32).range(1..))]
    pub substeps: Vec<u32>,
}

/// A body's position and velocity, whichever side it is on.
type State = (DVec2, DVec2);

/// Reads the states of `bodies` in `app`.
type Reader = fn(&App, Entity) -> State;

/// Our bead's state.
fn ours(app: &App, bead: Entity) -> State {
    let s = bead_state(app.world(), bead).expect("a bead");
    (s.position, s.velocity)
}

/// An avian body's state.
fn theirs(app: &App, body: Entity) -> State {
    let world = app.world();
    (
        world.get::<Position>(body).expect("a Position").0,
        world.get::<LinearVelocity>(body).expect("a velocity").0,
    )
}

/// One scene being stepped: its app, the bodies measured, how to read
/// them and how to take one step (returning its wall seconds).
struct Scene {
    app: App,
    bodies: Vec<Entity>,
    masses: Vec<f64>,
    read: Reader,
    step: fn(&mut App, usize) -> f64,
}

impl Scene {
    fn states(&self) -> Vec<State> {
        self.bodies
            .iter()
            .map(|&b| (self.read)(&self.app, b))
            .collect()
    }

    /// Momentum along x and energy (kinetic plus potential) of the bodies.
    fn momentum_and_energy(&self) -> (f64, f64) {
        self.states()
            .iter()
            .zip(&self.masses)
            .fold((0.0, 0.0), |(p, e), ((x, v), m)| {
                (
                    p + m * v.x,
                    e + m * (0.5 * v.length_squared() + GRAVITY * x.y),
                )
            })
    }
}

/// Steps our app once.
pub(crate) fn our_step(app: &mut App, _: usize) -> f64 {
    let start = Instant::now();
    app.update();
    start.elapsed().as_secs_f64()
}

/// Steps an avian2d app once.
pub(crate) fn their_step(app: &mut App, k: usize) -> f64 {
    let step = app.world().resource::<Time<Fixed>>().timestep();
    avian_side::timed_step(app, step, k)
}

/// Our app at `dt` with restitution `e`, gravity `(0, -g)`.
fn our_app(dt: f64, e: f64, g: f64) -> App {
    let params = SimParams {
        timestep: dt,
        gravity: DVec2::new(0.0, -g),
        method: Method::new(Integrator::Rattle, None).expect("RATTLE"),
        ..SimParams::default()
    };
    let mut app = Headless::new(WireBeadPlugin::new(params).expect("valid parameters")).build();
    app.insert_resource(Contacts::new(e).expect("a restitution"));
    app
}

/// An avian app at `dt` and `substeps`, gravity `(0, -g)`.
fn their_app(dt: f64, substeps: u32, g: f64) -> App {
    let step = Duration::from_secs_f64(dt);
    avian_side::physics_app(step, None, DVec2::new(0.0, -g), Some(substeps))
}

/// An avian ball: a dynamic circle of `mass` and `radius` at `at` moving at
/// `v`, bouncing with `e`, frictionless, not turning.
fn avian_ball(
    world: &mut World,
    mass: f64,
    radius: f64,
    at: DVec2,
    v: DVec2,
    e: f64,
) -> EntityWorldMut<'_> {
    world.spawn((
        RigidBody::Dynamic,
        Position(at),
        LinearVelocity(v),
        // A collider takes its scale from the body's `GlobalTransform`
        // when it is added (none: scale zero, a collider of no size); the
        // transform sync is off (see `avian_side`), so it stays the identity.
        Transform::default(),
        Collider::circle(radius),
        AvianRestitution::new(e).with_combine_rule(CoefficientCombine::Max),
        Friction::ZERO,
        Mass(mass as f32),
        AngularInertia(1.0),
        NoAutoMass,
        NoAutoAngularInertia,
        SleepingDisabled,
    ))
}

/// Where the cradle's pivots and balls start: the first ball pulled back.
fn cradle_layout() -> Vec<(DVec2, DVec2)> {
    let angle = RELEASE.to_radians();
    (0..5)
        .map(|i| {
            let pivot = DVec2::new(2.0 * BALL * i as f64, ROD);
            let ball = if i == 0 {
                pivot + ROD * DVec2::new(-angle.sin(), -angle.cos())
            } else {
                pivot - ROD * DVec2::Y
            };
            (pivot, ball)
        })
        .collect()
}

/// Our cradle.
fn our_cradle(dt: f64) -> Scene {
    let mut app = our_app(dt, 1.0, GRAVITY);
    let world = app.world_mut();
    let bodies = cradle_layout()
        .into_iter()
        .map(|(pivot_at, ball_at)| {
            let pivot = world
                .spawn(Bead::at_rest(1.0, pivot_at).expect("a pivot"))
                .id();
            world.spawn(Pin::new(pivot, pivot_at).expect("a pin"));
            let ball = (
                Bead::at_rest(1.0, ball_at).expect("a ball"),
                BeadRadius::new(BALL).expect("a radius"),
            );
            let ball = world.spawn(ball).id();
            world.spawn(Rod::new(pivot, ball, ROD).expect("a rod"));
            ball
        })
        .collect();
    Scene {
        app,
        bodies,
        masses: vec![1.0; 5],
        read: ours,
        step: our_step,
    }
}

/// avian2d's cradle at `substeps`.
fn their_cradle(dt: f64, substeps: u32) -> Scene {
    let mut app = their_app(dt, substeps, GRAVITY);
    let world = app.world_mut();
    let bodies = cradle_layout()
        .into_iter()
        .map(|(pivot_at, ball_at)| {
            let pivot = world.spawn((RigidBody::Static, Position(pivot_at))).id();
            let mut ball = avian_ball(world, 1.0, BALL, ball_at, DVec2::ZERO, 1.0);
            ball.insert(LockedAxes::ROTATION_LOCKED);
            let ball = ball.id();
            world.spawn(
                DistanceJoint::new(pivot, ball)
                    .with_limits(ROD, ROD)
                    .with_compliance(0.0),
            );
            ball
        })
        .collect();
    avian_side::warm_up(&mut app);
    Scene {
        app,
        bodies,
        masses: vec![1.0; 5],
        read: theirs,
        step: their_step,
    }
}

/// What one cradle run measured.
struct CradleRun {
    name: String,
    /// The last ball's fastest speed over its impact speed.
    out: f64,
    /// The fastest of the other four through the half swing after the
    /// first strike, over the impact speed.
    others: f64,
    /// The last ball's highest point over the release height.
    rise: f64,
    /// Momentum change along x across the step of the strikes (kg m/s).
    momentum: f64,
    /// Energy change across that step (J).
    energy: f64,
    ns_per_step: f64,
}

/// Runs a cradle for `steps` steps of `dt`, measuring from the first
/// strike through the half swing after it.
fn run_cradle(name: String, mut scene: Scene, dt: f64, steps: usize) -> CradleRun {
    let release = ROD * (1.0 - RELEASE.to_radians().cos());
    let impact = (2.0 * GRAVITY * release).sqrt();
    let bottom = 0.0;
    let (mut seconds, mut struck) = (0.0, None);
    let (mut out, mut others, mut highest) = (0f64, 0f64, f64::MIN);
    // The half swing after the strike, out and nearly back (the last ball
    // strikes the row again after half a period of the pendulum at this
    // amplitude, here to the second term of its series).
    let amplitude = RELEASE.to_radians();
    let half_swing =
        std::f64::consts::PI * (ROD / GRAVITY).sqrt() * (1.0 + amplitude * amplitude / 16.0);
    let mut first = None;
    for k in 1..=steps {
        let before = scene.momentum_and_energy();
        seconds += (scene.step)(&mut scene.app, k);
        let states = scene.states();
        if struck.is_none() && states[1..].iter().any(|(_, v)| v.length() > 1e-3 * impact) {
            let after = scene.momentum_and_energy();
            struck = Some((after.0 - before.0, after.1 - before.1));
            first = Some(k as f64 * dt);
        }
        if let Some(at) = first
            && k as f64 * dt <= at + 0.95 * half_swing
        {
            out = out.max(states[4].1.length());
            others = states[..4]
                .iter()
                .map(|(_, v)| v.length())
                .fold(others, f64::max);
            highest = highest.max(states[4].0.y - bottom);
        }
    }
    let (momentum, energy) = struck.unwrap_or((f64::NAN, f64::NAN));
    CradleRun {
        name,
        out: out / impact,
        others: others / impact,
        rise: highest / release,
        momentum,
        energy,
        ns_per_step: seconds * 1e9 / steps as f64,
    }
}

/// Our air track at restitution `e`.
fn our_track(dt: f64, e: f64) -> Scene {
    let mut app = our_app(dt, e, GRAVITY);
    let world = app.world_mut();
    let track = world.spawn(Wire::line()).id();
    let bodies = GLIDERS
        .iter()
        .map(|&(m, r, x, v)| {
            let params = BeadParams {
                mass: m,
                initial_position: DVec2::new(x, 0.0),
                initial_velocity: DVec2::new(v, 0.0),
            };
            let glider = (
                Bead::new(params).expect("a glider"),
                OnWire(track),
                BeadRadius::new(r).expect("a radius"),
            );
            world.spawn(glider).id()
        })
        .collect();
    Scene {
        app,
        bodies,
        masses: GLIDERS.iter().map(|g| g.0).collect(),
        read: ours,
        step: our_step,
    }
}

/// avian2d's air track at restitution `e` and `substeps`.
fn their_track(dt: f64, e: f64, substeps: u32) -> Scene {
    let mut app = their_app(dt, substeps, 0.0);
    let world = app.world_mut();
    let bodies = GLIDERS
        .iter()
        .map(|&(m, r, x, v)| {
            let mut glider = avian_ball(world, m, r, DVec2::new(x, 0.0), DVec2::new(v, 0.0), e);
            glider.insert(LockedAxes::new().lock_translation_y().lock_rotation());
            glider.id()
        })
        .collect();
    avian_side::warm_up(&mut app);
    Scene {
        app,
        bodies,
        masses: GLIDERS.iter().map(|g| g.0).collect(),
        read: theirs,
        step: their_step,
    }
}

/// What one air-track run measured.
struct TrackRun {
    name: String,
    /// Each glider's final velocity minus the formula's.
    errors: [f64; 2],
    momentum: f64,
    energy: f64,
    ns_per_step: f64,
}

/// Runs an air track at restitution `e` for `steps` steps.
fn run_track(name: String, mut scene: Scene, e: f64, steps: usize) -> TrackRun {
    let [(m1, ..), (m2, ..)] = GLIDERS;
    let (u1, u2) = (GLIDERS[0].3, GLIDERS[1].3);
    let common = (m1 * u1 + m2 * u2) / (m1 + m2);
    // v = common − e (u − common), each.
    let expected = [common - e * (u1 - common), common - e * (u2 - common)];
    let start = scene.momentum_and_energy();
    let mut seconds = 0.0;
    for k in 1..=steps {
        seconds += (scene.step)(&mut scene.app, k);
    }
    let states = scene.states();
    let end = scene.momentum_and_energy();
    let lost = 0.5 * m1 * m2 / (m1 + m2) * (u1 - u2).powi(2) * (1.0 - e * e);
    TrackRun {
        name,
        errors: [states[0].1.x - expected[0], states[1].1.x - expected[1]],
        momentum: end.0 - start.0,
        energy: end.1 - start.1 + lost,
        ns_per_step: seconds * 1e9 / steps as f64,
    }
}

/// Runs the job and prints its two tables.
pub fn run(args: &TouchArgs) {
    let counts = avian_side::substep_counts(&args.substeps);
    println!(
        "## Newton's cradle: 5 balls, the first from {RELEASE}°, dt = {:.5} s, {} steps\n",
        args.dt, args.steps
    );
    println!(
        "| run | last ball out / impact speed | others' fastest / impact speed | last ball's rise / release height | momentum change at the strikes (kg m/s) | energy change at the strikes (J) | ns per step |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    let mut cradles = vec![run_cradle(
        "wirebead RATTLE".into(),
        our_cradle(args.dt),
        args.dt,
        args.steps,
    )];
    for &k in &counts {
        cradles.push(run_cradle(
            format!("avian2d, {k} substeps"),
            their_cradle(args.dt, k),
            args.dt,
            args.steps,
        ));
    }
    for r in &cradles {
        println!(
            "| {} | {:.6} | {:.2e} | {:.6} | {:.2e} | {:.2e} | {:.0} |",
            r.name, r.out, r.others, r.rise, r.momentum, r.energy, r.ns_per_step
        );
    }
    println!(
        "\n## The air track: 1 kg at 2 m/s into 3 kg at −0.5 m/s, dt = {:.5} s, {} steps\n",
        args.dt, args.steps
    );
    println!(
        "| run | e | light glider's error (m/s) | heavy glider's error (m/s) | momentum change (kg m/s) | energy change beyond ½ μ u² (1 − e²) (J) | ns per step |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for e in [1.0, 0.0] {
        let mut runs = vec![run_track(
            "wirebead RATTLE".into(),
            our_track(args.dt, e),
            e,
            args.steps,
        )];
        for &k in &counts {
            runs.push(run_track(
                format!("avian2d, {k} substeps"),
                their_track(args.dt, e, k),
                e,
                args.steps,
            ));
        }
        for r in &runs {
            println!(
                "| {} | {e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.0} |",
                r.name, r.errors[0], r.errors[1], r.momentum, r.energy, r.ns_per_step
            );
        }
    }
}
