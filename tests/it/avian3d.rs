//! Rigid bodies of avian3d held on our wires in space by path joints: the
//! reference truths of ../shared/PHYSICS.md, "Bodies beside beads", and a
//! cart turned with a banked loop.

use avian3d::math::{AdjustPrecision, Vector};
use avian3d::prelude::*;
use bevy::math::cubic_splines::{CubicCardinalSpline, CyclicCubicGenerator};
use bevy::math::{DQuat, DVec3, Vec3};
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use wirebead::geometry::{
    Circle, Helix, Line, OnPlane, Plane, SpaceCurve, Spline, SplineKind, SplineSpec,
};
use wirebead::prelude::*;
use wirebead::reference::{bead_on_a_free_hoop, pendulum_period};
use wirebead::{GrabPoint, Integrator, SpaceBead, SpaceWire, SpringAnchor, avian3d::*};

const G: f64 = 9.81;
const DT: f64 = 1.0 / 60.0;
/// Avian's default.
const SUBSTEPS: u32 = 6;

/// Our plugin and avian3d's, gravity `gravity` (ours and avian's), stepping `dt` with avian's
/// default substeps, its first update taken (no step).
pub(super) fn physics_app(dt: f64, gravity: DVec3) -> App {
    let params = SimParams {
        timestep: dt,
        method: Method::new(Integrator::Rattle, None).expect("RATTLE"),
        gravity: gravity.truncate(),
        gravity_z: gravity.z,
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
/// 2 kg, 10 N, 1.5 m/s, no gravity; `PathJointForces` says the joint gave
/// 10 N along the rail (to 1e-3 N) and no torque while accelerating.
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
    // Accelerating, the motor gives its 10 N along the rail, and the joint
    // nothing else.
    let pushing = *app.world().get::<PathJointForces>(body).expect("forces");
    assert!(
        (pushing.motor_force.abs() - 10.0).abs() <= 1e-3
            && (pushing.force.length() - 10.0).abs() <= 1e-3
            && pushing.torque.length() <= 1e-3,
        "accelerating, the joint gave {pushing:?}"
    );
    for _ in 0..60 {
        app.update();
    }
    let (p, v, ..) = body_state(&app, body);
    eprintln!("motor in space: {accel:.4} m/s², then {v} at {p}");
    assert!((v.x.abs() - 1.5).abs() <= 1e-3, "holds {v}");
    assert!(v.y.abs().max(v.z.abs()) <= 1e-5 && p.y.abs().max(p.z.abs()) <= 1e-5);
}

/// A box held 0.2 m off its centre on a vertical unit hoop, kept from
/// turning against the wire (`Fixed`), only translates: its centre swings
/// on a unit circle with the point pendulum's period (to 1e-3 at 60 Hz),
/// its anchor on the hoop to 1e-5 m, and it never turns (1e-5 rad), where
/// free it would swing about its anchor.
#[test]
fn a_fixed_box_held_off_its_centre_only_translates() {
    let mut app = physics_app(DT, DVec3::new(0.0, -G, 0.0));
    let hoop = wire(
        &mut app,
        OnPlane(Circle { radius: 1.0 }),
        Transform::IDENTITY,
    );
    let theta0 = 60f64.to_radians();
    let arm = DVec3::new(0.2, 0.1, 0.0);
    let anchor = DVec3::new(theta0.sin(), -theta0.cos(), 0.0);
    let joint = PathJoint::new(hoop)
        .with_anchor(arm)
        .with_rotation(PathRotation::Fixed);
    let body = held_body(
        &mut app,
        (anchor - arm, DQuat::IDENTITY),
        DVec3::ZERO,
        (1.0, Vec3::new(0.3, 0.4, 0.5)),
        joint,
    );
    let exact = pendulum_period(1.0, G, theta0);
    let (mut off, mut turned, mut crossings, mut last) = (0.0f64, 0.0f64, Vec::new(), anchor);
    for step in 1..=((3.5 * exact / DT).round() as usize) {
        app.update();
        let (c, _, q, _) = body_state(&app, body);
        let a = c + q * arm;
        off = off.max((a.length() - 1.0).abs().max(a.z.abs()));
        turned = turned.max(angle(q, DQuat::IDENTITY));
        if last.x < 0.0 && a.x >= 0.0 {
            crossings.push((step as f64 - 1.0 - last.x / (a.x - last.x)) * DT);
        }
        last = a;
    }
    let n = crossings.len() - 1;
    let error = ((crossings[n] - crossings[0]) / n as f64 - exact) / exact;
    eprintln!(
        "fixed: period error {error:+.2e}, off the wire {off:.2e} m, turned {turned:.2e} rad"
    );
    assert!(error.abs() <= 1e-3, "period off by {error:+e}");
    assert!(off <= 1e-5, "the anchor strayed {off:e} m");
    assert!(turned <= 1e-5, "the box turned {turned:e} rad");
}

/// A spline in space closed through a crossing (a figure eight in the
/// xy-plane, rising and falling in z between its lobes, level where it
/// crosses itself): a body driven round it at 4 m/s under gravity visits
/// its lobes in turn (20 crossings, never the same lobe twice in a row)
/// and stays on it to 1e-5 m.
#[test]
fn a_body_keeps_its_branch_where_a_figure_eight_in_space_crosses_itself() {
    let mut app = physics_app(DT, DVec3::new(0.0, -G, 0.0));
    let n = 24;
    let points = (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            DVec3::new(2.0 * t.sin(), (2.0 * t).sin(), 0.4 * (2.0 * t).sin())
        })
        .collect();
    let spline = Spline::<DVec3>::new(SplineSpec {
        kind: SplineKind::CatmullRom,
        points,
        closed: true,
    })
    .expect("a figure eight");
    let rail = wire(&mut app, spline.clone(), Transform::IDENTITY);
    let joint = PathJoint::new(rail).with_motor(PathMotor::Velocity {
        speed: 4.0,
        max_force: 200.0,
    });
    let body = held_body(
        &mut app,
        (DVec3::ZERO, DQuat::IDENTITY),
        DVec3::ZERO,
        (1.0, Vec3::splat(0.1)),
        joint,
    );
    let mut lobes: Vec<bool> = Vec::new();
    let (mut inside, mut off, mut steps, mut hint) = (false, 0.0f64, 0, f64::NAN);
    while lobes.len() < 21 && steps < 60 * 60 {
        app.update();
        steps += 1;
        let (p, ..) = body_state(&app, body);
        let rows = spline.rows(p, hint);
        hint = spline.parameter(p, hint);
        off = off.max(rows[0].c.abs().max(rows[1].c.abs()));
        if p.x.abs() > 1.5 && !inside {
            lobes.push(p.x > 0.0);
            inside = true;
        } else if p.x.abs() < 1.0 {
            inside = false;
        }
    }
    let repeats = lobes.windows(2).filter(|w| w[0] == w[1]).count();
    eprintln!(
        "figure eight in space: {} lobe visits in {steps} steps; off the wire by {off:.2e} m",
        lobes.len()
    );
    assert_eq!(repeats, 0, "one lobe twice in a row: {lobes:?}");
    assert!(
        lobes.len() >= 21,
        "only {} lobe visits in a minute",
        lobes.len()
    );
    assert!(off <= 1e-5, "the body strayed {off:e} m from the spline");
}

