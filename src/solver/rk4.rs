//! Classical fourth-order Runge–Kutta with λ solved at every stage, eq. (7).

use super::settings::Gains;
use super::solve::{SolveError, Solved, solve_on};
use super::state::{Advance, BeadState, LinearForce};
use crate::geometry::{Coordinates, FixedTrack, ImplicitCurve, Track};
use crate::lane::{Lane, V2, Vector};

/// The acceleration at each later stage of eq. (7): eq. (4) solved afresh.
/// A trait rather than a closure, so that the batched step's stages are
/// inlined into its AVX2 function.
pub(crate) trait Stages<T, V = V2<T>> {
    /// Why a stage cannot be solved.
    type Error;
    /// The acceleration at `(x, v)`, a fraction `at` of the step after its
    /// start (½, ½, then 1).
    fn acceleration(&mut self, x: V, v: V, at: f64) -> Result<V, Self::Error>;
}

/// The later stages of eq. (7): where each is taken (a fraction of the
/// step after its start, along the previous stage's derivative) and the
/// weight of its derivative in the step's sum (the first stage's is 1).
pub(crate) const RK4_STAGES: [(f64, f64); 3] = [(0.5, 2.0), (0.5, 2.0), (1.0, 1.0)];

/// `(x, v) + t (dx, dv)`: a stage's state from the step's start and the
/// previous stage's derivative (`t` the stage's fraction of the step
/// times `h`), a stage's derivative added to the sum at its weight, and
/// the step's end from the sum (`t = h/6`).
#[inline(always)]
pub(crate) fn rk4_plus<T: Lane, V: Vector<T>>((x, v): (V, V), t: T, (dx, dv): (V, V)) -> (V, V) {
    (x.plus(t, dx), v.plus(t, dv))
}

/// Eq. (7) on lanes: one step of length `h` from `(x, v)` with `a` the
/// acceleration there; `stages` gives the acceleration at each later stage,
/// or stops the step with its error.
#[inline(always)]
pub(crate) fn rk4_lanes<T: Lane, V: Vector<T>, S: Stages<T, V>>(
    x: V,
    v: V,
    a: V,
    h: T,
    stages: &mut S,
) -> Result<(V, V), S::Error> {
    // The stages written out: the batched step runs faster so than with a
    // loop over them.
    let [(at2, w2), (at3, w3), (at4, w4)] = RK4_STAGES;
    let (x2, v2) = rk4_plus((x, v), h.splat(at2) * h, (v, a));
    let a2 = stages.acceleration(x2, v2, at2)?;
    let (x3, v3) = rk4_plus((x, v), h.splat(at3) * h, (v2, a2));
    let a3 = stages.acceleration(x3, v3, at3)?;
    let (x4, v4) = rk4_plus((x, v), h.splat(at4) * h, (v3, a3));
    let a4 = stages.acceleration(x4, v4, at4)?;
    let sum = rk4_plus((v, a), h.splat(w2), (v2, a2));
    let sum = rk4_plus(sum, h.splat(w3), (v3, a3));
    let sum = rk4_plus(sum, h.splat(w4), (v4, a4));
    Ok(rk4_plus((x, v), h / h.splat(6.0), sum))
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
    rk4_on(&FixedTrack(curve), 0.0, state, force, mass, gains, first, h)
}

/// [`rk4`] on a wire that may move, the step starting at time `t`: each
/// stage is solved at its own time.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn rk4_on<V: Coordinates, T: Track<V> + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState<V>,
    force: &LinearForce<V>,
    mass: f64,
    gains: Gains,
    first: &Solved<V>,
    h: f64,
) -> Result<Advance<V>, SolveError> {
    let mut stages = TrackStages {
        track,
        start: t,
        h,
        force,
        mass,
        gains,
    };
    let (x, v, a) = (state.position, state.velocity, first.acceleration);
    let (x1, v1) = rk4_lanes(x, v, a, h, &mut stages)?;
    Ok(Advance {
        state: BeadState {
            position: x1,
            velocity: v1,
        },
        lambda: first.lambda,
        constraint_force: first.constraint_force,
    })
}

/// The stages of one bead on any wire: [`solve_on`] at each, at its time.
struct TrackStages<'a, T: ?Sized, V> {
    track: &'a T,
    start: f64,
    h: f64,
    force: &'a LinearForce<V>,
    mass: f64,
    gains: Gains,
}

impl<V: Coordinates, T: Track<V> + ?Sized> Stages<f64, V> for TrackStages<'_, T, V> {
    type Error = SolveError;
    #[inline(always)]
    fn acceleration(&mut self, x: V, v: V, at: f64) -> Result<V, SolveError> {
        let stage = BeadState {
            position: x,
            velocity: v,
        };
        let t = self.start + at * self.h;
        solve_on(self.track, t, stage, self.force, self.mass, self.gains)
            .map(|solved| solved.acceleration)
    }
}
