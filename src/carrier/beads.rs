//! Beads of ours on wires that ride bodies, what both dimensions share:
//! each such bead is made a point body of avian (its mass, its rotation
//! locked, no collider) held on its wire by a path joint, so that avian
//! steps it with its carrier and the two push on each other as a body on a
//! path joint and its carrier do; a bead that cannot ride so is stopped
//! and says why.

use bevy::ecs::component::Mutable;
use bevy::ecs::query::{IterQueryData, QueryItem, ROQueryItem, ReadOnlyQueryData};
use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use crate::dynamics::{
    BeadDiagnostics, BeadForce, BeadMass, BeadPosition, BeadRadius, BeadVelocity, Boarded,
    Dimension, Diverged, DivergenceReason, Joint, Pin, RidingBody, Rod, SimParams, Spring,
    WireBeads, WireOnBody, WireRows,
};
use crate::plugin::{Divergences, SimClock};
use crate::solver::BeadState;
use crate::solver::path::{BodyVelocity, Held, JointBody, Rows};

/// What beads riding bodies need of one avian crate (avian2d or
/// avian3d): its components, read in `f64`, and the components that make
/// a bead a point body of it.
pub(crate) trait PointBodies: Send + Sync + 'static {
    /// The beads' coordinates.
    type V: Dimension;
    /// A body as a path joint's rows take it.
    type Body: JointBody<V = Self::V>;
    /// Avian's `Position`.
    type Position: Component;
    /// Avian's `LinearVelocity`.
    type Linear: Component;
    /// Avian's `AngularVelocity`.
    type Spin: Component;
    /// Avian's `ConstantForce`.
    type Force: Component<Mutability = Mutable> + PartialEq;
    /// A rigid body that may carry a wire, as read: where it is and how it
    /// moves.
    type Carrier: ReadOnlyQueryData;
    /// The path joint's state on a body.
    type Joint: Component;
    /// What the path joint did over the step.
    type JointForces: Component;

    /// A position in `f64`.
    fn position(position: &Self::Position) -> Self::V;
    /// A body's linear velocity in `f64`.
    fn linear(linear: &Self::Linear) -> Self::V;
    /// A body's velocity in `f64`.
    fn velocity(linear: &Self::Linear, spin: &Self::Spin) -> BodyVelocity<Self::Body>;
    /// The velocity of the point `at` of a carrier.
    fn carried(carrier: ROQueryItem<'_, '_, Self::Carrier>, at: Self::V) -> Self::V;
    /// A force held through avian's step.
    fn force(force: Self::V) -> Self::Force;
    /// A joint's rows where its last substep ended, and the body its wire
    /// rides.
    fn rows(joint: &Self::Joint) -> (Option<&Rows<Self::Body>>, Option<Entity>);
    /// A joint's mean force on its body over the step.
    fn joint_force(forces: &Self::JointForces) -> Self::V;
    /// The components that make `bead` a point body held on its wire: its
    /// mass, its rotation locked, no collider, `gravity` in place of
    /// avian's, and the joint afresh.
    fn point_body(bead: Boarder<Self::V>, gravity: Self::V) -> impl Bundle;
    /// A rigid body a spring pulls: where it is, and what takes the force.
    type Pulled: IterQueryData;
    /// Applies to `body` for the step the spring `k (target - p)` at its
    /// point `p`, `grab` in its frame; the spring's force.
    fn pull(
        body: QueryItem<'_, '_, Self::Pulled>,
        grab: Self::V,
        target: Self::V,
        k: f64,
    ) -> Self::V;
}

/// The beads are boarded in this set, in
/// [`WireBeadSystems::Prepare`](crate::WireBeadSystems::Prepare) before
/// the plugin's step; the beads left on carried wires are stopped after
/// it.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct Boarding;

