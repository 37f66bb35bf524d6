//! The spring of a [`SpringAnchor`] on a rigid body: the scene's mouse
//! drag of a body, or a game's pull. The force `k (anchor - p)` acts at
//! the body's [`GrabPoint`] `p` (its origin without one) for the step, so
//! that a body taken by a corner turns as well as moves.

use bevy::prelude::*;

use super::PointBodies;
use crate::dynamics::{BeadPosition, GrabPoint, SimParams, SpringAnchor};
use crate::geometry::Coordinates;

/// Pulls each body of `A`'s avian that has a [`SpringAnchor`] (and is no
/// bead of ours riding a body, which the bead's own spring pulls).
pub(crate) fn pull_bodies<A: PointBodies>(
    params: Res<SimParams>,
    mut bodies: Query<
        (&SpringAnchor<A::V>, Option<&GrabPoint<A::V>>, A::Pulled),
        Without<BeadPosition<A::V>>,
    >,
) {
    for (target, grab, body) in &mut bodies {
        let grab = grab.map_or(A::V::ZERO, GrabPoint::get);
        A::pull(body, grab, target.get(), params.drag_stiffness);
    }
}