/// The end of an open spline in space stops a body sliding down it: it
/// rests at the end to 1e-5 m and moves at most 1e-3 m/s there.
#[test]
fn the_end_of_an_open_curve_in_space_stops_the_body() {
    let mut app = physics_app(DT, DVec3::new(0.0, -G, 0.0));
    let end = DVec3::new(2.0, -1.0, 0.6);
    let spline = Spline::<DVec3>::new(SplineSpec {
        kind: SplineKind::CatmullRom,
        points: vec![DVec3::ZERO, DVec3::new(1.0, -0.5, 0.3), end],
        closed: false,
    })
    .expect("a spline");
    let rail = wire(&mut app, spline, Transform::IDENTITY);
    let body = held_body(
        &mut app,
        (DVec3::ZERO, DQuat::IDENTITY),
        DVec3::ZERO,
        (1.0, Vec3::splat(0.1)),
        PathJoint::new(rail),
    );
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
    eprintln!("end in space: held {off:.2e} m from the end, moving at most {moving:.2e} m/s");
    assert!(off <= 1e-5, "the body is {off:e} m from the end");
    assert!(
        moving <= 1e-3,
        "the body moves at {moving:e} m/s at the end"
    );
}

/// A joint that cannot do all it is asked does what it can and never
/// writes a number that is not finite: on an entity that is no wire it
/// holds nothing (the body falls as avian's free body does, to 1e-4 m in
/// a second); on a surface asked to turn the body with the wire's frame,
/// which a surface has not, it holds the anchor on the surface (a tilted
/// plane, to 1e-5 m) and lets the body turn.
#[test]
fn a_joint_that_cannot_hold_all_it_is_asked_holds_what_it_can() {
    let mut app = physics_app(DT, DVec3::new(0.0, -G, 0.0));
    let not_a_wire = app.world_mut().spawn(Transform::IDENTITY).id();
    let falling = held_body(
        &mut app,
        (DVec3::ZERO, DQuat::IDENTITY),
        DVec3::ZERO,
        (1.0, Vec3::splat(0.1)),
        PathJoint::new(not_a_wire).with_rotation(PathRotation::ToPath),
    );
    let tilt = Quat::from_rotation_z(0.3);
    let slope = app
        .world_mut()
        .spawn((SpaceWire::surface_of(Plane), Transform::from_rotation(tilt)))
        .id();
    let sliding = held_body(
        &mut app,
        (DVec3::new(0.0, 0.0, 0.0), DQuat::IDENTITY),
        DVec3::new(0.0, 0.0, 1.0),
        (1.0, Vec3::splat(0.1)),
        PathJoint::new(slope).with_rotation(PathRotation::AroundTangent),
    );
    let normal = DVec3::from(tilt * Vec3::Y);
    let mut off = 0.0f64;
    for _ in 0..60 {
        app.update();
        let (p, ..) = body_state(&app, sliding);
        off = off.max(p.dot(normal).abs());
    }
    let (p, v, q, w) = body_state(&app, falling);
    assert!(p.is_finite() && v.is_finite() && q.is_finite() && w.is_finite());
    let fallen = -0.5 * G * (1.0 + 1.0 / 360.0);
    assert!(
        (p.y - fallen).abs() <= 1e-4,
        "fell to {} m, not {fallen}",
        p.y
    );
    let (p, ..) = body_state(&app, sliding);
    eprintln!("on a surface: off it by {off:.2e} m, slid to {p}");
    assert!(off <= 1e-5, "the anchor left the surface by {off:e} m");
    assert!(p.x < -0.1, "the body did not slide down the slope: {p}");
}

