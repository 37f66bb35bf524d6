//! Where a wire is over time: [`WirePath`] (fixed, moving by a prescribed
//! motion, or followed from the poses a game writes), in the plane
//! ([`PosePath`]) and in space ([`SpacePath`]), and the [`Track`]s that
//! carry a curve ([`MovingTrack`]) or a surface ([`MovingSurface`]) along
//! one.

use bevy::math::{DVec2, DVec3};

use super::motion::carry;
use super::{
    Geometry, History, ImplicitCurve, ImplicitSurface, Placed, PlacedSurface, Placement, Track,
    Twist, WireSpace,
};

/// Where a wire is over time, in the plane ([`PosePath`]) or in space
/// ([`SpacePath`](super::SpacePath)): fixed, moving by a prescribed motion
/// about a resting pose, or followed from the poses a game wrote.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WirePath<V: WireSpace = DVec2> {
    /// At one pose.
    Fixed(V::Pose),
    /// `motion` about the resting pose `base`.
    Prescribed {
        /// The pose at `t = 0`.
        base: V::Pose,
        /// The motion.
        motion: V::Motion,
    },
    /// Interpolated from the last poses.
    Followed(History<V::Kept>),
}

/// Where a wire in the plane is over time.
pub type PosePath = WirePath<DVec2>;

impl<V: WireSpace> WirePath<V> {
    /// The pose and twist at `t`.
    #[inline]
    pub fn at(&self, t: f64) -> (V::Pose, Twist<V>) {
        match self {
            Self::Fixed(pose) => (
                *pose,
                Twist {
                    origin: pose.origin(),
                    ..Twist::default()
                },
            ),
            Self::Prescribed { base, motion } => V::motion_at(motion, *base, t),
            Self::Followed(history) => history.at(t),
        }
    }

    /// The pose at `t`.
    pub fn pose(&self, t: f64) -> V::Pose {
        self.at(t).0
    }

    /// The pose if the wire does not move: one fixed, on a motion that
    /// moves nothing, or followed and come to rest.
    pub fn fixed(&self) -> Option<V::Pose> {
        match self {
            Self::Fixed(pose) => Some(*pose),
            Self::Prescribed { base, motion } if !V::motion_moves(motion) => Some(*base),
            Self::Followed(history) if history.is_at_rest() => Some(history.newest().1),
            _ => None,
        }
    }

    /// The resting pose of a prescribed motion.
    pub fn base(&self) -> Option<V::Pose> {
        match self {
            Self::Prescribed { base, .. } => Some(*base),
            _ => None,
        }
    }

    /// A wire's path after a game moved it to `now` over the step from
    /// `start` to `start + h` (`path` where it was), and whether it is
    /// still moving: followed from its last poses, so that its velocity
    /// enters the step, or fixed at `now` once they are one.
    pub(crate) fn followed(path: Option<Self>, now: V::Pose, start: f64, h: f64) -> (Self, bool) {
        let mut history = match path {
            Some(Self::Fixed(at)) if at == now => return (Self::Fixed(now), false),
            Some(Self::Fixed(at)) => History::at_rest(f64::NEG_INFINITY, at),
            Some(Self::Followed(history)) => history,
            Some(path @ Self::Prescribed { .. }) => History::at_rest(start, path.pose(start)),
            None => History::at_rest(start, now),
        };
        history.push(start + h, h, now);
        if history.is_at_rest() {
            (Self::Fixed(now), false)
        } else {
            (Self::Followed(history), true)
        }
    }
}

/// Where a wire in space is over time.
pub type SpacePath = WirePath<DVec3>;

/// A curve in its local frame carried along a [`PosePath`].
pub struct MovingTrack<'a, C: ImplicitCurve + ?Sized> {
    /// The curve in its local frame.
    pub curve: &'a C,
    /// Where its frame is over time.
    pub path: &'a PosePath,
}

impl<C: ImplicitCurve + ?Sized> Track for MovingTrack<'_, C> {
    const MOVES: bool = true;
    #[inline]
    fn geometry(&self, t: f64, x: DVec2) -> Geometry {
        Placed {
            curve: self.curve,
            pose: self.path.pose(t),
        }
        .geometry(x)
    }
    fn scale(&self) -> f64 {
        self.curve.scale()
    }
    fn twist(&self, t: f64) -> Twist {
        self.path.at(t).1
    }
    fn carry(&self, x: DVec2, from: f64, to: f64) -> DVec2 {
        carry(&self.path.pose(from), &self.path.pose(to), x)
    }
    fn has_ends(&self) -> bool {
        self.curve.has_ends()
    }
    fn past_end(&self, t: f64, x: DVec2) -> f64 {
        self.curve.past_end(self.path.pose(t).to_local(x))
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
    use crate::geometry::{Oscillate, Pose, Pose3, SpaceMotion, WireMotion};

    /// One rule in both dimensions: a wire is fixed where it is put, on a
    /// motion that moves nothing, or followed and come to rest (at its
    /// newest pose); a moving one is not. Followed, it starts from where
    /// it was and stays put once its last poses are one.
    fn fixed_by_one_rule<V: WireSpace>(
        at: V::Pose,
        moved: V::Pose,
        (still, moving): (V::Motion, V::Motion),
    ) {
        assert_eq!(WirePath::<V>::Fixed(at).fixed(), Some(at));
        let resting = WirePath::<V>::Prescribed {
            base: at,
            motion: still,
        };
        assert_eq!(resting.fixed(), Some(at));
        assert_eq!(resting.base(), Some(at));
        let shaken = WirePath::<V>::Prescribed {
            base: at,
            motion: moving,
        };
        assert_eq!(shaken.fixed(), None);
        let (path, moves) = WirePath::followed(Some(WirePath::<V>::Fixed(at)), moved, 0.0, 0.1);
        assert!(moves && path.fixed().is_none(), "{path:?}");
        let (path, _) = WirePath::followed(Some(path), moved, 0.1, 0.1);
        let (path, moves) = WirePath::followed(Some(path), moved, 0.2, 0.1);
        assert!(!moves, "{path:?}");
        assert_eq!(path.fixed(), Some(moved));
    }

    /// Shaken at 2 Hz by `amplitude`.
    fn shaken<V>(amplitude: V) -> Oscillate<V> {
        Oscillate {
            amplitude,
            frequency: 2.0,
        }
    }

    #[test]
    fn a_wire_is_fixed_by_one_rule_in_the_plane_and_in_space() {
        fixed_by_one_rule::<DVec2>(
            Pose::new(DVec2::new(0.5, 0.0), 0.3),
            Pose::new(DVec2::new(0.6, 0.1), 0.3),
            (
                WireMotion::Oscillate(shaken(DVec2::ZERO)),
                WireMotion::Oscillate(shaken(DVec2::Y)),
            ),
        );
        let turned = |x: f64| Pose3::from_axis_angle(DVec3::new(x, 0.0, 0.0), DVec3::X, 0.3);
        fixed_by_one_rule::<DVec3>(
            turned(0.5).expect("a pose"),
            turned(0.6).expect("a pose"),
            (
                SpaceMotion::Spin {
                    angular_velocity: 0.0,
                    axis: DVec3::Z,
                },
                SpaceMotion::Oscillate(shaken(DVec3::Y)),
            ),
        );
    }
}
