//! One group of bodies being settled: the step cut at each instant its
//! beads meet, the strikes made there, and the bodies taken in whose boxes
//! come to meet the group's.

use bevy::math::DVec3;

use super::pool::{Met, Pool, Settled};
use super::{
    MAX_IMPACTS_PER_STEP, StepSpan, StruckPair, TOUCHING, TouchBead, TouchBody, TouchError,
    overlapping, swept,
};
use crate::geometry::Coordinates;
use crate::solver::contact::{bracket_root, locate_between};
use crate::solver::coupled::{closes, ends_in_touch, meets_near, opening_rate, pair_gap};
use crate::solver::solve::SolveError;
use crate::solver::state::BeadState;

mod strikes;

/// A bead (its index) with the box it sweeps.
type Boxed = (usize, (DVec3, DVec3));

/// One group of bodies being settled: where each is now and where its
/// step ends from there.
pub(super) struct Group<'a, V: Coordinates> {
    span: StepSpan,
    beads: &'a [TouchBead],
    bodies: Vec<usize>,
    /// The beads (indices into `beads`) of the group's bodies, and the box
    /// each has swept so far this step (from its start through each
    /// instant the group was cut at).
    members: Vec<usize>,
    paths: Vec<(DVec3, DVec3)>,
    pairs: Vec<(usize, usize)>,
    /// When the group is now.
    time: f64,
    /// Each body's states now and at the step's end, by the body's place
    /// in `bodies`.
    now: Vec<Vec<BeadState<V>>>,
    end: Vec<Vec<BeadState<V>>>,
    /// Whether a body's last step was a trial, not its end.
    tried: Vec<bool>,
    /// Whether the group was cut at all.
    cut: bool,
    /// The pairs in touch pressed into each other, held this step.
    pressed: Vec<(usize, usize)>,
    /// The part the last trial stepped the bodies by from now, and the
    /// states it took each body it stepped to; cleared by anything else
    /// that steps or holds a body.
    last_trial: Option<(f64, Trial<V>)>,
}

/// Each body's states after a trial, by its place in the group; none for
/// a body the trial did not step.
type Trial<V> = Vec<Option<Vec<BeadState<V>>>>;

impl<'a, V: Coordinates> Group<'a, V> {
    /// The group of `bodies` of `all`, from where each starts the step;
    /// `found` where they stand as the broad phase found them (its pairs
    /// are the group's).
    pub(super) fn new<B: TouchBody<V>>(
        span: StepSpan,
        (all, beads): (&[B], &'a [TouchBead]),
        bodies: Vec<usize>,
        (pool, found): (&Pool, bool),
    ) -> Self {
        let now = bodies.iter().map(|&b| all[b].start().to_vec()).collect();
        let end = bodies.iter().map(|&b| all[b].end().to_vec()).collect();
        let tried = vec![false; bodies.len()];
        let mut members: Vec<usize> = bodies
            .iter()
            .flat_map(|&b| pool.beads_of(b))
            .copied()
            .collect();
        members.sort_unstable();
        let mut group = Self {
            span,
            beads,
            bodies,
            members,
            paths: Vec::new(),
            pairs: Vec::new(),
            time: span.time,
            now,
            end,
            tried,
            cut: false,
            pressed: Vec::new(),
            last_trial: None,
        };
        group.pairs = if found {
            pool.pairs_within(&group.members)
        } else {
            group.find_pairs(&[]).0
        };
        group.paths = group.members.iter().map(|&i| group.swept(i)).collect();
        group
    }

    /// Grows each member's path to take in where it is now, or at the
    /// step's end.
    fn trace(&mut self, at_end: bool) {
        for k in 0..self.members.len() {
            let i = self.members[k];
            let p = self.state(i, at_end).position;
            let (low, high) = swept(&self.beads[i], p, p);
            let path = &mut self.paths[k];
            *path = (path.0.min(low), path.1.max(high));
        }
    }

    /// The pairs of the group's beads whose boxes from now to the end
    /// overlap, and the beads of `outside` (with their boxes) that
    /// overlap one of the group's.
    fn find_pairs(&self, outside: &[Boxed]) -> (Vec<(usize, usize)>, Vec<usize>) {
        let mut boxes: Vec<(DVec3, DVec3)> = self.members.iter().map(|&i| self.swept(i)).collect();
        let mine = boxes.len();
        boxes.extend(outside.iter().map(|(_, b)| *b));
        let mut pairs = Vec::new();
        let mut met = Vec::new();
        for (p, q) in overlapping(&boxes) {
            match (p < mine, q < mine) {
                (true, true) => pairs.push((self.members[p], self.members[q])),
                (true, false) => met.push(outside[q - mine].0),
                (false, true) => met.push(outside[p - mine].0),
                (false, false) => {}
            }
        }
        (pairs, met)
    }

    /// The bodies outside the group whose beads' boxes meet its beads'
    /// boxes from now on: those not yet settled (each with the rest of the
    /// group the broad phase first put it in), taken from the pool, and
    /// those settled with another group. The group is then settled again
    /// from the step's start with them, so that what they met before now
    /// is settled too.
    fn meets_outside(&self, pool: &mut Pool) -> Option<Met> {
        // Only the beads whose boxes meet the box about the whole group's.
        let (low, high) = self.members.iter().map(|&i| self.swept(i)).fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(low, high), (a, b)| (low.min(a), high.max(b)),
        );
        let outside: Vec<Boxed> = pool
            .near((low, high))
            .into_iter()
            .filter(|(j, _)| !self.bodies.contains(&self.beads[*j].body))
            .collect();
        let (_, met) = self.find_pairs(&outside);
        if met.is_empty() {
            return None;
        }
        let mut found = Met::default();
        for j in met {
            let body = self.beads[j].body;
            if !pool.free[body] {
                if !found.free.contains(&body) && !found.settled.contains(&body) {
                    found.settled.push(body);
                }
                continue;
            }
            match pool.group_of[body] {
                usize::MAX => {
                    pool.free[body] = false;
                    found.free.push(body);
                }
                g => found.free.extend(pool.take(g)),
            }
        }
        (!found.free.is_empty() || !found.settled.is_empty()).then_some(found)
    }