/// At a sharp corner in space (two straight segments meeting at 45°, the
/// second rising out of the first's plane), a body coasting at 2 m/s (no
/// gravity) goes on along the second segment at its speed's part along
/// it, `2 cos 45°` (to 1e-3), as in the plane, on the wire to 1e-5 m.
#[test]
fn a_body_turns_a_sharp_corner_in_space() {
    let mut app = physics_app(DT, DVec3::ZERO);
    let bend = DVec3::new(1.0, 0.0, 1.0) * std::f64::consts::FRAC_1_SQRT_2;
    let spline = Spline::<DVec3>::new(SplineSpec {
        kind: SplineKind::Segments(vec![
            [
                DVec3::new(-2.0, 0.0, 0.0),
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::ZERO,
                DVec3::ZERO,
            ],
            [DVec3::ZERO, 2.0 * bend, DVec3::ZERO, DVec3::ZERO],
        ]),
        points: Vec::new(),
        closed: false,
    })
    .expect("two segments");
    let rail = wire(&mut app, spline, Transform::IDENTITY);
    let body = held_body(
        &mut app,
        (DVec3::new(-1.5, 0.0, 0.0), DQuat::IDENTITY),
        DVec3::new(2.0, 0.0, 0.0),
        (1.0, Vec3::splat(0.1)),
        PathJoint::new(rail),
    );
    let mut off = 0.0f64;
    for _ in 0..60 {
        app.update();
        let (p, ..) = body_state(&app, body);
        // The distance from the two segments.
        let first = DVec3::new(p.x.min(0.0), 0.0, 0.0);
        let second = bend * p.dot(bend).max(0.0);
        off = off.max((p - first).length().min((p - second).length()));
    }
    let (p, v, ..) = body_state(&app, body);
    eprintln!("corner in space: off by {off:.2e} m; ends at {p} moving {v}");
    let expected = 2.0 * bend.x * bend;
    assert!(
        (v - expected).length() <= 1e-3,
        "after the corner it moves at {v}"
    );
    assert!(
        p.x > 0.1 && (p - bend * p.dot(bend)).length() <= 1e-5,
        "the body is at {p}, not on the second segment"
    );
    assert!(off <= 1e-5, "the body strayed {off:e} m from the wire");
}

