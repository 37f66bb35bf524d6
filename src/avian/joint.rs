//! The public face of a path joint: the component a game adds, how its
//! body may turn, what drives it, and what it did over the last step.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::PathJointState;

/// How a body held on a wire by a [`PathJoint`] may turn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
pub enum PathRotation {
    /// As it likes: only its anchor is held.
    #[default]
    Free,
    /// With the wire: the body keeps the angle it had to the wire's
    /// tangent at its anchor when the joint began, as a cart on a rail.
    Turned,
}

/// What drives a body along its wire (see
/// [`PathMotor`](crate::solver::PathMotor)'s variants), its
/// position target a point of the plane.
pub type PathMotor = crate::solver::path::PathMotor<DVec2>;

/// Holds a point of the rigid body it is on (the anchor, in the body's
/// frame from its origin, as avian's joints take theirs) on the wire
/// `wire`, free to slide along it. The body needs avian's `RigidBody`
/// (a dynamic one: a kinematic or static body is not moved by its joint);
/// the wire is an entity with a [`Wire`](crate::Wire) (fixed, or moving
/// as any wire of ours moves). A joint naming an entity that is no wire
/// holds nothing, and says so once in the log. The ends of an open wire
/// (a spline, a cycloid) stop the anchor there, as a buffer stops a cart.
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[require(PathJointState, PathJointForces)]
pub struct PathJoint {
    /// The wire's entity.
    pub wire: Entity,
    /// The anchor in the body's frame, from its origin.
    pub anchor: DVec2,
    /// How the body may turn.
    pub rotation: PathRotation,
    /// What drives the body along the wire, if anything.
    pub motor: Option<PathMotor>,
    /// The largest force (N) that holds the body against sliding along
    /// the wire while no motor drives it (0: it slides freely).
    pub friction: f64,
    /// How far the anchor yields per newton, m/N (0: rigid), as avian's
    /// joint compliance. A compliant joint is met in position only, as
    /// avian's joints are, and its velocity is not projected. One that is
    /// not a finite positive number (negative, NaN, infinite) is rigid.
    pub compliance: f64,
}

impl PathJoint {
    /// The body's origin held on `wire`, free to turn and to slide,
    /// rigidly.
    pub fn new(wire: Entity) -> Self {
        Self {
            wire,
            anchor: DVec2::ZERO,
            rotation: PathRotation::Free,
            motor: None,
            friction: 0.0,
            compliance: 0.0,
        }
    }

    /// The joint with the anchor at `anchor`, in the body's frame.
    pub fn with_anchor(self, anchor: DVec2) -> Self {
        Self { anchor, ..self }
    }

    /// The joint with the body turning as `rotation` says.
    pub fn with_rotation(self, rotation: PathRotation) -> Self {
        Self { rotation, ..self }
    }

    /// The joint driven by `motor`.
    pub fn with_motor(self, motor: PathMotor) -> Self {
        Self {
            motor: Some(motor),
            ..self
        }
    }

    /// The joint holding the body against sliding with a force of at most
    /// `friction` (N) while no motor drives it.
    pub fn with_friction(self, friction: f64) -> Self {
        Self { friction, ..self }
    }
}

/// What a [`PathJoint`] did to its body over the last physics step, as
/// avian's `JointForces` says it of avian's joints: the mean force and
/// torque the joint applied (through the body's centre of mass, the
/// wire's push, its motor or friction and its ends together), and the
/// part of the force its motor or friction gave along the wire.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
pub struct PathJointForces {
    /// The force on the body, N, world frame.
    pub force: DVec2,
    /// The torque about its centre of mass, N·m, counter-clockwise.
    pub torque: f64,
    /// The motor's (or friction's) force along the wire's own direction,
    /// N.
    pub motor_force: f64,
}
