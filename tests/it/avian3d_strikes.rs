//! Beads with radii that strike avian3d's bodies in space: a bead
//! dropped on a floor rises to `e² h` whatever the floor's shape (a box,
//! a convex hull, a triangle mesh), and a strike off a free ball's centre
//! turns it as `(r × J) / I` says, momentum and energy kept.

use std::f32::consts::FRAC_PI_2;

use avian3d::math::Vector;
use avian3d::prelude::*;
use bevy::math::DVec3;
use bevy::prelude::*;
use wirebead::geometry::{Line, OnPlane};
use wirebead::prelude::*;
use wirebead::{BeadStruckBody, Restitution as BeadRestitution, SceneEnergy, SpaceBead, SpaceWire};

use super::avian3d::physics_app;

const G: f64 = 9.81;
const DT: f64 = 1.0 / 60.0;

/// A bead of `mass` and `radius` at `at` moving at `velocity` on a line
/// through `at` along `along` (a unit vector in the xy plane turned about
/// z), of restitution `e`.
fn bead_on_line(
    app: &mut App,
    (at, angle): (DVec3, f32),
    velocity: DVec3,
    (mass, radius, e): (f64, f64, f64),
) -> Entity {
    let place =
        Transform::from_translation(at.as_vec3()).with_rotation(Quat::from_rotation_z(angle));
    let wire = app
        .world_mut()
        .spawn((SpaceWire::curve(OnPlane(Line)), place))
        .id();
    let params = BeadParams {
        mass,
        initial_position: at,
        initial_velocity: velocity,
    };
    app.world_mut()
        .spawn((
            SpaceBead::new(params).expect("a bead"),
            OnWire(wire),
            BeadRadius::new(radius).expect("a radius"),
            BeadRestitution::new(e).expect("a restitution"),
        ))
        .id()
}

fn state(app: &App, bead: Entity) -> (DVec3, DVec3) {
    let world = app.world();
    assert!(world.get::<Diverged>(bead).is_none(), "the bead stopped");
    let x = world.get::<BeadPosition<DVec3>>(bead).expect("a bead").0;
    let v = world.get::<BeadVelocity<DVec3>>(bead).expect("a bead").0;
    (x, v)
}

/// The strikes sent this update.
fn strikes(app: &App) -> Vec<BeadStruckBody> {
    crate::common::sent(app)
}

