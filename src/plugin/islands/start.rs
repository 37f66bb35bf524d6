//! How an island built again starts: each row as the islands it
//! replaces left it, where its beads have not moved since
//! ([`Carried`]), and the beads' velocities projected onto its
//! constraints ([`start_island`]); which islands a regrouping keeps whole
//! ([`kept`]); and the lookups a built island keeps, each bead's row on
//! its own wire and each bead's contacts.

use std::collections::HashMap;

use bevy::prelude::*;

use super::{CachedIsland, ContactRow, InIsland, WireRow};
use crate::dynamics::{BeadMotion, BeadRadius, Dimension, OnWire, WireContact, WirePose};
use crate::plugin::clock::SimClock;
use crate::solver::{BeadState, Contact, Island, IslandWork};

/// What the rebuild reads and writes of each bead: its motion, wire,
/// marker, whether it has a radius (and so steps in an island), and
/// whether it is held on its wire.
pub(super) type BuildBead<V> = (
    Entity,
    BeadMotion<V>,
    Option<&'static OnWire>,
    Has<InIsland>,
    Option<&'static BeadRadius>,
    Option<&'static mut WireContact>,
);

/// Where each row of the last islands is (its island and row), and where
/// its beads were when they were last stepped (or built, for an island
/// not stepped since): what a rebuilt island starts its rows from. Wire
/// rows by bead, wire and the wire's row; contacts by their two beads
/// (in order).
pub(super) struct Carried<V: Dimension> {
    wire_rows: HashMap<(Entity, Entity, usize), ((usize, usize), BeadState<V>)>,
    contacts: HashMap<(Entity, Entity), ((usize, usize), [BeadState<V>; 2])>,
}

impl<V: Dimension> Carried<V> {
    /// Where the `old` islands' rows are; `now` is where a bead is.
    pub(super) fn from(
        old: &[Option<CachedIsland<V>>],
        now: impl Fn(Entity) -> Option<BeadState<V>>,
    ) -> Self {
        let mut carried = Self {
            wire_rows: HashMap::new(),
            contacts: HashMap::new(),
        };
        for (k, cached) in old.iter().enumerate() {
            let Some(cached) = cached else { continue };
            let beads = &cached.report.beads;
            let at = |bead: usize| {
                cached
                    .states
                    .get(bead)
                    .copied()
                    .or_else(|| beads.get(bead).and_then(|&entity| now(entity)))
            };
            for row in &cached.wire_rows {
                if let (Some(&bead), Some(state)) = (beads.get(row.bead), at(row.bead)) {
                    let key = (bead, row.wire, row.part);
                    carried.wire_rows.insert(key, ((k, row.row), state));
                }
            }
            for contact in &cached.contacts {
                let (Some(&a), Some(&b)) = (beads.get(contact.a), beads.get(contact.b)) else {
                    continue;
                };
                let (Some(at_a), Some(at_b)) = (at(contact.a), at(contact.b)) else {
                    continue;
                };
                let ((a, at_a), (b, at_b)) = if a < b {
                    ((a, at_a), (b, at_b))
                } else {
                    ((b, at_b), (a, at_a))
                };
                carried
                    .contacts
                    .insert((a, b), ((k, contact.row), [at_a, at_b]));
            }
        }
        carried
    }
}

