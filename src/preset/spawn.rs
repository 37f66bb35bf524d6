//! Putting a scene into the world: its wires, beads and links as entities,
//! each marked as the scene's.

use bevy::prelude::*;

use super::format::{BeadPreset, SceneLink, ScenePreset};
use crate::dynamics::{Bead, BeadVelocity, OnWire, Pin, PrescribedMotion, Rod, Spring, Wire};
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
        let names = self.bead_names();
        let mut beads = Vec::new();
        let mut spawn_bead =
            |preset: &BeadPreset, wire: Option<(Entity, Twist)>, commands: &mut Commands| {
                let name = Name::new(names[beads.len()].clone());
                let params = preset.params();
                let Ok(bead) = Bead::new(params) else {
                    beads.push(Entity::PLACEHOLDER);
                    return;
                };
                let mut entity = commands.spawn((bead, name, FromPreset));
                if let Some((wire, twist)) = wire {
                    let velocity = BeadVelocity(params.initial_velocity_on(&twist));
                    entity.insert((OnWire(wire), velocity));
                }
                beads.push(entity.id());
            };
        for wire in &self.wires {
            let transform =
                Transform::from_xyz(wire.position.x as f32, wire.position.y as f32, 0.0)
                    .with_rotation(Quat::from_rotation_z(wire.angle_degrees.to_radians() as f32));
            let made = Wire::new(wire.shape.clone()).and_then(|w| w.with_surface(wire.surface()));
            let wire_entity = made.ok().map(|component| {
                let mut entity = commands.spawn((component, transform, FromPreset));
                if let Ok(motion) = PrescribedMotion::new(wire.motion)
                    && wire.motion.moves()
                {
                    entity.insert(motion);
                }
                entity.id()
            });
            let base = Pose::new(wire.position, wire.angle_degrees.to_radians());
            let (_, twist) = wire.motion.at(base, 0.0);
            for preset in &wire.beads {
                spawn_bead(preset, wire_entity.map(|e| (e, twist)), commands);
            }
        }
        for preset in &self.beads {
            spawn_bead(preset, None, commands);
        }
        for link in self.resolve_links(&names).unwrap_or_default() {
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
        beads
    }
}
