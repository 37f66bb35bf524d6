//! Newton's method on `C`, shared by RATTLE's position solve and
//! post-stabilization projection, eq. (9).

use bevy::math::DVec2;

use super::solve::{SolveError, normal_length_squared};
use super::state::BeadState;
use crate::geometry::ImplicitCurve;

/// Tolerance on `|C|` for the Newton solves (RATTLE, projection), in units
/// of the wire's scale: a few ulps, which Newton's quadratic convergence
/// reaches in two or three iterations.
pub const NEWTON_TOLERANCE: f64 = 4.0 * f64::EPSILON;
/// Where rounding keeps `|C|` from reaching [`NEWTON_TOLERANCE`], a residual
/// below this (in wire scales) after the last iteration is accepted.
pub const NEWTON_ACCEPT: f64 = 1e-10;
/// The most Newton iterations a solve takes before it gives up.
pub(crate) const NEWTON_MAX_ITERATIONS: u32 = 20;

fn newton_done(residual: f64, scale: f64, last: bool) -> bool {
    residual <= NEWTON_TOLERANCE * scale || (last && residual <= NEWTON_ACCEPT * scale)
}

/// Newton's method on `s ↦ C(base + s dir)`: the root `s`.
pub(crate) fn newton_along<C: ImplicitCurve + ?Sized>(
    curve: &C,
    base: DVec2,
    dir: DVec2,
) -> Result<f64, SolveError> {
    let scale = curve.scale().max(f64::MIN_POSITIVE);
    let mut s = 0.0;
    let mut residual = f64::INFINITY;
    for i in 0..=NEWTON_MAX_ITERATIONS {
        let p = base + s * dir;
        let g = curve.geometry(p);
        residual = g.c.abs();
        if newton_done(residual, scale, i == NEWTON_MAX_ITERATIONS) {
            return Ok(s);
        }
        if i == NEWTON_MAX_ITERATIONS {
            break;
        }
        let slope = g.normal.dot(dir);
        if !(slope.is_finite() && slope.abs() > 1e-300) {
            return Err(SolveError::Singular { x: p.x, y: p.y });
        }
        s -= g.c / slope;
    }
    Err(SolveError::NoConvergence {
        iterations: NEWTON_MAX_ITERATIONS,
        residual,
    })
}

/// Post-stabilization, eq. (9): moves the position onto `C = 0` by Newton
/// steps along the local gradient, then removes the velocity's normal
/// component.
pub fn project<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
) -> Result<BeadState, SolveError> {
    let scale = curve.scale().max(f64::MIN_POSITIVE);
    let mut x = state.position;
    let mut converged = false;
    let mut residual = f64::INFINITY;
    for i in 0..=NEWTON_MAX_ITERATIONS {
        let g = curve.geometry(x);
        residual = g.c.abs();
        if newton_done(residual, scale, i == NEWTON_MAX_ITERATIONS) {
            converged = true;
            break;
        }
        if i == NEWTON_MAX_ITERATIONS {
            break;
        }
        let nn = normal_length_squared(g.normal, x)?;
        x -= (g.c / nn) * g.normal;
    }
    if !converged {
        return Err(SolveError::NoConvergence {
            iterations: NEWTON_MAX_ITERATIONS,
            residual,
        });
    }
    let n = curve.gradient(x);
    let nn = normal_length_squared(n, x)?;
    let v = state.velocity - (n.dot(state.velocity) / nn) * n;
    Ok(BeadState {
        position: x,
        velocity: v,
    })
}
