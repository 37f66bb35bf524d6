//! Rigid bodies of avian2d on our wires: [`PathJoint`] holds a point of a
//! body (its anchor) on a [`Wire`], free to slide along it and, as asked,
//! free to turn or turned with the wire. Add [`PathJointPlugin`] after
//! avian's `PhysicsPlugins` and the [`WireBeadPlugin`](crate::WireBeadPlugin).
//!
//! The joint is solved in avian's substep loop, after its contacts and
//! its own joints, as RATTLE holds a bead: the body's position is put
//! back on the wire along the joint's gradients where the substep began,
//! to rounding, and its velocity onto the wire where it ends, so that it
//! composes with everything avian simulates and swings with the period of
//! the exact motion (docs/method.md, "Rigid bodies on wires"). A motor
//! drives it along the wire with a bounded force, friction holds it while
//! no motor does, and the ends of an open wire stop it. The wire's curve
//! and pose stay `f64`; the body's state converts at the edge, in
//! whatever precision the game built avian with.
//!
//! ```
//! use avian2d::prelude::*;
//! use bevy::prelude::*;
//! use wirebead::avian::{PathJoint, PathJointPlugin, PathRotation};
//! use wirebead::prelude::*;
//!
//! fn cart_on_a_hoop(mut commands: Commands) -> Result {
//!     let hoop = commands.spawn((Wire::circle(1.0)?, Transform::IDENTITY)).id();
//!     commands.spawn((
//!         RigidBody::Dynamic,
//!         Mass(2.0),
//!         AngularInertia(0.01),
//!         Position::from_xy(0.0, -1.0),
//!         // The body's origin on the hoop, turned with it as a cart.
//!         PathJoint::new(hoop).with_rotation(PathRotation::Turned),
//!     ));
//!     Ok(())
//! }
//!
//! App::new()
//!     .add_plugins((
//!         MinimalPlugins,
//!         WireBeadPlugin::default(),
//!         PhysicsPlugins::default(),
//!         PathJointPlugin,
//!     ))
//!     .add_systems(Startup, cart_on_a_hoop)
//!     .update();
//! ```

// Avian's numbers are `f32` or `f64` as the game builds it: the conversions
// to `f64` are identities in an `f64` build.
#![allow(clippy::useless_conversion)]

use avian2d::dynamics::solver::schedule::{SolverSystems, SubstepSchedule, SubstepSolverSystems};
use avian2d::dynamics::solver::solver_body::{SolverBody, SolverBodyInertia};
use avian2d::dynamics::solver::xpbd::XpbdSolverSystems;
use avian2d::math::AdjustPrecision;
use avian2d::prelude::*;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::dynamics::{Wire, WirePose};
use crate::geometry::{Near, Placed, PosePath, WireShape};
use crate::solver::path::{
    JointBody, JointState, Law, PlaneBody, PlaneVelocity, PlaneWire, Substep, turn_offset,
    velocity_on_wire,
};
use crate::{SimClock, SimParams};

mod joint;

pub use joint::{PathJoint, PathJointForces, PathMotor, PathRotation};

/// What a path joint holds from one substep to the next (the body's
/// angle less the wire's tangent angle at the anchor, once set, for a
/// body turned with its wire).
#[derive(Component, Clone, Debug)]
struct PathJointState(JointState<PlaneBody, f64>);

impl Default for PathJointState {
    fn default() -> Self {
        Self(JointState::new(PlaneBody {
            centre: DVec2::ZERO,
            angle: 0.0,
            arm: DVec2::ZERO,
            inverse_mass: DVec2::ZERO,
            inverse_inertia: 0.0,
        }))
    }
}

/// Solves [`PathJoint`]s in avian's substep loop. Add it after avian's
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

/// Reads each joint's body where the step begins; says once of a joint
/// whose wire is missing that it holds nothing.
fn prepare_path_joints(
    mut joints: Query<(
        Entity,
        &PathJoint,
        &mut PathJointState,
        &Position,
        &Rotation,
        &ComputedCenterOfMass,
    )>,
    wires: Query<(&Wire, &WirePose<DVec2>)>,
    clock: Res<SimClock>,
    params: Res<SimParams>,
) {
    for (entity, joint, mut state, position, rotation, centre) in &mut joints {
        let origin = DVec2::from(position.0);
        let angle = f64::from(rotation.as_radians());
        let local_centre = DVec2::from(centre.0);
        let body = PlaneBody {
            centre: origin + DVec2::from_angle(angle).rotate(local_centre),
            angle,
            arm: joint.anchor - local_centre,
            ..state.0.start
        };
        state.0.begin(body, clock.time - params.timestep);
        let placed = wires
            .get(joint.wire)
            .is_ok_and(|(_, pose)| pose.path().is_some());
        if !placed && !state.0.warned {
            warn!(
                "wirebead: the path joint of body {entity} holds nothing: entity {} is not a wire \
                 with a finite pose",
                joint.wire
            );
            state.0.warned = true;
        }
    }
}

