//! Beads of ours on wires that ride avian3d bodies: avian3d's side of
//! [`PointBodies`](crate::carrier::PointBodies).

use bevy::math::{DVec3, Vec3};

use super::{PathJoint, PathJointForces, PathJointState, Placing, placed_body, vector_of};
use crate::carrier::point_bodies;
use crate::solver::path::SpaceBody;

/// avian3d, for beads in space.
pub(super) struct Avian3d;

point_bodies!(
    avian3d, Avian3d, DVec3, SpaceBody,
    vector: vector_of, spin: vector_of, inertia: |m| AngularInertia::new(Vec3::splat(m))
);
