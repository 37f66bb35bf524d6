//! Wires that move: [`WireMotion`] (a prescribed motion) and [`Twist`], a
//! rigid motion's velocity and acceleration at one instant. [`Track`] is
//! what the solver asks of a wire at a time `t`: [`FixedTrack`] for a wire
//! that stays put, [`MovingTrack`](super::MovingTrack) for one that follows
//! a [`PosePath`](super::PosePath).
//!
//! A wire placed by a moving pose has `C(x, t) = C_local(Rᵀ(t)(x − p(t)))`.
//! Its points move rigidly: the point of the wire at `x` has the velocity
//! `w(x) = ṗ + ω J(x − p)` (`J` the quarter turn), so `∂C/∂t = −∇C·w` and
//! `Ċ = ∇C·(ẋ − w)`. Differentiating again, with `v_r = ẋ − w(x)` the
//! bead's velocity relative to the wire,
//!
//! ```text
//! C̈ = v_rᵀ H v_r + ∇C·(ẍ − a_w),   a_w = p̈ + ω̇ J r − ω² r + 2ω J v_r,   r = x − p
//! ```
//!
//! `a_w` is the acceleration of the wire's point under the bead plus the
//! Coriolis term: in the wire's frame the bead sees a fixed wire and the
//! force `f − m a_w`. The solver uses exactly that.

use std::f64::consts::TAU;

use bevy::math::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use super::{
    Coordinates, Geometry, ImplicitCurve, ImplicitSurface, Placement, Pose, Surface, Twist,
};
use crate::validate::{ParamError, finite, finite_vector, positive};

/// A prescribed motion of a wire about its resting pose (scene field
/// `motion`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum WireMotion {
    /// The wire stays where it is placed.
    #[default]
    Fixed,
    /// The wire's origin at `position + amplitude · sin(2π f t)`.
    Oscillate(Oscillate),
    /// The wire turns about its origin at a constant rate.
    Spin(Spin),
}

/// See [`WireMotion::Oscillate`]: in the plane (`DVec2`, the default) or
/// in space (`DVec3`, [`SpaceMotion::Oscillate`](super::SpaceMotion::Oscillate)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Oscillate<V = DVec2> {
    /// The displacement's amplitude (world units, every axis).
    pub amplitude: V,
    /// The frequency in Hz.
    pub frequency: f64,
}

impl<V: Coordinates> Oscillate<V> {
    /// The displacement `A sin(2π f t)` at `t`, its velocity and its
    /// acceleration, exact.
    pub fn at(&self, t: f64) -> (V, V, V) {
        let w = TAU * self.frequency;
        let (s, c) = (w * t).sin_cos();
        (
            self.amplitude * s,
            self.amplitude * (w * c),
            self.amplitude * (-w * w * s),
        )
    }
}

/// See [`WireMotion::Spin`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spin {
    /// Radians per second, counter-clockwise positive.
    pub angular_velocity: f64,
}

impl WireMotion {
    /// Checks that every number is finite and a frequency positive.
    pub fn validate(&self) -> Result<(), ParamError> {
        match self {
            Self::Fixed => Ok(()),
            Self::Oscillate(o) => {
                finite_vector("oscillation amplitude", o.amplitude)?;
                positive("oscillation frequency", o.frequency).map(drop)
            }
            Self::Spin(s) => finite("angular velocity", s.angular_velocity).map(drop),
        }
    }

    /// Whether the wire moves at all.
    pub fn moves(&self) -> bool {
        match self {
            Self::Fixed => false,
            Self::Oscillate(o) => o.amplitude != DVec2::ZERO,
            Self::Spin(s) => s.angular_velocity != 0.0,
        }
    }

    /// The pose at time `t` of a wire resting at `base`, and its twist,
    /// exact (no differencing).
    pub fn at(&self, base: Pose, t: f64) -> (Pose, Twist) {
        match self {
            Self::Fixed => (base, Twist::default()),
            Self::Oscillate(o) => {
                let (offset, velocity, acceleration) = o.at(t);
                let origin = base.origin + offset;
                let pose = Pose { origin, ..base };
                let twist = Twist {
                    origin,
                    velocity,
                    acceleration,
                    ..Twist::default()
                };
                (pose, twist)
            }
            Self::Spin(s) => {
                let turn = DVec2::from_angle(s.angular_velocity * t);
                let pose = Pose {
                    origin: base.origin,
                    rotation: turn.rotate(base.rotation),
                };
                let twist = Twist {
                    origin: base.origin,
                    angular_velocity: s.angular_velocity,
                    ..Twist::default()
                };
                (pose, twist)
            }
        }
    }
}

