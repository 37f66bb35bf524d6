//! Newton's method on `C`, shared by RATTLE's position solve and
//! post-stabilization projection, eq. (9), with its stopping test, and the
//! velocity's normal part removed after it. The restores that complete the
//! projection, eqs. (10) and (11), are in `restore`.

use bevy::math::DVec2;

use super::solve::{SolveError, normal_length_squared};
use super::state::BeadState;
use super::wire_normal::{along, usable};
use crate::geometry::{FixedTrack, ImplicitCurve, Track};
use crate::lane::{Lane, V2};

/// Tolerance on `|C|` for the Newton solves (RATTLE, projection), in units
/// of the wire's scale or of the point's largest coordinate, whichever is
/// larger: a few ulps, which Newton's quadratic convergence reaches in two
/// or three iterations, and below which rounding the coordinates keeps `C`
/// from going.
pub const NEWTON_TOLERANCE: f64 = 4.0 * f64::EPSILON;
/// Where rounding keeps `|C|` from reaching [`NEWTON_TOLERANCE`] (a bead
/// far from the origin beside its wire's scale), a residual below this (in
/// wire scales) is accepted once an iteration no longer halves it, or after
/// the last iteration.
pub const NEWTON_ACCEPT: f64 = 1e-10;
/// The most Newton iterations a solve takes before it gives up.
pub(crate) const NEWTON_MAX_ITERATIONS: u32 = 20;

/// The size of a point's largest coordinate: how far from the origin
/// rounding its coordinates reaches.
#[inline(always)]
pub(crate) fn reach<T: Lane>(p: V2<T>) -> T {
    p.x.abs().max(p.y.abs())
}

/// Whether the residual `|C|` of a Newton solve is within
/// [`NEWTON_TOLERANCE`] of the constraint's `scale` or of the `reach` of
/// the point it is evaluated at (rounding keeps `C` from going below a few
/// ulps of them).
#[inline(always)]
pub(crate) fn newton_within<T: Lane>(residual: T, scale: T, reach: T) -> T::Mask {
    residual.abs_le(residual.splat(NEWTON_TOLERANCE) * scale.max(reach))
}

/// Whether a Newton solve that has not reached [`newton_within`] takes
/// its residual `|C|` anyway: within [`NEWTON_ACCEPT`] of the constraint's
/// `scale` and stalled (no smaller than half the `previous` residual), or
/// at the `last` iteration.
#[inline(always)]
pub(crate) fn newton_accepted<T: Lane>(residual: T, previous: T, scale: T, last: bool) -> T::Mask {
    let accepted = residual.abs_le(residual.splat(NEWTON_ACCEPT) * scale);
    if last {
        accepted
    } else {
        accepted & residual.gt(residual.splat(0.5) * previous)
    }
}

/// Whether a Newton solve on one constraint is done at residual `|C|`,
/// after the `previous` residual, at a point of the given `reach`:
/// [`newton_within`] or [`newton_accepted`]. An island, with a residual
/// for each row, asks [`newton_within`] of every row and
/// [`newton_accepted`] of its worst row relative to that row's scale.
#[inline(always)]
pub(crate) fn newton_done<T: Lane>(
    residual: T,
    previous: T,
    scale: T,
    reach: T,
    last: bool,
) -> T::Mask {
    newton_within(residual, scale, reach) | newton_accepted(residual, previous, scale, last)
}

/// Newton's method on `s ↦ C(base + s dir, t)`: the root `s`.
pub(crate) fn newton_along<T: Track + ?Sized>(
    track: &T,
    t: f64,
    base: DVec2,
    dir: DVec2,
) -> Result<f64, SolveError> {
    let scale = track.scale().max(f64::MIN_POSITIVE);
    let mut s = 0.0;
    let mut residual = f64::INFINITY;
    for i in 0..=NEWTON_MAX_ITERATIONS {
        let p = base + s * dir;
        let g = track.geometry(t, p);
        let previous = residual;
        residual = g.c.abs();
        let last = i == NEWTON_MAX_ITERATIONS;
        if newton_done(residual, previous, scale, reach(p.into()), last) {
            return Ok(s);
        }
        if i == NEWTON_MAX_ITERATIONS {
            break;
        }
        let slope = g.normal.dot(dir);
        if !usable(slope.abs()) {
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
    project_on(&FixedTrack(curve), 0.0, state)
}

/// [`project`] onto a wire that may move, at time `t`: the velocity keeps
/// the wire's own normal velocity, so `Ċ = ∇C·(ẋ − w) = 0`.
pub(crate) fn project_on<T: Track + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState,
) -> Result<BeadState, SolveError> {
    let scale = track.scale().max(f64::MIN_POSITIVE);
    let mut x = state.position;
    let mut converged = false;
    let mut residual = f64::INFINITY;
    for i in 0..=NEWTON_MAX_ITERATIONS {
        let g = track.geometry(t, x);
        let previous = residual;
        residual = g.c.abs();
        let last = i == NEWTON_MAX_ITERATIONS;
        if newton_done(residual, previous, scale, reach(x.into()), last) {
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
    Ok(BeadState {
        position: x,
        velocity: tangential(track, t, x, state.velocity)?,
    })
}

/// The velocity of the wire's point at `x` at time `t` (zero on a fixed
/// wire).
#[inline(always)]
pub(super) fn wire_velocity<T: Track + ?Sized>(track: &T, t: f64, x: DVec2) -> DVec2 {
    if T::MOVES {
        track.twist(t).velocity_at(x)
    } else {
        DVec2::ZERO
    }
}

/// `v` without the part of its normal component that the wire does not
/// share: `∇C·(v − w) = 0` afterwards.
pub(super) fn tangential<T: Track + ?Sized>(
    track: &T,
    t: f64,
    x: DVec2,
    v: DVec2,
) -> Result<DVec2, SolveError> {
    let n = track.geometry(t, x).normal;
    let nn = normal_length_squared(n, x)?;
    let w = wire_velocity(track, t, x);
    Ok(v - DVec2::from(super::wire_normal::across(n.into(), nn, (v - w).into())))
}

/// `a` without its component along `n`.
pub(super) fn along_wire(n: DVec2, a: DVec2, x: DVec2) -> Result<DVec2, SolveError> {
    let nn = normal_length_squared(n, x)?;
    Ok(along(n.into(), nn, a.into()).into())
}
