//! Beads that strike avian3d's bodies: avian3d's side of
//! [`WorldShapes`](crate::carrier::WorldShapes).

// Avian's numbers are `f32` or `f64` as the game builds it.
#![allow(clippy::useless_conversion)]

use avian3d::math::{AdjustPrecision, Vector};
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
    rotation.0.as_dquat()
}

/// The inverse inertia in the world's frame.
fn inverse_inertia(inertia: &ComputedAngularInertia, rotation: &Rotation) -> DMat3 {
    inertia.rotated(rotation.0).inverse().to_mat3().as_dmat3()
}

/// The energy `½ ω·I ω` of a spin `spin`, `I` in the world's frame.
fn spin_energy(inertia: &ComputedAngularInertia, rotation: &Rotation, spin: DVec3) -> f64 {
    let tensor = inertia.rotated(rotation.0).value().to_mat3().as_dmat3();
    0.5 * spin.dot(tensor * spin)
}

world_shapes!(
    avian3d, Avian3dWorld, DVec3,
    up: vector_of, down: down, turn: turn, spin: vector_of, inverse_inertia: inverse_inertia,
    spin_energy: spin_energy
);
