//! [`History`]: a wire's motion known only from the poses a game wrote
//! into its `Transform`, one per step: the quadratic through the last
//! three, in the plane ([`PoseHistory`]) and in space ([`SpaceHistory`]).

use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Sub};

use bevy::math::{DQuat, DVec2, DVec3};

use super::{Coordinates, Pose, Pose3, Twist};

/// One pose as a [`History`] keeps it, in coordinates it can take the
/// quadratic through three of: the plane's origin and unwrapped angle, or
/// space's origin and rotation.
pub trait HistoryPose: Copy + Debug + PartialEq {
    /// The pose: [`Pose`] or [`Pose3`].
    type Pose: Copy;
    /// The coordinates its twist is in.
    type Coords: Coordinates;
    /// `pose` as kept, continuing from `previous` where there is one (no
    /// jump of a turn in an angle, no flip of a quaternion's sign).
    fn keep(pose: Self::Pose, previous: Option<&Self>) -> Self;
    /// The pose itself.
    fn pose(&self) -> Self::Pose;
    /// The pose one step before `older`, continuing from `newer` to
    /// `older` as far again: `2 older − newer`.
    fn mirror(older: &Self, newer: &Self) -> Self;
    /// The pose and twist at `s` steps of `h` from the newest of `three`
    /// (oldest first), on the quadratic through them.
    fn between(three: &[Self; 3], s: f64, h: f64) -> (Self::Pose, Twist<Self::Coords>);
}

/// The value at `s` steps of `h` from the last of `three` (oldest first)
/// on the quadratic through them, and its first and second derivatives in
/// time.
pub(crate) fn quadratic<T>(three: [T; 3], s: f64, h: f64) -> (T, T, T)
where
    T: Copy + Add<Output = T> + Sub<Output = T> + Mul<f64, Output = T> + Div<f64, Output = T>,
{
    let [x0, x1, x2] = three;
    let (d1, d2) = (x2 - x1, x2 - x1 * 2.0 + x0);
    let curve = 0.5 * s * (s + 1.0);
    let rate = s + 0.5;
    (x2 + d1 * s + d2 * curve, (d1 + d2 * rate) / h, d2 / (h * h))
}

/// The poses a wire had at the ends of the last steps, as a game wrote
/// them into its `Transform`: the motion between them is the quadratic
/// through the last three, so within a step the pose is interpolated to
/// third order in the step, the velocity to second and the acceleration
/// to first. With two poses the motion is linear, with one it is at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct History<P> {
    /// The time of the newest pose.
    time: f64,
    /// The time between poses.
    step: f64,
    /// The poses, oldest first.
    poses: [P; 3],
    /// How many of the three are real (1 to 3).
    known: u8,
}

/// The plane's [`History`].
pub type PoseHistory = History<PlanePose>;
/// Space's [`History`].
pub type SpaceHistory = History<SpacePose>;

impl<P: HistoryPose> History<P> {
    /// A wire at rest at `pose` at time `time`.
    pub fn at_rest(time: f64, pose: P::Pose) -> Self {
        Self {
            time,
            step: 0.0,
            poses: [P::keep(pose, None); 3],
            known: 1,
        }
    }

    /// The newest pose and its time.
    pub fn newest(&self) -> (f64, P::Pose) {
        (self.time, self.poses[2].pose())
    }

    /// Takes in the pose at `time`, one step `step` after the newest. A
    /// history whose newest pose is older than `time − step` is restarted
    /// from that pose held at `time − step` (the wire did not move in
    /// between).
    pub fn push(&mut self, time: f64, step: f64, pose: P::Pose) {
        let consecutive = ((self.time + step) - time).abs() <= 1e-9 * step.max(time.abs())
            && (self.known == 1 || (self.step - step).abs() <= 1e-12 * step);
        if !consecutive {
            let (_, last) = self.newest();
            *self = Self::at_rest(time - step, last);
        }
        self.step = step;
        let kept = P::keep(pose, Some(&self.poses[2]));
        self.poses = [self.poses[1], self.poses[2], kept];
        self.time = time;
        self.known = (self.known + 1).min(3);
        if self.known < 3 {
            // Extend back linearly: no curvature until three are known.
            self.poses[0] = P::mirror(&self.poses[1], &self.poses[2]);
        }
    }

    /// Whether the last three poses are one: the wire is at rest.
    pub fn is_at_rest(&self) -> bool {
        self.known == 1 || self.poses.iter().all(|p| *p == self.poses[2])
    }

    /// The interpolated pose and twist at `t` (meant for the last step,
    /// `time − step ≤ t ≤ time`).
    pub fn at(&self, t: f64) -> (P::Pose, Twist<P::Coords>) {
        if self.is_at_rest() || self.step <= 0.0 {
            let (_, pose) = self.newest();
            let (_, twist) = P::between(&[self.poses[2]; 3], 0.0, 1.0);
            return (pose, twist);
        }
        P::between(&self.poses, (t - self.time) / self.step, self.step)
    }
}

