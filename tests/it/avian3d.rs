//! Rigid bodies of avian3d held on our wires in space by path joints: the
//! reference truths of ../shared/PHYSICS.md, "Bodies beside beads", and a
//! cart turned with a banked loop.

use avian3d::math::{AdjustPrecision, Vector};
use avian3d::prelude::*;
use bevy::math::{DQuat, DVec3, Vec3};
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use wirebead::geometry::{Circle, Helix, Line, OnPlane, SpaceCurve};
use wirebead::prelude::*;
use wirebead::reference::pendulum_period;
use wirebead::{Integrator, SpaceWire, avian3d::*};

const G: f64 = 9.81;
const DT: f64 = 1.0 / 60.0;
/// Avian's default.
const SUBSTEPS: u32 = 6;

/// Our plugin and avian3d's, gravity `gravity`, stepping `dt` with avian's
/// default substeps, its first update taken (no step).
fn physics_app(dt: f64, gravity: DVec3) -> App {
    let params = SimParams {
        timestep: dt,
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
    app.insert_resource(Gravity(gravity.adjust_precision()));
    app.insert_resource(SubstepCount(SUBSTEPS));
    app.insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    app.finish();
    app.cleanup();
    app.update();
    app
}

/// A wire in space of `curve`, placed by `transform`.
fn wire(app: &mut App, curve: impl SpaceCurve + Send + Sync + 'static, at: Transform) -> Entity {
    app.world_mut().spawn((SpaceWire::curve(curve), at)).id()
}

/// A dynamic box of `mass` and principal moments `inertia` at `at`
/// turned by `rotation`, never asleep, held by `joint`.
fn held_body(
    app: &mut App,
    (at, rotation): (DVec3, DQuat),
    velocity: DVec3,
    (mass, inertia): (f32, Vec3),
    joint: PathJoint,
) -> Entity {
    app.world_mut()
        .spawn((
            RigidBody::Dynamic,
            Position(at.adjust_precision()),
            Rotation(rotation.adjust_precision()),
            LinearVelocity(velocity.adjust_precision()),
            Mass(mass),
            AngularInertia::new(inertia),
            SleepingDisabled,
            joint,
        ))
        .id()
}

/// The body's centre, velocity, orientation and spin, in `f64`.
fn body_state(app: &App, body: Entity) -> (DVec3, DVec3, DQuat, DVec3) {
    let world = app.world();
    let f = |v: Vector| DVec3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z));
    let q = world.get::<Rotation>(body).expect("a body").0;
    (
        f(world.get::<Position>(body).expect("a body").0),
        f(world.get::<LinearVelocity>(body).expect("a body").0),
        DQuat::from_xyzw(q.x.into(), q.y.into(), q.z.into(), q.w.into()),
        f(world.get::<AngularVelocity>(body).expect("a body").0),
    )
}

/// The angle between two orientations, accurate where they are near (a
/// quaternion read from `f32` is of length one only to about 1e-7, which
/// `acos` of their dot product turns into 1e-4 rad).
fn angle(a: DQuat, b: DQuat) -> f64 {
    let d = (a.normalize().inverse() * b.normalize()).normalize();
    2.0 * d.xyz().length().atan2(d.w.abs())
}

/// What a body swinging on a vertical unit hoop (the xy-plane, gravity
/// along −y) did: its period from its crossings of the bottom, the
/// farthest its centre strayed from the hoop, the most it turned, and the
/// most it turned other than with its orbit about z.
struct Swing {
    period: f64,
    off_the_wire: f64,
    turned: f64,
    turned_against_orbit: f64,
}

