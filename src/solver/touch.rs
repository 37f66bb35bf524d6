//! Beads that touch within a step: where they first meet, and the step
//! cut there, so that eq. (18)'s strikes happen at the instant of impact
//! and no bead passes through another, however fast.
//!
//! The step has been taken as if nothing touched. Then:
//!
//! 1. **Broad phase.** Each bead with a radius sweeps a box from where it
//!    started to where it ended, grown by its radius; sweep and prune on
//!    the boxes' lowest `x` finds the pairs whose boxes overlap. Beads on
//!    one wire, on different wires, free or joined: all the same.
//! 2. The bodies (islands) that such pairs join are settled together, each
//!    group of them apart from the others.
//! 3. **Where they meet.** A pair whose gap `|x_b − x_a| − (r_a + r_b)` is
//!    open where the group is now and closed at the step's end, or whose
//!    straight paths pass closer than the radii within the step (a fast
//!    pair that ends on the far side), is followed by re-stepping its two
//!    bodies from now for a part `τ` of what is left: regula falsi on `τ`
//!    brackets the gap's zero to 1e-13 of the step.
//! 4. The group is stepped to the first such instant; every pair touching
//!    there strikes ([`resolve_impacts`]), each bead answering through its
//!    body (a [`Response`]); the rest of the step is taken again from the
//!    struck state, and 3 repeats.
//!
//! A pair already touching that does not close (beads hanging side by
//! side, or moving on together after a strike at `e = 0`) is left in
//! touch.

use bevy::math::DVec3;
use thiserror::Error;

use super::contact::locate;
use super::impact::{ImpactError, Response, Strike, Touch, resolve_impacts};
use super::solve::SolveError;
use super::state::BeadState;
use crate::geometry::Coordinates;

/// Two beads whose gap is at most this fraction of their radii touch.
pub const TOUCHING: f64 = 1e-10;

/// A pair in touch closes (and strikes at once) where it closes faster
/// than this fraction of its two beads' speeds: slower is rounding.
const CLOSING: f64 = 1e-9;

/// A part of a step shorter than this fraction of the step is best taken
/// by a method whose velocity does not come from a position difference
/// over the part (RK4 with projection): RATTLE's loses the digits the
/// part is short by.
pub const SHORT_PART: f64 = 1e-3;

/// How many instants of impact one group of bodies may be cut at within
/// one step before the step is reported as not settling.
pub const MAX_IMPACTS_PER_STEP: usize = 64;

/// Something that steps a few beads together (an island): what settling
/// touches needs of it.
pub trait TouchBody<V: Coordinates> {
    /// The beads' states where the step started.
    fn start(&self) -> &[BeadState<V>];
    /// The beads' states where the step ended as taken so far.
    fn end(&self) -> &[BeadState<V>];
    /// Steps `states`, at `time`, on by `h`, from what the body kept at
    /// the last [`TouchBody::keep`] (or before the step). A part shorter
    /// than [`SHORT_PART`] of the step wants a method whose velocity does
    /// not come from a position difference.
    fn advance(&mut self, time: f64, h: f64, states: &mut [BeadState<V>])
    -> Result<(), SolveError>;
    /// Keeps what the body carries into its next step as it is now: the
    /// next [`TouchBody::advance`] starts from here.
    fn keep(&mut self);
    /// The velocity change of each of its beads per unit `impulse` on
    /// bead `bead`, at `states` and `time`.
    fn respond(
        &mut self,
        time: f64,
        states: &[BeadState<V>],
        bead: usize,
        impulse: V,
    ) -> Result<Vec<V>, SolveError>;
    /// The acceleration the applied forces give bead `bead` (its push,
    /// for the rest speed of a touching pair).
    fn push(&self, bead: usize) -> V;
    /// Takes `states` as where the step ends.
    fn finish(&mut self, states: &[BeadState<V>]);
}

/// A bead that may touch others: its body, its index there, its radius
/// and its restitution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TouchBead {
    /// The body (island) it steps in.
    pub body: usize,
    /// Its index among the body's beads.
    pub bead: usize,
    /// Its radius (positive).
    pub radius: f64,
    /// Its restitution: a pair strikes with the smaller of its two.
    pub restitution: f64,
}

