//! Rigid bodies of avian2d held on our wires by path joints: the reference
//! truths of ../shared/PHYSICS.md, "Bodies beside beads".

use avian2d::math::{AdjustPrecision, Vector};
use avian2d::prelude::*;
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use wirebead::avian::{
    PathJoint, PathJointForces, PathJointPlugin, PathMotor, PathRotation, WireOnBody,
};
use wirebead::geometry::{ImplicitCurve, Side, Spline, SplineKind, SplineSpec, Surface, WireShape};
use wirebead::headless::{Headless, run_steps};
use wirebead::prelude::*;
use wirebead::reference::{bead_on_a_free_hoop, pendulum_period};
use wirebead::{DivergenceReason, GrabPoint, Integrator, NextParams, ScenePreset, SpringAnchor};

const G: f64 = 9.81;
const DT: f64 = 1.0 / 60.0;
/// Avian's default.
const SUBSTEPS: u32 = 6;

/// Our plugin and avian's, gravity along −y, 60 Hz with `substeps`
/// substeps, its first update taken (no step).
fn physics_app(substeps: u32) -> App {
    physics_app_at(DT, substeps)
}

/// [`physics_app`] stepping `dt`.
fn physics_app_at(dt: f64, substeps: u32) -> App {
    physics_app_with(dt, substeps, DVec2::new(0.0, -G))
}

/// [`physics_app`] stepping `dt` under `gravity` (ours and avian's).
pub(super) fn physics_app_with(dt: f64, substeps: u32, gravity: DVec2) -> App {
    let params = SimParams {
        timestep: dt,
        gravity,
        method: Method::new(Integrator::Rattle, None).expect("RATTLE"),
        ..SimParams::default()
    };
    let mut app = App::new();
    app.add_plugins((
        // The process's task pools as every other test app asks for them.
        MinimalPlugins.set(TaskPoolPlugin {
            task_pool_options: wirebead::plugin::compute_on_all_cores(),
        }),
        WireBeadPlugin::new(params).expect("valid parameters"),
        PhysicsPlugins::default(),
        PathJointPlugin,
    ));
    app.insert_resource(Gravity(gravity.adjust_precision()));
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
    let joint = PathJoint::new(Entity::PLACEHOLDER).with_rotation(rotation);
    pendulum_held_by(app, theta0, inertia, joint)
}

/// [`pendulum`]'s body held on its circle by `joint` (whose wire is set to
/// the circle).
fn pendulum_held_by(app: &mut App, theta0: f64, inertia: f32, joint: PathJoint) -> Entity {
    let wire = app
        .world_mut()
        .spawn((Wire::circle(1.0).expect("a circle"), Transform::IDENTITY))
        .id();
    let at = DVec2::new(theta0.sin(), -theta0.cos());
    held_body(app, at, 1.0, inertia, PathJoint { wire, ..joint })
}

