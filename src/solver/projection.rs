//! Post-stabilization, eq. (9), for one bead on a wire that may move: the
//! Newton iteration of `newton` run on the wire at one time, and the
//! velocity's normal part removed after it. The restores that complete the
//! projection, eqs. (10) and (11), are in `restore`.

use std::marker::PhantomData;

use bevy::math::DVec2;

use super::newton::{Root, WireAt, newton_onto, tangential as tangential_on};
use super::solve::{SolveError, normal_length_squared, singular};
use super::state::BeadState;
use super::wire_normal::along;
use crate::geometry::{Coordinates, FixedTrack, Geometry, ImplicitCurve, Track};

/// A [`Track`] at time `t`, as the Newton iterations of `newton` see a
/// wire, in the plane or in space.
pub(crate) struct TrackAt<'a, T: ?Sized, V = DVec2> {
    /// The wire.
    pub(crate) track: &'a T,
    /// The time it is taken at.
    pub(crate) t: f64,
    /// The coordinates.
    pub(crate) space: PhantomData<V>,
}

impl<'a, V: Coordinates, T: Track<V> + ?Sized> TrackAt<'a, T, V> {
    /// `track` at time `t`.
    #[inline(always)]
    pub(crate) fn new(track: &'a T, t: f64) -> Self {
        Self {
            track,
            t,
            space: PhantomData,
        }
    }

    /// The wire's scale, as the Newton solves take it (never zero).
    #[inline(always)]
    pub(crate) fn scale(&self) -> f64 {
        self.track.scale().max(f64::MIN_POSITIVE)
    }
}

impl<V: Coordinates, T: Track<V> + ?Sized> WireAt<f64> for TrackAt<'_, T, V> {
    type V = V;
    type At = Geometry<V>;
    #[inline(always)]
    fn at(&self, p: V) -> Geometry<V> {
        self.track.geometry(self.t, p)
    }
    #[inline(always)]
    fn c(at: &Geometry<V>) -> f64 {
        at.c
    }
    #[inline(always)]
    fn normal(at: &Geometry<V>) -> V {
        at.normal
    }
    #[inline(always)]
    fn select(mask: bool, a: Geometry<V>, b: Geometry<V>) -> Geometry<V> {
        if mask { a } else { b }
    }
    #[inline(always)]
    fn velocity(&self, p: V) -> V {
        wire_velocity(self.track, self.t, p)
    }
}

/// Why a Newton iteration on one bead did not find its root (`point` the
/// last point it reached): it ran out of iterations, or it met a singular
/// point there.
pub(crate) fn newton_error<P, A, V: Coordinates>(root: &Root<f64, P, A>, point: V) -> SolveError {
    if root.running {
        SolveError::NoConvergence {
            iterations: super::newton::NEWTON_MAX_ITERATIONS,
            residual: root.residual,
        }
    } else {
        singular(point)
    }
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

/// [`project`] onto a wire that may move, at time `t`, in the plane or in
/// space: the velocity keeps the wire's own normal velocity, so
/// `Ċ = ∇C·(ẋ − w) = 0`.
pub(crate) fn project_on<V: Coordinates, T: Track<V> + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState<V>,
) -> Result<BeadState<V>, SolveError> {
    let wire = TrackAt::new(track, t);
    let x = state.position;
    let onto = newton_onto(&wire, x, wire.at(x), wire.scale(), true);
    let position = onto.root;
    if !onto.found {
        return Err(newton_error(&onto, position));
    }
    let (velocity, usable) = tangential_on(&wire, &onto.at, onto.root, state.velocity);
    if !usable {
        return Err(singular(position));
    }
    Ok(BeadState { position, velocity })
}

/// The velocity of the wire's point at `x` at time `t` (zero on a fixed
/// wire).
#[inline(always)]
pub(super) fn wire_velocity<V: Coordinates, T: Track<V> + ?Sized>(track: &T, t: f64, x: V) -> V {
    if T::MOVES {
        track.twist(t).velocity_at(x)
    } else {
        V::ZERO
    }
}

/// `v` without the part of its normal component that the wire does not
/// share: `∇C·(v − w) = 0` afterwards.
pub(super) fn tangential<V: Coordinates, T: Track<V> + ?Sized>(
    track: &T,
    t: f64,
    x: V,
    v: V,
) -> Result<V, SolveError> {
    let wire = TrackAt::new(track, t);
    let (v, usable) = tangential_on(&wire, &wire.at(x), x, v);
    if usable { Ok(v) } else { Err(singular(x)) }
}

/// `a` without its component along `n`.
pub(super) fn along_wire<V: Coordinates>(n: V, a: V, x: V) -> Result<V, SolveError> {
    let nn = normal_length_squared(n, x)?;
    Ok(along(n, nn, a))
}
