//! The wire table the bead step reads: every wire's shape and pose, kept
//! from change detection, and the plain circles or spheres the batched
//! step takes.

use bevy::prelude::*;

use super::lone::LoneStep;
use crate::dynamics::{DivergenceReason, OnWire, WirePose, WireRows};
use crate::geometry::{Placement, Surface, WirePath};

/// A wire as the step needs it: its shape and, for most wires, where it
/// stays; a moving wire's path and a one-sided, rough or damped wire's
/// surface behind one pointer, so the table stays small for the rest.
pub(crate) struct TableWire<V: LoneStep> {
    pub(super) shape: V::Lone,
    /// Where a plain wire that stays put is (when `track` is none).
    pub(super) pose: V::Pose,
    /// The path and surface of the others.
    pub(super) track: Option<Box<(WirePath<V>, Surface)>>,
}

impl<V: LoneStep> TableWire<V> {
    fn new(shape: V::Lone, path: WirePath<V>, surface: Surface) -> Self {
        match path.fixed() {
            Some(pose) if surface.is_plain() => Self {
                shape,
                pose,
                track: None,
            },
            _ => Self {
                shape,
                pose: V::Pose::default(),
                track: Some(Box::new((path, surface))),
            },
        }
    }

    /// The path (a fixed one for a wire that stays put).
    #[inline]
    pub(super) fn path(&self) -> WirePath<V> {
        match &self.track {
            Some(track) => track.0,
            None => WirePath::Fixed(self.pose),
        }
    }

    /// The surface.
    #[inline]
    pub(super) fn surface(&self) -> &Surface {
        self.track.as_deref().map_or(&Surface::PLAIN, |t| &t.1)
    }
}

/// A wire for the step, or why beads cannot be stepped on it.
type PlacedWire<V> = Result<TableWire<V>, DivergenceReason>;

/// Every wire's shape and pose, kept by the bead step from change
/// detection (a copy made when a wire changes, not each step), so a bead
/// finds its wire with one indexed read instead of a query lookup. The
/// plain circles or spheres that stay put unrotated (the batched step's
/// wires) are also kept as a small record each, which is all the step
/// reads for a bead on one.
pub(crate) struct WireTable<V: LoneStep> {
    /// Each wire's place in `wires` plus one, by entity index (0: none).
    slot: Vec<u32>,
    /// The wires, each with its entity.
    wires: Vec<(Entity, PlacedWire<V>)>,
    /// For each wire, its entity and, where it is a plain circle or sphere
    /// that stays put unrotated, its centre and radius (else a NaN
    /// radius).
    circles: Vec<(Entity, V, f64)>,
}

impl<V: LoneStep> Default for WireTable<V> {
    fn default() -> Self {
        Self {
            slot: Vec::new(),
            wires: Vec::new(),
            circles: Vec::new(),
        }
    }
}

