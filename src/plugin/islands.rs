//! Islands in the ECS: the beads joined by [`Rod`]s, [`Pin`]s, [`Joint`]s
//! and [`Spring`]s, and free beads (on no wire), grouped and cached in
//! [`Islands`] until the topology changes, and stepped each step by
//! [`solver::Island`]. A bead on a wire and joined to nothing keeps the
//! per-bead step (and its batched fast path).

use std::collections::HashMap;

use bevy::ecs::system::SystemParam;
use bevy::math::DVec2;
use bevy::prelude::*;

use super::restart::SimClock;
use super::step::{Divergences, describe_event};
use super::writeback::place;
use crate::dynamics::{
    Bead, BeadDiagnostics, ConstraintDiagnostics, ContactChanged, Diverged, DivergenceReason,
    Joint, OnWire, Pin, Rod, SimParams, Spring, Wire, WireContact, WirePose,
};
use crate::solver::{
    self, BeadState, Contact, Island, IslandRow, IslandWork, LinearForce, RowKind, SolveError,
    SpringLink, StepSettings,
};

use super::parallel::ParallelStep;

/// Marks a bead stepped in an island (joined to another bead or a point,
/// or on no wire); the per-bead step leaves it alone. Kept by the plugin.
#[derive(Component, Clone, Copy, Debug, Default)]
pub(crate) struct InIsland;

/// What the last step of one island reported.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IslandReport {
    /// The island's beads.
    pub beads: Vec<Entity>,
    /// Its constraint rows (a pin counts two).
    pub rows: usize,
    /// Kinetic and gravitational energy of its beads plus the energy in
    /// its springs, after the last step.
    pub energy: f64,
    /// How many rows the last solve dropped as redundant.
    pub redundant: usize,
    /// How many substeps the last step took (more than one where a Newton
    /// solve had no root at the full step).
    pub substeps: u32,
}

/// Which link a range of rows belongs to, for its diagnostics.
#[derive(Clone, Copy, Debug)]
enum LinkRows {
    /// One row: a rod or a joint.
    One(Entity, usize),
    /// A pin's two rows.
    Pin(Entity, usize),
}

/// One island as the step keeps it.
struct CachedIsland {
    report: IslandReport,
    island: Island,
    work: IslandWork,
    states: Vec<BeadState>,
    forces: Vec<LinearForce>,
    links: Vec<LinkRows>,
    /// The wire row of each bead on a wire: (bead, row, wire entity).
    wire_rows: Vec<(usize, usize, Entity)>,
    /// The first row of each pin fixed to another entity, and the pin.
    anchored: Vec<(usize, Entity)>,
    /// What this step did: not stepped (a bead of it has stopped), or the
    /// step's result.
    outcome: Option<Result<(), SolveError>>,
}

/// The islands of the current topology: beads joined by constraints and
/// springs, each solved as one system. Rebuilt when a link, a bead or a
/// wire is added, changed or removed, or the run restarts.
#[derive(Resource, Default)]
pub struct Islands {
    cached: Vec<CachedIsland>,
    dirty: bool,
}

impl Islands {
    /// What the last step of each island reported.
    pub fn iter(&self) -> impl Iterator<Item = &IslandReport> {
        self.cached.iter().map(|c| &c.report)
    }

    /// The report of the island holding `bead`, if it is in one.
    pub fn of(&self, bead: Entity) -> Option<&IslandReport> {
        self.iter().find(|r| r.beads.contains(&bead))
    }

    /// Asks for a rebuild before the next step.
    pub(crate) fn mark_dirty(&mut self) {
        self.dirty = true;
    }
}

/// Marks the islands for a rebuild: observed on the lifecycle events that
/// change which beads are joined or on which wire.
pub(crate) fn topology_changed<E: EntityEvent, B: Bundle>(
    _: On<E, B>,
    mut islands: ResMut<Islands>,
) {
    islands.mark_dirty();
}

