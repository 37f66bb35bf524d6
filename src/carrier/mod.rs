//! What the avian adapters share about wires that ride bodies: each path
//! joint on such a wire is met with its own body and its carrier's, one
//! joint after another in the substep (joints on one carrier move it in
//! turn); a bead of ours on one rides it as a point body on a path joint
//! (see `beads`).

use bevy::ecs::component::Mutable;
use bevy::prelude::*;

use crate::dynamics::{
    Boarded, Diverged, DivergenceReason, OnWire, RidingBody, WireBeads, WireOnBody,
};
use crate::plugin::{Divergences, SimClock, WireBeadSystems};

mod beads;
mod pull;
mod restart;
mod world;

pub(crate) use beads::{
    Boarder, Boarding, PointBodies, board_beads, hand_over_forces, point_bodies, read_back_beads,
};
pub(crate) use pull::pull_bodies;
pub(crate) use restart::body_start;
pub(crate) use world::{
    BodyRead, ColliderRead, WorldShapes, add_body_energy, any_bead_radius, apply_world_impulses,
    gather_world_bodies, world_shapes,
};

/// A joint's body in the substep's solver (`S` avian's solver body, `I`
/// its inertia), and its carrier's where the carrier has one.
pub(crate) type Solved<'a, S, I> = ((&'a mut S, &'a I), Option<(&'a mut S, &'a I)>);

/// A joint's state that knows the body its wire rides, if any.
pub(crate) trait RidesBody {
    /// The carrier's entity.
    fn carrier(&self) -> Option<Entity>;
}

/// Calls `solve` with each joint whose wire rides a body, its body and its
/// carrier's; a static carrier, which has no solver body, as none.
pub(crate) fn each_carried<J, T, S, I>(
    joints: &mut Query<(Entity, &J, &mut T)>,
    bodies: &mut Query<(&mut S, &I)>,
    mut solve: impl FnMut(&J, &mut T, Solved<S, I>),
) where
    J: Component,
    T: Component<Mutability = Mutable> + RidesBody,
    S: Component<Mutability = Mutable>,
    I: Component,
{
    for (entity, joint, mut state) in joints {
        let Some(carrier) = state.carrier() else {
            continue;
        };
        if let Ok([(mut body, inertia), (mut carried, carried_inertia)]) =
            bodies.get_many_mut([entity, carrier])
        {
            let carried = Some((&mut *carried, carried_inertia));
            solve(joint, &mut state, ((&mut *body, inertia), carried));
        } else if let Ok((mut body, inertia)) = bodies.get_mut(entity) {
            solve(joint, &mut state, ((&mut *body, inertia), None));
        }
    }
}

/// Keeps a body held on a carried wire and its carrier (`pair`) awake
/// for good: avian sleeps bodies one by one and a body asleep keeps no
/// velocity, so one of the pair falling asleep while the other moves
/// would take the pair's momentum with it. `S` is avian's `Sleeping`, `D`
/// its `SleepingDisabled` (`never`), `wake` its `WakeBody`.
pub(crate) fn keep_awake<S: Component, D: Component + Copy, W: Command>(
    pair: [Entity; 2],
    states: &Query<(Has<S>, Has<D>)>,
    (never, wake): (D, impl Fn(Entity) -> W),
    commands: &mut Commands,
) {
    for body in pair {
        let Ok((asleep, kept)) = states.get(body) else {
            continue;
        };
        if !kept {
            commands.entity(body).try_insert(never);
        }
        if asleep {
            commands.queue(wake(body));
        }
    }
}

/// Stops each bead of ours on a wire that rides a body that no avian
/// plugin boarded (none of its dimension was added), before the step, and
/// says why in one line: the wire is placed in the body's frame, which the
/// plugin's own step does not follow. The bead is
/// [`Diverged`] with [`DivergenceReason::InvalidWire`] until a restart.
fn stop_beads_on_carried_wires(
    beads: Query<(Entity, &OnWire), (With<RidingBody>, Without<Boarded>, Without<Diverged>)>,
    wires: Query<&WireOnBody>,
    clock: Res<SimClock>,
    mut divergences: Divergences,
) {
    for (bead, on) in &beads {
        let Ok(carrier) = wires.get(on.0) else {
            continue;
        };
        let why = format!(
            "wire {} rides body {}, and no avian plugin of the bead's dimension carries it",
            on.0, carrier.0
        );
        divergences.report(bead, DivergenceReason::InvalidWire(why), clock.time);
    }
}

/// Marks a bead put on a wire as [`RidingBody`] where the wire rides a
/// body, and unmarks it where it does not.
fn mark_bead_put_on_wire(
    put: On<Insert, OnWire>,
    beads: Query<&OnWire>,
    carried: Query<(), With<WireOnBody>>,
    mut commands: Commands,
) {
    let bead = put.entity;
    let rides = beads.get(bead).is_ok_and(|on| carried.contains(on.0));
    mark(&mut commands, bead, rides);
}

/// Marks the beads of a wire put on a body as [`RidingBody`] (`RIDES`),
/// or unmarks them as it is taken off one.
fn mark_beads_of_wire<E: EntityEvent, const RIDES: bool>(
    changed: On<E, WireOnBody>,
    wires: Query<&WireBeads>,
    mut commands: Commands,
) {
    for bead in wires
        .get(changed.event_target())
        .into_iter()
        .flat_map(|b| b.iter())
    {
        mark(&mut commands, bead, RIDES);
    }
}

/// Marks `bead` as riding a body, or takes the mark (and its boarding)
/// off.
fn mark(commands: &mut Commands, bead: Entity, rides: bool) {
    let mut bead = commands.entity(bead);
    if rides {
        bead.try_insert(RidingBody);
    } else {
        bead.try_remove::<(RidingBody, Boarded)>();
    }
}

/// Marks a bead taken off its wire as riding nothing.
fn unmark_bead_taken_off(taken: On<Remove, OnWire>, mut commands: Commands) {
    mark(&mut commands, taken.entity, false);
}

/// Whether [`stop_beads_on_carried_wires`] is scheduled: either avian
/// plugin schedules it, once.
#[derive(Resource)]
struct CarriedWiresWatched;

/// Schedules what both avian plugins share, once however many of them
/// the game adds.
pub(crate) fn share(app: &mut App) {
    if app.world().contains_resource::<CarriedWiresWatched>() {
        return;
    }
    app.insert_resource(CarriedWiresWatched)
        .add_observer(mark_bead_put_on_wire)
        .add_observer(unmark_bead_taken_off)
        .add_observer(mark_beads_of_wire::<Insert, true>)
        .add_observer(mark_beads_of_wire::<Remove, false>)
        .configure_sets(FixedUpdate, Boarding.in_set(WireBeadSystems::Prepare))
        .add_systems(
            FixedUpdate,
            stop_beads_on_carried_wires
                .in_set(WireBeadSystems::Prepare)
                .after(Boarding),
        );
}
