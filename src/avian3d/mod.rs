//! Rigid bodies of avian3d on our wires in space: [`PathJoint`] holds a
//! point of a body (its anchor) on a [`SpaceWire`] (a curve or a
//! surface), free to slide along it and, as asked, free to turn, turning
//! about one axis of the wire's frame, turned with the frame as a cart on
//! a rail, or not turning against the wire at all. Add
//! [`PathJointPlugin`] after avian's `PhysicsPlugins` and the
//! [`WireBeadPlugin`](crate::WireBeadPlugin).
//!
//! The joint is solved in avian's substep loop as the plane's
//! ([`crate::avian`]) is, by the same functions: the body's position and
//! orientation put back on the joint's rows along their gradients where
//! the substep began, to rounding, and its velocity and spin onto them
//! where it ends (docs/method.md, "Rigid bodies on wires"). The wire's
//! curve and pose stay `f64`; the body's state converts at the edge, in
//! whatever precision the game built avian with.
//!
//! ```
//! use avian3d::prelude::*;
//! use bevy::math::DVec3;
//! use bevy::prelude::*;
//! use wirebead::avian3d::{PathJoint, PathJointPlugin, PathRotation};
//! use wirebead::geometry::Helix;
//! use wirebead::prelude::*;
//! use wirebead::SpaceWire;
//!
//! fn cart_on_a_helix(mut commands: Commands) {
//!     let rail = commands
//!         .spawn((SpaceWire::curve(Helix { radius: 2.0, pitch: 3.0 }), Transform::IDENTITY))
//!         .id();
//!     commands.spawn((
//!         RigidBody::Dynamic,
//!         Mass(2.0),
//!         AngularInertia::new(Vec3::new(0.04, 0.09, 0.08)),
//!         Position::from_xyz(2.0, 0.0, 0.0),
//!         // The body's origin on the rail, turned with it as a cart.
//!         PathJoint::new(rail).with_rotation(PathRotation::ToPath),
//!     ));
//! }
//!
//! App::new()
//!     .add_plugins((
//!         MinimalPlugins,
//!         WireBeadPlugin::default(),
//!         PhysicsPlugins::default(),
//!         PathJointPlugin,
//!     ))
//!     .add_systems(Startup, cart_on_a_helix)
//!     .update();
//! ```

// Avian's numbers are `f32` or `f64` as the game builds it: the conversions
// to `f64` are identities in an `f64` build.
#![allow(clippy::useless_conversion)]

use avian3d::dynamics::solver::schedule::{SolverSystems, SubstepSchedule, SubstepSolverSystems};
use avian3d::dynamics::solver::solver_body::{SolverBody, SolverBodyInertia};
use avian3d::dynamics::solver::xpbd::XpbdSolverSystems;
use avian3d::math::{AdjustPrecision, Quaternion, Scalar, Vector};
use avian3d::prelude::*;
use bevy::math::{DMat3, DQuat, DVec3};
use bevy::prelude::*;

use crate::dynamics::{SpaceWire, WirePose};
use crate::geometry::{SpacePath, SpaceShape};
use crate::solver::path::{
    Alignment, BodyVelocity, JointBody, JointState, Law, SpaceBody, SpaceWireAt, Substep,
    velocity_on_wire,
};
use crate::{SimClock, SimParams};

mod joint;

pub use joint::{PathJoint, PathJointForces, PathMotor, PathRotation};

/// What a path joint in space holds from one substep to the next (how
/// the body turns with its wire, once fixed).
#[derive(Component, Clone, Debug)]
struct PathJointState(JointState<SpaceBody, Alignment>);

impl Default for PathJointState {
    fn default() -> Self {
        Self(JointState::new(SpaceBody {
            centre: DVec3::ZERO,
            rotation: DQuat::IDENTITY,
            arm: DVec3::ZERO,
            inverse_mass: DVec3::ZERO,
            inverse_inertia: DMat3::ZERO,
        }))
    }
}

/// Solves [`PathJoint`]s in avian3d's substep loop. Add it after avian's
/// `PhysicsPlugins`.
#[derive(Default)]
pub struct PathJointPlugin;

impl Plugin for PathJointPlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<PathJoint>()
            .register_type::<PathJointForces>()
            .add_systems(
                PhysicsSchedule,
                (
                    prepare_path_joints.in_set(SolverSystems::PrepareJoints),
                    write_path_joint_forces.in_set(SolverSystems::Finalize),
                ),
            )
            .add_systems(
                SubstepSchedule,
                (
                    solve_path_joints.in_set(XpbdSolverSystems::SolveUserConstraints),
                    // After avian turns the substep's corrections into
                    // velocity, before it damps it.
                    project_path_joint_velocities
                        .after(XpbdSolverSystems::VelocityProjection)
                        .before(SubstepSolverSystems::Damping),
                ),
            );
    }
}

