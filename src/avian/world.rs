//! Beads that strike avian2d's bodies: avian2d's side of
//! [`WorldShapes`](crate::carrier::WorldShapes).

// Avian's numbers are `f32` or `f64` as the game builds it.
#![allow(clippy::useless_conversion)]

use avian2d::math::{AdjustPrecision, Vector};
use avian2d::prelude::{ComputedAngularInertia, Rotation};
use bevy::math::{DMat3, DQuat, DVec2, DVec3};

use crate::carrier::world_shapes;

/// avian2d, for beads in the plane.
pub(super) struct Avian2dWorld;

/// One of avian2d's vectors in space, `z` zero.
fn up(v: Vector) -> DVec3 {
    DVec2::from(v).extend(0.0)
}

/// A vector in space as one of avian2d's, `z` dropped.
fn down(v: DVec3) -> Vector {
    v.truncate().adjust_precision()
}

/// A turn of the plane as a turn about `z`.
fn turn(rotation: &Rotation) -> DQuat {
    DQuat::from_rotation_z(f64::from(rotation.as_radians()))
}

/// A spin of the plane about `z`.
fn spin(spin: avian2d::math::Scalar) -> DVec3 {
    DVec3::Z * f64::from(spin)
}

/// The inverse inertia about `z`.
fn inverse_inertia(inertia: &ComputedAngularInertia, _: &Rotation) -> DMat3 {
    DMat3::from_diagonal(DVec3::Z * f64::from(inertia.inverse()))
}

/// The energy of a spin `spin` (about `z`).
fn spin_energy(inertia: &ComputedAngularInertia, _: &Rotation, spin: DVec3) -> f64 {
    0.5 * f64::from(inertia.value()) * spin.z * spin.z
}

world_shapes!(
    avian2d, Avian2dWorld, DVec2,
    up: up, down: down, turn: turn, spin: spin, inverse_inertia: inverse_inertia,
    spin_energy: spin_energy
);
