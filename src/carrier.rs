//! What the avian adapters share about wires that ride bodies: each path
//! joint on such a wire is met with its own body and its carrier's, one
//! joint after another in the substep (joints on one carrier move it in
//! turn).

use bevy::ecs::component::Mutable;
use bevy::prelude::*;

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
