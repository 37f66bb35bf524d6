//! Keyboard controls, pressed through `ButtonInput<KeyCode>` with no window.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::controls::KeyboardControlsPlugin;
use wirebead::prelude::*;
use wirebead::{Integrator, NextBeadParams, NextParams, Stabilization};

pub(crate) fn press(app: &mut App, key: KeyCode, steps: u32) {
    app.world_mut()
        .resource_mut::<ButtonInput<KeyCode>>()
        .press(key);
    run_steps(app, steps);
    let mut keys = app.world_mut().resource_mut::<ButtonInput<KeyCode>>();
    keys.release(key);
    keys.clear();
}

fn scene() -> (App, Entity) {
    let mut app = app(SimParams::default());
    app.add_plugins(KeyboardControlsPlugin);
    let wire = spawn_wire(&mut app, Wire::circle(1.0).unwrap(), Transform::default());
    let bead = spawn_bead(
        &mut app,
        wire,
        BeadParams {
            initial_position: DVec2::new(1.0, 0.0),
            ..default()
        },
    );
    (app, bead)
}

#[test]
fn space_restarts_and_applies_pending_params() {
    let (mut app, bead_entity) = scene();
    run_steps(&mut app, 30);
    app.world_mut()
        .resource_mut::<NextParams>()
        .update(|p| p.alpha = 250.0)
        .unwrap();
    let edit = NextBeadParams::new(BeadParams {
        mass: 3.0,
        initial_position: DVec2::new(-1.0, 0.0),
        ..default()
    })
    .unwrap();
    app.world_mut().entity_mut(bead_entity).insert(edit);
    run_steps(&mut app, 5);
    assert_eq!(
        app.world().resource::<SimParams>().alpha,
        100.0,
        "not before Space"
    );

    press(&mut app, KeyCode::Space, 0);
    assert_eq!(app.world().resource::<SimParams>().alpha, 250.0);
    let b = bead(&app, bead_entity);
    assert_eq!(
        (b.mass, b.position, b.velocity),
        (3.0, DVec2::new(-1.0, 0.0), DVec2::ZERO)
    );
    assert_eq!(steps(&app), 0);
}

#[test]
fn p_pauses_and_n_steps_exactly_once() {
    let (mut app, _) = scene();
    run_steps(&mut app, 10);
    press(&mut app, KeyCode::KeyP, 0);
    run_steps(&mut app, 10);
    assert_eq!(steps(&app), 10, "paused: no steps");
    press(&mut app, KeyCode::KeyN, 0);
    assert_eq!(steps(&app), 11, "one step");
    press(&mut app, KeyCode::KeyP, 0);
    run_steps(&mut app, 10);
    assert_eq!(steps(&app), 21, "running again");
}

/// `[` halves the run's speed (slow motion: 10 frames of a step each run
/// 5 steps), down to 1/20 of real time; `]` speeds it up again.
#[test]
fn brackets_slow_the_run_down_and_speed_it_up() {
    let (mut app, _) = scene();
    run_steps(&mut app, 10);
    assert_eq!(steps(&app), 10, "real time: a step a frame");
    press(&mut app, KeyCode::BracketLeft, 0);
    let speed = |app: &App| app.world().resource::<Time<Virtual>>().relative_speed_f64();
    assert_eq!(speed(&app), 0.5);
    run_steps(&mut app, 10);
    assert_eq!(steps(&app), 15, "half speed: five steps in ten frames");
    for _ in 0..5 {
        press(&mut app, KeyCode::BracketLeft, 0);
    }
    assert_eq!(speed(&app), 0.05, "no slower than 1/20");
    press(&mut app, KeyCode::BracketRight, 0);
    assert_eq!(speed(&app), 0.1);
    for _ in 0..4 {
        press(&mut app, KeyCode::BracketRight, 0);
    }
    assert_eq!(speed(&app), 1.0, "no faster than real time");
}

/// R turns every bead's velocity round, and the run goes on backwards: a
/// bead let go on a circle level with its centre, run for 2 s and turned
/// round, is back where it started 2 s later to 1e-9 m with RATTLE, which
/// is time-reversible (measured 1.5e-14 m); with semi-implicit Euler and
/// Baumgarte, which is not, it misses by more than a millimetre (measured
/// 0.28 m).
#[test]
fn r_runs_the_bead_back_to_its_start_with_rattle_only() {
    let mut missed = Vec::new();
    for integrator in [Integrator::Rattle, Integrator::SemiImplicitEuler] {
        let stabilization = (integrator != Integrator::Rattle).then_some(Stabilization::Baumgarte);
        let params = SimParams {
            method: Method::new(integrator, stabilization).expect("a method"),
            ..SimParams::default()
        };
        let mut app = app(params);
        app.add_plugins(KeyboardControlsPlugin);
        let wire = spawn_wire(&mut app, Wire::circle(1.0).unwrap(), Transform::default());
        let start = DVec2::new(1.0, 0.0);
        let b = spawn_bead(
            &mut app,
            wire,
            BeadParams {
                initial_position: start,
                ..default()
            },
        );
        run_steps(&mut app, 120);
        assert!(
            (bead(&app, b).position - start).length() > 0.5,
            "it swung away"
        );
        press(&mut app, KeyCode::KeyR, 0);
        run_steps(&mut app, 120);
        missed.push((bead(&app, b).position - start).length());
    }
    eprintln!(
        "back to the start: RATTLE {:e} m, Euler {:e} m",
        missed[0], missed[1]
    );
    assert!(
        missed[0] <= 1e-9,
        "RATTLE missed its start by {:e} m",
        missed[0]
    );
    assert!(missed[1] > 1e-3, "Euler came back by {:e} m", missed[1]);
}