/// A cart turned with a game's own Bevy curve in space (a closed
/// Catmull–Rom loop through six points at several heights, through
/// `Spline::from_curve`), coasting at 6 m/s with no gravity for 3 s
/// (more than a lap): its anchor stays on the curve to 1e-5 m, and its
/// orientation is the curve's rotation-minimizing frame there times the
/// one it began with, to 1e-4 rad, the frame's turn round the closed
/// loop included.
#[test]
fn a_cart_turned_with_a_bevy_curve_in_space_follows_its_frame() {
    let mut app = physics_app(DT, DVec3::ZERO);
    let points = [
        (4.0, 1.0, 1.0),
        (6.0, 3.0, 0.0),
        (4.0, 5.0, -1.0),
        (0.0, 4.0, -2.0),
        (-3.0, 2.0, -1.0),
        (-4.0, 0.5, 1.0),
    ]
    .map(|(x, y, z)| Vec3::new(x, y, z));
    let curve = CubicCardinalSpline::new_catmull_rom(points)
        .to_curve_cyclic()
        .expect("a loop");
    let spline = Spline::<DVec3>::from_curve(&curve);
    let rail = wire(&mut app, spline.clone(), Transform::IDENTITY);
    let start = DVec3::new(4.0, 1.0, 1.0);
    let frame_at = |p: DVec3, hint: f64| {
        let f = spline.frame(p, hint);
        DQuat::from_mat3(&bevy::math::DMat3::from_cols(
            f.tangent,
            f.normal,
            f.tangent.cross(f.normal),
        ))
    };
    let begin = frame_at(start, 0.0);
    let joint = PathJoint::new(rail).with_rotation(PathRotation::ToPath);
    let body = held_body(
        &mut app,
        (start, begin),
        6.0 * (begin * DVec3::X),
        (1.0, Vec3::new(0.1, 0.2, 0.15)),
        joint,
    );
    let (mut off, mut turned, mut hint) = (0.0f64, 0.0f64, 0.0);
    let mut travelled = 0.0;
    for _ in 0..180 {
        app.update();
        let (p, v, q, _) = body_state(&app, body);
        travelled += v.length() * DT;
        let rows = spline.rows(p, hint);
        hint = spline.parameter(p, hint);
        off = off.max(rows[0].c.abs().max(rows[1].c.abs()));
        turned = turned.max(angle(q, frame_at(p, hint)));
    }
    eprintln!(
        "bevy curve: {travelled:.1} m travelled, off the curve {off:.2e} m, turned from its frame \
         {turned:.2e} rad"
    );
    assert!(off <= 1e-5, "the anchor strayed {off:e} m");
    assert!(
        turned <= 1e-4,
        "the cart turned {turned:e} rad from the frame"
    );
}

/// What rides the hoop of [`pair_on_a_free_hoop`].
#[derive(Clone, Copy, PartialEq)]
enum Rider {
    /// A rigid body on a path joint.
    Body,
    /// A bead of ours.
    Bead,
}

