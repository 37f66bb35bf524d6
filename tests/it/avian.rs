//! Rigid bodies of avian2d held on our wires by path joints: the reference
//! truths of ../shared/PHYSICS.md, "Bodies beside beads".

use avian2d::math::{AdjustPrecision, Vector};
use avian2d::prelude::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use wirebead::Integrator;
use wirebead::avian::{PathJoint, PathJointPlugin, PathRotation};
use wirebead::prelude::*;
use wirebead::reference::pendulum_period;

const G: f64 = 9.81;
const DT: f64 = 1.0 / 60.0;
const SUBSTEPS: u32 = 48;

/// Our plugin and avian's, gravity along −y, 60 Hz with `substeps`
/// substeps (avian's default is 6), its first update taken (no step).
fn physics_app(substeps: u32) -> App {
    let params = SimParams {
        timestep: DT,
        gravity: DVec2::new(0.0, -G),
        method: Method::new(Integrator::Rattle, None).expect("RATTLE"),
        ..SimParams::default()
    };
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        WireBeadPlugin::new(params).expect("valid parameters"),
        PhysicsPlugins::default(),
        PathJointPlugin,
    ));
    app.insert_resource(Gravity(Vector::new(0.0, -G as _)));
    app.insert_resource(SubstepCount(substeps));
    app.insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    app.finish();
    app.cleanup();
    app.update();
    app
}

/// A body of mass 1 kg and inertia `inertia` about its centre, at rest
/// `theta0` from the bottom of a unit circle about the origin, held on it
/// at its centre; the body.
fn pendulum(app: &mut App, theta0: f64, inertia: f32, rotation: PathRotation) -> Entity {
    let wire = app
        .world_mut()
        .spawn((Wire::circle(1.0).expect("a circle"), Transform::IDENTITY))
        .id();
    let at = DVec2::new(theta0.sin(), -theta0.cos());
    app.world_mut()
        .spawn((
            RigidBody::Dynamic,
            Position(at.adjust_precision()),
            Mass(1.0),
            AngularInertia(inertia),
            SleepingDisabled,
            PathJoint::new(wire).with_rotation(rotation),
        ))
        .id()
}

/// The body's centre, velocity, angle and spin.
fn body_state(app: &App, body: Entity) -> (DVec2, DVec2, f64, f64) {
    let world = app.world();
    let position = DVec2::from(world.get::<Position>(body).expect("a body").0);
    let velocity = DVec2::from(world.get::<LinearVelocity>(body).expect("a body").0);
    let angle = f64::from(world.get::<Rotation>(body).expect("a body").as_radians());
    let spin = f64::from(world.get::<AngularVelocity>(body).expect("a body").0);
    (position, velocity, angle, spin)
}

/// What a swinging body did over `seconds`: the period from its upward
/// crossings of the bottom, the farthest its centre strayed from the
/// circle, and the most its angle moved against its angle round the circle
/// (from where each began).
struct Swing {
    period: f64,
    off_the_wire: f64,
    turned_against_orbit: f64,
    turned: f64,
    /// The largest change of `½ m v² + ½ I ω² + m g y` from the start, J.
    energy: f64,
}

