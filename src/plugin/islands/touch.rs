//! Beads that touch, in the island step: each island with a bead of a
//! [`BeadRadius`](crate::BeadRadius) keeps where its step started, and
//! after every island has stepped, [`solver::settle_touches`] cuts the
//! steps of those whose beads met and makes the strikes. This file only
//! moves data between the islands and the solver.

use bevy::prelude::*;

use super::CachedIsland;
use super::lone::{LoneBody, LoneTouch};
use super::world::{Met, WorldBodies, meet_world, near_beads_alone, near_world, report_world};
use crate::dynamics::{BeadStruckBody, BeadsStruck, Dimension, DivergenceReason};
use crate::plugin::report::{Divergences, log_strike};
use crate::plugin::step::LoneStep;
use crate::solver::{
    self, BeadState, MeetsObstacles, Obstacle, Pressed, SolveError, StepSettings, StepSpan,
    StruckPair, TouchBead, TouchBody, TouchError,
};

/// The bodies of a physics engine the beads meet, and where their
/// strikes are sent.
pub(super) type World<'a, 'w, V> = (
    &'a mut WorldBodies<V>,
    &'a mut MessageWriter<'w, BeadStruckBody>,
);

/// What an island keeps of its beads that touch: each one's index in the
/// island, radius, restitution and friction.
pub(super) type Touching = Vec<(usize, f64, f64, f64)>;

/// One island as the touch settlement steps it.
struct IslandBody<'a, V: Dimension> {
    cached: &'a mut CachedIsland<V>,
    settings: StepSettings,
}

impl<V: Dimension> TouchBody<V> for IslandBody<'_, V> {
    fn start(&self) -> &[BeadState<V>] {
        &self.cached.start
    }

    fn end(&self) -> &[BeadState<V>] {
        &self.cached.states
    }

    fn advance(
        &mut self,
        time: f64,
        h: f64,
        states: &mut [BeadState<V>],
    ) -> Result<(), SolveError> {
        let cached = &mut *self.cached;
        cached.work.rewind(&cached.mark);
        let settings = self.settings.part(h);
        cached.island.step_part(
            time,
            states,
            &cached.forces,
            &settings,
            self.settings.dt,
            &mut cached.work,
        )
    }

    fn keep(&mut self) {
        self.cached.mark = self.cached.work.mark();
    }

    fn respond(
        &mut self,
        time: f64,
        states: &[BeadState<V>],
        bead: usize,
        impulse: V,
    ) -> Result<Vec<V>, SolveError> {
        let cached = &mut *self.cached;
        cached.work.rewind(&cached.mark);
        let answer = cached
            .island
            .respond(time, states, bead, impulse, &mut cached.work)?
            .to_vec();
        // The rows were evaluated for the answer: back to where the step
        // carries on from.
        cached.work.rewind(&cached.mark);
        Ok(answer)
    }

    fn press(
        &mut self,
        time: f64,
        states: &[BeadState<V>],
    ) -> Result<Option<Pressed<V>>, SolveError> {
        let cached = &mut *self.cached;
        if cached.contacts.is_empty() {
            return Ok(None);
        }
        cached.work.rewind(&cached.mark);
        let (velocities, impulses) = cached.island.press(time, states, &mut cached.work)?;
        let velocities = velocities.to_vec();
        let impulses = cached
            .contacts
            .iter()
            .filter(|c| impulses[c.row] != 0.0)
            .map(|c| (c.a, c.b, impulses[c.row]))
            .collect();
        cached.work.rewind(&cached.mark);
        Ok(Some((velocities, impulses)))
    }

    fn push(&self, bead: usize) -> V {
        let cached = &*self.cached;
        cached.forces[bead].at(cached.states[bead].position) / cached.masses[bead]
    }

    fn finish(&mut self, states: &[BeadState<V>]) {
        self.cached.states.clear();
        self.cached.states.extend_from_slice(states);
    }

    fn contact(&self, a: usize, b: usize) -> Option<bool> {
        let row = self.cached.contact_row(a, b)?;
        Some(self.cached.mark.holds(row))
    }

    fn time_steps(&self) -> bool {
        self.settings.method.ends_on_constraints() && self.cached.island.time_steps()
    }

    fn ends_held(&self, a: usize, b: usize) -> bool {
        self.time_steps()
            && self
                .cached
                .contact_row(a, b)
                .is_some_and(|row| self.cached.work.holds(row))
    }

    fn hold(&mut self, a: usize, b: usize, held: bool) {
        if let Some(row) = self.cached.contact_row(a, b) {
            self.cached.mark.hold(row, held);
        }
    }

    fn rewind(&mut self) {
        self.cached.mark.clone_from(&self.cached.begin);
    }

    fn restart(&mut self, time: f64, dt: f64) -> Result<(), SolveError> {
        self.rewind();
        let mut states = self.cached.start.clone();
        self.advance(time, dt, &mut states)?;
        self.finish(&states);
        Ok(())
    }
}

