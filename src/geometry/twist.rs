//! [`Twist`]: a rigid motion's velocity and acceleration at one instant,
//! in the plane or in space.

use bevy::math::DVec2;

use super::Coordinates;

/// A rigid motion at one instant, in the plane or in space: the velocity
/// and acceleration of a reference point and the angular velocity and
/// acceleration about it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Twist<V: Coordinates = DVec2> {
    /// The reference point (the wire's origin `p`).
    pub origin: V,
    /// `ṗ`.
    pub velocity: V,
    /// `ω`: counter-clockwise positive in the plane, along the axis
    /// (right-handed) in space.
    pub angular_velocity: V::Angular,
    /// `p̈`.
    pub acceleration: V,
    /// `ω̇`.
    pub angular_acceleration: V::Angular,
}

impl<V: Coordinates> Twist<V> {
    /// The velocity `w(x) = ṗ + ω × (x − p)` of the moving frame's point
    /// at `x` (`ω J (x − p)` in the plane).
    #[inline]
    pub fn velocity_at(&self, x: V) -> V {
        self.velocity + V::turn(self.angular_velocity, x - self.origin)
    }

    /// `a_w = p̈ + ω̇ × r + ω × (ω × r) + 2ω × v_r` (`r = x − p`; in the
    /// plane `p̈ + ω̇ J r − ω² r + 2ω J v_r`): the acceleration of the
    /// frame's point at `x` plus the Coriolis term for a body moving at
    /// `relative_velocity` in the frame.
    #[inline]
    pub fn acceleration_at(&self, x: V, relative_velocity: V) -> V {
        let r = x - self.origin;
        let w = self.angular_velocity;
        self.acceleration + V::turn(self.angular_acceleration, r) - V::centripetal(w, r)
            + V::turn(V::twice(w), relative_velocity)
    }
}
