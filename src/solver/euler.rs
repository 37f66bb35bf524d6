//! The two Euler steps of eq. (6): explicit (`x` first) and semi-implicit
//! (`v` first, the assignment's).

use super::Advance;
use super::solve::Solved;
use super::state::BeadState;

/// Explicit Euler: `x₁ = x₀ + h v₀`, `v₁ = v₀ + h a₀`.
#[inline(always)]
pub fn explicit_euler(state: BeadState, first: &Solved, h: f64) -> Advance {
    Advance {
        state: BeadState {
            position: state.position + h * state.velocity,
            velocity: state.velocity + h * first.acceleration,
        },
        lambda: first.lambda,
        constraint_force: first.constraint_force,
    }
}

/// Semi-implicit (symplectic) Euler: `v₁ = v₀ + h a₀`, `x₁ = x₀ + h v₁`.
#[inline(always)]
pub fn semi_implicit_euler(state: BeadState, first: &Solved, h: f64) -> Advance {
    let v1 = state.velocity + h * first.acceleration;
    Advance {
        state: BeadState {
            position: state.position + h * v1,
            velocity: v1,
        },
        lambda: first.lambda,
        constraint_force: first.constraint_force,
    }
}