impl<V: Dimension> CachedIsland<V> {
    /// The contact row between beads `a` and `b` of the island, if it has
    /// one.
    fn contact_row(&self, a: usize, b: usize) -> Option<usize> {
        let (a, b) = (a.min(b), a.max(b));
        let (&from, &to) = (self.contact_starts.get(a)?, self.contact_starts.get(a + 1)?);
        let contacts = self.contacts.get(from..to)?;
        contacts.iter().find(|c| c.b == b).map(|c| c.row)
    }
}

/// How many steps ahead the islands are built for: beads with radii that
/// may meet within this many steps are joined by contact rows.
const NEAR_STEPS: f64 = 2.0;

/// How much of its radius more each bead's box is grown by when the
/// islands are built, so that a pair joined stays joined a while.
const NEAR_MARGIN: f64 = 0.25;

/// A bead with a radius as the islands are built and regrouped: where it
/// is, its radius and restitution, and whether it rides its wire alone
/// where no contact row joins it ([`LoneTouch`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Rider<V> {
    pub(super) state: BeadState<V>,
    pub(super) radius: f64,
    pub(super) restitution: f64,
    pub(super) alone: bool,
}

impl<V: Dimension> Rider<V> {
    /// Whether this bead and `other`, which may meet soon, are joined by
    /// a contact row: always, but for two beads that ride their wires
    /// alone and bounce (the lesser restitution above zero), which are
    /// joined only where they rest in touch
    /// ([`solver::rests_in_touch`]). Beads that bounce settle their
    /// meetings as two bodies, each stepped alone; beads at `e = 0` are
    /// held by their row in their island's step (see
    /// [`solver::settle_touches`]).
    fn joins(&self, other: &Self) -> bool {
        let bounce = self.restitution.min(other.restitution) > 0.0;
        !(self.alone && other.alone && bounce)
            || solver::rests_in_touch(&self.state, &other.state, self.radius + other.radius)
    }
}

/// The pairs of `beads` that the island builder joins by contact rows:
/// those that may meet within [`NEAR_STEPS`] steps of `dt`, with
/// [`NEAR_MARGIN`] to spare, and those [`regroup`] would look for, that
/// [`Rider::joins`].
pub(super) fn near<V: Dimension>(beads: &[Rider<V>], dt: f64) -> Vec<(usize, usize)> {
    let states: Vec<(BeadState<V>, f64)> = beads.iter().map(|b| (b.state, b.radius)).collect();
    let mut pairs = solver::may_touch_near(&states, (NEAR_STEPS * dt, NEAR_MARGIN), dt);
    pairs.retain(|&(i, j)| beads[i].joins(&beads[j]));
    pairs
}

