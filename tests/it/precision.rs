//! The assignment's float trouble on a unit circle is gone: the state is `f64`, and
//! a scene scaled ×10 (radius and gravity) follows the same dimensionless
//! trajectory.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::prelude::*;

/// The samples of 10 s, and when the bead diverged if it did.
fn trajectory(scale: f64, method: Method) -> (Vec<Sample>, Option<f64>) {
    let mut app = app(SimParams {
        gravity: DVec2::new(0.0, -9.81 * scale),
        method,
        ..default()
    });
    let wire = spawn_wire(&mut app, Wire::circle(scale).unwrap(), Transform::default());
    let bead = spawn_bead(
        &mut app,
        wire,
        BeadParams {
            mass: 1.0,
            initial_position: DVec2::new(0.6, -0.8) * scale,
            initial_velocity: DVec2::new(1.5, 0.5) * scale,
        },
    );
    run_for(&mut app, 10.0);
    let diverged = app.world().get::<Diverged>(bead).map(|d| d.time);
    (app.world().resource::<Recording>().of(bead), diverged)
}

#[test]
fn unit_and_radius_ten_circles_give_the_same_trajectory() {
    for method in Method::ALL {
        let (unit, unit_diverged) = trajectory(1.0, method);
        let (ten, ten_diverged) = trajectory(10.0, method);
        // Explicit Euler blows up at this step: at the same step at both scales.
        assert_eq!(unit_diverged, ten_diverged, "{method}");
        assert!(unit.len() >= 60);
        let worst = unit
            .iter()
            .zip(&ten)
            .map(|(a, b)| (b.position / 10.0 - a.position).length() / a.position.length())
            .fold(0.0, f64::max);
        assert!(worst <= 1e-9, "{method}: relative difference {worst:e}");
    }
}
