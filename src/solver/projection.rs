//! Newton's method on `C`, shared by RATTLE's position solve and
//! post-stabilization projection, eq. (9), and the energy-restoring
//! velocity scale that completes the projection, eq. (10).

use bevy::math::DVec2;

use super::settings::Gains;
use super::solve::{SolveError, normal_length_squared, resistance, solve_on};
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
fn wire_velocity<T: Track + ?Sized>(track: &T, t: f64, x: DVec2) -> DVec2 {
    if T::MOVES {
        track.twist(t).velocity_at(x)
    } else {
        DVec2::ZERO
    }
}

/// `v` without the part of its normal component that the wire does not
/// share: `∇C·(v − w) = 0` afterwards.
fn tangential<T: Track + ?Sized>(
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
fn along_wire(n: DVec2, a: DVec2, x: DVec2) -> Result<DVec2, SolveError> {
    let nn = normal_length_squared(n, x)?;
    Ok(along(n.into(), nn, a.into()).into())
}

/// Eq. (10): the factor that scales a projected velocity of kinetic
/// energy `kinetic_now` to the kinetic energy `kinetic_target`; 1 where
/// either is zero or not finite (nothing to scale, or nothing to scale to).
pub(crate) fn kinetic_scale(kinetic_target: f64, kinetic_now: f64) -> f64 {
    let ratio = kinetic_target / kinetic_now;
    if ratio.is_finite() && ratio > 0.0 {
        ratio.sqrt()
    } else {
        1.0
    }
}

/// Eq. (10) for one bead after an Euler step of length `h` from `start`
/// at time `t`: `projected`'s velocity scaled to the speed of
/// `v₀ + h a_t`, the start velocity plus the step's kick without its
/// normal part (`a_t` the applied acceleration's component along the wire
/// at `x₀`), and its normal component, which the scale multiplies from
/// rounding, removed again. On a moving wire the same holds in the wire's
/// frame: relative velocities, and the frame's acceleration `a_w` taken
/// from the applied one.
pub(crate) fn restore_speed<T: Track + ?Sized>(
    track: &T,
    t: f64,
    start: BeadState,
    projected: BeadState,
    force: &super::state::LinearForce,
    mass: f64,
    h: f64,
) -> Result<BeadState, SolveError> {
    let (x0, x1, t1) = (start.position, projected.position, t + h);
    let (w0, w1) = (wire_velocity(track, t, x0), wire_velocity(track, t1, x1));
    let relative = start.velocity - w0;
    let mut applied = force.at(x0) / mass;
    if T::MOVES {
        applied -= track.twist(t).acceleration_at(x0, relative);
    }
    let normal = track.geometry(t, x0).normal;
    if let Some((surface, sliding)) = track.surface() {
        // Friction and damping are part of the kick: the speed they take
        // away stays away.
        let lambda = solve_on(track, t, start, force, mass, Gains::NONE)?.lambda;
        applied += resistance(surface, sliding, normal, relative, mass * applied, lambda) / mass;
    }
    let kick = along_wire(normal, applied, x0)?;
    let target = (relative + h * kick).length_squared();
    let now = projected.velocity - w1;
    let scale = kinetic_scale(target, now.length_squared());
    Ok(BeadState {
        velocity: tangential(track, t1, x1, w1 + scale * now)?,
        ..projected
    })
}

/// The largest relative change of speed eq. (11) makes: a fourth-order
/// step's energy error is far below it; a larger mismatch means a bead at
/// a turning point or at rest, where the ratio of two near-zero kinetic
/// energies says nothing, and the velocity is left as projected.
pub const ENERGY_CORRECTION_LIMIT: f64 = 1e-3;

/// Eq. (11): the factor that brings a projected velocity of kinetic energy
/// `kinetic_now` to the energy balance `kinetic_target` of a conservative
/// system, or 1 where the change would exceed
/// [`ENERGY_CORRECTION_LIMIT`].
pub(crate) fn energy_scale(kinetic_target: f64, kinetic_now: f64) -> f64 {
    let scale = kinetic_scale(kinetic_target, kinetic_now);
    if (scale - 1.0).abs() <= ENERGY_CORRECTION_LIMIT {
        scale
    } else {
        1.0
    }
}

/// Eq. (11) for one bead after an RK4 step from `start`: `projected`'s
/// velocity scaled so that the energy is the start's, kinetic plus the
/// potential of the linear force of eq. (5) (gravity and the drag spring),
/// and its normal component removed again.
pub(crate) fn restore_energy<T: Track + ?Sized>(
    track: &T,
    t: f64,
    start: BeadState,
    projected: BeadState,
    force: &super::state::LinearForce,
    mass: f64,
) -> Result<BeadState, SolveError> {
    let target = 0.5 * mass * start.velocity.length_squared() + force.potential(start.position)
        - force.potential(projected.position);
    let scale = energy_scale(target, 0.5 * mass * projected.velocity.length_squared());
    Ok(BeadState {
        velocity: tangential(track, t, projected.position, scale * projected.velocity)?,
        ..projected
    })
}