/// A dynamic body of `mass` and `inertia` at `at`, never asleep, held by
/// `joint`.
fn held_body(app: &mut App, at: DVec2, mass: f32, inertia: f32, joint: PathJoint) -> Entity {
    app.world_mut()
        .spawn((
            RigidBody::Dynamic,
            Position(at.adjust_precision()),
            Mass(mass),
            AngularInertia(inertia),
            SleepingDisabled,
            joint,
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
    /// The fastest its centre moved across the circle, m/s.
    across: f64,
    /// The largest change of `½ m v² + ½ I ω² + m g y` from the start, J.
    energy: f64,
}

fn swing(app: &mut App, body: Entity, seconds: f64, inertia: f64) -> Swing {
    let dt = app.world().resource::<SimParams>().timestep;
    let (start, _, angle0, _) = body_state(app, body);
    let energy_of = |(p, v, _, w): (DVec2, DVec2, f64, f64)| {
        0.5 * v.length_squared() + 0.5 * inertia * w * w + G * p.y
    };
    let e0 = energy_of(body_state(app, body));
    let mut energy = 0.0f64;
    let orbit0 = start.x.atan2(-start.y);
    let mut crossings = Vec::new();
    let (mut off, mut against, mut turned, mut across) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut last = start;
    let steps = (seconds / dt).round() as usize;
    for step in 1..=steps {
        app.update();
        let (p, v, angle, _) = body_state(app, body);
        across = across.max(p.normalize().dot(v).abs());
        energy = energy.max((energy_of(body_state(app, body)) - e0).abs());
        off = off.max((p.length() - 1.0).abs());
        let orbit = p.x.atan2(-p.y);
        against = against.max(((angle - angle0) - (orbit - orbit0)).abs());
        turned = turned.max((angle - angle0).abs());
        if last.x < 0.0 && p.x >= 0.0 {
            // Linear between the two steps.
            let part = -last.x / (p.x - last.x);
            crossings.push((step as f64 - 1.0 + part) * dt);
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
        across,
        energy,
    }
}

/// How a pendulum on a path joint swung at 60 Hz and at 1 ms, avian's
/// default substeps in both.
struct Swings {
    coarse: Swing,
    fine: Swing,
    exact: f64,
}

fn swings(theta0: f64, inertia: f64, rotation: PathRotation) -> Swings {
    let point = pendulum_period(1.0, G, theta0);
    let exact = match rotation {
        PathRotation::Free => point,
        // The body's own inertia adds to the pendulum's: m r² + I.
        PathRotation::Turned => point * (1.0 + inertia).sqrt(),
    };
    let run = |dt: f64, periods: f64| {
        let mut app = physics_app_at(dt, SUBSTEPS);
        let body = pendulum(&mut app, theta0, inertia as f32, rotation);
        swing(&mut app, body, periods * exact, inertia)
    };
    Swings {
        coarse: run(DT, 4.5),
        fine: run(1e-3, 2.5),
        exact,
    }
}

impl Swings {
    fn errors(&self) -> (f64, f64) {
        (
            (self.coarse.period - self.exact) / self.exact,
            (self.fine.period - self.exact) / self.exact,
        )
    }
}

/// A body held at its centre on a circle, free to turn, swings as a point
/// pendulum: its period is the elliptic integral's, to 1e-3 at 60 Hz and
/// to 1e-5 at 1 ms with avian's six substeps (the joint is RATTLE on
/// avian's symplectic substep, so the period's error is second order in
/// the substep); its centre stays on the circle to 1e-5 m and moves along
/// it (across it at 1e-5 m/s at most: RATTLE's velocity step), and no torque
/// acts on it about its centre, so it never turns (1e-5 rad).
#[test]
fn a_body_held_at_its_centre_swings_as_a_point_pendulum_and_never_turns() {
    let s = swings(60f64.to_radians(), 0.5, PathRotation::Free);
    let (coarse, fine) = s.errors();
    eprintln!(
        "free: period error {coarse:+.2e} at 60 Hz, {fine:+.2e} at 1 ms; off the wire {:.2e} m, \
         across it at {:.2e} m/s, turned {:.2e} rad, energy {:.2e} J at 60 Hz",
        s.coarse.off_the_wire, s.coarse.across, s.coarse.turned, s.coarse.energy
    );
    assert!(coarse.abs() <= 1e-3, "period at 60 Hz off by {coarse:+e}");
    assert!(fine.abs() <= 1e-5, "period at 1 ms off by {fine:+e}");
    for swing in [&s.coarse, &s.fine] {
        assert!(
            swing.off_the_wire <= 1e-5,
            "the centre strayed {:e} m from the wire",
            swing.off_the_wire
        );
        assert!(
            swing.turned <= 1e-5,
            "the body turned by {:e} rad",
            swing.turned
        );
    }
}

/// A body turned with the circle spins at the orbit's rate, and its
/// inertia adds to the pendulum's: the period is
/// `4 sqrt((m r² + I) / (m g r)) K(sin²(θ0/2))`, to 1e-3 at 60 Hz and
/// 1e-5 at 1 ms, the centre on the circle to 1e-5 m and the body turned
/// with its orbit to 1e-5 rad.
#[test]
fn a_body_turned_with_its_circle_spins_with_the_orbit_and_swings_slower() {
    let s = swings(60f64.to_radians(), 0.5, PathRotation::Turned);
    let (coarse, fine) = s.errors();
    eprintln!(
        "turned: period error {coarse:+.2e} at 60 Hz, {fine:+.2e} at 1 ms; off the wire {:.2e} m, \
         turned against the orbit {:.2e} rad, energy {:.2e} J at 60 Hz",
        s.coarse.off_the_wire, s.coarse.turned_against_orbit, s.coarse.energy
    );
    assert!(coarse.abs() <= 1e-3, "period at 60 Hz off by {coarse:+e}");
    assert!(fine.abs() <= 1e-5, "period at 1 ms off by {fine:+e}");
    for swing in [&s.coarse, &s.fine] {
        assert!(
            swing.off_the_wire <= 1e-5,
            "the centre strayed {:e} m from the wire",
            swing.off_the_wire
        );
        assert!(
            swing.turned_against_orbit <= 1e-5,
            "the body turned against its orbit by {:e} rad",
            swing.turned_against_orbit
        );
    }
}

/// The path joint keeps a swing's energy where avian's own joints, first
/// order in the substep, take it: a body held at its centre on a unit
/// circle and one on avian's `DistanceJoint` of length 1 to the circle's
/// centre, in one world at six substeps, released together 60° from the
/// bottom. Over 3 s the path joint's energy stays within 1 % of its
/// start, and the distance joint's falls by more than ten times as much.
#[test]
fn a_path_joint_keeps_the_energy_avians_distance_joint_takes() {
    let mut app = physics_app(SUBSTEPS);
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
    let energy = |app: &App, body: Entity| {
        let (p, v, ..) = body_state(app, body);
        0.5 * v.length_squared() + G * p.y
    };
    let start = energy(&app, on_path);
    let (mut path_change, mut joint_change) = (0.0f64, 0.0f64);
    for _ in 0..180 {
        app.update();
        path_change = path_change.max((energy(&app, on_path) - start).abs());
        joint_change = joint_change.max((energy(&app, on_joint) - start).abs());
    }
    let drop = -start;
    eprintln!(
        "over 3 s: the path joint's energy moved {path_change:.2e} J, the distance joint's \
         {joint_change:.2e} J, of a swing of {drop:.2} J"
    );
    assert!(
        path_change <= 0.01 * drop,
        "the path joint's energy moved {path_change:e} J"
    );
    assert!(
        joint_change >= 10.0 * path_change,
        "the distance joint's energy moved {joint_change:e} J, the path joint's {path_change:e} J"
    );
}

/// A body of mass `mass` on a line along x through the origin (gravity
/// across it), held at its centre by `joint`.
fn on_a_line(app: &mut App, mass: f32, angle: f32, joint: impl Fn(Entity) -> PathJoint) -> Entity {
    let wire = app
        .world_mut()
        .spawn((
            Wire::line(),
            Transform::from_rotation(Quat::from_rotation_z(angle)),
        ))
        .id();
    app.world_mut()
        .spawn((
            RigidBody::Dynamic,
            Position::from_xy(0.0, 0.0),
            Mass(mass),
            AngularInertia(0.1),
            SleepingDisabled,
            joint(wire),
        ))
        .id()
}

/// A velocity motor of at most 4 N on a body of 2 kg at rest on a line
/// accelerates it at F/m = 2 m/s² (its speed after 1 s is 2 m/s to 1 %),
/// up to the 3 m/s it asks for, and holds that (to 1e-3 m/s) for a
/// second after; the body stays on the line (1e-5 m). The joint's forces
/// say so: 4 N from the motor while it accelerates, none once at speed,
/// and the body's weight from the wire throughout (to 1e-3).
#[test]
fn a_velocity_motor_accelerates_at_its_force_over_the_mass_and_holds_its_speed() {
    let mut app = physics_app(SUBSTEPS);
    let body = on_a_line(&mut app, 2.0, 0.0, |wire| {
        PathJoint::new(wire).with_motor(PathMotor::Velocity {
            speed: 3.0,
            max_force: 4.0,
        })
    });
    let mut off = 0.0f64;
    let mut speed_at = Vec::new();
    let mut forces = Vec::new();
    for _ in 0..150 {
        app.update();
        let (p, v, ..) = body_state(&app, body);
        off = off.max(p.y.abs());
        speed_at.push(v);
        forces.push(*app.world().get::<PathJointForces>(body).expect("forces"));
    }
    // Accelerating, the motor gives its 4 N and the wire holds the weight;
    // at speed, the motor gives nothing.
    let pushing = forces[30];
    let weight = 2.0 * G;
    assert!(
        (pushing.motor_force - 4.0).abs() <= 1e-3
            && (pushing.force - DVec2::new(4.0, weight)).length() <= 1e-3 * weight,
        "accelerating, the joint gave {pushing:?}"
    );
    let cruising = forces[140];
    assert!(
        cruising.motor_force.abs() <= 1e-3
            && (cruising.force - DVec2::new(0.0, weight)).length() <= 1e-3 * weight,
        "at speed, the joint gave {cruising:?}"
    );
    let after_one = speed_at[59].x;
    assert!(
        (after_one - 2.0).abs() <= 0.02,
        "after 1 s the body moves at {after_one} m/s, not 2"
    );
    let held = speed_at[90..]
        .iter()
        .map(|v| (v.x - 3.0).abs().max(v.y.abs()))
        .fold(0.0f64, f64::max);
    eprintln!(
        "motor: {after_one} m/s after 1 s; held 3 m/s to {held:.2e}; off the line {off:.2e} m"
    );
    assert!(held <= 1e-3, "the motor held its speed to {held:e} m/s");
    assert!(off <= 1e-5, "the body strayed {off:e} m from the line");
}

/// The motor's direction is the wire's own: on a circle, counter-clockwise.
/// A body at the bottom of a unit hoop driven at 1 m/s with room to spare
/// (100 N against its weight of 9.81) goes round counter-clockwise at
/// that speed, to 1e-3 m/s, the whole way round.
#[test]
fn a_motor_drives_a_hoops_body_counter_clockwise() {
    let mut app = physics_app(SUBSTEPS);
    let wire = app
        .world_mut()
        .spawn((Wire::circle(1.0).expect("a circle"), Transform::IDENTITY))
        .id();
    let body = held_body(
        &mut app,
        DVec2::new(0.0, -1.0),
        1.0,
        0.1,
        PathJoint::new(wire).with_motor(PathMotor::Velocity {
            speed: 1.0,
            max_force: 100.0,
        }),
    );
    let mut worst = 0.0f64;
    // Past the first second, once at speed; round once in 2π s.
    for step in 0..420 {
        app.update();
        let (p, v, ..) = body_state(&app, body);
        if step >= 60 {
            let ccw = p.perp().dot(v) / p.length();
            worst = worst.max((ccw - 1.0).abs());
        }
    }
    eprintln!("motor on a hoop: counter-clockwise at 1 m/s to {worst:.2e}");
    assert!(
        worst <= 1e-3,
        "the body went round at 1 m/s to {worst:e} only"
    );
}

/// Friction holds a body while its weight along the wire is less, and
/// slows it by its force beyond: on a line sloping 30°, a body of 1 kg
/// (9.81 sin 30° = 4.905 N down the slope) held by 6 N of friction moves
/// less than 1e-5 m in 2 s; held by 2 N it slides down at
/// (4.905 − 2) m/s² (its speed after 1 s to 1 %).
#[test]
fn friction_holds_a_body_on_a_slope_or_slows_its_slide() {
    let slope = -30f32.to_radians();
    let run = |friction: f64| {
        let mut app = physics_app(SUBSTEPS);
        let body = on_a_line(&mut app, 1.0, slope, |wire| {
            PathJoint::new(wire).with_friction(friction)
        });
        let mut states = Vec::new();
        for _ in 0..120 {
            app.update();
            states.push(body_state(&app, body));
        }
        states
    };
    let held = run(6.0);
    let moved = held.iter().map(|s| s.0.length()).fold(0.0f64, f64::max);
    let sliding = run(2.0);
    let speed = sliding[59].1.length();
    let expected = G * 0.5 - 2.0;
    eprintln!(
        "friction: held within {moved:.2e} m; sliding at {speed} m/s after 1 s, {expected} expected"
    );
    assert!(moved <= 1e-5, "the held body moved {moved:e} m");
    assert!(
        (speed - expected).abs() <= 0.01 * expected,
        "the sliding body moves at {speed} m/s after 1 s"
    );
}

/// The ends of an open wire stop the body: on a straight open spline from
/// (0, 0) down to (2, −1), a body released at the top slides down, stops
/// at the lower end and stays there (its anchor within 1e-5 m of the end,
/// and at rest to 1e-3 m/s, for the second after it arrives).
#[test]
fn the_end_of_an_open_wire_stops_the_body() {
    let mut app = physics_app(SUBSTEPS);
    let spline = Spline::new(SplineSpec {
        kind: SplineKind::CatmullRom,
        points: vec![DVec2::ZERO, DVec2::new(1.0, -0.5), DVec2::new(2.0, -1.0)],
        closed: false,
    })
    .expect("a spline");
    let wire = app
        .world_mut()
        .spawn((
            Wire::new(WireShape::Spline(spline)).expect("a wire"),
            Transform::IDENTITY,
        ))
        .id();
    let body = held_body(
        &mut app,
        DVec2::new(0.0, 0.0),
        1.0,
        0.1,
        PathJoint::new(wire),
    );
    let end = DVec2::new(2.0, -1.0);
    // Sliding 2.24 m at g sin(26.6°) = 4.39 m/s² takes about a second.
    for _ in 0..90 {
        app.update();
    }
    let (mut off, mut moving) = (0.0f64, 0.0f64);
    for _ in 0..60 {
        app.update();
        let (p, v, ..) = body_state(&app, body);
        off = off.max((p - end).length());
        moving = moving.max(v.length());
    }
    eprintln!("end: held {off:.2e} m from the end, moving at most {moving:.2e} m/s");
    assert!(off <= 1e-5, "the body is {off:e} m from the end");
    assert!(
        moving <= 1e-3,
        "the body moves at {moving:e} m/s at the end"
    );
}

/// A position motor draws the body to its target on the wire: critically
/// damped at 2 Hz, a body of 1 kg on a level line is within 1e-3 m of a
/// target 1 m along after 2 s, and at rest there to 1e-3 m/s.
#[test]
fn a_position_motor_draws_the_body_to_its_target() {
    let mut app = physics_app(SUBSTEPS);
    let body = on_a_line(&mut app, 1.0, 0.0, |wire| {
        PathJoint::new(wire).with_motor(PathMotor::Position {
            target: DVec2::new(1.0, 0.0),
            frequency: 2.0,
            damping_ratio: 1.0,
            max_force: 100.0,
        })
    });
    for _ in 0..120 {
        app.update();
    }
    let (p, v, ..) = body_state(&app, body);
    eprintln!("position motor: at {p} moving {v} after 2 s");
    assert!((p - DVec2::X).length() <= 1e-3, "the body is at {p}");
    assert!(v.length() <= 1e-3, "the body moves at {v}");
}

/// A path joint naming an entity that is no wire holds nothing: the body
/// falls freely, as avian alone would let it, with no NaN anywhere.
#[test]
fn a_path_joint_on_no_wire_holds_nothing() {
    let mut app = physics_app(SUBSTEPS);
    let not_a_wire = app.world_mut().spawn(Transform::IDENTITY).id();
    let body = held_body(
        &mut app,
        DVec2::new(0.0, 0.0),
        1.0,
        0.5,
        PathJoint::new(not_a_wire),
    );
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

/// Numbers a joint cannot use are read as documented, never as NaN: a
/// compliance that is negative or NaN is rigid, a motor whose speed,
/// frequency or force limit is NaN drives nothing, and a negative force
/// limit gives no force. Each such body swings as the plain pendulum
/// beside it, to 1e-9 m after 2 s, on its hoop to 1e-5 m.
#[test]
fn a_joint_given_bad_numbers_holds_its_body_as_a_plain_joint() {
    let mut app = physics_app(SUBSTEPS);
    let theta0 = std::f64::consts::FRAC_PI_3;
    let plain = pendulum(&mut app, theta0, 0.5, PathRotation::Free);
    let velocity = |speed, max_force| PathMotor::Velocity { speed, max_force };
    let spring = |frequency| PathMotor::Position {
        target: DVec2::new(0.0, -1.0),
        frequency,
        damping_ratio: 1.0,
        max_force: 10.0,
    };
    let joint = PathJoint::new(Entity::PLACEHOLDER);
    let bad = [
        (
            "a negative compliance",
            PathJoint {
                compliance: -1.0,
                ..joint.clone()
            },
        ),
        (
            "a NaN compliance",
            PathJoint {
                compliance: f64::NAN,
                ..joint.clone()
            },
        ),
        (
            "a NaN motor speed",
            joint.clone().with_motor(velocity(f64::NAN, 10.0)),
        ),
        (
            "a NaN force limit",
            joint.clone().with_motor(velocity(1.0, f64::NAN)),
        ),
        (
            "a negative force limit",
            joint.clone().with_motor(velocity(1.0, -5.0)),
        ),
        ("a NaN spring", joint.clone().with_motor(spring(f64::NAN))),
        ("a NaN friction", joint.with_friction(f64::NAN)),
    ];
    let bodies: Vec<(&str, Entity)> = bad
        .into_iter()
        .map(|(what, joint)| (what, pendulum_held_by(&mut app, theta0, 0.5, joint)))
        .collect();
    let mut off = vec![0.0f64; bodies.len()];
    for _ in 0..120 {
        app.update();
        for ((_, body), off) in bodies.iter().zip(&mut off) {
            let (p, ..) = body_state(&app, *body);
            *off = off.max((p.length() - 1.0).abs());
        }
    }
    let (expected, ..) = body_state(&app, plain);
    for ((what, body), off) in bodies.iter().zip(&off) {
        let (p, v, angle, spin) = body_state(&app, *body);
        assert!(
            p.is_finite() && v.is_finite() && angle.is_finite() && spin.is_finite(),
            "{what}: a number is not finite"
        );
        assert!(*off <= 1e-5, "{what}: {off} m off the hoop");
        let apart = (p - expected).length();
        assert!(apart <= 1e-9, "{what}: {apart} m from the plain pendulum");
    }
}

/// A kinematic body goes where the game sends it, its path joint
/// notwithstanding: sent at 1 m/s from the circle's centre, it is 1 m
/// along after a second.
#[test]
fn a_kinematic_body_is_not_moved_by_its_path_joint() {
    let mut app = physics_app(SUBSTEPS);
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

/// At a crossing a body keeps its branch: on a closed figure eight
/// (a Catmull-Rom spline through 24 points of `(2 sin t, sin 2t)`, its
/// two lobes crossing at the origin), a body driven round at 4 m/s
/// alternates between the lobes for ten laps, never going round one
/// twice, and stays on the spline to 1e-5 m.
#[test]
fn a_body_keeps_its_branch_where_a_figure_eight_crosses_itself() {
    let mut app = physics_app(SUBSTEPS);
    let n = 24;
    let points = (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            DVec2::new(2.0 * t.sin(), (2.0 * t).sin())
        })
        .collect();
    let spline = Spline::new(SplineSpec {
        kind: SplineKind::CatmullRom,
        points,
        closed: true,
    })
    .expect("a figure eight");
    let wire = app
        .world_mut()
        .spawn((
            Wire::new(WireShape::Spline(spline.clone())).expect("a wire"),
            Transform::IDENTITY,
        ))
        .id();
    let body = held_body(
        &mut app,
        DVec2::new(0.0, 0.0),
        1.0,
        0.1,
        PathJoint::new(wire).with_motor(PathMotor::Velocity {
            speed: 4.0,
            max_force: 200.0,
        }),
    );
    // The lobe of each visit to a lobe's far part (|x| > 1.5).
    let mut lobes: Vec<bool> = Vec::new();
    let (mut inside, mut off, mut steps) = (false, 0.0f64, 0);
    while lobes.len() < 21 && steps < 60 * 60 {
        app.update();
        steps += 1;
        let (p, ..) = body_state(&app, body);
        off = off.max(spline.value(p).abs());
        if p.x.abs() > 1.5 && !inside {
            lobes.push(p.x > 0.0);
            inside = true;
        } else if p.x.abs() < 1.0 {
            inside = false;
        }
    }
    let repeats = lobes.windows(2).filter(|w| w[0] == w[1]).count();
    assert_eq!(
        repeats, 0,
        "the body went round one lobe twice in a row: {lobes:?}"
    );
    eprintln!(
        "figure eight: {} lobe visits in {steps} steps; off the wire by {off:.2e} m",
        lobes.len()
    );
    assert!(
        lobes.len() >= 21,
        "only {} lobe visits in a minute",
        lobes.len()
    );
    assert!(off <= 1e-5, "the body strayed {off:e} m from the spline");
}

/// What a body does at a sharp corner of a wire (docs/method.md, "Rigid
/// bodies on wires"): on two straight segments meeting at 45°, a body
/// coasting at 2 m/s (no gravity) turns the corner and goes on along the
/// second segment at the speed's part along it, `2 cos 45°` (to 1e-3; the
/// rest taken by the corner, as by an inelastic kink), never more than
/// 1e-5 m off the wire.
#[test]
fn a_body_turns_a_sharp_corner_keeping_its_speed_along_the_new_segment() {
    let mut app = physics_app(SUBSTEPS);
    app.insert_resource(Gravity(Vector::ZERO));
    let bend = DVec2::new(1.0, 1.0) * std::f64::consts::FRAC_1_SQRT_2;
    let spline = Spline::new(SplineSpec {
        kind: SplineKind::Segments(vec![
            [
                DVec2::new(-2.0, 0.0),
                DVec2::new(2.0, 0.0),
                DVec2::ZERO,
                DVec2::ZERO,
            ],
            [DVec2::ZERO, 2.0 * bend, DVec2::ZERO, DVec2::ZERO],
        ]),
        points: Vec::new(),
        closed: false,
    })
    .expect("two segments");
    let wire = app
        .world_mut()
        .spawn((
            Wire::new(WireShape::Spline(spline.clone())).expect("a wire"),
            Transform::IDENTITY,
        ))
        .id();
    let body = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Position::from_xy(-1.5, 0.0),
            LinearVelocity(Vector::new(2.0, 0.0)),
            Mass(1.0),
            AngularInertia(0.1),
            SleepingDisabled,
            PathJoint::new(wire),
        ))
        .id();
    let mut off = 0.0f64;
    for _ in 0..60 {
        app.update();
        let (p, ..) = body_state(&app, body);
        off = off.max(spline.value(p).abs());
    }
    let (p, v, ..) = body_state(&app, body);
    eprintln!("corner: off by {off:.2e} m; ends at {p} moving {v}");
    let expected = 2.0 * bend.x * bend;
    assert!(
        (v - expected * 1.0).length() <= 1e-3,
        "after the corner the body moves at {v}"
    );
    assert!(
        p.x > 0.1 && (p.x - p.y).abs() <= 1e-5,
        "the body is at {p}, not on the second segment"
    );
    assert!(off <= 1e-5, "the body strayed {off:e} m from the wire");
}

/// No gravity, ours (now and after a restart) or avian's.
fn without_gravity(app: &mut App) {
    app.insert_resource(Gravity(Vector::ZERO));
    let world = app.world_mut();
    world.resource_mut::<SimParams>().gravity = DVec2::ZERO;
    world
        .resource_mut::<NextParams>()
        .update(|params| params.gravity = DVec2::ZERO)
        .expect("valid parameters");
}

/// A free carrier of 3 kg and inertia 0.5 at the origin, a unit hoop on it
/// with its centre `hoop_at` in its frame; no gravity, ours or avian's.
/// The carrier and the hoop.
fn free_hoop(app: &mut App, hoop_at: DVec2) -> (Entity, Entity) {
    without_gravity(app);
    let carrier = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Position(Vector::ZERO),
            Mass(3.0),
            AngularInertia(0.5),
            SleepingDisabled,
        ))
        .id();
    let hoop = app
        .world_mut()
        .spawn((
            Wire::circle(1.0).expect("a circle"),
            Transform::from_translation(hoop_at.as_vec2().extend(0.0)),
            WireOnBody(carrier),
        ))
        .id();
    (carrier, hoop)
}