/// A pose in the plane as a history keeps it: the origin and the angle,
/// unwrapped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanePose {
    origin: DVec2,
    angle: f64,
}

impl HistoryPose for PlanePose {
    type Pose = Pose;
    type Coords = DVec2;
    fn keep(pose: Pose, previous: Option<&Self>) -> Self {
        let angle = pose.rotation.to_angle();
        let angle = match previous {
            // The angle taken nearest to the previous one: no jump of 2π.
            Some(p) => {
                p.angle + (angle - p.angle + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI
            }
            None => angle,
        };
        Self {
            origin: pose.origin,
            angle,
        }
    }
    fn pose(&self) -> Pose {
        Pose::new(self.origin, self.angle)
    }
    fn mirror(older: &Self, newer: &Self) -> Self {
        Self {
            origin: 2.0 * older.origin - newer.origin,
            angle: 2.0 * older.angle - newer.angle,
        }
    }
    fn between(three: &[Self; 3], s: f64, h: f64) -> (Pose, Twist) {
        let (origin, velocity, acceleration) = quadratic(three.map(|p| p.origin), s, h);
        let (angle, rate, turn) = quadratic(three.map(|p| p.angle), s, h);
        (
            Pose::new(origin, angle),
            Twist {
                origin,
                velocity,
                angular_velocity: rate,
                acceleration,
                angular_acceleration: turn,
            },
        )
    }
}

/// A pose in space as a history keeps it: the origin and the rotation,
/// its sign kept from pose to pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpacePose {
    origin: DVec3,
    rotation: DQuat,
}

impl HistoryPose for SpacePose {
    type Pose = Pose3;
    type Coords = DVec3;
    fn keep(pose: Pose3, previous: Option<&Self>) -> Self {
        let rotation = match previous {
            Some(p) if p.rotation.dot(pose.rotation) < 0.0 => -pose.rotation,
            _ => pose.rotation,
        };
        Self {
            origin: pose.origin,
            rotation,
        }
    }
    fn pose(&self) -> Pose3 {
        Pose3 {
            origin: self.origin,
            rotation: self.rotation,
        }
    }
    fn mirror(older: &Self, newer: &Self) -> Self {
        // The turn from `newer` back to `older`, taken once more.
        let back = newer.rotation.inverse() * older.rotation;
        Self {
            origin: 2.0 * older.origin - newer.origin,
            rotation: (older.rotation * back).normalize(),
        }
    }
    /// The turn as rotation vectors in the newest pose's frame,
    /// `r = log(q₂⁻¹ q)`, on the quadratic through them; the angular
    /// velocity and acceleration are their rates turned into the world
    /// (exact for a turn about a fixed axis, to second order in the
    /// step's turn otherwise).
    fn between(three: &[Self; 3], s: f64, h: f64) -> (Pose3, Twist<DVec3>) {
        let (origin, velocity, acceleration) = quadratic(three.map(|p| p.origin), s, h);
        let newest = three[2].rotation;
        let turns = three.map(|p| (newest.inverse() * p.rotation).to_scaled_axis());
        let (turn, rate, change) = quadratic(turns, s, h);
        (
            Pose3 {
                origin,
                rotation: (newest * DQuat::from_scaled_axis(turn)).normalize(),
            },
            Twist {
                origin,
                velocity,
                angular_velocity: newest * rate,
                acceleration,
                angular_acceleration: newest * change,
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wire in space the game turns at a steady 1.5 rad/s about a tilted
    /// axis while moving its origin along a parabola: from its last three
    /// poses the history gives the turn's rate and the origin's velocity
    /// and acceleration to rounding.
    #[test]
    fn a_turn_about_a_fixed_axis_is_followed_exactly() {
        let axis = DVec3::new(0.3, 1.0, -0.2).normalize();
        let (w, h) = (1.5, 0.01);
        let pose = |t: f64| Pose3 {
            origin: DVec3::new(t, 0.5 * t * t, 0.0),
            rotation: DQuat::from_axis_angle(axis, w * t),
        };
        let mut history = SpaceHistory::at_rest(0.0, pose(0.0));
        for k in 1..=5 {
            history.push(k as f64 * h, h, pose(k as f64 * h));
        }
        let t = 4.5 * h;
        let (at, twist) = history.at(t);
        assert!((at.origin - pose(t).origin).length() < 1e-12);
        assert!(at.rotation.angle_between(pose(t).rotation) < 1e-12);
        assert!((twist.angular_velocity - axis * w).length() < 1e-12);
        assert!(twist.angular_acceleration.length() < 1e-9);
        assert!((twist.velocity - DVec3::new(1.0, t, 0.0)).length() < 1e-12);
        assert!((twist.acceleration - DVec3::Y).length() < 1e-9);
    }
}
