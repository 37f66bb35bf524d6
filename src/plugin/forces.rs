//! [`DragPlugin`]: the force the plugin itself adds in
//! [`WireBeadSystems::Forces`]: the drag spring. Gravity is added by the
//! step.

use bevy::prelude::*;

use super::schedule::WireBeadSystems;
use crate::dynamics::{Bead, Diverged, DragTarget, SimParams};

/// Pulls each bead that has a [`DragTarget`] toward it with the
/// assignment's spring.
#[derive(Default)]
pub struct DragPlugin;

impl Plugin for DragPlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<DragTarget>()
            .add_systems(FixedUpdate, apply_drag.in_set(WireBeadSystems::Forces));
    }
}

/// Adds the assignment's drag spring `k (target - x)` to dragged beads.
fn apply_drag(
    params: Res<SimParams>,
    mut beads: Query<(&mut Bead, &DragTarget), Without<Diverged>>,
) {
    for (mut bead, target) in &mut beads {
        bead.add_spring(params.drag_stiffness, target.get());
    }
}
