//! [`IslandPlugin`]: islands in the ECS. The beads joined by [`Rod`]s,
//! [`Pin`]s, [`Joint`]s and [`Spring`]s, and free beads (on no wire), are
//! grouped and cached in [`Islands`] until the topology changes, and
//! stepped each step by [`Island`]. A bead on a wire and joined to
//! nothing keeps the per-bead step (and its batched fast path); one with
//! a radius steps alone here, so that its meetings are settled with the
//! islands' (`lone`).
//!
//! | file | what it holds |
//! |---|---|
//! | `build` | rebuilding the islands when the topology changes, or the pairs that may touch |
//! | `start` | how an island built again starts: its rows as the last islands left them; which islands a regrouping keeps whole |
//! | `step` | stepping them: gather, solve (in parallel), write back |
//! | `lone` | beads with a radius that ride a plain wire alone, each a body of its own in the settlement |
//! | `touch` | beads that touch: the steps cut where they meet, the strikes |
//! | `world` | beads that meet the bodies of a physics engine ([`WorldBodies`]): gathered by its adapter, met after the beads' own touches |
//! | `send_back` | beads that settled off a wire sent back to its start ([`SendsBeadsBack`]) |

mod build;
mod lone;
mod send_back;
mod start;
mod step;
mod touch;
// Gathered only by an avian adapter.
#[cfg_attr(not(any(feature = "avian2d", feature = "avian3d")), allow(dead_code))]
mod world;

use std::collections::HashMap;

use bevy::ecs::lifecycle::{Add, Insert, Remove};
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

#[cfg(any(feature = "avian2d", feature = "avian3d"))]
pub(crate) use world::{BodyImpulse, WorldBodies, WorldBody};

use super::clock::advance_clock;
use super::schedule::WireBeadSystems;
use super::step::LoneStep;
use super::wires::place_wires;
use crate::dynamics::{
    BeadRadius, BeadSentBack, CatchesBeads, ConstraintDiagnostics, Dimension, Joint, OnWire, Pin,
    RidingBody, Rod, SendsBeadsBack, Spring,
};
use crate::solver::{BeadState, Island, IslandMark, IslandWork, LinearForce, SolveError};

/// Builds and steps the [`Islands`]: beads joined by links, and free beads,
/// in the plane (`Islands`) and in space (`Islands<DVec3>`, where every
/// bead steps in an island, those on a wire and joined to nothing in one
/// of their own).
#[derive(Default)]
pub struct IslandPlugin;

impl Plugin for IslandPlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<Rod>()
            .register_type::<Pin>()
            .register_type::<Pin<DVec3>>()
            .register_type::<Spring>()
            .register_type::<CatchesBeads>()
            .add_message::<BeadSentBack>()
            .register_type::<SendsBeadsBack>()
            .register_type::<SendsBeadsBack<DVec3>>()
            .register_type::<ConstraintDiagnostics>();
        add_islands::<DVec2>(app);
        add_islands::<DVec3>(app);
    }
}

/// The islands of one dimension: their resource, the lifecycle observers
/// that mark them for a rebuild, the rebuild and the step.
fn add_islands<V: LoneStep>(app: &mut App) {
    app.init_resource::<Islands<V>>()
        .add_observer(topology_changed::<Add, V::Bead, V>)
        .add_observer(topology_changed::<Remove, V::Bead, V>)
        .add_observer(topology_changed::<Insert, OnWire, V>)
        .add_observer(topology_changed::<Remove, OnWire, V>)
        .add_observer(topology_changed::<Insert, V::Wire, V>)
        .add_observer(topology_changed::<Remove, V::Wire, V>)
        .add_observer(topology_changed::<Insert, Rod, V>)
        .add_observer(topology_changed::<Remove, Rod, V>)
        .add_observer(topology_changed::<Insert, Pin<V>, V>)
        .add_observer(topology_changed::<Remove, Pin<V>, V>)
        .add_observer(topology_changed::<Insert, Spring, V>)
        .add_observer(topology_changed::<Remove, Spring, V>)
        .add_observer(topology_changed::<Insert, Joint<V>, V>)
        .add_observer(topology_changed::<Remove, Joint<V>, V>)
        .add_observer(topology_changed::<Insert, BeadRadius, V>)
        .add_observer(topology_changed::<Remove, BeadRadius, V>)
        .add_observer(topology_changed::<Insert, CatchesBeads, V>)
        .add_observer(topology_changed::<Remove, CatchesBeads, V>)
        .add_observer(topology_changed::<Insert, RidingBody, V>)
        .add_observer(topology_changed::<Remove, RidingBody, V>)
        .add_systems(
            PreUpdate,
            build::prepare_islands::<V>
                .run_if(islands_changed::<V>)
                .after(WireBeadSystems::Restart),
        )
        .add_systems(
            FixedUpdate,
            (
                build::prepare_islands::<V>
                    .run_if(islands_changed::<V>)
                    .after(place_wires::<V>)
                    .before(advance_clock)
                    .in_set(WireBeadSystems::Prepare),
                step::step_islands::<V>
                    .run_if(any_island::<V>)
                    .in_set(WireBeadSystems::Step),
                // Before the islands are built for the step: a bead sent
                // back is in the one it joins for this step.
                send_back::send_back::<V>
                    .run_if(any_with_component::<SendsBeadsBack<V>>)
                    .before(build::prepare_islands::<V>)
                    .in_set(WireBeadSystems::Prepare),
            ),
        );
}