/// A box of 1 kg with moments (0.3, 0.4, `iz`), held at its centre on a
/// vertical unit hoop by a joint turning it as `rotation` says, released
/// 60° from the bottom, run for `periods` periods of `exact` at `dt`.
fn swing(dt: f64, iz: f32, rotation: PathRotation, exact: f64, periods: f64) -> Swing {
    let mut app = physics_app(dt, DVec3::new(0.0, -G, 0.0));
    let hoop = wire(
        &mut app,
        OnPlane(Circle { radius: 1.0 }),
        Transform::IDENTITY,
    );
    let theta0 = 60f64.to_radians();
    let start = DVec3::new(theta0.sin(), -theta0.cos(), 0.0);
    let joint = PathJoint::new(hoop).with_rotation(rotation);
    let inertia = (1.0, Vec3::new(0.3, 0.4, iz));
    let body = held_body(
        &mut app,
        (start, DQuat::IDENTITY),
        DVec3::ZERO,
        inertia,
        joint,
    );
    let orbit0 = start.x.atan2(-start.y);
    let (mut off, mut turned, mut against) = (0.0f64, 0.0f64, 0.0f64);
    let mut crossings = Vec::new();
    let mut last = start;
    let steps = (periods * exact / dt).round() as usize;
    for step in 1..=steps {
        app.update();
        let (p, _, q, _) = body_state(&app, body);
        off = off.max((p.length() - 1.0).abs().max(p.z.abs()));
        turned = turned.max(angle(q, DQuat::IDENTITY));
        let orbit = p.x.atan2(-p.y);
        against = against.max(angle(q, DQuat::from_rotation_z(orbit - orbit0)));
        if last.x < 0.0 && p.x >= 0.0 {
            let part = -last.x / (p.x - last.x);
            crossings.push((step as f64 - 1.0 + part) * dt);
        }
        last = p;
    }
    assert!(
        crossings.len() >= 2,
        "{} crossings of the bottom",
        crossings.len()
    );
    let n = crossings.len() - 1;
    Swing {
        period: (crossings[n] - crossings[0]) / n as f64,
        off_the_wire: off,
        turned,
        turned_against_orbit: against,
    }
}

/// A box held at its centre on a vertical hoop in space, free to turn,
/// swings as a point pendulum: the elliptic integral's period to 1e-3 at
/// 60 Hz and 1e-5 at 1 ms (avian's six substeps), on the hoop to 1e-5 m,
/// and it never turns (1e-5 rad): no torque acts about its centre. The
/// same when it may turn about the hoop's binormal only (its axis, at
/// right angles to the hoop's plane): the rows that hold its other two
/// axes give no torque either.
#[test]
fn a_box_held_at_its_centre_in_space_swings_as_a_point_pendulum_and_never_turns() {
    let exact = pendulum_period(1.0, G, 60f64.to_radians());
    let runs = [(DT, 4.5, 1e-3), (1e-3, 2.5, 1e-5)];
    for rotation in [PathRotation::Free, PathRotation::AroundBinormal] {
        for (dt, periods, bound) in runs {
            let s = swing(dt, 0.5, rotation, exact, periods);
            let error = (s.period - exact) / exact;
            eprintln!(
                "space, {rotation:?}, dt {dt:.4}: period error {error:+.2e}, off the wire {:.2e} m, \
             turned {:.2e} rad",
                s.off_the_wire, s.turned
            );
            assert!(
                error.abs() <= bound,
                "period off by {error:+e} at dt = {dt}"
            );
            assert!(s.off_the_wire <= 1e-5, "strayed {:e} m", s.off_the_wire);
            assert!(s.turned <= 1e-5, "turned {:e} rad", s.turned);
        }
    }
}

/// A box turned with the hoop's frame (`ToPath`) spins with its orbit
/// about the hoop's axis, and its inertia about that axis adds to the
/// pendulum's: the period `4 sqrt((m r² + I) / (m g r)) K` to 1e-3 at
/// 60 Hz and 1e-4 at 1 ms (measured: 6.5e-6 and 2.8e-5; the plane's
/// joint meets 1e-5 at 1 ms), on the hoop to 1e-5 m, turned with its
/// orbit to 1e-5 rad.
#[test]
fn a_box_turned_with_its_hoop_in_space_spins_with_the_orbit_and_swings_slower() {
    let iz = 0.5;
    let exact = pendulum_period(1.0, G, 60f64.to_radians()) * (1.0f64 + iz).sqrt();
    for (dt, periods, bound) in [(DT, 4.5, 1e-3), (1e-3, 2.5, 1e-4)] {
        let s = swing(dt, iz as f32, PathRotation::ToPath, exact, periods);
        let error = (s.period - exact) / exact;
        eprintln!(
            "space, to path, dt {dt:.4}: period error {error:+.2e}, off the wire {:.2e} m, \
             turned against the orbit {:.2e} rad",
            s.off_the_wire, s.turned_against_orbit
        );
        assert!(
            error.abs() <= bound,
            "period off by {error:+e} at dt = {dt}"
        );
        assert!(s.off_the_wire <= 1e-5, "strayed {:e} m", s.off_the_wire);
        assert!(
            s.turned_against_orbit <= 1e-5,
            "turned against its orbit by {:e} rad",
            s.turned_against_orbit
        );
    }
}

