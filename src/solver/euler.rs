//! The two Euler steps of eq. (6): explicit (`x` first) and semi-implicit
//! (`v` first, the assignment's).

use super::method::Method;
use super::solve::Solved;
use super::state::{Advance, BeadState};
use crate::geometry::Coordinates;
use crate::lane::{Lane, Vector};

/// Which Euler step a method takes: the one place a method is read for
/// it, by the lone bead, the lanes, an island and a bead in flight.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Euler {
    /// Explicit Euler, `x` first.
    Explicit,
    /// Semi-implicit Euler, `v` first (the assignment's).
    SemiImplicit,
}

impl Euler {
    /// The Euler step `method` takes; `None` for RK4 and RATTLE.
    pub(crate) fn of(method: Method) -> Option<Self> {
        match method {
            Method::ExplicitEuler(_) => Some(Self::Explicit),
            Method::SemiImplicitEuler(_) => Some(Self::SemiImplicit),
            Method::Rk4(_) | Method::Rattle => None,
        }
    }

    /// The step on lanes from `(x, v)` with acceleration `a` over `h`.
    #[inline(always)]
    pub(crate) fn lanes<T: Lane, V: Vector<T>>(self, x: V, v: V, a: V, h: T) -> (V, V) {
        match self {
            Self::Explicit => explicit_euler_lanes(x, v, a, h),
            Self::SemiImplicit => semi_implicit_euler_lanes(x, v, a, h),
        }
    }

    /// The step of one bead from `state` with the start's solve `first`.
    #[inline(always)]
    pub(crate) fn advance<V: Coordinates>(
        self,
        state: BeadState<V>,
        first: &Solved<V>,
        h: f64,
    ) -> Advance<V> {
        let (x, v, a) = (state.position, state.velocity, first.acceleration);
        advance(first, self.lanes(x, v, a, h))
    }
}

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

/// Wraps a step of one bead as an [`Advance`].
#[inline(always)]
fn advance<V: Coordinates>(first: &Solved<V>, (position, velocity): (V, V)) -> Advance<V> {
    Advance {
        state: BeadState { position, velocity },
        lambda: first.lambda,
        constraint_force: first.constraint_force,
    }
}

/// Explicit Euler: `x₁ = x₀ + h v₀`, `v₁ = v₀ + h a₀`.
#[inline(always)]
pub fn explicit_euler<V: Coordinates>(
    state: BeadState<V>,
    first: &Solved<V>,
    h: f64,
) -> Advance<V> {
    Euler::Explicit.advance(state, first, h)
}

/// Semi-implicit (symplectic) Euler: `v₁ = v₀ + h a₀`, `x₁ = x₀ + h v₁`.
#[inline(always)]
pub fn semi_implicit_euler<V: Coordinates>(
    state: BeadState<V>,
    first: &Solved<V>,
    h: f64,
) -> Advance<V> {
    Euler::SemiImplicit.advance(state, first, h)
}
