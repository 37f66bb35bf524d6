//! Classical fourth-order Runge–Kutta with λ solved at every stage, eq. (7).

use super::Advance;
use super::settings::Gains;
use super::solve::{SolveError, Solved, solve};
use super::state::{BeadState, LinearForce};
use crate::geometry::ImplicitCurve;
use crate::lane::{Lane, V2};

/// Eq. (7) on lanes: one step of length `h` from `(x, v)` with `a` the
/// acceleration there; `accel` gives the acceleration at each later stage
/// (eq. 4 solved afresh), or stops the step with its error.
#[inline(always)]
pub(crate) fn rk4_lanes<T: Lane, E>(
    x: V2<T>,
    v: V2<T>,
    a: V2<T>,
    h: T,
    mut accel: impl FnMut(V2<T>, V2<T>) -> Result<V2<T>, E>,
) -> Result<(V2<T>, V2<T>), E> {
    let half = h.splat(0.5) * h;
    let v2 = v.plus(half, a);
    let a2 = accel(x.plus(half, v), v2)?;
    let v3 = v.plus(half, a2);
    let a3 = accel(x.plus(half, v2), v3)?;
    let v4 = v.plus(h, a3);
    let a4 = accel(x.plus(h, v3), v4)?;
    let (two, sixth) = (h.splat(2.0), h / h.splat(6.0));
    Ok((
        x.plus(sixth, v + v2.scale(two) + v3.scale(two) + v4),
        v.plus(sixth, a + a2.scale(two) + a3.scale(two) + a4),
    ))
}

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
    let accel = |x: V2<f64>, v: V2<f64>| {
        let stage = BeadState {
            position: x.into(),
            velocity: v.into(),
        };
        solve(curve, stage, force, mass, gains).map(|solved| solved.acceleration.into())
    };
    let (x, v, a) = (state.position, state.velocity, first.acceleration);
    let (x1, v1) = rk4_lanes(x.into(), v.into(), a.into(), h, accel)?;
    Ok(Advance {
        state: BeadState {
            position: x1.into(),
            velocity: v1.into(),
        },
        lambda: first.lambda,
        constraint_force: first.constraint_force,
    })
}
