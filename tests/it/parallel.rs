//! The parallel step gives bit-for-bit the sequential step's result, and
//! reports the same divergences; so do lean beads.

use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::headless::{Headless, run_steps};
use wirebead::plugin::StepSplit;
use wirebead::prelude::*;
use wirebead::{ParallelStep, SimClock};

use crate::common::bead;

const BEADS_PER_WIRE: usize = 1500;

/// Four wires of different shapes, moved and rotated, 1,500 beads on each
/// spread along it with different speeds, plus beads at the circle's centre
/// (a singular point). Returns the app and the beads in spawn order.
fn scene(parallel: ParallelStep, plugin: WireBeadPlugin) -> (App, Vec<Entity>) {
    let mut app = Headless::new(plugin).parallel(parallel).build();
    let wires = [
        (Wire::circle(1.0).unwrap(), Transform::default()),
        (
            Wire::ellipse(2.0, 1.0).unwrap(),
            Transform::from_xyz(5.0, 1.0, 0.0).with_rotation(Quat::from_rotation_z(0.4)),
        ),
        (
            Wire::sine(0.5, 3.0).unwrap(),
            Transform::from_xyz(-4.0, -2.0, 0.0),
        ),
        (
            Wire::parabola(0.8).unwrap(),
            Transform::from_xyz(0.0, 6.0, 0.0).with_rotation(Quat::from_rotation_z(-0.3)),
        ),
    ];
    let mut beads = Vec::new();
    for (w, (wire, transform)) in wires.into_iter().enumerate() {
        let local_points: Vec<DVec2> = (0..BEADS_PER_WIRE)
            .map(|i| {
                let s = i as f64 / BEADS_PER_WIRE as f64;
                match w {
                    0 | 1 => {
                        let a = std::f64::consts::TAU * s;
                        let (rx, ry) = if w == 0 { (1.0, 1.0) } else { (2.0, 1.0) };
                        DVec2::new(rx * a.cos(), ry * a.sin())
                    }
                    2 => {
                        let x = 6.0 * s - 3.0;
                        DVec2::new(x, 0.5 * (std::f64::consts::TAU * x / 3.0).sin())
                    }
                    _ => {
                        let x = 4.0 * s - 2.0;
                        DVec2::new(x, x * x / 3.2)
                    }
                }
            })
            .collect();
        let origin = DVec2::new(
            transform.translation.x.into(),
            transform.translation.y.into(),
        );
        let angle = f64::from(transform.rotation.to_euler(EulerRot::XYZ).2);
        let pose = wirebead::geometry::Pose::new(origin, angle);
        let wire = app.world_mut().spawn((wire, transform)).id();
        for (i, p) in local_points.into_iter().enumerate() {
            let speed = (i % 7) as f64 - 3.0;
            let params = BeadParams {
                mass: 0.5 + (i % 3) as f64,
                initial_position: pose.to_world(p),
                initial_velocity: DVec2::new(speed, 0.5 * speed),
            };
            beads.push(
                app.world_mut()
                    .spawn((Bead::new(params).unwrap(), OnWire(wire)))
                    .id(),
            );
        }
        if w == 0 {
            for _ in 0..3 {
                let at_centre = Bead::at_rest(1.0, DVec2::ZERO).unwrap();
                beads.push(app.world_mut().spawn((at_centre, OnWire(wire))).id());
            }
        }
    }
    (app, beads)
}

const STEPS: u32 = 300;

fn run(apps: [&mut App; 2]) {
    for app in apps {
        run_steps(app, STEPS);
    }
}

/// Asserts that every bead of `b` has bit for bit the state of its twin in
/// `a`, and the same divergence; returns how many diverged.
fn assert_same_beads(a: (&App, &[Entity]), b: (&App, &[Entity])) -> usize {
    let mut diverged = 0;
    let mut moved = 0;
    for (&ea, &eb) in a.1.iter().zip(b.1) {
        let (ba, bb) = (bead(a.0, ea), bead(b.0, eb));
        for (va, vb) in [(ba.position, bb.position), (ba.velocity, bb.velocity)] {
            assert_eq!(
                va.to_array().map(f64::to_bits),
                vb.to_array().map(f64::to_bits)
            );
        }
        let lambda = |app: &App, e| app.world().get::<BeadDiagnostics>(e).map(|d| d.lambda);
        if let (Some(la), Some(lb)) = (lambda(a.0, ea), lambda(b.0, eb)) {
            assert_eq!(la.to_bits(), lb.to_bits());
        }
        let (ra, rb) = (
            a.0.world().get::<Diverged>(ea),
            b.0.world().get::<Diverged>(eb),
        );
        assert_eq!(ra, rb, "the same beads diverge for the same reason");
        diverged += usize::from(ra.is_some());
        moved += usize::from(ba.position != ba.params.initial_position);
    }
    assert!(moved > 4 * BEADS_PER_WIRE - 10, "{moved} beads moved");
    diverged
}

