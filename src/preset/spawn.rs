//! Putting a scene into the world: its wires, beads and links as entities,
//! each marked as the scene's.

use bevy::prelude::*;

use super::format::{BeadPreset, SceneLink, ScenePreset};
use crate::dynamics::{
    BeadRadius, BeadVelocity, CatchesBeads, Dimension, OnWire, Pin, PrescribedMotion, Rod, Spring,
    Wire, WirePlace,
};
use crate::geometry::{Pose, Twist};

/// Marks the wires and beads spawned from a preset, which the next preset
/// replaces.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct FromPreset;

impl ScenePreset {
    /// Spawns the wires, the beads (named with [`Name`]) and the links,
    /// each tagged [`FromPreset`]; returns the beads in the file's order.
    /// Call on a validated preset: anything invalid is left out.
    pub fn spawn(&self, commands: &mut Commands) -> Vec<Entity> {
        let mut wires = Vec::new();
        for wire in &self.wires {
            // In `f64` to the solver; the plugin writes the `Transform`.
            let base = Pose::new(wire.position, wire.angle_degrees.to_radians());
            let made = Wire::new(wire.shape.clone()).and_then(|w| w.with_surface(wire.surface()));
            let wire_entity = made.ok().map(|component| {
                let mut entity = commands.spawn((component, WirePlace::new(base), FromPreset));
                if let Ok(motion) = PrescribedMotion::new(wire.motion)
                    && wire.motion.moves()
                {
                    entity.insert(motion);
                }
                if wire.catches {
                    entity.insert(CatchesBeads);
                }
                if let Some(Ok(back)) = wire.sends_back.map(|b| b.component()) {
                    entity.insert(back);
                }
                entity.id()
            });
            let (_, twist) = wire.motion.at(base, 0.0);
            wires.push((wire_entity, twist, wire.beads.as_slice()));
        }
        let links = self.links().unwrap_or_default();
        if let Ok(contacts) = self.contacts.contacts() {
            commands.insert_resource(contacts);
        }
        spawn_beads_and_links(&wires, &self.beads, links, self.bead_names(), commands)
    }
}

/// Spawns a scene's beads, each wire's (on it, if it was spawned, moving
/// by its twist at t = 0) and then the free ones, named in order from
/// `names`, and the links between them; the beads in the file's order.
pub(super) fn spawn_beads_and_links<V: Dimension>(
    wires: &[(Option<Entity>, Twist<V>, &[BeadPreset<V>])],
    free: &[BeadPreset<V>],
    links: Vec<SceneLink<V>>,
    names: Vec<String>,
    commands: &mut Commands,
) -> Vec<Entity> {
    let mut names = names.into_iter();
    let mut beads = Vec::new();
    for &(wire, twist, presets) in wires {
        for preset in presets {
            let on = wire.map(|e| (e, twist));
            beads.push(spawn_bead(preset, names.next(), on, commands));
        }
    }
    for preset in free {
        beads.push(spawn_bead(preset, names.next(), None, commands));
    }
    spawn_links(links, &beads, commands);
    beads
}

/// Spawns one bead of a scene named `name`, on `wire` moving by the
/// twist if there is one (its initial velocity relative to the wire's),
/// marked [`FromPreset`]; a placeholder if its parameters are invalid.
pub(super) fn spawn_bead<V: Dimension>(
    preset: &BeadPreset<V>,
    name: Option<String>,
    wire: Option<(Entity, Twist<V>)>,
    commands: &mut Commands,
) -> Entity {
    let params = preset.params();
    let Ok(bead) = V::bead(params) else {
        return Entity::PLACEHOLDER;
    };
    let mut entity = commands.spawn((bead, Name::new(name.unwrap_or_default()), FromPreset));
    if let Ok(radius) = BeadRadius::new(preset.radius)
        && preset.radius > 0.0
    {
        entity.insert(radius);
    }
    if let Some((wire, twist)) = wire {
        let velocity = BeadVelocity(params.initial_velocity_on(&twist));
        entity.insert((OnWire(wire), velocity));
    }
    entity.id()
}

/// Spawns a scene's links between its spawned `beads`, each marked
/// [`FromPreset`]; one that cannot be made is left out with a warning.
pub(super) fn spawn_links<V: Dimension>(
    links: Vec<SceneLink<V>>,
    beads: &[Entity],
    commands: &mut Commands,
) {
    for link in links {
        let spawned = match link {
            SceneLink::Rod { a, b, length } => Rod::new(beads[a], beads[b], length)
                .map(|rod| commands.spawn((rod, FromPreset)).id()),
            SceneLink::Pin { bead, at } => {
                Pin::new(beads[bead], at).map(|pin| commands.spawn((pin, FromPreset)).id())
            }
            SceneLink::Spring { a, b, spring: s } => {
                Spring::new(beads[a], beads[b], s.rest_length, s.stiffness, s.damping)
                    .map(|spring| commands.spawn((spring, FromPreset)).id())
            }
        };
        if let Err(e) = spawned {
            warn!("wirebead: a link of the scene was left out: {e}");
        }
    }
}
