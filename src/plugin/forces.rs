//! The forces the plugin itself adds in
//! [`WireBeadSystems::Forces`](crate::WireBeadSystems::Forces): the drag
//! spring. Gravity is added by the step.

use bevy::prelude::*;

use crate::dynamics::{Bead, Diverged, DragTarget, SimParams};

/// Adds the assignment's drag spring `k (target - x)` to dragged beads.
pub(crate) fn apply_drag(
    params: Res<SimParams>,
    mut beads: Query<(&mut Bead, &DragTarget), Without<Diverged>>,
) {
    for (mut bead, target) in &mut beads {
        bead.add_spring(params.drag_stiffness, target.get());
    }
}