/// Every link in the world, as the rebuild reads them.
#[derive(SystemParam)]
pub(crate) struct Links<'w, 's> {
    rods: Query<'w, 's, (Entity, &'static Rod)>,
    pins: Query<'w, 's, (Entity, &'static Pin)>,
    joints: Query<'w, 's, (Entity, &'static Joint)>,
    springs: Query<'w, 's, (Entity, &'static Spring)>,
}

/// A link while the islands are built: its rows and the beads it names.
struct Pending {
    entity: Entity,
    rows: Vec<IslandRow>,
    pin: bool,
    anchored: bool,
}

/// The two rows that hold a bead at `at`.
fn pin_rows(at: DVec2) -> Vec<IslandRow> {
    [DVec2::X, DVec2::Y]
        .map(|axis| IslandRow {
            kind: RowKind::Axis {
                axis,
                offset: axis.dot(at),
            },
            beads: vec![0],
        })
        .to_vec()
}

/// Whether the islands need a rebuild: the run condition of
/// [`prepare_islands`], so a step with nothing changed costs the executor
/// no task.
pub(crate) fn islands_changed(islands: Res<Islands>) -> bool {
    islands.dirty
}

/// Whether there is an island to step: the run condition of
/// [`step_islands`].
pub(crate) fn any_island(islands: Res<Islands>) -> bool {
    !islands.cached.is_empty()
}

/// Rebuilds [`Islands`] after the topology changed, and keeps the
/// [`InIsland`] marker on exactly the beads in one.
pub(crate) fn prepare_islands(
    mut islands: ResMut<Islands>,
    links: Links,
    beads: Query<(Entity, &Bead, Option<&OnWire>, Has<InIsland>)>,
    wires: Query<(&Wire, &WirePose)>,
    transforms: Query<&Transform>,
    mut commands: Commands,
    mut divergences: Divergences,
    clock: Res<SimClock>,
) {
    islands.dirty = false;
    islands.cached.clear();
    let is_bead = |e: Entity| beads.contains(e);
    let missing = |what: &str, link: Entity, bead: Entity| {
        warn!("wirebead: {what} {link} names {bead}, which is not a bead; the {what} is left out");
    };
    // Every link with the beads it names (as entities, for now).
    let mut named: Vec<(Pending, Vec<Entity>)> = Vec::new();
    let mut springs: Vec<(Entity, Spring)> = Vec::new();
    for (entity, rod) in &links.rods {
        let beads = rod.beads();
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
                },
                beads.to_vec(),
            )),
        }
    }
    for (entity, pin) in &links.pins {
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
            },
            vec![pin.bead()],
        ));
    }
    for (entity, joint) in &links.joints {
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
                },
                joint.beads().to_vec(),
            )),
        }
    }
    for (entity, spring) in &links.springs {
        match spring.beads().iter().find(|b| !is_bead(**b)) {
            Some(&b) => missing("spring", entity, b),
            None => springs.push((entity, *spring)),
        }
    }
    // The beads in islands: every bead a link names, and every bead on no
    // wire.
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
    for (entity, _, on_wire, _) in &beads {
        if on_wire.is_none() {
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
    let mut group_links: Vec<Vec<(Pending, Vec<usize>)>> =
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
        let mut masses = Vec::with_capacity(group.len());
        let mut rows = Vec::new();
        let mut wire_rows = Vec::new();
        let mut invalid = None;
        let mut sides = Vec::new();
        for (local, &entity) in entities.iter().enumerate() {
            let Ok((_, bead, on_wire, _)) = beads.get(entity) else {
                invalid = Some(format!("entity {entity} is no longer a bead"));
                break;
            };
            masses.push(bead.mass());
            let Some(on_wire) = on_wire else { continue };
            match wires.get(on_wire.0).map(|(w, p)| (w, p.get())) {
                Ok((wire, Ok(pose))) => {
                    sides.push((rows.len(), local, *wire.surface()));
                    wire_rows.push((local, rows.len(), on_wire.0));
                    rows.push(IslandRow {
                        kind: RowKind::Wire {
                            shape: wire.shape().clone(),
                            pose: pose.pose(clock.time),
                        },
                        beads: vec![local],
                    });
                }
                Ok((_, Err(e))) => invalid = Some(e.to_string()),
                Err(_) => invalid = Some(format!("entity {} has no Wire", on_wire.0)),
            }
        }
        let mut link_rows = Vec::new();
        let mut anchored = Vec::new();
        for (pending, local) in links {
            let start = rows.len();
            if pending.anchored {
                anchored.push((start, pending.entity));
            }
            link_rows.push(if pending.pin {
                LinkRows::Pin(pending.entity, start)
            } else {
                LinkRows::One(pending.entity, start)
            });
            for mut row in pending.rows {
                row.beads = row.beads.iter().map(|&i| local[i]).collect();
                rows.push(row);
            }
        }
        // A rough wire's bead gets a row to hold it still while static
        // friction can (set aside while it slides).
        let mut sticks = Vec::new();
        for &(row, local, surface) in &sides {
            if surface.friction.is_some() {
                sticks.push((row, rows.len()));
                rows.push(IslandRow {
                    kind: RowKind::Axis {
                        axis: DVec2::X,
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
        let built = built.map(|mut island| {
            for (row, _, surface) in sides {
                island.set_side(row, surface.side, surface.restitution);
                if surface.resists() {
                    let stick = sticks.iter().find(|s| s.0 == row).map(|s| s.1);
                    island.set_rough(row, surface.friction, surface.damping, stick);
                }
            }
            island
        });
        match built {
            Ok(island) => islands.cached.push(CachedIsland {
                report: IslandReport {
                    beads: entities,
                    rows: row_count,
                    ..default()
                },
                island,
                work: IslandWork::default(),
                states: Vec::with_capacity(group.len()),
                forces: Vec::with_capacity(group.len()),
                links: link_rows,
                wire_rows,
                anchored,
                outcome: None,
            }),
            Err(reason) => {
                for &bead in &entities {
                    divergences.report(bead, reason.clone(), clock.time);
                }
            }
        }
    }
    for (entity, _, _, marked) in &beads {
        match (index.contains_key(&entity), marked) {
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

/// Steps every island whose beads have not diverged: gathers their states
/// and forces, calls [`Island::step`] (the islands split over the compute
/// task pool from [`ParallelStep::threshold`] beads in islands up), writes
/// back the states, the diagnostics and the `Transform`s. An island whose
/// step fails stops as a whole, each of its beads marked [`Diverged`].
pub(crate) fn step_islands(
    params: Res<SimParams>,
    clock: Res<SimClock>,
    parallel: Res<ParallelStep>,
    mut islands: ResMut<Islands>,
    mut beads: Query<
        (
            &mut Bead,
            Option<&mut BeadDiagnostics>,
            Option<&mut Transform>,
            Option<&mut WireContact>,
        ),
        (With<InIsland>, Without<Diverged>),
    >,
    mut changes: MessageWriter<ContactChanged>,
    wires: Query<(Ref<Wire>, &WirePose)>,
    pins: Query<&Pin>,
    transforms: Query<&Transform, Without<InIsland>>,
    mut diagnostics: Query<&mut ConstraintDiagnostics>,
    mut divergences: Divergences,
) {
    let settings = params.step_settings();
    let gravity = params.gravity;
    let mut stepped_beads = 0;
    'gather: for cached in &mut islands.cached {
        cached.outcome = None;
        cached.states.clear();
        cached.forces.clear();
        for &entity in &cached.report.beads {
            let Ok((bead, ..)) = beads.get(entity) else {
                continue 'gather; // a bead of it stopped: so does the island
            };
            cached.states.push(bead.state());
            cached.forces.push(bead.step_force(gravity));
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
            info!("wirebead: bead {bead} {}", describe_event(&event));
            changes.write(ContactChanged { bead, event });
        }
        for &(local, row, _) in &cached.wire_rows {
            if let Ok((.., Some(mut contact))) = beads.get_mut(cached.report.beads[local]) {
                let held = if cached.work.holds(row) {
                    Contact::OnWire
                } else {
                    Contact::InFlight
                };
                if contact.contact != held {
                    contact.contact = held;
                }
            }
        }
        for (i, &entity) in cached.report.beads.iter().enumerate() {
            let Ok((mut bead, bead_diagnostics, transform, _)) = beads.get_mut(entity) else {
                continue;
            };
            let state = cached.states[i];
            bead.advance_to(state);
            if let Some(mut transform) = transform {
                place(&mut transform, state.position);
            }
            if let Some(mut d) = bead_diagnostics {
                let wire_row = cached
                    .wire_rows
                    .iter()
                    .find(|w| w.0 == i)
                    .map(|w| rows[w.1]);
                let (kinetic, potential) = state.energy(bead.mass(), gravity);
                *d = BeadDiagnostics {
                    c: wire_row.map_or(0.0, |r| r.c),
                    c_dot: wire_row.map_or(0.0, |r| r.c_dot),
                    lambda: wire_row.map_or(0.0, |r| r.lambda),
                    constraint_force: pushed[i],
                    kinetic,
                    potential,
                };
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
