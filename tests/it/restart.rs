//! Edits are pending until a restart, as in the assignment's panel.

use std::time::Duration;

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::prelude::*;
use wirebead::{NextBeadParams, NextParams, SimClock, Stabilization};

fn scene() -> (App, Entity) {
    let mut app = app(SimParams::default());
    let bead = circle_bead(&mut app, 1.0, DVec2::new(1.0, 0.0), DVec2::ZERO);
    (app, bead)
}

fn edit(app: &mut App, bead: Entity) {
    app.world_mut()
        .resource_mut::<NextParams>()
        .update(|p| {
            p.timestep = 1.0 / 120.0;
            p.alpha = 400.0;
            p.beta = 40.0;
            p.method = Method::Rattle;
            p.gravity = DVec2::new(0.0, -3.0);
        })
        .unwrap();
    let pending = NextBeadParams::new(BeadParams {
        mass: 2.5,
        initial_position: DVec2::new(0.0, -1.0),
        initial_velocity: DVec2::new(2.0, 0.0),
    })
    .unwrap();
    app.world_mut().entity_mut(bead).insert(pending);
}

#[test]
fn edits_without_restart_change_nothing() {
    let (mut control, control_bead) = scene();
    let (mut edited, edited_bead) = scene();
    run_steps(&mut control, 30);
    run_steps(&mut edited, 30);
    edit(&mut edited, edited_bead);
    run_steps(&mut control, 90);
    run_steps(&mut edited, 90);
    assert_eq!(bead(&control, control_bead), bead(&edited, edited_bead));
    assert_eq!(
        edited.world().resource::<SimParams>(),
        &SimParams::default()
    );
    assert_eq!(
        edited.world().resource::<Time<Fixed>>().timestep(),
        Duration::from_secs_f64(1.0 / 60.0)
    );
}

#[test]
fn restart_applies_pending_params_and_resets_state() {
    let (mut app, bead_entity) = scene();
    run_steps(&mut app, 45);
    edit(&mut app, bead_entity);
    app.world_mut().write_message(Restart);
    run_steps(&mut app, 0);

    let params = app.world().resource::<SimParams>().clone();
    assert_eq!(&params, app.world().resource::<NextParams>().get());
    assert_eq!(params.method, Method::Rattle);
    assert_eq!(
        app.world().resource::<Time<Fixed>>().timestep(),
        Duration::from_secs_f64(1.0 / 120.0)
    );
    let b = bead(&app, bead_entity);
    assert_eq!(b.mass, 2.5);
    assert_eq!(b.position, DVec2::new(0.0, -1.0));
    assert_eq!(b.velocity, DVec2::new(2.0, 0.0));
    assert!(app.world().get::<NextBeadParams>(bead_entity).is_none());
    let d = diagnostics(&app, bead_entity);
    let clock = *app.world().resource::<SimClock>();
    assert_eq!((clock.steps, clock.time), (0, 0.0));
    assert_eq!(d.kinetic, 0.5 * 2.5 * 4.0);

    // The next steps run with the new step and gravity: 120 steps are 1 s.
    run_steps(&mut app, 120);
    let clock = *app.world().resource::<SimClock>();
    assert_eq!(clock.steps, 120);
    assert!((clock.time - 1.0).abs() < 1e-12);
}

#[test]
fn restart_recovers_a_diverged_bead() {
    let (mut app, bead_entity) = scene();
    app.world_mut()
        .resource_mut::<NextParams>()
        .update(|p| {
            p.method = Method::ExplicitEuler(Stabilization::Baumgarte);
            p.timestep = 0.05;
        })
        .unwrap();
    app.world_mut().write_message(Restart);
    run_steps(&mut app, 0);
    run_for(&mut app, 10.0);
    assert!(app.world().get::<Diverged>(bead_entity).is_some());

    app.world_mut()
        .resource_mut::<NextParams>()
        .set(SimParams::default())
        .unwrap();
    app.world_mut().write_message(Restart);
    run_steps(&mut app, 0);
    assert!(app.world().get::<Diverged>(bead_entity).is_none());
    run_steps(&mut app, 60);
    assert!(app.world().get::<Diverged>(bead_entity).is_none());
    assert_eq!(steps(&app), 60);
}

#[test]
fn a_restart_keeps_the_state_of_a_bead_whose_params_were_written_invalid() {
    let (mut app, b) = scene();
    run_steps(&mut app, 30);
    let before = bead(&app, b);
    app.world_mut().get_mut::<BeadParams>(b).unwrap().mass = -1.0;
    app.world_mut().write_message(Restart);
    run_steps(&mut app, 0);
    let after = bead(&app, b);
    assert_eq!(
        (after.position, after.velocity),
        (before.position, before.velocity)
    );
    assert_eq!(after.mass, 1.0, "the mass stays the valid one");
    // It steps on from where it was, as if no restart had come.
    run_steps(&mut app, 30);
    let (mut control, c) = scene();
    run_steps(&mut control, 60);
    assert_eq!(bead(&app, b).state(), bead(&control, c).state());
    assert!(app.world().get::<Diverged>(b).is_none());
}

/// A wire's [`WirePlace`](wirebead::WirePlace) written in the frame a
/// restart is sent, before any step has followed it, is where the
/// restarted run's wire rests: a bead restarted at rest at the bottom of
/// the circle about the new place stays there to 1e-12 m over 0.5 s.
/// Placed from its old `Transform` instead, the wire would be taken to
/// move 0.5 m in the restarted run's first step, and the bead with it.
#[test]
fn a_restart_rests_a_wire_at_the_place_written_with_it() {
    use wirebead::geometry::Pose;
    use wirebead::{Restart, WirePlace};
    let mut app = app(SimParams {
        method: Method::Rattle,
        ..SimParams::default()
    });
    let wire = app
        .world_mut()
        .spawn((Wire::circle(1.0).unwrap(), WirePlace::new(Pose::IDENTITY)))
        .id();
    let rider = bead_at_rest_on(&mut app, wire, DVec2::ZERO);
    run_steps(&mut app, 30);
    let centre = DVec2::new(0.5, 0.0);
    let bottom = centre - DVec2::Y;
    app.world_mut().get_mut::<WirePlace>(wire).unwrap().0 = Pose::new(centre, 0.0);
    let at_bottom = NextBeadParams::new(BeadParams {
        mass: 1.0,
        initial_position: bottom,
        initial_velocity: DVec2::ZERO,
    })
    .unwrap();
    app.world_mut().entity_mut(rider).insert(at_bottom);
    app.world_mut().write_message(Restart);
    let mut moved = 0.0f64;
    for _ in 0..30 {
        run_steps(&mut app, 1);
        moved = moved.max((bead(&app, rider).position - bottom).length());
    }
    assert!(moved <= 1e-12, "the bead moved {moved:e} m from the bottom");
}
