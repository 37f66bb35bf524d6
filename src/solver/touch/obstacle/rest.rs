//! Resting contact: the pairs that end a step overlapping, and how each
//! parts (see the module above, 3).

use super::Meeting;
use crate::geometry::Coordinates;
use crate::solver::solve::SolveError;
use crate::solver::state::BeadState;
use crate::solver::touch::TouchBody;

/// An overlap at the step's end (of the bead's radius) that resting
/// contact leaves as it is.
pub(super) const SETTLED: f64 = 1e-12;

/// The least cosine between the normal and the way a bead moves when
/// pushed along it for the bead to part from a body it overlaps (60°);
/// past it, the body parts from the bead, where it can move.
const ALIGNED: f64 = 0.5;

/// A pair that ends the step overlapping: its normal there (out of the
/// body), the point of the body, and how much of the overlap the bead and
/// the body each take away (all of it one or the other).
pub(super) struct Overlap<V> {
    pub(super) pair: usize,
    pub(super) normal: V,
    pub(super) point: V,
    /// The bead's share, m.
    pub(super) bead: f64,
    /// The body's share, m.
    pub(super) body: f64,
    /// The body's point's velocity change along the normal per unit
    /// impulse along it (`n·K n`).
    pub(super) body_weight: f64,
}

impl<V: Coordinates, B: TouchBody<V> + ?Sized> Meeting<'_, '_, V, B> {
    /// The pairs that overlap where the step ends (at `end`), past
    /// [`SETTLED`]: each one's normal and shares.
    pub(super) fn overlaps(&mut self, end: &[BeadState<V>]) -> Result<Vec<Overlap<V>>, SolveError> {
        let time = self.span.time + self.span.dt;
        let mut found = Vec::new();
        for (k, pair) in self.pairs.iter().enumerate() {
            let Some(near) = self.nearest(k, 1.0, end[pair.bead].position) else {
                continue;
            };
            let overlap = pair.radius - near.distance;
            // NaN, too, is no overlap.
            if overlap.is_nan() || overlap <= SETTLED * pair.radius {
                continue;
            }
            let n = near.normal;
            let answer = self.body.respond(time, end, pair.bead, n)?;
            let along = answer[pair.bead];
            let bead = n.dot(along);
            let point = self.obstacles[pair.obstacle].point(1.0, near.point);
            let body = n.xyz().dot(point.response * n.xyz());
            // The bead parts where it moves along the normal readily
            // enough; else the body does, where it can move.
            let aligned = bead >= ALIGNED * along.dot(along).sqrt();
            let bead_parts = aligned || !(body > 0.0 && body.is_finite());
            if bead_parts && !(bead > 0.0 && bead.is_finite()) {
                continue;
            }
            found.push(Overlap {
                pair: k,
                normal: n,
                point: near.point,
                bead: if bead_parts { overlap } else { 0.0 },
                body: if bead_parts { 0.0 } else { overlap },
                body_weight: body,
            });
        }
        Ok(found)
    }

    /// Gives the beads at `now` (the part `done` of the step in), for
    /// each of `overlaps`, the velocity along its normal that moves its
    /// bead its share over the rest of the step, through the body's
    /// answer to an impulse along it: each pair's impulse.
    pub(super) fn push_apart(
        &mut self,
        (done, now): (f64, &mut [BeadState<V>]),
        overlaps: &[Overlap<V>],
    ) -> Result<Vec<f64>, SolveError> {
        let left = (1.0 - done) * self.span.dt;
        let time = self.span.time + done * self.span.dt;
        let mut impulses = Vec::with_capacity(overlaps.len());
        for overlap in overlaps {
            let i = self.pairs[overlap.pair].bead;
            let answer = self.body.respond(time, now, i, overlap.normal)?;
            let w = overlap.normal.dot(answer[i]);
            let impulse = if w > 0.0 && left > 0.0 {
                overlap.bead / left / w
            } else {
                0.0
            };
            for (state, dv) in now.iter_mut().zip(answer) {
                state.velocity += dv * impulse;
            }
            impulses.push(impulse);
        }
        Ok(impulses)
    }

    /// Takes back from the beads at `end` the velocity `push_apart` gave
    /// them (each of `impulses` along its pair's normal, answered where
    /// the step ends): the parting moves them and leaves their motion as
    /// it was, so that it adds no energy.
    pub(super) fn take_back(
        &mut self,
        (overlaps, impulses): (&[Overlap<V>], &[f64]),
        end: &mut [BeadState<V>],
    ) -> Result<(), SolveError> {
        let time = self.span.time + self.span.dt;
        for (overlap, &impulse) in overlaps.iter().zip(impulses) {
            if impulse == 0.0 {
                continue;
            }
            let i = self.pairs[overlap.pair].bead;
            let answer = self.body.respond(time, end, i, overlap.normal)?;
            for (state, dv) in end.iter_mut().zip(answer) {
                state.velocity -= dv * impulse;
            }
        }
        Ok(())
    }

    /// Moves the body's beads so that pair `k`'s bead goes `depth` along
    /// `normal`, each along its answer to an impulse along it: to first
    /// order, along what holds them.
    pub(super) fn move_out(
        &mut self,
        k: usize,
        normal: V,
        depth: f64,
        states: &mut [BeadState<V>],
    ) -> Result<(), SolveError> {
        let i = self.pairs[k].bead;
        let time = self.span.time + self.span.dt;
        let answer = self.body.respond(time, states, i, normal)?;
        let w = normal.dot(answer[i]);
        if !(w > 0.0 && depth.is_finite()) {
            return Ok(());
        }
        for (state, dv) in states.iter_mut().zip(answer) {
            state.position += dv * (depth / w);
        }
        Ok(())
    }
}
