//! avian2d's bodies as the [`Timeline`](crate::plugin::Timeline) records
//! them: avian's values in `f64`, exactly, and back.

// Avian's numbers are `f32` or `f64` as the game builds it.
#![allow(clippy::useless_conversion)]

use avian2d::math::AdjustPrecision;
use avian2d::prelude::*;
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use crate::plugin::RecordedBody;

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
        position: DVec2::from(position.0).extend(0.0),
        rotation: [f64::from(rotation.cos), f64::from(rotation.sin), 0.0, 0.0],
        velocity: DVec2::from(linear.0).extend(0.0),
        spin: DVec3::Z * f64::from(angular.0),
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
    let [cos, sin, ..] = body.rotation;
    (
        Position(body.position.truncate().adjust_precision()),
        Rotation::from_sin_cos(sin.adjust_precision(), cos.adjust_precision()),
        LinearVelocity(body.velocity.truncate().adjust_precision()),
        AngularVelocity(body.spin.z.adjust_precision()),
        body.transform,
    )
}
