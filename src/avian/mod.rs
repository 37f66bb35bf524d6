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

use avian2d::dynamics::solver::islands::WakeBody;
use avian2d::dynamics::solver::schedule::{SolverSystems, SubstepSchedule, SubstepSolverSystems};
use avian2d::dynamics::solver::solver_body::{SolverBody, SolverBodyInertia};
use avian2d::dynamics::solver::xpbd::XpbdSolverSystems;
use avian2d::math::AdjustPrecision;
use avian2d::prelude::*;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::carrier::{
    Boarding, board_beads, body_start, hand_over_forces, pull_bodies, read_back_beads,
};
use crate::carrier::{add_body_energy, any_bead_radius, apply_world_impulses, gather_world_bodies};
use crate::dynamics::{Wire, WirePose};
use crate::geometry::{Near, Placed, PosePath, WireShape};
use crate::plugin::WorldBodies;
use crate::solver::path::{
    Held, JointBody, JointState, JointWire, Law, PlaneBody, PlaneVelocity, PlaneWire, Substep,
    turn_offset, velocity_on_wire,
};
use crate::{GrabPoint, SceneEnergy, SimClock, SimParams, SpringAnchor, WireBeadSystems};
use beads::Avian2d;
use carried::{Solved, project_carried_path_joint_velocities, solve_carried_path_joints};
pub(crate) use recorded::body_of_record;
use recorded::recorded_body;
use world::Avian2dWorld;

mod beads;
mod carried;
mod joint;
mod recorded;
mod world;

pub use crate::dynamics::WireOnBody;
pub use joint::{PathJoint, PathJointForces, PathMotor, PathRotation};

/// What a path joint holds from one substep to the next (the body's
/// angle less the wire's tangent angle at the anchor, once set, for a
/// body turned with its wire), and the body its wire rides, if any.
#[derive(Component, Clone, Debug)]
struct PathJointState(JointState<PlaneBody, f64>, Option<Entity>);

impl Default for PathJointState {
    fn default() -> Self {
        Self(
            JointState::new(at_rest(DVec2::ZERO, 0.0, DVec2::ZERO)),
            None,
        )
    }
}

/// A body at `centre` turned by `angle`, its anchor `arm` from its centre
/// of mass, not yet given its masses.
fn at_rest(centre: DVec2, angle: f64, arm: DVec2) -> PlaneBody {
    PlaneBody {
        centre,
        angle,
        arm,
        inverse_mass: DVec2::ZERO,
        inverse_inertia: 0.0,
    }
}

body_start!(avian2d, 2, record: recorded_body, recorded: body_of_record);

/// Solves [`PathJoint`]s in avian's substep loop. Add it after avian's
/// `PhysicsPlugins`. It also carries our beads on wires that ride
/// bodies ([`WireOnBody`]), each as a point body on a path joint, and
/// lets our beads with a radius strike its colliders (each strike sent as
/// [`BeadStruckBody`](crate::BeadStruckBody); docs/method.md, "Beads that
/// strike bodies").
#[derive(Default)]
pub struct PathJointPlugin;

