//! Beads in space through the plugin: `SpaceBead`s on `SpaceWire`s, joined
//! by rods and pins, stepped in islands and written to their `Transform`s.

use std::f64::consts::TAU;

use bevy::math::DVec3;
use bevy::prelude::*;
use wirebead::geometry::{Circle, Helix, OnPlane, Pose3, SpaceMotion, SpacePath, Sphere};
use wirebead::headless::{Headless, run_for, space_bead_state};
use wirebead::prelude::*;
use wirebead::{
    BeadMass, ConstraintDiagnostics, Islands, NextBeadParams, PrescribedMotion, SceneEnergy,
    SpaceBead, SpaceWire,
};

use crate::space::conical_start;

const G: f64 = 9.81;

/// A headless app stepping with RATTLE at `dt`.
fn app(dt: f64) -> App {
    let params = SimParams {
        timestep: dt,
        method: Method::Rattle,
        ..default()
    };
    Headless::new(WireBeadPlugin::new(params).expect("valid parameters"))
        .single_threaded()
        .build()
}

/// A bead in space of mass 1 at `position` moving at `velocity`, on
/// `wire` if there is one.
fn spawn(app: &mut App, wire: Option<Entity>, position: DVec3, velocity: DVec3) -> Entity {
    let bead = SpaceBead::new(BeadParams {
        mass: 1.0,
        initial_position: position,
        initial_velocity: velocity,
    })
    .expect("a valid bead");
    let mut bead = app.world_mut().spawn(bead);
    if let Some(wire) = wire {
        bead.insert(OnWire(wire));
    }
    bead.id()
}

/// A conical pendulum inside a sphere of radius 1.2 m, 40° from the
/// downward vertical: the bead, the radius and the bead's start.
fn conical_in_sphere(app: &mut App) -> (Entity, f64, wirebead::solver::BeadState<DVec3>) {
    let (r, alpha) = (1.2, 40f64.to_radians());
    let wire = app
        .world_mut()
        .spawn(SpaceWire::surface_of(Sphere { radius: r }))
        .id();
    let (start, _) = conical_start(r, alpha);
    (
        spawn(app, Some(wire), start.position, start.velocity),
        r,
        start,
    )
}

/// The conical pendulum inside a sphere of radius 1.2 m, 40° from the
/// downward vertical, through the plugin (RATTLE at 1 ms, 3 s): its height
/// stays within 1e-5 r, it stays on the sphere to 1e-12, its `Transform`
/// is its position in `f32`, and, alone on a surface, it takes a step of
/// its own, in no island.
#[test]
fn a_conical_pendulum_on_a_sphere_steps_through_the_plugin() {
    let mut app = app(1e-3);
    let (bead, r, start) = conical_in_sphere(&mut app);
    let mut worst = (0.0f64, 0.0f64);
    for _ in 0..30 {
        run_for(&mut app, 0.1);
        let state = space_bead_state(app.world(), bead).expect("a bead in space");
        worst.0 = worst.0.max((state.position.y - start.position.y).abs());
        worst.1 = worst.1.max((state.position.length() - r).abs());
        let transform = app.world().get::<Transform>(bead).expect("a transform");
        assert_eq!(transform.translation, state.position.as_vec3());
    }
    assert!(worst.0 <= 1e-5 * r, "the height moved {:e}", worst.0);
    assert!(worst.1 <= 1e-12, "left the sphere by {:e}", worst.1);
    let islands = app.world().resource::<Islands<DVec3>>();
    assert!(islands.of(bead).is_none(), "a bead alone on a surface");
}

