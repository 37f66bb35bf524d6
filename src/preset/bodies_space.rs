//! A scene file's rigid bodies in avian3d: each body spawned as an avian
//! body (its collider, mass, principal moments, pose, velocity and
//! contact materials), and each path joint of the file.

use avian3d::math::{AdjustPrecision, Scalar};
use avian3d::prelude::*;
use bevy::math::{DQuat, DVec3};
use bevy::prelude::*;

use super::{
    BodyKind, BodyShape, PathRotationPreset, SceneBody, SceneJoin, ScenePath, SpaceBodyPreset,
};
use crate::avian3d::{BodyStart, PathJoint, PathRotation, body_of_record, rotation_of, vector_of};
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
fn collider(shape: &BodyShape<DVec3>) -> Collider {
    let size = |x: f64| x as Scalar;
    match shape {
        BodyShape::Box(b) => {
            let full = b.half_extents * 2.0;
            Collider::cuboid(size(full.x), size(full.y), size(full.z))
        }
        BodyShape::Ball(b) => Collider::sphere(size(b.radius)),
        BodyShape::Capsule(c) => Collider::capsule(size(c.radius), size(2.0 * c.half_length)),
    }
}

/// Spawns a scene's bodies, each marked [`FromPreset`] and named, with
/// its [`BodyStart`] for a restart; the bodies in the file's order. Call
/// on a validated scene.
pub(crate) fn spawn_bodies(bodies: &[SpaceBodyPreset], commands: &mut Commands) -> Vec<Entity> {
    bodies
        .iter()
        .map(|body| {
            let start = BodyStart {
                position: Position(body.position.adjust_precision()),
                rotation: Rotation(body.pose().rotation.adjust_precision()),
                linear: LinearVelocity(body.velocity.adjust_precision()),
                angular: AngularVelocity(body.angular_velocity.adjust_precision()),
            };
            let mut entity = commands.spawn((
                (rigid_body(body.kind), collider(&body.shape), start),
                (start.position, start.rotation, start.linear, start.angular),
                Restitution::new(body.restitution as Scalar),
                Friction::new(body.friction as Scalar),
            ));
            if let Some((mass, moments)) = body.mass_properties() {
                entity.insert((Mass(mass as f32), AngularInertia::new(moments.as_vec3())));
            }
            entity.id()
        })
        .collect()
}

/// Spawns the joint of a scene's join between its two bodies `pair`: a
/// hinge as avian's `RevoluteJoint` about its axis (its joint frames
/// turned so that their `z`, avian's hinge axis, lies along it where the
/// bodies start) or its `SphericalJoint` where it has no axis, a coupling
/// as its `DistanceJoint`; the bodies not colliding with each other. The
/// joint.
pub(super) fn join(pair: [Entity; 2], join: &SceneJoin<DVec3>, commands: &mut Commands) -> Entity {
    let mut joint = commands.spawn(JointCollisionDisabled);
    match *join {
        SceneJoin::Hinge {
            at,
            axis: Some(axis),
            ..
        } => {
            let basis = DQuat::from_rotation_arc(DVec3::Z, axis);
            joint.insert(
                RevoluteJoint::new(pair[0], pair[1])
                    .with_anchor(at.adjust_precision())
                    .with_basis(basis.adjust_precision()),
            )
        }
        SceneJoin::Hinge { at, axis: None, .. } => {
            joint.insert(SphericalJoint::new(pair[0], pair[1]).with_anchor(at.adjust_precision()))
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

/// The path joint of a scene's `path` on the wire `wire`.
pub(super) fn joint(wire: Entity, path: &ScenePath<DVec3>) -> PathJoint {
    let rotation = match path.rotation {
        PathRotationPreset::AroundTangent => PathRotation::AroundTangent,
        PathRotationPreset::AroundNormal => PathRotation::AroundNormal,
        PathRotationPreset::AroundBinormal => PathRotation::AroundBinormal,
        PathRotationPreset::ToPath => PathRotation::ToPath,
        PathRotationPreset::Fixed => PathRotation::Fixed,
        PathRotationPreset::Free | PathRotationPreset::Tangent => PathRotation::Free,
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

/// The state of the rigid body `body` as a scene's run records it: its
/// origin, its rotation, its velocity and spin; `None` where it is no
/// avian3d body.
pub(crate) fn body_state(world: &World, body: Entity) -> Option<(DVec3, DQuat, DVec3, DVec3)> {
    Some(state_of(
        world.get::<Position>(body)?,
        world.get::<Rotation>(body)?,
        world.get::<LinearVelocity>(body)?,
        world.get::<AngularVelocity>(body)?,
    ))
}

/// The state of a body as a [`Timeline`](crate::plugin::Timeline)
/// recorded it, as [`body_state`] reads it.
pub(crate) fn recorded_state(body: &RecordedBody) -> (DVec3, DQuat, DVec3, DVec3) {
    let (position, rotation, velocity, spin, _) = body_of_record(body);
    state_of(&position, &rotation, &velocity, &spin)
}

/// A body's state in `f64`.
fn state_of(
    position: &Position,
    rotation: &Rotation,
    velocity: &LinearVelocity,
    spin: &AngularVelocity,
) -> (DVec3, DQuat, DVec3, DVec3) {
    (
        vector_of(position.0),
        rotation_of(rotation.0),
        vector_of(velocity.0),
        vector_of(spin.0),
    )
}