/// A cart turned with a banked loop (`ToPath`): a helix of radius 2 m and
/// pitch 3 m about z, so a vertical loop banked 13.4° that moves 3 m
/// sideways a turn; a box of 2 kg held 0.2 m below its centre, entering at
/// 11 m/s at the bottom. At 60 Hz over 1.5 s (about one loop), its anchor
/// stays on the rail to 1e-5 m and its orientation is the rail's frame
/// there times the one it began with to 1e-4 rad.
#[test]
fn a_cart_on_a_banked_loop_keeps_the_rails_up() {
    let mut app = physics_app(DT, DVec3::new(0.0, -G, 0.0));
    // The helix climbs along its local y; turned so y is the world's z,
    // its radius from the axis at the bottom points down.
    let turn = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let helix = Helix {
        radius: 2.0,
        pitch: 3.0,
    };
    let rail = wire(&mut app, helix, Transform::from_rotation(turn));
    let place = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
    // The bottom of the loop: local θ where the radius points along −y
    // of the world (local +z turned by the place is world −y).
    let local = DVec3::new(0.0, 0.75, 2.0);
    let anchor = place * local;
    let frame = helix.frame(local, f64::NAN);
    let tangent = place * frame.tangent;
    let normal = place * frame.normal;
    // The box: +x along the rail, +y along the rail's normal turned
    // inward (up, at the bottom), its anchor 0.2 m below its centre.
    let up = -normal;
    let body_rotation = DQuat::from_mat3(&bevy::math::DMat3::from_cols(
        tangent,
        up,
        tangent.cross(up),
    ));
    let arm = DVec3::new(0.0, -0.2, 0.0);
    let centre = anchor - body_rotation * arm;
    let joint = PathJoint::new(rail)
        .with_anchor(arm)
        .with_rotation(PathRotation::ToPath);
    let inertia = (2.0, Vec3::new(0.043, 0.087, 0.075));
    let body = held_body(
        &mut app,
        (centre, body_rotation),
        11.0 * tangent,
        inertia,
        joint,
    );
    let start_frame = DQuat::from_mat3(&bevy::math::DMat3::from_cols(
        tangent,
        normal,
        tangent.cross(normal),
    ));
    let offset = start_frame.inverse() * body_rotation;
    let (mut off, mut turned, mut hint) = (0.0f64, 0.0f64, f64::NAN);
    for _ in 0..90 {
        app.update();
        let (c, _, q, _) = body_state(&app, body);
        let a = place.inverse() * (c + q * arm);
        let rows = helix.rows(a, hint);
        off = off.max(rows[0].c.abs().max(rows[1].c.abs()));
        hint = helix.parameter(a, hint);
        let f = helix.frame(a, hint);
        let (t, n) = (place * f.tangent, place * f.normal);
        let frame = DQuat::from_mat3(&bevy::math::DMat3::from_cols(t, n, t.cross(n)));
        turned = turned.max(angle(q, frame * offset));
    }
    eprintln!(
        "banked loop: off the rail {off:.2e} m, turned from the rail's frame {turned:.2e} rad"
    );
    assert!(off <= 1e-5, "the anchor strayed {off:e} m from the rail");
    assert!(
        turned <= 1e-4,
        "the cart turned {turned:e} rad from the rail's frame"
    );
}

/// A velocity motor on a straight rail in space accelerates a body at
/// `F/m` (to 1 %) until it reaches its speed, then holds it (to 1e-3):
/// 2 kg, 10 N, 1.5 m/s, no gravity.
#[test]
fn a_velocity_motor_in_space_accelerates_at_its_force_over_the_mass() {
    let mut app = physics_app(DT, DVec3::ZERO);
    let rail = wire(&mut app, OnPlane(Line), Transform::IDENTITY);
    let joint = PathJoint::new(rail).with_motor(PathMotor::Velocity {
        speed: 1.5,
        max_force: 10.0,
    });
    let body = held_body(
        &mut app,
        (DVec3::ZERO, DQuat::IDENTITY),
        DVec3::ZERO,
        (2.0, Vec3::splat(0.1)),
        joint,
    );
    app.update();
    let (_, v, ..) = body_state(&app, body);
    let accel = v.length() / DT;
    assert!(
        (accel - 5.0).abs() <= 0.05,
        "accelerated at {accel} m/s², not F/m = 5"
    );
    for _ in 0..60 {
        app.update();
    }
    let (p, v, ..) = body_state(&app, body);
    eprintln!("motor in space: {accel:.4} m/s², then {v} at {p}");
    assert!((v.x.abs() - 1.5).abs() <= 1e-3, "holds {v}");
    assert!(v.y.abs().max(v.z.abs()) <= 1e-5 && p.y.abs().max(p.z.abs()) <= 1e-5);
}
