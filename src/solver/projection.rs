//! Post-stabilization, eq. (9), for one bead on a wire that may move: the
//! Newton iteration of `newton` run on the wire at one time, and the
//! velocity's normal part removed after it. The restores that complete the
//! projection, eqs. (10) and (11), are in `restore`.

use bevy::math::DVec2;

use super::newton::{Root, WireAt, newton_onto, tangential as tangential_on};
use super::solve::{SolveError, normal_length_squared};
use super::state::BeadState;
use super::wire_normal::along;
use crate::geometry::{FixedTrack, Geometry, ImplicitCurve, Track};
use crate::lane::V2;

/// A [`Track`] at time `t`, as the Newton iterations of `newton` see a
/// wire.
pub(crate) struct TrackAt<'a, T: ?Sized> {
    /// The wire.
    pub(crate) track: &'a T,
    /// The time it is taken at.
    pub(crate) t: f64,
}

impl<T: Track + ?Sized> TrackAt<'_, T> {
    /// The wire's scale, as the Newton solves take it (never zero).
    #[inline(always)]
    pub(crate) fn scale(&self) -> f64 {
        self.track.scale().max(f64::MIN_POSITIVE)
    }
}

impl<T: Track + ?Sized> WireAt<f64> for TrackAt<'_, T> {
    type V = V2<f64>;
    type At = Geometry;
    #[inline(always)]
    fn at(&self, p: V2<f64>) -> Geometry {
        self.track.geometry(self.t, p.into())
    }
    #[inline(always)]
    fn c(at: &Geometry) -> f64 {
        at.c
    }
    #[inline(always)]
    fn normal(at: &Geometry) -> V2<f64> {
        at.normal.into()
    }
    #[inline(always)]
    fn select(mask: bool, a: Geometry, b: Geometry) -> Geometry {
        if mask { a } else { b }
    }
    #[inline(always)]
    fn velocity(&self, p: V2<f64>) -> V2<f64> {
        wire_velocity(self.track, self.t, p.into()).into()
    }
}

/// Why a Newton iteration on one bead did not find its root (`point` the
/// last point it reached): it ran out of iterations, or it met a singular
/// point there.
pub(crate) fn newton_error<P, A>(root: &Root<f64, P, A>, point: DVec2) -> SolveError {
    if root.running {
        SolveError::NoConvergence {
            iterations: super::newton::NEWTON_MAX_ITERATIONS,
            residual: root.residual,
        }
    } else {
        SolveError::Singular {
            x: point.x,
            y: point.y,
        }
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

/// [`project`] onto a wire that may move, at time `t`: the velocity keeps
/// the wire's own normal velocity, so `Ċ = ∇C·(ẋ − w) = 0`.
pub(crate) fn project_on<T: Track + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState,
) -> Result<BeadState, SolveError> {
    let wire = TrackAt { track, t };
    let x = V2::from(state.position);
    let onto = newton_onto(&wire, x, wire.at(x), wire.scale(), true);
    let position = DVec2::from(onto.root);
    if !onto.found {
        return Err(newton_error(&onto, position));
    }
    let (velocity, usable) = tangential_on(&wire, &onto.at, onto.root, state.velocity.into());
    if !usable {
        return Err(SolveError::Singular {
            x: position.x,
            y: position.y,
        });
    }
    Ok(BeadState {
        position,
        velocity: velocity.into(),
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
    let wire = TrackAt { track, t };
    let (v, usable) = tangential_on(&wire, &wire.at(x.into()), x.into(), v.into());
    if usable {
        Ok(v.into())
    } else {
        Err(SolveError::Singular { x: x.x, y: x.y })
    }
}

/// `a` without its component along `n`.
pub(super) fn along_wire(n: DVec2, a: DVec2, x: DVec2) -> Result<DVec2, SolveError> {
    let nn = normal_length_squared(n, x)?;
    Ok(along(n, nn, a))
}
