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

use avian3d::dynamics::solver::islands::WakeBody;
use avian3d::dynamics::solver::schedule::{SolverSystems, SubstepSchedule, SubstepSolverSystems};
use avian3d::dynamics::solver::solver_body::{SolverBody, SolverBodyInertia};
use avian3d::dynamics::solver::xpbd::XpbdSolverSystems;
use avian3d::math::{AdjustPrecision, Quaternion, Scalar, Vector};
use avian3d::prelude::*;
use bevy::math::{DMat3, DQuat, DVec3};
use bevy::prelude::*;

use crate::carrier::{
    Boarding, board_beads, body_start, hand_over_forces, pull_bodies, read_back_beads,
};
use crate::carrier::{add_body_energy, any_bead_radius, apply_world_impulses, gather_world_bodies};
use crate::dynamics::{SpaceWire, WirePose};
use crate::geometry::{SpacePath, SpaceShape};
use crate::plugin::WorldBodies;
use crate::solver::path::{
    Alignment, BodyVelocity, Held, JointBody, JointState, JointWire, Law, SpaceBody, SpaceWireAt,
    Substep, velocity_on_wire,
};
use crate::{GrabPoint, SceneEnergy, SimClock, SimParams, SpringAnchor, WireBeadSystems};
use beads::Avian3d;
use carried::{Solved, project_carried_path_joint_velocities, solve_carried_path_joints};
pub(crate) use recorded::body_of_record;
use recorded::recorded_body;
use world::Avian3dWorld;

mod beads;
mod carried;
mod joint;
mod recorded;
mod world;

pub use crate::dynamics::WireOnBody;
pub use joint::{PathJoint, PathJointForces, PathMotor, PathRotation};

/// What a path joint in space holds from one substep to the next (how
/// the body turns with its wire, once fixed), and the body its wire
/// rides, if any.
#[derive(Component, Clone, Debug)]
struct PathJointState(JointState<SpaceBody, Alignment>, Option<Entity>);

impl Default for PathJointState {
    fn default() -> Self {
        Self(
            JointState::new(at_rest(DVec3::ZERO, DQuat::IDENTITY, DVec3::ZERO)),
            None,
        )
    }
}

/// A body at `centre` turned by `rotation`, its anchor `arm` from its
/// centre of mass (in its frame), not yet given its masses.
fn at_rest(centre: DVec3, rotation: DQuat, arm: DVec3) -> SpaceBody {
    SpaceBody {
        centre,
        rotation,
        arm,
        inverse_mass: DVec3::ZERO,
        inverse_inertia: DMat3::ZERO,
    }
}

body_start!(avian3d, 3, record: recorded_body, recorded: body_of_record);

/// Solves [`PathJoint`]s in avian3d's substep loop. Add it after avian's
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
            .init_resource::<WorldBodies<DVec3>>()
            .register_type::<WireOnBody>()
            .register_type::<GrabPoint<DVec3>>()
            .add_systems(
                FixedUpdate,
                (
                    board_beads::<Avian3d>.in_set(Boarding),
                    gather_world_bodies::<Avian3dWorld>
                        .in_set(WireBeadSystems::Forces)
                        .run_if(any_bead_radius),
                    apply_world_impulses::<Avian3dWorld>
                        .in_set(WireBeadSystems::Writeback)
                        .run_if(any_bead_radius),
                    hand_over_forces::<Avian3d>.in_set(WireBeadSystems::Step),
                    pull_bodies::<Avian3d>
                        .in_set(WireBeadSystems::Forces)
                        .run_if(any_with_component::<SpringAnchor<DVec3>>),
                ),
            )
            .add_systems(PreUpdate, restart_bodies.in_set(WireBeadSystems::Restart))
            .add_systems(
                FixedPostUpdate,
                add_body_energy::<Avian3dWorld>
                    .after(PhysicsSystems::StepSimulation)
                    .run_if(resource_exists::<SceneEnergy>),
            )
            .add_systems(
                PhysicsSchedule,
                (
                    prepare_path_joints.in_set(SolverSystems::PrepareJoints),
                    write_path_joint_forces.in_set(SolverSystems::Finalize),
                    read_back_beads::<Avian3d>.in_set(PhysicsStepSystems::Last),
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

/// A rotation of avian's, in `f64`.
pub(crate) fn rotation_of(q: Quaternion) -> DQuat {
    DQuat::from_xyzw(
        f64::from(q.x),
        f64::from(q.y),
        f64::from(q.z),
        f64::from(q.w),
    )
}

/// A vector of avian's, in `f64`.
pub(crate) fn vector_of(v: Vector) -> DVec3 {
    DVec3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z))
}