/// [`free_hoop`], and a body of 1 kg held on the hoop by `joint` at the
/// hoop's point along +x, moving at `velocity`. The carrier, the hoop and
/// the body.
fn hoop_on_a_free_body(
    app: &mut App,
    hoop_at: DVec2,
    velocity: DVec2,
    joint: PathJoint,
) -> (Entity, Entity, Entity) {
    let (carrier, hoop) = free_hoop(app, hoop_at);
    let body = held_body(
        app,
        hoop_at + DVec2::X,
        1.0,
        0.01,
        PathJoint {
            wire: hoop,
            ..joint
        },
    );
    app.world_mut()
        .entity_mut(body)
        .insert(LinearVelocity(velocity.adjust_precision()));
    (carrier, hoop, body)
}

/// The momentum and the angular momentum about the centre of mass of the
/// 1 kg body (inertia 0.01) and its 3 kg carrier (inertia 0.5).
fn pair_momenta(app: &App, body: Entity, carrier: Entity) -> (DVec2, f64) {
    let (a, va, _, wa) = body_state(app, body);
    let (b, vb, _, wb) = body_state(app, carrier);
    let centre = (a + 3.0 * b) / 4.0;
    let momentum = va + 3.0 * vb;
    let angular =
        (a - centre).perp_dot(va) + 0.01 * wa + 3.0 * (b - centre).perp_dot(vb) + 0.5 * wb;
    (momentum, angular)
}

