//! Stepping the [`Islands`]: each island's states and forces gathered,
//! solved (the islands split over the compute task pool), and the states,
//! diagnostics and `Transform`s written back.

use bevy::prelude::*;

use super::{CachedIsland, InIsland, Islands, LinkRows};
use crate::dynamics::{
    BeadDiagnostics, BeadForce, BeadMotion, BeadPosition, BeadVelocity, ConstraintDiagnostics,
    Diverged, DivergenceReason, Pin, SimParams, Wire, WireContact, WirePose,
};
use crate::plugin::clock::SimClock;
use crate::plugin::parallel::{ParallelStep, StepSplit};
use crate::plugin::report::{ContactReports, Divergences};
use crate::plugin::writeback::place;
use crate::solver::{BeadState, Contact, StepSettings};

/// The beads [`step_islands`] steps: those in an island that have not
/// stopped.
type Stepped = (With<InIsland>, Without<Diverged>);

/// Steps every island whose beads have not diverged: gathers their states
/// and forces, calls [`Island::step`] (the islands split over the compute
/// task pool from [`ParallelStep::threshold`] beads in islands up), writes
/// back the states, the diagnostics and the `Transform`s. An island whose
/// step fails stops as a whole, each of its beads marked [`Diverged`].
pub(super) fn step_islands(
    params: Res<SimParams>,
    clock: Res<SimClock>,
    parallel: Res<ParallelStep>,
    mut islands: ResMut<Islands>,
    mut beads: ParamSet<(
        Query<(&BeadPosition, &BeadVelocity, &BeadForce), Stepped>,
        Query<
            (
                BeadMotion,
                Option<&mut BeadDiagnostics>,
                Option<&mut Transform>,
                Option<&mut WireContact>,
            ),
            Stepped,
        >,
    )>,
    mut changes: ContactReports,
    wires: Query<(Ref<Wire>, &WirePose)>,
    pins: Query<&Pin>,
    transforms: Query<&Transform, Without<InIsland>>,
    mut diagnostics: Query<&mut ConstraintDiagnostics>,
    mut divergences: Divergences,
    mut split: ResMut<StepSplit>,
) {
    let settings = params.step_settings();
    let gravity = params.gravity;
    let mut stepped_beads = 0;
    // The gather looks up the three columns it reads, not every column
    // the write-back needs.
    let motion = beads.p0();
    'gather: for cached in &mut islands.cached {
        cached.outcome = None;
        cached.states.clear();
        cached.forces.clear();
        for &entity in &cached.report.beads {
            let Ok((position, velocity, force)) = motion.get(entity) else {
                continue 'gather; // a bead of it stopped: so does the island
            };
            let state = BeadState {
                position: position.0,
                velocity: velocity.0,
            };
            let mass = cached.masses[cached.states.len()];
            cached.states.push(state);
            cached
                .forces
                .push(force.linear(mass, gravity, state.position));
        }
        for &(_, row, wire) in &cached.wire_rows {
            let Ok((wire, pose)) = wires.get(wire) else {
                continue;
            };
            if let Ok(path) = pose.get() {
                let reshaped = wire.is_changed().then(|| wire.shape().clone());
                cached.island.move_wire(row, reshaped, path);
            }
        }
        for &(row, pin) in &cached.anchored {
            if let Some(at) = pins.get(pin).ok().and_then(|p| p.locate(&transforms)) {
                cached.island.place_axis(row, at.x);
                cached.island.place_axis(row + 1, at.y);
            }
        }
        cached.outcome = Some(Ok(()));
        stepped_beads += cached.states.len();
    }
    let time = clock.time - settings.dt;
    match parallel.pool(stepped_beads) {
        Some((pool, threads)) => {
            // A few chunks per thread, so that one slow island (a rope
            // in substeps) does not leave the other threads idle.
            let size = islands.cached.len().div_ceil(4 * threads).max(1);
            split.island_chunks = islands.cached.len().div_ceil(size);
            split.island_threads = threads;
            pool.scope(|scope| {
                for chunk in islands.cached.chunks_mut(size) {
                    let settings = &settings;
                    scope.spawn(async move {
                        for cached in chunk {
                            step_island(cached, time, settings);
                        }
                    });
                }
            });
        }
        None => {
            split.island_threads = 0;
            split.island_chunks = 1;
            for cached in &mut islands.cached {
                step_island(cached, time, &settings);
            }
        }
    }
    for cached in &mut islands.cached {
        match cached.outcome {
            None => continue,
            Some(Err(e)) => {
                for &bead in &cached.report.beads {
                    divergences.report(bead, DivergenceReason::Solve(e), clock.time);
                }
                continue;
            }
            Some(Ok(())) => {}
        }
        let rows = cached.work.rows();
        let pushed = cached.work.constraint_forces();
        for &(_, local, event) in cached.work.events() {
            let bead = cached.report.beads[local];
            changes.report(bead, event);
        }
        // One lookup per bead writes all it has.
        let mut written = beads.p1();
        for (i, &entity) in cached.report.beads.iter().enumerate() {
            let Ok((mut bead, bead_diagnostics, transform, contact)) = written.get_mut(entity)
            else {
                continue;
            };
            let state = cached.states[i];
            bead.advance_to(state);
            if let Some(mut transform) = transform {
                place(&mut transform, state.position);
            }
            let wire_row = cached.wire_rows.iter().find(|w| w.0 == i).map(|w| w.1);
            if let (Some(mut contact), Some(row)) = (contact, wire_row) {
                let held = if cached.work.holds(row) {
                    Contact::OnWire
                } else {
                    Contact::InFlight
                };
                if contact.contact != held {
                    contact.contact = held;
                }
            }
            if let Some(mut d) = bead_diagnostics {
                let row = wire_row.map(|r| rows[r]).unwrap_or_default();
                *d = BeadDiagnostics::of(state, cached.masses[i], gravity, row, pushed[i]);
            }
        }
        for link in &cached.links {
            let (entity, report) = match *link {
                LinkRows::One(entity, row) => (
                    entity,
                    ConstraintDiagnostics {
                        c: rows[row].c,
                        c_dot: rows[row].c_dot,
                        lambda: rows[row].lambda,
                    },
                ),
                LinkRows::Pin(entity, row) => {
                    let (x, y) = (rows[row], rows[row + 1]);
                    let c = x.c.hypot(y.c);
                    let c_dot = if c > 0.0 {
                        (x.c * x.c_dot + y.c * y.c_dot) / c
                    } else {
                        0.0
                    };
                    (
                        entity,
                        ConstraintDiagnostics {
                            c,
                            c_dot,
                            lambda: x.lambda.hypot(y.lambda),
                        },
                    )
                }
            };
            if let Ok(mut d) = diagnostics.get_mut(entity) {
                *d = report;
            }
        }
        cached.report.energy = cached.island.energy(&cached.states, gravity);
        cached.report.redundant = cached.work.redundant();
        cached.report.substeps = cached.work.substeps();
    }
}

/// Steps one gathered island (see [`step_islands`]), its result into
/// its `outcome`.
fn step_island(cached: &mut CachedIsland, time: f64, settings: &StepSettings) {
    if cached.outcome.is_none() {
        return;
    }
    cached.outcome = Some(cached.island.step_at(
        time,
        &mut cached.states,
        &cached.forces,
        settings,
        &mut cached.work,
    ));
}
