//! The Newton position solve of RATTLE and of projection, and its check
//! that the root it found continues the step's start. Where a lone bead's
//! Newton step divides by one slope, an island's solves a matrix for all
//! its rows' multipliers, so the iteration is the island's own; it stops
//! by the lone bead's test, each row within its tolerance or the worst
//! row accepted.

use super::{CONTACT_PASSES, CONTACT_SLACK, EXACT_STEPS, Island, IslandWork};
use crate::geometry::WireSpace;

/// The most chord steps a dense island's RATTLE position solve takes.
pub(super) const CHORD_ITERATIONS: u32 = 60;

/// A chord step that leaves `C` above this fraction of the last is not
/// converging.
pub(super) const CHORD_STALL: f64 = 0.9;

use crate::solver::newton::{NEWTON_MAX_ITERATIONS, newton_accepted, newton_within};
use crate::solver::solve::SolveError;

impl<V: WireSpace> Island<V> {
    /// Newton's method for `C(x + W Jᵀ μ) = 0` from `work.x`, along the
    /// gradients of `direction`: moves `work.x` onto the constraints and
    /// returns with `work.lambda` holding the total μ.
    ///
    /// Along the current gradients (projection) each iteration factors
    /// `J W Jᵀ` afresh. Along the first gradients (RATTLE) the Newton
    /// matrix `J(x) W J₀ᵀ` is not symmetric: one row takes the exact step;
    /// several start as a chord iteration on the factored `J₀ W J₀ᵀ` (no
    /// new factorization, linear convergence at a rate set by how far the
    /// rows turn over the step) and switch to exact Newton steps (LU of
    /// the band or sparse matrix) once the chord stops shrinking `C`
    /// fourfold per iteration. Two exact steps that do not shrink `C`, or
    /// [`EXACT_STEPS`] that do not reach the tolerance, mean no root near:
    /// the step is halved. A dense island ([`Island::time_steps`]) stays
    /// on the chord, up to [`CHORD_ITERATIONS`] steps, two that do not
    /// shrink `C` by a tenth meaning no root near: the LU of its many rows
    /// costs some thirty chord steps. The iterations evaluate `C` and the
    /// gradients only, not `J̇q̇` or the bias.
    ///
    /// `warm` starts RATTLE's solve from the multipliers in
    /// `work.lambda` (those of rows set aside dropped), the beads pushed
    /// by them from the drift; otherwise from none.
    pub(super) fn newton(
        &self,
        work: &mut IslandWork<V>,
        direction: Direction,
        warm: bool,
    ) -> Result<(), SolveError> {
        let rows = self.rows();
        if warm && direction == Direction::First && work.lambda.len() == rows {
            // From the multipliers in hand, those of rows set aside dropped.
            for (mu, &inactive) in work.lambda.iter_mut().zip(&work.inactive) {
                if inactive || !mu.is_finite() {
                    *mu = 0.0;
                }
            }
            self.push(&work.first_gradient, &work.lambda, &mut work.x);
        } else {
            work.lambda.clear();
            work.lambda.resize(rows, 0.0);
        }
        let chord_only = direction == Direction::First && rows > 1 && self.time_steps();
        let limit = if chord_only {
            CHORD_ITERATIONS
        } else {
            NEWTON_MAX_ITERATIONS
        };
        let mut exact = direction == Direction::First && rows == 1;
        let mut previous = f64::INFINITY;
        let mut previous_taken = f64::INFINITY;
        let mut rising = 0;
        let mut exacts = 0;
        let mut i = 0;
        loop {
            self.evaluate_positions(work);
            let last = i == limit;
            // Every row within the tolerance, as one bead's solve asks of
            // its wire; or the worst row, relative to its scale, accepted.
            let mut within = true;
            let mut worst = 0.0f64;
            // The worst row for the acceptance, a held contact's with its
            // slack.
            let mut taken = 0.0f64;
            for r in 0..rows {
                let scale = self.rows[r].scale().max(f64::MIN_POSITIVE);
                let residual = work.c[r].abs();
                worst = worst.max(residual / scale);
                let slack = if self.contacts[r] { CONTACT_SLACK } else { 1.0 };
                taken = taken.max(residual / (slack * scale));
                // The reach only while every row so far is within.
                within = within && newton_within(residual, scale, self.reach(r, &work.x));
            }
            if within || newton_accepted(taken, previous_taken, 1.0, last) {
                return self.same_branch(work, direction, worst);
            }
            if last || !worst.is_finite() {
                return Err(SolveError::NoConvergence {
                    iterations: limit,
                    residual: worst,
                });
            }
            if (exact && direction == Direction::First && worst >= previous)
                || (chord_only && worst > CHORD_STALL * previous)
            {
                // Exact Newton steps converge fast near a root, chord steps
                // steadily; two that do not shrink C (or, on the chord, by
                // a tenth) mean there is none near: halve the step.
                rising += 1;
                if rising == 2 {
                    return Err(SolveError::NoConvergence {
                        iterations: i,
                        residual: worst,
                    });
                }
            } else {
                rising = 0;
            }
            exact |= !chord_only && direction == Direction::First && worst > 0.25 * previous;
            if exact && direction == Direction::First {
                // Exact Newton steps converge quadratically near a root:
                // this many that have not reached it mean there is none near.
                exacts += 1;
                if exacts > EXACT_STEPS {
                    return Err(SolveError::NoConvergence {
                        iterations: i,
                        residual: worst,
                    });
                }
            }
            (previous, previous_taken) = (worst, taken);
            work.rhs.clear();
            work.rhs.extend(work.c.iter().map(|c| -c));
            let along = match direction {
                Direction::First => &work.first_gradient,
                Direction::Current => {
                    self.factor(work, false)?;
                    &work.gradient
                }
            };
            let solved_exactly = exact
                && self.normal.solve_unsymmetric(
                    &self.inverse_mass,
                    &work.gradient,
                    along,
                    &work.inactive,
                    &mut work.lu,
                    &mut work.rhs,
                    self.natural_order(),
                );
            if !solved_exactly {
                // A singular Newton matrix (a redundant row): the chord step.
                work.rhs.clear();
                work.rhs.extend(work.c.iter().map(|c| -c));
                self.normal.solve(&mut work.factored, &mut work.rhs);
            }
            for (total, step) in work.lambda.iter_mut().zip(&work.rhs) {
                *total += step;
            }
            self.push(along, &work.rhs, &mut work.x);
            i += 1;
        }
    }