/// A bead from rest on a helix wire (its two rows) through the plugin,
/// RATTLE at 1 ms for 3 s: `y(t) = −½ g sin²φ t²`, `tan φ = p/(2πr)`,
/// within 1e-5 relative, and on the helix to 1e-12.
#[test]
fn a_bead_slides_down_a_helix_wire() {
    let (radius, pitch) = (0.8, 0.5);
    let mut app = app(1e-3);
    let wire = app
        .world_mut()
        .spawn(SpaceWire::curve(Helix { radius, pitch }))
        .id();
    let bead = spawn(
        &mut app,
        Some(wire),
        DVec3::new(radius, 0.0, 0.0),
        DVec3::ZERO,
    );
    run_for(&mut app, 3.0);
    let p = space_bead_state(app.world(), bead)
        .expect("a bead")
        .position;
    let slope = (pitch / (TAU * radius)).atan();
    let exact = -0.5 * G * slope.sin().powi(2) * 9.0;
    assert!(
        ((p.y - exact) / exact).abs() <= 1e-5,
        "y = {} against {exact}",
        p.y
    );
    let [a, b] = wirebead::geometry::SpaceCurve::rows(&Helix { radius, pitch }, p, f64::NAN);
    assert!(
        a.c.hypot(b.c) <= 1e-12,
        "off the helix by {:e}",
        a.c.hypot(b.c)
    );
    let islands = app.world().resource::<Islands<DVec3>>();
    assert_eq!(islands.of(bead).map(|r| r.rows), Some(2));
}

/// A rope of five beads in space hanging from a pin by rods of 0.3 m,
/// started swinging out of every plane: RATTLE at 1 ms for 2 s holds every
/// rod and the pin to 1e-9 and keeps the island's energy to 1e-4 of its
/// drop, `m g` times the rope's length.
#[test]
fn a_rope_in_space_hangs_from_a_pin() {
    let mut app = app(1e-3);
    let link = 0.3;
    let beads: Vec<Entity> = (0..5)
        .map(|i| {
            let k = i as f64;
            let at = DVec3::new(0.2 * k * link, -0.9 * k * link, 0.2 * k * link)
                .normalize_or_zero()
                * (k * link);
            spawn(&mut app, None, at, DVec3::new(0.0, 0.0, 0.4 * k))
        })
        .collect();
    let world = app.world_mut();
    let mut links = vec![
        world
            .spawn(Pin::new(beads[0], DVec3::ZERO).expect("a pin"))
            .id(),
    ];
    for pair in beads.windows(2) {
        let rod = Rod::new(pair[0], pair[1], link).expect("a rod");
        links.push(world.spawn(rod).id());
    }
    run_for(&mut app, 0.001);
    let energy = |app: &App| {
        app.world()
            .resource::<Islands<DVec3>>()
            .of(beads[0])
            .expect("one island")
            .energy
    };
    let e0 = energy(&app);
    let (mut held, mut drift) = (0.0f64, 0.0f64);
    for _ in 0..20 {
        run_for(&mut app, 0.1);
        for &link in &links {
            let c = app
                .world()
                .get::<ConstraintDiagnostics>(link)
                .expect("a link");
            held = held.max(c.c.abs());
        }
        drift = drift.max((energy(&app) - e0).abs());
    }
    assert!(held <= 1e-9, "a link drifted {held:e}");
    assert!(
        drift <= 1e-4 * 5.0 * G * 4.0 * link,
        "the energy moved {drift:e}"
    );
    let report = app
        .world()
        .resource::<Islands<DVec3>>()
        .of(beads[0])
        .cloned();
    assert_eq!(report.map(|r| (r.beads.len(), r.rows)), Some((5, 7)));
}

/// Runs `app` for `tenths` tenths of a second, handing `look` the app, the
/// time and `bead`'s position after each.
fn every_tenth(app: &mut App, bead: Entity, tenths: usize, mut look: impl FnMut(&App, f64, DVec3)) {
    for _ in 0..tenths {
        run_for(app, 0.1);
        let t = app.world().resource::<wirebead::SimClock>().time;
        let p = space_bead_state(app.world(), bead)
            .expect("a bead")
            .position;
        look(app, t, p);
    }
}

/// A vertical hoop of radius `r` spinning at `omega` about the y-axis,
/// and its spin.
fn spinning_hoop(app: &mut App, r: f64, omega: f64) -> (Entity, SpaceMotion) {
    let spin = SpaceMotion::Spin {
        angular_velocity: omega,
        axis: DVec3::Y,
    };
    let wire = app
        .world_mut()
        .spawn((
            SpaceWire::curve(OnPlane(Circle { radius: r })),
            PrescribedMotion::in_space(spin).expect("a spin"),
        ))
        .id();
    (wire, spin)
}