/// Starts a fresh island where its beads are: each wire row on its wire's
/// motion, and the beads' velocities projected onto the island's
/// constraints ([`Island::project_velocities`]), so that the state a run
/// starts from is the one simulated. A change is logged in one line.
/// Returns the work and the beads' states it starts from (none where one
/// is not finite): what a rebuild before its first step compares the
/// beads with, so that a bead moved since starts its rows afresh.
pub(super) fn start_island<V: Dimension>(
    island: &mut Island<V>,
    entities: &[Entity],
    (wire_rows, contacts): (&[WireRow], &[ContactRow]),
    (old, was): (&[Option<CachedIsland<V>>], &Carried<V>),
    wires: &Query<(&V::Wire, &WirePose<V>)>,
    beads: &mut Query<BuildBead<V>>,
    clock: &SimClock,
) -> (IslandWork<V>, Vec<BeadState<V>>) {
    let mut work = IslandWork::default();
    let now = |bead: Entity| beads.get(bead).ok().map(|(_, now, ..)| now.state());
    for wire_row in wire_rows {
        if let Ok((_, pose)) = wires.get(wire_row.wire)
            && let Ok(path) = pose.get()
        {
            island.move_wire(wire_row.row, None, path);
        }
        let bead = entities[wire_row.bead];
        let key = (bead, wire_row.wire, wire_row.part);
        if let Some(&((k, from), then)) = was.wire_rows.get(&key)
            && now(bead) == Some(then)
            && let Some(Some(then)) = old.get(k)
        {
            let row = (wire_row.row, island.stick_row(wire_row.row));
            work.carry_held(row, &then.work, (from, then.island.stick_row(from)));
        }
    }
    // A contact whose beads are where the last island left them starts
    // as it was: pressed with its force, or set aside, and held by static
    // friction where it was, at the same line.
    for contact in contacts {
        let (a, b) = (entities[contact.a], entities[contact.b]);
        let (a, b) = (a.min(b), a.max(b));
        let Some(&((k, from), [at_a, at_b])) = was.contacts.get(&(a, b)) else {
            continue;
        };
        if now(a) == Some(at_a)
            && now(b) == Some(at_b)
            && let Some(Some(then)) = old.get(k)
        {
            let row = (contact.row, island.stick_row(contact.row));
            work.carry_held(row, &then.work, (from, then.island.stick_row(from)));
        }
    }
    let mut states: Vec<BeadState<V>> = Vec::with_capacity(entities.len());
    for &entity in entities {
        match beads.get(entity) {
            Ok((_, bead, ..)) if bead.state().is_finite() => states.push(bead.state()),
            // A bead whose state is not finite: the step reports it.
            _ => return (work, Vec::new()),
        }
    }
    // A bead an island starts off its own wire (one that starts away from
    // a wire that ends has left it) is in flight from the start; one the
    // last islands carried is as they left it.
    for wire_row in wire_rows.iter().filter(|w| w.own && !work.carries(w.row)) {
        if island.starts_aside(wire_row.row, clock.time, &states, &[])
            && let Ok((.., Some(mut contact))) = beads.get_mut(entities[wire_row.bead])
            && contact.contact != Contact::InFlight
        {
            contact.contact = Contact::InFlight;
        }
    }
    let Ok((before, after)) = island.project_velocities(clock.time, &mut states, &mut work) else {
        // No projection (a singular point): the step meets it and reports.
        return (work, states);
    };
    let mut changed = Vec::new();
    for (&entity, state) in entities.iter().zip(&states) {
        if let Ok((_, mut bead, ..)) = beads.get_mut(entity) {
            let change = state.velocity - bead.velocity.0;
            let speed = bead.velocity.0.dot(bead.velocity.0).sqrt();
            if change.dot(change).sqrt() > 1e-9 * speed.max(1.0) {
                changed.push(entity.to_string());
            }
            if bead.velocity.0 != state.velocity {
                bead.velocity.0 = state.velocity;
            }
        }
    }
    if !changed.is_empty() {
        info!(
            "wirebead: the velocities of beads {} broke their constraints and were projected onto them; their island's kinetic energy went from {before:.6} J to {after:.6} J",
            changed.join(", ")
        );
    }
    (work, states)
}

/// The old islands a rebuild that only regroups may keep whole, by the
/// least of their beads: those that stepped and that no pair of beads
/// that may touch wants built again (`wanting`, see `touch::regroup`).
pub(super) fn by_least_bead<V: Dimension>(
    old: &[Option<CachedIsland<V>>],
    wanting: &[bool],
) -> HashMap<Entity, usize> {
    old.iter()
        .enumerate()
        .filter_map(|(k, cached)| {
            let cached = cached.as_ref()?;
            let least = cached.report.beads.iter().min()?;
            let keeps = cached.outcome == Some(Ok(())) && wanting.get(k) == Some(&false);
            keeps.then_some((*least, k))
        })
        .collect()
}

/// Takes out of `old` the island a rebuild that only regroups keeps for
/// the beads `entities` (see [`by_least_bead`]): one of the same beads,
/// each of the mass it was built with. It steps on as though no rebuild
/// had been: its contact rows (every pair of its beads that may meet
/// within the step has one), their forces, stick lines and its halvings
/// as they were.
pub(super) fn kept<V: Dimension>(
    old: &mut [Option<CachedIsland<V>>],
    by_least: &HashMap<Entity, usize>,
    entities: &[Entity],
    mass: impl Fn(Entity) -> Option<f64>,
) -> Option<CachedIsland<V>> {
    let k = *by_least.get(entities.iter().min()?)?;
    let cached = old.get(k)?.as_ref()?;
    let was = &cached.report.beads;
    let sorted = |beads: &[Entity]| {
        let mut beads = beads.to_vec();
        beads.sort_unstable();
        beads
    };
    if was.len() != entities.len() || sorted(was) != sorted(entities) {
        return None;
    }
    if was
        .iter()
        .zip(&cached.masses)
        .any(|(&e, &m)| mass(e) != Some(m))
    {
        return None;
    }
    old.get_mut(k)?.take()
}

/// Each of `beads` beads' row on its own wire among `wire_rows`, if it is
/// on one.
pub(super) fn own_rows(wire_rows: &[WireRow], beads: usize) -> Vec<Option<usize>> {
    let mut own = vec![None; beads];
    for wire_row in wire_rows.iter().filter(|w| w.own) {
        if let Some(slot) = own.get_mut(wire_row.bead) {
            slot.get_or_insert(wire_row.row);
        }
    }
    own
}

/// Where each of `beads` beads' contacts with the beads after it start in
/// `contacts` (sorted by their beads), and where the last ends.
pub(super) fn contact_starts(contacts: &[ContactRow], beads: usize) -> Vec<usize> {
    (0..=beads)
        .map(|a| contacts.partition_point(|c| c.a < a))
        .collect()
}
