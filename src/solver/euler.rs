//! The two Euler steps of eq. (6): explicit (`x` first) and semi-implicit
//! (`v` first, the assignment's).

use super::solve::Solved;
use super::state::{Advance, BeadState};
use crate::lane::{Lane, V2, Vector};

/// Explicit Euler on lanes: `x₁ = x₀ + h v₀`, `v₁ = v₀ + h a₀`.
#[inline(always)]
pub(crate) fn explicit_euler_lanes<T: Lane, V: Vector<T>>(x: V, v: V, a: V, h: T) -> (V, V) {
    (x.plus(h, v), v.plus(h, a))
}

/// Semi-implicit (symplectic) Euler on lanes: `v₁ = v₀ + h a₀`,
/// `x₁ = x₀ + h v₁`.
#[inline(always)]
pub(crate) fn semi_implicit_euler_lanes<T: Lane, V: Vector<T>>(x: V, v: V, a: V, h: T) -> (V, V) {
    let v1 = v.plus(h, a);
    (x.plus(h, v1), v1)
}

/// Wraps a step on one lane as an [`Advance`].
#[inline(always)]
fn advance(first: &Solved, (x, v): (V2<f64>, V2<f64>)) -> Advance {
    Advance {
        state: BeadState {
            position: x.into(),
            velocity: v.into(),
        },
        lambda: first.lambda,
        constraint_force: first.constraint_force,
    }
}

/// Explicit Euler: `x₁ = x₀ + h v₀`, `v₁ = v₀ + h a₀`.
#[inline(always)]
pub fn explicit_euler(state: BeadState, first: &Solved, h: f64) -> Advance {
    let (x, v, a) = (state.position, state.velocity, first.acceleration);
    advance(first, explicit_euler_lanes(x.into(), v.into(), a.into(), h))
}

/// Semi-implicit (symplectic) Euler: `v₁ = v₀ + h a₀`, `x₁ = x₀ + h v₁`.
#[inline(always)]
pub fn semi_implicit_euler(state: BeadState, first: &Solved, h: f64) -> Advance {
    let (x, v, a) = (state.position, state.velocity, first.acceleration);
    advance(
        first,
        semi_implicit_euler_lanes(x.into(), v.into(), a.into(), h),
    )
}
