//! Beads with radii that strike avian2d's bodies: the reference truths of
//! ../shared/PHYSICS.md, "Bodies beside beads" (a bead dropped on a floor
//! rises to `e² h`; a head-on strike exchanges velocities), momentum and
//! energy kept with dynamic bodies, no tunnelling, resting contact on a
//! moving platform.

use std::f32::consts::FRAC_PI_2;

use avian2d::math::{AdjustPrecision, Vector};
use avian2d::prelude::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::prelude::*;
use wirebead::{BeadStruckBody, Restitution as BeadRestitution, SceneEnergy};

use super::avian::physics_app_with;

const G: f64 = 9.81;
const DT: f64 = 1.0 / 60.0;

/// A line wire through `(x, 0)` at `angle` radians from +x.
fn line(app: &mut App, x: f32, angle: f32) -> Entity {
    let at = Transform::from_xyz(x, 0.0, 0.0).with_rotation(Quat::from_rotation_z(angle));
    app.world_mut().spawn((Wire::line(), at)).id()
}

/// A bead of `mass` and `radius` on `wire` at `at` moving at `velocity`,
/// of restitution `e`.
fn bead(
    app: &mut App,
    wire: Entity,
    (at, velocity): (DVec2, DVec2),
    (mass, radius, e): (f64, f64, f64),
) -> Entity {
    let params = BeadParams {
        mass,
        initial_position: at,
        initial_velocity: velocity,
    };
    app.world_mut()
        .spawn((
            Bead::new(params).expect("a bead"),
            OnWire(wire),
            BeadRadius::new(radius).expect("a radius"),
            BeadRestitution::new(e).expect("a restitution"),
        ))
        .id()
}

fn state(app: &App, bead: Entity) -> (DVec2, DVec2) {
    let world = app.world();
    if let Some(d) = world.get::<Diverged>(bead) {
        panic!("the bead stopped: {:?}", d);
    }
    let x = world.get::<BeadPosition>(bead).expect("a bead").0;
    let v = world.get::<BeadVelocity>(bead).expect("a bead").0;
    (x, v)
}

fn body(app: &App, body: Entity) -> (DVec2, DVec2, f64) {
    let world = app.world();
    let x = DVec2::from(world.get::<Position>(body).expect("a body").0);
    let v = DVec2::from(world.get::<LinearVelocity>(body).expect("a body").0);
    let w = f64::from(world.get::<AngularVelocity>(body).expect("a body").0);
    (x, v, w)
}

/// The strikes sent this update.
fn strikes(app: &App) -> Vec<BeadStruckBody> {
    crate::common::sent(app)
}

/// A bead of radius 5 cm dropped from 1 m (its lowest point) on a vertical
/// line onto a static floor, each of restitution 0.5 (the strike takes
/// their mean), rises to `e² h = 0.25 m`, striking at `√(2 g h)` and again at `e`
/// times that, to what avian's `f32` floor leaves; it never sinks in.
#[test]
fn a_bead_dropped_on_a_static_floor_rises_to_e_squared_h() {
    let mut app = physics_app_with(DT, 6, DVec2::new(0.0, -G));
    let wire = line(&mut app, 0.0, FRAC_PI_2);
    let r = 0.05;
    let dropped = bead(
        &mut app,
        wire,
        (DVec2::new(0.0, 1.0 + r), DVec2::ZERO),
        (1.0, r, 0.5),
    );
    app.world_mut().spawn((
        RigidBody::Static,
        Collider::rectangle(4.0, 1.0),
        Position(Vector::new(0.0, -0.5)),
        Restitution::new(0.5),
    ));
    let (mut top, mut struck, mut lowest) = (0.0_f64, Vec::new(), f64::INFINITY);
    for _ in 0..90 {
        app.update();
        struck.extend(strikes(&app));
        let (x, _) = state(&app, dropped);
        lowest = lowest.min(x.y - r);
        if struck.len() == 1 {
            top = top.max(x.y - r);
        }
    }
    println!("strikes {struck:?}, rose to {top:.9} m, lowest {lowest:e} m");
    let closing = (2.0 * G).sqrt();
    assert!((struck[0].closing_speed - closing).abs() < 1e-6 * closing);
    assert!(struck[0].bounced);
    // From e² h it strikes again at e times the speed.
    assert!((struck[1].closing_speed - 0.5 * closing).abs() < 1e-6 * closing);
    // The apex falls between two steps: within a step's fall of it.
    assert!(
        (0.25 - 0.5 * G * DT * DT..=0.25 + 1e-6).contains(&top),
        "rose to {top}"
    );
    assert!(lowest >= -1e-6, "sank {lowest:e} m into the floor");
}

