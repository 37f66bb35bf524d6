//! Every bad input gets its error in words, never a panic, never a NaN in a
//! `Transform`, and leaves the running simulation as it was.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::prelude::*;
use wirebead::{NextBeadParams, NextParams, ScenePreset, SpringAnchor};

fn scene() -> (App, Entity) {
    let mut app = app(SimParams::default());
    let bead = circle_bead(&mut app, 1.0, DVec2::new(0.8, -0.6), DVec2::new(0.5, 0.0));
    run_steps(&mut app, 20);
    (app, bead)
}

/// Runs `bad` against a scene and checks that, afterwards, the scene steps
/// exactly as an untouched one does and no parameter changed.
fn leaves_simulation_untouched(bad: impl FnOnce(&mut App, Entity) -> String, expected: &str) {
    let (mut control, control_bead) = scene();
    let (mut app, bead_entity) = scene();
    let error = bad(&mut app, bead_entity);
    assert_eq!(error, expected);
    for app in [&mut control, &mut app] {
        app.world_mut().write_message(Restart);
        run_steps(app, 60);
    }
    assert_eq!(
        bead(&app, bead_entity),
        bead(&control, control_bead),
        "{expected}"
    );
    assert_eq!(
        app.world().resource::<SimParams>(),
        control.world().resource::<SimParams>()
    );
    assert_eq!(
        app.world().resource::<NextParams>(),
        control.world().resource::<NextParams>()
    );
    assert!(app.world().get::<NextBeadParams>(bead_entity).is_none());
    assert!(app.world().get::<SpringAnchor>(bead_entity).is_none());
}

fn pending_edit(edit: impl FnOnce(&mut SimParams)) -> impl FnOnce(&mut App, Entity) -> String {
    |app, _| {
        app.world_mut()
            .resource_mut::<NextParams>()
            .update(edit)
            .unwrap_err()
            .to_string()
    }
}

fn bead_edit(edit: impl FnOnce(&mut BeadParams)) -> impl FnOnce(&mut App, Entity) -> String {
    |_, _| {
        let mut params = BeadParams::default();
        edit(&mut params);
        NextBeadParams::new(params).unwrap_err().to_string()
    }
}

#[test]
fn negative_mass_is_refused() {
    leaves_simulation_untouched(
        bead_edit(|b| b.mass = -2.0),
        "mass must be positive and finite, got -2",
    );
}

#[test]
fn non_finite_mass_is_refused() {
    leaves_simulation_untouched(
        bead_edit(|b| b.mass = f64::NAN),
        "mass must be positive and finite, got NaN",
    );
    leaves_simulation_untouched(
        bead_edit(|b| b.mass = f64::INFINITY),
        "mass must be positive and finite, got inf",
    );
    leaves_simulation_untouched(
        bead_edit(|b| b.mass = 0.0),
        "mass must be positive and finite, got 0",
    );
}

#[test]
fn zero_radius_is_refused() {
    leaves_simulation_untouched(
        |_, _| Wire::circle(0.0).unwrap_err().to_string(),
        "radius must be positive and finite, got 0",
    );
    leaves_simulation_untouched(
        |_, _| Wire::ellipse(1.0, -1.0).unwrap_err().to_string(),
        "semi-axis b must be positive and finite, got -1",
    );
}

#[test]
fn non_positive_timestep_is_refused() {
    leaves_simulation_untouched(
        pending_edit(|p| p.timestep = 0.0),
        "timestep must be positive and finite, got 0",
    );
    leaves_simulation_untouched(
        pending_edit(|p| p.timestep = -0.01),
        "timestep must be positive and finite, got -0.01",
    );
    leaves_simulation_untouched(
        pending_edit(|p| p.timestep = 1e-9),
        "timestep must be between 0.000001 and 1, got 0.000000001",
    );
}

#[test]
fn nan_anywhere_is_refused() {
    leaves_simulation_untouched(
        pending_edit(|p| p.timestep = f64::NAN),
        "timestep must be positive and finite, got NaN",
    );
    leaves_simulation_untouched(
        pending_edit(|p| p.gravity.x = f64::NAN),
        "gravity must be finite, got (NaN, -9.81)",
    );
    leaves_simulation_untouched(
        pending_edit(|p| p.alpha = f64::NAN),
        "alpha must be zero or more and finite, got NaN",
    );
    leaves_simulation_untouched(
        pending_edit(|p| p.beta = f64::NAN),
        "beta must be zero or more and finite, got NaN",
    );
    leaves_simulation_untouched(
        pending_edit(|p| p.drag_stiffness = f64::NAN),
        "drag stiffness k must be zero or more and finite, got NaN",
    );
    leaves_simulation_untouched(
        bead_edit(|b| b.initial_position.y = f64::NAN),
        "initial position must be finite, got (0, NaN)",
    );
    leaves_simulation_untouched(
        bead_edit(|b| b.initial_velocity.x = f64::INFINITY),
        "initial velocity must be finite, got (inf, 0)",
    );
    leaves_simulation_untouched(
        |_, _| {
            SpringAnchor::new(DVec2::new(f64::NAN, 0.0))
                .unwrap_err()
                .to_string()
        },
        "spring anchor must be finite, got (NaN, 0)",
    );
    leaves_simulation_untouched(
        |_, _| Wire::sine(f64::NAN, 1.0).unwrap_err().to_string(),
        "amplitude must be finite, got NaN",
    );
}

#[test]
fn malformed_scene_file_is_refused() {
    leaves_simulation_untouched(
        |_, _| {
            ScenePreset::from_ron("(name: \"broken\", wires: [")
                .unwrap_err()
                .to_string()
        },
        "malformed scene file at line 1, column 25: Expected opening `(` for struct `WirePreset`",
    );
}

