//! The constraint force of eq. (3): λ for one bead on one wire, in closed
//! form.

use bevy::math::DVec2;

use super::friction;
use super::settings::Gains;
use super::state::{BeadState, LinearForce};
use super::wire_normal::{along, usable};
use crate::geometry::{Coordinates, FixedTrack, Geometry, ImplicitCurve, Surface, Track};
use crate::lane::{Lane, V2, Vector};

/// Why a step could not be taken.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// `∇C` vanishes (or is not finite) where the bead is: there is no
    /// normal to push along.
    #[error("the bead is at a singular point of its wire ({x}, {y}), where the normal ∇C vanishes")]
    Singular {
        /// x of the point.
        x: f64,
        /// y of the point.
        y: f64,
    },
    /// As [`SolveError::Singular`], for a bead in space.
    #[error(
        "the bead is at a singular point of its wire ({x}, {y}, {z}), where the normal ∇C vanishes"
    )]
    SingularInSpace {
        /// x of the point.
        x: f64,
        /// y of the point.
        y: f64,
        /// z of the point.
        z: f64,
    },
    /// The RATTLE or projection Newton iteration did not reach tolerance.
    #[error(
        "the constraint solve did not converge: |C| = {residual:e} after {iterations} iterations"
    )]
    NoConvergence {
        /// Newton iterations taken.
        iterations: u32,
        /// The remaining `|C|`.
        residual: f64,
    },
    /// An island was handed a different number of states or forces than
    /// it has beads.
    #[error("the island has {beads} beads but was given {states} states and {forces} forces")]
    WrongLength {
        /// The island's beads.
        beads: usize,
        /// The states given.
        states: usize,
        /// The forces given.
        forces: usize,
    },
    /// The new state has a NaN or infinite component.
    #[error("the state became non-finite")]
    NonFinite,
    /// The step left the bead farther off its wire than the bound: the
    /// simulation has blown up.
    #[error("the bead drifted {c:.3e} off its wire, past the bound {bound:.3e}")]
    DriftExceeded {
        /// The drift `C` after the step (before any projection).
        c: f64,
        /// The bound, in world units.
        bound: f64,
    },
}

/// The constraint force at one state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Solved<V = DVec2> {
    /// λ of eq. (3).
    pub lambda: f64,
    /// `λN`.
    pub constraint_force: V,
    /// `(f + λN)/m`.
    pub acceleration: V,
}

/// [`SolveError::Singular`] (or [`SolveError::SingularInSpace`]) for a
/// bead at the singular point `x` of its wire.
#[cold]
pub(crate) fn singular<V: Coordinates>(x: V) -> SolveError {
    let p = x.xyz();
    if V::DIMENSION == 2 {
        SolveError::Singular { x: p.x, y: p.y }
    } else {
        SolveError::SingularInSpace {
            x: p.x,
            y: p.y,
            z: p.z,
        }
    }
}

/// `|N|²` where the bead is at `x`, or [`SolveError::Singular`] where the
/// normal vanishes or is not finite.
#[inline(always)]
pub(crate) fn normal_length_squared<V: Coordinates>(normal: V, x: V) -> Result<f64, SolveError> {
    let nn = normal.dot(normal);
    if usable(nn) { Ok(nn) } else { Err(singular(x)) }
}

/// Eqs. (3) and (4) on lanes: what [`constraint_force`] returns.
#[derive(Clone, Copy)]
pub(crate) struct ConstraintForce<T, V = V2<T>> {
    /// `|N|²`.
    pub(crate) nn: T,
    /// λ.
    pub(crate) lambda: T,
    /// `(f + λN) / m`.
    pub(crate) acceleration: V,
}

