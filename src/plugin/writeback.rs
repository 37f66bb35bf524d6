//! [`WritebackPlugin`]: `f64` positions into `Transform`s, converted at
//! this edge, in [`WireBeadSystems::Writeback`].

use bevy::ecs::change_detection::Tick;
use bevy::math::DVec2;
use bevy::prelude::*;

use super::parallel::ParallelStep;
use super::schedule::WireBeadSystems;
use crate::dynamics::BeadPosition;

/// Keeps each bead's `Transform` at its position where the step did not
/// write it itself (a restart, a game's own edit).
#[derive(Default)]
pub struct WritebackPlugin;

impl Plugin for WritebackPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<LastStep>().add_systems(
            FixedUpdate,
            write_transforms.in_set(WireBeadSystems::Writeback),
        );
    }
}

/// The change tick of the last run of the step: it wrote the `Transform`
/// of every bead it changed then.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub(crate) struct LastStep(pub(crate) Tick);

/// Writes each bead's position into its `Transform` (x and y; z is kept)
/// where the bead changed other than by the last step (a restart, a
/// game's own edit); the step writes the ones it steps. A non-finite
/// position is never written.
fn write_transforms(
    parallel: Res<ParallelStep>,
    stepped: Res<LastStep>,
    mut beads: Query<(Ref<BeadPosition>, &mut Transform), Changed<BeadPosition>>,
) {
    let write = |(position, mut transform): (Ref<BeadPosition>, Mut<Transform>)| {
        // The step wrote the ones it changed last (without reading them
        // again here).
        if position.last_changed() != stepped.0 {
            place(&mut transform, position.0);
        }
    };
    if beads.iter().size_hint().1.unwrap_or(usize::MAX) >= parallel.threshold {
        beads.par_iter_mut().for_each(write);
    } else {
        beads.iter_mut().for_each(write);
    }
}

/// Writes a bead's position into its `Transform` (x and y, rounded to
/// `f32`; z is kept), unless it is not finite in `f32` (a NaN, or a
/// coordinate past `f32::MAX`): then the `Transform` keeps its last value.
#[inline(always)]
pub(crate) fn place(transform: &mut Transform, position: DVec2) {
    let at = position.as_vec2();
    if at.is_finite() {
        transform.translation.x = at.x;
        transform.translation.y = at.y;
    }
}
