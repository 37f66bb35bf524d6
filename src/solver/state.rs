//! The plain values a step works on: a bead's [`BeadState`] and the
//! [`LinearForce`] acting on it.

use bevy::math::DVec2;

use crate::lane::{Lane, V2, Vector};

/// Position and velocity of one bead.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BeadState {
    /// Position.
    pub position: DVec2,
    /// Velocity.
    pub velocity: DVec2,
}

impl BeadState {
    /// Both vectors finite.
    pub fn is_finite(&self) -> bool {
        self.position.is_finite() && self.velocity.is_finite()
    }

    /// Kinetic and gravitational potential energy `(½ m |v|², -m g·x)`.
    pub fn energy(&self, mass: f64, gravity: DVec2) -> (f64, f64) {
        (
            0.5 * mass * self.velocity.length_squared(),
            -mass * gravity.dot(self.position),
        )
    }
}

/// An external force linearized about the step's starting position,
/// eq. (5): `f(x) = force - stiffness (x - at)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinearForce {
    /// The force at `at`.
    pub force: DVec2,
    /// The isotropic stiffness `S` (a spring's k).
    pub stiffness: f64,
    /// Where `force` was evaluated.
    pub at: DVec2,
}

impl LinearForce {
    /// A force that does not depend on position.
    pub fn constant(force: DVec2) -> Self {
        Self {
            force,
            ..Self::default()
        }
    }

    /// The potential of the force, `U(x) = −force·(x − at) + ½ S |x − at|²`
    /// (so `f = −∇U`), zero at `at`: the force of eq. (5) is conservative.
    pub fn potential(&self, x: DVec2) -> f64 {
        self.lanes().potential(x.into())
    }

    /// `f(x)`.
    #[inline]
    pub fn at(&self, x: DVec2) -> DVec2 {
        self.lanes().at(x.into()).into()
    }

    /// The force as the formulas over lanes take it.
    #[inline(always)]
    pub(crate) fn lanes(&self) -> LinearForceLanes<f64> {
        LinearForceLanes {
            force: self.force.into(),
            stiffness: self.stiffness,
            at: self.at.into(),
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
pub struct Advance {
    /// The new state.
    pub state: BeadState,
    /// The constraint multiplier the step applied (for RATTLE the mean of
    /// its position and velocity multipliers).
    pub lambda: f64,
    /// The constraint force the step applied.
    pub constraint_force: DVec2,
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