/// The rotating hoop through the plugin: a hoop of radius 1 spinning at
/// 6 rad/s about its vertical diameter (`PrescribedMotion::in_space`), a
/// bead released at relative rest at `cos θ* = g/(ω² r)` stays there to
/// 1e-6 rad over 2 s (RATTLE at 0.5 ms), and the plugin turns the wire's
/// `Transform` with it.
#[test]
fn a_bead_on_a_spinning_hoop_wire_stays_at_its_equilibrium() {
    let (r, omega) = (1.0, 6.0);
    let mut app = app(5e-4);
    let (wire, spin) = spinning_hoop(&mut app, r, omega);
    let star = (G / (omega * omega * r)).acos();
    let local = DVec3::new(r * star.sin(), -r * star.cos(), 0.0);
    let path = SpacePath::Prescribed {
        base: Pose3::IDENTITY,
        motion: spin,
    };
    let velocity = path.at(0.0).1.velocity_at(local);
    let bead = spawn(&mut app, Some(wire), local, velocity);
    let mut worst = 0.0f64;
    every_tenth(&mut app, bead, 20, |app, t, p| {
        let local = path.at(t).0.to_local(p);
        worst = worst.max((local.x.atan2(-local.y) - star).abs());
        let turned = app.world().get::<Transform>(wire).expect("a wire").rotation;
        let expected = Quat::from_axis_angle(Vec3::Y, (omega * t) as f32);
        assert!(
            turned.dot(expected).abs() > 1.0 - 1e-6,
            "the hoop is at {turned} at t = {t}, not {expected}"
        );
    });
    assert!(worst <= 1e-6, "θ* = {star} wandered by {worst:e}");
}

/// `Restart` returns beads in space to their `BeadParams` and wires on a
/// prescribed motion to their resting pose: a bead on the spinning hoop
/// run 0.5 s, restarted and run 0.5 s again ends bit for bit where it
/// ended the first time, and right after the restart it is where it
/// started, at rest relative to the hoop.
#[test]
fn a_restart_returns_beads_in_space_to_their_start() {
    let (r, omega) = (1.0, 4.0);
    let mut app = app(1e-3);
    let (wire, spin) = spinning_hoop(&mut app, r, omega);
    let start = DVec3::new(r * 0.5f64.sin(), -r * 0.5f64.cos(), 0.0);
    let relative_rest = spin.at(Pose3::IDENTITY, 0.0).1.velocity_at(start);
    let bead = spawn(&mut app, Some(wire), start, relative_rest);
    // The velocity a bead in space restarts with is relative to its wire.
    app.world_mut()
        .entity_mut(bead)
        .insert(BeadParams::<DVec3> {
            mass: 1.0,
            initial_position: start,
            initial_velocity: DVec3::ZERO,
        });
    run_for(&mut app, 0.5);
    let first = space_bead_state(app.world(), bead).expect("a bead");
    assert!((first.position - start).length() > 1e-2, "it did not move");
    app.world_mut().write_message(Restart);
    wirebead::headless::idle(&mut app);
    let restarted = space_bead_state(app.world(), bead).expect("a bead");
    assert_eq!(restarted.position, start);
    assert_eq!(restarted.velocity, relative_rest);
    let rotation = app.world().get::<Transform>(wire).expect("a wire").rotation;
    assert_eq!(rotation, Quat::IDENTITY);
    run_for(&mut app, 0.5);
    let again = space_bead_state(app.world(), bead).expect("a bead");
    assert_eq!(
        (again.position, again.velocity),
        (first.position, first.velocity)
    );
}