/// A rotation of avian's, in `f64`.
fn rotation_of(q: Quaternion) -> DQuat {
    DQuat::from_xyzw(
        f64::from(q.x),
        f64::from(q.y),
        f64::from(q.z),
        f64::from(q.w),
    )
}

/// A vector of avian's, in `f64`.
fn vector_of(v: Vector) -> DVec3 {
    DVec3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z))
}

/// The wires in space with their poses.
type Wires<'w, 's> = Query<'w, 's, (&'static SpaceWire, &'static WirePose<DVec3>)>;

/// Reads each joint's body where the step begins; says once of a joint
/// whose wire is missing, or cannot turn the body as asked, that it holds
/// nothing, or only its anchor.
fn prepare_path_joints(
    mut joints: Query<(
        Entity,
        &PathJoint,
        &mut PathJointState,
        &Position,
        &Rotation,
        &ComputedCenterOfMass,
    )>,
    wires: Wires,
    clock: Res<SimClock>,
    params: Res<SimParams>,
) {
    for (entity, joint, mut state, position, rotation, centre) in &mut joints {
        let rotation = rotation_of(rotation.0).normalize();
        let local_centre = vector_of(centre.0);
        let body = SpaceBody {
            centre: vector_of(position.0) + rotation * local_centre,
            rotation,
            arm: joint.anchor - local_centre,
            ..state.0.start
        };
        state.0.begin(body, clock.time - params.timestep);
        if state.0.warned {
            continue;
        }
        let why = match wires.get(joint.wire) {
            Ok((_, pose)) if pose.path().is_none() => Some("its wire has no finite pose"),
            Ok((wire, _))
                if matches!(wire.shape(), SpaceShape::Surface(_))
                    && !matches!(joint.rotation, PathRotation::Free | PathRotation::Fixed) =>
            {
                Some("a surface has no tangent to turn it with, so it holds the anchor only")
            }
            Ok(_) => None,
            Err(_) => Some("its wire is not a wire in space"),
        };
        if let Some(why) = why {
            warn!(
                "wirebead: the path joint of body {entity} on entity {}: {why}",
                joint.wire
            );
            state.0.warned = true;
        }
    }
}

/// The body as the joint sees it: where the step began, moved by the
/// substep's `delta`.
fn space_body(start: SpaceBody, body: &SolverBody, inertia: &SolverBodyInertia) -> SpaceBody {
    let m = inertia.effective_inv_angular_inertia();
    let column =
        |x: Scalar, y: Scalar, z: Scalar| DVec3::new(f64::from(x), f64::from(y), f64::from(z));
    SpaceBody {
        centre: start.centre + vector_of(body.delta_position),
        rotation: (rotation_of(body.delta_rotation.0) * start.rotation).normalize(),
        inverse_mass: vector_of(inertia.effective_inv_mass()),
        inverse_inertia: DMat3::from_cols(
            column(m.m00, m.m01, m.m02),
            column(m.m01, m.m11, m.m12),
            column(m.m02, m.m12, m.m22),
        ),
        ..start
    }
}

/// Each joint's impulses over the step, as its mean forces.
fn write_path_joint_forces(mut joints: Query<(&PathJointState, &mut PathJointForces)>) {
    for (state, mut forces) in &mut joints {
        if let Some((force, torque, motor_force)) = state.0.mean_forces() {
            *forces = PathJointForces {
                force,
                torque,
                motor_force,
            };
        }
    }
}

/// The wire of a joint: its shape and where it is over time.
fn wire_of<'a>(wires: &'a Wires, joint: &PathJoint) -> Option<(&'a SpaceShape, SpacePath)> {
    wires
        .get(joint.wire)
        .ok()
        .and_then(|(wire, pose)| Some((wire.shape(), pose.path()?)))
}

/// What the joint asks beside holding its body.
fn law(joint: &PathJoint) -> Law<DVec3> {
    Law::new(joint.motor, joint.friction, joint.compliance)
}

/// Each joint with the body it holds, as the substep's solver has it.
type JointBodies<'w, 's> = Query<
    'w,
    's,
    (
        &'static PathJoint,
        &'static mut PathJointState,
        &'static mut SolverBody,
        &'static SolverBodyInertia,
    ),
>;

