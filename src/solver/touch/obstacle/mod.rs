//! Beads that meet the bodies of a physics engine (obstacles) within a
//! step, each event answered among only the beads of the one body it
//! concerns (its island, or a bead alone).
//!
//! The step has been taken as if no obstacle were there. For each pair of
//! a bead of radius `r` and an obstacle near its path (the broad phase is
//! the caller's):
//!
//! 1. **Where they meet.** The gap `g(s) = d(x(s), body(s)) − r` between
//!    the bead's surface and the body's, `s` the part of the step passed,
//!    the body moving on with the velocity and spin it had at the step's
//!    start. Where it closes by the step's end, or where a ball swept
//!    straight along the bead's path meets the body within it (a fast
//!    bead that would end on the far side: conservative advancement, never
//!    past the first touch), regula falsi on `s`, the body's beads stepped
//!    again from the step's start to each trial, finds `g = 0` to 1e-13 of
//!    the step.
//! 2. **The strike**, at the earliest such instant, with the impact law of
//!    two beads ([`resolve_impacts`]): the body's point is a bead of its
//!    own whose velocity is `v + ω × r` and whose answer to an impulse `J`
//!    at the point is `K J`, `K = I/M − [r]× I⁻¹ [r]×` (zero for a static
//!    or kinematic body, which nothing moves); restitution and friction
//!    are the means of the bead's and the body's. The rest of the step is
//!    taken again from the struck state, and 1 repeats.
//! 3. **Resting contact.** A pair in touch where a part starts (a marble
//!    on a platform) is not located. Where the step ends with it
//!    overlapping, one of the two parts from the other: the bead, where a
//!    push along the normal moves it within 60° of the normal (a bead on
//!    a wire across a crate resting on it cannot), or where the body
//!    cannot move; else the body. The bead parts by a split impulse: the
//!    beads are given, where the last part starts, the velocity along the
//!    normal that moves it out over the part, the part is taken again,
//!    and the same impulse, answered where it ends, is taken back, so
//!    that the beads end parted on their wires, their motion as it was,
//!    no energy added. The body parts by an impulse that moves it out
//!    over the next step ([`BodyPush`]). The pair is then struck where
//!    the step ends, at `e = 0` where its bounce would be slower than
//!    what one step's forces give it. A bead so rests on a floor, rides a
//!    moving platform, or holds up a crate, step after step. Where the
//!    body of beads may not be stepped again (its own beads struck each
//!    other within the step), its beads are moved out along their answer
//!    instead, to first order on their wires. A bead that parts from a
//!    body strikes it there as a body that does not give: the body did
//!    not move away as it was struck before (a crate pressed against a
//!    wall, whose contacts are not known here), and a bead pushed on
//!    against it would be held back in place with a velocity that says
//!    it moves.
//!
//! The body's impulse (the sum of every strike's on it) is returned for
//! the caller to apply at the point struck; within the step, the body
//! moves on from the strike as the impulse sets it moving
//! ([`Obstacle::struck`]), so that what a bead struck does not run into
//! it again.

use bevy::math::{DMat3, DVec3};

use super::{StepSpan, TOUCHING, TouchBody, TouchError};
use crate::geometry::Coordinates;
use crate::solver::contact::bracket_root;
use crate::solver::impact::{Response, Strike, Touch, resolve_impacts};
use crate::solver::solve::SolveError;
use crate::solver::state::BeadState;

mod aware;
mod rest;

pub(crate) use aware::MeetsObstacles;

/// How many instants one body's beads may strike obstacles at within one
/// step before the step is reported as not settling.
const MAX_INSTANTS: usize = 32;

/// The shortest part of a step (of the step) a resting contact is parted
/// over by a velocity; what is left of a shorter one is moved.
const SHORTEST: f64 = 1e-6;

/// How many straight sweeps a meeting is looked for along before a bead
/// that grazes a body is taken not to meet it.
const SWEEPS: usize = 64;

/// Where a body is nearest a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Nearest<V> {
    /// The point of the body's surface nearest.
    pub point: V,
    /// The unit normal out of its surface there (towards the point
    /// where the point is outside).
    pub normal: V,
    /// The point's signed distance from the surface: negative inside.
    pub distance: f64,
}