/// An edit of a bead in space waits for the restart, as in the plane: a
/// `NextBeadParams<DVec3>` changes nothing while the run goes on; the
/// restart applies its mass and start (the velocity relative to the
/// spinning hoop), removes it, and keeps it as the bead's `BeadParams`.
#[test]
fn a_restart_applies_an_edit_of_a_bead_in_space() {
    let (r, omega) = (1.0, 4.0);
    let mut app = app(1e-3);
    let (wire, spin) = spinning_hoop(&mut app, r, omega);
    let start = DVec3::new(0.0, -r, 0.0);
    let bead = spawn(&mut app, Some(wire), start, DVec3::ZERO);
    run_for(&mut app, 0.1);
    let edited = BeadParams::<DVec3> {
        mass: 2.5,
        initial_position: DVec3::new(r * 0.6, -r * 0.8, 0.0),
        // Along the hoop's tangent there.
        initial_velocity: DVec3::new(0.4, 0.3, 0.0),
    };
    app.world_mut()
        .entity_mut(bead)
        .insert(NextBeadParams::in_space(edited).expect("a valid edit"));
    let before = space_bead_state(app.world(), bead).expect("a bead");
    wirebead::headless::idle(&mut app);
    let pending = space_bead_state(app.world(), bead).expect("a bead");
    assert_eq!(pending, before, "an edit moved the bead before the restart");
    assert_eq!(
        app.world().get::<BeadMass>(bead).map(BeadMass::get),
        Some(1.0)
    );

    app.world_mut().write_message(Restart);
    wirebead::headless::idle(&mut app);
    let restarted = space_bead_state(app.world(), bead).expect("a bead");
    let hoop_velocity = spin
        .at(Pose3::IDENTITY, 0.0)
        .1
        .velocity_at(edited.initial_position);
    assert_eq!(restarted.position, edited.initial_position);
    assert_eq!(restarted.velocity, edited.initial_velocity + hoop_velocity);
    assert_eq!(
        app.world().get::<BeadMass>(bead).map(BeadMass::get),
        Some(2.5)
    );
    assert_eq!(app.world().get::<BeadParams<DVec3>>(bead), Some(&edited));
    assert!(app.world().get::<NextBeadParams<DVec3>>(bead).is_none());
}

/// A bead in space at a singular point of its wire (a sphere's centre)
/// and one whose position a game made not finite are stopped and marked
/// `Diverged` with their reasons, their `Transform`s never written with a
/// NaN; a rod between a bead in the plane and one in space is left out
/// and both go on stepping.
#[test]
fn bad_beads_in_space_are_stopped_and_mixed_rods_left_out() {
    let mut app = app(1e-3);
    let sphere = app
        .world_mut()
        .spawn(SpaceWire::surface_of(Sphere { radius: 1.0 }))
        .id();
    let centre = spawn(&mut app, Some(sphere), DVec3::ZERO, DVec3::X);
    let lost = spawn(&mut app, None, DVec3::new(0.0, -3.0, 0.0), DVec3::ZERO);
    app.world_mut()
        .entity_mut(lost)
        .insert(BeadPosition(DVec3::new(f64::NAN, 0.0, 0.0)));
    let free = spawn(&mut app, None, DVec3::new(0.0, 5.0, 0.0), DVec3::ZERO);
    let flat = app
        .world_mut()
        .spawn(Bead::at_rest(1.0, bevy::math::DVec2::new(0.0, 5.0)).expect("a bead"))
        .id();
    app.world_mut()
        .spawn(Rod::new(free, flat, 1.0).expect("a rod"));
    run_for(&mut app, 0.1);
    let world = app.world();
    let reason = |bead| world.get::<Diverged>(bead).map(|d| d.reason.to_string());
    assert!(
        reason(centre).is_some_and(|r| r.contains("singular")),
        "{:?}",
        reason(centre)
    );
    assert!(
        reason(lost).is_some_and(|r| r.contains("finite")),
        "{:?}",
        reason(lost)
    );
    for bead in [centre, lost] {
        let t = world.get::<Transform>(bead).expect("a transform");
        assert!(t.translation.is_finite());
    }
    // Free fall for 0.1 s, in space and in the plane, the rod left out.
    let fallen = space_bead_state(world, free).expect("a bead").position.y;
    let expected = 5.0 - 0.5 * G * 0.01;
    assert!((fallen - expected).abs() < 1e-9, "fell to {fallen}");
    let flat_y = wirebead::headless::bead_state(world, flat)
        .expect("a bead")
        .position
        .y;
    assert!((flat_y - expected).abs() < 1e-9, "fell to {flat_y}");
    assert!(world.get::<Diverged>(free).is_none() && world.get::<Diverged>(flat).is_none());
}