/// A bead about to ride a body: where it is and how it moves in the world,
/// its mass, and the wire it is held on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Boarder<V> {
    /// Its position.
    pub at: V,
    /// Its velocity: its own relative to the wire, plus the carrier's
    /// point's where it starts.
    pub velocity: V,
    /// Its mass, kg.
    pub mass: f64,
    /// The wire's entity.
    pub wire: Entity,
}

/// The wires of one dimension that ride bodies, with their beads.
pub(crate) type CarriedWires<'w, 's, V> = Query<
    'w,
    's,
    (
        Entity,
        &'static WireOnBody,
        &'static WireBeads,
        &'static <V as Dimension>::Wire,
    ),
>;

/// The beads of one dimension on carried wires that are not boarded yet
/// and have not stopped: where they are, how they move, their mass and
/// radius.
pub(crate) type Waiting<'w, 's, V> = Query<
    'w,
    's,
    (
        &'static BeadPosition<V>,
        &'static BeadVelocity<V>,
        &'static BeadMass,
        Option<&'static BeadRadius>,
    ),
    (
        With<<V as Dimension>::Bead>,
        With<RidingBody>,
        Without<Boarded>,
        Without<Diverged>,
    ),
>;

/// Every link of one dimension, as boarding asks whether a bead is joined
/// to another or to a point.
#[derive(SystemParam)]
pub(crate) struct Links<'w, 's, V: Dimension> {
    rods: Query<'w, 's, &'static Rod>,
    springs: Query<'w, 's, &'static Spring>,
    pins: Query<'w, 's, &'static Pin<V>>,
    joints: Query<'w, 's, &'static Joint<V>>,
}

impl<V: Dimension> Links<'_, '_, V> {
    /// Whether a link names `bead`.
    fn join(&self, bead: Entity) -> bool {
        self.rods.iter().any(|rod| rod.beads().contains(&bead))
            || self
                .springs
                .iter()
                .any(|spring| spring.beads().contains(&bead))
            || self.pins.iter().any(|pin| pin.bead() == bead)
            || self
                .joints
                .iter()
                .any(|joint| joint.beads().contains(&bead))
    }
}

/// Boards each bead of `beads` on a wire of `wires` not yet boarded:
/// marked [`Boarded`] and given `body(boarder)`, the components
/// that make it a point body of avian held on its wire. `carrier(body, at)`
/// is the velocity of the point `at` of the rigid body `body`, `None`
/// where `body` is no rigid body. A bead that cannot ride is stopped,
/// its wire invalid, with the reason in words.
fn board<V: Dimension, B: Bundle>(
    (wires, beads, links): (&CarriedWires<V>, &Waiting<V>, &Links<V>),
    carrier: impl Fn(Entity, V) -> Option<V>,
    body: impl Fn(Boarder<V>) -> B,
    commands: &mut Commands,
    (divergences, clock): (&mut Divergences, &SimClock),
) {
    for (wire, on, riders, shape) in wires {
        for bead in riders.iter() {
            let Ok((position, velocity, mass, radius)) = beads.get(bead) else {
                continue;
            };
            let riding = if radius.is_some_and(|r| r.get() > 0.0) {
                Err("the bead has a radius, and beads that touch do not ride bodies yet")
            } else if links.join(bead) {
                Err("the bead is joined to others, and joined beads do not ride bodies yet")
            } else if !shape.surface().is_plain() {
                Err(
                    "the wire is one-sided, rough or damped, and beads ride only plain wires on bodies",
                )
            } else {
                carrier(on.0, position.0).ok_or("that entity is no rigid body")
            };
            match riding {
                Ok(carried) => {
                    let boarder = Boarder {
                        at: position.0,
                        velocity: velocity.0 + carried,
                        mass: mass.get(),
                        wire,
                    };
                    commands.entity(bead).insert((Boarded, body(boarder)));
                }
                Err(why) => {
                    let why = format!("wire {wire} rides body {}, but {why}", on.0);
                    divergences.report(bead, DivergenceReason::InvalidWire(why), clock.time);
                }
            }
        }
    }
}