/// The floor's top at y = 0, as a box, as a convex hull of the box's
/// corners and as a triangle mesh of its top: a bead of radius 5 cm
/// dropped from 1 m on a vertical line at (0.3, ·, 0.2) rises to
/// `e² h = 0.25 m` off each (restitution 0.5 each), striking again at
/// `e` times its first speed, and never sinks in.
#[test]
fn a_bead_dropped_on_a_box_a_hull_or_a_mesh_rises_to_e_squared_h() {
    let corners: Vec<Vector> = (0..8)
        .map(|k| {
            let pick = |bit: usize, lo: f32, hi: f32| if k & bit == 0 { lo } else { hi };
            Vector::new(pick(1, -2.0, 2.0), pick(2, -1.0, 0.0), pick(4, -2.0, 2.0))
        })
        .collect();
    let top = vec![
        Vector::new(-2.0, 0.0, -2.0),
        Vector::new(2.0, 0.0, -2.0),
        Vector::new(2.0, 0.0, 2.0),
        Vector::new(-2.0, 0.0, 2.0),
    ];
    let floors = [
        (
            "box",
            Collider::cuboid(4.0, 1.0, 4.0),
            Vector::new(0.0, -0.5, 0.0),
        ),
        (
            "hull",
            Collider::convex_hull(corners).expect("a hull"),
            Vector::ZERO,
        ),
        (
            "mesh",
            Collider::trimesh(top, vec![[0, 2, 1], [0, 3, 2]]),
            Vector::ZERO,
        ),
    ];
    for (name, shape, at) in floors {
        let mut app = physics_app(DT, DVec3::new(0.0, -G, 0.0));
        let r = 0.05;
        let start = DVec3::new(0.3, 1.0 + r, 0.2);
        let dropped = bead_on_line(&mut app, (start, FRAC_PI_2), DVec3::ZERO, (1.0, r, 0.5));
        app.world_mut().spawn((
            RigidBody::Static,
            shape,
            Position(at),
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
        println!(
            "{name}: {} strike(s), rose to {top:.9} m, lowest {lowest:e} m",
            struck.len()
        );
        let closing = (2.0 * G).sqrt();
        assert!(
            (struck[0].closing_speed - closing).abs() < 1e-6 * closing,
            "{name}"
        );
        let again = struck[1].closing_speed;
        assert!(
            (again - 0.5 * closing).abs() < 1e-6 * closing,
            "{name}: again at {again}"
        );
        assert!(
            (0.25 - 0.5 * G * DT * DT..=0.25 + 1e-6).contains(&top),
            "{name}: rose to {top}"
        );
        assert!(lowest >= -1e-6, "{name}: sank {lowest:e} m into the floor");
    }
}

/// A bead of 1 kg at 2 m/s along x strikes a free ball of 2 kg whose
/// centre lies 0.1 m off its line along z, no gravity, both of
/// restitution 1 and no friction: the ball leaves along the normal at the point struck
/// (through its centre, so that it does not turn), the bead keeps only
/// what its line lets it, and the momentum along the line and the
/// kinetic energy are kept (the line's force does no work), to `f32`
/// rounding.
#[test]
fn a_bead_striking_a_ball_off_its_line_sends_it_along_the_normal() {
    let mut app = physics_app(DT, DVec3::ZERO);
    let (u, m, mass, radius) = (2.0, 1.0, 2.0, 0.3);
    let start = DVec3::new(-1.0, 0.0, 0.0);
    let moving = bead_on_line(
        &mut app,
        (start, 0.0),
        DVec3::new(u, 0.0, 0.0),
        (m, 0.05, 1.0),
    );
    let centre = DVec3::new(0.5, 0.0, 0.1);
    let ball = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Collider::sphere(radius as f32),
            Mass(mass as f32),
            Position(centre.as_vec3()),
            Restitution::new(1.0),
            Friction::new(0.0),
            SleepingDisabled,
        ))
        .id();
    app.init_resource::<SceneEnergy>();
    let (mut impulse, mut off) = (0.0, 0.0_f64);
    for _ in 0..60 {
        app.update();
        impulse += strikes(&app).iter().map(|s| s.impulse).sum::<f64>();
        let total = app.world().resource::<SceneEnergy>().total;
        off = off.max((total - 0.5 * m * u * u).abs());
    }
    let (_, v) = state(&app, moving);
    let world = app.world();
    let w = world
        .get::<LinearVelocity>(ball)
        .expect("a ball")
        .0
        .as_dvec3();
    let spin = world
        .get::<AngularVelocity>(ball)
        .expect("a ball")
        .0
        .as_dvec3();
    let energy = 0.5 * m * v.length_squared() + 0.5 * mass * w.length_squared();
    println!("impulse {impulse}, bead {v}, ball {w} turning {spin}, energy {energy}");
    // Where they met: the bead's centre at x with (x, 0, 0) 0.35 m from
    // the ball's; the normal from there to the ball's centre.
    let x = centre.x - (0.35_f64.powi(2) - 0.1_f64.powi(2)).sqrt();
    let normal = (centre - DVec3::new(x, 0.0, 0.0)).normalize();
    assert!(
        (w.normalize() - normal).length() < 1e-5,
        "the ball leaves along {w}, not {normal}"
    );
    assert!(
        (mass * w.length() - impulse).abs() < 1e-5,
        "the ball took {w} for {impulse} N s"
    );
    // What avian's `f32` point of contact leaves of the lever arm.
    assert!(spin.length() < 1e-5, "turning at {spin}");
    assert!(
        (m * v.x + mass * w.x - m * u).abs() < 1e-5,
        "momentum along the line"
    );
    assert!((energy - 0.5 * m * u * u).abs() < 1e-5, "energy {energy}");
    // The scene's energy counts the ball's.
    assert!(off < 1e-5, "the scene's energy moved by {off:e} J");
}