/// Sixty beads in space (on spheres, on helices and free), stepped with
/// the islands and the lone beads split over threads and on one thread,
/// end bit for bit the same after 0.5 s: on one thread the beads on the
/// sphere take the batched step eight at a time, split over threads one
/// by one.
#[test]
fn beads_in_space_step_the_same_in_parallel_and_in_sequence() {
    let run = |parallel: wirebead::ParallelStep| {
        let params = SimParams {
            timestep: 1e-3,
            method: Method::Rattle,
            ..default()
        };
        let mut app = Headless::new(WireBeadPlugin::new(params).expect("valid parameters"))
            .parallel(parallel)
            .build();
        let sphere = app
            .world_mut()
            .spawn(SpaceWire::surface_of(Sphere { radius: 1.0 }))
            .id();
        let helix = app
            .world_mut()
            .spawn(SpaceWire::curve(Helix {
                radius: 1.0,
                pitch: 0.7,
            }))
            .id();
        let beads: Vec<Entity> = (0..60)
            .map(|i| {
                let a = 0.1 * i as f64;
                let on = [Some(sphere), Some(helix), None][i % 3];
                let at = match i % 3 {
                    0 => DVec3::new(a.sin() * 0.6, -0.8, a.cos() * 0.6),
                    1 => DVec3::new(a.cos(), 0.7 * a / std::f64::consts::TAU, a.sin()),
                    _ => DVec3::new(a, 0.0, -a),
                };
                spawn(&mut app, on, at, DVec3::new(0.3, 0.0, 0.2 * a))
            })
            .collect();
        run_for(&mut app, 0.5);
        beads
            .iter()
            .map(|&b| {
                let s = space_bead_state(app.world(), b).expect("a bead");
                (s.position, s.velocity)
            })
            .collect::<Vec<_>>()
    };
    let parallel = run(wirebead::ParallelStep { threshold: 1 });
    let sequential = run(wirebead::ParallelStep::OFF);
    assert_eq!(parallel, sequential);
}

/// Friction and damping on curves in space act along the curve's one
/// tangent, the two rows pressing as one: a bead sent round a horizontal
/// hoop with damping 0.8 N·s/m and no gravity along it slows as
/// `v₀ e^{−c t / m}` (within 1e-3 over 2 s, not twice as fast); on a rough
/// helix (μs = 0.5, μk = 0.3) a bead at rest stays put where the slope's
/// tangent 0.32 is below μs (after its first step, to 1e-9 over 1 s); and
/// down a rough straight incline in space at 0.80, sliding, it speeds up
/// at `g (sin φ − μk cos φ)` to 1e-6 (the incline's turn is an `f32`
/// rotation).
#[test]
fn friction_and_damping_act_along_a_curve_in_space() {
    use wirebead::Surface;
    use wirebead::geometry::Friction;
    // Damping round a horizontal hoop.
    let (c, v0, r) = (0.8, 2.0, 1.0);
    let mut damped = app(1e-3);
    let wire = SpaceWire::curve(OnPlane(Circle { radius: r }))
        .with_surface(Surface {
            damping: c,
            ..Surface::PLAIN
        })
        .expect("a damped hoop");
    let flat = Transform::from_rotation(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2));
    let hoop = damped.world_mut().spawn((wire, flat)).id();
    // On the hoop in the xz-plane, moving along it.
    let at = DVec3::new(r, 0.0, 0.0);
    let bead = spawn(&mut damped, Some(hoop), at, DVec3::new(0.0, 0.0, v0));
    run_for(&mut damped, 2.0);
    let speed = space_bead_state(damped.world(), bead)
        .expect("a bead")
        .velocity
        .length();
    let expected = v0 * (-c * 2.0f64).exp();
    assert!(
        ((speed - expected) / expected).abs() <= 1e-3,
        "{speed} m/s, against {expected}"
    );
    // Static and kinetic friction on helices.
    let rough = Surface {
        friction: Friction::new(0.5, 0.3).expect("friction"),
        ..Surface::PLAIN
    };
    let on_helix = |pitch: f64, duration: f64| {
        let mut app = app(1e-3);
        let wire = SpaceWire::curve(Helix { radius: 1.0, pitch })
            .with_surface(rough)
            .expect("a rough helix");
        let helix = app.world_mut().spawn(wire).id();
        let bead = spawn(
            &mut app,
            Some(helix),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::ZERO,
        );
        run_for(&mut app, duration);
        space_bead_state(app.world(), bead)
            .expect("a bead")
            .position
    };
    // Static friction takes hold at the end of the first step, when the
    // bead's sliding velocity is first not zero: it creeps that step only.
    let (early, late) = (on_helix(2.0, 0.05), on_helix(2.0, 1.0));
    assert!(
        (late - early).length() <= 1e-9,
        "slid from {early} to {late}"
    );
    assert!(
        (late - DVec3::new(1.0, 0.0, 0.0)).length() <= 1e-5,
        "at {late}"
    );
    // Kinetic friction down a rough straight incline at tan φ = 0.80 in
    // space: once sliding, it speeds up at exactly g (sin φ − μk cos φ).
    let slope = (5.0f64 / TAU).atan();
    let mut incline = app(1e-3);
    let wire = SpaceWire::curve(OnPlane(wirebead::geometry::Line))
        .with_surface(rough)
        .expect("a rough incline");
    let tilt = Transform::from_rotation(Quat::from_rotation_z(-(slope as f32)));
    let line = incline.world_mut().spawn((wire, tilt)).id();
    let bead = spawn(&mut incline, Some(line), DVec3::ZERO, DVec3::ZERO);
    let speed = |app: &App| {
        space_bead_state(app.world(), bead)
            .expect("a bead")
            .velocity
            .length()
    };
    run_for(&mut incline, 0.05);
    let v0 = speed(&incline);
    run_for(&mut incline, 0.1);
    let measured = (speed(&incline) - v0) / 0.1;
    let expected = G * (slope.sin() - 0.3 * slope.cos());
    assert!(
        ((measured - expected) / expected).abs() <= 1e-6,
        "sped up at {measured} m/s², against {expected}"
    );
}

