//! The pile job: beads poured into a bowl, ours against avian's colliders.
//!
//! - **The scene** ([`Pour`]): `--beads` beads of 2 cm and 1 kg at rest on
//!   a grid in the bottom of a bowl of radius 1 m, lowest first, under
//!   gravity `(0, -9.81)` (`(0, -9.81, 0)` in space), `--steps` steps of
//!   `--dt`, in the plane and in space.
//! - **Ours**: the plugin with the pour's scene file: each bead on a
//!   one-sided circle (sphere) of radius 1 m that pushes inward, at
//!   `e = 0`, RATTLE; its contacts are one dense island's.
//! - **avian2d / avian3d**: each bead a dynamic body with a
//!   `Collider::circle(0.02)` (`sphere`), restitution 0, no friction,
//!   rotation locked, mass 1 (`NoAutoMass`); the bowl one static body,
//!   in the plane a closed `Collider::polyline` of 512 segments on a
//!   circle of radius 1.02 m, in space a `Collider::trimesh` of a sphere
//!   of radius 1.02 m (64 × 32 quads), so that a ball's centre rests
//!   where ours does, 1 m from the middle. Default substeps (6); the
//!   other settings are the `avian_side` app's (no damping, no sleeping,
//!   the transform sync off).
//!
//! Measured over each run: the wall milliseconds of each step (the
//! `App::update` call alone), their mean over the fall and the first
//! landings (up to 0.5 s), the piling (0.5 to 1.5 s) and the settling
//! (from 1.5 s), and the worst; the worst overlap of two beads and the
//! worst of a bead into the bowl, as shares of a radius; the largest rise
//! of the energy (kinetic plus potential) from one step to the next, and
//! the energy at the end less the lowest it has been. A run that passes
//! `--budget` seconds of stepping stops there, and the table says where.

use std::time::Duration;

use bevy::app::App;
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;
use clap::{Args, ValueEnum};
use wirebead::headless::{Headless, bead_state, space_bead_state};
use wirebead::prelude::*;
use wirebead::preset::{PILE_RADIUS, Pour};

use crate::{avian_side, touch};

/// Magnitude of gravity, m/s², along −y (the scene files' default).
const GRAVITY: f64 = 9.81;
/// The bowl's radius (where the beads' centres rest), metres.
const BOWL: f64 = 1.0;

/// Options of the pile job.
#[derive(Args, Debug)]
pub struct PileArgs {
    /// Beads poured.
    #[arg(long, default_value_t = 1000, value_parser = avian_side::positive)]
    pub beads: usize,
    /// The timestep, seconds.
    #[arg(long, default_value_t = 1.0 / 60.0, value_parser = avian_side::positive_f64)]
    pub dt: f64,
    /// Steps to simulate.
    #[arg(long, default_value_t = 180, value_parser = avian_side::positive)]
    pub steps: usize,
    /// Wall seconds of stepping each run may take before it stops.
    #[arg(long, default_value_t = 300.0, value_parser = avian_side::positive_f64)]
    pub budget: f64,
    /// The piles to pour.
    #[arg(long, value_enum, default_value_t = Piles::Both)]
    pub piles: Piles,
}

/// Which piles the job pours.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Piles {
    /// In the plane, against avian2d.
    Plane,
    /// In space, against avian3d.
    Space,
    /// Both.
    Both,
}

/// Each bead's position and velocity, in space (`z = 0` in the plane).
type States = Vec<(DVec3, DVec3)>;

/// One pile being poured: its app, its beads, how to read them and how
/// to take one step (returning its wall seconds).
struct Pile {
    app: App,
    beads: Vec<Entity>,
    read: fn(&App, &[Entity]) -> States,
    step: fn(&mut App, usize) -> f64,
}

/// What one run measured.
struct Run {
    name: String,
    /// Wall seconds of each step taken.
    seconds: Vec<f64>,
    /// The worst overlap of two beads, as a share of a radius.
    overlap: f64,
    /// The worst of a bead past the bowl, as a share of a radius.
    into_bowl: f64,
    /// The largest rise of the energy from one step to the next, J.
    rise: f64,
    /// The energy at the end less the lowest it has been, J.
    above: f64,
    /// Where the budget stopped it, if it did.
    stopped: Option<usize>,
}

