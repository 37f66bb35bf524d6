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
        self.spawn_all(commands).0
    }

    /// [`ScenePreset::spawn`], and the bodies in avian2d (feature
    /// `avian2d`; without it they are left out, with a warning): the
    /// beads and the bodies in the file's order.
    pub fn spawn_all(&self, commands: &mut Commands) -> (Vec<Entity>, Vec<Entity>) {
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
        let spawned: Vec<Option<Entity>> = wires.iter().map(|w| w.0).collect();
        let bodies = self.spawn_bodies(&spawned, commands);
        let beads = spawn_beads_and_links(&wires, &self.beads, links, self.bead_names(), commands);
        (beads, bodies)
    }

    /// Spawns the bodies in avian2d, puts the wires that ride them on
    /// them (`wires` the spawned wires) and the path joints on them,
    /// spawns the hinges and couplings, and sets avian's gravity to the
    /// scene's.
    #[cfg(feature = "avian2d")]
    fn spawn_bodies(&self, wires: &[Option<Entity>], commands: &mut Commands) -> Vec<Entity> {
        if self.bodies.is_empty() {
            return Vec::new();
        }
        use avian2d::math::AdjustPrecision;
        commands.insert_resource(avian2d::prelude::Gravity(
            self.params.gravity.adjust_precision(),
        ));
        let bodies = super::bodies_plane::spawn_bodies(&self.bodies, commands);
        join_bodies(
            (wires, &bodies),
            (self.wires.iter().map(|w| w.body.as_str()), &self.bodies),
            (
                &self.paths().unwrap_or_default(),
                super::bodies_plane::joint,
            ),
            (&self.joins().unwrap_or_default(), super::bodies_plane::join),
            commands,
        );
        bodies
    }

    /// Says that the bodies are left out: this build has no avian2d.
    #[cfg(not(feature = "avian2d"))]
    fn spawn_bodies(&self, _: &[Option<Entity>], _: &mut Commands) -> Vec<Entity> {
        bodies_left_out(&self.name, self.bodies.len(), "avian2d")
    }
}

/// Says once, where a scene has bodies, that this build leaves them out
/// for want of `feature`; no bodies.
#[cfg(not(all(feature = "avian2d", feature = "avian3d")))]
pub(super) fn bodies_left_out(scene: &str, count: usize, feature: &str) -> Vec<Entity> {
    if count > 0 {
        warn!(
            "wirebead: scene {scene:?} has {count} bodies, which this build cannot run (build with the {feature} feature); they are left out"
        );
    }
    Vec::new()
}

/// Joins a scene's spawned `bodies` (of the file's `presets`, in order)
/// to the rest of it: each wire whose body is named (`wire_bodies`, each
/// wire's) rides that body, each path joint is put on its body (`joint`
/// making it from its wire's entity), each hinge and coupling is spawned
/// (`join` spawning it between its two bodies), and each body is named and marked
/// [`FromPreset`].
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
pub(super) fn join_bodies<'a, V, B, J, F, H>(
    (wires, bodies): (&[Option<Entity>], &[Entity]),
    (wire_bodies, presets): (impl Iterator<Item = &'a str>, &[B]),
    (paths, joint): (&[super::ScenePath<V>], F),
    (joins, join): (&[super::SceneJoin<V>], H),
    commands: &mut Commands,
) where
    V: crate::geometry::Coordinates,
    B: super::SceneBody,
    J: Bundle,
    F: Fn(Entity, &super::ScenePath<V>) -> J,
    H: Fn([Entity; 2], &super::SceneJoin<V>, &mut Commands) -> Entity,
{
    for (wire, body) in wires.iter().zip(wire_bodies) {
        let carrier = presets
            .iter()
            .position(|b| !body.is_empty() && b.name() == body);
        if let (Some(wire), Some(carrier)) = (wire, carrier) {
            commands
                .entity(*wire)
                .insert(crate::dynamics::WireOnBody(bodies[carrier]));
        }
    }
    for path in paths {
        if let Some(wire) = wires[path.wire] {
            commands.entity(bodies[path.body]).insert(joint(wire, path));
        }
    }
    for joined in joins {
        let pair = joined.bodies().map(|b| bodies[b]);
        let spawned = join(pair, joined, commands);
        commands.entity(spawned).insert(FromPreset);
    }
    for (&body, preset) in bodies.iter().zip(presets) {
        commands
            .entity(body)
            .insert((Name::new(preset.name().to_owned()), FromPreset));
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
