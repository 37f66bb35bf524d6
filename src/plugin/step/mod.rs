//! [`BeadStepPlugin`]: steps each bead on a wire and joined to nothing, in
//! [`WireBeadSystems::Step`]: in the plane on any curve, in space on a
//! surface. The system only moves data between the ECS and
//! [`solver`](crate::solver); the beads are walked table by table as
//! slices, split over the compute task pool.
//!
//! | file | what it holds |
//! |---|---|
//! | `lone` | what each dimension's lone step needs: its shapes, circles or spheres, tracks |
//! | `table` | the wire table: each wire's shape and pose, from change detection |
//! | `run` | a run of beads stepped on one thread: batched and single-bead steps |

mod lone;
mod run;
mod table;

use bevy::ecs::system::SystemChangeTick;
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use super::clock::SimClock;
use super::islands::InIsland;
use super::parallel::{ParallelStep, StepSplit};
use super::report::{ContactReports, Divergences, FoundDivergences, FoundEvents};
use super::schedule::WireBeadSystems;
use super::writeback::LastStep;
use crate::dynamics::{
    Bead, BeadDiagnostics, BeadForce, BeadMass, BeadPosition, BeadVelocity, Diverged, OnWire,
    RidingBody, SimParams, SpaceBead, WireContact, WirePose,
};
pub(crate) use lone::{LoneStep, OnTrack};
use run::{StepContext, split_table};
use table::WireTable;

/// Steps the beads that ride a wire alone (see
/// [`WireBeadSystems::Step`]); beads joined to others are the
/// [`IslandPlugin`](super::IslandPlugin)'s.
#[derive(Default)]
pub struct BeadStepPlugin;

impl Plugin for BeadStepPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            FixedUpdate,
            // Each skipped, not run empty, while its dimension has no bead.
            (
                step_beads::<DVec2>.run_if(any_with_component::<Bead>),
                step_beads::<DVec3>.run_if(any_with_component::<SpaceBead>),
            )
                .in_set(WireBeadSystems::Step),
        );
    }
}

/// Steps every bead that has not diverged: solve, integrate, check, update
/// diagnostics (see [`WireBeadSystems::Step`](crate::WireBeadSystems::Step)).
/// Walks the beads table by table as slices, split over the compute task
/// pool from [`ParallelStep::threshold`] beads up.
fn step_beads<V: LoneStep>(
    params: Res<SimParams>,
    clock: Res<SimClock>,
    parallel: Res<ParallelStep>,
    mut wires: Local<WireTable<V>>,
    changed: Query<(Entity, &V::Wire, &WirePose<V>), Or<(Changed<V::Wire>, Changed<WirePose<V>>)>>,
    mut removed_wires: RemovedComponents<V::Wire>,
    mut removed_poses: RemovedComponents<WirePose<V>>,
    mut beads: Query<
        (
            Entity,
            &mut BeadPosition<V>,
            &mut BeadVelocity<V>,
            &BeadMass,
            &mut BeadForce<V>,
            &OnWire,
            Option<&mut BeadDiagnostics<V>>,
            Option<&mut Transform>,
            Option<&mut WireContact>,
        ),
        (Without<Diverged>, Without<InIsland>, Without<RidingBody>),
    >,
    mut found: Local<FoundDivergences>,
    mut events: Local<FoundEvents<V>>,
    mut changes: ContactReports<V>,
    mut stepped: ResMut<LastStep<V>>,
    mut split_report: ResMut<StepSplit>,
    ticks: SystemChangeTick,
    mut divergences: Divergences,
) {
    let removed = removed_wires.read().chain(removed_poses.read());
    wires.refresh(removed, changed);
    let ctx = StepContext {
        settings: params.step_settings(),
        gravity: V::gravity(&params),
        wires: &wires,
        found: &found,
        events: &events,
        time: clock.time,
    };
    let count = beads.iter().size_hint().1.unwrap_or(usize::MAX);
    let pool = parallel.pool(count);
    let threads = pool.map_or(1, |(_, threads)| threads);
    let Ok(tables) = beads.contiguous_iter_mut() else {
        error!("wirebead: the bead query is not table-dense; no bead was stepped");
        return;
    };
    let split = |table| split_table(table, threads);
    let mut runs = 0;
    match pool {
        Some((pool, _)) => {
            pool.scope(|scope| {
                for run in tables.flat_map(split) {
                    let ctx = &ctx;
                    runs += 1;
                    scope.spawn(async move { ctx.step_run(run) });
                }
            });
        }
        None => {
            for run in tables.flat_map(split) {
                runs += 1;
                ctx.step_run(run);
            }
        }
    };
    split_report.bead_threads = pool.map_or(0, |(_, threads)| threads);
    split_report.bead_runs = runs;
    found.report(&mut divergences);
    for (bead, event) in events.take() {
        if let Ok((.., Some(mut contact))) = beads.get_mut(bead) {
            contact.set_changed();
        }
        changes.report(bead, event);
    }
    stepped.set(ticks.this_run());
}
