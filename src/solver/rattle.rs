//! RATTLE for one bead on one wire, eq. (8).

use super::projection::newton_along;
use super::settings::Gains;
use super::solve::{SolveError, normal_length_squared, resistance, solve_on};
use super::state::{Advance, BeadState, LinearForce};
use bevy::math::DVec2;

use crate::geometry::{FixedTrack, ImplicitCurve, Track};

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
    rattle_on(&FixedTrack(curve), 0.0, state, force, mass, h)
}

/// [`rattle`] on a wire that may move, the step starting at time `t`:
/// the position solve meets `C(x₁, t + h) = 0`, the velocity solve
/// `∇C·(v₁ − w(x₁)) = 0` at `t + h`, the wire's own velocity `w` taking
/// the place of `−∂C/∂t`.
pub(crate) fn rattle_on<T: Track + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState,
    force: &LinearForce,
    mass: f64,
    h: f64,
) -> Result<Advance, SolveError> {
    let BeadState {
        position: x0,
        velocity: v0,
    } = state;
    let t1 = t + h;
    let n0 = track.geometry(t, x0).normal;
    normal_length_squared(n0, x0)?;
    // Friction and damping along the wire, held at their start value
    // through the step (eq. 17).
    let resisted = match track.surface() {
        Some((surface, sliding)) => {
            let twist = track.twist(t);
            let relative = v0 - twist.velocity_at(x0);
            let applied = force.at(x0) - mass * twist.acceleration_at(x0, relative);
            let lambda = solve_on(track, t, state, force, mass, Gains::NONE)?.lambda;
            resistance(surface, sliding, n0, relative, applied, lambda)
        }
        None => DVec2::ZERO,
    };
    let free = x0 + h * v0 + (h * h / (2.0 * mass)) * (force.at(x0) + resisted);
    let s = newton_along(track, t1, free, n0)?;
    let x1 = free + s * n0;
    let lambda = 2.0 * mass * s / (h * h);
    let v_half = (x1 - x0) / h;
    let n1 = track.geometry(t1, x1).normal;
    let nn1 = normal_length_squared(n1, x1)?;
    let w = v_half + (h / (2.0 * mass)) * (force.at(x1) + resisted);
    let wire = if T::MOVES {
        track.twist(t1).velocity_at(x1)
    } else {
        DVec2::ZERO
    };
    let mu_scaled = -n1.dot(w - wire) / nn1;
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