/// A wire over time, as the solver asks for it: its geometry where a bead
/// is at time `t`, and the velocity and acceleration of its points. `V`
/// is the plane's [`DVec2`] (a curve) or space's `DVec3` (a surface).
pub trait Track<V: Coordinates = DVec2> {
    /// Whether the wire may move. When false, `velocity_at` and
    /// `acceleration_at` are zero and the solver skips them.
    const MOVES: bool;
    /// `C`, `∇C` and the Hessian at `x` at time `t`.
    fn geometry(&self, t: f64, x: V) -> Geometry<V>;
    /// A characteristic length (see [`ImplicitCurve::scale`]).
    fn scale(&self) -> f64;
    /// The wire's twist at time `t`.
    fn twist(&self, t: f64) -> Twist<V>;
    /// Whether the wire ends (see [`ImplicitCurve::has_ends`]).
    fn has_ends(&self) -> bool;
    /// How far past an end the point nearest `x` is at time `t` (see
    /// [`ImplicitCurve::past_end`]).
    fn past_end(&self, t: f64, x: V) -> f64;
    /// Where the point of the wire that is at `x` at time `from` is at time
    /// `to` (a bead held still on the wire is carried there).
    fn carry(&self, x: V, from: f64, to: f64) -> V;
    /// Friction and damping along the wire, if it has any, and the
    /// direction the bead slid in at the step's start (see [`Rough`]).
    #[inline(always)]
    fn surface(&self) -> Option<(&Surface, V)> {
        None
    }
}

/// A wire with friction or damping along it: `track` with `surface`, for
/// one step of a bead that slid in the direction `sliding` at the step's
/// start (zero if it was at rest). Kinetic friction keeps opposing that
/// direction through the step, so that a bead friction stops within a step
/// reverses rather than chatters, and the step is cut where it stops.
pub struct Rough<'a, T: ?Sized, V: Coordinates = DVec2> {
    /// The wire.
    pub track: &'a T,
    /// What resists sliding on it.
    pub surface: &'a Surface,
    /// The bead's velocity along the wire (relative to it) at the step's
    /// start.
    pub sliding: V,
}

impl<V: Coordinates, T: Track<V> + ?Sized> Track<V> for Rough<'_, T, V> {
    const MOVES: bool = T::MOVES;
    #[inline(always)]
    fn geometry(&self, t: f64, x: V) -> Geometry<V> {
        self.track.geometry(t, x)
    }
    fn scale(&self) -> f64 {
        self.track.scale()
    }
    fn twist(&self, t: f64) -> Twist<V> {
        self.track.twist(t)
    }
    fn carry(&self, x: V, from: f64, to: f64) -> V {
        self.track.carry(x, from, to)
    }
    fn has_ends(&self) -> bool {
        self.track.has_ends()
    }
    fn past_end(&self, t: f64, x: V) -> f64 {
        self.track.past_end(t, x)
    }
    fn surface(&self) -> Option<(&Surface, V)> {
        Some((self.surface, self.sliding))
    }
}

/// Where the point of a wire at `x` when the wire sat at `from` is when
/// it sits at `to`: the same local point, placed again.
#[inline]
pub(crate) fn carry<V: Coordinates, P: Placement<V>>(from: &P, to: &P, x: V) -> V {
    to.to_world(from.to_local(x))
}

/// A wire that stays put: the curve (in the plane) or the surface (in
/// space) itself, in world coordinates.
pub struct FixedTrack<'a, C: ?Sized>(pub &'a C);

impl<S: ImplicitSurface + ?Sized> Track<DVec3> for FixedTrack<'_, S> {
    const MOVES: bool = false;
    #[inline(always)]
    fn geometry(&self, _t: f64, x: DVec3) -> Geometry<DVec3> {
        self.0.geometry(x)
    }
    fn scale(&self) -> f64 {
        self.0.scale()
    }
    fn twist(&self, _t: f64) -> Twist<DVec3> {
        Twist::default()
    }
    fn carry(&self, x: DVec3, _from: f64, _to: f64) -> DVec3 {
        x
    }
    fn has_ends(&self) -> bool {
        false
    }
    fn past_end(&self, _t: f64, _x: DVec3) -> f64 {
        f64::NEG_INFINITY
    }
}