/// Marks a bead the island plugin steps: in an island (joined to another
/// bead or a point, or on no wire), or with a radius riding a wire alone
/// (its meetings settled with the islands'); the per-bead step leaves it
/// alone. Kept by the plugin.
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
    /// The largest drift `|C|` of the rows that held after the last step
    /// (rods, pins, wires and contacts; not a one-sided wire its bead has
    /// left).
    pub drift: f64,
    /// How many rows the last solve dropped as redundant.
    pub redundant: usize,
    /// How many substeps the last step took (more than one where a Newton
    /// solve had no root at the full step).
    pub substeps: u32,
    /// The pairs of its beads pressed together at the end of the last
    /// step, each with the force they press with.
    pub pressed: Vec<PressedPair>,
    /// How many steps it has written back since it was built. Islands
    /// that merge or split as pairs of beads meet and part are built
    /// anew; the others are kept, and count on.
    pub steps: u64,
}

/// Two beads that touch, pressed together at the end of a step: the
/// force of their contact row, `λ` (newtons, along the line between their
/// centres; zero or more).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PressedPair {
    /// One bead.
    pub a: Entity,
    /// The other.
    pub b: Entity,
    /// The force each presses on the other with.
    pub force: f64,
}

/// A contact row of an island: the row, the row that holds the pair by
/// static friction (where it has friction, in the plane), its two beads
/// (`a < b`, their indices in the island) and the sum of their radii.
#[derive(Clone, Copy, Debug)]
struct ContactRow {
    row: usize,
    stick: Option<usize>,
    a: usize,
    b: usize,
    reach: f64,
}

/// Which link a range of rows belongs to, for its diagnostics.
#[derive(Clone, Copy, Debug)]
enum LinkRows {
    /// One row: a rod or a joint.
    One(Entity, usize),
    /// A pin's rows, one for each axis.
    Pin(Entity, usize),
}

/// A wire row of an island: the bead it holds, the row, the wire,
/// which of the wire's rows it is (a curve in space has two), and whether
/// the wire is the bead's own (or one that catches it, see
/// [`CatchesBeads`](crate::CatchesBeads)).
#[derive(Clone, Copy, Debug)]
struct WireRow {
    bead: usize,
    row: usize,
    wire: Entity,
    part: usize,
    own: bool,
}

/// One island as the step keeps it.
#[derive(Clone)]
struct CachedIsland<V: Dimension> {
    report: IslandReport,
    island: Island<V>,
    work: IslandWork<V>,
    states: Vec<BeadState<V>>,
    forces: Vec<LinearForce<V>>,
    /// Each bead's mass, as the island was built with it (a restart or a
    /// change of links builds it again).
    masses: Vec<f64>,
    links: Vec<LinkRows>,
    /// The wire rows of the beads on a wire.
    wire_rows: Vec<WireRow>,
    /// Each bead's row on its own wire, if it is on one.
    own_rows: Vec<Option<usize>>,
    /// The first row of each pin fixed to another entity, and the pin.
    anchored: Vec<(usize, Entity)>,
    /// The contact rows between its beads that may touch, by `(a, b)`.
    contacts: Vec<ContactRow>,
    /// Where each bead's contacts with the beads after it start in
    /// `contacts` (one more than it has beads).
    contact_starts: Vec<usize>,
    /// What this step did: not stepped (a bead of it has stopped), or the
    /// step's result.
    outcome: Option<Result<(), SolveError>>,
    /// Its beads with a radius, gathered each step (see `touch`).
    touching: touch::Touching,
    /// Whether each of its beads would ride its wire alone but for the
    /// contact rows that join it (see `touch::near`).
    alone: Vec<bool>,
    /// Where the step started and what its work carried into it, kept
    /// while it has beads that touch.
    start: Vec<BeadState<V>>,
    mark: IslandMark<V>,
    /// What its work carried into the step, kept while it has beads that
    /// touch (for a settlement taken again from the step's start).
    begin: IslandMark<V>,
}