impl Plugin for PathJointPlugin {
    fn build(&self, app: &mut App) {
        crate::carrier::share(app);
        add_timeline_systems(app);
        app.register_type::<PathJoint>()
            .register_type::<PathJointForces>()
            .init_resource::<WorldBodies<DVec2>>()
            .register_type::<WireOnBody>()
            .register_type::<GrabPoint<DVec2>>()
            .add_systems(
                FixedUpdate,
                (
                    board_beads::<Avian2d>.in_set(Boarding),
                    gather_world_bodies::<Avian2dWorld>
                        .in_set(WireBeadSystems::Forces)
                        .run_if(any_bead_radius),
                    apply_world_impulses::<Avian2dWorld>
                        .in_set(WireBeadSystems::Writeback)
                        .run_if(any_bead_radius),
                    hand_over_forces::<Avian2d>.in_set(WireBeadSystems::Step),
                    pull_bodies::<Avian2d>
                        .in_set(WireBeadSystems::Forces)
                        .run_if(any_with_component::<SpringAnchor<DVec2>>),
                ),
            )
            .add_systems(PreUpdate, restart_bodies.in_set(WireBeadSystems::Restart))
            .add_systems(
                FixedPostUpdate,
                add_body_energy::<Avian2dWorld>
                    .after(PhysicsSystems::StepSimulation)
                    .run_if(resource_exists::<SceneEnergy>),
            )
            .add_systems(
                PhysicsSchedule,
                (
                    prepare_path_joints.in_set(SolverSystems::PrepareJoints),
                    write_path_joint_forces.in_set(SolverSystems::Finalize),
                    read_back_beads::<Avian2d>.in_set(PhysicsStepSystems::Last),
                ),
            )
            .add_systems(
                SubstepSchedule,
                (
                    (solve_path_joints, solve_carried_path_joints)
                        .chain()
                        .in_set(XpbdSolverSystems::SolveUserConstraints),
                    // After avian turns the substep's corrections into
                    // velocity, before it damps it.
                    (
                        project_path_joint_velocities,
                        project_carried_path_joint_velocities,
                    )
                        .chain()
                        .after(XpbdSolverSystems::VelocityProjection)
                        .before(SubstepSolverSystems::Damping),
                ),
            );
    }
}

/// The wires of path joints: each one's shape, where it is over time and
/// the body it rides, if any.
type Wires<'w, 's> = Query<
    'w,
    's,
    (
        &'static Wire,
        &'static WirePose<DVec2>,
        Option<&'static WireOnBody>,
    ),
>;

/// Where a rigid body is: its origin, its turn and its centre of mass.
type Placing<'a> = (&'a Position, &'a Rotation, &'a ComputedCenterOfMass);

/// A body placed as avian has it, its anchor at `anchor` from its origin
/// (in its frame).
fn placed_body((position, rotation, centre): Placing, anchor: DVec2) -> PlaneBody {
    let origin = DVec2::from(position.0);
    let angle = f64::from(rotation.as_radians());
    let local_centre = DVec2::from(centre.0);
    at_rest(
        origin + DVec2::from_angle(angle).rotate(local_centre),
        angle,
        anchor - local_centre,
    )
}

/// Reads each joint's body, and the body its wire rides, where the step
/// begins; says once of a joint whose wire is missing that it holds
/// nothing, and of a wire on an entity that is no rigid body that it
/// stays where its place puts it.
fn prepare_path_joints(
    mut joints: Query<(Entity, &PathJoint, &mut PathJointState, Placing)>,
    bodies: Query<Placing, With<RigidBody>>,
    sleeping: Query<(Has<Sleeping>, Has<SleepingDisabled>)>,
    wires: Wires,
    clock: Res<SimClock>,
    params: Res<SimParams>,
    mut commands: Commands,
) {
    for (entity, joint, mut state, placing) in &mut joints {
        let body = placed_body(placing, joint.anchor);
        let (placed, rides) = match wires.get(joint.wire) {
            Ok((_, pose, on)) => (pose.path().is_some(), on.map(|on| on.0)),
            Err(_) => (false, None),
        };
        // A carrier's anchor is its origin; a body carries no wire that
        // holds it.
        let carrier = rides
            .filter(|&e| e != entity)
            .and_then(|e| bodies.get(e).ok().map(|b| (e, placed_body(b, DVec2::ZERO))));
        state.1 = carrier.map(|(e, _)| e);
        if let Some((e, _)) = carrier {
            let never = (SleepingDisabled, WakeBody);
            crate::carrier::keep_awake([e, entity], &sleeping, never, &mut commands);
        }
        let at = Held {
            body,
            carrier: carrier.map(|(_, b)| b),
        };
        state.0.begin(at, clock.time - params.timestep);
        if state.0.warned {
            continue;
        }
        let why = if !placed {
            Some(format!(
                "holds nothing: entity {} is not a wire with a finite pose",
                joint.wire
            ))
        } else if let (Some(rides), None) = (rides, carrier) {
            Some(format!(
                "its wire rides entity {rides}, which is no other rigid body: the wire stays \
                 where its place puts it"
            ))
        } else {
            None
        };
        if let Some(why) = why {
            warn!("wirebead: the path joint of body {entity} {why}");
            state.0.warned = true;
        }
    }
}

