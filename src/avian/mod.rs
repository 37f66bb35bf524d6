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

use avian2d::dynamics::solver::schedule::{SolverSystems, SubstepSchedule, SubstepSolverSystems};
use avian2d::dynamics::solver::solver_body::{SolverBody, SolverBodyInertia};
use avian2d::dynamics::solver::xpbd::XpbdSolverSystems;
use avian2d::math::AdjustPrecision;
use avian2d::prelude::*;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::dynamics::{Wire, WirePose};
use crate::geometry::{ImplicitCurve, Near, Placed, PosePath, WireShape};
use crate::solver::path::{
    BodyRow, Drive, PlaneBody, PlaneVelocity, Rows, along_curve, held, past_end, project,
    project_driven, project_velocity, turn_offset, turns_a_corner,
};
use crate::{SimClock, SimParams};

mod joint;

pub use joint::{PathJoint, PathJointForces, PathMotor, PathRotation};

/// What a path joint holds from one substep to the next.
#[derive(Component, Clone, Debug)]
struct PathJointState {
    /// The time the step began at, and how far into it the substeps are.
    time: (f64, f64),
    /// The centre of mass and the angle where the step began.
    start: (DVec2, f64),
    /// The centre of mass and the angle where the substep began.
    previous: (DVec2, f64),
    /// The anchor from the centre of mass, in the body's frame.
    arm: DVec2,
    /// The body's angle less the wire's at the anchor, once set.
    offset: Option<f64>,
    /// The curve's parameter at the anchor: its branch where it crosses
    /// itself.
    hint: f64,
    /// Why the joint holds nothing, once said.
    warned: bool,
    /// The impulse the joint gave over the step so far: linear, angular,
    /// and its drive's along the wire.
    impulse: (DVec2, f64, f64),
}

impl Default for PathJointState {
    fn default() -> Self {
        Self {
            time: (0.0, 0.0),
            start: (DVec2::ZERO, 0.0),
            previous: (DVec2::ZERO, 0.0),
            arm: DVec2::ZERO,
            offset: None,
            // Anywhere on the curve, until the anchor has been on it.
            hint: f64::NAN,
            warned: false,
            impulse: (DVec2::ZERO, 0.0, 0.0),
        }
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
        state.start = (
            origin + DVec2::from_angle(angle).rotate(local_centre),
            angle,
        );
        state.previous = state.start;
        state.impulse = (DVec2::ZERO, 0.0, 0.0);
        state.arm = joint.anchor - local_centre;
        state.time = (clock.time - params.timestep, 0.0);
        let placed = wires
            .get(joint.wire)
            .is_ok_and(|(_, pose)| pose.path().is_some());
        if !placed && !state.warned {
            warn!(
                "wirebead: the path joint of body {entity} holds nothing: entity {} is not a wire \
                 with a finite pose",
                joint.wire
            );
            state.warned = true;
        }
    }
}

/// The body as the joint sees it: its centre and angle where the substep
/// has it (`start` moved by the substep's `delta`).
fn plane_body(state: &PathJointState, body: &SolverBody, inertia: &SolverBodyInertia) -> PlaneBody {
    let (start, start_angle) = state.start;
    PlaneBody {
        centre: start + DVec2::from(body.delta_position),
        angle: start_angle + f64::from(body.delta_rotation.as_radians()),
        arm: state.arm,
        inverse_mass: DVec2::from(inertia.effective_inv_mass()),
        inverse_inertia: f64::from(inertia.effective_inv_angular_inertia()),
    }
}

/// The rows a joint holds: the anchor on the wire and, turned with it,
/// the body's angle; `None` at a singular point.
fn held_rows(
    joint: &PathJoint,
    offset: Option<f64>,
    curve: &impl ImplicitCurve,
    body: &PlaneBody,
) -> Option<Rows> {
    let turned = match joint.rotation {
        PathRotation::Turned => offset,
        PathRotation::Free => None,
    };
    held(curve, body, turned)
}

/// The joint's rows with, where `end` is given, the end the anchor is
/// past.
fn rows_with_end(
    joint: &PathJoint,
    offset: Option<f64>,
    curve: &impl ImplicitCurve,
    body: &PlaneBody,
    end: bool,
) -> Option<Rows> {
    let mut rows = held_rows(joint, offset, curve, body)?;
    if end {
        rows.push(past_end(curve, body)?);
    }
    Some(rows)
}