/// What a body (or a bead of ours) on a hoop fixed to a free body in space
/// did over 5 s at `dt`: the farthest either strayed from the two-body
/// answer (m), the largest change of the pair's momentum over its size,
/// and the carrier's fastest spin (rad/s). The hoop lies in the carrier's
/// xy-plane, the carrier turned 30° about x so the pair turns in a tilted
/// plane.
fn pair_on_a_free_hoop(dt: f64, rider: Rider) -> (f64, f64, f64) {
    let mut app = physics_app(dt, DVec3::ZERO);
    let (m, big_m, u) = (1.0, 3.0, 1.5);
    let tilt = DQuat::from_rotation_x(30f64.to_radians());
    let carrier = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Position(Vector::ZERO),
            Rotation(tilt.adjust_precision()),
            Mass(big_m as f32),
            AngularInertia::new(Vec3::new(0.5, 0.6, 0.7)),
            SleepingDisabled,
        ))
        .id();
    let hoop = app
        .world_mut()
        .spawn((
            SpaceWire::curve(OnPlane(Circle { radius: 1.0 })),
            Transform::IDENTITY,
            WireOnBody(carrier),
        ))
        .id();
    let (start, velocity) = (tilt * DVec3::X, tilt * DVec3::new(0.0, u, 0.0));
    let body = match rider {
        Rider::Body => held_body(
            &mut app,
            (start, DQuat::IDENTITY),
            velocity,
            (m as f32, Vec3::splat(0.01)),
            PathJoint::new(hoop),
        ),
        Rider::Bead => {
            let params = BeadParams {
                mass: m,
                initial_position: start,
                initial_velocity: velocity,
            };
            let bead = SpaceBead::new(params).expect("a bead");
            app.world_mut().spawn((bead, OnWire(hoop))).id()
        }
    };
    // The rider as its user reads it: a body's avian state, a bead's own.
    let rider_state = |app: &App| match rider {
        Rider::Body => {
            let (x, v, _, _) = body_state(app, body);
            (x, v)
        }
        Rider::Bead => {
            let world = app.world();
            assert!(world.get::<Diverged>(body).is_none());
            (
                world.get::<BeadPosition<DVec3>>(body).expect("a bead").0,
                world.get::<BeadVelocity<DVec3>>(body).expect("a bead").0,
            )
        }
    };
    let momentum = |app: &App| {
        let (_, v) = rider_state(app);
        let (_, w, _, _) = body_state(app, carrier);
        m * v + big_m * w
    };
    let p0 = m * velocity;
    let (mut off, mut drift, mut spin) = (0.0f64, 0.0f64, 0.0f64);
    let steps = (5.0 / dt).round() as usize;
    for k in 1..=steps {
        app.update();
        let (bead, _) = rider_state(&app);
        let (centre, _, _, w) = body_state(&app, carrier);
        let (bead_at, centre_at) = bead_on_a_free_hoop(
            (m, big_m),
            (start, velocity),
            (DVec3::ZERO, DVec3::ZERO),
            k as f64 * dt,
        );
        off = off
            .max((bead - bead_at).length())
            .max((centre - centre_at).length());
        drift = drift.max((momentum(&app) - p0).length() / p0.length());
        spin = spin.max(w.length());
    }
    (off, drift, spin)
}

/// A bead of ours on a hoop fixed to a free body in space, no gravity, at
/// 60 Hz: it rides as a point body on a path joint, and the pair turns as
/// the two-body answer says to 1e-4 m over 5 s, as the bead's own columns
/// report it; momentum to 1e-5 of itself; the carrier's spin under 1e-4
/// rad/s, as for a body on the joint.
#[test]
fn a_bead_on_a_hoop_fixed_to_a_free_body_in_space_turns_the_pair_as_two_bodies_do() {
    let (off, drift, spin) = pair_on_a_free_hoop(DT, Rider::Bead);
    println!("off the two-body answer {off:.2e} m, momentum {drift:.2e}, spin {spin:.2e} rad/s");
    assert!(off <= 1e-4, "{off:e} m off the two-body answer");
    assert!(drift <= 1e-5, "the momentum changed by {drift:e} of itself");
    assert!(spin <= 1e-4, "the carrier spins at {spin:e} rad/s");
}

/// A body held on a hoop fixed to a free body in space, no gravity, at
/// 60 Hz with avian's substeps: the pair turns about its centre of mass as
/// the two-body answer says, to 1e-4 m over 5 s; its momentum is kept to
/// 1e-5 of itself, and the carrier barely spins (1e-4 rad/s: unlike the
/// plane's, the hoop's plane row pushes off the carrier's centre as it
/// puts back the body's `f32` rounding across the plane).
#[test]
fn a_body_on_a_hoop_fixed_to_a_free_body_in_space_turns_the_pair_as_two_bodies_do() {
    let (off, drift, spin) = pair_on_a_free_hoop(DT, Rider::Body);
    println!("off the two-body answer {off:.2e} m, momentum {drift:.2e}, spin {spin:.2e} rad/s");
    assert!(off <= 1e-4, "{off:e} m off the two-body answer");
    assert!(drift <= 1e-5, "the momentum changed by {drift:e} of itself");
    assert!(spin <= 1e-4, "the carrier spins at {spin:e} rad/s");
}