/// A body held on a hoop fixed to a free body, no gravity, at 60 Hz with
/// avian's substeps: the hoop's push and its reaction turn the pair about
/// its centre of mass as the two-body answer says, to 1e-4 m over 5 s; the
/// pair's momentum is kept to 1e-5 of itself (`f32` rounding of the
/// velocities avian keeps is the floor), and the carrier, pushed only
/// through its centre, never spins (1e-5 rad/s).
#[test]
fn a_body_on_a_hoop_fixed_to_a_free_body_turns_the_pair_as_two_bodies_do() {
    let mut app = physics_app(SUBSTEPS);
    let u = 1.5;
    let (carrier, _, body) = hoop_on_a_free_body(
        &mut app,
        DVec2::ZERO,
        DVec2::new(0.0, u),
        PathJoint::new(Entity::PLACEHOLDER),
    );
    let (p0, _) = pair_momenta(&app, body, carrier);
    let (mut off, mut drift, mut spin) = (0.0f64, 0.0f64, 0.0f64);
    for k in 1..=300 {
        app.update();
        let (bead, _, _, _) = body_state(&app, body);
        let (centre, _, _, w) = body_state(&app, carrier);
        let (bead_at, centre_at) = bead_on_a_free_hoop(
            (1.0, 3.0),
            (DVec3::X, DVec3::new(0.0, u, 0.0)),
            (DVec3::ZERO, DVec3::ZERO),
            k as f64 * DT,
        );
        off = off
            .max((bead.extend(0.0) - bead_at).length())
            .max((centre.extend(0.0) - centre_at).length());
        let (p, _) = pair_momenta(&app, body, carrier);
        drift = drift.max((p - p0).length() / p0.length());
        spin = spin.max(w.abs());
    }
    println!("off the two-body answer {off:.2e} m, momentum {drift:.2e}, spin {spin:.2e} rad/s");
    assert!(off <= 1e-4, "{off:e} m off the two-body answer");
    assert!(drift <= 1e-5, "the momentum changed by {drift:e} of itself");
    assert!(spin <= 1e-5, "the carrier spins at {spin:e} rad/s");
}