/// Whether the islands should be built again before the next step, and
/// which want it: two beads that may meet within it are not joined by a
/// contact row (in different islands, or not yet near at the last build;
/// of two beads that ride their wires alone, only where they rest in
/// touch, see [`near`]), or two joined by one have gone far apart (their
/// islands may part). None where nothing wants it; else whether each of
/// `cached` does (the others may be kept whole).
pub(super) fn regroup<V: Dimension>(
    cached: &[CachedIsland<V>],
    (lone, near_alone): (&[LoneTouch<V>], &[(usize, usize)]),
    dt: f64,
) -> Option<Vec<bool>> {
    let stepped = |k: usize| lone.get(k).filter(|l| matches!(l.outcome, Some(Ok(()))));
    let islands_touch = cached
        .iter()
        .any(|island| island.outcome == Some(Ok(())) && !island.touching.is_empty());
    if !islands_touch && lone.iter().all(|l| l.restitution > 0.0) {
        // Every bead with a radius rides alone and bounces: a pair is
        // joined only where it rests in touch, and the settlement named
        // every pair that ends the step in touch.
        let rests = near_alone.iter().any(|&(a, b)| {
            let (Some(a), Some(b)) = (stepped(a), stepped(b)) else {
                return false;
            };
            solver::rests_in_touch(&a.state, &b.state, a.radius + b.radius)
        });
        return rests.then(|| vec![false; cached.len()]);
    }
    let mut beads = Vec::new();
    // Each bead's island (none for one alone) and index there.
    let mut place = Vec::new();
    let mut wanting = vec![false; cached.len()];
    for (k, island) in cached.iter().enumerate() {
        if island.outcome != Some(Ok(())) {
            continue;
        }
        for &(bead, radius, restitution, _) in &island.touching {
            beads.push(Rider {
                state: island.states[bead],
                radius,
                restitution,
                alone: island.alone[bead],
            });
            place.push((Some(k), bead));
        }
        wanting[k] = island.contacts.iter().any(|contact| {
            let (a, b) = (island.states.get(contact.a), island.states.get(contact.b));
            let (Some(a), Some(b)) = (a, b) else {
                return false;
            };
            let reach = contact.reach;
            let gap = solver::pair_gap(a.position, b.position, reach);
            gap > 4.0 * reach + 4.0 * NEAR_STEPS * dt * solver::pair_speeds(a, b)
        });
    }
    for (k, lone) in lone.iter().enumerate() {
        if matches!(lone.outcome, Some(Ok(()))) {
            beads.push(Rider {
                state: lone.state,
                radius: lone.radius,
                restitution: lone.restitution,
                alone: true,
            });
            place.push((None, k));
        }
    }
    let states: Vec<(BeadState<V>, f64)> = beads.iter().map(|b| (b.state, b.radius)).collect();
    let mut any = wanting.contains(&true);
    for (i, j) in solver::may_touch(&states, dt, 0.0) {
        let ((ki, a), (kj, b)) = (place[i], place[j]);
        let joined = ki.is_some_and(|k| ki == kj && cached[k].contact_row(a, b).is_some());
        if !joined && beads[i].joins(&beads[j]) {
            any = true;
            for k in [ki, kj].into_iter().flatten() {
                wanting[k] = true;
            }
        }
    }
    any.then_some(wanting)
}

