//! Beads that meet the bodies of a physics engine: an adapter (avian's)
//! gathers the bodies near the beads into [`WorldBodies`] before the step;
//! beads alone meet them in each part of their step the settlement of the
//! beads' own touches takes (`solver::MeetsObstacles`), islands once it is
//! done ([`solver::meet_obstacles`]); the impulses on the bodies are left
//! for the adapter to apply. This file only moves data between the
//! islands, the bodies and the solver.

use bevy::math::DVec3;
use bevy::prelude::*;

use super::lone::LoneBody;
use crate::dynamics::{BeadStruckBody, Dimension};
use crate::plugin::report::log_strike;
use crate::plugin::step::LoneStep;
use crate::solver::{
    self, BodyPush, Obstacle, ObstaclePair, ObstacleStrike, StepSpan, TouchBead, TouchBody,
    TouchError,
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

/// What one body of beads (an island, or a bead alone) did meeting the
/// bodies of the world in one pass: each pair met (the bead's index in
/// the settlement, the pair), the strikes, the pushes, and why it failed.
pub(super) struct Met<V> {
    named: Vec<(usize, ObstaclePair)>,
    struck: Vec<ObstacleStrike<V>>,
    pushed: Vec<BodyPush<V>>,
    failed: Option<TouchError>,
}

impl<V> Met<V> {
    /// What a body did that met the world as it was stepped
    /// ([`MeetsObstacles`](crate::solver::MeetsObstacles)): its pairs,
    /// strikes and pushes, and why it failed.
    pub(super) fn of(
        named: Vec<(usize, ObstaclePair)>,
        (struck, pushed): (Vec<ObstacleStrike<V>>, Vec<BodyPush<V>>),
        failed: Option<TouchError>,
    ) -> Self {
        Self {
            named,
            struck,
            pushed,
            failed,
        }
    }
}

/// The pairs of each body's beads (`beads`, each a body's bead with its
/// radius) and the bodies of `world` whose swept boxes meet over the step
/// as `bodies` have taken it: by body, each with its bead's index in
/// `beads`.
pub(super) fn near_world<V: Dimension>(
    bodies: &[&mut dyn TouchBody<V>],
    beads: &[TouchBead],
    world: &WorldBodies<V>,
) -> Vec<Vec<(usize, ObstaclePair)>> {
    let boxes = swept_boxes(beads, false, |t| {
        let body = bodies.get(t.body)?;
        Some((body.start()[t.bead].position, body.end()[t.bead].position))
    });
    near_boxes(bodies.len(), (beads, &boxes), world)
}

/// The pairs of beads alone (each the body of its own, after `islands`
/// islands) and the bodies of `world` whose boxes meet over the step: each
/// bead's box from where it started to where it ended, grown by as much
/// again (what a strike on another bead may send it through), by body.
pub(super) fn near_beads_alone<V: LoneStep>(
    bodies: &[LoneBody<V>],
    (beads, islands): (&[TouchBead], usize),
    world: &WorldBodies<V>,
) -> Vec<Vec<(usize, ObstaclePair)>> {
    let boxes = swept_boxes(beads, true, |t| {
        let body = bodies.get(t.body.checked_sub(islands)?)?;
        Some((body.start()[0].position, body.end()[0].position))
    });
    let mut by_body = near_boxes(islands + bodies.len(), (beads, &boxes), world);
    by_body.drain(..islands.min(by_body.len()));
    by_body
}

/// Each bead's box over the step, by its index in `beads`: swept from
/// where `ends` says it started to where it ended (none for a bead it
/// does not know), grown by that way again where `grow`.
fn swept_boxes<V: Dimension>(
    beads: &[TouchBead],
    grow: bool,
    ends: impl Fn(&TouchBead) -> Option<(V, V)>,
) -> Vec<(usize, (DVec3, DVec3))> {
    beads
        .iter()
        .enumerate()
        .filter_map(|(i, t)| {
            let (from, to) = ends(t)?;
            let (lo, hi) = solver::swept(t, from, to);
            let more = if grow {
                (to - from).xyz().abs()
            } else {
                DVec3::ZERO
            };
            Some((i, (lo - more, hi + more)))
        })
        .collect()
}

/// The pairs of the beads whose `boxes` are given (each a bead's index in
/// `beads` and its box) and the bodies of `world` whose swept boxes meet
/// them, by body (of `bodies`).
fn near_boxes<V: Dimension>(
    bodies: usize,
    (beads, boxes): (&[TouchBead], &[(usize, (DVec3, DVec3))]),
    world: &WorldBodies<V>,
) -> Vec<Vec<(usize, ObstaclePair)>> {
    let mut by_body: Vec<Vec<(usize, ObstaclePair)>> = vec![Vec::new(); bodies];
    if world.bodies.is_empty() || boxes.is_empty() {
        return by_body;
    }
    let count = boxes.len();
    let all: Vec<(DVec3, DVec3)> = boxes
        .iter()
        .map(|&(_, b)| b)
        .chain(world.bodies.iter().map(|b| b.bounds))
        .collect();
    for (i, j) in solver::overlapping(&all) {
        let (k, obstacle) = match (i < count, j < count) {
            (true, false) => (i, j - count),
            (false, true) => (j, i - count),
            _ => continue,
        };
        let bead = boxes[k].0;
        let t = beads[bead];
        if let Some(list) = by_body.get_mut(t.body) {
            list.push((
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
    }
    by_body
}

/// Meets the bodies of `world` with the beads of `body` in `named` (see
/// [`solver::meet_obstacles`]; `exact` where the body may be stepped
/// again from the step's start).
pub(super) fn meet_world<V: Dimension>(
    span: StepSpan,
    body: &mut dyn TouchBody<V>,
    (named, exact): (Vec<(usize, ObstaclePair)>, bool),
    world: &mut WorldBodies<V>,
) -> Met<V> {
    let mut obstacles: Vec<&mut dyn Obstacle<V>> = world
        .bodies
        .iter_mut()
        .map(|b| &mut *b.obstacle as &mut dyn Obstacle<V>)
        .collect();
    let pairs: Vec<ObstaclePair> = named.iter().map(|(_, p)| *p).collect();
    let (mut struck, mut pushed) = (Vec::new(), Vec::new());
    let met = solver::meet_obstacles(
        span,
        body,
        (&pairs, &mut obstacles),
        exact,
        (&mut struck, &mut pushed),
    );
    Met {
        named,
        struck,
        pushed,
        failed: met.err(),
    }
}

/// Sends each strike of `met` and logs it, leaves each impulse on a body
/// in `world`, and names each bead of a body that failed in `failed`,
/// with the reason (`entities` the settlement's beads').
pub(super) fn report_world<V: Dimension>(
    met: &Met<V>,
    (world, entities): (&mut WorldBodies<V>, &[Entity]),
    (sent, failed): (
        &mut MessageWriter<BeadStruckBody>,
        &mut Vec<(Entity, TouchError)>,
    ),
) {
    for strike in &met.struck {
        let (bead, pair) = met.named[strike.pair];
        report(
            strike,
            (entities[bead], world.bodies[pair.obstacle].entity),
            sent,
        );
    }
    // The impulses on the bodies that move: the strikes', then the pushes'.
    let struck = met.struck.iter().map(|s| (s.pair, s.point, s.impulse));
    let pushed = met.pushed.iter().map(|p| (p.pair, p.point, p.impulse));
    for (pair, point, impulse) in struck.chain(pushed) {
        let (_, pair) = met.named[pair];
        if let Some(body) = world.bodies[pair.obstacle].moved {
            world.impulses.push(BodyImpulse {
                body,
                point,
                impulse,
            });
        }
    }
    if let Some(e) = met.failed {
        failed.extend(met.named.iter().map(|&(bead, _)| (entities[bead], e)));
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
