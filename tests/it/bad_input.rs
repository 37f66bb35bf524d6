//! Every bad input given to a running app gets its error in words, never a
//! panic, never a NaN in a `Transform`, and leaves the running simulation
//! as it was. The constructors' own refusals (a wire of zero radius, a bad
//! spline, a malformed scene file) are unit tests beside them.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::prelude::*;
use wirebead::{NextBeadParams, NextParams, SpringAnchor};

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
        .get_mut::<BeadVelocity>(bead_entity)
        .unwrap()
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

/// A [`WirePlace`](wirebead::WirePlace) that is not finite, or whose turn
/// is no rotation, is not taken, at spawn or when a game writes it: the
/// wire's `Transform` places it, as if it had none. Its bead rides the
/// circle about the `Transform`'s (0.5, 0) to 1e-9, and the `Transform`
/// stays finite where it was.
#[test]
fn a_wire_place_that_places_nothing_leaves_the_wire_at_its_transform() {
    use wirebead::WirePlace;
    use wirebead::geometry::Pose;
    let nan = Pose {
        origin: DVec2::new(f64::NAN, 0.0),
        rotation: DVec2::X,
    };
    let no_turn = Pose {
        origin: DVec2::ZERO,
        rotation: DVec2::ZERO,
    };
    let stretched = Pose {
        origin: DVec2::ZERO,
        rotation: DVec2::new(2.0, 0.0),
    };
    let centre = DVec2::new(0.5, 0.0);
    for bad in [nan, no_turn, stretched] {
        let mut app = app(params(Method::Rattle, 1.0 / 240.0));
        let wire = app
            .world_mut()
            .spawn((
                Wire::circle(1.0).unwrap(),
                Transform::from_xyz(0.5, 0.0, 0.0),
                WirePlace::new(bad),
            ))
            .id();
        let bead = bead_at_rest_on(&mut app, wire, centre);
        run_for(&mut app, 0.5);
        // Written again by the game.
        app.world_mut().get_mut::<WirePlace>(wire).unwrap().0 = bad;
        run_for(&mut app, 0.5);
        let at = crate::common::bead(&app, bead).position;
        let off = ((at - centre).length() - 1.0).abs();
        assert!(off <= 1e-9, "{bad:?}: the bead is {off:e} m off the circle");
        assert!(app.world().get::<Diverged>(bead).is_none(), "{bad:?}");
        let shown = *app.world().get::<Transform>(wire).unwrap();
        assert_eq!(shown, Transform::from_xyz(0.5, 0.0, 0.0), "{bad:?}");
    }
}