/// One strike within a step: the two beads (indices into the list of
/// [`TouchBead`]s), when, and what it did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StruckPair {
    /// The first bead.
    pub a: usize,
    /// The second bead.
    pub b: usize,
    /// When it struck.
    pub time: f64,
    /// The strike: impulse along the normal from `a` to `b`, closing
    /// speed, bounce.
    pub strike: Strike,
}

/// Why the touches of a step could not be settled, in words.
#[derive(Clone, Copy, Debug, Error, PartialEq)]
pub enum TouchError {
    /// A body's step failed while the step was cut.
    #[error("{0}")]
    Solve(#[from] SolveError),
    /// The strikes failed.
    #[error("{0}")]
    Impact(#[from] ImpactError),
    /// A group met more instants of impact within one step than allowed.
    #[error(
        "beads {a} and {b} were still striking after {MAX_IMPACTS_PER_STEP} instants of impact within one step"
    )]
    TooManyImpacts {
        /// The first bead of the last pair.
        a: usize,
        /// The second bead of the last pair.
        b: usize,
    },
    /// A bead names a body or a bead of a body that is not there.
    #[error("touching bead {bead} names a body or a bead that is not there")]
    Missing {
        /// The bead.
        bead: usize,
    },
}

/// The step `[time, time + dt]` the bodies were stepped over.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSpan {
    /// When it starts.
    pub time: f64,
    /// How long it is.
    pub dt: f64,
}

/// Settles the touches of one step (see the module's documentation):
/// `bodies` were stepped over `span` as if nothing touched; where beads in
/// `beads` met within it, the step is cut and the strikes made, and each
/// body that took part is [`finish`](TouchBody::finish)ed at its new end.
/// Each strike is appended to `struck`.
pub fn settle_touches<V: Coordinates, B: TouchBody<V>>(
    span: StepSpan,
    bodies: &mut [B],
    beads: &[TouchBead],
    struck: &mut Vec<StruckPair>,
) -> Result<(), TouchError> {
    for (i, bead) in beads.iter().enumerate() {
        let known = bodies
            .get(bead.body)
            .is_some_and(|b| bead.bead < b.start().len().min(b.end().len()));
        if !known {
            return Err(TouchError::Missing { bead: i });
        }
    }
    let boxes: Vec<(DVec3, DVec3)> = beads
        .iter()
        .map(|t| {
            let body = &bodies[t.body];
            swept(
                t,
                body.start()[t.bead].position,
                body.end()[t.bead].position,
            )
        })
        .collect();
    let pairs = overlapping(&boxes);
    let found = groups(beads, bodies.len(), &pairs);
    let mut pool = Pool {
        boxes,
        group_of: vec![usize::MAX; bodies.len()],
        free: vec![true; bodies.len()],
        groups: found,
    };
    for (g, group) in pool.groups.iter().enumerate() {
        for &body in group {
            pool.group_of[body] = g;
        }
    }
    for g in 0..pool.groups.len() {
        let Some(first) = pool.groups[g].first() else {
            continue;
        };
        if !pool.free[*first] {
            continue; // taken in by a group settled before it
        }
        let group = pool.take(g);
        Group::new(span, bodies, beads, group).settle(bodies, &mut pool, struck)?;
    }
    Ok(())
}

/// The box bead `t` sweeps between `from` and `to`, grown by its radius
/// and what counts as touching.
fn swept<V: Coordinates>(t: &TouchBead, from: V, to: V) -> (DVec3, DVec3) {
    let (a, b) = (from.xyz(), to.xyz());
    let grown = t.radius * (1.0 + 4.0 * TOUCHING);
    (a.min(b) - grown, a.max(b) + grown)
}

/// The bodies not yet settled this step, in the groups the broad phase
/// first put them in, and each bead's box from the step's start to its
/// end.
struct Pool {
    boxes: Vec<(DVec3, DVec3)>,
    group_of: Vec<usize>,
    free: Vec<bool>,
    groups: Vec<Vec<usize>>,
}

impl Pool {
    /// Takes the free bodies of group `g`.
    fn take(&mut self, g: usize) -> Vec<usize> {
        let bodies: Vec<usize> = self.groups[g]
            .iter()
            .copied()
            .filter(|&b| self.free[b])
            .collect();
        for &b in &bodies {
            self.free[b] = false;
        }
        bodies
    }
}