/// A body's point as a strike meets it: its velocity, and its velocity
/// change `K J` per impulse `J` there (each in space, the plane's `z`
/// zero); `K` zero for a body nothing moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BodyPoint {
    /// The point's velocity.
    pub velocity: DVec3,
    /// `K`: `1/M − [r]× I⁻¹ [r]×`, `r` the point from the centre of mass.
    pub response: DMat3,
}

/// A body of a physics engine that beads meet, as it moves over one step.
pub(crate) trait Obstacle<V> {
    /// Where its surface is nearest `at` a part `s` of the step in (its
    /// start at 0, its end at 1); none where the shape cannot say.
    fn nearest(&self, s: f64, at: V) -> Option<Nearest<V>>;
    /// Its point `at` a part `s` of the step in.
    fn point(&self, s: f64, at: V) -> BodyPoint;
    /// How far any point of it moves over the whole step, at most.
    fn reach(&self) -> f64;
    /// Its restitution and Coulomb friction against a bead.
    fn surface(&self) -> (f64, f64);
    /// It took `impulse` at its point `at` a part `s` of the step in: it
    /// moves on from there as the impulse sets it moving.
    fn struck(&mut self, s: f64, at: V, impulse: V);
}

/// A bead of a body and an obstacle that may meet within the step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ObstaclePair {
    /// The bead's index in its body.
    pub bead: usize,
    /// Its radius (positive), restitution and friction.
    pub radius: f64,
    /// Its restitution: a strike takes the mean of the bead's and the
    /// obstacle's.
    pub restitution: f64,
    /// Its friction, taken as restitution is.
    pub friction: f64,
    /// The obstacle's index.
    pub obstacle: usize,
}

/// What a pair's strikes at one instant did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ObstacleStrike<V> {
    /// The pair's index in the list given.
    pub pair: usize,
    /// When.
    pub time: f64,
    /// The point of the body struck.
    pub point: V,
    /// The impulse on the body (N s): along the normal and against the
    /// slip.
    pub impulse: V,
    /// The first strike's impulse along the normal, closing speed and
    /// bounce; its friction impulse, the sum of all.
    pub strike: Strike,
}

/// An impulse that parts a body from a bead resting on it (no strike:
/// what moves the body its share of their overlap over the next step).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BodyPush<V> {
    /// The pair's index in the list given.
    pub pair: usize,
    /// The point of the body pushed.
    pub point: V,
    /// The impulse on the body (N s).
    pub impulse: V,
}

/// The step of one body's beads as it meets obstacles.
struct Meeting<'a, 'b, V, B: ?Sized> {
    span: StepSpan,
    body: &'a mut B,
    pairs: &'a [ObstaclePair],
    obstacles: &'a mut [&'b mut dyn Obstacle<V>],
}