/// Boards each bead on a wire that rides a body (see [`board`]); `A` the
/// avian crate of the bead's dimension.
pub(crate) fn board_beads<A: PointBodies>(
    beads: (CarriedWires<A::V>, Waiting<A::V>, Links<A::V>),
    carriers: Query<A::Carrier>,
    (params, clock): (Res<SimParams>, Res<SimClock>),
    mut commands: Commands,
    mut divergences: Divergences,
) {
    let (wires, waiting, links) = beads;
    let carried = |body: Entity, at: A::V| carriers.get(body).ok().map(|c| A::carried(c, at));
    let gravity = A::V::gravity(&params);
    board(
        (&wires, &waiting, &links),
        carried,
        |bead| A::point_body(bead, gravity),
        &mut commands,
        (&mut divergences, &clock),
    );
}

/// Hands each riding bead's forces of the step (the drag spring, a game's
/// own) to avian as a force held through its step, emptying the bead's
/// accumulator as the plugin's step does.
pub(crate) fn hand_over_forces<A: PointBodies>(
    mut beads: Query<
        (&mut BeadForce<A::V>, &mut A::Force),
        (With<<A::V as Dimension>::Bead>, With<Boarded>),
    >,
) {
    for (mut force, mut held) in &mut beads {
        let force_now = A::force(force.get().0);
        if *held != force_now {
            *held = force_now;
        }
        force.clear();
    }
}

/// What a riding bead's read back takes: avian's state of it, its joint's,
/// and its own columns.
type Riding<A> = (
    (
        &'static <A as PointBodies>::Position,
        &'static <A as PointBodies>::Linear,
        &'static BeadMass,
    ),
    (
        &'static <A as PointBodies>::Joint,
        &'static <A as PointBodies>::JointForces,
    ),
    (
        &'static mut BeadPosition<<A as PointBodies>::V>,
        &'static mut BeadVelocity<<A as PointBodies>::V>,
        Option<&'static mut BeadDiagnostics<<A as PointBodies>::V>>,
    ),
);

/// Reads each riding bead back when avian's step ends: its position and
/// velocity, and its diagnostics from its joint's rows (the row furthest
/// from met, its rate, and the joint's mean force).
pub(crate) fn read_back_beads<A: PointBodies>(
    mut beads: Query<Riding<A>, (With<<A::V as Dimension>::Bead>, With<Boarded>)>,
    carriers: Query<(&A::Linear, &A::Spin)>,
    params: Res<SimParams>,
) {
    for ((position, linear, mass), (joint, forces), (mut at, mut v, diagnostics)) in &mut beads {
        let state = BeadState {
            position: A::position(position),
            velocity: A::linear(linear),
        };
        if at.0 != state.position {
            at.0 = state.position;
        }
        if v.0 != state.velocity {
            v.0 = state.velocity;
        }
        let Some(mut diagnostics) = diagnostics else {
            continue;
        };
        let (rows, carrier) = A::rows(joint);
        let moving = Held {
            body: BodyVelocity {
                linear: state.velocity,
                ..default()
            },
            carrier: carrier
                .and_then(|carrier| carriers.get(carrier).ok())
                .map(|(linear, spin)| A::velocity(linear, spin)),
        };
        let force = A::joint_force(forces);
        let row = rows
            .map(|rows| rows.report(&moving, force))
            .unwrap_or_default();
        let gravity = A::V::gravity(&params);
        *diagnostics = BeadDiagnostics::of(state, mass.get(), gravity, row, force);
    }
}