    /// The place of bead `i`'s body in the group.
    fn slot(&self, i: usize) -> usize {
        let body = self.beads[i].body;
        self.bodies.iter().position(|&b| b == body).unwrap_or(0)
    }

    /// Bead `i`'s state now, or at the step's end.
    fn state(&self, i: usize, at_end: bool) -> BeadState<V> {
        let slot = self.slot(i);
        let states = if at_end {
            &self.end[slot]
        } else {
            &self.now[slot]
        };
        states[self.beads[i].bead]
    }

    /// The box bead `i` sweeps from now to the step's end.
    fn swept(&self, i: usize) -> (DVec3, DVec3) {
        let (from, to) = (self.state(i, false), self.state(i, true));
        swept(&self.beads[i], from.position, to.position)
    }

    /// The gap of pair `(i, j)` between the positions `xa` and `xb`.
    fn gap(&self, (i, j): (usize, usize), xa: V, xb: V) -> f64 {
        pair_gap(xa, xb, self.beads[i].radius + self.beads[j].radius)
    }

    /// How far the group's end is from now.
    fn left(&self) -> f64 {
        self.span.time + self.span.dt - self.time
    }

    /// Cuts the step at each instant of impact in turn, then finishes the
    /// bodies it cut.
    pub(super) fn settle<B: TouchBody<V>>(
        mut self,
        bodies: &mut [B],
        pool: &mut Pool,
        struck: &mut Vec<StruckPair>,
    ) -> Result<Settled, TouchError> {
        let mut last = (0, 0);
        let mut instants = 0;
        while instants < MAX_IMPACTS_PER_STEP * self.pairs.len().max(1) {
            instants += 1;
            let Some((tau, pair)) = self.first_meeting(bodies)? else {
                self.finish(bodies, pool)?;
                return Ok(Settled::Done(self.bodies));
            };
            last = pair;
            self.cut = true;
            self.step_all(bodies, tau, true)?;
            self.trace(false);
            self.strike(bodies, struck)?;
            self.step_all(bodies, self.left(), false)?;
            self.trace(true);
            if let Some(met) = self.meets_outside(pool) {
                return Ok(Settled::Met(self.bodies, met));
            }
            self.pairs = self.find_pairs(&[]).0;
        }
        Err(TouchError::TooManyImpacts {
            a: last.0,
            b: last.1,
            instants,
        })
    }