impl<V: LoneStep> WireTable<V> {
    /// Takes in the wires that changed or were added since the last call,
    /// and drops the ones whose `Wire` or `WirePose` was removed.
    pub(super) fn refresh<'a>(
        &mut self,
        removed: impl IntoIterator<Item = Entity>,
        changed: impl IntoIterator<Item = (Entity, &'a V::Wire, &'a WirePose<V>)>,
    ) {
        for entity in removed {
            if let Some(k) = self.place(entity) {
                let _ = self.wires.swap_remove(k);
                self.circles.swap_remove(k);
                self.slot[entity.index_u32() as usize] = 0;
                if let Some(&(moved, _)) = self.wires.get(k) {
                    self.slot[moved.index_u32() as usize] = k as u32 + 1;
                }
            }
        }
        for (entity, wire, pose) in changed {
            let placed = match (pose.get(), V::lone_shape(wire)) {
                (Ok(path), Some(shape)) => Ok(TableWire::new(shape, path, *wire.surface())),
                (Err(e), _) => Err(DivergenceReason::InvalidWire(e.to_string())),
                (_, None) => Err(DivergenceReason::InvalidWire(
                    "a bead on a curve in space steps in an island".into(),
                )),
            };
            let circle = match &placed {
                Ok(TableWire {
                    shape,
                    pose,
                    track: None,
                }) if Placement::<V>::is_unrotated(pose) => match V::round(shape) {
                    Some(radius) => (entity, Placement::<V>::origin(pose), radius),
                    None => (entity, V::ZERO, f64::NAN),
                },
                _ => (entity, V::ZERO, f64::NAN),
            };
            let index = entity.index_u32() as usize;
            if index >= self.slot.len() {
                self.slot.resize(index + 1, 0);
            }
            match self.slot[index].checked_sub(1) {
                Some(k) => {
                    // This wire, or a despawned one whose index it reuses.
                    self.wires[k as usize] = (entity, placed);
                    self.circles[k as usize] = circle;
                }
                None => {
                    self.wires.push((entity, placed));
                    self.circles.push(circle);
                    self.slot[index] = self.wires.len() as u32;
                }
            }
        }
    }

    /// Where wire `entity` is in the table.
    #[inline(always)]
    fn place(&self, entity: Entity) -> Option<usize> {
        let k = self.slot.get(entity.index_u32() as usize)?.checked_sub(1)? as usize;
        (self.wires[k].0 == entity).then_some(k)
    }

    /// The wire a bead is on.
    #[inline]
    pub(super) fn get(&self, on: &OnWire) -> Result<&TableWire<V>, DivergenceReason> {
        match self.place(on.0) {
            Some(k) => self.wires[k].1.as_ref().map_err(Clone::clone),
            None => Err(DivergenceReason::InvalidWire(format!(
                "entity {} has no Wire",
                on.0
            ))),
        }
    }

    /// The centre and radius of the wire a bead is on, where it is a plain
    /// circle or sphere that stays put unrotated.
    #[inline(always)]
    pub(super) fn circle(&self, on: &OnWire) -> Option<(V, f64)> {
        let k = self.slot.get(on.0.index_u32() as usize)?.checked_sub(1)? as usize;
        let &(entity, centre, radius) = self.circles.get(k)?;
        (entity == on.0 && !radius.is_nan()).then_some((centre, radius))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::Wire;
    use bevy::math::DVec2;

    /// A plain circle at `x` on the x axis.
    fn placed(x: f32) -> (Wire, WirePose) {
        let pose = WirePose::from_transform(&Transform::from_xyz(x, 0.0, 0.0));
        (Wire::circle(1.0 + f64::from(x)).unwrap(), pose)
    }

    #[test]
    fn the_wire_table_finds_each_wire_after_a_removal_and_not_the_removed_one() {
        let mut world = World::new();
        let wires: Vec<Entity> = (0..4).map(|_| world.spawn_empty().id()).collect();
        let data: Vec<_> = (0..4).map(|i| placed(i as f32)).collect();
        let mut table = WireTable::<DVec2>::default();
        table.refresh([], wires.iter().zip(&data).map(|(&e, (w, p))| (e, w, p)));
        // Wire 1 goes: the last one takes its place in the table.
        table.refresh([wires[1]], []);
        // A later entity with wire 1's index.
        let reused = Entity::from_index_and_generation(
            wires[1].index(),
            wires[1].generation().after_versions(1),
        );
        for (i, &wire) in wires.iter().enumerate() {
            let found = table.circle(&OnWire(wire));
            if i == 1 {
                assert_eq!(found, None);
                assert!(table.get(&OnWire(wire)).is_err());
            } else {
                let (centre, radius) = found.expect("a wire in the table");
                assert_eq!(
                    (centre, radius),
                    (DVec2::new(i as f64, 0.0), 1.0 + i as f64)
                );
                assert!(table.get(&OnWire(wire)).is_ok());
            }
        }
        // The entity that reuses the index is not the removed wire.
        assert!(table.circle(&OnWire(reused)).is_none());
        let (w, p) = placed(7.0);
        table.refresh([], [(reused, &w, &p)]);
        assert_eq!(
            table.circle(&OnWire(reused)),
            Some((DVec2::new(7.0, 0.0), 8.0))
        );
        assert!(table.circle(&OnWire(wires[1])).is_none());
    }
}