/// The pairs of boxes `(lowest, highest corner)` that overlap, by sweep
/// and prune along `x`, each as `(i, j)` with `i < j`.
pub fn overlapping(boxes: &[(DVec3, DVec3)]) -> Vec<(usize, usize)> {
    let mut order: Vec<usize> = (0..boxes.len()).collect();
    order.sort_by(|&i, &j| boxes[i].0.x.total_cmp(&boxes[j].0.x));
    let mut open: Vec<usize> = Vec::new();
    let mut pairs = Vec::new();
    for &i in &order {
        let (low, high) = boxes[i];
        open.retain(|&j| boxes[j].1.x >= low.x);
        for &j in &open {
            let (other_low, other_high) = boxes[j];
            if low.cmple(other_high).all() && other_low.cmple(high).all() {
                pairs.push((i.min(j), i.max(j)));
            }
        }
        open.push(i);
    }
    pairs.sort_unstable();
    pairs
}

/// The bodies the pairs join, grouped (union–find), in the order of
/// their first pair.
fn groups(beads: &[TouchBead], bodies: usize, pairs: &[(usize, usize)]) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..bodies).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for &(i, j) in pairs {
        let (a, b) = (
            root(&mut parent, beads[i].body),
            root(&mut parent, beads[j].body),
        );
        parent[a.max(b)] = a.min(b);
    }
    let mut found: Vec<(usize, Vec<usize>)> = Vec::new();
    for &(i, j) in pairs {
        let r = root(&mut parent, beads[i].body);
        let at = match found.iter().position(|g| g.0 == r) {
            Some(at) => at,
            None => {
                found.push((r, Vec::new()));
                found.len() - 1
            }
        };
        for body in [beads[i].body, beads[j].body] {
            if !found[at].1.contains(&body) {
                found[at].1.push(body);
            }
        }
    }
    found.into_iter().map(|(_, b)| b).collect()
}

/// A bead (its index) with the box it sweeps.
type Boxed = (usize, (DVec3, DVec3));

/// One group of bodies being settled: where each is now and where its
/// step ends from there.
struct Group<'a, V: Coordinates> {
    span: StepSpan,
    beads: &'a [TouchBead],
    bodies: Vec<usize>,
    /// The beads (indices into `beads`) of the group's bodies.
    members: Vec<usize>,
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
}

