//! A scene file's rigid bodies in avian2d: each body spawned as an avian
//! body (its collider, mass, inertia, pose, velocity and contact
//! materials), and each path joint of the file.

// Avian's numbers are `f32` or `f64` as the game builds it.
#![allow(clippy::useless_conversion)]

use avian2d::math::{AdjustPrecision, Scalar};
use avian2d::prelude::*;
use bevy::math::DVec2;
use bevy::prelude::*;

use super::{BodyKind, BodyPreset, BodyShape, PathRotationPreset, SceneBody, SceneJoin, ScenePath};
use crate::avian::{BodyStart, PathJoint, PathRotation, body_of_record};
use crate::plugin::RecordedBody;

/// Avian's kind of body for a scene's.
fn rigid_body(kind: BodyKind) -> RigidBody {
    match kind {
        BodyKind::Dynamic => RigidBody::Dynamic,
        BodyKind::Static => RigidBody::Static,
        BodyKind::Kinematic => RigidBody::Kinematic,
    }
}

/// The collider of a body's shape.
fn collider(shape: &BodyShape<DVec2>) -> Collider {
    let size = |x: f64| x as Scalar;
    match shape {
        BodyShape::Box(b) => {
            Collider::rectangle(size(2.0 * b.half_extents.x), size(2.0 * b.half_extents.y))
        }
        BodyShape::Ball(b) => Collider::circle(size(b.radius)),
        BodyShape::Capsule(c) => Collider::capsule(size(c.radius), size(2.0 * c.half_length)),
    }
}

/// Spawns a scene's bodies, each marked [`FromPreset`] and named, with
/// its [`BodyStart`] for a restart; the bodies in the file's order. Call
/// on a validated scene.
pub(crate) fn spawn_bodies(bodies: &[BodyPreset], commands: &mut Commands) -> Vec<Entity> {
    bodies
        .iter()
        .map(|body| {
            let start = BodyStart {
                position: Position(body.position.adjust_precision()),
                rotation: Rotation::radians(body.angle_degrees.to_radians() as Scalar),
                linear: LinearVelocity(body.velocity.adjust_precision()),
                angular: AngularVelocity(body.angular_velocity as Scalar),
            };
            let mut entity = commands.spawn((
                (rigid_body(body.kind), collider(&body.shape), start),
                (start.position, start.rotation, start.linear, start.angular),
                Restitution::new(body.restitution as Scalar),
                Friction::new(body.friction as Scalar),
            ));
            if let Some((mass, inertia)) = body.mass_properties() {
                entity.insert((Mass(mass as f32), AngularInertia(inertia as f32)));
            }
            entity.id()
        })
        .collect()
}

/// The path joint of a scene's `path` on the wire `wire`.
pub(super) fn joint(wire: Entity, path: &ScenePath) -> PathJoint {
    let rotation = match path.rotation {
        PathRotationPreset::Tangent => PathRotation::Turned,
        _ => PathRotation::Free,
    };
    let joint = PathJoint::new(wire)
        .with_anchor(path.anchor)
        .with_friction(path.friction)
        .with_rotation(rotation);
    match path.motor {
        Some(motor) => joint.with_motor(motor),
        None => joint,
    }
}

/// Spawns the joint of a scene's join between its two bodies `pair`: a
/// hinge as avian's `RevoluteJoint` at its point, a coupling as its
/// `DistanceJoint`; the bodies not colliding with each other. The joint.
pub(super) fn join(pair: [Entity; 2], join: &SceneJoin, commands: &mut Commands) -> Entity {
    let mut joint = commands.spawn(JointCollisionDisabled);
    match *join {
        SceneJoin::Hinge { at, .. } => {
            joint.insert(RevoluteJoint::new(pair[0], pair[1]).with_anchor(at.adjust_precision()))
        }
        SceneJoin::Coupling {
            anchors, length, ..
        } => joint.insert(
            DistanceJoint::new(pair[0], pair[1])
                .with_local_anchor1(anchors[0].adjust_precision())
                .with_local_anchor2(anchors[1].adjust_precision())
                .with_limits(length as Scalar, length as Scalar),
        ),
    };
    joint.id()
}

/// The state of the rigid body `body` as a scene's run records it: its
/// origin, its angle (rad, counter-clockwise), its velocity and spin;
/// `None` where it is no avian2d body.
pub(crate) fn body_state(world: &World, body: Entity) -> Option<(DVec2, f64, DVec2, f64)> {
    Some(state_of(
        world.get::<Position>(body)?,
        world.get::<Rotation>(body)?,
        world.get::<LinearVelocity>(body)?,
        world.get::<AngularVelocity>(body)?,
    ))
}

/// The state of a body as a [`Timeline`](crate::plugin::Timeline)
/// recorded it, as [`body_state`] reads it.
pub(crate) fn recorded_state(body: &RecordedBody) -> (DVec2, f64, DVec2, f64) {
    let (position, rotation, velocity, spin, _) = body_of_record(body);
    state_of(&position, &rotation, &velocity, &spin)
}

/// A body's state in `f64`.
fn state_of(
    position: &Position,
    rotation: &Rotation,
    velocity: &LinearVelocity,
    spin: &AngularVelocity,
) -> (DVec2, f64, DVec2, f64) {
    (
        DVec2::from(position.0),
        f64::from(rotation.as_radians()),
        DVec2::from(velocity.0),
        f64::from(spin.0),
    )
}