    /// Newton along the current gradients, each contact row set aside
    /// whose beads touched where the step began and that the projection
    /// leaves overlapping held and the projection taken again from where
    /// it started (see [`Island::step_at`]).
    pub(super) fn newton_holding(&self, work: &mut IslandWork<V>) -> Result<(), SolveError> {
        let start = work.x.clone();
        // Each pass holds one contact row more at least.
        for _ in 0..self.rows() + CONTACT_PASSES {
            self.newton(work, Direction::Current, false)?;
            if !self.hold_overlapping(work) {
                break;
            }
            work.x.clone_from(&start);
        }
        Ok(())
    }

    /// The largest coordinate of row `r`'s beads at `x`: how far rounding
    /// the coordinates its `C` is computed from reaches.
    pub(super) fn reach(&self, r: usize, x: &[V]) -> f64 {
        (self.row_start[r]..self.row_start[r + 1])
            .map(|e| x[self.entry_bead[e]].reach())
            .fold(0.0, f64::max)
    }

    /// Checks that a Newton solution is the continuation of the start: no
    /// row's gradient may have turned by a right angle or more from the
    /// direction it was moved along (a rod flipped end over end, a bead
    /// carried across its wire's centre). Such a root is refused as no
    /// convergence, so the step is halved.
    pub(super) fn same_branch(
        &self,
        work: &IslandWork<V>,
        direction: Direction,
        residual: f64,
    ) -> Result<(), SolveError> {
        if direction == Direction::Current {
            return Ok(());
        }
        for r in 0..self.rows() {
            if work.inactive.get(r) == Some(&true) {
                continue;
            }
            let turn: f64 = (self.row_start[r]..self.row_start[r + 1])
                .map(|e| work.gradient[e].dot(work.first_gradient[e]))
                .sum();
            if turn.is_nan() || turn <= 0.0 {
                return Err(SolveError::NoConvergence {
                    iterations: NEWTON_MAX_ITERATIONS,
                    residual,
                });
            }
        }
        Ok(())
    }
}

/// The gradients a Newton iteration moves along.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Direction {
    /// Those at the step's start (RATTLE), factored before the iteration.
    First,
    /// Those at each iterate (projection), factored at each.
    Current,
}