/// [`PointBodies`] for one avian crate, whose components have the same
/// names in both: `$avian` the crate, `$bodies` the type to implement it
/// on, `$v` the beads' coordinates and `$body` a body of the joint's rows;
/// `$vector` reads one of the crate's vectors in `f64`, `$spin` its
/// angular velocity, and `$inertia` is the angular inertia of a point
/// body of mass `m` (`f32`), which a dynamic body must have and a locked
/// rotation leaves unused. Invoked in each avian adapter, where its path
/// joint's components are in scope.
macro_rules! point_bodies {
    (
        $avian:ident, $bodies:ident, $v:ty, $body:ty,
        vector: $vector:expr, spin: $spin:expr, inertia: |$m:ident| $inertia:expr
    ) => {
        impl $crate::carrier::PointBodies for $bodies {
            type V = $v;
            type Body = $body;
            type Position = $avian::prelude::Position;
            type Linear = $avian::prelude::LinearVelocity;
            type Spin = $avian::prelude::AngularVelocity;
            type Force = $avian::prelude::ConstantForce;
            type Carrier = (
                Placing<'static>,
                &'static $avian::prelude::LinearVelocity,
                &'static $avian::prelude::AngularVelocity,
                &'static $avian::prelude::RigidBody,
            );
            type Joint = PathJointState;
            type JointForces = PathJointForces;

            fn position(position: &Self::Position) -> $v {
                $vector(position.0)
            }

            fn linear(linear: &Self::Linear) -> $v {
                $vector(linear.0)
            }

            fn velocity(
                linear: &Self::Linear,
                spin: &Self::Spin,
            ) -> $crate::solver::path::BodyVelocity<$body> {
                $crate::solver::path::BodyVelocity {
                    linear: Self::linear(linear),
                    spin: $spin(spin.0),
                }
            }

            fn carried(
                (placing, linear, spin, _): bevy::ecs::query::ROQueryItem<'_, '_, Self::Carrier>,
                at: $v,
            ) -> $v {
                let centre = placed_body(placing, <$v>::ZERO).centre;
                Self::velocity(linear, spin).carried_to(centre, at).linear
            }

            fn force(force: $v) -> Self::Force {
                use $avian::math::AdjustPrecision as _;
                $avian::prelude::ConstantForce(force.adjust_precision())
            }

            fn rows(
                joint: &PathJointState,
            ) -> (
                Option<&$crate::solver::path::Rows<$body>>,
                Option<bevy::prelude::Entity>,
            ) {
                (joint.0.rows.as_ref(), joint.1)
            }

            fn joint_force(forces: &PathJointForces) -> $v {
                forces.force
            }

            fn point_body(
                bead: $crate::carrier::Boarder<$v>,
                gravity: $v,
            ) -> impl bevy::prelude::Bundle {
                use $avian::math::AdjustPrecision as _;
                use $avian::prelude::*;
                let $m = bead.mass as f32;
                (
                    (
                        RigidBody::Dynamic,
                        Position(bead.at.adjust_precision()),
                        LinearVelocity(bead.velocity.adjust_precision()),
                        AngularVelocity::default(),
                        Mass($m),
                        $inertia,
                        LockedAxes::ROTATION_LOCKED,
                    ),
                    (
                        GravityScale(0.0),
                        ConstantLinearAcceleration(gravity.adjust_precision()),
                        ConstantForce::default(),
                        PathJoint::new(bead.wire),
                        PathJointState::default(),
                    ),
                )
            }

            type Pulled = (Placing<'static>, $avian::prelude::Forces);

            fn pull(
                (placing, mut forces): bevy::ecs::query::QueryItem<'_, '_, Self::Pulled>,
                grab: $v,
                target: $v,
                k: f64,
            ) -> $v {
                use $avian::math::AdjustPrecision as _;
                use $avian::prelude::WriteRigidBodyForces as _;
                use $crate::solver::path::JointBody as _;
                let at = placed_body(placing, grab).anchor();
                let force = k * (target - at);
                forces.apply_force_at_point(force.adjust_precision(), at.adjust_precision());
                force
            }
        }
    };
}

pub(crate) use point_bodies;
