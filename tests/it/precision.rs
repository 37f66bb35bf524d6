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

/// A scene's `(position, angle)` of a plane wire reaches the solver in
/// `f64`: an ellipse of semi-axes 1.5 and 1 placed at x = 0.1 and turned
/// 30° holds its bead on the exact ellipse the file describes
/// (`(u/a)² + (v/b)² = 1` in its frame) to 1e-12 over 2 s of RATTLE,
/// where its `f32` `Transform` would put it at x = 0.100000001490116 and
/// turn it by a rounded angle.
#[test]
fn a_plane_scene_wire_is_where_its_file_puts_it() {
    let (a, b) = (1.5, 1.0);
    let centre = DVec2::new(0.1, 0.0);
    let turn = DVec2::from_angle(30f64.to_radians());
    // In the ellipse's frame: turned back by 30° about its centre.
    let back = DVec2::new(turn.x, -turn.y);
    let local = |p: DVec2| back.rotate(p - centre);
    let start = centre + turn.rotate(DVec2::new(a * 0.6, -b * 0.8));
    let text = format!(
        "(name: \"off the origin\", params: (integrator: Rattle, timestep: 0.001, gravity: (0.0, -9.81)),
          wires: [(shape: Ellipse((a: {a:?}, b: {b:?})), position: ({:?}, 0.0), angle_degrees: 30.0,
                   beads: [(mass: 1.0, initial_position: ({:?}, {:?}))])])",
        centre.x, start.x, start.y
    );
    let scene = wirebead::ScenePreset::from_ron(&text).expect("the scene loads");
    let mut app = app(scene.params.clone());
    let bead = scene.spawn(&mut app.world_mut().commands())[0];
    app.world_mut().flush();
    let (mut off, mut moved) = (0.0f64, 0.0f64);
    for _ in 0..2000 {
        app.update();
        let at = wirebead::headless::bead_state(app.world(), bead)
            .expect("a bead")
            .position;
        let p = local(at);
        off = off.max(((p.x / a).powi(2) + (p.y / b).powi(2) - 1.0).abs());
        moved = moved.max((at - start).length());
    }
    assert!(moved > 0.3, "the bead slid only {moved} m");
    assert!(
        off <= 1e-12,
        "the bead strayed {off:e} from the exact ellipse"
    );
}

/// A scene's turn of a wire in space reaches the solver in `f64`: a hoop
/// of radius 1 turned 60° about x keeps its bead in the exact plane of
/// the turned hoop (normal `R z`) to 1e-12 over 2 s of RATTLE, where
/// reading it back from the wire's `f32` `Transform` tilts that plane by
/// some 1e-8.
#[test]
fn a_hoop_turned_60_degrees_about_x_keeps_its_bead_in_the_exact_plane() {
    use bevy::math::{DQuat, DVec3};
    let turn = DQuat::from_axis_angle(DVec3::X, 60f64.to_radians());
    let normal = turn * DVec3::Z;
    let start = turn * DVec3::new(30f64.to_radians().cos(), -(30f64.to_radians().sin()), 0.0);
    let text = format!(
        "(name: \"turned hoop\", dimension: 3,
          params: (integrator: Rattle, timestep: 0.001, gravity: (0.0, -9.81, 0.0)),
          wires: [(shape: Circle((radius: 1.0)), position: (0.0, 0.0, 0.0),
                   rotation: (axis: (1.0, 0.0, 0.0), angle_degrees: 60.0),
                   beads: [(mass: 1.0, initial_position: ({:?}, {:?}, {:?}))])])",
        start.x, start.y, start.z
    );
    let wirebead::SceneFile::Space(scene) =
        wirebead::SceneFile::from_ron(&text).expect("the scene loads")
    else {
        panic!("a scene in space");
    };
    let plugin = WireBeadPlugin::new(scene.params.0.clone()).expect("valid params");
    let mut app = wirebead::headless::Headless::new(plugin)
        .single_threaded()
        .build();
    let bead = scene.spawn(&mut app.world_mut().commands())[0];
    app.world_mut().flush();
    let (mut out_of_plane, mut off, mut moved) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..2000 {
        app.update();
        let at = wirebead::headless::space_bead_state(app.world(), bead)
            .expect("a bead")
            .position;
        out_of_plane = out_of_plane.max(at.dot(normal).abs());
        off = off.max((at.length() - 1.0).abs());
        moved = moved.max((at - start).length());
    }
    assert!(moved > 0.5, "the bead swung only {moved} m");
    assert!(
        out_of_plane <= 1e-12,
        "the bead left the turned hoop's plane by {out_of_plane:e} m"
    );
    assert!(off <= 1e-12, "the bead strayed {off:e} m from the hoop");
}