/// A hoop fixed off its carrier's centre of mass: the hoop's push now
/// turns the carrier, and the pair keeps its momentum and its angular
/// momentum about its centre of mass over 5 s at 60 Hz (to 1e-5 and 1e-4
/// of their sizes, `f32` state), with the body on the hoop as the carrier
/// has it to 1e-5 m.
#[test]
fn a_hoop_off_its_carriers_centre_turns_the_carrier_and_keeps_the_pairs_momenta() {
    let mut app = physics_app(SUBSTEPS);
    let hoop_at = DVec2::new(0.4, 0.0);
    let (carrier, _, body) = hoop_on_a_free_body(
        &mut app,
        hoop_at,
        DVec2::new(0.0, 1.5),
        PathJoint::new(Entity::PLACEHOLDER),
    );
    let (p0, l0) = pair_momenta(&app, body, carrier);
    let (mut drift, mut turning, mut off, mut spin) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..300 {
        app.update();
        let (p, l) = pair_momenta(&app, body, carrier);
        drift = drift.max((p - p0).length() / p0.length());
        turning = turning.max((l - l0).abs() / l0.abs());
        let (a, _, _, _) = body_state(&app, body);
        let (b, _, angle, w) = body_state(&app, carrier);
        let centre = b + DVec2::from_angle(angle).rotate(hoop_at);
        off = off.max(((a - centre).length() - 1.0).abs());
        spin = spin.max(w.abs());
    }
    println!(
        "momentum {drift:.2e}, angular momentum {turning:.2e}, off {off:.2e} m, spin up to {spin:.3} rad/s"
    );
    assert!(
        spin > 0.05,
        "the carrier should turn, spins at most {spin} rad/s"
    );
    assert!(drift <= 1e-5, "the momentum changed by {drift:e} of itself");
    assert!(
        turning <= 1e-4,
        "the angular momentum changed by {turning:e} of itself"
    );
    assert!(off <= 1e-5, "the body is {off:e} m off the hoop");
}

/// A velocity motor on a hoop fixed to a free body drives the body round
/// the hoop against the carrier, which it pushes back and turns: the
/// body's speed along the hoop relative to the carrier comes to the
/// motor's 2 m/s and holds it (1e-3), and the pair's momentum and angular
/// momentum about its centre of mass stay zero (1e-5 kg·m/s, and 1e-4
/// kg·m²/s, 5e-5 of the body's own 2 kg·m²/s about the hoop's centre).
#[test]
fn a_motor_on_a_carried_hoop_drives_the_body_against_its_carrier() {
    let mut app = physics_app(SUBSTEPS);
    let joint = PathJoint::new(Entity::PLACEHOLDER).with_motor(PathMotor::Velocity {
        speed: 2.0,
        max_force: 4.0,
    });
    let (carrier, _, body) = hoop_on_a_free_body(&mut app, DVec2::ZERO, DVec2::ZERO, joint);
    let (mut worst_p, mut worst_l, mut relative) = (0.0f64, 0.0f64, 0.0);
    for step in 0..180 {
        app.update();
        let (p, l) = pair_momenta(&app, body, carrier);
        worst_p = worst_p.max(p.length());
        worst_l = worst_l.max(l.abs());
        let (a, va, _, _) = body_state(&app, body);
        let (b, vb, _, wb) = body_state(&app, carrier);
        let r = a - b;
        let tangent = DVec2::new(-r.y, r.x).normalize();
        relative = (va - vb - wb * DVec2::new(-r.y, r.x)).dot(tangent);
        if step >= 120 {
            assert!(
                (relative - 2.0).abs() <= 1e-3,
                "at step {step}, {relative} m/s along the hoop"
            );
        }
    }
    println!(
        "relative speed {relative:.6} m/s, momentum {worst_p:.2e}, angular momentum {worst_l:.2e}"
    );
    assert!(worst_p <= 1e-5, "the pair's momentum reached {worst_p:e}");
    assert!(
        worst_l <= 1e-4,
        "the pair's angular momentum reached {worst_l:e}"
    );
}

