//! What the avian adapters share about wires that ride bodies: each path
//! joint on such a wire is met with its own body and its carrier's, one
//! joint after another in the substep (joints on one carrier move it in
//! turn).

use bevy::ecs::component::Mutable;
use bevy::prelude::*;

use crate::dynamics::{Diverged, DivergenceReason, WireBeads, WireOnBody};
use crate::plugin::{Divergences, SimClock, WireBeadSystems};

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

/// Stops each bead of ours on a wire that rides a body, before the step,
/// and says why in one line: a wire that rides a body is placed in the
/// body's frame, which our beads do not follow yet (a path joint's body
/// does), so stepping the bead would put it on the wire as if its place
/// were in the world. The bead is [`Diverged`] with
/// [`DivergenceReason::InvalidWire`] until a restart, as a bead on a wire
/// that cannot be placed is.
fn stop_beads_on_carried_wires(
    wires: Query<(Entity, &WireOnBody, &WireBeads)>,
    stopped: Query<(), With<Diverged>>,
    clock: Res<SimClock>,
    mut divergences: Divergences,
) {
    for (wire, on, beads) in &wires {
        for bead in beads.iter().filter(|&bead| !stopped.contains(bead)) {
            let why = format!(
                "wire {wire} rides body {}, which beads do not ride yet (a PathJoint's body does)",
                on.0
            );
            divergences.report(bead, DivergenceReason::InvalidWire(why), clock.time);
        }
    }
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
    app.insert_resource(CarriedWiresWatched).add_systems(
        FixedUpdate,
        stop_beads_on_carried_wires.in_set(WireBeadSystems::Prepare),
    );
}
