//! [`SpringAnchorPlugin`]: the force the plugin itself adds in
//! [`WireBeadSystems::Forces`]: the spring toward a bead's anchor. Gravity is added by the
//! step.

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use super::schedule::WireBeadSystems;
use crate::dynamics::{BeadForces, Dimension, Diverged, SimParams, SpringAnchor};

/// Pulls each bead that has a [`SpringAnchor`] toward it with the
/// assignment's spring.
#[derive(Default)]
pub struct SpringAnchorPlugin;

impl Plugin for SpringAnchorPlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<SpringAnchor>()
            .register_type::<SpringAnchor<DVec3>>()
            .add_systems(
                FixedUpdate,
                // Each skipped, not run empty, while no bead has an anchor.
                (
                    apply_anchor_springs::<DVec2>.run_if(any_with_component::<SpringAnchor<DVec2>>),
                    apply_anchor_springs::<DVec3>.run_if(any_with_component::<SpringAnchor<DVec3>>),
                )
                    .in_set(WireBeadSystems::Forces),
            );
    }
}

/// Adds the spring `k (anchor - x)` to each bead with a [`SpringAnchor`]
/// (the assignment's drag spring).
fn apply_anchor_springs<V: Dimension>(
    params: Res<SimParams>,
    mut beads: Query<(BeadForces<V>, &SpringAnchor<V>), Without<Diverged>>,
) {
    for (mut bead, target) in &mut beads {
        bead.add_spring(params.drag_stiffness, target.get());
    }
}