#[test]
fn parallel_step_matches_sequential_bit_for_bit() {
    let (mut sequential, seq_beads) = scene(ParallelStep::OFF, WireBeadPlugin::default());
    let (mut parallel, par_beads) = scene(ParallelStep { threshold: 0 }, WireBeadPlugin::default());
    run([&mut sequential, &mut parallel]);
    let diverged = assert_same_beads((&sequential, &seq_beads), (&parallel, &par_beads));
    assert_eq!(diverged, 3, "the three beads at the circle's centre");
    for (&s, &p) in seq_beads.iter().zip(&par_beads) {
        assert_eq!(
            sequential.world().get::<BeadDiagnostics>(s).unwrap(),
            parallel.world().get::<BeadDiagnostics>(p).unwrap()
        );
    }
    for app in [&sequential, &parallel] {
        assert_eq!(app.world().resource::<SimClock>().steps, u64::from(STEPS));
    }
    // The parallel run was split: a pool of more than one thread, and
    // more than one run of beads handed to it; the sequential one was not.
    let split = |app: &App| *app.world().resource::<StepSplit>();
    assert_eq!(split(&sequential).bead_threads, 0);
    assert_eq!(split(&sequential).bead_runs, 1);
    if crate::common::splits() {
        assert!(split(&parallel).bead_threads > 1, "{:?}", split(&parallel));
        assert!(split(&parallel).bead_runs > 1, "{:?}", split(&parallel));
    }
}

#[test]
fn lean_beads_step_like_full_ones_without_their_extras() {
    let (mut full, full_beads) = scene(ParallelStep::OFF, WireBeadPlugin::default());
    let (mut lean, lean_beads) = scene(
        ParallelStep { threshold: 0 },
        WireBeadPlugin::default().lean(),
    );
    // A lean bead given a Transform has it written.
    let watched = lean_beads[0];
    lean.world_mut()
        .entity_mut(watched)
        .insert(Transform::default());
    run([&mut full, &mut lean]);
    assert_eq!(
        assert_same_beads((&full, &full_beads), (&lean, &lean_beads)),
        3
    );
    for &bead in &lean_beads[1..] {
        let entity = lean.world().entity(bead);
        assert!(!entity.contains::<Transform>() && !entity.contains::<GlobalTransform>());
        assert!(!entity.contains::<BeadDiagnostics>());
    }
    let position = lean.world().get::<BeadPosition>(watched).unwrap().0;
    let written = lean.world().get::<Transform>(watched).unwrap().translation;
    assert_eq!(
        (written.x, written.y),
        (position.x as f32, position.y as f32)
    );
    // Divergences are timed by the clock: the centre beads fail in step 1.
    let dt = lean.world().resource::<SimParams>().timestep;
    let clock = *lean.world().resource::<SimClock>();
    assert_eq!(clock.steps, u64::from(STEPS));
    let first = lean.world().get::<Diverged>(lean_beads[BEADS_PER_WIRE]);
    assert_eq!(first.map(|d| d.time), Some(dt));
}

/// A bead's `Transform` is where the bead is spawned before any step (a
/// scene loaded paused draws its beads in place, not at the origin), in
/// the plane and in space; a lean bead gets none.
#[test]
fn a_bead_is_placed_where_it_is_spawned_before_its_first_step() {
    let mut app = Headless::new(WireBeadPlugin::default()).build();
    let plane = app
        .world_mut()
        .spawn(Bead::at_rest(1.0, DVec2::new(0.25, -1.5)).unwrap())
        .id();
    let space = app
        .world_mut()
        .spawn(wirebead::SpaceBead::at_rest(1.0, bevy::math::DVec3::new(-2.0, 0.5, 3.0)).unwrap())
        .id();
    let at = |app: &App, bead: Entity| app.world().get::<Transform>(bead).unwrap().translation;
    assert_eq!(at(&app, plane), Vec3::new(0.25, -1.5, 0.0));
    assert_eq!(at(&app, space), Vec3::new(-2.0, 0.5, 3.0));
    assert_eq!(app.world().resource::<SimClock>().steps, 0);

    let mut lean = Headless::new(WireBeadPlugin::default().lean()).build();
    let bead = lean
        .world_mut()
        .spawn(Bead::at_rest(1.0, DVec2::new(0.25, -1.5)).unwrap())
        .id();
    assert!(!lean.world().entity(bead).contains::<Transform>());
}
