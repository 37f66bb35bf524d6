//! Beads that touch within a step: where they first meet, and the step
//! cut there, so that eq. (18)'s strikes happen at the instant of impact
//! and no bead passes through another, however fast.
//!
//! The step has been taken as if nothing touched. Then:
//!
//! 1. **Broad phase.** Each bead with a radius sweeps a box from where it
//!    started to where it ended, grown by its radius; a grid of cells
//!    about two boxes wide finds the pairs whose boxes overlap
//!    ([`overlapping`]). Beads on one wire, on different wires, free or
//!    joined: all the same.
//! 2. The bodies (islands) that such pairs join are settled together, each
//!    group of them apart from the others.
//! 3. **Where they meet.** A pair whose gap `|x_b − x_a| − (r_a + r_b)` is
//!    open where the group is now and closed at the step's end, or whose
//!    straight paths pass closer than the radii within the step (a fast
//!    pair that ends on the far side), is followed by re-stepping its two
//!    bodies from now for a part `τ` of what is left: regula falsi on `τ`
//!    brackets the gap's zero to 1e-13 of the step.
//! 4. The group is stepped to the first such instant; every pair touching
//!    there strikes ([`resolve_impacts`](crate::solver::resolve_impacts)),
//!    each bead answering through its body (a
//!    [`Response`](crate::solver::Response)); the rest of the step is taken
//!    again from the struck state, and 3 repeats.
//! 5. Where a strike sends a bead of the group to meet beads of bodies
//!    outside it (not yet settled, or settled with another group), the
//!    group and those bodies (with the groups they were settled with) are
//!    settled again as one from the step's start
//!    ([`TouchBody::restart`]), so that what those bodies met before the
//!    instant is settled too.
//!
//! A pair already touching that does not close (beads hanging side by
//! side, or moving on together after a strike at `e = 0`) is left in
//! touch. Where a body joins the pair by a contact row (an island's
//! [`set_contact`](crate::solver::Island::set_contact)), a strike that
//! leaves the pair in touch holds the row, so that the pair pressed
//! together for the rest of the step stays apart; a bounce sets it aside.
//! A pair left in touch that the rest of the step presses into each
//! other is held there too, at the instant it touches. A held pair does
//! not strike: its body answers a strike on either bead with the row
//! held, so beads pressed together take a blow as one. Pairs at `e = 0`
//! that a contact row joins are struck all at once (their rows held and
//! the body's velocities projected onto them, [`TouchBody::press`]), so
//! that a pile does not trade ever smaller strikes pair by pair.
//!
//! A pair at `e = 0` joined by a contact row that meets no faster than
//! one whole step's forces move its two beads (`|f| / m` times the step,
//! each) is not struck at its instant: its body's step holds the row
//! where the pair would end overlapping, so that it ends the step in
//! touch, with no strike to report (a plastic impact within the step,
//! as a time-stepping scheme takes every contact). Momentum is kept and
//! `½ μ v²` lost as by the strike; where the pair ends is at most its
//! closing speed times the step from where the strike at its instant
//! would leave it. A pile settling in a bowl meets countless times at
//! such speeds (inelastic collapse), where cutting the step at each
//! meeting would not end. So, for the same reason, is a pair at `e = 0`
//! that meets within [`NEAR_MEETING`] (1/16) of the step's start, however
//! fast: in a pile each strike passes its momentum on to neighbours a
//! hair away, hundreds of meetings a step. Its row is held from the
//! step's start, so the plastic impact acts over the `gap / v` before the
//! pair meets as well: for two free beads on a line that is exactly the
//! impact at its instant (the centre of mass moves as it would, and the
//! pair ends in touch at the momentum's velocity); elsewhere the two
//! differ by what the contact's force does over at most a sixteenth of
//! the step.
//!
//! | file | what it holds |
//! |---|---|
//! | `mod` | [`TouchBody`], [`TouchBead`], [`settle_touches`] and the groups the broad phase finds |
//! | `broad` | the broad phase ([`overlapping`]): which boxes overlap, by a grid |
//! | `group` | one group settled: where its pairs meet, the steps to and from each instant, the strikes, the bodies it meets |
//! | `obstacle` | beads that meet the bodies of a physics engine ([`meet_obstacles`]): where, the strikes, resting contact |
//! | `pool` | the bodies of a step's settlement: which are settled, each bead's box, how a group's settlement ended |

use bevy::math::DVec3;
use thiserror::Error;

use super::coupled::{islands, opening_rate, pair_gap, pair_speeds, parts};
use super::impact::{ImpactError, Strike};
use super::solve::{SolveError, singular};
use super::state::BeadState;
use super::wire_normal::{along, usable};
use crate::geometry::Coordinates;