/// Meets `obstacles` with the beads of `body` that `pairs` name (see the
/// module's documentation): `body` was stepped over `span` as if nothing
/// were there; where a bead meets an obstacle within it, the step is cut
/// and the strike made (`exact`: `body` may be stepped again from the
/// step's start, no strike of its own beads having cut it), or, where it
/// may not, the beads that end the step overlapping a body or past it are
/// moved out and struck where it ends. Each strike is appended to
/// `struck`, and the body is [`finish`](TouchBody::finish)ed.
pub(crate) fn meet_obstacles<V: Coordinates, B: TouchBody<V> + ?Sized>(
    span: StepSpan,
    body: &mut B,
    (pairs, obstacles): (&[ObstaclePair], &mut [&mut dyn Obstacle<V>]),
    exact: bool,
    (struck, pushed): (&mut Vec<ObstacleStrike<V>>, &mut Vec<BodyPush<V>>),
) -> Result<(), TouchError> {
    let (start, mut end) = (body.start().to_vec(), body.end().to_vec());
    let missing = |p: &ObstaclePair| {
        start.len() <= p.bead || end.len() <= p.bead || obstacles.len() <= p.obstacle
    };
    if let Some(bead) = pairs.iter().position(missing) {
        return Err(TouchError::Missing { bead });
    }
    let mut meeting = Meeting {
        span,
        body,
        pairs,
        obstacles,
    };
    let mut meets = false;
    for (k, pair) in pairs.iter().enumerate() {
        meets |= meeting.gap(k, 1.0, end[pair.bead].position) <= TOUCHING * pair.radius
            || meeting
                .sweep(k, (0.0, start[pair.bead].position), end[pair.bead].position)
                .is_some();
    }
    if !meets {
        return Ok(());
    }
    // Where the last part of the step starts: what resting contact is
    // answered from where the body may be stepped again.
    let mut last = None;
    if exact {
        meeting.body.rewind();
        let mut now = start;
        let mut done = 0.0;
        for instant in 0.. {
            let Some(s) = meeting.earliest((done, &now), &end)? else {
                break;
            };
            if instant == MAX_INSTANTS {
                let bead = pairs.first().map_or(0, |p| p.bead);
                return Err(TouchError::ObstacleStrikes {
                    bead,
                    instants: instant,
                });
            }
            meeting.advance(done, s, &mut now)?;
            meeting.body.keep();
            done = s;
            meeting.strike_touching(s, (&mut now, &[]), struck)?;
            end.clone_from(&now);
            meeting.advance(done, 1.0, &mut end)?;
        }
        last = Some((done, now));
    } else {
        // Into or past a body, where the step met it on the way (a bead in
        // touch where the step starts and pushed on into the body by a
        // bead behind it, too): back to where it met it.
        for (k, pair) in pairs.iter().enumerate() {
            let (from, to) = (start[pair.bead].position, end[pair.bead].position);
            if let Some(s) = meeting.sweep(k, (0.0, from), to) {
                let met = from + (to - from) * s;
                if let Some(near) = meeting.nearest(k, 1.0, met) {
                    let depth = near.normal.dot(met - to);
                    if depth > 0.0 {
                        meeting.move_out(k, near.normal, depth, &mut end)?;
                    }
                }
            }
        }
    }
    // Resting contact: each pair that ends overlapping is parted, the
    // bead and the body each taking its share.
    let overlaps = meeting.overlaps(&end)?;
    match last {
        // A part too short to part the beads over by a velocity: moved.
        Some((done, mut now)) if !overlaps.is_empty() && done < 1.0 - SHORTEST => {
            let pushes = meeting.push_apart((done, &mut now), &overlaps)?;
            end.clone_from(&now);
            meeting.advance(done, 1.0, &mut end)?;
            meeting.take_back((&overlaps, &pushes), &mut end)?;
        }
        _ => {
            for overlap in &overlaps {
                meeting.move_out(overlap.pair, overlap.normal, overlap.bead, &mut end)?;
            }
        }
    }
    for overlap in &overlaps {
        if overlap.body > 0.0 && overlap.body_weight > 0.0 {
            // What moves the body its share over the next step.
            let impulse = overlap.body / meeting.span.dt / overlap.body_weight;
            pushed.push(BodyPush {
                pair: overlap.pair,
                point: overlap.point,
                impulse: overlap.normal * -impulse,
            });
        }
    }
    // A bead that had to part from a body strikes it as a body that does
    // not give: it did not move away as it was struck before (something
    // else holds it).
    let pinned: Vec<usize> = overlaps
        .iter()
        .filter(|o| o.bead > 0.0)
        .map(|o| o.pair)
        .collect();
    meeting.strike_touching(1.0, (&mut end, &pinned), struck)?;
    meeting.body.finish(&end);
    Ok(())
}

impl<V: Coordinates, B: TouchBody<V> + ?Sized> Meeting<'_, '_, V, B> {
    /// Where pair `k`'s obstacle is nearest `at`, a part `s` of the step
    /// in.
    fn nearest(&self, k: usize, s: f64, at: V) -> Option<Nearest<V>> {
        self.obstacles.get(self.pairs[k].obstacle)?.nearest(s, at)
    }

    /// Pair `k`'s gap with its bead at `at`, a part `s` of the step in:
    /// infinite where the obstacle cannot say.
    fn gap(&self, k: usize, s: f64, at: V) -> f64 {
        self.nearest(k, s, at)
            .map_or(f64::INFINITY, |n| n.distance - self.pairs[k].radius)
    }

