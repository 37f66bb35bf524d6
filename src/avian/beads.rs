//! Beads of ours on wires that ride avian2d bodies: avian2d's side of
//! [`PointBodies`](crate::carrier::PointBodies).

// Avian's numbers are `f32` or `f64` as the game builds it.
#![allow(clippy::useless_conversion)]

use bevy::math::DVec2;

use super::{PathJoint, PathJointForces, PathJointState, Placing, placed_body};
use crate::carrier::point_bodies;
use crate::solver::path::PlaneBody;

/// avian2d, for beads in the plane.
pub(super) struct Avian2d;

point_bodies!(
    avian2d, Avian2d, DVec2, PlaneBody,
    vector: DVec2::from, spin: f64::from, inertia: |m| AngularInertia(m)
);
