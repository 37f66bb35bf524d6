//! Stepping the [`Islands`]: each island's states and forces gathered,
//! solved (the islands split over the compute task pool), and the states,
//! diagnostics and `Transform`s written back.

use bevy::prelude::*;

use super::lone::LoneTouch;
use super::world::WorldBodies;
use super::{CachedIsland, InIsland, Islands, LinkRows, PressedPair, touch};
use crate::dynamics::{
    BeadDiagnostics, BeadForce, BeadMotion, BeadPosition, BeadRadius, BeadStruckBody, BeadVelocity,
    BeadsStruck, ConstraintDiagnostics, Contacts, Dimension, Diverged, DivergenceReason, Pin,
    Restitution, RidingBody, SimParams, WireContact, WirePose, WireRows,
};
use crate::plugin::clock::SimClock;
use crate::plugin::parallel::{ParallelStep, StepSplit};
use crate::plugin::report::{ContactReports, Divergences};
use crate::plugin::step::LoneStep;
use crate::solver::{BeadState, Contact, RowReport, StepSettings};

/// The beads [`step_islands`] steps: those in an island (or riding a
/// wire alone with a radius) that have not stopped and ride no body.
type Stepped = (With<InIsland>, Without<Diverged>, Without<RidingBody>);

/// What a step gathers of each bead: its state, the force on it, its
/// radius and restitution.
type Gathered<V> = (
    &'static BeadPosition<V>,
    &'static BeadVelocity<V>,
    &'static BeadForce<V>,
    Option<&'static BeadRadius>,
    Option<&'static Restitution>,
);

/// Steps every island whose beads have not diverged: gathers their states
/// and forces, calls [`Island::step`] (the islands split over the compute
/// task pool from [`ParallelStep::threshold`] beads in islands up), writes
/// back the states, the diagnostics and the `Transform`s. An island whose
/// step fails stops as a whole, each of its beads marked [`Diverged`].
/// Between the step and the write-back, the steps of islands whose beads
/// met are cut where they met and the strikes made (`touch`).
#[allow(clippy::too_many_arguments)]
pub(super) fn step_islands<V: LoneStep>(
    params: Res<SimParams>,
    contacts: Res<Contacts>,
    clock: Res<SimClock>,
    parallel: Res<ParallelStep>,
    mut islands: ResMut<Islands<V>>,
    mut beads: ParamSet<(
        Query<Gathered<V>, Stepped>,
        Query<
            (
                BeadMotion<V>,
                Option<&mut BeadDiagnostics<V>>,
                Option<&mut Transform>,
                Option<&mut WireContact>,
            ),
            Stepped,
        >,
    )>,
    mut changes: ContactReports<V>,
    wires: Query<(Ref<V::Wire>, &WirePose<V>)>,
    pins: Query<&Pin<V>>,
    transforms: Query<&Transform, Without<InIsland>>,
    mut diagnostics: Query<&mut ConstraintDiagnostics>,
    mut divergences: Divergences,
    mut split: ResMut<StepSplit>,
    (mut struck, mut world, mut sent): (
        MessageWriter<BeadsStruck>,
        Option<ResMut<WorldBodies<V>>>,
        MessageWriter<BeadStruckBody>,
    ),
) {
    let settings = params.step_settings();
    let gravity = V::gravity(&params);
    let mut stepped_beads = 0;
    // The gather looks up the three columns it reads, not every column
    // the write-back needs.
    let motion = beads.p0();
    'gather: for cached in &mut islands.cached {
        cached.outcome = None;
        cached.states.clear();
        cached.forces.clear();
        cached.touching.clear();
        for &entity in &cached.report.beads {
            let Ok((position, velocity, force, radius, restitution)) = motion.get(entity) else {
                continue 'gather; // a bead of it stopped: so does the island
            };
            let state = BeadState {
                position: position.0,
                velocity: velocity.0,
            };
            if let Some(radius) = radius.filter(|r| r.get() > 0.0) {
                let e = restitution.map_or(contacts.restitution(), Restitution::get);
                cached
                    .touching
                    .push((cached.states.len(), radius.get(), e, contacts.friction()));
            }
            let mass = cached.masses[cached.states.len()];
            cached.states.push(state);
            cached
                .forces
                .push(force.linear(mass, gravity, state.position));
        }
        for wire_row in &cached.wire_rows {
            let Ok((wire, pose)) = wires.get(wire_row.wire) else {
                continue;
            };
            if let Ok(path) = pose.get() {
                let reshaped = wire
                    .is_changed()
                    .then(|| wire.rows().swap_remove(wire_row.part));
                cached.island.move_wire(wire_row.row, reshaped, path);
            }
        }
        for &(row, pin) in &cached.anchored {
            if let Some(at) = pins.get(pin).ok().and_then(|p| p.locate(&transforms)) {
                for (k, axis) in V::AXES.iter().enumerate() {
                    cached.island.place_axis(row + k, axis.dot(at));
                }
            }
        }
        // Each contact row's restitution, the least of its two beads'.
        for contact in &cached.contacts {
            let e = |bead: usize| {
                let k = cached.touching.partition_point(|t| t.0 < bead);
                cached
                    .touching
                    .get(k)
                    .filter(|t| t.0 == bead)
                    .map_or(1.0, |t| t.2)
            };
            let restitution = e(contact.a).min(e(contact.b));
            cached
                .island
                .set_contact_restitution(contact.row, restitution);
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
    // The beads that ride their wires alone, each stepped by itself.
    let Islands { cached, lone, .. } = &mut *islands;
    let motion = beads.p0();
    let shapes: Vec<Option<V::Lone>> = lone
        .iter_mut()
        .map(|lone| {
            let shape = gather_lone(lone, &motion, &wires, (&contacts, gravity))?;
            lone.step(&shape, time, &settings);
            Some(shape)
        })
        .collect();
    let mut near_alone = Vec::new();
    touch::settle(
        cached,
        (lone, &shapes),
        time,
        &settings,
        (&mut struck, world.as_deref_mut().map(|w| (w, &mut sent))),
        &mut divergences,
        &mut near_alone,
    );
    if let Some(wanting) = touch::regroup(cached, (lone, &near_alone), settings.dt) {
        islands.mark_regrouped(wanting);
    }
    let mut written = beads.p1();
    for lone in &mut islands.lone {
        match &lone.outcome {
            None => continue,
            Some(Err(reason)) => {
                divergences.report(lone.entity, reason.clone(), clock.time);
                continue;
            }
            Some(Ok(())) => {}
        }
        let Ok((mut bead, bead_diagnostics, transform, _)) = written.get_mut(lone.entity) else {
            continue;
        };
        bead.advance_to(lone.state);
        if let Some(mut transform) = transform {
            V::place(&mut transform, lone.state.position);
        }
        let diagnosed = lone.diagnostics(gravity);
        lone.energy = diagnosed.energy();
        if let Some(mut d) = bead_diagnostics {
            *d = diagnosed;
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
                V::place(&mut transform, state.position);
            }
            let wire_row = cached.own_rows.get(i).copied().flatten();
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
                LinkRows::Pin(entity, row) => (entity, pin_report(&rows[row..][..V::AXES.len()])),
            };
            if let Ok(mut d) = diagnostics.get_mut(entity) {
                *d = report;
            }
        }
        cached.report.pressed.clear();
        for contact in &cached.contacts {
            if cached.work.holds(contact.row) {
                cached.report.pressed.push(PressedPair {
                    a: cached.report.beads[contact.a],
                    b: cached.report.beads[contact.b],
                    force: rows[contact.row].lambda,
                });
            }
        }
        cached.report.drift = (0..rows.len())
            .filter(|&row| cached.work.holds(row))
            .fold(0.0, |drift, row| f64::max(drift, rows[row].c.abs()));
        cached.report.energy = cached.island.energy_of(&cached.states, gravity);
        cached.report.redundant = cached.work.redundant();
        cached.report.substeps = cached.work.substeps();
        cached.report.steps += 1;
    }
}