impl<'a, V: Coordinates> Group<'a, V> {
    fn new<B: TouchBody<V>>(
        span: StepSpan,
        all: &[B],
        beads: &'a [TouchBead],
        bodies: Vec<usize>,
    ) -> Self {
        let now = bodies.iter().map(|&b| all[b].start().to_vec()).collect();
        let end = bodies.iter().map(|&b| all[b].end().to_vec()).collect();
        let tried = vec![false; bodies.len()];
        let members = (0..beads.len())
            .filter(|&i| bodies.contains(&beads[i].body))
            .collect();
        let mut group = Self {
            span,
            beads,
            bodies,
            members,
            pairs: Vec::new(),
            time: span.time,
            now,
            end,
            tried,
            cut: false,
        };
        group.pairs = group.find_pairs(&[]).0;
        group
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

    /// Takes into the group the bodies not yet settled whose beads' boxes
    /// meet its beads' boxes from now on (with the rest of the group the
    /// broad phase first put them in), each stepped to now; then finds
    /// the group's pairs again.
    fn absorb<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        pool: &mut Pool,
    ) -> Result<(), SolveError> {
        // Only the beads whose boxes meet the box about the whole group's.
        let (low, high) = self.members.iter().map(|&i| self.swept(i)).fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(low, high), (a, b)| (low.min(a), high.max(b)),
        );
        let outside: Vec<Boxed> = (0..self.beads.len())
            .filter(|&j| pool.free[self.beads[j].body])
            .map(|j| (j, pool.boxes[j]))
            .filter(|(_, (a, b))| a.cmple(high).all() && low.cmple(*b).all())
            .collect();
        let (_, met) = self.find_pairs(&outside);
        for j in met {
            let body = self.beads[j].body;
            if !pool.free[body] {
                continue;
            }
            let taken = match pool.group_of[body] {
                usize::MAX => {
                    pool.free[body] = false;
                    vec![body]
                }
                g => pool.take(g),
            };
            for body in taken {
                let mut now = bodies[body].start().to_vec();
                let since = self.time - self.span.time;
                if since > 0.0 {
                    bodies[body].advance(self.span.time, since, &mut now)?;
                    bodies[body].keep();
                }
                let mut end = now.clone();
                bodies[body].advance(self.time, self.left(), &mut end)?;
                self.bodies.push(body);
                self.now.push(now);
                self.end.push(end);
                self.tried.push(false);
                self.members
                    .extend((0..self.beads.len()).filter(|&i| self.beads[i].body == body));
            }
        }
        self.pairs = self.find_pairs(&[]).0;
        Ok(())
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
        let d = xb - xa;
        d.dot(d).sqrt() - (self.beads[i].radius + self.beads[j].radius)
    }

    /// How far the group's end is from now.
    fn left(&self) -> f64 {
        self.span.time + self.span.dt - self.time
    }

    /// Cuts the step at each instant of impact in turn, then finishes the
    /// bodies it cut.
    fn settle<B: TouchBody<V>>(
        mut self,
        bodies: &mut [B],
        pool: &mut Pool,
        struck: &mut Vec<StruckPair>,
    ) -> Result<(), TouchError> {
        let mut last = (0, 0);
        for _ in 0..MAX_IMPACTS_PER_STEP {
            let Some((tau, pair)) = self.first_meeting(bodies)? else {
                return self.finish(bodies);
            };
            last = pair;
            self.cut = true;
            self.step_all(bodies, tau, true)?;
            self.strike(bodies, struck)?;
            self.step_all(bodies, self.left(), false)?;
            self.absorb(bodies, pool)?;
        }
        Err(TouchError::TooManyImpacts {
            a: last.0,
            b: last.1,
        })
    }

    /// The first instant (from now) a pair that is apart meets, and the
    /// pair; none if no pair meets before the step's end.
    fn first_meeting<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
    ) -> Result<Option<(f64, (usize, usize))>, TouchError> {
        let h = self.left();
        let mut first: Option<(f64, (usize, usize))> = None;
        for k in 0..self.pairs.len() {
            let pair = self.pairs[k];
            let (a0, b0) = (self.state(pair.0, false), self.state(pair.1, false));
            let (a1, b1) = (self.state(pair.0, true), self.state(pair.1, true));
            let r = self.beads[pair.0].radius + self.beads[pair.1].radius;
            let g0 = self.gap(pair, a0.position, b0.position);
            if g0 <= TOUCHING * r {
                // In touch: struck now if it closes, else left resting.
                let n = b0.position - a0.position;
                let u = n.dot(b0.velocity - a0.velocity) / n.dot(n).sqrt();
                let speeds =
                    a0.velocity.dot(a0.velocity).sqrt() + b0.velocity.dot(b0.velocity).sqrt();
                if -u > CLOSING * speeds {
                    return Ok(Some((0.0, pair)));
                }
                continue;
            }
            if h <= 0.0 {
                continue;
            }
            let within = first.map_or(h, |(tau, _)| tau);
            let Some(bracket) = self.bracket(bodies, pair, [a0, b0, a1, b1], h)? else {
                continue;
            };
            if bracket > within {
                // Meets, but after a pair already found: still look for
                // the instant if it may come first.
                let trial = self.trial_gap(bodies, pair, within)?;
                if trial > 0.0 {
                    continue;
                }
            }
            let hi = bracket.min(within);
            let tau = locate(hi, g0, |tau| self.trial_gap(bodies, pair, tau))?;
            if first.is_none_or(|(t, _)| tau < t) {
                first = Some((tau, pair));
            }
        }
        Ok(first)
    }

    /// A part `τ ≤ h` at whose end the pair's gap is closed, if it meets:
    /// `h` where it ends closed, else the instant its straight paths come
    /// closest, where they come closer than the radii and the bodies'
    /// own paths close the gap there too.
    fn bracket<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        pair: (usize, usize),
        [a0, b0, a1, b1]: [BeadState<V>; 4],
        h: f64,
    ) -> Result<Option<f64>, TouchError> {
        if self.gap(pair, a1.position, b1.position) <= 0.0 {
            return Ok(Some(h));
        }
        let d0 = b0.position - a0.position;
        let change = (b1.position - a1.position) - d0;
        let length = change.dot(change);
        if length.is_nan() || length <= 0.0 {
            return Ok(None);
        }
        let s = (-d0.dot(change) / length).clamp(0.0, 1.0);
        let closest = d0 + change * s;
        let r = self.beads[pair.0].radius + self.beads[pair.1].radius;
        if s <= 0.0 || s >= 1.0 || closest.dot(closest).sqrt() >= r {
            return Ok(None);
        }
        let tau = s * h;
        Ok((self.trial_gap(bodies, pair, tau)? <= 0.0).then_some(tau))
    }

    /// The pair's gap after stepping its bodies from now by `tau`.
    fn trial_gap<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        pair: (usize, usize),
        tau: f64,
    ) -> Result<f64, SolveError> {
        let (sa, sb) = (self.slot(pair.0), self.slot(pair.1));
        let mut xa = self.now[sa].clone();
        bodies[self.bodies[sa]].advance(self.time, tau, &mut xa)?;
        self.tried[sa] = true;
        let pa = xa[self.beads[pair.0].bead].position;
        let pb = if sb == sa {
            xa[self.beads[pair.1].bead].position
        } else {
            let mut xb = self.now[sb].clone();
            bodies[self.bodies[sb]].advance(self.time, tau, &mut xb)?;
            self.tried[sb] = true;
            xb[self.beads[pair.1].bead].position
        };
        Ok(self.gap(pair, pa, pb))
    }

    /// Steps every body of the group from now by `h`: to a new now (kept
    /// by each body), or to the step's end.
    fn step_all<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        h: f64,
        to_now: bool,
    ) -> Result<(), TouchError> {
        for slot in 0..self.bodies.len() {
            let body = &mut bodies[self.bodies[slot]];
            let mut states = self.now[slot].clone();
            if h > 0.0 {
                body.advance(self.time, h, &mut states)?;
            }
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

    /// Strikes every pair touching now (eq. 18, pair by pair).
    fn strike<B: TouchBody<V>>(
        &mut self,
        bodies: &mut [B],
        struck: &mut Vec<StruckPair>,
    ) -> Result<(), TouchError> {
        // The group's velocities side by side, each body's from its offset.
        let mut offsets = Vec::with_capacity(self.bodies.len());
        let mut velocities = Vec::new();
        for states in &self.now {
            offsets.push(velocities.len());
            velocities.extend(states.iter().map(|s| s.velocity));
        }
        let flat = |group: &Self, i: usize| offsets[group.slot(i)] + group.beads[i].bead;
        let mut touches = Vec::new();
        let mut responses = Vec::new();
        let mut named = Vec::new();
        for &pair in &self.pairs {
            let (a, b) = (self.state(pair.0, false), self.state(pair.1, false));
            let (ta, tb) = (self.beads[pair.0], self.beads[pair.1]);
            let r = ta.radius + tb.radius;
            if self.gap(pair, a.position, b.position) > TOUCHING * r {
                continue;
            }
            let (fa, fb) = (flat(self, pair.0), flat(self, pair.1));
            let e = ta.restitution.min(tb.restitution);
            let touch =
                Touch::between((fa, a.position, ta.radius), (fb, b.position, tb.radius), e)?;
            let n = touch.normal();
            let (sa, sb) = (self.slot(pair.0), self.slot(pair.1));
            let push =
                bodies[self.bodies[sb]].push(tb.bead) - bodies[self.bodies[sa]].push(ta.bead);
            let touch = touch.resting_below(n.dot(push).abs() * self.span.dt);
            let mut changes = Vec::new();
            for (slot, bead, sign) in [(sa, ta.bead, -1.0), (sb, tb.bead, 1.0)] {
                let answer = bodies[self.bodies[slot]].respond(
                    self.time,
                    &self.now[slot],
                    bead,
                    n * sign,
                )?;
                changes.extend(
                    answer
                        .into_iter()
                        .enumerate()
                        .map(|(k, dv)| (offsets[slot] + k, dv)),
                );
            }
            responses.push(Response::new(&touch, changes));
            touches.push(touch);
            named.push(pair);
        }
        let mut strikes = Vec::new();
        resolve_impacts(&touches, &responses, &mut velocities, &mut strikes)?;
        for strike in strikes {
            let (a, b) = named[strike.touch];
            struck.push(StruckPair {
                a,
                b,
                time: self.time,
                strike,
            });
        }
        for (states, &offset) in self.now.iter_mut().zip(&offsets) {
            for (k, state) in states.iter_mut().enumerate() {
                state.velocity = velocities[offset + k];
            }
        }
        Ok(())
    }

    /// Hands each body its new end, if the group was cut; a body whose
    /// last step was a trial is stepped to its end once more, so that what
    /// it reports is its end's.
    fn finish<B: TouchBody<V>>(mut self, bodies: &mut [B]) -> Result<(), TouchError> {
        if !self.cut && !self.tried.iter().any(|&t| t) {
            return Ok(());
        }
        if self.tried.iter().any(|&t| t) {
            self.step_all(bodies, self.left(), false)?;
        }
        for (slot, &body) in self.bodies.iter().enumerate() {
            bodies[body].finish(&self.end[slot]);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::{DVec2, DVec3};

    use super::*;

    /// Free beads of unit mass coasting at constant velocity: exact, so
    /// that where they meet is known in closed form.
    struct Coasting {
        start: Vec<BeadState>,
        end: Vec<BeadState>,
        steps: usize,
    }

    impl Coasting {
        fn new(states: &[(f64, f64)], dt: f64) -> Self {
            let start: Vec<BeadState> = states
                .iter()
                .map(|&(x, v)| BeadState {
                    position: DVec2::new(x, 0.0),
                    velocity: DVec2::new(v, 0.0),
                })
                .collect();
            let mut end = start.clone();
            for s in &mut end {
                s.position += s.velocity * dt;
            }
            Self {
                start,
                end,
                steps: 0,
            }
        }
    }

    impl TouchBody<DVec2> for Coasting {
        fn start(&self) -> &[BeadState] {
            &self.start
        }
        fn end(&self) -> &[BeadState] {
            &self.end
        }
        fn advance(&mut self, _: f64, h: f64, states: &mut [BeadState]) -> Result<(), SolveError> {
            self.steps += 1;
            for s in states {
                s.position += s.velocity * h;
            }
            Ok(())
        }
        fn keep(&mut self) {}
        fn respond(
            &mut self,
            _: f64,
            states: &[BeadState],
            bead: usize,
            impulse: DVec2,
        ) -> Result<Vec<DVec2>, SolveError> {
            let mut answer = vec![DVec2::ZERO; states.len()];
            answer[bead] = impulse;
            Ok(answer)
        }
        fn push(&self, _: usize) -> DVec2 {
            DVec2::ZERO
        }
        fn finish(&mut self, states: &[BeadState]) {
            self.end = states.to_vec();
        }
    }

    fn beads(bodies: usize, radius: f64) -> Vec<TouchBead> {
        (0..bodies)
            .map(|body| TouchBead {
                body,
                bead: 0,
                radius,
                restitution: 1.0,
            })
            .collect()
    }

    /// Two equal beads that would pass right through each other within one
    /// step meet at the instant their gap closes and exchange velocities:
    /// their ends are the exact ones to 1e-12.
    #[test]
    fn a_pair_that_would_pass_through_in_one_step_meets_and_exchanges() {
        let dt = 0.1;
        // Gap 0.4 closing at 12 m/s: they meet at 1/30 s, and would be
        // 0.8 past each other at the step's end.
        let mut bodies = vec![
            Coasting::new(&[(0.0, 6.0)], dt),
            Coasting::new(&[(0.5, -6.0)], dt),
        ];
        let span = StepSpan { time: 2.0, dt };
        let mut struck = Vec::new();
        settle_touches(span, &mut bodies, &beads(2, 0.05), &mut struck).expect("settles");
        assert_eq!(struck.len(), 1, "{struck:?}");
        let meet = 0.4 / 12.0;
        assert!(
            (struck[0].time - (2.0 + meet)).abs() <= 1e-12,
            "{}",
            struck[0].time
        );
        let (a, b) = (bodies[0].end[0], bodies[1].end[0]);
        let xa = 6.0 * meet - 6.0 * (dt - meet);
        let xb = 0.5 - 6.0 * meet + 6.0 * (dt - meet);
        assert!(
            (a.position.x - xa).abs() <= 1e-12,
            "{} against {xa}",
            a.position.x
        );
        assert!(
            (b.position.x - xb).abs() <= 1e-12,
            "{} against {xb}",
            b.position.x
        );
        assert!((a.velocity.x + 6.0).abs() <= 1e-12 && (b.velocity.x - 6.0).abs() <= 1e-12);
    }

    /// Five equal balls, four touching at rest and one coming in: exactly
    /// one leaves, at the speed that came in, and the rest stay touching
    /// at rest.
    #[test]
    fn one_ball_into_a_touching_row_sends_out_one() {
        let (dt, r, v) = (0.01, 0.05, 3.0);
        let mut bodies = vec![Coasting::new(&[(-0.02, v)], dt)];
        for k in 1..5 {
            bodies.push(Coasting::new(&[(0.1 * k as f64, 0.0)], dt));
        }
        let mut struck = Vec::new();
        let span = StepSpan { time: 0.0, dt };
        settle_touches(span, &mut bodies, &beads(5, r), &mut struck).expect("settles");
        assert_eq!(struck.len(), 4, "one strike down the row: {struck:?}");
        for (k, body) in bodies.iter().enumerate() {
            let expected = if k == 4 { v } else { 0.0 };
            assert!(
                (body.end[0].velocity.x - expected).abs() <= 1e-12,
                "ball {k}"
            );
        }
        assert!((bodies[0].end[0].position.x - 0.0).abs() <= 1e-12);
    }

    /// A pair that starts touching and closing strikes at once; pairs that
    /// are apart and never meet, or touch without closing, cost no step.
    #[test]
    fn a_closing_pair_in_touch_strikes_at_once_and_pairs_that_never_meet_are_left() {
        let dt = 0.01;
        let mut bodies = vec![
            Coasting::new(&[(0.0, 1.0)], dt),
            Coasting::new(&[(0.1, 0.0)], dt),
        ];
        let mut struck = Vec::new();
        let span = StepSpan { time: 0.0, dt };
        settle_touches(span, &mut bodies, &beads(2, 0.05), &mut struck).expect("settles");
        assert_eq!(struck.len(), 1);
        assert_eq!(struck[0].time, 0.0);
        assert!((bodies[1].end[0].position.x - (0.1 + dt)).abs() <= 1e-15);

        let mut apart = vec![
            Coasting::new(&[(0.0, 0.0)], dt),
            Coasting::new(&[(0.1, 1.0)], dt),
            Coasting::new(&[(5.0, 1.0)], dt),
        ];
        struck.clear();
        settle_touches(span, &mut apart, &beads(3, 0.05), &mut struck).expect("settles");
        assert!(struck.is_empty());
        assert!(apart.iter().all(|b| b.steps == 0), "no pair needed a step");
    }

    #[test]
    fn a_bead_naming_a_missing_body_is_refused_in_words() {
        let mut bodies = vec![Coasting::new(&[(0.0, 0.0)], 0.01)];
        let err = settle_touches(
            StepSpan {
                time: 0.0,
                dt: 0.01,
            },
            &mut bodies,
            &beads(2, 0.1),
            &mut Vec::new(),
        )
        .unwrap_err();
        assert_eq!(
            err.to_string(),
            "touching bead 1 names a body or a bead that is not there"
        );
    }

    proptest::proptest! {
        /// Sweep and prune finds exactly the overlapping pairs that
        /// testing every pair finds.
        #[test]
        fn sweep_and_prune_finds_every_overlapping_pair(
            boxes in proptest::collection::vec(
                ((-5.0..5.0f64, -5.0..5.0f64, -5.0..5.0f64), (0.0..2.0f64, 0.0..2.0f64, 0.0..2.0f64)),
                0..40,
            ),
        ) {
            let boxes: Vec<(DVec3, DVec3)> = boxes
                .into_iter()
                .map(|((x, y, z), (w, h, d))| {
                    let low = DVec3::new(x, y, z);
                    (low, low + DVec3::new(w, h, d))
                })
                .collect();
            let mut every = Vec::new();
            for i in 0..boxes.len() {
                for j in i + 1..boxes.len() {
                    let (a, b) = (boxes[i], boxes[j]);
                    if a.0.cmple(b.1).all() && b.0.cmple(a.1).all() {
                        every.push((i, j));
                    }
                }
            }
            proptest::prop_assert_eq!(overlapping(&boxes), every);
        }
    }
}