mod broad;
mod group;
mod obstacle;
mod pool;
#[cfg(test)]
mod tests;

pub(crate) use broad::overlapping;
use group::Group;
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
pub(crate) use obstacle::{BodyPoint, Nearest};
pub(crate) use obstacle::{
    BodyPush, MeetsObstacles, Obstacle, ObstaclePair, ObstacleStrike, meet_obstacles,
};
use pool::{Pool, Settled};

pub(crate) use super::coupled::TOUCHING;

/// How many instants of impact one group of bodies may be cut at within
/// one step, per pair of beads it follows (a pile meets many), before
/// the step is reported as not settling.
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
    /// than a thousandth of the step wants a
    /// method whose velocity does not come from a position difference
    /// ([`StepSettings::part`](crate::solver::StepSettings::part)).
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
    /// Takes what the body carries into its steps back to where the step
    /// began: the next [`TouchBody::advance`] starts from there. A body
    /// that keeps nothing between its steps has nothing to do.
    fn rewind(&mut self) {}
    /// Whether a contact row of the body joins its beads `a` and `b`
    /// (see [`Island::set_contact`](crate::solver::Island::set_contact)),
    /// and if so whether it holds them in the steps from the last
    /// [`TouchBody::keep`]; none where no row joins them (the body cannot
    /// hold them in touch, and they strike only).
    fn contact(&self, a: usize, b: usize) -> Option<bool> {
        let _ = (a, b);
        None
    }
    /// Its beads' velocities at `states` and `time` projected onto what
    /// holds them in the steps from the last [`TouchBody::keep`], its held
    /// contacts included (see [`Island::press`](crate::solver::Island::press)):
    /// an inelastic strike of every held pair at once, with each held
    /// pair's impulse `(a, b, p)` (N s, pushing positive). None where the
    /// body has no contact rows.
    fn press(
        &mut self,
        time: f64,
        states: &[BeadState<V>],
    ) -> Result<Option<Pressed<V>>, SolveError> {
        let _ = (time, states);
        Ok(None)
    }
    /// Whether the body takes the meetings of its beads at `e = 0` that a
    /// contact row joins by time-stepping (see
    /// [`Island::time_steps`](crate::solver::Island)): such a pair in touch
    /// that closes is its step's to hold, not struck at its instant.
    fn time_steps(&self) -> bool {
        false
    }
    /// Whether the body's step, as taken so far, ends holding a contact
    /// row between its beads `a` and `b` that it time-steps
    /// ([`TouchBody::time_steps`]): the pair ends pressed together as the
    /// step's complementarity problem left it (overlapping by no more than
    /// the row's compliance lets a push), which is that step's meeting,
    /// not one to locate.
    fn ends_held(&self, a: usize, b: usize) -> bool {
        let _ = (a, b);
        false
    }
    /// Holds the contact between beads `a` and `b` in the steps from the
    /// last [`TouchBody::keep`] (a strike left them in touch), or sets it
    /// aside (they bounced or part). A body without the row ignores it.
    fn hold(&mut self, a: usize, b: usize, held: bool) {
        let _ = (a, b, held);
    }
    /// Takes the body back to where the step `[time, time + dt]` began,
    /// its end to the step from there as if nothing touched: its beads
    /// are settled again with a group whose bead came to meet them. The
    /// default steps from [`TouchBody::start`], for a body that keeps
    /// nothing between its steps.
    fn restart(&mut self, time: f64, dt: f64) -> Result<(), SolveError> {
        let mut states = self.start().to_vec();
        self.advance(time, dt, &mut states)?;
        self.finish(&states);
        Ok(())
    }
}

/// A body borrowed: bodies of different kinds settle together as
/// `&mut dyn TouchBody<V>`.
impl<V: Coordinates, T: TouchBody<V> + ?Sized> TouchBody<V> for &mut T {
    fn start(&self) -> &[BeadState<V>] {
        (**self).start()
    }
    fn end(&self) -> &[BeadState<V>] {
        (**self).end()
    }
    fn advance(
        &mut self,
        time: f64,
        h: f64,
        states: &mut [BeadState<V>],
    ) -> Result<(), SolveError> {
        (**self).advance(time, h, states)
    }
    fn keep(&mut self) {
        (**self).keep();
    }
    fn respond(
        &mut self,
        time: f64,
        states: &[BeadState<V>],
        bead: usize,
        impulse: V,
    ) -> Result<Vec<V>, SolveError> {
        (**self).respond(time, states, bead, impulse)
    }
    fn push(&self, bead: usize) -> V {
        (**self).push(bead)
    }
    fn finish(&mut self, states: &[BeadState<V>]) {
        (**self).finish(states);
    }
    fn rewind(&mut self) {
        (**self).rewind();
    }
    fn contact(&self, a: usize, b: usize) -> Option<bool> {
        (**self).contact(a, b)
    }
    fn press(
        &mut self,
        time: f64,
        states: &[BeadState<V>],
    ) -> Result<Option<Pressed<V>>, SolveError> {
        (**self).press(time, states)
    }
    fn time_steps(&self) -> bool {
        (**self).time_steps()
    }
    fn ends_held(&self, a: usize, b: usize) -> bool {
        (**self).ends_held(a, b)
    }
    fn hold(&mut self, a: usize, b: usize, held: bool) {
        (**self).hold(a, b, held);
    }
    fn restart(&mut self, time: f64, dt: f64) -> Result<(), SolveError> {
        (**self).restart(time, dt)
    }
}