/// The islands of the current topology: beads joined by constraints and
/// springs, each solved as one system. Rebuilt when a link, a bead or a
/// wire is added, changed or removed, or the run restarts; as beads with
/// radii come near or part, only the islands they join or leave are
/// built again. `Islands` are the plane's, `Islands<DVec3>` space's.
///
/// A clone (as the [`Timeline`](crate::plugin::Timeline) keeps one each
/// step) steps on exactly as the original would.
#[derive(Resource, Clone)]
pub struct Islands<V: Dimension = DVec2> {
    cached: Vec<CachedIsland<V>>,
    /// The beads with a radius on a plain wire, joined to nothing: each
    /// steps alone, and settles touches as a body of its own.
    lone: Vec<lone::LoneTouch<V>>,
    dirty: bool,
    /// Whether the pairs of beads that may touch changed since the
    /// islands were built, and nothing else did: the rebuild keeps each
    /// island that does not want it (`wanting`) whose beads are as they
    /// were.
    regrouped: bool,
    /// Which islands a pair of beads that may touch wants built again
    /// (see `touch::regroup`).
    wanting: Vec<bool>,
    /// Since when each bead off a wire that sends beads back has been
    /// slower than the wire's settling speed ([`SendsBeadsBack`]), s:
    /// kept here so that a clone steps on as the original would.
    settling: HashMap<Entity, f64>,
}

impl<V: Dimension> Default for Islands<V> {
    fn default() -> Self {
        Self {
            cached: Vec::new(),
            lone: Vec::new(),
            dirty: false,
            regrouped: false,
            wanting: Vec::new(),
            settling: HashMap::new(),
        }
    }
}

impl<V: Dimension> Islands<V> {
    /// What the last step of each island reported.
    pub fn iter(&self) -> impl Iterator<Item = &IslandReport> {
        self.cached.iter().map(|c| &c.report)
    }

    /// The report of the island holding `bead`, if it is in one.
    pub fn of(&self, bead: Entity) -> Option<&IslandReport> {
        self.iter().find(|r| r.beads.contains(&bead))
    }

    /// The kinetic and gravitational energy of every bead the islands
    /// step, and the energy in their springs, after the last step: each
    /// island's, and each bead with a radius that rides a wire alone.
    pub(crate) fn energy(&self) -> f64 {
        let joined: f64 = self.iter().map(|r| r.energy).sum();
        joined + self.lone.iter().map(|l| l.energy).sum::<f64>()
    }

    /// Roughly how much memory a clone of the islands takes, in bytes:
    /// the step's buffers hold about twenty numbers per bead coordinate
    /// and per row.
    pub(crate) fn bytes(&self) -> usize {
        self.cached
            .iter()
            .map(|c| {
                20 * (c.states.len() * size_of::<V>() + c.report.rows * size_of::<f64>())
                    + size_of::<CachedIsland<V>>()
            })
            .sum::<usize>()
            + self.lone.len() * size_of::<lone::LoneTouch<V>>()
            + self.settling.len() * size_of::<(Entity, f64)>()
    }

    /// Asks for a rebuild before the next step.
    pub(crate) fn mark_dirty(&mut self) {
        self.dirty = true;
    }

    /// Asks for the islands that `wanting` names (a pair of beads that
    /// may touch is not joined, or one joined has parted) to be built
    /// again before the next step, the others kept as they are.
    fn mark_regrouped(&mut self, wanting: Vec<bool>) {
        self.regrouped = true;
        self.wanting = wanting;
    }
}

/// Marks the islands for a rebuild: observed on the lifecycle events that
/// change which beads are joined or on which wire.
fn topology_changed<E: EntityEvent, B: Bundle, V: Dimension>(
    _: On<E, B>,
    mut islands: ResMut<Islands<V>>,
) {
    islands.mark_dirty();
}

/// Whether the islands need a rebuild: the run condition of
/// [`build::prepare_islands`], so a step with nothing changed costs the executor
/// no task.
fn islands_changed<V: Dimension>(islands: Res<Islands<V>>) -> bool {
    islands.dirty || islands.regrouped
}

/// Whether there is an island or a bead alone to step: the run condition of
/// [`step::step_islands`].
fn any_island<V: Dimension>(islands: Res<Islands<V>>) -> bool {
    !islands.cached.is_empty() || !islands.lone.is_empty()
}