/// A cart on a banked circular track (a hoop of 2 m tilted 20° from
/// level) with `RailOrientation` up `+y`: over 3 s its up axis stays the
/// track's normal (the tilted plane's) to 1e-9 in `f64` and to `f32` in
/// its `Transform`, and its forward runs along the track. On a vertical
/// loop the same cart's up points to the loop's centre, upside down at
/// the top.
#[test]
fn a_cart_turns_with_its_track() {
    use wirebead::RailOrientation;
    let tilt = 20f64.to_radians();
    let mut banked = app(1e-3);
    // The circle's local xy-plane turned to lie 20° from level.
    let bank = Quat::from_rotation_x((-std::f64::consts::FRAC_PI_2 + tilt) as f32);
    let track = banked
        .world_mut()
        .spawn((
            SpaceWire::curve(OnPlane(Circle { radius: 2.0 })),
            Transform::from_rotation(bank),
        ))
        .id();
    // The track as the plugin reads it: the Transform's turn in f64.
    let turn = bank.as_dquat().normalize();
    let plane_normal = turn * DVec3::Z;
    let start = turn * DVec3::new(2.0, 0.0, 0.0);
    let along = turn * DVec3::new(0.0, 3.0, 0.0);
    let cart = spawn(&mut banked, Some(track), start, along);
    banked
        .world_mut()
        .entity_mut(cart)
        .insert(RailOrientation::new(DVec3::Y).expect("an up"));
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..30 {
        run_for(&mut banked, 0.1);
        let world = banked.world();
        let rail = world.get::<RailOrientation>(cart).expect("a rail");
        let up = rail.rotation() * DVec3::Y;
        worst.0 = worst.0.max((up - plane_normal).length());
        let velocity = space_bead_state(world, cart).expect("a cart").velocity;
        let forward = rail.rotation() * DVec3::NEG_Z;
        worst.1 = worst.1.max(forward.cross(velocity.normalize()).length());
        let transform = world.get::<Transform>(cart).expect("a transform");
        let up32 = (transform.rotation * Vec3::Y).as_dvec3();
        worst.2 = worst.2.max((up32 - plane_normal).length());
    }
    assert!(
        worst.0 <= 1e-9,
        "its up left the track's normal by {:e}",
        worst.0
    );
    assert!(
        worst.1 <= 1e-9,
        "its forward left the track by {:e}",
        worst.1
    );
    assert!(worst.2 <= 1e-6, "its Transform's up is {:e} off", worst.2);

    // Through a vertical loop, from the bottom: upside down at the top.
    let mut looping = app(1e-3);
    let lap = looping
        .world_mut()
        .spawn(SpaceWire::curve(OnPlane(Circle { radius: 1.0 })))
        .id();
    let fast = (5.0 * G).sqrt() + 1.0;
    let cart = spawn(
        &mut looping,
        Some(lap),
        DVec3::new(0.0, -1.0, 0.0),
        DVec3::new(fast, 0.0, 0.0),
    );
    looping
        .world_mut()
        .entity_mut(cart)
        .insert(RailOrientation::new(DVec3::Y).expect("an up"));
    let mut upside_down = false;
    for _ in 0..200 {
        run_for(&mut looping, 0.005);
        let world = looping.world();
        let p = space_bead_state(world, cart).expect("a cart").position;
        let up = world
            .get::<RailOrientation>(cart)
            .expect("a rail")
            .rotation()
            * DVec3::Y;
        assert!(
            (up + p).length() <= 1e-9,
            "its up {up} is not toward the centre from {p}"
        );
        upside_down |= up.y < -0.999;
    }
    assert!(upside_down, "it never went over the top");
}

