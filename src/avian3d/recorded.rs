//! avian3d's bodies as the [`Timeline`](crate::plugin::Timeline) records
//! them: avian's values in `f64`, exactly, and back.

// Avian's numbers are `f32` or `f64` as the game builds it.
#![allow(clippy::useless_conversion)]

use avian3d::math::{AdjustPrecision, Quaternion};
use avian3d::prelude::*;
use bevy::prelude::*;

use crate::plugin::RecordedBody;

use super::vector_of;

/// A body's state as the timeline records it: avian's values, in `f64`.
pub(super) fn recorded_body(
    entity: Entity,
    (position, rotation, linear, angular): (
        &Position,
        &Rotation,
        &LinearVelocity,
        &AngularVelocity,
    ),
    transform: Transform,
) -> RecordedBody {
    RecordedBody {
        entity,
        position: vector_of(position.0),
        rotation: rotation.0.to_array().map(f64::from),
        velocity: vector_of(linear.0),
        spin: vector_of(angular.0),
        transform,
    }
}

/// The body's state as recorded, in avian's components.
pub(crate) fn body_of_record(
    body: &RecordedBody,
) -> (
    Position,
    Rotation,
    LinearVelocity,
    AngularVelocity,
    Transform,
) {
    (
        Position(body.position.adjust_precision()),
        Rotation(Quaternion::from_array(
            body.rotation.map(|c| c.adjust_precision()),
        )),
        LinearVelocity(body.velocity.adjust_precision()),
        AngularVelocity(body.spin.adjust_precision()),
        body.transform,
    )
}
