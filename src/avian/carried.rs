//! Path joints on wires that ride bodies: each joint with its body and
//! its carrier, met one after another in the substep.

use avian2d::dynamics::solver::solver_body::{SolverBody, SolverBodyInertia};
use bevy::prelude::*;

use super::{PathJoint, PathJointState, Wires, project_path_joint_velocity, solve_path_joint};
use crate::carrier::{self, RidesBody, each_carried};

/// The bodies of joints on wires that ride bodies, and their carriers.
pub(super) type SolverBodies<'w, 's> =
    Query<'w, 's, (&'static mut SolverBody, &'static SolverBodyInertia)>;

/// A joint's body in the substep's solver, and its carrier's where the
/// carrier has one.
pub(super) type Solved<'a> = carrier::Solved<'a, SolverBody, SolverBodyInertia>;

impl RidesBody for PathJointState {
    fn carrier(&self) -> Option<Entity> {
        self.1
    }
}

/// SHAKE's step for each joint on a wire that rides a body: the body and
/// the carrier put back together (see [`solve_path_joints`]).
pub(super) fn solve_carried_path_joints(
    mut joints: Query<(Entity, &PathJoint, &mut PathJointState)>,
    mut bodies: SolverBodies,
    wires: Wires,
    time: Res<Time>,
) {
    let h = time.delta_secs_f64();
    if h.is_nan() || h <= 0.0 {
        return;
    }
    each_carried(&mut joints, &mut bodies, |joint, state, solved| {
        solve_path_joint(joint, state, solved, &wires, h);
    });
}

/// RATTLE's velocity step for each joint on a wire that rides a body: the
/// body's and the carrier's velocities together (see
/// [`project_path_joint_velocities`]).
pub(super) fn project_carried_path_joint_velocities(
    mut joints: Query<(Entity, &PathJoint, &mut PathJointState)>,
    mut bodies: SolverBodies,
    wires: Wires,
) {
    each_carried(&mut joints, &mut bodies, |joint, state, solved| {
        project_path_joint_velocity(joint, state, solved, &wires);
    });
}
