//! Beads that strike avian3d's bodies: avian3d's side of
//! [`WorldShapes`](crate::carrier::WorldShapes).

// Avian's numbers are `f32` or `f64` as the game builds it.
#![allow(clippy::useless_conversion)]

use avian3d::math::{AdjustPrecision, Matrix, Vector};
use avian3d::prelude::{ComputedAngularInertia, Rotation};
use bevy::math::{DMat3, DQuat, DVec3};

use super::vector_of;
use crate::carrier::world_shapes;

/// avian3d, for beads in space.
pub(super) struct Avian3dWorld;

/// A vector in space as one of avian3d's.
fn down(v: DVec3) -> Vector {
    v.adjust_precision()
}

/// A turn as a quaternion in `f64`.
fn turn(rotation: &Rotation) -> DQuat {
    DQuat::from_array(rotation.0.to_array().map(f64::from))
}

/// One of avian3d's matrices in `f64`.
fn matrix(m: Matrix) -> DMat3 {
    DMat3::from_cols_array(&m.to_cols_array().map(f64::from))
}

/// The inverse inertia in the world's frame.
fn inverse_inertia(inertia: &ComputedAngularInertia, rotation: &Rotation) -> DMat3 {
    matrix(inertia.rotated(rotation.0).inverse().to_mat3())
}

/// The energy `½ ω·I ω` of a spin `spin`, `I` in the world's frame.
fn spin_energy(inertia: &ComputedAngularInertia, rotation: &Rotation, spin: DVec3) -> f64 {
    let tensor = matrix(inertia.rotated(rotation.0).value().to_mat3());
    0.5 * spin.dot(tensor * spin)
}

world_shapes!(
    avian3d, Avian3dWorld, DVec3,
    up: vector_of, down: down, turn: turn, spin: vector_of, inverse_inertia: inverse_inertia,
    spin_energy: spin_energy
);