/// What a body's beads do when its held contacts are pressed at once
/// ([`TouchBody::press`]): their velocities, and each held pair's impulse
/// `(a, b, p)`.
pub type Pressed<V> = (Vec<V>, Vec<(usize, usize, f64)>);

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
    /// Its Coulomb friction `μ` against another bead: a pair rubs with
    /// the smaller of its two (see [`rub`](crate::solver::rub)).
    pub friction: f64,
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
        "beads {a} and {b} were still striking after {instants} instants of impact within one step"
    )]
    TooManyImpacts {
        /// The first bead of the last pair.
        a: usize,
        /// The second bead of the last pair.
        b: usize,
        /// How many instants the group was cut at.
        instants: usize,
    },
    /// A body's beads met the bodies of the world at more instants within
    /// one step than allowed.
    #[error(
        "bead {bead} and the bodies it meets were still striking after {instants} instants of impact within one step"
    )]
    ObstacleStrikes {
        /// The bead of the first pair.
        bead: usize,
        /// How many instants the step was cut at.
        instants: usize,
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
/// Each strike is appended to `struck`. `near` is set to the pairs of
/// `beads` (each `(i, j)`, `i < j`, in order) whose boxes as the
/// settlement leaves them overlap: each box takes in its bead's path
/// through the step, as settled, grown by its radius, so that every pair
/// whose beads end the step in touch is among them.
pub fn settle_touches<V: Coordinates, B: TouchBody<V>>(
    span: StepSpan,
    bodies: &mut [B],
    beads: &[TouchBead],
    (struck, near): (&mut Vec<StruckPair>, &mut Vec<(usize, usize)>),
) -> Result<(), TouchError> {
    near.clear();
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
    let mut pool = Pool::new(boxes, beads, bodies.len(), (pairs, found));
    // Which settlement each body was settled in, and each settlement's
    // bodies.
    let mut settled_in = vec![usize::MAX; bodies.len()];
    let mut settlements: Vec<Vec<usize>> = Vec::new();
    for g in 0..pool.groups.len() {
        let Some(first) = pool.groups[g].first() else {
            continue;
        };
        if !pool.free[*first] {
            continue; // taken in by a group settled before it
        }
        let mut group = pool.take(g);
        // Its bodies stand where the broad phase found them until a strike
        // sends them to be settled again.
        let mut found_here = true;
        loop {
            let group_now = Group::new(span, (bodies, beads), group, (&pool, found_here));
            match group_now.settle(bodies, &mut pool, struck)? {
                Settled::Done(done) => {
                    for &body in &done {
                        settled_in[body] = settlements.len();
                    }
                    settlements.push(done);
                    break;
                }
                // A bead of the group came to meet bodies outside it: all
                // are settled again as one, from the step's start (those
                // settled before with their groups).
                Settled::Met(mine, met) => {
                    let mut again = mine;
                    for body in met.settled {
                        if !again.contains(&body) {
                            again.append(&mut settlements[settled_in[body]]);
                        }
                    }
                    for &body in &again {
                        bodies[body].restart(span.time, span.dt)?;
                    }
                    struck.retain(|p| {
                        !again.contains(&beads[p.a].body) && !again.contains(&beads[p.b].body)
                    });
                    again.extend(met.free);
                    group = again;
                    found_here = false;
                }
            }
        }
    }
    pool.overlapping_now(near);
    Ok(())
}

/// The box bead `t` sweeps between `from` and `to`, grown by its radius
/// and what counts as touching.
pub(crate) fn swept<V: Coordinates>(t: &TouchBead, from: V, to: V) -> (DVec3, DVec3) {
    let (a, b) = (from.xyz(), to.xyz());
    let grown = t.radius * (1.0 + 4.0 * TOUCHING);
    (a.min(b) - grown, a.max(b) + grown)
}

/// The pairs of beads, each `(state, radius)`, that may come to touch
/// within `within` seconds: those whose boxes overlap, each grown by its
/// radius, a `margin` fraction more, and along each axis twice the way its
/// velocity takes it in `within` ([`overlapping`]). An island builder
/// joins such pairs by contact rows before they meet (see
/// [`Island::set_contact`](crate::solver::Island::set_contact)).
pub(crate) fn may_touch<V: Coordinates>(
    beads: &[(BeadState<V>, f64)],
    within: f64,
    margin: f64,
) -> Vec<(usize, usize)> {
    let boxes: Vec<(DVec3, DVec3)> = beads
        .iter()
        .map(|&(state, radius)| grown(state, radius, within, margin))
        .collect();
    overlapping(&boxes)
}

/// The pairs of [`may_touch`] within `within` and `margin` whose gap is
/// also within that margin of their radii and twice the way their speeds
/// take them in `within` (two beads side by side along a diagonal, whose
/// boxes overlap, are not), or that [`may_touch`] within `soon` and no
/// margin (those a regrouping looks for, which so are always among
/// these).
pub(crate) fn may_touch_near<V: Coordinates>(
    beads: &[(BeadState<V>, f64)],
    (within, margin): (f64, f64),
    soon: f64,
) -> Vec<(usize, usize)> {
    let mut pairs = may_touch(beads, within, margin);
    pairs.retain(|&(i, j)| {
        let ((a, ra), (b, rb)) = (beads[i], beads[j]);
        let gap = pair_gap(a.position, b.position, ra + rb);
        let near = gap <= margin * (ra + rb) + 2.0 * within * pair_speeds(&a, &b);
        let (box_a, box_b) = (grown(a, ra, soon, 0.0), grown(b, rb, soon, 0.0));
        near || gap.is_nan() || (box_a.0.cmple(box_b.1).all() && box_b.0.cmple(box_a.1).all())
    });
    pairs
}

/// The box of a bead at `state` of `radius`, grown by its radius, a
/// `margin` fraction more, and along each axis twice the way its velocity
/// takes it in `within`.
fn grown<V: Coordinates>(
    state: BeadState<V>,
    radius: f64,
    within: f64,
    margin: f64,
) -> (DVec3, DVec3) {
    let p = state.position.xyz();
    let grown = radius * (1.0 + margin) + 2.0 * within * state.velocity.xyz().abs();
    (p - grown, p + grown)
}

/// Whether beads `a` and `b`, of `reach` (their two radii), rest in
/// touch: touching (their gap within [`TOUCHING`] of the reach) and not
/// parting. Two beads that ride their wires alone and rest in touch are
/// joined by a contact row, so that what presses them together is held
/// rather than struck step after step; apart, or parting as after an
/// elastic strike, they settle their meetings as two bodies.
pub(crate) fn rests_in_touch<V: Coordinates>(
    a: &BeadState<V>,
    b: &BeadState<V>,
    reach: f64,
) -> bool {
    let gap = pair_gap(a.position, b.position, reach);
    let (rate, speeds) = opening_rate(a, b);
    gap <= TOUCHING * reach && !parts(rate, reach, speeds)
}

/// The velocity change of a bead of `mass` held at `position` on a wire
/// whose normal there is `normal`, per `impulse` on it: the impulse's
/// part along the wire over the mass (the row's `J W Jᵀ` answer for a
/// body of one bead). An error in words at a singular point of the wire.
pub(crate) fn wire_response<V: Coordinates>(
    position: V,
    normal: V,
    mass: f64,
    impulse: V,
) -> Result<V, SolveError> {
    let nn = normal.dot(normal);
    if !usable(nn) {
        return Err(singular(position));
    }
    Ok(along(normal, nn, impulse) / mass)
}

/// The bodies the pairs join, grouped ([`islands`]'s grouping, the pairs
/// as links), each group that a pair names, in the order of its first
/// body.
fn groups(beads: &[TouchBead], bodies: usize, pairs: &[(usize, usize)]) -> Vec<Vec<usize>> {
    // Only the bodies a pair names, numbered in order (so that the groups
    // come in the order of their first bodies): a step whose beads are
    // mostly apart makes no group of each lone body.
    let mut is_named = vec![false; bodies];
    for &(i, j) in pairs {
        is_named[beads[i].body] = true;
        is_named[beads[j].body] = true;
    }
    let named: Vec<usize> = (0..bodies).filter(|&b| is_named[b]).collect();
    let mut slot = vec![usize::MAX; bodies];
    for (k, &body) in named.iter().enumerate() {
        slot[body] = k;
    }
    let links: Vec<[usize; 2]> = pairs
        .iter()
        .map(|&(i, j)| [slot[beads[i].body], slot[beads[j].body]])
        .collect();
    let mut found = islands(named.len(), links.iter().map(|l| l.as_slice()));
    for group in &mut found {
        for body in group.iter_mut() {
            *body = named[*body];
        }
    }
    found
}
