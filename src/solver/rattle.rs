//! RATTLE for one bead on one wire, eq. (8).

use super::Advance;
use super::projection::newton_along;
use super::solve::{SolveError, normal_length_squared};
use super::state::{BeadState, LinearForce};
use crate::geometry::ImplicitCurve;

/// One RATTLE step of length `h`: the position solve by Newton along
/// `N₀`, then the velocity solve, linear in μ. λ reported is the mean of
/// the two multipliers, `λN` the mean of their forces.
pub fn rattle<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
    force: &LinearForce,
    mass: f64,
    h: f64,
) -> Result<Advance, SolveError> {
    let BeadState {
        position: x0,
        velocity: v0,
    } = state;
    let n0 = curve.gradient(x0);
    normal_length_squared(n0, x0)?;
    let free = x0 + h * v0 + (h * h / (2.0 * mass)) * force.at(x0);
    let s = newton_along(curve, free, n0)?;
    let x1 = free + s * n0;
    let lambda = 2.0 * mass * s / (h * h);
    let v_half = (x1 - x0) / h;
    let n1 = curve.gradient(x1);
    let nn1 = normal_length_squared(n1, x1)?;
    let w = v_half + (h / (2.0 * mass)) * force.at(x1);
    let mu_scaled = -n1.dot(w) / nn1;
    let v1 = w + mu_scaled * n1;
    let mu = 2.0 * mass * mu_scaled / h;
    Ok(Advance {
        state: BeadState {
            position: x1,
            velocity: v1,
        },
        lambda: 0.5 * (lambda + mu),
        constraint_force: 0.5 * (lambda * n0 + mu * n1),
    })
}