/// Settles the touches of the step that started at `time` (see
/// [`solver::settle_touches`]): the islands that stepped and have beads
/// with radii take part; each strike is sent as [`BeadsStruck`] and
/// logged, and a failure stops the touching beads, reported in words.
/// `near_alone` is set to the pairs of beads in `lone` whose paths
/// through the step, as settled, came near (see
/// [`solver::settle_touches`]): every pair of them that ends in touch.
pub(super) fn settle<V: LoneStep>(
    cached: &mut [CachedIsland<V>],
    (lone, shapes): (&mut [LoneTouch<V>], &[Option<V::Lone>]),
    time: f64,
    settings: &StepSettings,
    (struck, world): (&mut MessageWriter<BeadsStruck>, Option<World<V>>),
    divergences: &mut Divergences,
    near_alone: &mut Vec<(usize, usize)>,
) {
    near_alone.clear();
    let mut beads = Vec::new();
    let mut entities = Vec::new();
    // The beads alone that stepped, each a body after the islands, and
    // each one's place in `lone`.
    let mut alone = Vec::new();
    let lone_bodies: Vec<LoneBody<V>> = lone
        .iter_mut()
        .zip(shapes)
        .enumerate()
        .filter(|(_, (lone, _))| matches!(lone.outcome, Some(Ok(()))))
        .filter_map(|(k, (lone, shape))| {
            let shape = shape.as_ref()?;
            alone.push(k);
            Some(LoneBody {
                lone,
                shape,
                settings: *settings,
            })
        })
        .collect();
    for (k, body) in lone_bodies.iter().enumerate() {
        beads.push(TouchBead {
            body: cached.len() + k,
            bead: 0,
            radius: body.lone.radius,
            restitution: body.lone.restitution,
            friction: body.lone.friction,
        });
        entities.push(body.lone.entity);
    }
    for (body, island) in cached.iter().enumerate() {
        if island.outcome != Some(Ok(())) {
            continue;
        }
        for &(bead, radius, restitution, friction) in &island.touching {
            beads.push(TouchBead {
                body,
                bead,
                radius,
                restitution,
                friction,
            });
            entities.push(island.report.beads[bead]);
        }
    }
    if beads.is_empty() || (beads.len() < 2 && world.is_none()) {
        return;
    }
    let mut island_bodies: Vec<IslandBody<V>> = cached
        .iter_mut()
        .map(|cached| IslandBody {
            cached,
            settings: *settings,
        })
        .collect();
    let span = StepSpan {
        time,
        dt: settings.dt,
    };
    let islands = island_bodies.len();
    let (world, sent) = world.unzip();
    // Beads alone meet the bodies of the world in each part of their step
    // the settlement steps them over, their whole step first; islands meet
    // them after, where the settlement leaves them.
    let near = world
        .as_deref()
        .map(|w| near_beads_alone(&lone_bodies, (&beads, islands), w))
        .unwrap_or_default();
    let shapes: Vec<&dyn Obstacle<V>> = world
        .as_deref()
        .map(|w| {
            w.bodies
                .iter()
                .map(|b| &*b.obstacle as &dyn Obstacle<V>)
                .collect()
        })
        .unwrap_or_default();
    let mut lone_bodies: Vec<MeetsObstacles<V, LoneBody<V>>> = lone_bodies
        .into_iter()
        .enumerate()
        .map(|(k, body)| {
            let pairs = near.get(k).map_or_else(Vec::new, |named| {
                named.iter().map(|&(_, pair)| pair).collect()
            });
            MeetsObstacles::new(body, span, (pairs, &shapes))
        })
        .collect();
    let mut failed = Vec::new();
    for (k, body) in lone_bodies.iter_mut().enumerate() {
        if !body.pairs().is_empty()
            && let Err(e) = body.restart(span.time, span.dt)
        {
            failed.push((entities[k], TouchError::Solve(e)));
        }
    }
    let mut bodies: Vec<&mut dyn TouchBody<V>> = island_bodies
        .iter_mut()
        .map(|b| b as &mut dyn TouchBody<V>)
        .chain(lone_bodies.iter_mut().map(|b| b as &mut dyn TouchBody<V>))
        .collect();
    let (mut pairs, mut near_pairs) = (Vec::new(), Vec::new());
    let settled = if beads.len() < 2 {
        Ok(())
    } else {
        solver::settle_touches(span, &mut bodies, &beads, (&mut pairs, &mut near_pairs))
    };
    drop(bodies);
    // The pairs of beads alone that came near, by their places in `lone`.
    near_alone.extend(
        near_pairs
            .iter()
            .filter_map(|&(i, j)| Some((*alone.get(i)?, *alone.get(j)?))),
    );
    for pair in &pairs {
        report(pair, &entities, struck);
    }
    let mut met: Vec<Met<V>> = lone_bodies
        .iter_mut()
        .zip(near)
        .map(|(body, named)| {
            let (done, why) = body.met();
            Met::of(named, done, why)
        })
        .collect();
    drop(lone_bodies);
    drop(shapes);
    if let (Some(world), Some(sent)) = (world, sent)
        && settled.is_ok()
    {
        // Each island meets the bodies of the world where the beads'
        // settlement leaves it: from the step's start where no strike
        // between its beads cut its step, else where it ends.
        let mut cut = vec![false; islands];
        for pair in &pairs {
            for body in [beads[pair.a].body, beads[pair.b].body] {
                if let Some(cut) = cut.get_mut(body) {
                    *cut = true;
                }
            }
        }
        let mut bodies: Vec<&mut dyn TouchBody<V>> = island_bodies
            .iter_mut()
            .map(|b| b as &mut dyn TouchBody<V>)
            .collect();
        let near = near_world(&bodies, &beads, world);
        met.extend(
            near.into_iter()
                .enumerate()
                .filter(|(_, named)| !named.is_empty())
                .map(|(k, named)| meet_world(span, &mut *bodies[k], (named, !cut[k]), world)),
        );
        for done in &met {
            report_world(done, (world, &entities), (sent, &mut failed));
        }
    }
    for (bead, e) in failed {
        let why = DivergenceReason::Touch(e.to_string());
        divergences.report(bead, why, time + settings.dt);
    }
    if let Err(e) = settled {
        let why = match e {
            TouchError::TooManyImpacts { a, b, instants } => format!(
                "beads {} and {} were still striking after {instants} instants of impact within one step",
                entities[a], entities[b],
            ),
            e => e.to_string(),
        };
        for &bead in &entities {
            divergences.report(
                bead,
                DivergenceReason::Touch(why.clone()),
                time + settings.dt,
            );
        }
    }
}

/// Sends one strike and logs it in one line ([`log_strike`]).
fn report(pair: &StruckPair, entities: &[Entity], struck: &mut MessageWriter<BeadsStruck>) {
    let (a, b) = (entities[pair.a], entities[pair.b]);
    let s = pair.strike;
    log_strike(&format!("beads {a} and {b}"), (pair.time, &s), "apart");
    struck.write(BeadsStruck {
        a,
        b,
        time: pair.time,
        impulse: s.impulse,
        closing_speed: s.closing_speed,
        bounced: s.bounced,
        friction_impulse: s.friction_impulse,
    });
}
