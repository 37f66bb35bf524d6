//! Rigid bodies of avian2d on our wires: [`PathJoint`] holds a point of a
//! body (its anchor) on a [`Wire`], free to slide along it and, as asked,
//! free to turn or turned with the wire. Add [`PathJointPlugin`] after
//! avian's `PhysicsPlugins` and the [`WireBeadPlugin`](crate::WireBeadPlugin).
//!
//! The joint is solved in avian's substep loop, after its contacts and
//! its own joints, by the position corrections of extended position-based
//! dynamics, so that it composes with everything avian simulates (docs/method.md,
//! "Rigid bodies on wires"). The wire's curve and pose stay `f64`; the
//! body's state converts at the edge, in whatever precision the game
//! built avian with.
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

use avian2d::dynamics::solver::schedule::{SolverSystems, SubstepSchedule};
use avian2d::dynamics::solver::solver_body::{SolverBody, SolverBodyInertia};
use avian2d::dynamics::solver::xpbd::XpbdSolverSystems;
use avian2d::math::AdjustPrecision;
use avian2d::prelude::*;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::dynamics::{Wire, WirePose};
use crate::geometry::{Near, Placed};
use crate::solver::path::{BodyRow, PlaneBody, correct, on_curve, turn_offset, turned_with_curve};
use crate::{SimClock, SimParams};

/// How a body held on a wire by a [`PathJoint`] may turn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
pub enum PathRotation {
    /// As it likes: only its anchor is held.
    #[default]
    Free,
    /// With the wire: the body keeps the angle it had to the wire's
    /// tangent at its anchor when the joint began, as a cart on a rail.
    Turned,
}

/// Holds a point of the rigid body it is on (the anchor, in the body's
/// frame from its origin, as avian's joints take theirs) on the wire
/// `wire`, free to slide along it. The body needs avian's `RigidBody`
/// (a dynamic one: a kinematic or static body is not moved by its joint);
/// the wire is an entity with a [`Wire`] (fixed, or moving as any wire of
/// ours moves). A joint naming an entity that is no wire holds nothing,
/// and says so once in the log.
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[require(PathJointState)]
pub struct PathJoint {
    /// The wire's entity.
    pub wire: Entity,
    /// The anchor in the body's frame, from its origin.
    pub anchor: DVec2,
    /// How the body may turn.
    pub rotation: PathRotation,
    /// How far the anchor yields per newton, m/N (0: rigid), as avian's
    /// joint compliance.
    pub compliance: f64,
}

impl PathJoint {
    /// The body's origin held on `wire`, free to turn, rigidly.
    pub fn new(wire: Entity) -> Self {
        Self {
            wire,
            anchor: DVec2::ZERO,
            rotation: PathRotation::Free,
            compliance: 0.0,
        }
    }

    /// The joint with the anchor at `anchor`, in the body's frame.
    pub fn with_anchor(self, anchor: DVec2) -> Self {
        Self { anchor, ..self }
    }

    /// The joint with the body turning as `rotation` says.
    pub fn with_rotation(self, rotation: PathRotation) -> Self {
        Self { rotation, ..self }
    }
}

/// What a path joint holds from one substep to the next: the body where
/// the step began and the offset of a body turned with the wire.
#[derive(Component, Clone, Debug)]
struct PathJointState {
    /// The time the step began at, and how far into it the substeps are.
    time: (f64, f64),
    /// The centre of mass and the angle where the step began.
    start: (DVec2, f64),
    /// The anchor from the centre of mass, in the body's frame.
    arm: DVec2,
    /// The body's angle less the wire's at the anchor, once set.
    offset: Option<f64>,
    /// The curve's parameter at the anchor: its branch where it crosses
    /// itself.
    hint: f64,
    /// Why the joint holds nothing, once said.
    warned: bool,
}

impl Default for PathJointState {
    fn default() -> Self {
        Self {
            time: (0.0, 0.0),
            start: (DVec2::ZERO, 0.0),
            arm: DVec2::ZERO,
            offset: None,
            // Anywhere on the curve, until the anchor has been on it.
            hint: f64::NAN,
            warned: false,
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
            .add_systems(
                PhysicsSchedule,
                prepare_path_joints.in_set(SolverSystems::PrepareJoints),
            )
            .add_systems(
                SubstepSchedule,
                solve_path_joints.in_set(XpbdSolverSystems::SolveUserConstraints),
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

/// One XPBD correction of each joint's rows in the substep.
fn solve_path_joints(
    mut joints: Query<(
        &PathJoint,
        &mut PathJointState,
        &mut SolverBody,
        &SolverBodyInertia,
    )>,
    wires: Query<(&Wire, &WirePose<DVec2>)>,
    time: Res<Time>,
) {
    let h = time.delta_secs_f64();
    if h.is_nan() || h <= 0.0 {
        return;
    }
    for (joint, mut state, mut body, inertia) in &mut joints {
        state.time.1 += h;
        // A kinematic body goes where the game sends it; a static one has
        // no solver body at all.
        if body.flags.is_kinematic() {
            continue;
        }
        let Some((shape, path)) = wires
            .get(joint.wire)
            .ok()
            .and_then(|(wire, pose)| Some((wire.shape(), pose.path()?)))
        else {
            continue;
        };
        let pose = path.pose(state.time.0 + state.time.1);
        let near = Near {
            curve: shape.curve(),
            hint: state.hint,
        };
        let curve = Placed { curve: &near, pose };
        let (start, start_angle) = state.start;
        let centre = start + DVec2::from(body.delta_position);
        let angle = start_angle + f64::from(body.delta_rotation.as_radians());
        let mut plane = PlaneBody {
            centre,
            anchor: centre + DVec2::from_angle(angle).rotate(state.arm),
            inverse_mass: DVec2::from(inertia.effective_inv_mass()),
            inverse_inertia: f64::from(inertia.effective_inv_angular_inertia()),
        };
        if !(plane.anchor.is_finite() && angle.is_finite()) {
            continue;
        }
        let arm = state.arm;
        let mut moved = (DVec2::ZERO, 0.0);
        let apply = |row: Option<BodyRow>, plane: &mut PlaneBody, moved: &mut (DVec2, f64)| {
            let Some(row) = row else { return };
            let step = correct(&row, plane, 0.0, joint.compliance, h);
            moved.0 += step.centre;
            moved.1 += step.angle;
            plane.centre += step.centre;
            plane.anchor = plane.centre + DVec2::from_angle(angle + moved.1).rotate(arm);
        };
        apply(on_curve(&curve, &plane), &mut plane, &mut moved);
        if joint.rotation == PathRotation::Turned {
            if state.offset.is_none() {
                state.offset = turn_offset(&curve, &plane, angle + moved.1);
            }
            if let Some(offset) = state.offset {
                apply(
                    turned_with_curve(&curve, &plane, angle + moved.1, offset),
                    &mut plane,
                    &mut moved,
                );
            }
        }
        state.hint = shape
            .curve()
            .parameter(pose.to_local(plane.anchor), state.hint);
        body.delta_position += moved.0.adjust_precision();
        body.delta_rotation = Rotation::radians((angle + moved.1 - start_angle).adjust_precision());
    }
}