    /// Steps `states`, a part `from` of the step in, on to the part `to`.
    fn advance(
        &mut self,
        from: f64,
        to: f64,
        states: &mut [BeadState<V>],
    ) -> Result<(), SolveError> {
        let (dt, h) = (self.span.dt, (to - from) * self.span.dt);
        // No time to step over: the beads are where they are.
        if h.is_nan() || h <= 0.0 {
            return Ok(());
        }
        self.body.advance(self.span.time + from * dt, h, states)
    }

    /// The first part of the step at which a ball of pair `k`'s radius,
    /// going straight from `x0` (at the part `s0`) to `x1` (at its end),
    /// touches its obstacle as it moves: conservative advancement, each
    /// move as long as the gap over the fastest the two may close.
    fn sweep(&self, k: usize, (s0, x0): (f64, V), x1: V) -> Option<f64> {
        let obstacle = self.obstacles.get(self.pairs[k].obstacle)?;
        let left = 1.0 - s0;
        if left.is_nan() || left <= 0.0 {
            return None;
        }
        let d = x1 - x0;
        let rate = d.dot(d).sqrt() / left + obstacle.reach();
        if rate.is_nan() || rate <= 0.0 {
            return None;
        }
        let touch = TOUCHING * self.pairs[k].radius;
        let mut s = s0;
        for _ in 0..SWEEPS {
            let at = x0 + d * ((s - s0) / left);
            let gap = self.gap(k, s, at);
            if gap.is_nan() || gap <= touch {
                return Some(s);
            }
            s += gap / rate;
            if s > 1.0 {
                return None;
            }
        }
        Some(s)
    }

    /// The earliest part of the step after `done` (where the beads are
    /// at `now`, the step's end as taken from there at `end`) at which a
    /// pair apart there meets its obstacle.
    fn earliest(
        &mut self,
        (done, now): (f64, &[BeadState<V>]),
        end: &[BeadState<V>],
    ) -> Result<Option<f64>, SolveError> {
        let mut first: Option<f64> = None;
        for (k, pair) in self.pairs.iter().enumerate() {
            let i = pair.bead;
            let g0 = self.gap(k, done, now[i].position);
            if g0.is_nan() || g0 <= TOUCHING * pair.radius {
                continue; // in touch: resting contact, where the step ends
            }
            let until = first.unwrap_or(1.0);
            // The end of a bracket: a little past where the straight
            // sweeps from each trial first touch the body on the bead's
            // path (never on its far side), or where the step ends
            // overlapping.
            let mut closed = None;
            let mut from = (done, now[i].position);
            for _ in 0..4 {
                let Some(s) = self.sweep(k, from, end[i].position) else {
                    break;
                };
                if s >= until {
                    break;
                }
                let (g, at) = self.gap_after(k, (done, now), s)?;
                if g <= 0.0 {
                    closed = Some((s, g));
                    break;
                }
                // In touch: a quarter of the radius on, the bead is in the
                // body (whose far face is at least a diameter on).
                let d = end[i].position - at;
                let length = d.dot(d).sqrt();
                let on = if length > 0.0 {
                    (s + 0.25 * pair.radius / length * (1.0 - s)).min(until)
                } else {
                    until
                };
                if on > s {
                    let (g, _) = self.gap_after(k, (done, now), on)?;
                    if g <= 0.0 {
                        closed = Some((on, g));
                        break;
                    }
                }
                if s <= from.0 {
                    break;
                }
                from = (s, at);
            }
            let g1 = self.gap(k, 1.0, end[i].position);
            if closed.is_none() && g1 <= 0.0 {
                closed = Some((1.0, g1));
            }
            let Some(closed) = closed else {
                continue;
            };
            let at = |s: f64| self.gap_after(k, (done, now), s).map(|(g, _)| g);
            let s = bracket_root((done, g0), closed, 1e-13, at)?;
            if s < until {
                first = Some(s);
            }
        }
        Ok(first)
    }

