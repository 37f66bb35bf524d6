//! The bodies of one step's settlement: which are settled, in which
//! group the broad phase first put them, each bead's box, and how a
//! group's settlement ended.

use bevy::math::DVec3;

use super::TouchBead;

/// The bodies not yet settled this step, in the groups the broad phase
/// first put them in, each bead's box (from the step's start to its end,
/// grown to take in the path its settlement gave it), each body's beads,
/// and the beads in order of where their boxes first began along `x`.
pub(super) struct Pool {
    pub(super) boxes: Vec<(DVec3, DVec3)>,
    pub(super) group_of: Vec<usize>,
    pub(super) free: Vec<bool>,
    pub(super) groups: Vec<Vec<usize>>,
    /// The beads of body `b` are `members[first[b]..first[b + 1]]`.
    first: Vec<usize>,
    members: Vec<usize>,
    /// The beads (with a box) by `key`, the lowest `x` of their first
    /// box; how far a box now reaches above its key along `x`, and below.
    by_x: Vec<usize>,
    key: Vec<f64>,
    above: f64,
    below: f64,
    /// The pairs of beads whose boxes overlapped where the step began
    /// (each `(i, j)`, `i < j`, in order), those of bead `i` from
    /// `pairs_from[i]` on.
    pairs: Vec<(usize, usize)>,
    pairs_from: Vec<usize>,
    /// The beads whose boxes have grown since the broad phase.
    grown: Vec<usize>,
}

impl Pool {
    /// The pool of `bodies` bodies before any is settled, the broad phase
    /// having found `pairs` and the `groups` they join.
    pub(super) fn new(
        boxes: Vec<(DVec3, DVec3)>,
        beads: &[TouchBead],
        bodies: usize,
        (pairs, groups): (Vec<(usize, usize)>, Vec<Vec<usize>>),
    ) -> Self {
        let pairs_from = (0..=beads.len())
            .map(|i| pairs.partition_point(|&(a, _)| a < i))
            .collect();
        let mut first = vec![0; bodies + 1];
        for bead in beads {
            first[bead.body + 1] += 1;
        }
        for b in 0..bodies {
            first[b + 1] += first[b];
        }
        let mut next = first.clone();
        let mut members = vec![0; beads.len()];
        for (i, bead) in beads.iter().enumerate() {
            members[next[bead.body]] = i;
            next[bead.body] += 1;
        }
        let key: Vec<f64> = boxes.iter().map(|b| b.0.x).collect();
        let mut by_x: Vec<usize> = (0..boxes.len()).filter(|&i| !key[i].is_nan()).collect();
        by_x.sort_unstable_by(|&i, &j| key[i].total_cmp(&key[j]));
        let above = boxes
            .iter()
            .map(|(low, high)| high.x - low.x)
            .filter(|w| !w.is_nan())
            .fold(0.0, f64::max);
        let mut pool = Self {
            boxes,
            group_of: vec![usize::MAX; bodies],
            free: vec![true; bodies],
            groups,
            first,
            members,
            by_x,
            key,
            above,
            below: 0.0,
            pairs,
            pairs_from,
            grown: Vec::new(),
        };
        for (g, group) in pool.groups.iter().enumerate() {
            for &body in group {
                pool.group_of[body] = g;
            }
        }
        pool
    }

    /// The beads of body `body`.
    pub(super) fn beads_of(&self, body: usize) -> &[usize] {
        &self.members[self.first[body]..self.first[body + 1]]
    }

    /// The beads whose boxes meet the box `(low, high)`, each with its
    /// box.
    pub(super) fn near(&self, (low, high): (DVec3, DVec3)) -> Vec<(usize, (DVec3, DVec3))> {
        let from = self
            .by_x
            .partition_point(|&j| self.key[j] < low.x - self.above);
        self.by_x[from..]
            .iter()
            .take_while(|&&j| self.key[j] <= high.x + self.below)
            .map(|&j| (j, self.boxes[j]))
            .filter(|(_, (a, b))| a.cmple(high).all() && low.cmple(*b).all())
            .collect()
    }

    /// The pairs of `members` (in order) whose boxes overlapped where the
    /// step began, in order: those of a group whose bodies stand where the
    /// broad phase found them.
    pub(super) fn pairs_within(&self, members: &[usize]) -> Vec<(usize, usize)> {
        let mut within = Vec::new();
        for &i in members {
            let (Some(&from), Some(&to)) = (self.pairs_from.get(i), self.pairs_from.get(i + 1))
            else {
                continue;
            };
            within.extend(
                self.pairs[from..to]
                    .iter()
                    .filter(|(_, j)| members.binary_search(j).is_ok()),
            );
        }
        within
    }

    /// Grows bead `j`'s box to take in `path`, the box of the path its
    /// settlement gave it.
    pub(super) fn grow(&mut self, j: usize, path: (DVec3, DVec3)) {
        let b = &mut self.boxes[j];
        let was = *b;
        *b = (b.0.min(path.0), b.1.max(path.1));
        if *b != was {
            self.grown.push(j);
        }
        if !self.key[j].is_nan() {
            self.above = self.above.max(b.1.x - self.key[j]);
            self.below = self.below.max(self.key[j] - b.0.x);
        }
    }

    /// The pairs of beads whose boxes overlap now, each `(i, j)`, `i < j`,
    /// in order, into `out`: those the broad phase found, and those that
    /// a box grown since meets.
    pub(super) fn overlapping_now(&self, out: &mut Vec<(usize, usize)>) {
        out.clear();
        out.extend_from_slice(&self.pairs);
        for &j in &self.grown {
            out.extend(
                self.near(self.boxes[j])
                    .into_iter()
                    .filter(|&(i, _)| i != j)
                    .map(|(i, _)| (i.min(j), i.max(j))),
            );
        }
        if !self.grown.is_empty() {
            out.sort_unstable();
            out.dedup();
        }
    }

    /// Takes the free bodies of group `g`.
    pub(super) fn take(&mut self, g: usize) -> Vec<usize> {
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

/// How a group's settlement ended.
pub(super) enum Settled {
    /// Its bodies are settled: these.
    Done(Vec<usize>),
    /// A bead of these bodies came to meet beads of the bodies outside.
    Met(Vec<usize>, Met),
}

/// The bodies outside a group that its beads came to meet.
#[derive(Debug, Default)]
pub(super) struct Met {
    /// Not settled yet, taken from the pool with the rest of their groups.
    pub(super) free: Vec<usize>,
    /// Settled with another group before.
    pub(super) settled: Vec<usize>,
}