/// Gathers bead `lone`'s state, force, radius and restitution for its
/// step, and its wire's path, under `contacts` and `gravity`; the wire's
/// shape, if the bead and its wire are there (else its outcome says why
/// it did not step, or it stopped).
fn gather_lone<V: LoneStep>(
    lone: &mut LoneTouch<V>,
    motion: &Query<Gathered<V>, Stepped>,
    wires: &Query<(Ref<V::Wire>, &WirePose<V>)>,
    (contacts, gravity): (&Contacts, V),
) -> Option<V::Lone> {
    lone.outcome = None;
    lone.output = None;
    let (position, velocity, force, radius, restitution) = motion.get(lone.entity).ok()?;
    lone.state = BeadState {
        position: position.0,
        velocity: velocity.0,
    };
    lone.radius = radius.map_or(0.0, BeadRadius::get);
    lone.restitution = restitution.map_or(contacts.restitution(), Restitution::get);
    lone.friction = contacts.friction();
    lone.force = force.linear(lone.mass, gravity, lone.state.position);
    let found = match wires.get(lone.wire) {
        Ok((wire, pose)) => pose.get().map_err(|e| e.to_string()).and_then(|path| {
            lone.path = path;
            V::lone_shape(&wire)
                .ok_or_else(|| format!("wire {} has no shape a bead rides alone", lone.wire))
        }),
        Err(_) => Err(format!("entity {} has no Wire", lone.wire)),
    };
    match found {
        Ok(shape) => Some(shape),
        Err(why) => {
            lone.outcome = Some(Err(DivergenceReason::InvalidWire(why)));
            None
        }
    }
}

/// A pin's rows reported together: the bead's distance from its point,
/// that distance's rate, and the length of the pin's force.
fn pin_report(rows: &[RowReport]) -> ConstraintDiagnostics {
    let c = rows.iter().fold(0.0, |sum, r| f64::hypot(sum, r.c));
    let c_dot = if c > 0.0 {
        rows.iter().map(|r| r.c * r.c_dot).sum::<f64>() / c
    } else {
        0.0
    };
    let lambda = rows.iter().fold(0.0, |sum, r| f64::hypot(sum, r.lambda));
    ConstraintDiagnostics { c, c_dot, lambda }
}

/// Steps one gathered island (see [`step_islands`]), its result into
/// its `outcome`.
fn step_island<V: Dimension>(cached: &mut CachedIsland<V>, time: f64, settings: &StepSettings) {
    if cached.outcome.is_none() {
        return;
    }
    if !cached.touching.is_empty() {
        cached.island.begin(time, &cached.states, &mut cached.work);
        cached.start.clone_from(&cached.states);
        cached.mark = cached.work.mark();
        cached.begin.clone_from(&cached.mark);
    }
    cached.outcome = Some(cached.island.step_at(
        time,
        &mut cached.states,
        &cached.forces,
        settings,
        &mut cached.work,
    ));
}
