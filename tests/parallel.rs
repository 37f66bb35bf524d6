//! The parallel step gives bit-for-bit the sequential step's result, and
//! reports the same divergences.

use std::time::Duration;

use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use wirebead::prelude::*;

const BEADS_PER_WIRE: usize = 1500;

/// Four wires of different shapes, moved and rotated, 1,500 beads on each
/// spread along it with different speeds, plus beads at the circle's centre
/// (a singular point). Returns the app and the beads in spawn order.
fn scene(parallel: ParallelStep) -> (App, Vec<Entity>) {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins.set(TaskPoolPlugin {
            task_pool_options: wirebead::plugin::compute_on_all_cores(),
        }),
        WireBeadPlugin::default(),
    ))
    .insert_resource(parallel)
    .insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    app.world_mut()
        .resource_mut::<Time<Virtual>>()
        .set_max_delta(Duration::from_secs(1_000));
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
        let pose = wirebead::wire::Pose::new(origin, angle);
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
    app.update();
    (app, beads)
}

#[test]
fn parallel_step_matches_sequential_bit_for_bit() {
    let (mut sequential, seq_beads) = scene(ParallelStep::OFF);
    let (mut parallel, par_beads) = scene(ParallelStep { threshold: 0 });
    for app in [&mut sequential, &mut parallel] {
        app.insert_resource(TimeUpdateStrategy::FixedTimesteps(300));
        app.update();
    }
    let mut diverged = 0;
    let mut moved = 0;
    for (&s, &p) in seq_beads.iter().zip(&par_beads) {
        let (a, b) = (
            sequential.world().get::<Bead>(s).unwrap(),
            parallel.world().get::<Bead>(p).unwrap(),
        );
        assert_eq!(
            a.position.to_array().map(f64::to_bits),
            b.position.to_array().map(f64::to_bits)
        );
        assert_eq!(
            a.velocity.to_array().map(f64::to_bits),
            b.velocity.to_array().map(f64::to_bits)
        );
        let (da, db) = (
            sequential.world().get::<BeadDiagnostics>(s).unwrap(),
            parallel.world().get::<BeadDiagnostics>(p).unwrap(),
        );
        assert_eq!(da, db);
        let (ra, rb) = (
            sequential.world().get::<Diverged>(s),
            parallel.world().get::<Diverged>(p),
        );
        assert_eq!(ra, rb, "the same beads diverge for the same reason");
        diverged += usize::from(ra.is_some());
        moved += usize::from(a.position != a.params().initial_position);
    }
    assert_eq!(diverged, 3, "the three beads at the circle's centre");
    assert!(moved > 4 * BEADS_PER_WIRE - 10, "{moved} beads moved");
    let steps = sequential
        .world()
        .get::<BeadDiagnostics>(seq_beads[0])
        .unwrap()
        .steps;
    assert_eq!(steps, 300);
}