/// λ of eq. (3) and the acceleration of eq. (4), written once for one
/// bead (`f64`) and for eight side by side: `n` is `∇C`, `hv` is `H ẋ`,
/// `c` is `C`, all where the bead is; `v` its velocity, `f` the force on
/// it, `m` its mass. The caller checks `nn` (a vanishing normal).
#[inline(always)]
pub(crate) fn constraint_force<T: Lane, V: Vector<T>>(
    n: V,
    hv: V,
    c: T,
    v: V,
    f: V,
    m: T,
    gains: Gains,
) -> ConstraintForce<T, V> {
    let vhv = v.dot(hv);
    let (alpha, beta) = (m.splat(gains.alpha), m.splat(gains.beta));
    let nn = n.dot(n);
    let lambda = (-m * vhv - m * alpha * c - m * beta * n.dot(v) - n.dot(f)) / nn;
    ConstraintForce {
        nn,
        lambda,
        // The reciprocal does not wait for λ; a division here would.
        acceleration: (f + n.scale(lambda)).scale(m.recip()),
    }
}

/// Eq. (3) where the wire's geometry is `g`, checked for a vanishing
/// normal.
#[inline(always)]
fn constraint_force_at<V: Coordinates>(
    g: &Geometry<V>,
    state: BeadState<V>,
    f: V,
    mass: f64,
    gains: Gains,
) -> Result<ConstraintForce<f64, V>, SolveError> {
    normal_length_squared(g.normal, state.position)?;
    let v = state.velocity;
    let hv = V::hessian_times(&g.hessian, v);
    Ok(constraint_force(g.normal, hv, g.c, v, f, mass, gains))
}

/// λ of eq. (3) for a bead of mass `mass` in `state` under the force `f`,
/// where the wire's geometry is `g`.
#[inline(always)]
pub fn lambda(
    g: &Geometry,
    state: BeadState,
    f: DVec2,
    mass: f64,
    gains: Gains,
) -> Result<f64, SolveError> {
    constraint_force_at(g, state, f, mass, gains).map(|s| s.lambda)
}

/// Solves eq. (3) at `state` and returns λ, `λN` and the acceleration.
#[inline(always)]
pub fn solve<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
    force: &LinearForce,
    mass: f64,
    gains: Gains,
) -> Result<Solved, SolveError> {
    solve_on(&FixedTrack(curve), 0.0, state, force, mass, gains)
}

/// Eq. (3) on a wire that may move, at time `t`: in the wire's frame the
/// bead has the relative velocity `v_r = ẋ − w(x)` and feels
/// `f − m a_w` (see [`Twist::acceleration_at`](crate::geometry::Twist::acceleration_at)),
/// so eq. (3) is solved with those, and `a_w` is added back to the
/// acceleration.
#[inline(always)]
pub(crate) fn solve_on<V: Coordinates, T: Track<V> + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState<V>,
    force: &LinearForce<V>,
    mass: f64,
    gains: Gains,
) -> Result<Solved<V>, SolveError> {
    let g = track.geometry(t, state.position);
    let f = force.at(state.position);
    if !T::MOVES && track.surface().is_none() {
        let solved = constraint_force_at(&g, state, f, mass, gains)?;
        return Ok(Solved {
            lambda: solved.lambda,
            constraint_force: g.normal * solved.lambda,
            acceleration: solved.acceleration,
        });
    }
    let InFrame {
        relative,
        frame,
        applied,
    } = in_frame(track, t, state, f, mass);
    let seen = BeadState {
        velocity: relative,
        ..state
    };
    let solved = constraint_force_at(&g, seen, applied, mass, gains)?;
    let mut acceleration = solved.acceleration + frame;
    if let Some((surface, sliding)) = track.surface() {
        acceleration +=
            resistance(surface, sliding, g.normal, relative, applied, solved.lambda) / mass;
    }
    Ok(Solved {
        lambda: solved.lambda,
        constraint_force: g.normal * solved.lambda,
        acceleration,
    })
}

/// A bead of mass `m` under the force `f`, seen from its wire's frame (see
/// [`in_frame`]).
pub(crate) struct InFrame<V = DVec2> {
    /// The bead's velocity relative to the wire, `v_r = ẋ − w(x)`.
    pub(crate) relative: V,
    /// The frame's acceleration `a_w` where the bead is.
    pub(crate) frame: V,
    /// The force the bead feels in the frame, `f − m a_w`.
    pub(crate) applied: V,
}