/// A bead of 1 kg at 2 m/s on a level line strikes a free ball of 1 kg
/// head on, both of restitution 1 and no friction, no gravity: the bead stops and the
/// ball leaves at 2 m/s without turning (the 1D strike of equal masses),
/// momentum and energy kept to `f32` rounding; the scene's energy, which
/// counts the ball, stays 2 J throughout.
#[test]
fn a_bead_strikes_a_free_ball_head_on_and_stops() {
    let mut app = physics_app_with(DT, 6, DVec2::ZERO);
    let wire = line(&mut app, 0.0, 0.0);
    let u = 2.0;
    let moving = bead(
        &mut app,
        wire,
        (DVec2::new(-1.0, 0.0), DVec2::new(u, 0.0)),
        (1.0, 0.1, 1.0),
    );
    let ball = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Collider::circle(0.2),
            Mass(1.0),
            Position(Vector::new(0.5, 0.0)),
            Restitution::new(1.0),
            Friction::new(0.0),
            SleepingDisabled,
        ))
        .id();
    app.init_resource::<SceneEnergy>();
    let mut off = 0.0_f64;
    for _ in 0..60 {
        app.update();
        let total = app.world().resource::<SceneEnergy>().total;
        off = off.max((total - 0.5 * u * u).abs());
    }
    let (_, v) = state(&app, moving);
    let (_, w, spin) = body(&app, ball);
    println!("bead {v}, ball {w} turning {spin:e}, the scene's energy off by up to {off:e} J");
    // The scene's energy counts the ball's: it stays the bead's first.
    assert!(off < 1e-5, "the scene's energy moved by {off:e} J");
    assert!(v.length() < 1e-5, "the bead moves on at {v}");
    assert!(
        (w - DVec2::new(u, 0.0)).length() < 1e-5,
        "the ball leaves at {w}"
    );
    assert!(spin.abs() < 1e-6);
}

/// A bead strikes a free box 10 cm off its centre line: the box takes the
/// bead's impulse at that point, so that it turns at `(r × J) / I`, and
/// the strike at `e = 1` keeps momentum along the line and the kinetic
/// energy, to `f32` rounding.
#[test]
fn a_bead_striking_a_box_off_centre_turns_it_and_keeps_momentum_and_energy() {
    let mut app = physics_app_with(DT, 6, DVec2::ZERO);
    let wire = line(&mut app, 0.0, 0.0);
    let (u, m, mass, inertia) = (2.0, 1.0, 2.0, 0.05);
    // The line at y = 0 meets the box's face 0.1 m above its centre.
    let moving = bead(
        &mut app,
        wire,
        (DVec2::new(-1.0, 0.0), DVec2::new(u, 0.0)),
        (m, 0.05, 1.0),
    );
    let struck = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Collider::rectangle(0.4, 0.6),
            Mass(mass as f32),
            AngularInertia(inertia as f32),
            Position(Vector::new(0.5, -0.1)),
            Restitution::new(1.0),
            Friction::new(0.0),
            SleepingDisabled,
        ))
        .id();
    app.init_resource::<SceneEnergy>();
    let (mut impulses, mut hits, mut off) = (0.0, 0, 0.0_f64);
    for _ in 0..60 {
        app.update();
        for s in strikes(&app) {
            impulses += s.impulse;
            hits += 1;
        }
        let total = app.world().resource::<SceneEnergy>().total;
        off = off.max((total - 0.5 * m * u * u).abs());
    }
    let (_, v) = state(&app, moving);
    let (_, w, spin) = body(&app, struck);
    let momentum = m * v.x + mass * w.x;
    let energy = 0.5 * m * v.length_squared()
        + 0.5 * mass * w.length_squared()
        + 0.5 * inertia * spin * spin;
    println!(
        "{hits} strike(s), impulse {impulses}, bead {v}, box {w} turning {spin}, momentum {momentum}, energy {energy}"
    );
    assert_eq!(hits, 1);
    assert!(
        (mass * w.x - impulses).abs() < 1e-5,
        "the box took {w} for {impulses} N s"
    );
    // r × J about the centre: r = (-0.2, 0.1), J = (p, 0).
    assert!(
        (inertia * spin + 0.1 * impulses).abs() < 1e-5,
        "turning at {spin}"
    );
    assert!((momentum - m * u).abs() < 1e-5, "momentum {momentum}");
    assert!((energy - 0.5 * m * u * u).abs() < 1e-5, "energy {energy}");
    // The scene's energy counts the box's, turning included.
    assert!(off < 1e-5, "the scene's energy moved by {off:e} J");
}