/// A bead in space sliding off the top of a one-sided sphere through the
/// plugin (its island's row pushes only outward): it leaves where
/// `cos θ = ⅔ cos θ₀`, within 1e-3 (an island finds the step it leaves
/// in, 4.3e-4 here; the lone step of the plane finds the moment, to
/// 1e-6), a `ContactChanged<DVec3>` says so and its `WireContact` reads in
/// flight.
#[test]
fn a_bead_leaves_a_one_sided_sphere_in_space_through_the_plugin() {
    use wirebead::solver::ContactEvent;
    use wirebead::{ContactChanged, Side, Surface, WireContact};
    let r = 2.0;
    let mut app = app(1e-3);
    let wire = SpaceWire::surface_of(Sphere { radius: r })
        .with_surface(Surface {
            side: Side::Positive,
            ..Surface::PLAIN
        })
        .expect("a one-sided sphere");
    let sphere = app.world_mut().spawn(wire).id();
    let theta0 = 2f64.to_radians();
    let across = DVec3::new(1.0, 0.0, -1.0).normalize();
    let start = r * (theta0.cos() * DVec3::Y + theta0.sin() * across);
    let bead = spawn(&mut app, Some(sphere), start, DVec3::ZERO);
    let mut left = None;
    for _ in 0..300 {
        run_for(&mut app, 0.01);
        let changes = app.world().resource::<Messages<ContactChanged<DVec3>>>();
        for change in changes.iter_current_update_messages() {
            if let ContactEvent::Left { position, .. } = change.event {
                left.get_or_insert(position);
            }
        }
        if left.is_some() {
            break;
        }
    }
    let at = left.expect("the bead left the sphere");
    let expected = 2.0 / 3.0 * theta0.cos();
    let cos_theta = at.y / at.length();
    assert!(
        (cos_theta - expected).abs() <= 1e-3,
        "left at cos θ = {cos_theta}, against {expected}"
    );
    let contact = app.world().get::<WireContact>(bead).expect("a contact");
    assert!(!contact.is_on(), "its contact still reads on the sphere");
}

