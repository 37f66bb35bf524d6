//! A bead on a vertical circle is a pendulum: its period and its energy are
//! known exactly (`wirebead::reference`: the elliptic-integral period and the conserved energy).

use crate::common::*;
use wirebead::Stabilization;
use wirebead::prelude::*;
use wirebead::reference::pendulum_period;

const G: f64 = 9.81;

/// What one pendulum run measured against the exact answer.
struct Errors {
    /// (measured - exact) / exact.
    period: f64,
    /// max |C| / r.
    drift: f64,
    /// max |E - E0| / (m |g| r) over the run.
    energy: f64,
    /// max |E - E0| / (m |g| r) over the first and the last tenth of the run.
    energy_first: f64,
    energy_last: f64,
}

fn run_pendulum(method: Method, dt: f64, theta0_deg: f64, periods: f64) -> Errors {
    let r = 1.0;
    let theta0 = theta0_deg.to_radians();
    let exact = pendulum_period(r, G, theta0);
    let mut app = app(params(method, dt));
    let bead = pendulum(&mut app, r, theta0);
    app.world_mut().write_message(Restart);
    run_steps(&mut app, 0);
    let e0 = diagnostics(&app, bead).energy();
    run_for(&mut app, periods * exact);
    if let Some(d) = app.world().get::<Diverged>(bead) {
        panic!("{method} at {theta0_deg}° diverged: {}", d.reason);
    }
    let samples = app.world().resource::<Recording>().of(bead);
    let energy_error = |s: &[Sample]| {
        s.iter()
            .map(|s| (s.diagnostics.energy() - e0).abs() / (G * r))
            .fold(0.0, f64::max)
    };
    let tenth = samples.len() / 10;
    Errors {
        period: (measured_period(&samples) - exact) / exact,
        drift: max_drift(&samples) / r,
        energy: energy_error(&samples),
        energy_first: energy_error(&samples[..tenth]),
        energy_last: energy_error(&samples[samples.len() - tenth..]),
    }
}

/// Each integrator at the step it needs, with the relative period error it
/// earns there, below 150° and above it (near the separatrix a first-order
/// method's small energy error moves the period most).
const PERIOD_CASES: &[(Method, f64, f64, f64)] = &[
    // (method, dt, tolerance up to 135°, tolerance at 160°)
    (
        Method::ExplicitEuler(Stabilization::Baumgarte),
        1e-4,
        1.5e-2,
        8e-2,
    ),
    (
        Method::SemiImplicitEuler(Stabilization::Baumgarte),
        1e-4,
        3e-3,
        1.5e-2,
    ),
    (
        Method::SemiImplicitEuler(Stabilization::Projection),
        1e-4,
        8e-3,
        4e-2,
    ),
    (
        Method::Rk4(Stabilization::Baumgarte),
        1.0 / 60.0,
        1e-4,
        1e-4,
    ),
    (
        Method::Rk4(Stabilization::Projection),
        1.0 / 60.0,
        1e-4,
        1e-4,
    ),
    (Method::Rattle, 1.0 / 60.0, 1e-3, 1e-3),
];

#[test]
fn period_matches_elliptic_integral() {
    for &(method, dt, tol_low, tol_high) in PERIOD_CASES {
        for theta0 in [30.0, 90.0, 135.0, 160.0] {
            let errors = run_pendulum(method, dt, theta0, 2.2);
            let tolerance = if theta0 > 150.0 { tol_high } else { tol_low };
            assert!(
                errors.period.abs() <= tolerance,
                "{method}, dt = {dt}, θ0 = {theta0}°: period error {:+.3e} > {tolerance:e}",
                errors.period
            );
        }
    }
}

#[test]
fn period_error_shrinks_at_each_integrators_order() {
    // Halving dt divides the period error by about 2^order.
    for (method, dt, order) in [
        (
            Method::SemiImplicitEuler(Stabilization::Baumgarte),
            1.0 / 480.0,
            1.0,
        ),
        (Method::Rattle, 1.0 / 60.0, 2.0),
        (Method::Rk4(Stabilization::None), 1.0 / 60.0, 4.0),
    ] {
        let coarse = run_pendulum(method, dt, 90.0, 2.2).period.abs();
        let fine = run_pendulum(method, dt / 2.0, 90.0, 2.2).period.abs();
        let observed = (coarse / fine).log2();
        assert!(
            (observed - order).abs() <= 0.35,
            "{method}: observed order {observed:.2}, expected {order}"
        );
    }
}

#[test]
fn rattle_holds_the_wire_and_bounds_energy_over_1000_periods() {
    let e = run_pendulum(Method::Rattle, 1.0 / 60.0, 135.0, 1000.0);
    assert!(e.drift <= 1e-14, "max |C|/r = {:e}", e.drift);
    assert!(e.energy <= 3e-3, "max energy error {:e} m|g|r", e.energy);
    // Bounded, not drifting: the last hundred periods are no worse than the first.
    assert!(
        e.energy_last <= 1.1 * e.energy_first,
        "energy error grew from {:e} to {:e}",
        e.energy_first,
        e.energy_last
    );
}

#[test]
fn projection_holds_the_wire_over_1000_periods() {
    let e = run_pendulum(
        Method::Rk4(Stabilization::Projection),
        1.0 / 60.0,
        135.0,
        1000.0,
    );
    assert!(e.drift <= 1e-14, "max |C|/r = {:e}", e.drift);
    assert!(e.energy <= 5e-3, "max energy error {:e} m|g|r", e.energy);
}