/// The body as the joint sees it: where the step began, moved by the
/// substep's `delta`.
fn plane_body(state: &PathJointState, body: &SolverBody, inertia: &SolverBodyInertia) -> PlaneBody {
    let start = state.0.start;
    PlaneBody {
        centre: start.centre + DVec2::from(body.delta_position),
        angle: start.angle + f64::from(body.delta_rotation.as_radians()),
        inverse_mass: DVec2::from(inertia.effective_inv_mass()),
        inverse_inertia: f64::from(inertia.effective_inv_angular_inertia()),
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
fn wire_of<'a>(
    wires: &'a Query<(&Wire, &WirePose<DVec2>)>,
    joint: &PathJoint,
) -> Option<(&'a WireShape, PosePath)> {
    wires
        .get(joint.wire)
        .ok()
        .and_then(|(wire, pose)| Some((wire.shape(), pose.path()?)))
}

/// What the joint asks beside holding its body.
fn law(joint: &PathJoint) -> Law<DVec2> {
    Law::new(joint.motor, joint.friction, joint.compliance)
}

/// How the joint turns its body: by the offset it keeps, where it turns
/// it with the wire.
fn turned(joint: &PathJoint, state: &PathJointState) -> Option<f64> {
    match joint.rotation {
        PathRotation::Turned => state.0.turn,
        PathRotation::Free => None,
    }
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
fn solve_path_joints(
    mut joints: JointBodies,
    wires: Query<(&Wire, &WirePose<DVec2>)>,
    time: Res<Time>,
) {
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

/// SHAKE's step for one joint (see [`solve_path_joints`]).
fn solve_path_joint(
    joint: &PathJoint,
    state: &mut PathJointState,
    body: &mut SolverBody,
    inertia: &SolverBodyInertia,
    wires: &Query<(&Wire, &WirePose<DVec2>)>,
    h: f64,
) {
    state.0.time.1 += h;
    // A kinematic body goes where the game sends it; a static one has
    // no solver body at all.
    if body.flags.is_kinematic() {
        return;
    }
    let Some((shape, path)) = wire_of(wires, joint) else {
        return;
    };
    let now = state.0.time.0 + state.0.time.1;
    let near = Near {
        curve: shape.curve(),
        hint: state.0.hint,
    };
    let predicted = plane_body(state, body, inertia);
    let previous = PlaneBody {
        centre: state.0.previous.centre,
        angle: state.0.previous.angle,
        ..predicted
    };
    if !(predicted.anchor().is_finite() && predicted.angle.is_finite()) {
        return;
    }
    let placed = |pose| Placed { curve: &near, pose };
    if joint.rotation == PathRotation::Turned && state.0.turn.is_none() {
        state.0.turn = turn_offset(&placed(path.pose(now - h)), &previous);
    }
    let wire_at = |pose| PlaneWire {
        curve: placed(pose),
        turned: turned(joint, state),
        travel: shape.travel(),
    };
    let (before, after) = (wire_at(path.pose(now - h)), wire_at(path.pose(now)));
    let (_, twist) = path.at(now - h);
    let substep = Substep {
        before: &before,
        after: &after,
        previous,
        predicted,
        v: PlaneVelocity {
            linear: DVec2::from(body.linear_velocity),
            spin: f64::from(body.angular_velocity),
        },
        frame: PlaneVelocity {
            linear: twist.velocity_at(previous.centre),
            spin: twist.angular_velocity,
        },
        h,
        start: state.0.rows.take(),
    };
    let Some((projected, driven)) = substep.correct(&law(joint)) else {
        return;
    };
    // The move is the impulse over the substep: Δq = h M⁻¹ p.
    let (p, tau) = projected.impulse;
    state.0.add_impulse((p / h, tau / h), driven / h);
    let moved = projected.body;
    state.0.hint = shape
        .curve()
        .parameter(after.curve.pose.to_local(moved.anchor()), state.0.hint);
    body.delta_position += (moved.centre - predicted.centre).adjust_precision();
    body.delta_rotation = Rotation::radians((moved.angle - state.0.start.angle).adjust_precision());
}

/// RATTLE's velocity step for each joint, after avian has turned the
/// substep's corrections into velocity: the velocity onto the rows where
/// the substep ends, the end of an open wire stopping an anchor that
/// would pass it (the motor and friction act in the position step).
fn project_path_joint_velocities(mut joints: JointBodies, wires: Query<(&Wire, &WirePose<DVec2>)>) {
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
    wires: &Query<(&Wire, &WirePose<DVec2>)>,
) {
    let plane = plane_body(state, body, inertia);
    state.0.previous = plane;
    state.0.rows = None;
    if body.flags.is_kinematic() {
        return;
    }
    let Some((shape, path)) = wire_of(wires, joint) else {
        return;
    };
    let near = Near {
        curve: shape.curve(),
        hint: state.0.hint,
    };
    let (pose, twist) = path.at(state.0.time.0 + state.0.time.1);
    let wire = PlaneWire {
        curve: Placed { curve: &near, pose },
        turned: turned(joint, state),
        travel: shape.travel(),
    };
    let v = PlaneVelocity {
        linear: DVec2::from(body.linear_velocity),
        spin: f64::from(body.angular_velocity),
    };
    let frame = PlaneVelocity {
        linear: twist.velocity_at(plane.centre),
        spin: twist.angular_velocity,
    };
    let rigid = law(joint).rigid();
    let Some((v, impulse, rows)) = velocity_on_wire(rigid, &wire, &plane, v, frame) else {
        return;
    };
    state.0.rows = rows;
    if v.is_finite() {
        state.0.add_impulse(impulse, 0.0);
        body.linear_velocity = v.linear.adjust_precision();
        body.angular_velocity = v.spin.adjust_precision();
    }
}