/// A bead at 300 m/s (5 m a step at 60 Hz) meets a static wall 2 cm
/// thick within a step: it bounces back off the wall's near face at its
/// speed (e = 1), never past it, however far the step would take it.
#[test]
fn a_bead_as_fast_as_a_bullet_bounces_off_a_thin_wall() {
    let mut app = physics_app_with(DT, 6, DVec2::ZERO);
    let wire = line(&mut app, 0.0, 0.0);
    let (u, r) = (300.0, 0.05);
    let fast = bead(
        &mut app,
        wire,
        (DVec2::new(-1.0, 0.0), DVec2::new(u, 0.0)),
        (1.0, r, 1.0),
    );
    app.world_mut().spawn((
        RigidBody::Static,
        Collider::rectangle(0.02, 2.0),
        Position(Vector::new(1.01, 0.0)),
        Restitution::new(1.0),
    ));
    let mut farthest = f64::NEG_INFINITY;
    for _ in 0..3 {
        app.update();
        let (x, _) = state(&app, fast);
        farthest = farthest.max(x.x);
    }
    let (x, v) = state(&app, fast);
    println!("at {x}, moving {v}, farthest {farthest}");
    assert!(
        farthest <= 1.0 - r + 1e-6,
        "passed the wall's face to {farthest}"
    );
    assert!((v.x + u).abs() < 1e-6 * u, "moving {v}");
}

/// A bead resting on a kinematic platform that rises at 0.5 m/s rides it
/// up: after a second it sits on the platform's top, to what avian's
/// `f32` positions leave, moving with it.
#[test]
fn a_bead_rides_a_rising_platform() {
    let mut app = physics_app_with(DT, 6, DVec2::new(0.0, -G));
    let wire = line(&mut app, 0.0, FRAC_PI_2);
    let r = 0.05;
    // Restitution 0 and the platform's 0: it does not bounce as the
    // platform sets off.
    let rider = bead(
        &mut app,
        wire,
        (DVec2::new(0.0, r), DVec2::ZERO),
        (1.0, r, 0.0),
    );
    let platform = app
        .world_mut()
        .spawn((
            RigidBody::Kinematic,
            Collider::rectangle(1.0, 0.2),
            Position(Vector::new(0.0, -0.1)),
            LinearVelocity(DVec2::new(0.0, 0.5).adjust_precision()),
        ))
        .id();
    let mut off = 0.0_f64;
    for _ in 0..60 {
        app.update();
        let (x, _) = state(&app, rider);
        let (top, _, _) = body(&app, platform);
        off = off.max((x.y - r - (top.y + 0.1)).abs());
    }
    let (x, v) = state(&app, rider);
    println!("at {x} moving {v}, off the top by up to {off:e} m");
    assert!(off < 1e-5, "{off:e} m off the platform's top");
    assert!((x.y - r - 0.5).abs() < 1e-4, "at {x}");
    assert!((v.y - 0.5).abs() < 1e-5, "moving {v}");
}

/// A hundred marbles (radius 5 cm, 0.1 kg) at 20 m/s, each on a level
/// rail of its own 12 cm above the last, run into a wall of ten static
/// boxes 10 cm thick, each of restitution 0.5: over 1 s at 60 Hz (a third
/// of a metre a step, three times the wall's thickness) each strikes the
/// wall once, at its face, and none passes through.
#[test]
fn a_hundred_marbles_at_20_m_s_never_pass_a_wall_of_boxes() {
    let mut app = physics_app_with(DT, 6, DVec2::ZERO);
    let r = 0.05;
    let face = 3.0 - 0.05;
    let mut marbles = Vec::new();
    for row in 0..100 {
        let y = 0.12 * row as f64;
        let at = Transform::from_xyz(0.0, y as f32, 0.0);
        let wire = app.world_mut().spawn((Wire::line(), at)).id();
        // Each a little behind the last, so that they strike one by one.
        let start = (DVec2::new(-0.01 * row as f64, y), DVec2::new(20.0, 0.0));
        marbles.push(bead(&mut app, wire, start, (0.1, r, 0.5)));
    }
    for block in 0..10 {
        app.world_mut().spawn((
            RigidBody::Static,
            Collider::rectangle(0.1, 1.2),
            Position(Vector::new(3.0, (0.6 + 1.2 * block as f64 - 0.06) as _)),
            Restitution::new(0.5),
        ));
    }
    let (mut farthest, mut struck) = (f64::NEG_INFINITY, Vec::new());
    for _ in 0..60 {
        app.update();
        struck.extend(strikes(&app));
        for &m in &marbles {
            farthest = farthest.max(state(&app, m).0.x);
        }
    }
    let first: Vec<f64> = struck.iter().map(|s| s.closing_speed).collect();
    println!(
        "{} strikes on the wall; the farthest centre {farthest} m (the face at {face} m)",
        struck.len()
    );
    assert_eq!(struck.len(), 100, "each marble strikes the wall once");
    assert!(first.iter().all(|&u| (u - 20.0).abs() < 1e-9), "{first:?}");
    assert!(farthest <= face - r + 1e-6, "a marble reached {farthest} m");
}