/// The game turns a hoop by writing its `Transform` each step (about the
/// vertical, at 4 rad/s): the hoop is followed from its last poses and its
/// bead's trajectory is the prescribed spin's. A steady turn is a straight
/// line in the turn's rotation vector, which the history's quadratic
/// holds exactly, so after 2 s the two are apart by the `Transform`'s
/// `f32` alone: less than 1e-6 at 1/100 s and at 1/200 s.
#[test]
fn a_hoop_the_game_turns_gives_the_prescribed_spins_trajectory() {
    const OMEGA: f64 = 4.0;
    fn turn_hoop(
        clock: Res<wirebead::SimClock>,
        params: Res<SimParams>,
        mut wires: Query<&mut Transform, With<SpaceWire>>,
    ) {
        let t = clock.time + params.timestep;
        for mut transform in &mut wires {
            transform.rotation = Quat::from_axis_angle(Vec3::Y, (OMEGA * t) as f32);
        }
    }
    let spun = |dt: f64, by_game: bool| {
        let mut app = app(dt);
        let (wire, spin) = spinning_hoop(&mut app, 1.0, OMEGA);
        if by_game {
            app.world_mut()
                .entity_mut(wire)
                .remove::<PrescribedMotion<DVec3>>();
            app.add_systems(FixedUpdate, turn_hoop.before(WireBeadSystems::Prepare));
        }
        let start = DVec3::new(0.5, -0.75f64.sqrt(), 0.0);
        let velocity = spin.at(Pose3::IDENTITY, 0.0).1.velocity_at(start);
        let bead = spawn(&mut app, Some(wire), start, velocity);
        run_for(&mut app, 2.0);
        assert!(app.world().get::<Diverged>(bead).is_none());
        space_bead_state(app.world(), bead)
            .expect("a bead")
            .position
    };
    for dt in [1.0 / 100.0, 1.0 / 200.0] {
        let gap = (spun(dt, true) - spun(dt, false)).length();
        assert!(gap < 1e-6, "the trajectories part by {gap:e} at {dt} s");
    }
}

/// A level plane in space oscillating along the 3D amplitude
/// (0.3, 0.2, −0.1) m at 1.5 Hz (`PrescribedMotion::in_space`), a bead on
/// it started at rest relative to it: the plane pushes only along its
/// normal, so over 2 s the bead's height is the plane's, `0.2 sin 2πft`,
/// and across the plane it keeps the velocity it started with, each to
/// 1e-9.
#[test]
fn a_bead_rides_a_plane_oscillating_in_space() {
    use wirebead::geometry::{Oscillate, Plane};
    let amplitude = DVec3::new(0.3, 0.2, -0.1);
    let frequency = 1.5;
    let shake = SpaceMotion::Oscillate(Oscillate {
        amplitude,
        frequency,
    });
    let mut app = app(1e-3);
    let wire = app
        .world_mut()
        .spawn((
            SpaceWire::surface_of(Plane),
            PrescribedMotion::in_space(shake).expect("a shake"),
        ))
        .id();
    let start = DVec3::new(0.5, 0.0, -0.25);
    let velocity = shake.at(Pose3::IDENTITY, 0.0).1.velocity_at(start);
    let bead = spawn(&mut app, Some(wire), start, velocity);
    let mut worst = 0.0f64;
    every_tenth(&mut app, bead, 20, |_, t, p| {
        let height = amplitude.y * (TAU * frequency * t).sin();
        let across = start + DVec3::new(velocity.x, 0.0, velocity.z) * t;
        worst = worst
            .max((p.y - height).abs())
            .max((p.x - across.x).abs())
            .max((p.z - across.z).abs());
    });
    assert!(worst <= 1e-9, "off the plane's motion by {worst:e}");
}

/// The scene's energy ([`SceneEnergy`], which the panel plots) counts a
/// bead in space stepped alone on its surface, in no island: a conical
/// pendulum in a sphere, RATTLE at 1 ms for a second, has the scene's
/// energy its own `½ m |v|² + m g y` to 1e-12 at every tenth of a second,
/// and keeps it within 1e-6 J of its start.
#[test]
fn the_scene_energy_counts_a_bead_alone_on_a_surface() {
    let mut app = app(1e-3);
    app.init_resource::<SceneEnergy>();
    let (bead, ..) = conical_in_sphere(&mut app);
    let own = |app: &App| {
        let s = space_bead_state(app.world(), bead).expect("a bead in space");
        0.5 * s.velocity.length_squared() + G * s.position.y
    };
    let first = own(&app);
    for _ in 0..10 {
        run_for(&mut app, 0.1);
        let scene = app.world().resource::<SceneEnergy>().total;
        assert!(
            (scene - own(&app)).abs() <= 1e-12,
            "{scene} against {}",
            own(&app)
        );
        assert!(
            (scene - first).abs() <= 1e-6,
            "{scene} against {first} at the start"
        );
    }
}
