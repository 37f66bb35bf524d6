//! What a [`Timeline`](super::Timeline) frame holds: every bead's and
//! wire's state after a step, the islands' work, avian's moving bodies;
//! and the world's columns it is captured from and restored to.

use std::any::Any;

use bevy::ecs::system::SystemParam;
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use super::super::clock::SimClock;
use super::super::islands::Islands;
use super::super::wires::MovingWires;
use crate::dynamics::{
    BeadDiagnostics, BeadPosition, BeadVelocity, Dimension, Diverged, RailOrientation, WireContact,
    WirePlace, WirePose,
};

/// One bead as a [`Timeline`](super::Timeline) recorded it after a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordedBead<V> {
    /// The time after the step ([`SimClock::time`]).
    pub time: f64,
    /// Its position.
    pub position: V,
    /// Its velocity.
    pub velocity: V,
    /// Whether it was held on its wire (not in flight off a one-sided
    /// wire, and on a wire at all).
    pub on_wire: bool,
    /// When it diverged, if it had.
    pub diverged: Option<f64>,
}

/// A rigid body of avian as a [`Timeline`](super::Timeline) recorded it after a step: the
/// values avian held, each exactly in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordedBody {
    /// The body.
    pub entity: Entity,
    /// Its origin (`z` zero in the plane).
    pub position: DVec3,
    /// Its turn as avian holds it: in the plane `[cos, sin, 0, 0]` of its
    /// angle, in space its quaternion's `[x, y, z, w]`.
    pub rotation: [f64; 4],
    /// Its velocity.
    pub velocity: DVec3,
    /// Its spin (about `z` in the plane).
    pub spin: DVec3,
    /// Its `Transform`.
    pub transform: Transform,
}

#[cfg_attr(
    not(any(feature = "avian2d", feature = "avian3d")),
    allow(dead_code, reason = "the avian adapters record the bodies")
)]
/// Avian's moving bodies of one dimension in a frame: their states, and
/// what the avian adapter keeps of their joints (its own type).
pub(super) struct BodiesFrame {
    pub(super) bodies: Vec<RecordedBody>,
    pub(super) joints: Box<dyn Any + Send + Sync>,
    pub(super) bytes: usize,
}

#[cfg_attr(
    not(any(feature = "avian2d", feature = "avian3d")),
    allow(dead_code, reason = "the avian adapters record the bodies")
)]
/// Where a frame keeps the bodies of a dimension (2 or 3).
pub(super) fn part(dimension: usize) -> usize {
    usize::from(dimension == 3)
}

/// The whole state after one step.
pub(super) struct Frame {
    pub(super) clock: SimClock,
    pub(super) plane: Scene<DVec2>,
    pub(super) space: Scene<DVec3>,
    /// Avian's moving bodies in the plane and in space, once recorded.
    pub(super) bodies: [Option<BodiesFrame>; 2],
    pub(super) bytes: usize,
}

impl Frame {
    /// Whether `other` is the same state (see [`Timeline`]).
    pub(super) fn same(&self, other: &Frame) -> bool {
        self.clock.steps == other.clock.steps
            && self.clock.time.to_bits() == other.clock.time.to_bits()
            && self.plane.same(&other.plane)
            && self.space.same(&other.space)
    }
}

/// A wire as a frame holds it: its pose, `Transform` and place.
type WireFrame<V> = (Entity, WirePose<V>, Transform, Option<WirePlace<V>>);

/// One dimension's part of a frame.
pub(super) struct Scene<V: Dimension> {
    beads: Vec<BeadFrame<V>>,
    wires: Vec<WireFrame<V>>,
    moving: MovingWires<V>,
    islands: Islands<V>,
}

impl<V: Dimension> Scene<V> {
    pub(super) fn bead(&self, bead: Entity, time: f64) -> Option<RecordedBead<V>> {
        let i = self.beads.binary_search_by_key(&bead, |b| b.entity).ok()?;
        let b = &self.beads[i];
        Some(RecordedBead {
            time,
            position: b.position,
            velocity: b.velocity,
            on_wire: b.contact.is_some_and(|c| c.is_on()),
            diverged: b.diverged.as_ref().map(|d| d.time),
        })
    }

    fn same(&self, other: &Self) -> bool {
        self.beads.len() == other.beads.len()
            && self.beads.iter().zip(&other.beads).all(|(a, b)| a.same(b))
    }

    /// Roughly how much memory it takes.
    pub(super) fn bytes(&self) -> usize {
        self.beads.len() * size_of::<BeadFrame<V>>()
            + self.wires.len() * size_of::<WireFrame<V>>()
            + self.islands.bytes()
    }
}