/// Our beads' states in the plane.
fn ours_plane(app: &App, beads: &[Entity]) -> States {
    beads
        .iter()
        .map(|&b| {
            let s = bead_state(app.world(), b).expect("a bead");
            (s.position.extend(0.0), s.velocity.extend(0.0))
        })
        .collect()
}

/// Our beads' states in space.
fn ours_space(app: &App, beads: &[Entity]) -> States {
    beads
        .iter()
        .map(|&b| {
            let s = space_bead_state(app.world(), b).expect("a bead");
            (s.position, s.velocity)
        })
        .collect()
}

/// An avian side's balls' states: their `P`osition and `L`inear
/// velocity components, lifted into space by `lift`.
fn theirs<P, L, V>(app: &App, beads: &[Entity], lift: fn(V) -> DVec3) -> States
where
    P: Component + std::ops::Deref<Target = V>,
    L: Component + std::ops::Deref<Target = V>,
    V: Copy,
{
    let world = app.world();
    beads
        .iter()
        .map(|&b| {
            let x = **world.get::<P>(b).expect("a position");
            let v = **world.get::<L>(b).expect("a velocity");
            (lift(x), lift(v))
        })
        .collect()
}

/// avian2d's balls' states.
fn theirs_plane(app: &App, beads: &[Entity]) -> States {
    use avian2d::prelude::{LinearVelocity, Position};
    theirs::<Position, LinearVelocity, DVec2>(app, beads, |v| v.extend(0.0))
}

/// avian3d's balls' states.
fn theirs_space(app: &App, beads: &[Entity]) -> States {
    use avian3d::prelude::{LinearVelocity, Position};
    theirs::<Position, LinearVelocity, DVec3>(app, beads, |v| v)
}

/// Steps an avian3d app once.
fn space_step(app: &mut App, k: usize) -> f64 {
    let step = app.world().resource::<Time<Fixed>>().timestep();
    avian_side::space::timed_step(app, step, k)
}

/// The pour's starting places, in space (`z = 0` in the plane).
fn places(args: &PileArgs, space: bool) -> (wirebead::SceneFile, Vec<DVec3>) {
    let scene = Pour {
        beads: args.beads,
        space,
        bowl: BOWL,
        timestep: args.dt,
    }
    .scene()
    .unwrap_or_else(|e| panic!("{e}"));
    let at = match &scene {
        wirebead::SceneFile::Plane(scene) => scene
            .all_beads()
            .map(|b| b.initial_position.extend(0.0))
            .collect(),
        wirebead::SceneFile::Space(scene) => scene
            .wires
            .iter()
            .flat_map(|w| &w.beads)
            .map(|b| b.initial_position)
            .collect(),
    };
    (scene, at)
}

/// Our pile.
fn our_pile(args: &PileArgs, space: bool) -> Pile {
    let (scene, _) = places(args, space);
    let plugin = WireBeadPlugin::new(scene.params().clone()).expect("valid parameters");
    let mut app = Headless::new(plugin).build();
    let beads = scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    Pile {
        app,
        beads,
        read: if space { ours_space } else { ours_plane },
        step: touch::our_step,
    }
}

/// avian2d's pile.
fn their_plane_pile(args: &PileArgs) -> Pile {
    use avian2d::prelude::{
        AngularInertia, CoefficientCombine, Collider, Friction, LockedAxes, Mass,
        NoAutoAngularInertia, NoAutoMass, Position, Restitution, RigidBody, SleepingDisabled,
    };
    let (_, at) = places(args, false);
    let step = Duration::from_secs_f64(args.dt);
    let mut app = avian_side::physics_app(step, None, DVec2::new(0.0, -GRAVITY), None);
    let world = app.world_mut();
    let rim = BOWL + PILE_RADIUS;
    let mut rim_points: Vec<DVec2> = (0..512)
        .map(|k| rim * DVec2::from_angle(std::f64::consts::TAU * k as f64 / 512.0))
        .collect();
    rim_points.push(rim_points[0]);
    world.spawn((
        RigidBody::Static,
        Position(DVec2::ZERO),
        Transform::default(),
        Collider::polyline(rim_points, None),
        Friction::ZERO,
        Restitution::ZERO.with_combine_rule(CoefficientCombine::Min),
    ));
    let beads = at
        .iter()
        .map(|x| {
            world
                .spawn((
                    RigidBody::Dynamic,
                    Position(x.truncate()),
                    Transform::default(),
                    Collider::circle(PILE_RADIUS),
                    Restitution::ZERO.with_combine_rule(CoefficientCombine::Min),
                    Friction::ZERO,
                    LockedAxes::ROTATION_LOCKED,
                    Mass(1.0),
                    AngularInertia(1.0),
                    NoAutoMass,
                    NoAutoAngularInertia,
                    SleepingDisabled,
                ))
                .id()
        })
        .collect();
    avian_side::warm_up(&mut app);
    Pile {
        app,
        beads,
        read: theirs_plane,
        step: touch::their_step,
    }
}