/// A spring anchor pulls a free body in space at its grab point: over one
/// step the force `k (anchor - p)` moves it by `F/m` and turns it by
/// `I⁻¹ (r × F)` (to 1e-5 relative, f32).
#[test]
fn a_spring_anchor_pulls_a_body_in_space_by_its_grab_point() {
    let mut app = physics_app(DT, DVec3::ZERO);
    let (mass, inertia) = (2.0, 0.5);
    let body = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Position(Vector::ZERO),
            Mass(mass),
            AngularInertia::new(Vec3::splat(inertia)),
            SpringAnchor::new(DVec3::new(0.5, 1.0, 0.0)).expect("finite"),
            GrabPoint::new(DVec3::new(0.5, 0.0, 0.0)).expect("finite"),
        ))
        .id();
    app.update();
    let k = app.world().resource::<SimParams>().drag_stiffness;
    let (_, velocity, _, spin) = body_state(&app, body);
    let v = DVec3::new(0.0, k / f64::from(mass) * DT, 0.0);
    let w = DVec3::new(0.0, 0.0, 0.5 * k / f64::from(inertia) * DT);
    println!("pulled in space: v {velocity} (expected {v}), w {spin} (expected {w})");
    assert!(
        (velocity - v).length() <= 1e-5 * v.length(),
        "{velocity} against {v}"
    );
    assert!(
        (spin - w).length() <= 1e-5 * w.length(),
        "{spin} against {w}"
    );
}

/// The period of the box of a scene in space hinged 0.5 m above its
/// centre to a post at the origin, let go 30° out in the x–y plane
/// (`hinge` the joint's line): from two crossings of the bottom moving
/// +x, and the farthest it left that plane.
fn hinged_box_swing(hinge: &str) -> (f64, f64) {
    let (s, c) = 30f64.to_radians().sin_cos();
    let text = format!(
        r#"(
    name: "A hinged box",
    dimension: 3,
    params: (integrator: Rattle, gravity: (0.0, -9.81, 0.0)),
    bodies: [
        (name: "post", kind: Static, shape: Ball((radius: 0.05)), position: (0.0, 0.0, 0.0)),
        (name: "box", shape: Box((half_extents: (0.1, 0.05, 0.05))), mass: 1.0,
         position: ({x}, {y}, 0.0), rotation: (axis: (0.0, 0.0, 1.0), angle_degrees: 30.0)),
    ],
    constraints: [{hinge}],
)"#,
        x = 0.5 * s,
        y = -0.5 * c,
    );
    let wirebead::SceneFile::Space(scene) = wirebead::SceneFile::from_ron(&text).expect("reads")
    else {
        panic!("a scene in space");
    };
    let plugin = WireBeadPlugin::new(scene.params.0.clone()).expect("valid parameters");
    let mut app = wirebead::headless::Headless::new(plugin)
        .single_threaded()
        .bodies(true)
        .build();
    let (_, bodies) = scene.spawn_all(&mut app.world_mut().commands());
    app.world_mut().flush();
    let dt = scene.params.0.timestep;
    let (mut crossings, mut off_plane) = (Vec::new(), 0.0f64);
    let mut last = body_state(&app, bodies[1]).0;
    let mut step = 0;
    while crossings.len() < 2 && step < 6000 {
        wirebead::headless::run_steps(&mut app, 1);
        step += 1;
        let x = body_state(&app, bodies[1]).0;
        off_plane = off_plane.max(x.z.abs());
        if last.x < 0.0 && x.x >= 0.0 && x.y < 0.0 {
            crossings.push((step as f64 - 1.0 + -last.x / (x.x - last.x)) * dt);
        }
        last = x;
    }
    (crossings[1] - crossings[0], off_plane)
}

/// A scene's hinge in space is avian's revolute joint about its axis, or
/// its ball joint where it has none: a box hinged 0.5 m above its centre
/// about `z` swings in the x–y plane as the physical pendulum of
/// equivalent length `(I + m d²) / (m d)` from 30°, its period to 4e-3 at
/// 60 Hz with avian's six substeps (avian's own joints: 2.5e-3 here); on a
/// ball joint the same.
#[test]
fn a_scenes_hinge_in_space_swings_its_box_about_its_axis() {
    let inertia = (0.04 + 0.01) / 12.0;
    let exact = pendulum_period((inertia + 0.25) / 0.5, G, 30f64.to_radians());
    for (hinge, what) in [
        (
            r#"Hinge((a: "post", b: "box", at: (0.0, 0.0, 0.0), axis: (0.0, 0.0, 1.0)))"#,
            "hinge",
        ),
        (
            r#"Hinge((a: "post", b: "box", at: (0.0, 0.0, 0.0)))"#,
            "ball joint",
        ),
    ] {
        let (period, off) = hinged_box_swing(hinge);
        println!("{what}: period {period:.6} s against {exact:.6} s, off its plane {off:.1e} m");
        assert!(
            ((period - exact) / exact).abs() <= 4e-3,
            "{what}: period {period} s against {exact} s"
        );
        assert!(off <= 1e-4, "{what}: left its plane by {off:e} m");
    }
}