/// One bead as a frame holds it.
#[derive(Clone, Debug)]
struct BeadFrame<V: Dimension> {
    entity: Entity,
    position: V,
    velocity: V,
    contact: Option<WireContact>,
    diagnostics: Option<BeadDiagnostics<V>>,
    diverged: Option<Diverged>,
    transform: Option<Transform>,
    rail: Option<RailOrientation>,
}

impl<V: Dimension> BeadFrame<V> {
    /// The same bead in the same state: position and velocity bit for bit.
    fn same(&self, other: &Self) -> bool {
        let bits = |v: V| v.xyz().to_array().map(f64::to_bits);
        let contact = |c: &Option<WireContact>| c.map(|c| (c.contact, c.along.to_bits()));
        self.entity == other.entity
            && bits(self.position) == bits(other.position)
            && bits(self.velocity) == bits(other.velocity)
            && contact(&self.contact) == contact(&other.contact)
            && self.diagnostics == other.diagnostics
            && self.diverged == other.diverged
    }
}

/// A bead's recorded columns.
type BeadColumns<V> = (
    Entity,
    &'static mut BeadPosition<V>,
    &'static mut BeadVelocity<V>,
    Option<&'static mut WireContact>,
    Option<&'static mut BeadDiagnostics<V>>,
    Option<&'static Diverged>,
    Option<&'static mut Transform>,
    Option<&'static mut RailOrientation>,
);

/// One dimension's state in the world, to record or restore.
#[derive(SystemParam)]
pub(super) struct SceneState<'w, 's, V: Dimension> {
    beads: Query<'w, 's, BeadColumns<V>, With<<V as Dimension>::Bead>>,
    wires: Query<
        'w,
        's,
        (
            Entity,
            &'static mut WirePose<V>,
            &'static mut Transform,
            Option<&'static mut WirePlace<V>>,
        ),
        (
            With<<V as Dimension>::Wire>,
            Without<<V as Dimension>::Bead>,
        ),
    >,
    moving: ResMut<'w, MovingWires<V>>,
    islands: ResMut<'w, Islands<V>>,
}

impl<V: Dimension> SceneState<'_, '_, V> {
    pub(super) fn capture(&self) -> Scene<V> {
        let mut beads: Vec<BeadFrame<V>> = self
            .beads
            .iter()
            .map(
                |(entity, position, velocity, contact, diagnostics, diverged, transform, rail)| {
                    BeadFrame {
                        entity,
                        position: position.0,
                        velocity: velocity.0,
                        contact: contact.copied(),
                        diagnostics: diagnostics.copied(),
                        diverged: diverged.cloned(),
                        transform: transform.copied(),
                        rail: rail.copied(),
                    }
                },
            )
            .collect();
        beads.sort_unstable_by_key(|b| b.entity);
        Scene {
            beads,
            wires: self
                .wires
                .iter()
                .map(|(entity, pose, transform, place)| (entity, *pose, *transform, place.copied()))
                .collect(),
            moving: self.moving.clone(),
            islands: self.islands.clone(),
        }
    }

    pub(super) fn restore(&mut self, scene: &Scene<V>, commands: &mut Commands) {
        for b in &scene.beads {
            let Ok((
                entity,
                mut position,
                mut velocity,
                contact,
                diagnostics,
                diverged,
                transform,
                rail,
            )) = self.beads.get_mut(b.entity)
            else {
                continue;
            };
            position.set_if_neq(BeadPosition(b.position));
            velocity.set_if_neq(BeadVelocity(b.velocity));
            if let (Some(mut now), Some(then)) = (contact, b.contact) {
                *now = then;
            }
            if let (Some(mut now), Some(then)) = (diagnostics, b.diagnostics) {
                now.set_if_neq(then);
            }
            if let (Some(mut now), Some(then)) = (transform, b.transform) {
                now.set_if_neq(then);
            }
            if let (Some(mut now), Some(then)) = (rail, b.rail) {
                *now = then;
            }
            match (diverged, &b.diverged) {
                (Some(_), None) => {
                    commands.entity(entity).remove::<Diverged>();
                }
                (None, Some(then)) => {
                    commands.entity(entity).insert(then.clone());
                }
                _ => {}
            }
        }
        for (entity, pose, transform, place) in &scene.wires {
            if let Ok((_, mut now, mut shown, placed)) = self.wires.get_mut(*entity) {
                now.set_if_neq(*pose);
                shown.set_if_neq(*transform);
                if let (Some(mut placed), Some(place)) = (placed, place) {
                    placed.set_if_neq(*place);
                }
            }
        }
        *self.moving = scene.moving.clone();
        *self.islands = scene.islands.clone();
    }
}

/// The plane's and space's states (they share `Transform`).
pub(super) type Scenes<'w, 's> = ParamSet<
    'w,
    's,
    (
        SceneState<'static, 'static, DVec2>,
        SceneState<'static, 'static, DVec3>,
    ),
>;