#[test]
fn bead_at_a_singular_point_is_reported_and_others_run_on() {
    let mut app = app(SimParams::default());
    let wire = spawn_wire(&mut app, Wire::circle(1.0).unwrap(), Transform::default());
    let centre = spawn_bead(
        &mut app,
        wire,
        BeadParams {
            initial_position: DVec2::ZERO,
            ..default()
        },
    );
    let fine = spawn_bead(
        &mut app,
        wire,
        BeadParams {
            initial_position: DVec2::new(1.0, 0.0),
            ..default()
        },
    );
    run_steps(&mut app, 30);
    let diverged = app.world().get::<Diverged>(centre).expect("reported");
    assert_eq!(
        diverged.reason.to_string(),
        "the bead is at a singular point of its wire (0, 0), where the normal ∇C vanishes"
    );
    assert_eq!(bead(&app, centre).position, DVec2::ZERO);
    assert!(
        app.world()
            .get::<Transform>(centre)
            .unwrap()
            .translation
            .is_finite()
    );
    assert!(app.world().get::<Diverged>(fine).is_none());
    assert_eq!(steps(&app), 30);
}

#[test]
fn nan_written_into_a_bead_is_reported_not_propagated() {
    let (mut app, bead_entity) = scene();
    let before = *app.world().get::<Transform>(bead_entity).unwrap();
    app.world_mut()
        .get_mut::<Bead>(bead_entity)
        .unwrap()
        .velocity
        .x = f64::NAN;
    run_steps(&mut app, 5);
    let diverged = app.world().get::<Diverged>(bead_entity).expect("reported");
    assert_eq!(
        diverged.reason.to_string(),
        "its position or velocity is not finite"
    );
    assert_eq!(*app.world().get::<Transform>(bead_entity).unwrap(), before);
}

/// Tracks refuse bad numbers in words: a motion, a surface, a spline, and
/// the same in a scene file (which names the wire).
#[test]
fn bad_tracks_are_refused_in_words() {
    use wirebead::geometry::{Spline, SplineKind, SplineSpec};
    use wirebead::{Friction, Oscillate, PrescribedMotion, Surface, WireMotion};
    let shake = |amplitude, frequency| {
        PrescribedMotion::new(WireMotion::Oscillate(Oscillate {
            amplitude,
            frequency,
        }))
        .unwrap_err()
        .to_string()
    };
    assert_eq!(
        shake(DVec2::new(f64::NAN, 0.0), 1.0),
        "oscillation amplitude must be finite, got (NaN, 0)"
    );
    assert_eq!(
        shake(DVec2::Y, 0.0),
        "oscillation frequency must be positive and finite, got 0"
    );
    let surface = |surface: Surface| Wire::line().with_surface(surface).unwrap_err().to_string();
    assert_eq!(
        surface(Surface {
            restitution: 1.5,
            ..Surface::PLAIN
        }),
        "restitution must be between 0 and 1, got 1.5"
    );
    assert_eq!(
        Friction::new(0.2, 0.5).unwrap_err().to_string(),
        "kinetic friction must not exceed static friction"
    );
    assert_eq!(
        surface(Surface {
            damping: -1.0,
            ..Surface::PLAIN
        }),
        "damping along the wire must be zero or more and finite, got -1"
    );
    let spline = |points: Vec<DVec2>| {
        Spline::new(SplineSpec {
            kind: SplineKind::CatmullRom,
            points,
            closed: false,
        })
        .unwrap_err()
        .to_string()
    };
    assert_eq!(
        spline(vec![DVec2::ZERO]),
        "a cardinal spline needs two points at least"
    );
    assert_eq!(
        spline(vec![DVec2::ZERO, DVec2::new(f64::NAN, 1.0)]),
        "a spline's points must be finite"
    );
    let scene = |wire: &str| {
        ScenePreset::from_ron(&format!("(name: \"t\", wires: [({wire}, beads: [()])])"))
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        scene("shape: Line(()), friction: (static: -1.0, kinetic: 0.0)"),
        "wire 0: static friction must be zero or more and finite, got -1"
    );
    assert_eq!(
        scene("shape: Line(()), motion: Spin((angular_velocity: inf))"),
        "wire 0: angular velocity must be finite, got inf"
    );
    assert!(
        scene("shape: Spline((points: [(0.0, 0.0)]))")
            .contains("a cardinal spline needs two points at least"),
        "{}",
        scene("shape: Spline((points: [(0.0, 0.0)]))")
    );
}

/// A bead put exactly on a cycloid's cusp (where the curve has no
/// tangent) is reported at a singular point; the bead beside it runs on.
#[test]
fn a_bead_on_a_cycloids_cusp_is_reported_as_singular() {
    use wirebead::geometry::Cycloid;
    let mut app = app(SimParams::default());
    let wire = spawn_wire(
        &mut app,
        Wire::new(wirebead::WireShape::Cycloid(Cycloid::new(1.0))).unwrap(),
        Transform::default(),
    );
    let cusp = spawn_bead(
        &mut app,
        wire,
        BeadParams {
            initial_position: DVec2::new(std::f64::consts::PI, 2.0),
            ..default()
        },
    );
    let fine = spawn_bead(
        &mut app,
        wire,
        BeadParams {
            initial_position: Cycloid::new(1.0).point(2.0),
            ..default()
        },
    );
    run_steps(&mut app, 30);
    let diverged = app.world().get::<Diverged>(cusp).expect("reported");
    assert!(
        diverged
            .reason
            .to_string()
            .starts_with("the bead is at a singular point of its wire"),
        "{}",
        diverged.reason
    );
    assert!(app.world().get::<Diverged>(fine).is_none());
}
