//! The restores that complete a projection: the speed of eq. (10) after an
//! Euler step, the energy of eq. (11) after RK4. The scale factors and one
//! bead's targets are written once over [`Lane`], for one bead and for the
//! batched lanes; an island scales all its beads by one factor from the
//! same [`kinetic_scale`] and [`energy_scale`], its targets summed over its
//! beads (and its springs), and takes the kick's part off the constraints
//! away by a matrix solve where a lone bead removes its normal component.

use super::projection::{along_wire, tangential, wire_velocity};
use super::settings::Gains;
use super::solve::{SolveError, resistance, solve_on};
use super::state::{BeadState, LinearForce, LinearForceLanes};
use crate::geometry::{Coordinates, Track};
use crate::lane::{Lane, Vector};

/// The largest relative change of speed eq. (11) makes: a fourth-order
/// step's energy error is far below it; a larger mismatch means a bead at
/// a turning point or at rest, where the ratio of two near-zero kinetic
/// energies says nothing, and the velocity is left as projected.
pub const ENERGY_CORRECTION_LIMIT: f64 = 1e-3;

/// Eq. (10): the factor that scales a projected velocity of kinetic
/// energy `kinetic_now` to the kinetic energy `kinetic_target`; 1 where
/// either is zero or not finite (nothing to scale, or nothing to scale to).
#[inline(always)]
pub(crate) fn kinetic_scale<T: Lane>(kinetic_target: T, kinetic_now: T) -> T {
    let ratio = kinetic_target / kinetic_now;
    let scales = ratio.is_finite() & ratio.gt(ratio.splat(0.0));
    T::select(scales, ratio.sqrt(), ratio.splat(1.0))
}

/// Eq. (11): the factor that brings a projected velocity of kinetic energy
/// `kinetic_now` to the energy balance `kinetic_target` of a conservative
/// system, or 1 where the change would exceed
/// [`ENERGY_CORRECTION_LIMIT`].
#[inline(always)]
pub(crate) fn energy_scale<T: Lane>(kinetic_target: T, kinetic_now: T) -> T {
    let scale = kinetic_scale(kinetic_target, kinetic_now);
    let one = scale.splat(1.0);
    let small = (scale - one).abs_le(scale.splat(ENERGY_CORRECTION_LIMIT));
    T::select(small, scale, one)
}

/// Eq. (10) for one bead: the factor that gives the projected velocity
/// `now` (relative to the wire) the speed of `relative + h kick`, the
/// start's velocity relative to the wire plus the step's kick along it.
#[inline(always)]
pub(crate) fn speed_scale<T: Lane, V: Vector<T>>(relative: V, kick: V, h: T, now: V) -> T {
    let moved = relative.plus(h, kick);
    kinetic_scale(moved.dot(moved), now.dot(now))
}

/// Eq. (11) for one bead of mass `m` under `force`: the factor that gives
/// the projected state `(xp, vp)` the energy of the start `(x0, v0)`,
/// kinetic plus the potential of the linear force of eq. (5).
#[inline(always)]
pub(crate) fn bead_energy_scale<T: Lane, V: Vector<T>>(
    force: &LinearForceLanes<T, V>,
    m: T,
    (x0, v0): (V, V),
    (xp, vp): (V, V),
) -> T {
    let half = m.splat(0.5);
    let target = half * m * v0.dot(v0) + force.potential(x0) - force.potential(xp);
    energy_scale(target, half * m * vp.dot(vp))
}

/// What completes one bead's projection after a step of length `h` from
/// `start` at time `t`, `projected` being where the projection put it.
///
/// After an Euler step (`euler`), eq. (10): `projected`'s velocity scaled
/// to the speed of `v₀ + h a_t`, the start velocity plus the step's kick
/// without its normal part (`a_t` the applied acceleration's component
/// along the wire at `x₀`, friction and damping included: the speed they
/// take away stays away). On a moving wire the same holds in the wire's
/// frame: relative velocities, and the frame's acceleration `a_w` taken
/// from the applied one.
///
/// After RK4, eq. (11): `projected`'s velocity scaled so that the energy
/// is the start's, kinetic plus the potential of the linear force of
/// eq. (5) (gravity and the drag spring). It keeps a conservative
/// system's energy: on a moving wire (which does work on the bead) or with
/// friction or damping (which take energy away) the projection is left as
/// it is.
///
/// Either way the velocity's normal component, which the scale multiplies
/// from rounding, is removed again.
#[allow(clippy::too_many_arguments)]
pub(crate) fn restore<V: Coordinates, T: Track<V> + ?Sized>(
    track: &T,
    t: f64,
    h: f64,
    euler: bool,
    start: BeadState<V>,
    projected: BeadState<V>,
    force: &LinearForce<V>,
    mass: f64,
) -> Result<BeadState<V>, SolveError> {
    let (x0, x1, t1) = (start.position, projected.position, t + h);
    let velocity = if euler {
        let (w0, w1) = (wire_velocity(track, t, x0), wire_velocity(track, t1, x1));
        let relative = start.velocity - w0;
        let mut applied = force.at(x0) / mass;
        if T::MOVES {
            applied -= track.twist(t).acceleration_at(x0, relative);
        }
        let normal = track.geometry(t, x0).normal;
        if let Some((surface, sliding)) = track.surface() {
            let lambda = solve_on(track, t, start, force, mass, Gains::NONE)?.lambda;
            let resisted = resistance(surface, sliding, normal, relative, applied * mass, lambda);
            applied += resisted / mass;
        }
        let kick = along_wire(normal, applied, x0)?;
        let now = projected.velocity - w1;
        let scale = speed_scale(relative, kick, h, now);
        w1 + now * scale
    } else if T::MOVES || track.surface().is_some_and(|(s, _)| s.resists()) {
        return Ok(projected);
    } else {
        let scale = bead_energy_scale(
            &force.lanes(),
            mass,
            (x0, start.velocity),
            (x1, projected.velocity),
        );
        projected.velocity * scale
    };
    Ok(BeadState {
        velocity: tangential(track, t1, x1, velocity)?,
        ..projected
    })
}