impl<C: ImplicitCurve + ?Sized> Track for FixedTrack<'_, C> {
    const MOVES: bool = false;
    #[inline(always)]
    fn geometry(&self, _t: f64, x: DVec2) -> Geometry {
        self.0.geometry(x)
    }
    fn scale(&self) -> f64 {
        self.0.scale()
    }
    fn twist(&self, _t: f64) -> Twist {
        Twist::default()
    }
    fn carry(&self, x: DVec2, _from: f64, _to: f64) -> DVec2 {
        x
    }
    fn has_ends(&self) -> bool {
        self.0.has_ends()
    }
    fn past_end(&self, _t: f64, x: DVec2) -> f64 {
        self.0.past_end(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PoseHistory;
    use approx::assert_relative_eq;

    /// The prescribed motions' velocities and accelerations are the
    /// derivatives of their poses (central differences).
    #[test]
    fn prescribed_twists_are_the_derivatives_of_the_poses() {
        let base = Pose::new(DVec2::new(0.4, -0.2), 0.3);
        let x = DVec2::new(1.1, 0.7);
        let u = base.to_local(x);
        for motion in [
            WireMotion::Oscillate(Oscillate {
                amplitude: DVec2::new(0.1, 0.3),
                frequency: 1.7,
            }),
            WireMotion::Spin(Spin {
                angular_velocity: 2.3,
            }),
        ] {
            let t = 0.37;
            let h = 1e-5;
            // The world position of the frame's point with local coordinates u.
            let point = |t: f64| motion.at(base, t).0.to_world(u);
            let (pose, twist) = motion.at(base, t);
            assert_relative_eq!(pose.to_world(u).x, point(t).x);
            let fd_v = (point(t + h) - point(t - h)) / (2.0 * h);
            let fd_a = (point(t + h) - 2.0 * point(t) + point(t - h)) / (h * h);
            let x_t = point(t);
            let v = twist.velocity_at(x_t);
            let a = twist.acceleration_at(x_t, DVec2::ZERO);
            assert_relative_eq!(v.x, fd_v.x, epsilon = 1e-8);
            assert_relative_eq!(v.y, fd_v.y, epsilon = 1e-8);
            assert_relative_eq!(a.x, fd_a.x, epsilon = 1e-4);
            assert_relative_eq!(a.y, fd_a.y, epsilon = 1e-4);
        }
    }

    /// A history of poses on a quadratic motion reproduces it exactly, and
    /// on a sine to the orders its doc states.
    #[test]
    fn a_followed_history_interpolates_to_the_stated_orders() {
        let motion = WireMotion::Oscillate(Oscillate {
            amplitude: DVec2::new(0.0, 0.2),
            frequency: 1.0,
        });
        let base = Pose::IDENTITY;
        let errors = |h: f64| {
            let mut history = PoseHistory::at_rest(0.0, base);
            for k in 1..=10 {
                let t = k as f64 * h;
                history.push(t, h, motion.at(base, t).0);
            }
            let t = 9.5 * h;
            let (pose, twist) = history.at(t);
            let (exact_pose, exact) = motion.at(base, t);
            (
                (pose.origin - exact_pose.origin).length(),
                (twist.velocity - exact.velocity).length(),
                (twist.acceleration - exact.acceleration).length(),
            )
        };
        let (p1, v1, a1) = errors(0.002);
        let (p2, v2, a2) = errors(0.001);
        assert!((p1 / p2).log2() > 2.8, "pose order {}", (p1 / p2).log2());
        assert!(
            (v1 / v2).log2() > 1.7,
            "velocity order {}",
            (v1 / v2).log2()
        );
        assert!(
            (a1 / a2).log2() > 0.9,
            "acceleration order {}",
            (a1 / a2).log2()
        );
        // A spin across the ±π cut is followed without a jump.
        let mut history = PoseHistory::at_rest(0.0, Pose::new(DVec2::ZERO, 3.1));
        history.push(0.1, 0.1, Pose::new(DVec2::ZERO, 3.2));
        history.push(0.2, 0.1, Pose::new(DVec2::ZERO, 3.3));
        assert_relative_eq!(history.at(0.2).1.angular_velocity, 1.0, epsilon = 1e-9);
    }
}