/// A bead of ours (1 kg) on a hoop fixed to a free body (3 kg), no
/// gravity, at 60 Hz with avian's substeps: it rides the hoop as a point
/// body on a path joint, and the pair turns as the two-body answer says,
/// to 1e-4 m over 5 s, as the bead's own columns report it; the pair's
/// momentum is kept to 1e-5 of itself and the carrier never spins (1e-5
/// rad/s). Its diagnostics say it stays on the hoop (1e-5 m).
#[test]
fn a_bead_on_a_hoop_fixed_to_a_free_body_turns_the_pair_as_two_bodies_do() {
    let mut app = physics_app(SUBSTEPS);
    let (carrier, hoop) = free_hoop(&mut app, DVec2::ZERO);
    let u = 1.5;
    let params = BeadParams {
        mass: 1.0,
        initial_position: DVec2::X,
        initial_velocity: DVec2::new(0.0, u),
    };
    let bead = app
        .world_mut()
        .spawn((Bead::new(params).expect("a bead"), OnWire(hoop)))
        .id();
    let state = |app: &App| {
        let world = app.world();
        let x = world.get::<BeadPosition>(bead).expect("a bead").0;
        let v = world.get::<BeadVelocity>(bead).expect("a bead").0;
        let c = world.get::<BeadDiagnostics>(bead).expect("diagnostics").c;
        let (centre, w, _, spin) = body_state(app, carrier);
        (x, v, c, centre, w, spin)
    };
    let p0 = DVec2::new(0.0, u);
    let (mut off, mut drift, mut spun, mut drifted) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for k in 1..=300 {
        app.update();
        assert!(app.world().get::<Diverged>(bead).is_none());
        let (x, v, c, centre, w, spin) = state(&app);
        let (bead_at, centre_at) = bead_on_a_free_hoop(
            (1.0, 3.0),
            (DVec3::X, p0.extend(0.0)),
            (DVec3::ZERO, DVec3::ZERO),
            k as f64 * DT,
        );
        off = off
            .max((x.extend(0.0) - bead_at).length())
            .max((centre.extend(0.0) - centre_at).length());
        drift = drift.max((v + 3.0 * w - p0).length() / p0.length());
        spun = spun.max(spin.abs());
        drifted = drifted.max(c.abs());
    }
    println!(
        "off the two-body answer {off:.2e} m, momentum {drift:.2e}, spin {spun:.2e} rad/s, C up to {drifted:.2e}"
    );
    assert!(off <= 1e-4, "{off:e} m off the two-body answer");
    assert!(drift <= 1e-5, "the momentum changed by {drift:e} of itself");
    assert!(spun <= 1e-5, "the carrier spins at {spun:e} rad/s");
    assert!(drifted <= 1e-5, "the bead's C reached {drifted:e}");
}

/// A static body turned 30° at (2, 1) carrying a hoop of radius 1.5 at
/// (0.5, 0) in its frame: a bead on it released level with the hoop's
/// centre swings under the plugin's gravity (avian's is set otherwise)
/// with the exact pendulum's period, to 1e-3 at 60 Hz, about the hoop's
/// centre in the world.
#[test]
fn a_bead_on_a_hoop_on_a_static_body_swings_with_the_pendulums_period() {
    let mut app = physics_app(SUBSTEPS);
    app.insert_resource(Gravity(Vector::new(3.0, 0.0)));
    let angle = 30f64.to_radians();
    let carrier = app
        .world_mut()
        .spawn((
            RigidBody::Static,
            Position(DVec2::new(2.0, 1.0).adjust_precision()),
            Rotation::radians(angle as _),
        ))
        .id();
    let hoop = app
        .world_mut()
        .spawn((
            Wire::circle(1.5).expect("a circle"),
            Transform::from_xyz(0.5, 0.0, 0.0),
            WireOnBody(carrier),
        ))
        .id();
    let centre = DVec2::new(2.0, 1.0) + DVec2::from_angle(angle).rotate(DVec2::new(0.5, 0.0));
    let start = centre + DVec2::new(1.5, 0.0);
    let bead = app
        .world_mut()
        .spawn((Bead::at_rest(1.0, start).expect("a bead"), OnWire(hoop)))
        .id();
    let mut crossings = Vec::new();
    let (mut off, mut last) = (0.0f64, start);
    for k in 1..=400 {
        app.update();
        let x = app.world().get::<BeadPosition>(bead).expect("a bead").0;
        off = off.max(((x - centre).length() - 1.5).abs());
        // Upward crossings of the bottom, between steps by the line.
        if last.x < centre.x && x.x >= centre.x {
            let s = (centre.x - last.x) / (x.x - last.x);
            crossings.push((k as f64 - 1.0 + s) * DT);
        }
        last = x;
    }
    let period = crossings[crossings.len() - 1] - crossings[crossings.len() - 2];
    let exact = pendulum_period(1.5, G, std::f64::consts::FRAC_PI_2);
    println!("period {period:.6} s against {exact:.6} s, off the hoop {off:.2e} m");
    assert!(
        ((period - exact) / exact).abs() <= 1e-3,
        "period {period} s against {exact} s"
    );
    assert!(off <= 1e-5, "the bead strayed {off:e} m off the hoop");
}

/// A force added in `WireBeadSystems::Forces` (a game's own, or the drag
/// spring) moves a bead riding a body as it moves any bead: 2 N on 0.5 kg
/// along a line carried by a static body, no gravity, for 1 s. Its speed
/// is `F t / m` to 1e-5; the distance is avian's semi-implicit Euler's
/// over its `N` substeps, `½ (F/m) t² (1 + 1/N)`, to 1e-5.
#[test]
fn a_force_on_a_riding_bead_accelerates_it_at_the_force_over_its_mass() {
    fn push(mut beads: Query<BeadForces>) {
        for mut bead in &mut beads {
            bead.add_force(DVec2::new(2.0, 0.0));
        }
    }
    let mut app = physics_app(SUBSTEPS);
    without_gravity(&mut app);
    app.add_systems(FixedUpdate, push.in_set(WireBeadSystems::Forces));
    let carrier = app
        .world_mut()
        .spawn((RigidBody::Static, Position(Vector::new(0.0, 1.0))))
        .id();
    let line = app
        .world_mut()
        .spawn((Wire::line(), Transform::IDENTITY, WireOnBody(carrier)))
        .id();
    let bead = app
        .world_mut()
        .spawn((
            Bead::at_rest(0.5, DVec2::new(0.0, 1.0)).expect("a bead"),
            OnWire(line),
        ))
        .id();
    for _ in 0..60 {
        app.update();
    }
    let x = app.world().get::<BeadPosition>(bead).expect("a bead").0;
    let v = app.world().get::<BeadVelocity>(bead).expect("a bead").0;
    let (t, substeps) = (60.0 * DT, 60.0 * f64::from(SUBSTEPS));
    let expected = 0.5 * (2.0 / 0.5) * t * t * (1.0 + 1.0 / substeps);
    println!(
        "covered {:.6} m against {expected:.6} m at {} m/s",
        x.x, v.x
    );
    assert!(
        ((x.x - expected) / expected).abs() <= 1e-5,
        "covered {} m",
        x.x
    );
    assert!((v.x / (4.0 * t) - 1.0).abs() <= 1e-5, "at {} m/s", v.x);
    assert!((x.y - 1.0).abs() <= 1e-5, "left the line to y = {}", x.y);
}

