//! Surfaces that move in space: [`SpaceMotion`], an oscillation of the
//! origin along a 3D amplitude or a spin about any axis through it. The
//! frame's velocity and acceleration are exact, and eq. (15) takes them in
//! its 3D form.

use bevy::math::{DQuat, DVec3};

use crate::geometry::{Oscillate, Pose3, Twist};
use crate::validate::{ParamError, finite, positive};

/// A prescribed motion of a surface about its resting pose.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum SpaceMotion {
    /// The surface stays where it is placed.
    #[default]
    Fixed,
    /// The surface's origin at `position + amplitude · sin(2π f t)`.
    Oscillate(Oscillate<DVec3>),
    /// The surface turns right-handed about `axis` through its origin at
    /// `angular_velocity` radians per second.
    Spin {
        /// Radians per second.
        angular_velocity: f64,
        /// The axis (any length but zero).
        axis: DVec3,
    },
}

impl SpaceMotion {
    /// Checks that every number is finite, a frequency positive and an
    /// axis not zero.
    pub fn validate(&self) -> Result<(), ParamError> {
        match self {
            Self::Fixed => Ok(()),
            Self::Oscillate(o) => {
                for a in o.amplitude.to_array() {
                    finite("oscillation amplitude", a)?;
                }
                positive("oscillation frequency", o.frequency).map(drop)
            }
            Self::Spin {
                angular_velocity,
                axis,
            } => {
                finite("angular velocity", *angular_velocity)?;
                for a in axis.to_array() {
                    finite("spin axis", a)?;
                }
                positive("spin axis length", axis.length()).map(drop)
            }
        }
    }

    /// Whether the surface moves at all.
    pub fn moves(&self) -> bool {
        match self {
            Self::Fixed => false,
            Self::Oscillate(o) => o.amplitude != DVec3::ZERO,
            Self::Spin {
                angular_velocity, ..
            } => *angular_velocity != 0.0,
        }
    }

    /// The pose at time `t` of a surface resting at `base`, and its twist,
    /// exact.
    pub fn at(&self, base: Pose3, t: f64) -> (Pose3, Twist<DVec3>) {
        match *self {
            Self::Fixed => (
                base,
                Twist {
                    origin: base.origin,
                    ..Twist::default()
                },
            ),
            Self::Oscillate(o) => {
                let (offset, velocity, acceleration) = o.at(t);
                let origin = base.origin + offset;
                let twist = Twist {
                    origin,
                    velocity,
                    acceleration,
                    ..Twist::default()
                };
                (Pose3 { origin, ..base }, twist)
            }
            Self::Spin {
                angular_velocity,
                axis,
            } => {
                let axis = axis.normalize();
                let turn = DQuat::from_axis_angle(axis, angular_velocity * t);
                let pose = Pose3 {
                    origin: base.origin,
                    rotation: turn * base.rotation,
                };
                let twist = Twist {
                    origin: base.origin,
                    angular_velocity: angular_velocity * axis,
                    ..Twist::default()
                };
                (pose, twist)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A spin's twist is the derivative of its poses: a point fixed to the
    /// surface moves at `ω × r` (central differences).
    #[test]
    fn a_spins_twist_is_the_derivative_of_its_poses() {
        let base =
            Pose3::from_axis_angle(DVec3::new(0.3, -0.2, 0.5), DVec3::new(1.0, 2.0, 0.5), 0.7)
                .expect("a pose");
        let motion = SpaceMotion::Spin {
            angular_velocity: 1.7,
            axis: DVec3::new(-0.4, 1.0, 0.3),
        };
        let local = DVec3::new(0.9, -0.4, 1.1);
        let (t, h) = (0.8, 1e-6);
        let at = |t: f64| motion.at(base, t).0.to_world(local);
        let numeric = (at(t + h) - at(t - h)) / (2.0 * h);
        let (pose, twist) = motion.at(base, t);
        let exact = twist.velocity_at(pose.to_world(local));
        assert!(
            (numeric - exact).length() < 1e-8,
            "{numeric} against {exact}"
        );
    }

    /// A zero axis, a NaN, a frequency of zero are refused in words.
    #[test]
    fn a_zero_axis_or_a_nan_is_refused() {
        let zero = SpaceMotion::Spin {
            angular_velocity: 1.0,
            axis: DVec3::ZERO,
        };
        assert!(
            zero.validate()
                .unwrap_err()
                .to_string()
                .contains("spin axis")
        );
        let nan = SpaceMotion::Oscillate(Oscillate {
            amplitude: DVec3::new(0.0, f64::NAN, 0.0),
            frequency: 1.0,
        });
        assert!(nan.validate().is_err());
        let still = SpaceMotion::Oscillate(Oscillate {
            amplitude: DVec3::X,
            frequency: 0.0,
        });
        assert!(
            still
                .validate()
                .unwrap_err()
                .to_string()
                .contains("frequency")
        );
    }
}