fn swing(app: &mut App, body: Entity, seconds: f64, inertia: f64) -> Swing {
    let (start, _, angle0, _) = body_state(app, body);
    let energy_of = |(p, v, _, w): (DVec2, DVec2, f64, f64)| {
        0.5 * v.length_squared() + 0.5 * inertia * w * w + G * p.y
    };
    let e0 = energy_of(body_state(app, body));
    let mut energy = 0.0f64;
    let orbit0 = start.x.atan2(-start.y);
    let mut crossings = Vec::new();
    let (mut off, mut against, mut turned) = (0.0f64, 0.0f64, 0.0f64);
    let mut last = start;
    let steps = (seconds / DT).round() as usize;
    for step in 1..=steps {
        app.update();
        let (p, _, angle, _) = body_state(app, body);
        energy = energy.max((energy_of(body_state(app, body)) - e0).abs());
        off = off.max((p.length() - 1.0).abs());
        let orbit = p.x.atan2(-p.y);
        against = against.max(((angle - angle0) - (orbit - orbit0)).abs());
        turned = turned.max((angle - angle0).abs());
        if last.x < 0.0 && p.x >= 0.0 {
            // Linear between the two steps.
            let part = -last.x / (p.x - last.x);
            crossings.push((step as f64 - 1.0 + part) * DT);
        }
        last = p;
    }
    assert!(
        crossings.len() >= 2,
        "the body crossed the bottom {} times",
        crossings.len()
    );
    let periods = crossings.len() - 1;
    Swing {
        period: (crossings[periods] - crossings[0]) / periods as f64,
        off_the_wire: off,
        turned_against_orbit: against,
        turned,
        energy,
    }
}

/// A body held at its centre on a circle, free to turn, swings as a point
/// pendulum: its period is the elliptic integral's, and no torque acts on
/// it about its centre, so it never turns. The substep's first-order error
/// (each correction takes energy from the swing, as avian's own joints do)
/// shrinks with the substep: a quarter of the substep loses about a
/// quarter of the energy (measured: 6 substeps of 1/60 s lose 1.57 J of
/// the 4.9 J over 4.5 periods, 48 lose 0.24 J).
#[test]
fn a_body_held_at_its_centre_swings_as_a_point_pendulum_and_never_turns() {
    let theta0 = 60f64.to_radians();
    let exact = pendulum_period(1.0, G, theta0);
    let run = |substeps: u32| {
        let mut app = physics_app(substeps);
        let body = pendulum(&mut app, theta0, 0.5, PathRotation::Free);
        swing(&mut app, body, 4.5 * exact, 0.5)
    };
    let (coarse, fine) = (run(SUBSTEPS / 4), run(SUBSTEPS));
    let error = (fine.period - exact) / exact;
    eprintln!(
        "free: period error {error:+.2e}, off the wire {:.2e} m, turned {:.2e} rad, energy lost \
         {:.2e} J at {SUBSTEPS} substeps and {:.2e} J at a quarter of them",
        fine.off_the_wire, fine.turned, fine.energy, coarse.energy
    );
    assert!(
        error.abs() <= 3e-3,
        "period {} against {exact}: {error:+e}",
        fine.period
    );
    let order = coarse.energy / fine.energy;
    assert!(
        (3.0..=5.0).contains(&order),
        "a quarter of the substep lost {order} times less energy, not about 4"
    );
    for s in [&coarse, &fine] {
        assert!(
            s.off_the_wire <= 1e-6,
            "the centre strayed {:e} m from the wire",
            s.off_the_wire
        );
        assert!(s.turned <= 1e-6, "the body turned by {:e} rad", s.turned);
    }
}

/// A body turned with the circle spins at the orbit's rate, and its
/// inertia adds to the pendulum's: the period is
/// `4 sqrt((m r² + I) / (m g r)) K(sin²(θ0/2))`.
#[test]
fn a_body_turned_with_its_circle_spins_with_the_orbit_and_swings_slower() {
    let mut app = physics_app(SUBSTEPS);
    let (theta0, inertia) = (60f64.to_radians(), 0.5f64);
    let body = pendulum(&mut app, theta0, inertia as f32, PathRotation::Turned);
    let point = pendulum_period(1.0, G, theta0);
    let exact = point * (1.0 + inertia).sqrt();
    let s = swing(&mut app, body, 4.5 * exact, inertia);
    let error = (s.period - exact) / exact;
    eprintln!(
        "turned: period error {error:+.2e}, off the wire {:.2e} m, turned against the orbit {:.2e} rad, energy {:.2e} J",
        s.off_the_wire, s.turned_against_orbit, s.energy
    );
    assert!(
        error.abs() <= 2e-3,
        "period {} against {exact}: {error:+e}",
        s.period
    );
    assert!(
        s.off_the_wire <= 1e-4,
        "the centre strayed {:e} m from the wire",
        s.off_the_wire
    );
    assert!(
        s.turned_against_orbit <= 1e-3,
        "the body turned against its orbit by {:e} rad",
        s.turned_against_orbit
    );
}

