//! The plain values a step works on: a bead's [`BeadState`] and the
//! [`LinearForce`] acting on it.

use bevy::math::DVec2;

use crate::geometry::Coordinates;
use crate::lane::{Lane, V2, Vector};

/// Position and velocity of one bead, in the plane (`DVec2`, the
/// default) or in space (`DVec3`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BeadState<V = DVec2> {
    /// Position.
    pub position: V,
    /// Velocity.
    pub velocity: V,
}

impl<V: Coordinates> BeadState<V> {
    /// Both vectors finite.
    pub fn is_finite(&self) -> bool {
        self.position.is_finite() && self.velocity.is_finite()
    }

    /// Kinetic and gravitational potential energy `(½ m |v|², -m g·x)`.
    pub fn energy(&self, mass: f64, gravity: V) -> (f64, f64) {
        (
            0.5 * mass * self.velocity.dot(self.velocity),
            -mass * gravity.dot(self.position),
        )
    }
}

/// An external force linearized about the step's starting position,
/// eq. (5): `f(x) = force - stiffness (x - at)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinearForce<V = DVec2> {
    /// The force at `at`.
    pub force: V,
    /// The isotropic stiffness `S` (a spring's k).
    pub stiffness: f64,
    /// Where `force` was evaluated.
    pub at: V,
}

impl<V: Coordinates> LinearForce<V> {
    /// A force that does not depend on position.
    pub fn constant(force: V) -> Self {
        Self {
            force,
            stiffness: 0.0,
            at: V::ZERO,
        }
    }

    /// The potential of the force, `U(x) = −force·(x − at) + ½ S |x − at|²`
    /// (so `f = −∇U`), zero at `at`: the force of eq. (5) is conservative.
    pub fn potential(&self, x: V) -> f64 {
        self.lanes().potential(x)
    }

    /// `f(x)`.
    #[inline]
    pub fn at(&self, x: V) -> V {
        self.lanes().at(x)
    }

    /// The force as the formulas over lanes take it.
    #[inline(always)]
    pub(crate) fn lanes(&self) -> LinearForceLanes<f64, V> {
        LinearForceLanes {
            force: self.force,
            stiffness: self.stiffness,
            at: self.at,
        }
    }
}

/// [`LinearForce`] on lanes, in the plane or in space.
#[derive(Clone, Copy)]
pub(crate) struct LinearForceLanes<T, V = V2<T>> {
    pub(crate) force: V,
    pub(crate) stiffness: T,
    pub(crate) at: V,
}

impl<T: Lane, V: Vector<T>> LinearForceLanes<T, V> {
    /// Eq. (5): `f(x) = force - stiffness (x - at)`.
    #[inline(always)]
    pub(crate) fn at(&self, x: V) -> V {
        self.force - (x - self.at).scale(self.stiffness)
    }

    /// The potential of eq. (5)'s force (see [`LinearForce::potential`]).
    #[inline(always)]
    pub(crate) fn potential(&self, x: V) -> T {
        let d = x - self.at;
        -self.force.dot(d) + self.stiffness.splat(0.5) * self.stiffness * d.dot(d)
    }
}

/// What an integrator hands back: the new state and the constraint force
/// it applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Advance<V = DVec2> {
    /// The new state.
    pub state: BeadState<V>,
    /// The constraint multiplier the step applied (for RATTLE the mean of
    /// its position and velocity multipliers).
    pub lambda: f64,
    /// The constraint force the step applied.
    pub constraint_force: V,
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn linear_force_reproduces_the_drag_spring() {
        let target = DVec2::new(2.0, 1.0);
        let k = 30.0;
        let at = DVec2::new(0.5, -0.5);
        let f = LinearForce {
            force: k * (target - at),
            stiffness: k,
            at,
        };
        let x = DVec2::new(-0.3, 0.8);
        let expect = k * (target - x);
        assert_relative_eq!(f.at(x).x, expect.x, epsilon = 1e-12);
        assert_relative_eq!(f.at(x).y, expect.y, epsilon = 1e-12);
    }
}
