//! Classical fourth-order Runge–Kutta with λ solved at every stage, eq. (7).

use super::Advance;
use super::settings::Gains;
use super::solve::{SolveError, Solved, solve};
use super::state::{BeadState, LinearForce};
use crate::geometry::ImplicitCurve;
use crate::lane::{Lane, V2};

/// The acceleration at each later stage of eq. (7): eq. (4) solved afresh.
/// A trait rather than a closure, so that the batched step's stages are
/// inlined into its AVX2 function.
pub(crate) trait Stages<T> {
    /// Why a stage cannot be solved.
    type Error;
    /// The acceleration at `(x, v)`.
    fn acceleration(&mut self, x: V2<T>, v: V2<T>) -> Result<V2<T>, Self::Error>;
}

/// Eq. (7) on lanes: one step of length `h` from `(x, v)` with `a` the
/// acceleration there; `stages` gives the acceleration at each later stage,
/// or stops the step with its error.
#[inline(always)]
pub(crate) fn rk4_lanes<T: Lane, S: Stages<T>>(
    x: V2<T>,
    v: V2<T>,
    a: V2<T>,
    h: T,
    stages: &mut S,
) -> Result<(V2<T>, V2<T>), S::Error> {
    let half = h.splat(0.5) * h;
    let v2 = v.plus(half, a);
    let a2 = stages.acceleration(x.plus(half, v), v2)?;
    let v3 = v.plus(half, a2);
    let a3 = stages.acceleration(x.plus(half, v2), v3)?;
    let v4 = v.plus(h, a3);
    let a4 = stages.acceleration(x.plus(h, v3), v4)?;
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
    let mut stages = CurveStages {
        curve,
        force,
        mass,
        gains,
    };
    let (x, v, a) = (state.position, state.velocity, first.acceleration);
    let (x1, v1) = rk4_lanes(x.into(), v.into(), a.into(), h, &mut stages)?;
    Ok(Advance {
        state: BeadState {
            position: x1.into(),
            velocity: v1.into(),
        },
        lambda: first.lambda,
        constraint_force: first.constraint_force,
    })
}

/// The stages of one bead on any curve: [`solve`] at each.
struct CurveStages<'a, C: ?Sized> {
    curve: &'a C,
    force: &'a LinearForce,
    mass: f64,
    gains: Gains,
}

impl<C: ImplicitCurve + ?Sized> Stages<f64> for CurveStages<'_, C> {
    type Error = SolveError;
    #[inline(always)]
    fn acceleration(&mut self, x: V2<f64>, v: V2<f64>) -> Result<V2<f64>, SolveError> {
        let stage = BeadState {
            position: x.into(),
            velocity: v.into(),
        };
        solve(self.curve, stage, self.force, self.mass, self.gains)
            .map(|solved| solved.acceleration.into())
    }
}