/// The path joint composes as avian's own joints do: a body held at its
/// centre on a unit circle, at avian's default six substeps, swings as a
/// body on avian's `DistanceJoint` of length 1 to a fixed point at the
/// circle's centre does, the two in one world (measured apart by at most
/// 4e-6 m over 3 s, as rounding in `f32` leaves them: both correct the
/// same row by the same rule).
#[test]
fn a_body_on_a_circle_swings_as_one_on_avians_distance_joint() {
    let mut app = physics_app(6);
    let theta0 = 60f64.to_radians();
    let on_path = pendulum(&mut app, theta0, 0.5, PathRotation::Free);
    let at = DVec2::new(theta0.sin(), -theta0.cos());
    let world = app.world_mut();
    let centre = world
        .spawn((RigidBody::Static, Position::from_xy(0.0, 0.0)))
        .id();
    let on_joint = world
        .spawn((
            RigidBody::Dynamic,
            Position(at.adjust_precision()),
            Mass(1.0),
            AngularInertia(0.5),
            SleepingDisabled,
        ))
        .id();
    world.spawn(
        DistanceJoint::new(centre, on_joint)
            .with_limits(1.0, 1.0)
            .with_compliance(0.0),
    );
    let mut apart = 0.0f64;
    for _ in 0..180 {
        app.update();
        let (a, ..) = body_state(&app, on_path);
        let (b, ..) = body_state(&app, on_joint);
        apart = apart.max((a - b).length());
    }
    eprintln!("path joint against avian's distance joint: {apart:.2e} m apart at most");
    assert!(apart <= 1e-5, "the two bodies came {apart:e} m apart");
}

/// A path joint naming an entity that is no wire holds nothing: the body
/// falls freely, as avian alone would let it, with no NaN anywhere.
#[test]
fn a_path_joint_on_no_wire_holds_nothing() {
    let mut app = physics_app(6);
    let not_a_wire = app.world_mut().spawn(Transform::IDENTITY).id();
    let body = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Position::from_xy(0.0, 0.0),
            Mass(1.0),
            AngularInertia(0.5),
            SleepingDisabled,
            PathJoint::new(not_a_wire),
        ))
        .id();
    for _ in 0..60 {
        app.update();
    }
    let (p, v, angle, spin) = body_state(&app, body);
    assert!(p.is_finite() && v.is_finite() && angle.is_finite() && spin.is_finite());
    // Avian's semi-implicit Euler: y = −g t² (1 + 1/n)/2 after n steps of
    // t/n; its substeps make n 360.
    let fallen = -0.5 * G * (1.0 + 1.0 / 360.0);
    assert!(
        (p.y - fallen).abs() <= 1e-4,
        "the body fell to {} m, not {fallen}",
        p.y
    );
}

/// A kinematic body goes where the game sends it, its path joint
/// notwithstanding: sent at 1 m/s from the circle's centre, it is 1 m
/// along after a second.
#[test]
fn a_kinematic_body_is_not_moved_by_its_path_joint() {
    let mut app = physics_app(6);
    let wire = app
        .world_mut()
        .spawn((Wire::circle(1.0).expect("a circle"), Transform::IDENTITY))
        .id();
    let body = app
        .world_mut()
        .spawn((
            RigidBody::Kinematic,
            Position::from_xy(0.0, 0.5),
            LinearVelocity(Vector::new(1.0, 0.0)),
            PathJoint::new(wire),
        ))
        .id();
    for _ in 0..60 {
        app.update();
    }
    let (p, ..) = body_state(&app, body);
    assert!(
        (p - DVec2::new(1.0, 0.5)).length() <= 1e-5,
        "the body is at {p}"
    );
}
