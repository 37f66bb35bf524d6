//! The assignment's analysis (its Figures 1.1–1.3): how α, β and the timestep
//! change the drift off the wire under Baumgarte stabilization.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::prelude::*;
use wirebead::{BeadDiverged, Integrator, Stabilization};

/// The assignment's setup: a vertical unit circle, the bead starting at the bottom
/// with a sideways push, semi-implicit Euler. Returns the samples of 10 s.
fn assignment_run(
    alpha: f64,
    beta: f64,
    integrator: Integrator,
    dt: f64,
) -> (App, Entity, Vec<Sample>) {
    let mut app = app(SimParams {
        timestep: dt,
        alpha,
        beta,
        method: Method::new(integrator, Some(Stabilization::Baumgarte)).unwrap(),
        ..default()
    });
    let bead = circle_bead(&mut app, 1.0, DVec2::new(0.0, -1.0), DVec2::new(4.0, 0.0));
    run_for(&mut app, 10.0);
    let samples = app.world().resource::<Recording>().of(bead);
    (app, bead, samples)
}

fn mean_drift(samples: &[Sample]) -> f64 {
    samples.iter().map(|s| s.diagnostics.c.abs()).sum::<f64>() / samples.len() as f64
}

#[test]
fn drift_grows_without_alpha() {
    // With no spring nothing pulls the bead back: |C| keeps growing until the
    // bead is a whole radius off and the run is declared blown up.
    let (app, bead, samples) = assignment_run(0.0, 0.0, Integrator::SemiImplicitEuler, 1.0 / 60.0);
    let window = |from: f64, to: f64| {
        let s: Vec<Sample> = samples
            .iter()
            .filter(|s| s.t > from && s.t <= to)
            .copied()
            .collect();
        max_drift(&s)
    };
    let drifts = [
        window(0.0, 0.5),
        window(0.5, 1.0),
        window(1.0, 2.0),
        window(2.0, 4.0),
    ];
    for pair in drifts.windows(2) {
        assert!(
            pair[1] > 1.2 * pair[0],
            "max |C| over 0-0.5, 0.5-1, 1-2, 2-4 s: {drifts:?}"
        );
    }
    assert!(
        app.world().get::<Diverged>(bead).is_some(),
        "α = 0 ends a whole radius off the wire"
    );
}

#[test]
fn drift_shrinks_as_alpha_grows() {
    let drifts: Vec<f64> = [0.0, 10.0, 100.0, 1000.0]
        .iter()
        .map(|&alpha| {
            mean_drift(&assignment_run(alpha, 10.0, Integrator::SemiImplicitEuler, 1.0 / 60.0).2)
        })
        .collect();
    for pair in drifts.windows(2) {
        assert!(
            pair[1] < 0.7 * pair[0],
            "mean |C| by α = 0, 10, 100, 1000: {drifts:?}"
        );
    }
}

#[test]
fn too_much_damping_brings_drift_back() {
    // α = 100: β = 20 is critical damping (β² = 4α); β = 100 overdamps but
    // is still a stable step (semi-implicit Euler needs β < (4 - h²α)/2h ≈ 119).
    let drift = |beta| {
        let (app, bead, samples) =
            assignment_run(100.0, beta, Integrator::SemiImplicitEuler, 1.0 / 60.0);
        assert!(
            app.world().get::<Diverged>(bead).is_none(),
            "β = {beta} diverged"
        );
        mean_drift(&samples)
    };
    let (matched, too_large) = (drift(20.0), drift(100.0));
    assert!(
        too_large > 3.0 * matched,
        "mean |C|: β = 20 {matched:e}, β = 100 {too_large:e}"
    );
}

#[test]
fn explicit_euler_blow_up_is_reported_not_a_nan() {
    // Stable at a small step...
    let (app, bead, _) = assignment_run(100.0, 20.0, Integrator::ExplicitEuler, 1.0 / 240.0);
    assert!(app.world().get::<Diverged>(bead).is_none());

    // ...blows up at the assignment's 0.05 s, and says so.
    let (mut app, bead, _) = assignment_run(100.0, 20.0, Integrator::ExplicitEuler, 0.05);
    let diverged = app
        .world()
        .get::<Diverged>(bead)
        .expect("the blow-up is reported")
        .clone();
    assert!(diverged.time < 10.0);
    let messages: Vec<BeadDiverged> = app
        .world_mut()
        .resource_mut::<Messages<BeadDiverged>>()
        .drain()
        .collect();
    assert_eq!(messages.len(), 1);
    assert_eq!(messages[0].bead, bead);
    assert!(
        messages[0].reason.to_string().contains("drifted"),
        "{}",
        messages[0].reason
    );
    let state = bead_state(&app, bead);
    let transform = *app.world().get::<Transform>(bead).unwrap();
    assert!(state.is_finite() && transform.translation.is_finite());
    // It stopped: more steps do not move it.
    run_steps(&mut app, 10);
    assert_eq!(bead_state(&app, bead), state);
}

fn bead_state(app: &App, entity: Entity) -> wirebead::solver::BeadState {
    bead(app, entity).state()
}