/// A restart takes a riding bead back to its start and its velocity
/// relative to the carrier's point there, and it rides again: on a hoop
/// carried by a body spun at 1 rad/s, the bead set at rest on the hoop
/// starts each run moving with the hoop's point (1 m/s), to 1e-4 (`f32`).
#[test]
fn a_restart_boards_the_bead_again_at_its_start() {
    let mut app = physics_app(SUBSTEPS);
    without_gravity(&mut app);
    let carrier = app
        .world_mut()
        .spawn((
            RigidBody::Kinematic,
            Position(Vector::ZERO),
            AngularVelocity(1.0),
        ))
        .id();
    let hoop = app
        .world_mut()
        .spawn((
            Wire::circle(1.0).expect("a circle"),
            Transform::IDENTITY,
            WireOnBody(carrier),
        ))
        .id();
    let start = DVec2::new(0.0, -1.0);
    let bead = app
        .world_mut()
        .spawn((Bead::at_rest(1.0, start).expect("a bead"), OnWire(hoop)))
        .id();
    for run in 0..2 {
        app.update();
        let v = app.world().get::<BeadVelocity>(bead).expect("a bead").0;
        // One step on: carried round by the hoop at 1 m/s.
        assert!(
            (v.length() - 1.0).abs() <= 1e-4,
            "run {run}: the bead moves at {v} m/s"
        );
        for _ in 0..30 {
            app.update();
        }
        let x = app.world().get::<BeadPosition>(bead).expect("a bead").0;
        assert!(
            (x - start).length() > 0.4,
            "run {run}: the bead stayed at {x}"
        );
        app.world_mut().write_message(Restart);
        app.update();
        let world = app.world();
        let x = world.get::<BeadPosition>(bead).expect("a bead").0;
        assert!(world.get::<Diverged>(bead).is_none());
        assert!(
            (x - start).length() <= 0.02,
            "run {run}: restarted at {x}, one step from {start}"
        );
    }
}

/// A bead that cannot ride a body is stopped before the step and says
/// why, naming its wire and the carrier: one with a radius, one joined
/// to another by a rod, one on a one-sided wire, and one whose wire rides
/// an entity that is no rigid body. Each stays where it was put.
#[test]
fn a_bead_that_cannot_ride_a_body_is_stopped_and_says_why() {
    let mut app = physics_app(SUBSTEPS);
    let (carrier, hoop) = free_hoop(&mut app, DVec2::ZERO);
    let one_sided = app
        .world_mut()
        .spawn((
            Wire::circle(1.0)
                .and_then(|w| {
                    w.with_surface(Surface {
                        side: Side::Positive,
                        ..Surface::PLAIN
                    })
                })
                .expect("a one-sided circle"),
            Transform::IDENTITY,
            WireOnBody(carrier),
        ))
        .id();
    let nobody = app.world_mut().spawn_empty().id();
    let on_nothing = app
        .world_mut()
        .spawn((
            Wire::circle(1.0).expect("a circle"),
            Transform::IDENTITY,
            WireOnBody(nobody),
        ))
        .id();
    let start = DVec2::new(0.6, -0.8);
    let spawn = |app: &mut App, wire: Entity| {
        app.world_mut()
            .spawn((Bead::at_rest(1.0, start).expect("a bead"), OnWire(wire)))
            .id()
    };
    let round = spawn(&mut app, hoop);
    app.world_mut()
        .entity_mut(round)
        .insert(BeadRadius::new(0.05).expect("a radius"));
    let joined = spawn(&mut app, hoop);
    let other = app
        .world_mut()
        .spawn(Bead::at_rest(1.0, DVec2::new(0.0, -2.0)).expect("a bead"))
        .id();
    app.world_mut()
        .spawn(Rod::new(joined, other, 1.2).expect("a rod"));
    let sided = spawn(&mut app, one_sided);
    let stranded = spawn(&mut app, on_nothing);
    for _ in 0..3 {
        app.update();
    }
    for (bead, wire, rides, says) in [
        (round, hoop, carrier, "radius"),
        (joined, hoop, carrier, "joined"),
        (sided, one_sided, carrier, "one-sided"),
        (stranded, on_nothing, nobody, "no rigid body"),
    ] {
        let world = app.world();
        let diverged = world.get::<Diverged>(bead).expect("the bead is stopped");
        let said = diverged.reason.to_string();
        assert!(
            matches!(diverged.reason, DivergenceReason::InvalidWire(_))
                && said.contains(&format!("wire {wire} rides body {rides}"))
                && said.contains(says),
            "{said}"
        );
        let at = world.get::<BeadPosition>(bead).expect("a bead").0;
        assert_eq!(at, start, "the stopped bead moved to {at}");
    }
}

/// The scene format's own scene: a box of 2 kg on a unit hoop by a path
/// joint at its centre, released level with the hoop's centre, at 1 ms.
const CART_SCENE: &str = include_str!("../scenes/cart_on_hoop.scene.ron");

/// A headless app running `scene` with its bodies in avian2d, and its
/// bodies.
fn scene_app(scene: &ScenePreset) -> (App, Vec<Entity>) {
    let plugin = WireBeadPlugin::new(scene.params.clone()).expect("valid parameters");
    let mut app = Headless::new(plugin)
        .single_threaded()
        .bodies(false)
        .build();
    let (_, bodies) = scene.spawn_all(&mut app.world_mut().commands());
    app.world_mut().flush();
    (app, bodies)
}

/// The period of the body of `scene` (a scene file of bodies on a unit
/// hoop about the origin, released level with its centre), from two
/// crossings of the bottom moving right, the farthest it strayed off the
/// hoop, and the most it turned.
fn scene_swing(scene: &str) -> (f64, f64, f64) {
    let scene = ScenePreset::from_ron(scene).expect("the scene reads");
    scene_swing_of(&scene, 0)
}

/// [`scene_swing`] of the body `body` (its index in the file) of a scene
/// read.
fn scene_swing_of(scene: &ScenePreset, body: usize) -> (f64, f64, f64) {
    let dt = scene.params.timestep;
    let (mut app, bodies) = scene_app(scene);
    let cart = bodies[body];
    let (mut crossings, mut off, mut turned) = (Vec::new(), 0.0f64, 0.0f64);
    let (mut last, _, _, _) = body_state(&app, cart);
    let mut step = 0;
    while crossings.len() < 2 && step < 6000 {
        run_steps(&mut app, 1);
        step += 1;
        let (x, _, angle, _) = body_state(&app, cart);
        off = off.max((x.length() - 1.0).abs());
        turned = turned.max(angle.abs());
        if last.x < 0.0 && x.x >= 0.0 && x.y < 0.0 {
            let s = -last.x / (x.x - last.x);
            crossings.push((step as f64 - 1.0 + s) * dt);
        }
        last = x;
    }
    (crossings[1] - crossings[0], off, turned)
}