    /// The first instant (from now) a pair that is apart meets, and the
    /// pair; none if no pair meets before the step's end. Every pair that
    /// may meet is followed at once: regula falsi on the least of their
    /// gaps, each trial stepping their bodies once, so that the cost of a
    /// cut does not grow with the number of pairs.
    fn first_meeting<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
    ) -> Result<Option<(f64, (usize, usize))>, TouchError> {
        let h = self.left();
        let mut pressed = Vec::new();
        // The pairs that may meet, each with its gap now and the part of
        // the step by which it may have met.
        let mut candidates = Vec::new();
        for k in 0..self.pairs.len() {
            let pair = self.pairs[k];
            let (a0, b0) = (self.state(pair.0, false), self.state(pair.1, false));
            let (a1, b1) = (self.state(pair.0, true), self.state(pair.1, true));
            let r = self.beads[pair.0].radius + self.beads[pair.1].radius;
            let g0 = self.gap(pair, a0.position, b0.position);
            let end = self.gap(pair, a1.position, b1.position);
            if g0 <= TOUCHING * r {
                if self.held(bodies, pair) {
                    continue; // its contact row keeps it from closing
                }
                // In touch: struck now if it closes, else left resting;
                // one that meets slowly or near the step's start and
                // that its body's step ends in touch (its row held) has
                // met within the step.
                if let Some(speed) = self.closing(pair) {
                    let within = self.meets_slowly(bodies, pair, (a0, b0))
                        || (self.pressable(bodies, pair)
                            && (meets_near(0.0, g0, speed, self.span.dt)
                                || bodies[self.bodies[self.slot(pair.0)]].time_steps()));
                    if !(within && (ends_in_touch(end, r) || self.ends_held(bodies, pair))) {
                        return Ok(Some((0.0, pair)));
                    }
                    continue;
                }
                if end < -TOUCHING * r {
                    pressed.push(pair);
                }
                continue;
            }
            // Apart: a pair the step ends in touch (as one whose row the
            // step held) is in touch where the next step starts; one that
            // meets slowly is its body's step to hold where it ends
            // overlapping, and left alone where it ends apart.
            if h <= 0.0
                || ends_in_touch(end, r)
                || self.ends_held(bodies, pair)
                || (end > 0.0 && self.meets_slowly(bodies, pair, (a0, b0)))
                || (end > 0.0 && self.stepped_past(bodies, pair, [a0, b0, a1, b1], g0))
            {
                continue;
            }
            if let Some(by) = self.may_meet(pair, [a0, b0, a1, b1], end, h) {
                candidates.push((pair, g0, by));
            }
        }
        let first = self.locate_first(bodies, &mut candidates, h)?;
        // Pairs in touch that the rest of the step presses into each
        // other: held from now where a contact row can, and the step taken
        // again. Each pair once a step, so that the cuts end.
        let mut held = None;
        for pair in pressed {
            let slot = self.slot(pair.0);
            let (ba, bb) = (self.beads[pair.0].bead, self.beads[pair.1].bead);
            let body = &mut bodies[self.bodies[slot]];
            if slot == self.slot(pair.1)
                && body.contact(ba, bb) == Some(false)
                && !self.pressed.contains(&pair)
            {
                body.hold(ba, bb, true);
                self.pressed.push(pair);
                self.last_trial = None;
                held = held.or(Some((0.0, pair)));
            }
        }
        Ok(held.or(first))
    }

    /// How fast pair `(i, j)`, in touch now, closes (m/s, positive); none
    /// where it does not. Closing by rounding, or too slowly to close by
    /// what counts as touching within the step, is not closing.
    fn closing(&self, pair: (usize, usize)) -> Option<f64> {
        let (a, b) = (self.state(pair.0, false), self.state(pair.1, false));
        let r = self.beads[pair.0].radius + self.beads[pair.1].radius;
        let (u, speeds) = opening_rate(&a, &b);
        closes(u, r, speeds, self.span.dt).then_some(-u)
    }

    /// The part `τ ≤ h` by which a pair apart now, its gap `end` at the
    /// step's end, may have met: `h` where its gap ends closed, else where
    /// its straight paths come closest, if they come closer than the radii
    /// within the step (a pair too fast for a step); none if it does not
    /// meet.
    fn may_meet(
        &self,
        pair: (usize, usize),
        [a0, b0, a1, b1]: [BeadState<V>; 4],
        end: f64,
        h: f64,
    ) -> Option<f64> {
        if end <= 0.0 {
            return Some(h);
        }
        let d0 = b0.position - a0.position;
        let change = (b1.position - a1.position) - d0;
        let length = change.dot(change);
        if length.is_nan() || length <= 0.0 {
            return None;
        }
        let s = (-d0.dot(change) / length).clamp(0.0, 1.0);
        let closest = d0 + change * s;
        let r = self.beads[pair.0].radius + self.beads[pair.1].radius;
        (s > 0.0 && s < 1.0 && closest.dot(closest).sqrt() < r).then_some(s * h)
    }

    /// Where the first of `candidates` (pair, gap now, part by which it
    /// may have met) meets. Newton's method on the least gap from the
    /// earliest meeting their smooth paths predict ([`Group::predict`]),
    /// each trial stepping the bodies and taking the gap's rate from the
    /// closest pair, ends where the least gap is within
    /// [`ARRIVED`] of the touching tolerance of nothing; where it does not
    /// within [`NEWTON_TRIALS`], the earliest part at whose end one has
    /// met brackets the meeting, and regula falsi on the least gap
    /// locates it within what Newton's trials bracketed.
    fn locate_first<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        candidates: &mut [((usize, usize), f64, f64)],
        h: f64,
    ) -> Result<Option<(f64, (usize, usize))>, TouchError> {
        let g0 = candidates.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
        let mut low = (0.0, g0);
        let mut high = None;
        let predicted = candidates
            .iter()
            .filter_map(|c| self.predict(c.0, c.2))
            .fold(f64::INFINITY, f64::min);
        let mut tau = predicted;
        for _ in 0..NEWTON_TRIALS {
            if !(tau > low.0 && tau <= high.map_or(h, |(b, _)| b)) {
                break;
            }
            let (gap, pair, rate) = self.least_gap(bodies, candidates, tau)?;
            let reach = self.beads[pair.0].radius + self.beads[pair.1].radius;
            if gap.abs() <= ARRIVED * TOUCHING * reach {
                return Ok(Some((tau, pair)));
            }
            if gap > 0.0 {
                low = (tau, gap);
            } else {
                high = Some((tau, gap));
            }
            tau -= gap / rate;
        }
        if high.is_none() {
            candidates.sort_by(|x, y| x.2.total_cmp(&y.2));
            let mut tried = f64::NAN;
            for k in 0..candidates.len() {
                let by = candidates[k].2;
                if by == tried || by <= low.0 {
                    continue;
                }
                tried = by;
                let (gap, ..) = self.least_gap(bodies, candidates, by)?;
                if gap <= 0.0 {
                    high = Some((by, gap));
                    break;
                }
                low = (by, gap);
                if by >= h {
                    break;
                }
            }
        }
        let Some(high) = high else {
            return Ok(None);
        };
        let tau = locate_between(low, high, h, |tau| {
            Ok(self.least_gap(bodies, candidates, tau)?.0)
        })?;
        let (_, pair, _) = self.least_gap(bodies, candidates, tau)?;
        Ok(Some((tau, pair)))
    }

    /// The earliest part of the step left by which pair `(i, j)` meets
    /// on the cubic paths through its beads' states now and at the
    /// step's end (Hermite's: exact where a bead's acceleration is
    /// constant), looked for up to `by`; none if it does not meet there.
    fn predict(&self, pair: (usize, usize), by: f64) -> Option<f64> {
        let h = self.left();
        let ends = |i: usize| (self.state(i, false), self.state(i, true));
        let ((a0, a1), (b0, b1)) = (ends(pair.0), ends(pair.1));
        let gap = |tau: f64| {
            let at = |s0: BeadState<V>, s1: BeadState<V>| hermite(s0, s1, h, tau);
            self.gap(pair, at(a0, a1), at(b0, b1))
        };
        // The first of 32 samples at which the gap has closed brackets
        // the meeting; regula falsi on the cubic, which costs no step,
        // finds it to the last bit (to 1e-13 of the step would be looser
        // than what Newton's first trial is to meet).
        let samples = 32;
        let mut before = (0.0, gap(0.0));
        if before.1.is_nan() || before.1 <= 0.0 {
            return Some(0.0); // in touch already
        }
        for k in 1..=samples {
            let tau = by * k as f64 / samples as f64;
            let here = gap(tau);
            if here <= 0.0 {
                let found = bracket_root(before, (tau, here), 0.0, |tau| {
                    Ok::<_, std::convert::Infallible>(gap(tau))
                });
                return found.ok();
            }
            before = (tau, here);
        }
        None
    }

    /// The least gap of `candidates` after stepping their bodies from now
    /// by `tau` (each once), its pair, and how fast that pair's gap opens
    /// there.
    fn least_gap<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        candidates: &[((usize, usize), f64, f64)],
        tau: f64,
    ) -> Result<(f64, (usize, usize), f64), SolveError> {
        self.last_trial = None;
        let mut stepped: Trial<V> = vec![None; self.bodies.len()];
        let mut least = (f64::INFINITY, (0, 0), 0.0);
        for &(pair, ..) in candidates {
            let mut state = |i: usize| -> Result<BeadState<V>, SolveError> {
                let slot = self.slot(i);
                if stepped[slot].is_none() {
                    let mut states = self.now[slot].clone();
                    bodies[self.bodies[slot]].advance(self.time, tau, &mut states)?;
                    self.tried[slot] = true;
                    stepped[slot] = Some(states);
                }
                let states = stepped[slot].as_deref().unwrap_or_default();
                Ok(states[self.beads[i].bead])
            };
            let (a, b) = (state(pair.0)?, state(pair.1)?);
            let gap = self.gap(pair, a.position, b.position);
            if gap < least.0 {
                least = (gap, pair, opening_rate(&a, &b).0);
            }
        }
        self.last_trial = Some((tau, stepped));
        Ok(least)
    }

    /// Steps every body of the group from now by `h`: to a new now (kept
    /// by each body), or to the step's end.
    fn step_all<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        h: f64,
        to_now: bool,
    ) -> Result<(), TouchError> {
        // A body the last trial stepped by just `h` (and nothing since)
        // is where this step would take it.
        let mut trial = match self.last_trial.take() {
            Some((tau, stepped)) if tau == h => stepped,
            _ => Vec::new(),
        };
        for slot in 0..self.bodies.len() {
            let body = &mut bodies[self.bodies[slot]];
            let states = match trial.get_mut(slot).and_then(Option::take) {
                Some(states) => states,
                None => {
                    let mut states = self.now[slot].clone();
                    if h > 0.0 {
                        body.advance(self.time, h, &mut states)?;
                    }
                    states
                }
            };
            self.tried[slot] = false;
            if to_now {
                body.keep();
                self.now[slot] = states;
            } else {
                self.end[slot] = states;
            }
        }
        if to_now {
            self.time += h;
        }
        Ok(())
    }

    /// Hands each body its new end, if the group was cut; a body whose
    /// last step was a trial is stepped to its end once more, so that what
    /// it reports is its end's.
    fn finish<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        pool: &mut Pool,
    ) -> Result<(), TouchError> {
        if !self.cut && !self.tried.iter().any(|&t| t) {
            return Ok(());
        }
        if self.tried.iter().any(|&t| t) {
            self.step_all(bodies, self.left(), false)?;
        }
        for (slot, &body) in self.bodies.iter().enumerate() {
            bodies[body].finish(&self.end[slot]);
        }
        // The paths the cuts gave, for the groups settled after it.
        self.trace(true);
        for (&i, &path) in self.members.iter().zip(&self.paths) {
            pool.grow(i, path);
        }
        Ok(())
    }
}

/// How close to touching, as a fraction of [`TOUCHING`] of a pair's
/// reach, Newton's trials must bring the least gap to end the search for
/// an instant of impact.
const ARRIVED: f64 = 0.01;

/// How many of Newton's trials an instant of impact is looked for with
/// before regula falsi takes over.
const NEWTON_TRIALS: usize = 4;

/// Where the cubic through `s0` and `s1`, `h` apart, with their positions
/// and velocities (Hermite's), is `tau` after `s0`.
pub(super) fn hermite<V: Coordinates>(s0: BeadState<V>, s1: BeadState<V>, h: f64, tau: f64) -> V {
    let s = tau / h;
    let (s2, s3) = (s * s, s * s * s);
    s0.position * (2.0 * s3 - 3.0 * s2 + 1.0)
        + s0.velocity * ((s3 - 2.0 * s2 + s) * h)
        + s1.position * (-2.0 * s3 + 3.0 * s2)
        + s1.velocity * ((s3 - s2) * h)
}
