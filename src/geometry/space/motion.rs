//! Surfaces that move in space: [`SpaceMotion`] (an oscillation of the
//! origin along a 3D amplitude, or a spin about any axis through it),
//! [`SpacePath`] (where a surface is over time) and [`MovingSurface`], the
//! [`Track`] the solver steps a bead on it with. The frame's velocity and
//! acceleration are exact, and eq. (15) takes them in its 3D form.

use bevy::math::{DQuat, DVec3};

use super::ImplicitSurface;
use crate::geometry::motion::carry;
use crate::geometry::{Geometry, Oscillate, PlacedSurface, Pose3, SpaceHistory, Track, Twist};
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

/// Where a wire in space is over time: at one pose, moving by a
/// prescribed motion about a resting pose, or followed from the poses a
/// game wrote.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpacePath {
    /// At one pose.
    Fixed(Pose3),
    /// `motion` about the resting pose `base`.
    Prescribed {
        /// The pose at `t = 0`.
        base: Pose3,
        /// The motion.
        motion: SpaceMotion,
    },
    /// Interpolated from the last poses.
    Followed(SpaceHistory),
}

impl SpacePath {
    /// The pose and twist at `t`.
    pub fn at(&self, t: f64) -> (Pose3, Twist<DVec3>) {
        match self {
            Self::Fixed(pose) => SpaceMotion::Fixed.at(*pose, t),
            Self::Prescribed { base, motion } => motion.at(*base, t),
            Self::Followed(history) => history.at(t),
        }
    }

    /// The pose at `t`.
    pub fn pose(&self, t: f64) -> Pose3 {
        self.at(t).0
    }

    /// The pose if the surface does not move.
    pub fn fixed(&self) -> Option<Pose3> {
        match self {
            Self::Fixed(pose) => Some(*pose),
            Self::Prescribed {
                base,
                motion: SpaceMotion::Fixed,
            } => Some(*base),
            Self::Prescribed { .. } | Self::Followed(_) => None,
        }
    }
}

/// A surface in its local frame carried along a [`SpacePath`].
pub struct MovingSurface<'a, S: ImplicitSurface + ?Sized> {
    /// The surface in its local frame.
    pub surface: &'a S,
    /// Where its frame is over time.
    pub path: &'a SpacePath,
}

impl<S: ImplicitSurface + ?Sized> Track<DVec3> for MovingSurface<'_, S> {
    const MOVES: bool = true;
    #[inline]
    fn geometry(&self, t: f64, x: DVec3) -> Geometry<DVec3> {
        PlacedSurface {
            surface: self.surface,
            pose: self.path.pose(t),
        }
        .geometry(x)
    }
    fn scale(&self) -> f64 {
        self.surface.scale()
    }
    fn twist(&self, t: f64) -> Twist<DVec3> {
        self.path.at(t).1
    }
    fn carry(&self, x: DVec3, from: f64, to: f64) -> DVec3 {
        carry(&self.path.pose(from), &self.path.pose(to), x)
    }
    fn has_ends(&self) -> bool {
        false
    }
    fn past_end(&self, _t: f64, _x: DVec3) -> f64 {
        f64::NEG_INFINITY
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