/// A scene file with a body on a path joint runs as written: the
/// format's own scene, a box on a hoop released level with its centre,
/// swings with the exact pendulum's period to 1e-5 at its 1 ms, stays on
/// the hoop (1e-5 m) and never turns (1e-5 rad), the joint `Free`. With
/// `Tangent` it turns with the orbit and swings with its inertia's
/// period, `4 sqrt((m r² + I) / (m g r)) K`, to 1.5e-5: its error is the
/// same in each period and the same at 60 Hz (from −7e-6 to −1.2e-5 as
/// the inertia goes from 0.003 to 0.07 kg·m²), the floor of avian's `f32`
/// turn, not the step's.
#[test]
fn a_scene_files_box_on_a_hoop_swings_with_the_exact_period() {
    let exact = pendulum_period(1.0, G, std::f64::consts::FRAC_PI_2);
    let (period, off, turned) = scene_swing(CART_SCENE);
    println!(
        "scene, Free: period {period:.7} s against {exact:.7} s, off {off:.2e} m, turned {turned:.2e} rad"
    );
    assert!(
        ((period - exact) / exact).abs() <= 1e-5,
        "period {period} s against {exact} s"
    );
    assert!(off <= 1e-5, "strayed {off:e} m off the hoop");
    assert!(turned <= 1e-5, "turned {turned:e} rad");
    // The box's own inertia lengthens the period: an equivalent length
    // of (m r² + I) / (m r).
    let inertia = 2.0 * (0.04 + 0.01) / 3.0;
    let length = (2.0 + inertia) / 2.0;
    let exact = pendulum_period(length, G, std::f64::consts::FRAC_PI_2);
    let (period, off, _) = scene_swing(&CART_SCENE.replace("rotation: Free", "rotation: Tangent"));
    println!("scene, Tangent: period {period:.7} s against {exact:.7} s, off {off:.2e} m");
    assert!(
        ((period - exact) / exact).abs() <= 1.5e-5,
        "period {period} s against {exact} s"
    );
    assert!(off <= 1e-5, "strayed {off:e} m off the hoop");
}

/// A spring anchor pulls a free body at its grab point, as the scene's
/// mouse drag does: over one step the force `k (anchor - p)` moves the
/// body by `F/m` and turns it by `(r × F)/I` (to 1e-5 relative, f32);
/// once the anchor goes, the body coasts (1e-6).
#[test]
fn a_spring_anchor_pulls_a_body_by_its_grab_point() {
    let mut app = physics_app(SUBSTEPS);
    without_gravity(&mut app);
    let (mass, inertia) = (2.0, 0.5);
    let body = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Position(Vector::ZERO),
            Mass(mass),
            AngularInertia(inertia),
            SpringAnchor::new(DVec2::new(0.5, 1.0)).expect("finite"),
            GrabPoint::new(DVec2::new(0.5, 0.0)).expect("finite"),
        ))
        .id();
    run_steps(&mut app, 1);
    let k = app.world().resource::<SimParams>().drag_stiffness;
    let (_, velocity, _, spin) = body_state(&app, body);
    let (v, w) = (k / f64::from(mass) * DT, 0.5 * k / f64::from(inertia) * DT);
    println!("pulled: v {velocity} (expected (0, {v})), w {spin} (expected {w})");
    assert!(velocity.x.abs() <= 1e-5 * v, "{velocity}");
    assert!((velocity.y - v).abs() <= 1e-5 * v, "{velocity} against {v}");
    assert!((spin - w).abs() <= 1e-5 * w, "{spin} against {w}");
    app.world_mut().entity_mut(body).remove::<SpringAnchor>();
    run_steps(&mut app, 1);
    let (_, coasting, _, spun) = body_state(&app, body);
    assert!(
        (coasting - velocity).length() <= 1e-6,
        "{coasting} after {velocity}"
    );
    assert!((spun - spin).abs() <= 1e-6, "{spun} after {spin}");
}

/// A restart puts a scene's bodies back where the file starts them, a
/// path joint met afresh: the run after it repeats the run before it (the
/// box's state 0.2 s in, turned with its hoop, the same to 1e-6), and a
/// restart as the scene starts (as the window's loading of a scene sends)
/// changes nothing, its static floor included.
#[test]
fn a_restart_puts_a_scenes_bodies_back_at_their_start() {
    let floor = r#"    ), (name: "floor", kind: Static, shape: Box((half_extents: (2.0, 0.1))), position: (0.0, -1.5))],
    wires"#;
    let text = CART_SCENE
        .replace("rotation: Free", "rotation: Tangent")
        .replace("    )],\n    wires", floor);
    let scene = ScenePreset::from_ron(&text).expect("the scene reads");
    assert_eq!(scene.bodies.len(), 2, "{text}");
    let steps = (0.2 / scene.params.timestep).round() as u32;
    let (mut app, bodies) = scene_app(&scene);
    app.world_mut().write_message(Restart);
    let cart = bodies[0];
    let start = body_state(&app, cart);
    run_steps(&mut app, steps);
    let first = body_state(&app, cart);
    run_steps(&mut app, 2 * steps);
    app.world_mut().write_message(Restart);
    run_steps(&mut app, steps);
    let again = body_state(&app, cart);
    println!("restarted: {first:?} then {again:?} (from {start:?})");
    assert!((first.0 - start.0).length() > 0.1, "the box never swung");
    assert!(
        (again.0 - first.0).length() <= 1e-6,
        "{again:?} against {first:?}"
    );
    assert!(
        (again.1 - first.1).length() <= 1e-6,
        "{again:?} against {first:?}"
    );
    assert!(
        (again.2 - first.2).abs() <= 1e-6,
        "{again:?} against {first:?}"
    );
    assert!(
        (again.3 - first.3).abs() <= 1e-6,
        "{again:?} against {first:?}"
    );
}

/// A box of 1 kg, 0.2 m by 0.1 m, hinged to a static post at the origin
/// 0.5 m above its centre, let go 30° out; `hinge` the joint's line.
fn hinged_box(hinge: &str) -> String {
    let (s, c) = 30f64.to_radians().sin_cos();
    format!(
        r#"(
    name: "A hinged box",
    params: (integrator: Rattle, gravity: (0.0, -9.81)),
    bodies: [
        (name: "post", kind: Static, shape: Ball((radius: 0.05)), position: (0.0, 0.0)),
        (name: "box", shape: Box((half_extents: (0.1, 0.05))), mass: 1.0,
         position: ({x}, {y}), angle_degrees: 30.0),
    ],
    constraints: [{hinge}],
)"#,
        x = 0.5 * s,
        y = -0.5 * c,
    )
}

/// A scene's hinge is avian's revolute joint at its point: a box hinged
/// 0.5 m above its centre swings as the physical pendulum of equivalent
/// length `(I + m d²) / (m d)` from 30°, its period to 4e-3 at 60 Hz
/// with avian's six substeps (avian's own joint: 2.5e-3 here; an anchor
/// 1 cm off would miss by 1 %).
#[test]
fn a_scenes_hinge_swings_its_box_as_a_physical_pendulum() {
    let text = hinged_box(r#"Hinge((a: "post", b: "box", at: (0.0, 0.0)))"#);
    let inertia = (0.04 + 0.01) / 12.0;
    let length = (inertia + 0.25) / 0.5;
    let exact = pendulum_period(length, G, 30f64.to_radians());
    let scene = ScenePreset::from_ron(&text).expect("the scene reads");
    let (period, _, _) = scene_swing_of(&scene, 1);
    println!("hinged box: period {period:.6} s against {exact:.6} s");
    assert!(
        ((period - exact) / exact).abs() <= 4e-3,
        "period {period} s against {exact} s"
    );
}
