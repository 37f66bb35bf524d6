//! Rebuilding the [`Islands`] after the topology changed: which beads the
//! links join, each island's rows, and the [`InIsland`] markers.

use std::collections::HashMap;

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use super::lone::LoneTouch;
use super::start::{
    BuildBead, Carried, by_least_bead, contact_starts, kept, own_rows, start_island,
};
use super::touch::Rider;
use super::{CachedIsland, ContactRow, InIsland, IslandReport, Islands, LinkRows, WireRow, touch};
use crate::dynamics::{
    Bead, CatchesBeads, Contacts, Dimension, DivergenceReason, Joint, OnWire, Pin, Restitution,
    RidingBody, Rod, SimParams, SpaceBead, Spring, WirePose, WireRows,
};
use crate::geometry::{Friction, Side, Surface};
use crate::plugin::clock::SimClock;
use crate::plugin::report::Divergences;
use crate::plugin::step::LoneStep;
use crate::solver::{self, Island, IslandRow, RowKind, SpringLink};

/// Every link in the world, as the rebuild reads them.
#[derive(SystemParam)]
pub(super) struct Links<'w, 's, V: Dimension> {
    rods: Query<'w, 's, (Entity, &'static Rod)>,
    pins: Query<'w, 's, (Entity, &'static Pin<V>)>,
    joints: Query<'w, 's, (Entity, &'static Joint<V>)>,
    springs: Query<'w, 's, (Entity, &'static Spring)>,
    /// Every bead, of either dimension: a link that names a bead of the
    /// other dimension is that dimension's, not a link to nothing.
    any_bead: Query<'w, 's, (), Or<(With<Bead>, With<SpaceBead>)>>,
}

/// A link while the islands are built: its rows and the beads it names.
struct Pending<V: Dimension> {
    entity: Entity,
    rows: Vec<IslandRow<V>>,
    pin: bool,
    anchored: bool,
    /// A contact between two beads near each other (see `touch`): the
    /// sum of their radii.
    contact: Option<f64>,
}

/// An island's wire rows while it is built: which wire each is of, each
/// wire's surface by its first row, and the rows of wires that catch.
#[derive(Default)]
struct WiredRows {
    wire_rows: Vec<WireRow>,
    /// Each wire's first row, bead, surface, and on a curve in space its
    /// second row.
    sides: Vec<(usize, usize, Surface, Option<usize>)>,
    /// The rows of wires that catch the bead rather than hold it.
    catching: Vec<usize>,
}

impl WiredRows {
    /// Appends to `rows` the rows that put bead `local` on `wire` (`own`:
    /// the wire it is on; otherwise one that catches it, and nothing for a
    /// two-sided one), placed where the wire is at `time`. An error in
    /// words for a wire that is not one or not placed.
    fn add<V: Dimension>(
        &mut self,
        rows: &mut Vec<IslandRow<V>>,
        wire: Entity,
        local: usize,
        own: bool,
        wires: &Query<(&V::Wire, &WirePose<V>)>,
        time: f64,
    ) -> Result<(), String> {
        let (shape, path) = match wires.get(wire).map(|(w, p)| (w, p.get())) {
            Ok((shape, Ok(path))) => (shape, path),
            Ok((_, Err(e))) => return Err(e.to_string()),
            Err(_) => return Err(format!("entity {wire} has no Wire")),
        };
        let surface = *shape.surface();
        if !own && surface.side == Side::Both {
            return Ok(());
        }
        let pose = path.at(time).0;
        let shapes = shape.rows();
        // A curve in space: its two rows rub as one (see
        // `Island::pair_rows`).
        let partner = (shapes.len() == 2).then_some(rows.len() + 1);
        self.sides.push((rows.len(), local, surface, partner));
        for (part, shape) in shapes.into_iter().enumerate() {
            if !own {
                self.catching.push(rows.len());
            }
            self.wire_rows.push(WireRow {
                bead: local,
                row: rows.len(),
                wire,
                part,
                own,
            });
            rows.push(IslandRow {
                kind: RowKind::Wire { shape, pose },
                beads: vec![local],
            });
        }
        Ok(())
    }
}

/// The rows that hold a bead at `at`, one along each axis.
fn pin_rows<V: Dimension>(at: V) -> Vec<IslandRow<V>> {
    V::AXES
        .iter()
        .map(|&axis| IslandRow {
            kind: RowKind::Axis {
                axis,
                offset: axis.dot(at),
            },
            beads: vec![0],
        })
        .collect()
}

/// Rebuilds [`Islands`] after the topology changed, and keeps the
/// [`InIsland`] marker on exactly the beads in one.
pub(super) fn prepare_islands<V: LoneStep>(
    mut islands: ResMut<Islands<V>>,
    links: Links<V>,
    mut beads: Query<BuildBead<V>>,
    wires: Query<(&V::Wire, &WirePose<V>)>,
    catching: Query<Entity, (With<CatchesBeads>, With<V::Wire>)>,
    restitutions: Query<&Restitution>,
    transforms: Query<&Transform>,
    riding: Query<(), With<RidingBody>>,
    mut commands: Commands,
    mut divergences: Divergences,
    clock: Res<SimClock>,
    params: Res<SimParams>,
    contacts: Res<Contacts>,
) {
    // Where only the pairs that may touch changed, an island none of them
    // concerns whose beads are as they were is kept whole.
    let regrouped = !islands.dirty;
    (islands.dirty, islands.regrouped) = (false, false);
    let wanting = std::mem::take(&mut islands.wanting);
    // The islands being rebuilt, and where their rows are: a rebuilt
    // island starts each row as it was where its beads still are.
    let mut old: Vec<Option<CachedIsland<V>>> = std::mem::take(&mut islands.cached)
        .into_iter()
        .map(Some)
        .collect();
    let by_least = if regrouped {
        by_least_bead(&old, &wanting)
    } else {
        HashMap::new()
    };
    islands.lone.clear();
    let was = Carried::from(&old, |bead| {
        beads.get(bead).ok().map(|(_, now, ..)| now.state())
    });
    let mut catchers: Vec<Entity> = catching.iter().collect();
    catchers.sort_unstable();
    let is_bead = |e: Entity| beads.contains(e);
    // A link naming a bead of the other dimension is the other
    // dimension's to build (or to refuse, if it mixes them).
    let ours = |named: &[Entity]| named.iter().any(|&b| is_bead(b));
    let missing = |what: &str, link: Entity, bead: Entity| {
        if links.any_bead.contains(bead) {
            warn!(
                "wirebead: {what} {link} joins beads in the plane and in space; the {what} is left out"
            );
        } else {
            warn!(
                "wirebead: {what} {link} names {bead}, which is not a bead; the {what} is left out"
            );
        }
    };
    let elsewhere =
        |named: &[Entity]| !ours(named) && named.iter().all(|&b| links.any_bead.contains(b));
    // Every link with the beads it names (as entities, for now).
    let mut named: Vec<(Pending<V>, Vec<Entity>)> = Vec::new();
    let mut springs: Vec<(Entity, Spring)> = Vec::new();
    for (entity, rod) in &links.rods {
        let beads = rod.beads();
        if elsewhere(&beads) {
            continue;
        }
        match beads.iter().find(|b| !is_bead(**b)) {
            Some(&b) => missing("rod", entity, b),
            None => named.push((
                Pending {
                    entity,
                    rows: vec![IslandRow {
                        kind: RowKind::Rod {
                            length: rod.length(),
                        },
                        beads: vec![0, 1],
                    }],
                    pin: false,
                    anchored: false,
                    contact: None,
                },
                beads.to_vec(),
            )),
        }
    }
    for (entity, pin) in &links.pins {
        if elsewhere(&[pin.bead()]) {
            continue;
        }
        if !is_bead(pin.bead()) {
            missing("pin", entity, pin.bead());
            continue;
        }
        let Some(at) = pin.locate(&transforms) else {
            warn!(
                "wirebead: pin {entity} is fixed to {}, which has no finite Transform; the pin is left out",
                pin.anchor().unwrap_or(Entity::PLACEHOLDER)
            );
            continue;
        };
        named.push((
            Pending {
                entity,
                rows: pin_rows(at),
                pin: true,
                anchored: pin.anchor().is_some(),
                contact: None,
            },
            vec![pin.bead()],
        ));
    }
    for (entity, joint) in &links.joints {
        if elsewhere(joint.beads()) {
            continue;
        }
        match joint.beads().iter().find(|b| !is_bead(**b)) {
            Some(&b) => missing("joint", entity, b),
            None => named.push((
                Pending {
                    entity,
                    rows: vec![IslandRow {
                        kind: RowKind::Custom(joint.constraint().clone()),
                        beads: (0..joint.beads().len()).collect(),
                    }],
                    pin: false,
                    anchored: false,
                    contact: None,
                },
                joint.beads().to_vec(),
            )),
        }
    }
    for (entity, spring) in &links.springs {
        if elsewhere(&spring.beads()) {
            continue;
        }
        match spring.beads().iter().find(|b| !is_bead(**b)) {
            Some(&b) => missing("spring", entity, b),
            None => springs.push((entity, *spring)),
        }
    }
    // The beads a link names: none of them rides its wire alone.
    let mut linked: Vec<Entity> = named
        .iter()
        .flat_map(|(_, b)| b.iter().copied())
        .chain(springs.iter().flat_map(|(_, s)| s.beads()))
        .collect();
    linked.sort_unstable();
    // A bead with a radius on a plain wire of one row (not traced),
    // joined to nothing and caught by no other wire, rides it alone.
    let rides_alone = |entity: Entity, on_wire: Option<&OnWire>| {
        let Some(wire) = on_wire.and_then(|on| wires.get(on.0).ok()) else {
            return false;
        };
        let plain = wire.0.lone()
            && wire.0.surface().is_plain()
            && V::lone_shape(wire.0).is_some_and(|shape| !V::traced(&shape));
        plain
            && linked.binary_search(&entity).is_err()
            && catchers
                .iter()
                .all(|&w| on_wire.is_some_and(|on| on.0 == w))
    };
    // Beads with radii that may meet soon, joined by contact rows, and
    // whether each rides its wire alone.
    let with_radius: Vec<(Entity, Rider<V>)> = beads
        .iter()
        .filter_map(|(entity, bead, on_wire, _, radius, _)| {
            let radius = radius?.get();
            let restitution = restitutions
                .get(entity)
                .map_or(contacts.restitution(), Restitution::get);
            (radius > 0.0).then(|| {
                let rider = Rider {
                    state: bead.state(),
                    radius,
                    restitution,
                    alone: rides_alone(entity, on_wire),
                };
                (entity, rider)
            })
        })
        .collect();
    let riders: Vec<Rider<V>> = with_radius.iter().map(|b| b.1).collect();
    // A pair with friction in the plane gets a second row, to hold it
    // while static friction can (set aside while it slips); in space a
    // pair has no one direction to be held in.
    let sticks = contacts.friction() > 0.0 && V::stick_axis(V::AXES[0]).is_some();
    for (i, j) in touch::near(&riders, params.timestep) {
        let ((a, rider_a), (b, rider_b)) = (with_radius[i], with_radius[j]);
        let (ra, rb) = (rider_a.radius, rider_b.radius);
        let row = IslandRow {
            kind: RowKind::Rod { length: ra + rb },
            beads: vec![0, 1],
        };
        let rows = if sticks {
            vec![row.clone(), row]
        } else {
            vec![row]
        };
        named.push((
            Pending {
                entity: a,
                rows,
                pin: false,
                anchored: false,
                contact: Some(ra + rb),
            },
            vec![a, b],
        ));
    }
    // The beads in islands: every bead a link names, every bead on no
    // wire, every bead on a wire without a step of its own (a curve in
    // space) unless the wire rides a body (avian steps the bead), and
    // every bead with a radius that does not ride its wire alone (its step
    // may be cut where it meets another).
    let mut index: HashMap<Entity, usize> = HashMap::new();
    let mut members: Vec<Entity> = Vec::new();
    let mut join = |bead: Entity, members: &mut Vec<Entity>| {
        *index.entry(bead).or_insert_with(|| {
            members.push(bead);
            members.len() - 1
        })
    };
    for (_, beads_named) in &named {
        for &b in beads_named {
            join(b, &mut members);
        }
    }
    for (_, spring) in &springs {
        for b in spring.beads() {
            join(b, &mut members);
        }
    }
    let mut alone: Vec<Entity> = with_radius
        .iter()
        .filter(|b| b.1.alone)
        .map(|b| b.0)
        .collect();
    alone.sort_unstable();
    for (entity, _, on_wire, _, radius, _) in &beads {
        let lone = on_wire.is_some_and(|on| wires.get(on.0).map_or(true, |(w, _)| w.lone()))
            || riding.contains(entity);
        let touches = radius.is_some() && alone.binary_search(&entity).is_err();
        if !lone || touches {
            join(entity, &mut members);
        }
    }
    let named_count = named.len();
    let link_beads: Vec<Vec<usize>> = named
        .iter()
        .map(|(_, b)| b.iter().map(|e| index[e]).collect())
        .chain(
            springs
                .iter()
                .map(|(_, s)| s.beads().iter().map(|e| index[e]).collect()),
        )
        .collect();
    let groups = solver::islands(members.len(), link_beads.iter().map(Vec::as_slice));
    let mut group_of = vec![(0, 0); members.len()];
    for (g, group) in groups.iter().enumerate() {
        for (local, &m) in group.iter().enumerate() {
            group_of[m] = (g, local);
        }
    }
    // Sort the links into their groups, with bead indices local to them.
    let mut group_links: Vec<Vec<(Pending<V>, Vec<usize>)>> =
        (0..groups.len()).map(|_| Vec::new()).collect();
    let mut group_springs: Vec<Vec<SpringLink>> = vec![Vec::new(); groups.len()];
    for ((pending, _), local) in named.into_iter().zip(&link_beads) {
        let g = group_of[local[0]].0;
        let local = local.iter().map(|&m| group_of[m].1).collect();
        group_links[g].push((pending, local));
    }
    for ((_, spring), local) in springs.iter().zip(&link_beads[named_count..]) {
        let (rest_length, stiffness, damping) = spring.law();
        let g = group_of[local[0]].0;
        group_springs[g].push(SpringLink {
            a: group_of[local[0]].1,
            b: group_of[local[1]].1,
            rest_length,
            stiffness,
            damping,
        });
    }
    for ((group, links), springs) in groups.iter().zip(group_links).zip(group_springs) {
        let entities: Vec<Entity> = group.iter().map(|&m| members[m]).collect();
        let mass = |e: Entity| beads.get(e).ok().map(|(_, bead, ..)| bead.mass());
        if let Some(island) = kept(&mut old, &by_least, &entities, mass) {
            islands.cached.push(island);
            continue;
        }
        let mut masses = Vec::with_capacity(group.len());
        let mut rows = Vec::new();
        let mut wired = WiredRows::default();
        let mut invalid = None;
        for (local, &entity) in entities.iter().enumerate() {
            let Ok((_, bead, on_wire, _, radius, _)) = beads.get(entity) else {
                invalid = Some(format!("entity {entity} is no longer a bead"));
                break;
            };
            masses.push(bead.mass());
            let own = on_wire.map(|on| on.0);
            if let Some(wire) = own
                && let Err(why) = wired.add(&mut rows, wire, local, true, &wires, clock.time)
            {
                invalid = Some(why);
            }
            // A bead with a radius may land on every wire that catches.
            if radius.is_some_and(|r| r.get() > 0.0) {
                for &wire in catchers.iter().filter(|&&w| Some(w) != own) {
                    if let Err(why) = wired.add(&mut rows, wire, local, false, &wires, clock.time) {
                        invalid = Some(why);
                    }
                }
            }
        }
        let WiredRows {
            wire_rows,
            sides,
            catching,
        } = wired;
        let mut link_rows = Vec::new();
        let mut anchored = Vec::new();
        let mut pair_rows = Vec::new();
        for (pending, local) in links {
            let start = rows.len();
            if pending.anchored {
                anchored.push((start, pending.entity));
            }
            if let Some(reach) = pending.contact {
                pair_rows.push(ContactRow {
                    row: start,
                    stick: (pending.rows.len() > 1).then_some(start + 1),
                    a: local[0].min(local[1]),
                    b: local[0].max(local[1]),
                    reach,
                });
            } else if pending.pin {
                link_rows.push(LinkRows::Pin(pending.entity, start));
            } else {
                link_rows.push(LinkRows::One(pending.entity, start));
            }
            for mut row in pending.rows {
                row.beads = row.beads.iter().map(|&i| local[i]).collect();
                rows.push(row);
            }
        }
        // A rough wire's bead gets a row to hold it still while static
        // friction can (set aside while it slides), where it has one
        // direction to be held in: along a curve (in the plane or in
        // space), not on a surface.
        let mut sticks = Vec::new();
        for &(row, local, surface, partner) in &sides {
            let one_tangent = partner.is_some() || V::stick_axis(V::AXES[0]).is_some();
            if surface.friction.is_some() && one_tangent {
                sticks.push((row, rows.len()));
                rows.push(IslandRow {
                    kind: RowKind::Axis {
                        axis: V::AXES[0],
                        offset: 0.0,
                    },
                    beads: vec![local],
                });
            }
        }
        let row_count = rows.len();
        let built = match invalid {
            Some(why) => Err(DivergenceReason::InvalidWire(why)),
            None => Island::new(&masses, rows, springs)
                .map_err(|e| DivergenceReason::InvalidConstraint(e.to_string())),
        };
        pair_rows.sort_unstable_by_key(|c| (c.a, c.b));
        let pair_friction = Friction {
            static_coefficient: contacts.friction(),
            kinetic_coefficient: contacts.friction(),
        };
        let built = built.map(|mut island| {
            for contact in &pair_rows {
                island.set_contact(contact.row);
                if pair_friction.is_some() {
                    island.set_contact_friction(contact.row, pair_friction, contact.stick);
                }
            }
            for &row in &catching {
                island.set_catching(row);
            }
            for (row, local, surface, partner) in sides {
                island.set_side(row, surface.side, surface.restitution);
                if surface.resists() {
                    let stick = sticks.iter().find(|s| s.0 == row).map(|s| s.1);
                    if let Err(e) = island.set_rough(row, surface.friction, surface.damping, stick)
                    {
                        warn!(
                            "wirebead: the rough wire under bead {}: {e}; it is left smooth \
                             for that bead",
                            entities[local]
                        );
                    }
                    if let Some(partner) = partner {
                        island.pair_rows(row, partner);
                    }
                }
            }
            island
        });
        match built {
            Ok(mut island) => {
                let riding = entities
                    .iter()
                    .map(|e| alone.binary_search(e).is_ok())
                    .collect();
                let (work, states) = start_island(
                    &mut island,
                    &entities,
                    (&wire_rows, &pair_rows),
                    (&old, &was),
                    &wires,
                    &mut beads,
                    &clock,
                );
                islands.cached.push(CachedIsland {
                    report: IslandReport {
                        beads: entities,
                        rows: row_count,
                        ..default()
                    },
                    island,
                    work,
                    states,
                    forces: Vec::with_capacity(group.len()),
                    masses: masses.clone(),
                    links: link_rows,
                    own_rows: own_rows(&wire_rows, group.len()),
                    wire_rows,
                    anchored,
                    contact_starts: contact_starts(&pair_rows, group.len()),
                    contacts: pair_rows,
                    outcome: None,
                    touching: Vec::new(),
                    alone: riding,
                    start: Vec::new(),
                    mark: default(),
                    begin: default(),
                });
            }
            Err(reason) => {
                for &bead in &entities {
                    divergences.report(bead, reason.clone(), clock.time);
                }
            }
        }
    }
    // The beads with a radius that ride their wire alone and no contact
    // row joins: each a body of its own.
    for &entity in &alone {
        if index.contains_key(&entity) {
            continue;
        }
        let Ok((_, bead, Some(on_wire), ..)) = beads.get(entity) else {
            continue;
        };
        islands
            .lone
            .push(LoneTouch::new(entity, on_wire.0, bead.mass(), bead.state()));
    }
    let stepped =
        |entity: Entity| index.contains_key(&entity) || alone.binary_search(&entity).is_ok();
    for (entity, _, _, marked, ..) in &beads {
        match (stepped(entity), marked) {
            (true, false) => {
                commands.entity(entity).try_insert(InIsland);
            }
            (false, true) => {
                commands.entity(entity).try_remove::<InIsland>();
            }
            _ => {}
        }
    }
}
