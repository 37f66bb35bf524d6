//! [`WritebackPlugin`]: `f64` positions into `Transform`s, converted at
//! this edge, in [`WireBeadSystems::Writeback`].

use std::marker::PhantomData;

use bevy::ecs::change_detection::Tick;
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use super::clock::SimClock;
use super::energy::{SceneEnergy, measure_scene_energy};
use super::parallel::ParallelStep;
use super::schedule::WireBeadSystems;
use crate::dynamics::{
    Bead, BeadParams, BeadPosition, Dimension, OnWire, RailOrientation, RidingBody, SpaceBead,
    SpaceWire, WirePose,
};
use crate::geometry::SpaceShape;

/// Keeps each bead's `Transform` at its position where the step did not
/// write it itself (a restart, a game's own edit), places it there as
/// the bead is spawned (drawn where it is before its first step, in a
/// scene loaded paused), and keeps the [`SceneEnergy`] where the app has
/// it.
#[derive(Default)]
pub struct WritebackPlugin;

impl Plugin for WritebackPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<LastStep<DVec2>>()
            .init_resource::<LastStep<DVec3>>()
            .add_systems(
                FixedUpdate,
                // Each skipped, not run empty, while there is nothing to
                // write.
                (
                    write_transforms::<DVec2>.run_if(any_with_component::<Bead>),
                    (
                        write_transforms::<DVec3>.run_if(any_with_component::<SpaceBead>),
                        orient_rails.run_if(any_with_component::<RailOrientation>),
                    )
                        .chain(),
                )
                    .in_set(WireBeadSystems::Writeback),
            )
            .add_observer(place_spawned::<Bead, DVec2>)
            .add_observer(place_spawned::<SpaceBead, DVec3>)
            .register_type::<SceneEnergy>()
            .add_systems(
                FixedUpdate,
                measure_scene_energy
                    .run_if(resource_exists::<SceneEnergy>)
                    .in_set(WireBeadSystems::Writeback),
            );
    }
}

/// The change tick of the last run of the step of the beads in `V`'s
/// dimension: it wrote the `Transform` of every bead it changed then.
#[derive(Resource)]
pub(crate) struct LastStep<V>(Tick, PhantomData<fn() -> V>);

impl<V> Default for LastStep<V> {
    fn default() -> Self {
        Self(Tick::default(), PhantomData)
    }
}

impl<V> LastStep<V> {
    /// The step ran at `tick`.
    pub(crate) fn set(&mut self, tick: Tick) {
        self.0 = tick;
    }
}

/// Writes each bead's position into its `Transform` (in the plane x and
/// y, z kept; see [`Dimension::place`]) where the bead changed other than
/// by the last step (a restart, a game's own edit); the step writes the
/// ones it steps. A non-finite position is never written.
fn write_transforms<V: Dimension>(
    parallel: Res<ParallelStep>,
    stepped: Res<LastStep<V>>,
    mut beads: Query<
        (Ref<BeadPosition<V>>, &mut Transform),
        (Changed<BeadPosition<V>>, Without<RidingBody>),
    >,
) {
    let write = |(position, mut transform): (Ref<BeadPosition<V>>, Mut<Transform>)| {
        // The step wrote the ones it changed last (without reading them
        // again here).
        if position.last_changed() != stepped.0 {
            V::place(&mut transform, position.0);
        }
    };
    if beads.iter().size_hint().1.unwrap_or(usize::MAX) >= parallel.threshold {
        beads.par_iter_mut().for_each(write);
    } else {
        beads.iter_mut().for_each(write);
    }
}

/// Places a bead's `Transform` at its position as the bead (marked `B`)
/// is spawned; a bead without one (a lean bead) is left as it is.
fn place_spawned<B: Component, V: Dimension>(
    added: On<Add, B>,
    mut beads: Query<(&BeadPosition<V>, &mut Transform)>,
) {
    if let Ok((position, mut transform)) = beads.get_mut(added.entity) {
        V::place(&mut transform, position.0);
    }
}

/// Turns each bead with a [`RailOrientation`] on a curve in space with its
/// track, where it is after the step (see [`RailOrientation`]); a
/// rotation that is not finite is never written. A bead riding a body is
/// avian's, and keeps the turn it had.
fn orient_rails(
    clock: Res<SimClock>,
    mut beads: Query<
        (
            &BeadPosition<DVec3>,
            &BeadParams<DVec3>,
            &OnWire,
            &mut RailOrientation,
            &mut Transform,
        ),
        Without<RidingBody>,
    >,
    wires: Query<(&SpaceWire, &WirePose<DVec3>)>,
) {
    for (position, params, on, mut rail, mut transform) in &mut beads {
        let Ok((wire, pose)) = wires.get(on.0) else {
            continue;
        };
        let (SpaceShape::Curve(curve), Ok(path)) = (wire.shape(), pose.get()) else {
            continue;
        };
        let pose = path.at(clock.time).0;
        let start = || (path.at(0.0).0, params.initial_position);
        if let Some(rotation) = rail.orient(curve.as_ref(), &pose, position.0, start) {
            let rotation = rotation.as_quat();
            if rotation.is_finite() {
                transform.rotation = rotation;
            }
        }
    }
}