/// `state` of a bead of mass `mass` under the force `f`, seen from its
/// wire's frame at time `t`: for eq. (3) on a moving wire, RATTLE's and
/// static friction's force along the wire.
#[inline(always)]
pub(crate) fn in_frame<V: Coordinates, T: Track<V> + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState<V>,
    f: V,
    mass: f64,
) -> InFrame<V> {
    let twist = track.twist(t);
    let relative = state.velocity - twist.velocity_at(state.position);
    let frame = twist.acceleration_at(state.position, relative);
    InFrame {
        relative,
        frame,
        applied: f - frame * mass,
    }
}

/// Eq. (17): the force along the wire that friction and damping put on a
/// bead whose velocity relative to the wire is `relative`, pressed on it
/// with `|λ ∇C|`, under the applied force `applied` (in the wire's frame),
/// in a step that started sliding along `sliding`. Sliding, kinetic
/// friction `μk |λ∇C|` opposes the start's direction of sliding (taken
/// along the wire where the bead is) and damping the sliding itself; from
/// rest (`sliding` zero), static friction cancels the force along the wire
/// up to `μs |λ∇C|`, and past it kinetic friction opposes that force.
pub(crate) fn resistance<V: Coordinates>(
    surface: &Surface,
    sliding: V,
    normal: V,
    relative: V,
    applied: V,
    lambda: f64,
) -> V {
    let nn = normal.dot(normal);
    let along = |a: V| along(normal, nn, a);
    let press = friction::press(lambda, nn);
    let damping = friction::damping(surface.damping, along(relative));
    let direction = along(sliding);
    let speed = direction.dot(direction).sqrt();
    if speed > 0.0 {
        return damping + friction::kinetic(&surface.friction, press, direction, speed);
    }
    let pull = along(applied);
    let strength = pull.dot(pull).sqrt();
    if friction::holds(&surface.friction, strength, press) {
        -pull
    } else {
        friction::kinetic(&surface.friction, press, pull, strength)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Circle, Ellipse, Placed, Pose};
    use approx::assert_relative_eq;

    use crate::solver::test_support::G;

    #[test]
    fn lambda_on_circle_is_the_centripetal_and_gravity_balance() {
        // At the bottom of a unit circle moving at speed u: λ = -(m u²/r + m|g|)
        // (pointing inward, N points outward).
        let circle = Circle { radius: 1.0 };
        let u = 3.0;
        let state = BeadState {
            position: DVec2::new(0.0, -1.0),
            velocity: DVec2::new(u, 0.0),
        };
        let s = solve(
            &circle,
            state,
            &LinearForce::constant(2.0 * G),
            2.0,
            Gains::NONE,
        )
        .unwrap();
        assert_relative_eq!(s.lambda, -(2.0 * u * u + 2.0 * 9.81), epsilon = 1e-12);
        assert_relative_eq!(s.acceleration.y, u * u, epsilon = 1e-12);
    }

    #[test]
    fn baumgarte_lambda_makes_c_double_dot_follow_the_law() {
        // Check C̈ = -αC - βĊ numerically on an ellipse, off the wire, placed and rotated.
        let ellipse = Ellipse { a: 2.0, b: 1.0 };
        let placed = Placed {
            curve: &ellipse,
            pose: Pose::new(DVec2::new(0.5, 0.2), 0.4),
        };
        let state = BeadState {
            position: placed.pose.to_world(DVec2::new(1.2, 0.9)),
            velocity: DVec2::new(0.3, -0.8),
        };
        let force = LinearForce::constant(DVec2::new(0.7, -9.81));
        let (alpha, beta, m) = (50.0, 7.0, 1.5);
        let s = solve(&placed, state, &force, m, Gains { alpha, beta }).unwrap();
        let g = placed.geometry(state.position);
        let c_dot = g.normal.dot(state.velocity);
        let c_ddot = state.velocity.dot(g.hessian * state.velocity) + g.normal.dot(s.acceleration);
        assert_relative_eq!(c_ddot, -alpha * g.c - beta * c_dot, epsilon = 1e-12);
    }
}
