//! Beads that meet the bodies of a physics engine: an adapter (avian's)
//! gathers the bodies near the beads into [`WorldBodies`] before the step;
//! after the beads' own touches are settled, each island or bead alone
//! whose beads come near one meets it ([`solver::meet_obstacles`]), and
//! the impulses on the bodies are left for the adapter to apply. This file
//! only moves data between the islands, the bodies and the solver.

use bevy::math::DVec3;
use bevy::prelude::*;

use crate::dynamics::{BeadStruckBody, Dimension};
use crate::plugin::report::log_strike;
use crate::solver::{
    self, Obstacle, ObstaclePair, ObstacleStrike, StepSpan, TouchBead, TouchBody, TouchError,
};

/// A body of the world as beads meet it over one step: its collider's
/// entity, the box it sweeps over the step, and its shape and motion.
pub(crate) struct WorldBody<V> {
    /// The collider's entity.
    pub entity: Entity,
    /// The rigid body that takes its impulses: none where strikes do not
    /// move it (static, kinematic, or a collider on no body).
    pub moved: Option<Entity>,
    /// The box its shape sweeps over the step.
    pub bounds: (DVec3, DVec3),
    /// Its shape where it is over the step, and how it answers a strike.
    pub obstacle: Box<dyn Obstacle<V> + Send + Sync>,
}

/// An impulse a bead gave a body of the world: what its adapter applies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BodyImpulse<V> {
    /// The rigid body.
    pub body: Entity,
    /// Where, in the world.
    pub point: V,
    /// The impulse on it, N s.
    pub impulse: V,
}

/// The bodies of a physics engine that beads with radii meet over the
/// coming step (gathered by its adapter before the step), and the
/// impulses they took (applied by it after).
#[derive(Resource)]
pub(crate) struct WorldBodies<V: Dimension> {
    /// The bodies near the beads.
    pub bodies: Vec<WorldBody<V>>,
    /// What the beads gave them this step.
    pub impulses: Vec<BodyImpulse<V>>,
}

impl<V: Dimension> Default for WorldBodies<V> {
    fn default() -> Self {
        Self {
            bodies: Vec::new(),
            impulses: Vec::new(),
        }
    }
}

/// Where a bead of the settlement is: its index among its beads, and
/// its entity.
pub(super) struct Settled<'a> {
    pub beads: &'a [TouchBead],
    pub entities: &'a [Entity],
    /// Which bodies (islands, then beads alone) a strike between beads
    /// cut this step: they are not stepped again from its start.
    pub cut: &'a [bool],
}

/// Meets the bodies of `world` with the beads of `bodies` that come near
/// them over `span` (see [`solver::meet_obstacles`]), each body of beads
/// on its own; each strike is sent and logged, each impulse left in
/// `world`. A body whose beads fail stops, its beads named in `failed`
/// with the reason in words.
pub(super) fn meet_world<V: Dimension>(
    span: StepSpan,
    bodies: &mut [&mut dyn TouchBody<V>],
    settled: Settled,
    world: &mut WorldBodies<V>,
    (sent, failed): (
        &mut MessageWriter<BeadStruckBody>,
        &mut Vec<(Entity, TouchError)>,
    ),
) {
    if world.bodies.is_empty() || settled.beads.is_empty() {
        return;
    }
    let mut boxes: Vec<(DVec3, DVec3)> = settled
        .beads
        .iter()
        .map(|t| {
            let body = &bodies[t.body];
            solver::swept(
                t,
                body.start()[t.bead].position,
                body.end()[t.bead].position,
            )
        })
        .collect();
    let count = boxes.len();
    boxes.extend(world.bodies.iter().map(|b| b.bounds));
    // Each bead's pairs with the bodies whose boxes meet its own, by its
    // body.
    let mut by_body: Vec<Vec<(usize, ObstaclePair)>> = vec![Vec::new(); bodies.len()];
    for (i, j) in solver::overlapping(&boxes) {
        let (bead, obstacle) = match (i < count, j < count) {
            (true, false) => (i, j - count),
            (false, true) => (j, i - count),
            _ => continue,
        };
        let t = settled.beads[bead];
        by_body[t.body].push((
            bead,
            ObstaclePair {
                bead: t.bead,
                radius: t.radius,
                restitution: t.restitution,
                friction: t.friction,
                obstacle,
            },
        ));
    }
    let found: Vec<(Entity, Option<Entity>)> =
        world.bodies.iter().map(|b| (b.entity, b.moved)).collect();
    let WorldBodies {
        bodies: shapes,
        impulses,
    } = world;
    let mut obstacles: Vec<&mut dyn Obstacle<V>> = shapes
        .iter_mut()
        .map(|b| &mut *b.obstacle as &mut dyn Obstacle<V>)
        .collect();
    let (mut struck, mut pushed) = (Vec::new(), Vec::new());
    for (k, named) in by_body.iter().enumerate() {
        if named.is_empty() {
            continue;
        }
        let pairs: Vec<ObstaclePair> = named.iter().map(|(_, p)| *p).collect();
        let exact = !settled.cut.get(k).copied().unwrap_or(true);
        struck.clear();
        pushed.clear();
        let met = solver::meet_obstacles(
            span,
            &mut *bodies[k],
            (&pairs, &mut obstacles),
            exact,
            (&mut struck, &mut pushed),
        );
        for strike in &struck {
            let (bead, pair) = named[strike.pair];
            let (entity, moved) = found[pair.obstacle];
            report(strike, (settled.entities[bead], entity), sent);
            if let Some(moved) = moved {
                impulses.push(BodyImpulse {
                    body: moved,
                    point: strike.point,
                    impulse: strike.impulse,
                });
            }
        }
        for push in &pushed {
            let (_, pair) = named[push.pair];
            if let (_, Some(moved)) = found[pair.obstacle] {
                impulses.push(BodyImpulse {
                    body: moved,
                    point: push.point,
                    impulse: push.impulse,
                });
            }
        }
        if let Err(e) = met {
            failed.extend(named.iter().map(|&(bead, _)| (settled.entities[bead], e)));
        }
    }
}

/// Sends one strike of a bead on a body and logs it in one line
/// ([`log_strike`]).
fn report<V: Dimension>(
    strike: &ObstacleStrike<V>,
    (bead, body): (Entity, Entity),
    sent: &mut MessageWriter<BeadStruckBody>,
) {
    let s = strike.strike;
    log_strike(
        &format!("bead {bead} and body {body}"),
        (strike.time, &s),
        "off",
    );
    sent.write(BeadStruckBody {
        bead,
        body,
        time: strike.time,
        impulse: s.impulse,
        closing_speed: s.closing_speed,
        bounced: s.bounced,
        friction_impulse: s.friction_impulse,
    });
}