/// A sphere of radius `radius` as triangles: `around` quads round and
/// `up` from pole to pole, each split in two.
fn sphere_mesh(radius: f64, around: u32, up: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut vertices = Vec::new();
    for j in 0..=up {
        let polar = std::f64::consts::PI * f64::from(j) / f64::from(up);
        for i in 0..around {
            let azimuth = std::f64::consts::TAU * f64::from(i) / f64::from(around);
            vertices.push(
                radius
                    * DVec3::new(
                        polar.sin() * azimuth.cos(),
                        polar.cos(),
                        polar.sin() * azimuth.sin(),
                    ),
            );
        }
    }
    let at = |i: u32, j: u32| j * around + i % around;
    let mut triangles = Vec::new();
    for j in 0..up {
        for i in 0..around {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    (vertices, triangles)
}

/// avian3d's pile.
fn their_space_pile(args: &PileArgs) -> Pile {
    use avian3d::prelude::{
        AngularInertia, CoefficientCombine, Collider, Friction, LockedAxes, Mass,
        NoAutoAngularInertia, NoAutoMass, Position, Restitution, RigidBody, SleepingDisabled,
    };
    let (_, at) = places(args, true);
    let step = Duration::from_secs_f64(args.dt);
    let mut app = avian_side::space::physics_app(step, None, DVec3::new(0.0, -GRAVITY, 0.0), None);
    let world = app.world_mut();
    let (vertices, triangles) = sphere_mesh(BOWL + PILE_RADIUS, 64, 32);
    world.spawn((
        RigidBody::Static,
        Position(DVec3::ZERO),
        Transform::default(),
        Collider::trimesh(vertices, triangles),
        Friction::ZERO,
        Restitution::ZERO.with_combine_rule(CoefficientCombine::Min),
    ));
    let beads = at
        .iter()
        .map(|&x| {
            world
                .spawn((
                    RigidBody::Dynamic,
                    Position(x),
                    Transform::default(),
                    Collider::sphere(PILE_RADIUS),
                    Restitution::ZERO.with_combine_rule(CoefficientCombine::Min),
                    Friction::ZERO,
                    LockedAxes::ROTATION_LOCKED,
                    Mass(1.0),
                    AngularInertia::new(bevy::math::Vec3::ONE),
                    NoAutoMass,
                    NoAutoAngularInertia,
                    SleepingDisabled,
                ))
                .id()
        })
        .collect();
    avian_side::space::warm_up(&mut app);
    Pile {
        app,
        beads,
        read: theirs_space,
        step: space_step,
    }
}

/// The worst overlap of two beads of [`PILE_RADIUS`] at `states`, as a
/// share of a radius (negative while all are apart): sorted along x, each
/// bead against those within a diameter of it along x.
fn worst_overlap(states: &States) -> f64 {
    let r = PILE_RADIUS;
    let mut x: Vec<DVec3> = states.iter().map(|s| s.0).collect();
    x.sort_by(|a, b| a.x.total_cmp(&b.x));
    let mut worst = f64::MIN;
    for (i, a) in x.iter().enumerate() {
        for b in x[i + 1..].iter().take_while(|b| b.x - a.x < 2.0 * r) {
            worst = worst.max((2.0 * r - (*b - *a).length()) / r);
        }
    }
    worst
}

/// The energy of beads of 1 kg at `states`: kinetic plus potential.
fn energy(states: &States) -> f64 {
    states
        .iter()
        .map(|(x, v)| 0.5 * v.length_squared() + GRAVITY * x.y)
        .sum()
}

/// Pours `pile` for the job's steps, or until its budget runs out.
fn pour(name: String, mut pile: Pile, args: &PileArgs) -> Run {
    let mut run = Run {
        name,
        seconds: Vec::with_capacity(args.steps),
        overlap: f64::MIN,
        into_bowl: f64::MIN,
        rise: f64::MIN,
        above: 0.0,
        stopped: None,
    };
    let states = (pile.read)(&pile.app, &pile.beads);
    let (mut before, mut lowest) = (energy(&states), energy(&states));
    for k in 1..=args.steps {
        run.seconds.push((pile.step)(&mut pile.app, k));
        let states = (pile.read)(&pile.app, &pile.beads);
        run.overlap = run.overlap.max(worst_overlap(&states));
        let past = states
            .iter()
            .map(|(x, _)| (x.length() - BOWL) / PILE_RADIUS)
            .fold(f64::MIN, f64::max);
        run.into_bowl = run.into_bowl.max(past);
        let e = energy(&states);
        run.rise = run.rise.max(e - before);
        lowest = lowest.min(e);
        run.above = e - lowest;
        before = e;
        if run.seconds.iter().sum::<f64>() > args.budget && k < args.steps {
            run.stopped = Some(k);
            break;
        }
    }
    eprintln!("done: {}", run.name);
    run
}

/// The mean milliseconds of `run`'s steps from `from` to `to` seconds of
/// simulated time, or a dash where it took none.
fn phase(run: &Run, dt: f64, (from, to): (f64, f64)) -> String {
    let taken: Vec<f64> = run
        .seconds
        .iter()
        .enumerate()
        .filter(|(k, _)| {
            let t = *k as f64 * dt;
            t >= from && t < to
        })
        .map(|(_, s)| *s)
        .collect();
    if taken.is_empty() {
        "—".into()
    } else {
        format!(
            "{:.1}",
            1e3 * taken.iter().sum::<f64>() / taken.len() as f64
        )
    }
}

/// Runs the pile job and prints its table.
pub fn run(args: &PileArgs) {
    let mut runs = Vec::new();
    if args.piles != Piles::Space {
        runs.push(pour(
            "wirebead RATTLE, plane".into(),
            our_pile(args, false),
            args,
        ));
        runs.push(pour(
            format!("avian2d, {} substeps", avian_side::default_substeps()),
            their_plane_pile(args),
            args,
        ));
    }
    if args.piles != Piles::Plane {
        runs.push(pour(
            "wirebead RATTLE, space".into(),
            our_pile(args, true),
            args,
        ));
        runs.push(pour(
            format!("avian3d, {} substeps", avian_side::default_substeps()),
            their_space_pile(args),
            args,
        ));
    }
    let end = args.steps as f64 * args.dt;
    println!(
        "## {} beads of 2 cm poured into a bowl of 1 m at e = 0, dt = {:.5} s, {} steps ({end:.2} s)\n",
        args.beads, args.dt, args.steps
    );
    println!(
        "| run | ms per step, up to 0.5 s | 0.5 to 1.5 s | from 1.5 s | worst step (ms) | worst overlap (of a radius) | worst into the bowl (of a radius) | largest energy rise in a step (J) | energy at the end above its lowest (J) | steps taken |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for r in &runs {
        let worst = r.seconds.iter().copied().fold(0.0, f64::max);
        let taken = match r.stopped {
            Some(k) => format!("{k}, stopped by the {:.0} s budget", args.budget),
            None => r.seconds.len().to_string(),
        };
        println!(
            "| {} | {} | {} | {} | {:.1} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {taken} |",
            r.name,
            phase(r, args.dt, (0.0, 0.5)),
            phase(r, args.dt, (0.5, 1.5)),
            phase(r, args.dt, (1.5, f64::INFINITY)),
            1e3 * worst,
            r.overlap,
            r.into_bowl,
            r.rise,
            r.above,
        );
    }
}