/// The impulse that changes a body's velocity by `linear` and `spin`
/// (`M Δv`), along the axes it moves along (a locked axis takes what it
/// is given, unknown, and reports none).
fn impulse_of(body: &PlaneBody, linear: DVec2, spin: f64) -> (DVec2, f64) {
    let over = |change: f64, inverse: f64| if inverse > 0.0 { change / inverse } else { 0.0 };
    (
        DVec2::new(
            over(linear.x, body.inverse_mass.x),
            over(linear.y, body.inverse_mass.y),
        ),
        over(spin, body.inverse_inertia),
    )
}

/// Each joint's impulses over the step, as its mean forces.
fn write_path_joint_forces(mut joints: Query<(&PathJointState, &mut PathJointForces)>) {
    for (state, mut forces) in &mut joints {
        // The step's length: its substeps together.
        let dt = state.time.1;
        if dt <= 0.0 {
            continue;
        }
        let (linear, angular, driven) = state.impulse;
        let mean = PathJointForces {
            force: linear / dt,
            torque: angular / dt,
            motor_force: driven / dt,
        };
        if mean.force.is_finite() && mean.torque.is_finite() && mean.motor_force.is_finite() {
            *forces = mean;
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
    state.time.1 += h;
    // A kinematic body goes where the game sends it; a static one has
    // no solver body at all.
    if body.flags.is_kinematic() {
        return;
    }
    let Some((shape, path)) = wire_of(wires, joint) else {
        return;
    };
    let now = state.time.0 + state.time.1;
    let near = Near {
        curve: shape.curve(),
        hint: state.hint,
    };
    let before = Placed {
        curve: &near,
        pose: path.pose(now - h),
    };
    let after = Placed {
        curve: &near,
        pose: path.pose(now),
    };
    let predicted = plane_body(state, body, inertia);
    let previous = PlaneBody {
        centre: state.previous.0,
        angle: state.previous.1,
        ..predicted
    };
    if !(predicted.anchor().is_finite() && predicted.angle.is_finite()) {
        return;
    }
    if joint.rotation == PathRotation::Turned && state.offset.is_none() {
        state.offset = turn_offset(&before, &previous);
    }
    let end = past_end(&after, &predicted).is_some_and(|row| row.value > 0.0);
    let offset = state.offset;
    let Some(start) = rows_with_end(joint, offset, &before, &previous, end) else {
        return;
    };
    let tolerance = 1e-12 * shape.curve().scale().max(1.0);
    let compliance = joint.yielding() / (h * h);
    let rows_at = |b: &PlaneBody| rows_with_end(joint, offset, &after, b, end);
    // At an end the buffer holds the anchor, whatever drives it.
    let drive = if end {
        None
    } else {
        let v = PlaneVelocity {
            linear: DVec2::from(body.linear_velocity),
            spin: f64::from(body.angular_velocity),
        };
        let (_, twist) = path.at(now - h);
        let frame = PlaneVelocity {
            linear: twist.velocity_at(previous.centre),
            spin: twist.angular_velocity,
        };
        drive_of(joint, &before, shape, &previous, v, frame, h)
    };
    let put_back = |start: &Rows, from: &PlaneBody| match drive {
        Some(drive) => project_driven(
            start, from, &drive, predicted, compliance, tolerance, rows_at,
        ),
        None => project(start, predicted, compliance, tolerance, rows_at).map(|p| (p, 0.0)),
    };
    let Some((mut projected, mut driven)) = put_back(&start, &previous) else {
        return;
    };
    // Past a sharp corner the gradients where the substep began point off
    // the wire's new direction: put the body back along those where it
    // is instead, onto the nearest point of the new segment.
    if let Some(there) = projected.rows
        && turns_a_corner((&previous, &start), (&projected.body, &there))
        && let Some(here) = rows_at(&predicted)
        && let Some(nearest) = put_back(&here, &predicted)
    {
        (projected, driven) = nearest;
    }
    // The move is the impulse over the substep: Δq = h M⁻¹ p.
    let (linear, angular) = impulse_of(
        &predicted,
        projected.body.centre - predicted.centre,
        projected.body.angle - predicted.angle,
    );
    state.impulse.0 += linear / h;
    state.impulse.1 += angular / h;
    state.impulse.2 += driven / h;
    let moved = projected.body;
    state.hint = shape
        .curve()
        .parameter(after.pose.to_local(moved.anchor()), state.hint);
    body.delta_position += (moved.centre - predicted.centre).adjust_precision();
    body.delta_rotation = Rotation::radians((moved.angle - state.start.1).adjust_precision());
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
    state.previous = (plane.centre, plane.angle);
    if body.flags.is_kinematic() {
        return;
    }
    let Some((shape, path)) = wire_of(wires, joint) else {
        return;
    };
    let near = Near {
        curve: shape.curve(),
        hint: state.hint,
    };
    let (pose, twist) = path.at(state.time.0 + state.time.1);
    let curve = Placed { curve: &near, pose };
    let v = PlaneVelocity {
        linear: DVec2::from(body.linear_velocity),
        spin: f64::from(body.angular_velocity),
    };
    let frame = PlaneVelocity {
        linear: twist.velocity_at(plane.centre),
        spin: twist.angular_velocity,
    };
    let old = v;
    let Some(v) = joint_velocity(joint, state.offset, &curve, &plane, v, frame) else {
        return;
    };
    if v.linear.is_finite() && v.spin.is_finite() {
        let (linear, angular) = impulse_of(&plane, v.linear - old.linear, v.spin - old.spin);
        state.impulse.0 += linear;
        state.impulse.1 += angular;
        body.linear_velocity = v.linear.adjust_precision();
        body.angular_velocity = v.spin.adjust_precision();
    }
}

/// The drive of a joint in the substep that begins with the body at
/// `previous` moving at `v` (the wire's frame at `frame`): its motor, or
/// its friction while no motor drives it, as a displacement along the
/// wire and a bound; `None` for a joint that neither drives nor holds.
fn drive_of<C: ImplicitCurve>(
    joint: &PathJoint,
    curve: &Placed<'_, C>,
    shape: &WireShape,
    previous: &PlaneBody,
    v: PlaneVelocity,
    frame: PlaneVelocity,
    h: f64,
) -> Option<Drive> {
    // A joint that neither drives nor holds costs no evaluation of the wire.
    let drives_or_holds = joint.motor.is_some() || joint.friction > 0.0;
    if !drives_or_holds {
        return None;
    }
    let along = along_curve(curve, previous, shape.travel())?;
    let relative = along.rate(v) - along.rate(frame);
    let (speed, max_force) = match joint.motor {
        Some(PathMotor::Velocity { speed, max_force }) => (speed, max_force),
        Some(PathMotor::Position {
            target,
            frequency,
            damping_ratio,
            max_force,
        }) => {
            // The spring–damper's implicit step, as avian's motors take it.
            let error = along
                .along_centre
                .dot(curve.pose.to_world(target) - previous.anchor());
            let omega = std::f64::consts::TAU * frequency;
            let damping = 2.0 * damping_ratio * omega;
            let change = (omega * omega * error - damping * relative) * h
                / (1.0 + damping * h + omega * omega * h * h);
            (relative + change, max_force)
        }
        None if joint.friction > 0.0 => (0.0, joint.friction),
        None => return None,
    };
    let (speed, max_force) = (speed + along.rate(frame), max_force.max(0.0));
    (speed.is_finite() && !max_force.is_nan()).then(|| Drive {
        direction: along.along_centre,
        from: previous.anchor(),
        shift: speed * h,
        bound: max_force * h * h,
    })
}

/// The velocity a joint leaves its body with: on its rows where the
/// substep ends, stopped at an end of an open wire it would pass.
fn joint_velocity(
    joint: &PathJoint,
    offset: Option<f64>,
    curve: &impl ImplicitCurve,
    body: &PlaneBody,
    v: PlaneVelocity,
    frame: PlaneVelocity,
) -> Option<PlaneVelocity> {
    // A compliant joint is met in position only.
    let mut rows = if joint.yielding() > 0.0 {
        Rows::default()
    } else {
        held_rows(joint, offset, curve, body)?
    };
    if let Some(end) = past_end(curve, body)
        && end.value > -1e-9 * curve.scale()
        && end.rate(v) > end.rate(frame)
    {
        rows.push(BodyRow { value: 0.0, ..end });
    }
    Some(project_velocity(&rows, body, v, frame)?.0)
}