    /// Pair `k`'s gap, and where its bead is, a part `s` of the step in,
    /// the body's beads stepped there from `now` at the part `done`.
    fn gap_after(
        &mut self,
        k: usize,
        (done, now): (f64, &[BeadState<V>]),
        s: f64,
    ) -> Result<(f64, V), SolveError> {
        let mut states = now.to_vec();
        self.advance(done, s, &mut states)?;
        let at = states[self.pairs[k].bead].position;
        Ok((self.gap(k, s, at), at))
    }

    /// Strikes every pair in touch a part `s` of the step in, its beads
    /// at `states`, with the law of two beads: each obstacle's point a
    /// bead of its own (one of the `pinned` pairs' as a point nothing
    /// moves); and a ledger of each one's impulse.
    fn strike_touching(
        &mut self,
        s: f64,
        (states, pinned): (&mut [BeadState<V>], &[usize]),
        struck: &mut Vec<ObstacleStrike<V>>,
    ) -> Result<(), TouchError> {
        let time = self.span.time + s * self.span.dt;
        let beads = states.len();
        let mut touching = Vec::new();
        for (k, pair) in self.pairs.iter().enumerate() {
            let at = states[pair.bead].position;
            if let Some(near) = self.nearest(k, s, at)
                && near.distance - pair.radius <= TOUCHING * pair.radius
            {
                touching.push((k, near));
            }
        }
        if touching.is_empty() {
            return Ok(());
        }
        // The beads', then each touch's point's, then each one's ledger.
        let count = touching.len();
        let mut velocities: Vec<V> = states.iter().map(|s| s.velocity).collect();
        let mut touches = Vec::with_capacity(count);
        let mut responses = Vec::with_capacity(count);
        let mut points = Vec::with_capacity(count);
        for (slot, &(k, near)) in touching.iter().enumerate() {
            let pair = self.pairs[k];
            let obstacle = &*self.obstacles[pair.obstacle];
            let mut point = obstacle.point(s, near.point);
            if pinned.contains(&k) {
                point.response = DMat3::ZERO;
            }
            points.push(point);
            velocities.push(V::from_xyz(point.velocity));
            let (e, mu) = obstacle.surface();
            let (body, ledger) = (beads + slot, beads + count + slot);
            let x = states[pair.bead].position;
            let touch = Touch::between(
                (body, x - near.normal, 0.0),
                (pair.bead, x, pair.radius),
                0.5 * (pair.restitution + e),
            )?
            .with_friction(0.5 * (pair.friction + mu));
            let push = self.body.push(pair.bead);
            let touch = touch.resting_below(near.normal.dot(push).abs() * self.span.dt);
            let answer = |d: V| -> Result<Vec<(usize, V)>, SolveError> {
                let mut changes: Vec<(usize, V)> = self
                    .body
                    .respond(time, states, pair.bead, d)?
                    .into_iter()
                    .enumerate()
                    .collect();
                changes.push((body, V::from_xyz(point.response * -d.xyz())));
                changes.push((ledger, -d));
                Ok(changes)
            };
            responses.push(Response::answered(&touch, answer)?);
            touches.push(touch);
        }
        velocities.extend(std::iter::repeat_n(V::ZERO, count));
        let mut strikes = Vec::new();
        resolve_impacts(&touches, &responses, &mut velocities, &mut strikes)?;
        for (state, &v) in states.iter_mut().zip(&velocities) {
            state.velocity = v;
        }
        for (slot, &(k, near)) in touching.iter().enumerate() {
            let impulse = velocities[beads + count + slot];
            if impulse != V::ZERO {
                self.obstacles[self.pairs[k].obstacle].struck(s, near.point, impulse);
            }
            let mut mine = strikes.iter().filter(|strike| strike.touch == slot);
            let Some(&first) = mine.next() else {
                continue;
            };
            let friction_impulse =
                first.friction_impulse + mine.map(|s| s.friction_impulse).sum::<f64>();
            struck.push(ObstacleStrike {
                pair: k,
                time,
                point: near.point,
                impulse: velocities[beads + count + slot],
                strike: Strike {
                    touch: k,
                    friction_impulse,
                    ..first
                },
            });
        }
        Ok(())
    }
}
