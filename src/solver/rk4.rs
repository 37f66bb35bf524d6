//! Classical fourth-order Runge–Kutta with λ solved at every stage, eq. (7).

use super::Advance;
use super::settings::Gains;
use super::solve::{SolveError, Solved, solve};
use super::state::{BeadState, LinearForce};
use crate::geometry::ImplicitCurve;

/// One RK4 step of length `h` from `state`, given `first`, the solve at
/// `state`. λ and `λN` reported are those of the first stage.
#[inline(always)]
pub fn rk4<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
    force: &LinearForce,
    mass: f64,
    gains: Gains,
    first: &Solved,
    h: f64,
) -> Result<Advance, SolveError> {
    let BeadState {
        position: x,
        velocity: v,
    } = state;
    let accel =
        |s: BeadState| solve(curve, s, force, mass, gains).map(|solved| solved.acceleration);
    let k1 = (v, first.acceleration);
    let s2 = BeadState {
        position: x + 0.5 * h * k1.0,
        velocity: v + 0.5 * h * k1.1,
    };
    let k2 = (s2.velocity, accel(s2)?);
    let s3 = BeadState {
        position: x + 0.5 * h * k2.0,
        velocity: v + 0.5 * h * k2.1,
    };
    let k3 = (s3.velocity, accel(s3)?);
    let s4 = BeadState {
        position: x + h * k3.0,
        velocity: v + h * k3.1,
    };
    let k4 = (s4.velocity, accel(s4)?);
    Ok(Advance {
        state: BeadState {
            position: x + h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0),
            velocity: v + h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1),
        },
        lambda: first.lambda,
        constraint_force: first.constraint_force,
    })
}