/// The wires in space of path joints: each one's shape, where it is over
/// time and the body it rides, if any.
type Wires<'w, 's> = Query<
    'w,
    's,
    (
        &'static SpaceWire,
        &'static WirePose<DVec3>,
        Option<&'static WireOnBody>,
    ),
>;

/// Where a rigid body is: its origin, its turn and its centre of mass.
type Placing<'a> = (&'a Position, &'a Rotation, &'a ComputedCenterOfMass);

/// A body placed as avian has it, its anchor at `anchor` from its origin
/// (in its frame).
fn placed_body((position, rotation, centre): Placing, anchor: DVec3) -> SpaceBody {
    let rotation = rotation_of(rotation.0).normalize();
    let local_centre = vector_of(centre.0);
    at_rest(
        vector_of(position.0) + rotation * local_centre,
        rotation,
        anchor - local_centre,
    )
}

/// Reads each joint's body, and the body its wire rides, where the step
/// begins; says once of a joint whose wire is missing, or cannot turn the
/// body as asked, that it holds nothing, or only its anchor, and of a
/// wire on an entity that is no rigid body that it stays where its place
/// puts it.
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
        let rides = wires
            .get(joint.wire)
            .ok()
            .and_then(|(_, _, on)| on.map(|on| on.0));
        // A carrier's anchor is its origin; a body carries no wire that
        // holds it.
        let carrier = rides
            .filter(|&e| e != entity)
            .and_then(|e| bodies.get(e).ok().map(|b| (e, placed_body(b, DVec3::ZERO))));
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
        let why = match wires.get(joint.wire) {
            Ok((_, pose, _)) if pose.path().is_none() => {
                Some("its wire has no finite pose".to_string())
            }
            Ok((wire, _, _))
                if matches!(wire.shape(), SpaceShape::Surface(_))
                    && !matches!(joint.rotation, PathRotation::Free | PathRotation::Fixed) =>
            {
                Some(
                    "a surface has no tangent to turn it with, so it holds the anchor only"
                        .to_string(),
                )
            }
            Ok(_) => match (rides, carrier) {
                (Some(rides), None) => Some(format!(
                    "its wire rides entity {rides}, which is no other rigid body: the wire \
                     stays where its place puts it"
                )),
                _ => None,
            },
            Err(_) => Some("its wire is not a wire in space".to_string()),
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

/// A body as the joint sees it: where the step began (`start`), moved by
/// the substep's `delta`; one with no solver body (a static carrier)
/// stays where it began.
fn space_body(start: SpaceBody, solver: Option<(&SolverBody, &SolverBodyInertia)>) -> SpaceBody {
    let Some((body, inertia)) = solver else {
        return start;
    };
    let m = inertia.effective_inv_angular_inertia();
    let column =
        |x: Scalar, y: Scalar, z: Scalar| DVec3::new(f64::from(x), f64::from(y), f64::from(z));
    // A kinematic body goes where the game sends it: no joint moves it.
    let movable = if body.flags.is_kinematic() { 0.0 } else { 1.0 };
    SpaceBody {
        centre: start.centre + vector_of(body.delta_position),
        rotation: (rotation_of(body.delta_rotation.0) * start.rotation).normalize(),
        inverse_mass: vector_of(inertia.effective_inv_mass()) * movable,
        inverse_inertia: DMat3::from_cols(
            column(m.m00, m.m01, m.m02),
            column(m.m01, m.m11, m.m12),
            column(m.m02, m.m12, m.m22),
        ) * movable,
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

/// The wire of a joint: its shape and where it is over time (in its
/// carrier's frame, where it rides one).
fn wire_of<'a>(wires: &'a Wires, joint: &PathJoint) -> Option<(&'a SpaceShape, SpacePath)> {
    wires
        .get(joint.wire)
        .ok()
        .and_then(|(wire, pose, _)| Some((wire.shape(), pose.path()?)))
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

/// The body's velocity as avian's solver has it (at rest without a solver
/// body).
fn velocity_of(solver: Option<&SolverBody>) -> BodyVelocity<SpaceBody> {
    solver.map_or_else(BodyVelocity::default, |body| BodyVelocity {
        linear: vector_of(body.linear_velocity),
        spin: vector_of(body.angular_velocity),
    })
}

/// SHAKE's step for one joint (see [`solve_path_joints`]).
fn solve_path_joint(
    joint: &PathJoint,
    state: &mut PathJointState,
    ((body, inertia), carried): Solved,
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
    let carrier_solver = carried.as_ref().map(|(b, i)| (&**b, *i));
    let predicted = Held {
        body: space_body(state.start.body, Some((&*body, inertia))),
        carrier: state.start.carrier.map(|c| space_body(c, carrier_solver)),
    };
    // Where the substep began, as hard to move as now.
    let began = |was: SpaceBody, now: SpaceBody| SpaceBody {
        centre: was.centre,
        rotation: was.rotation,
        ..now
    };
    let previous = Held {
        body: began(state.previous.body, predicted.body),
        carrier: state
            .previous
            .carrier
            .zip(predicted.carrier)
            .map(|(was, now)| began(was, now)),
    };
    if !(predicted.body.anchor().is_finite() && predicted.body.rotation.is_finite()) {
        return;
    }
    let mut before = SpaceWireAt {
        shape,
        pose: path.pose(now - h),
        hint: state.hint,
        alignment: None,
    };
    if let Some(turn) = joint.rotation.turn()
        && state.turn.is_none()
        && let Some(frame) = before
            .carried_by(previous.carrier.as_ref())
            .frame(&previous.body, turn)
    {
        state.turn = Some(Alignment {
            turn,
            axes: (previous.body.rotation.inverse() * frame).normalize(),
        });
    }
    before.alignment = state.turn;
    let after = SpaceWireAt {
        pose: path.pose(now),
        ..before
    };
    // The velocity the body would have riding rigidly with the wire:
    // with its carrier, or as the game moves it.
    let frame = match previous.carrier {
        Some(carrier) => velocity_of(carrier_solver.map(|(b, _)| b))
            .carried_to(carrier.centre, previous.body.centre),
        None => BodyVelocity::riding(&path.at(now - h).1, previous.body.centre),
    };
    let substep = Substep {
        before: &before,
        after: &after,
        previous,
        predicted,
        v: velocity_of(Some(&*body)),
        frame,
        h,
        start: state.rows.take(),
    };
    let Some((projected, driven)) = substep.correct(&law(joint)) else {
        return;
    };
    let (p, tau) = projected.impulse.body;
    state.add_impulse((p / h, tau / h), driven / h);
    let moved = projected.body;
    state.hint = after
        .carried_by(moved.carrier.as_ref())
        .parameter(&moved.body);
    let start = state.start;
    let write =
        |solver: &mut SolverBody, moved: SpaceBody, predicted: SpaceBody, start: SpaceBody| {
            solver.delta_position += (moved.centre - predicted.centre).adjust_precision();
            solver.delta_rotation = Rotation(
                (moved.rotation * start.rotation.inverse())
                    .normalize()
                    .adjust_precision(),
            );
        };
    write(body, moved.body, predicted.body, start.body);
    if let (Some((carrier, _)), Some(moved), Some(predicted), Some(start)) =
        (carried, moved.carrier, predicted.carrier, start.carrier)
    {
        write(carrier, moved, predicted, start);
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
    let carrier_solver = carried.as_ref().map(|(b, i)| (&**b, *i));
    let now = Held {
        body: space_body(state.0.start.body, Some((&*body, inertia))),
        carrier: state.0.start.carrier.map(|c| space_body(c, carrier_solver)),
    };
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
    let v = Held {
        body: velocity_of(Some(&*body)),
        carrier: now
            .carrier
            .map(|_| velocity_of(carrier_solver.map(|(b, _)| b))),
    };
    // A carrier's velocity is the joint's to keep; a wire the game moves
    // is followed.
    let frame = if now.carrier.is_some() {
        BodyVelocity::default()
    } else {
        BodyVelocity::riding(&twist, now.body.centre)
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
