//! RATTLE for one bead on one wire, eq. (8), written once over [`Lane`]
//! for one bead and for the batched lanes. An island's RATTLE solves for
//! all its rows' multipliers at once (a matrix solve in each Newton step
//! and in the velocity solve), so its step is its own.

use super::newton::{Root, WireAt, newton_along};
use super::projection::{TrackAt, newton_error};
use super::settings::Gains;
use super::solve::{
    InFrame, SolveError, in_frame, normal_length_squared, resistance, singular, solve_on,
};
use super::state::{Advance, BeadState, LinearForce, LinearForceLanes};
use crate::geometry::{Coordinates, FixedTrack, ImplicitCurve, Track};
use crate::lane::{Lane, Vector};

/// One RATTLE step of length `h`: the position solve by Newton along
/// `N₀`, then the velocity solve, linear in μ. λ reported is the mean of
/// the two multipliers, `λN` the mean of their forces.
pub fn rattle<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
    force: &LinearForce,
    mass: f64,
    h: f64,
) -> Result<Advance, SolveError> {
    rattle_on(&FixedTrack(curve), 0.0, state, force, mass, h)
}

/// [`rattle`] on a wire that may move, the step starting at time `t`:
/// the position solve meets `C(x₁, t + h) = 0`, the velocity solve
/// `∇C·(v₁ − w(x₁)) = 0` at `t + h`, the wire's own velocity `w` taking
/// the place of `−∂C/∂t`.
pub(crate) fn rattle_on<V: Coordinates, T: Track<V> + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState<V>,
    force: &LinearForce<V>,
    mass: f64,
    h: f64,
) -> Result<Advance<V>, SolveError> {
    let BeadState {
        position: x0,
        velocity: v0,
    } = state;
    let n0 = track.geometry(t, x0).normal;
    normal_length_squared(n0, x0)?;
    // Friction and damping along the wire, held at their start value
    // through the step (eq. 17).
    let resisted = match track.surface() {
        Some((surface, sliding)) => {
            let InFrame {
                relative, applied, ..
            } = in_frame(track, t, state, force.at(x0), mass);
            let lambda = solve_on(track, t, state, force, mass, Gains::NONE)?.lambda;
            resistance(surface, sliding, n0, relative, applied, lambda)
        }
        None => V::ZERO,
    };
    let wire = TrackAt::new(track, t + h);
    let step = rattle_lanes(
        &wire,
        (x0, v0),
        n0,
        &force.lanes(),
        resisted,
        mass,
        h,
        wire.scale(),
        true,
    );
    let x1 = step.x;
    if !step.root.found {
        return Err(newton_error(&step.root, x1));
    }
    if !step.end_usable {
        return Err(singular(x1));
    }
    Ok(Advance {
        state: BeadState {
            position: x1,
            velocity: step.v,
        },
        lambda: step.lambda,
        constraint_force: step.constraint_force,
    })
}

/// What [`rattle_lanes`] returns in each lane.
pub(crate) struct Rattled<T: Lane, V, A> {
    /// The new position.
    pub(crate) x: V,
    /// The new velocity.
    pub(crate) v: V,
    /// The mean of the position and velocity multipliers.
    pub(crate) lambda: T,
    /// The mean of their forces.
    pub(crate) constraint_force: V,
    /// The position solve: found where the new position meets the wire,
    /// and the wire there.
    pub(crate) root: Root<T, T, A>,
    /// The lanes where the normal at the new position is usable.
    pub(crate) end_usable: T::Mask,
}

/// RATTLE's unconstrained position, eq. (8): `x₀ + h v₀ + h²/(2m) f₀`
/// from `(x0, v0)` for a bead of mass `m` under the force `f0`; for a
/// lone bead, the lanes and each bead of an island.
#[inline(always)]
pub(crate) fn rattle_drift<T: Lane, V: Vector<T>>((x0, v0): (V, V), f0: V, m: T, h: T) -> V {
    x0.plus(h, v0).plus(h * h / (m.splat(2.0) * m), f0)
}

/// RATTLE's second half kick, eq. (8): `v + h/(2m) f₁` on the mean
/// velocity `v = (x₁ − x₀)/h` of a bead of mass `m` under the force `f1`
/// at the new position, before the velocity solve; for a lone bead, the
/// lanes and each bead of an island.
#[inline(always)]
pub(crate) fn rattle_half_kick<T: Lane, V: Vector<T>>(v: V, f1: V, m: T, h: T) -> V {
    v.plus(h / (m.splat(2.0) * m), f1)
}

/// Eq. (8) on lanes, for one bead and for the batched lanes: from
/// `(x0, v0)`, where the normal is `n0`, a step of length `h` for a bead
/// of mass `m` under `force` and the force `resisted` along the wire (held
/// through the step) onto `wire` at the step's end, of size `scale`, in
/// the lanes `active`. The position solve is Newton along `n0` from the
/// unconstrained point; the velocity solve is linear in μ, relative to the
/// wire's own velocity.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn rattle_lanes<T: Lane, W: WireAt<T>>(
    wire: &W,
    (x0, v0): (W::V, W::V),
    n0: W::V,
    force: &LinearForceLanes<T, W::V>,
    resisted: W::V,
    m: T,
    h: T,
    scale: T,
    active: T::Mask,
) -> Rattled<T, W::V, W::At> {
    let two_m = m.splat(2.0) * m;
    let free = rattle_drift((x0, v0), force.at(x0) + resisted, m, h);
    // Newton's last point is `free + s n0`, the new position.
    let root = newton_along(wire, free, n0, scale, active);
    let s = root.root;
    let x1 = free.plus(s, n0);
    let lambda = two_m * s / (h * h);
    let v_half = (x1 - x0).div(h);
    let n1 = W::normal(&root.at);
    let (nn1, end_usable) = W::normal_length_squared(&root.at);
    let w = rattle_half_kick(v_half, force.at(x1) + resisted, m, h);
    let mu_scaled = -n1.dot(w - wire.velocity(x1)) / nn1;
    let v1 = w.plus(mu_scaled, n1);
    let mu = two_m * mu_scaled / h;
    let half = m.splat(0.5);
    Rattled {
        x: x1,
        v: v1,
        lambda: half * (lambda + mu),
        constraint_force: (n0.scale(lambda) + n1.scale(mu)).scale(half),
        root,
        end_usable,
    }
}