/// SHAKE's step for each joint in the substep: the body, moved freely by
/// avian's substep, put back on its rows along their gradients where the
/// substep began, to rounding.
fn solve_path_joints(mut joints: JointBodies, wires: Wires, time: Res<Time>) {
    let h = time.delta_secs_f64();
    if h.is_nan() || h <= 0.0 {
        return;
    }
    // Each joint moves its own body only: the joints run in parallel.
    joints
        .par_iter_mut()
        .for_each(|(joint, mut state, mut body, inertia)| {
            solve_path_joint(joint, &mut state, &mut body, inertia, &wires, h);
        });
}

/// The body's velocity as avian's solver has it.
fn velocity_of(body: &SolverBody) -> BodyVelocity<SpaceBody> {
    BodyVelocity {
        linear: vector_of(body.linear_velocity),
        spin: vector_of(body.angular_velocity),
    }
}

/// SHAKE's step for one joint (see [`solve_path_joints`]).
fn solve_path_joint(
    joint: &PathJoint,
    state: &mut PathJointState,
    body: &mut SolverBody,
    inertia: &SolverBodyInertia,
    wires: &Wires,
    h: f64,
) {
    let state = &mut state.0;
    state.time.1 += h;
    if body.flags.is_kinematic() {
        return;
    }
    let Some((shape, path)) = wire_of(wires, joint) else {
        return;
    };
    let now = state.time.0 + state.time.1;
    let predicted = space_body(state.start, body, inertia);
    let previous = SpaceBody {
        centre: state.previous.centre,
        rotation: state.previous.rotation,
        ..predicted
    };
    if !(predicted.anchor().is_finite() && predicted.rotation.is_finite()) {
        return;
    }
    let (pose, twist) = path.at(now - h);
    let mut before = SpaceWireAt {
        shape,
        pose,
        hint: state.hint,
        alignment: None,
    };
    if let Some(turn) = joint.rotation.turn()
        && state.turn.is_none()
        && let Some(frame) = before.frame(&previous, turn)
    {
        state.turn = Some(Alignment {
            turn,
            axes: (previous.rotation.inverse() * frame).normalize(),
        });
    }
    before.alignment = state.turn;
    let after = SpaceWireAt {
        pose: path.pose(now),
        ..before
    };
    let substep = Substep {
        before: &before,
        after: &after,
        previous,
        predicted,
        v: velocity_of(body),
        frame: BodyVelocity {
            linear: twist.velocity_at(previous.centre),
            spin: twist.angular_velocity,
        },
        h,
        start: state.rows.take(),
    };
    let Some((projected, driven)) = substep.correct(&law(joint)) else {
        return;
    };
    let (p, tau) = projected.impulse;
    state.add_impulse((p / h, tau / h), driven / h);
    let moved = projected.body;
    state.hint = after.parameter(&moved);
    body.delta_position += (moved.centre - predicted.centre).adjust_precision();
    body.delta_rotation = Rotation(
        (moved.rotation * state.start.rotation.inverse())
            .normalize()
            .adjust_precision(),
    );
}

/// RATTLE's velocity step for each joint, after avian has turned the
/// substep's corrections into velocity: the velocity onto the rows where
/// the substep ends, the end of an open wire stopping an anchor that
/// would pass it (the motor and friction act in the position step).
fn project_path_joint_velocities(mut joints: JointBodies, wires: Wires) {
    joints
        .par_iter_mut()
        .for_each(|(joint, mut state, mut body, inertia)| {
            project_path_joint_velocity(joint, &mut state, &mut body, inertia, &wires);
        });
}

/// RATTLE's velocity step for one joint (see
/// [`project_path_joint_velocities`]).
fn project_path_joint_velocity(
    joint: &PathJoint,
    state: &mut PathJointState,
    body: &mut SolverBody,
    inertia: &SolverBodyInertia,
    wires: &Wires,
) {
    let now = space_body(state.0.start, body, inertia);
    state.0.previous = now;
    state.0.rows = None;
    if body.flags.is_kinematic() {
        return;
    }
    let Some((shape, path)) = wire_of(wires, joint) else {
        return;
    };
    let (pose, twist) = path.at(state.0.time.0 + state.0.time.1);
    let wire = SpaceWireAt {
        shape,
        pose,
        hint: state.0.hint,
        alignment: state.0.turn,
    };
    let frame = BodyVelocity {
        linear: twist.velocity_at(now.centre),
        spin: twist.angular_velocity,
    };
    let rigid = law(joint).rigid();
    let Some((v, impulse, rows)) = velocity_on_wire(rigid, &wire, &now, velocity_of(body), frame)
    else {
        return;
    };
    state.0.rows = rows;
    if v.is_finite() {
        state.0.add_impulse(impulse, 0.0);
        body.linear_velocity = v.linear.adjust_precision();
        body.angular_velocity = v.spin.adjust_precision();
    }
}