/// A body as the joint sees it: where the step began (`start`), moved by
/// the substep's `delta`; one with no solver body (a static carrier)
/// stays where it began.
fn plane_body(start: PlaneBody, solver: Option<(&SolverBody, &SolverBodyInertia)>) -> PlaneBody {
    let Some((body, inertia)) = solver else {
        return start;
    };
    // A kinematic body goes where the game sends it: no joint moves it.
    let movable = if body.flags.is_kinematic() { 0.0 } else { 1.0 };
    PlaneBody {
        centre: start.centre + DVec2::from(body.delta_position),
        angle: start.angle + f64::from(body.delta_rotation.as_radians()),
        inverse_mass: DVec2::from(inertia.effective_inv_mass()) * movable,
        inverse_inertia: f64::from(inertia.effective_inv_angular_inertia()) * movable,
        ..start
    }
}

/// A body's velocity as avian's solver has it (at rest without a solver
/// body).
fn velocity_of(solver: Option<&SolverBody>) -> PlaneVelocity {
    solver.map_or_else(PlaneVelocity::default, |body| PlaneVelocity {
        linear: DVec2::from(body.linear_velocity),
        spin: f64::from(body.angular_velocity),
    })
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

/// The wire of a joint: its shape and where it is over time (in its
/// carrier's frame, where it rides one).
fn wire_of<'a>(wires: &'a Wires, joint: &PathJoint) -> Option<(&'a WireShape, PosePath)> {
    wires
        .get(joint.wire)
        .ok()
        .and_then(|(wire, pose, _)| Some((wire.shape(), pose.path()?)))
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

/// SHAKE's step for each joint on a wire that rides no body, in the
/// substep: the body, moved freely by avian's substep, put back on its
/// rows along their gradients where the substep began, to rounding.
fn solve_path_joints(mut joints: JointBodies, wires: Wires, time: Res<Time>) {
    let h = time.delta_secs_f64();
    if h.is_nan() || h <= 0.0 {
        return;
    }
    // Each joint moves its own body only: the joints run in parallel.
    joints
        .par_iter_mut()
        .for_each(|(joint, mut state, mut body, inertia)| {
            if state.1.is_none() {
                solve_path_joint(joint, &mut state, ((&mut *body, inertia), None), &wires, h);
            }
        });
}

/// SHAKE's step for one joint (see [`solve_path_joints`]).
fn solve_path_joint(
    joint: &PathJoint,
    state: &mut PathJointState,
    ((body, inertia), carried): Solved,
    wires: &Wires,
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
    let (start, previous) = (state.0.start, state.0.previous);
    let carrier_solver = carried.as_ref().map(|(b, i)| (&**b, *i));
    let predicted = Held {
        body: plane_body(start.body, Some((&*body, inertia))),
        carrier: start.carrier.map(|c| plane_body(c, carrier_solver)),
    };
    // Where the substep began, as hard to move as now.
    let began = |was: PlaneBody, now: PlaneBody| PlaneBody {
        centre: was.centre,
        angle: was.angle,
        ..now
    };
    let previous = Held {
        body: began(previous.body, predicted.body),
        carrier: previous
            .carrier
            .zip(predicted.carrier)
            .map(|(was, now)| began(was, now)),
    };
    if !(predicted.body.anchor().is_finite() && predicted.body.angle.is_finite()) {
        return;
    }
    let wire_at = |pose, turned| PlaneWire {
        curve: Placed { curve: &near, pose },
        turned,
        travel: shape.travel(),
    };
    if joint.rotation == PathRotation::Turned && state.0.turn.is_none() {
        let wire = wire_at(path.pose(now - h), None).carried_by(previous.carrier.as_ref());
        state.0.turn = turn_offset(&wire.curve, &previous.body);
    }
    let turned = turned(joint, state);
    let (before, after) = (
        wire_at(path.pose(now - h), turned),
        wire_at(path.pose(now), turned),
    );
    // The velocity the body would have riding rigidly with the wire:
    // with its carrier, or as the game moves it.
    let frame = match previous.carrier {
        Some(carrier) => velocity_of(carrier_solver.map(|(b, _)| b))
            .carried_to(carrier.centre, previous.body.centre),
        None => PlaneVelocity::riding(&path.at(now - h).1, previous.body.centre),
    };
    let substep = Substep {
        before: &before,
        after: &after,
        previous,
        predicted,
        v: velocity_of(Some(&*body)),
        frame,
        h,
        start: state.0.rows.take(),
    };
    let Some((projected, driven)) = substep.correct(&law(joint)) else {
        return;
    };
    // The move is the impulse over the substep: Δq = h M⁻¹ p.
    let (p, tau) = projected.impulse.body;
    state.0.add_impulse((p / h, tau / h), driven / h);
    let moved = projected.body;
    let placed = after.carried_by(moved.carrier.as_ref());
    state.0.hint = shape.curve().parameter(
        placed.curve.pose.to_local(moved.body.anchor()),
        state.0.hint,
    );
    body.delta_position += (moved.body.centre - predicted.body.centre).adjust_precision();
    body.delta_rotation =
        Rotation::radians((moved.body.angle - start.body.angle).adjust_precision());
    if let (Some((carrier, _)), Some(moved), Some(predicted), Some(start)) =
        (carried, moved.carrier, predicted.carrier, start.carrier)
    {
        carrier.delta_position += (moved.centre - predicted.centre).adjust_precision();
        carrier.delta_rotation = Rotation::radians((moved.angle - start.angle).adjust_precision());
    }
}

/// RATTLE's velocity step for each joint on a wire that rides no body,
/// after avian has turned the substep's corrections into velocity: the
/// velocity onto the rows where the substep ends, the end of an open wire
/// stopping an anchor that would pass it (the motor and friction act in
/// the position step).
fn project_path_joint_velocities(mut joints: JointBodies, wires: Wires) {
    joints
        .par_iter_mut()
        .for_each(|(joint, mut state, mut body, inertia)| {
            if state.1.is_none() {
                project_path_joint_velocity(
                    joint,
                    &mut state,
                    ((&mut *body, inertia), None),
                    &wires,
                );
            }
        });
}

/// RATTLE's velocity step for one joint (see
/// [`project_path_joint_velocities`]).
fn project_path_joint_velocity(
    joint: &PathJoint,
    state: &mut PathJointState,
    ((body, inertia), carried): Solved,
    wires: &Wires,
) {
    let start = state.0.start;
    let carrier_solver = carried.as_ref().map(|(b, i)| (&**b, *i));
    let now = Held {
        body: plane_body(start.body, Some((&*body, inertia))),
        carrier: start.carrier.map(|c| plane_body(c, carrier_solver)),
    };
    state.0.previous = now;
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
    let v = Held {
        body: velocity_of(Some(&*body)),
        carrier: now
            .carrier
            .map(|_| velocity_of(carrier_solver.map(|(b, _)| b))),
    };
    // A carrier's velocity is the joint's to keep; a wire the game moves
    // is followed.
    let frame = if now.carrier.is_some() {
        PlaneVelocity::default()
    } else {
        PlaneVelocity::riding(&twist, now.body.centre)
    };
    let rigid = law(joint).rigid();
    let Some((v, impulse, rows)) = velocity_on_wire(rigid, &wire, &now, v, frame) else {
        return;
    };
    state.0.rows = rows;
    if v.is_finite() {
        state.0.add_impulse(impulse.body, 0.0);
        body.linear_velocity = v.body.linear.adjust_precision();
        body.angular_velocity = v.body.spin.adjust_precision();
        if let (Some((carrier, _)), Some(v)) = (carried, v.carrier) {
            carrier.linear_velocity = v.linear.adjust_precision();
            carrier.angular_velocity = v.spin.adjust_precision();
        }
    }
}
