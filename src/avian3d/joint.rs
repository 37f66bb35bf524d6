//! The public face of a path joint in space: the component a game adds,
//! how its body may turn, and what it did over the last step.

use bevy::math::DVec3;
use bevy::prelude::*;

use super::PathJointState;
use crate::solver::path::SpaceTurn;

/// How a body held on a wire in space by a [`PathJoint`] may turn, as
/// Jolt's path constraint offers. The wire's frame at the anchor is its
/// tangent (the way its parameter grows), its first normal and their
/// binormal, as [`CurveFrame`](crate::geometry::CurveFrame) gives them:
/// rotation-minimizing along a spline or a traced curve, out from the
/// axis on a helix, in the plane of a planar shape. An axis of the body
/// that turns with a frame direction is the one that lay along it when
/// the joint began.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
pub enum PathRotation {
    /// As it likes: only its anchor is held.
    #[default]
    Free,
    /// About the wire's tangent only: the body's axis along the tangent
    /// stays along it.
    AroundTangent,
    /// About the wire's normal only.
    AroundNormal,
    /// About the wire's binormal only.
    AroundBinormal,
    /// With the wire's frame, as a cart on a rail (as
    /// [`RailOrientation`](crate::RailOrientation) turns a bead): it keeps
    /// the orientation it had to the frame when the joint began.
    ToPath,
    /// Not at all against the wire: it keeps the orientation it had to
    /// the wire's own axes (fixed in the world on a wire that does not
    /// move).
    Fixed,
}

impl PathRotation {
    /// The rows that hold it, if any.
    pub(super) fn turn(self) -> Option<SpaceTurn> {
        match self {
            Self::Free => None,
            Self::AroundTangent => Some(SpaceTurn::AroundTangent),
            Self::AroundNormal => Some(SpaceTurn::AroundNormal),
            Self::AroundBinormal => Some(SpaceTurn::AroundBinormal),
            Self::ToPath => Some(SpaceTurn::ToPath),
            Self::Fixed => Some(SpaceTurn::Fixed),
        }
    }
}

/// What drives a body along its wire in space (see
/// [`PathMotor`](crate::solver::PathMotor)'s variants), its position
/// target a point of space.
pub type PathMotor = crate::solver::PathMotor<DVec3>;

/// Holds a point of the avian3d rigid body it is on (the anchor, in the
/// body's frame from its origin) on the wire `wire`, a
/// [`SpaceWire`](crate::SpaceWire): a curve, the anchor free to slide
/// along it, or a surface, free to slide over it. The body needs avian's
/// `RigidBody` (a dynamic one: a kinematic or static body is not moved
/// by its joint). A joint naming an entity that is no wire in space holds
/// nothing, and says so once in the log; so does one whose rotation
/// needs a frame the wire has not (a surface, which has no tangent, holds
/// only `Free` and `Fixed`). The ends of an open curve stop the anchor
/// there, as a buffer stops a cart.
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[require(PathJointState, PathJointForces)]
pub struct PathJoint {
    /// The wire's entity.
    pub wire: Entity,
    /// The anchor in the body's frame, from its origin.
    pub anchor: DVec3,
    /// How the body may turn.
    pub rotation: PathRotation,
    /// What drives the body along the wire, if anything.
    pub motor: Option<PathMotor>,
    /// The largest force (N) that holds the body against sliding along
    /// the wire while no motor drives it (0: it slides freely).
    pub friction: f64,
    /// How far the anchor yields per newton, m/N (0: rigid), as avian's
    /// joint compliance; one that is not a finite positive number is
    /// rigid.
    pub compliance: f64,
}

impl PathJoint {
    /// The body's origin held on `wire`, free to turn and to slide,
    /// rigidly.
    pub fn new(wire: Entity) -> Self {
        Self {
            wire,
            anchor: DVec3::ZERO,
            rotation: PathRotation::Free,
            motor: None,
            friction: 0.0,
            compliance: 0.0,
        }
    }

    /// The joint with the anchor at `anchor`, in the body's frame.
    pub fn with_anchor(self, anchor: DVec3) -> Self {
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

/// What a [`PathJoint`] did to its body over the last physics step: the
/// mean force and torque it applied (through and about the body's centre
/// of mass, world frame), and the part its motor or friction gave along
/// the wire.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
pub struct PathJointForces {
    /// The force on the body, N, world frame.
    pub force: DVec3,
    /// The torque about its centre of mass, N·m, world frame.
    pub torque: DVec3,
    /// The motor's (or friction's) force along the wire's own direction,
    /// N.
    pub motor_force: f64,
}
