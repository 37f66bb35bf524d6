//! Eq. (12) on an island (λ and the accelerations, from `J W Jᵀ`
//! factored), and the RK4 and RATTLE steps built on it. Each bead moves
//! by the lone bead's formulas (RK4's stages and sum, RATTLE's drift and
//! half kick); what is the island's own is the matrix solve for the
//! multipliers, in eq. (12), in RATTLE's Newton position solve and in its
//! velocity solve.

use super::newton::Direction;
use super::{CONTACT_PASSES, Island, IslandWork, RowReport};
use crate::geometry::WireSpace;

use crate::solver::rattle::{rattle_drift, rattle_half_kick};
use crate::solver::rk4::{RK4_STAGES, rk4_plus};
use crate::solver::settings::Gains;
use crate::solver::solve::{SolveError, singular};
use crate::solver::state::LinearForce;

impl<V: WireSpace> Island<V> {
    /// Factors `J W Jᵀ` at the work's current state (`work.gradient` at
    /// `work.x`), or at the step's start (`work.first_gradient` at
    /// `work.x0`); a vanishing row is a singular point, reported at its
    /// first bead's position.
    pub(super) fn factor(
        &self,
        work: &mut IslandWork<V>,
        at_start: bool,
    ) -> Result<(), SolveError> {
        let (gradient, x) = if at_start {
            (&work.first_gradient, &work.x0)
        } else {
            (&work.gradient, &work.x)
        };
        self.normal
            .factor(
                &self.inverse_mass,
                gradient,
                &work.inactive,
                self.natural_order(),
                &mut work.factored,
            )
            .map_err(|r| {
                let p = x[self.entry_bead[self.row_start[r]]];
                singular(p)
            })
    }

    /// Eq. (12) at a stage `(x, v)`: λ, and the accelerations
    /// `W (Q + Jᵀλ)` into `work.acceleration`, at `work.x, work.v` (set to
    /// `work.x0, work.v0` first at the step's start).
    pub(super) fn accelerate(
        &self,
        forces: &[LinearForce<V>],
        gains: Gains,
        work: &mut IslandWork<V>,
        stage: Stage,
    ) -> Result<(), SolveError> {
        if stage == Stage::Start {
            work.x.clone_from(&work.x0);
            work.v.clone_from(&work.v0);
        }
        self.evaluate_at_new(work);
        self.applied(forces, &work.x, &work.v, &mut work.force);
        if self.rows() > 0 {
            self.factor(work, false)?;
        }
        work.lambda.clear();
        for r in 0..self.rows() {
            let pushed: f64 = (self.row_start[r]..self.row_start[r + 1])
                .map(|e| {
                    let bead = self.entry_bead[e];
                    work.gradient[e].dot(work.force[bead] * self.inverse_mass[bead])
                })
                .sum();
            let c_dot = self.rate(r, &work.gradient, &work.v, &work.bias);
            work.lambda
                .push(-work.curvature[r] - pushed - gains.alpha * work.c[r] - gains.beta * c_dot);
        }
        self.normal.solve(&mut work.factored, &mut work.lambda);
        work.acceleration.clear();
        work.acceleration.extend(
            work.force
                .iter()
                .zip(&self.inverse_mass)
                .map(|(f, w)| *f * *w),
        );
        self.push(&work.gradient, &work.lambda, &mut work.acceleration);
        Ok(())
    }

    /// Keeps the last solve's λ as the step's report.
    pub(super) fn keep_lambda(&self, work: &mut IslandWork<V>) {
        work.reports.clear();
        work.reports
            .extend(work.lambda.iter().map(|&lambda| RowReport {
                lambda,
                ..RowReport::default()
            }));
    }

    /// Eq. (7) on the island: four solves of eq. (12); λ reported is the
    /// first stage's.
    pub(super) fn rk4(
        &self,
        forces: &[LinearForce<V>],
        gains: Gains,
        h: f64,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        self.accelerate(forces, gains, work, Stage::Start)?;
        self.keep_lambda(work);
        let n = self.beads();
        let start = work.time;
        let pair = |x: &[V], v: &[V], i: usize| (x[i], v[i]);
        work.x_sum.clone_from(&work.v0);
        work.v_sum.clone_from(&work.acceleration);
        for (at, weight) in RK4_STAGES {
            // The stage's state from the previous stage's derivative, which
            // is (work.v, work.acceleration).
            for i in 0..n {
                let derivative = pair(&work.v, &work.acceleration, i);
                (work.x[i], work.v[i]) = rk4_plus(pair(&work.x0, &work.v0, i), at * h, derivative);
            }
            work.time = start + at * h;
            self.accelerate(forces, gains, work, Stage::Later)?;
            for i in 0..n {
                let derivative = pair(&work.v, &work.acceleration, i);
                (work.x_sum[i], work.v_sum[i]) =
                    rk4_plus(pair(&work.x_sum, &work.v_sum, i), weight, derivative);
            }
        }
        let sixth = h / 6.0;
        for i in 0..n {
            let sum = pair(&work.x_sum, &work.v_sum, i);
            (work.x[i], work.v[i]) = rk4_plus(pair(&work.x0, &work.v0, i), sixth, sum);
        }
        Ok(())
    }

    /// Eq. (8) for an island: SHAKE's position solve (Newton on all of the
    /// island's `C` along `W J₀ᵀ`), then the linear velocity solve.
    ///
    /// A contact row set aside whose beads touched at the step's start
    /// and that the position solve leaves overlapping is held and the
    /// solve taken again (see [`Island::step_at`]). Where the position
    /// solve finds no root with the contacts held (a jammed pile holds
    /// more of them than its beads can meet at once), those whose
    /// multipliers pull are let go and the solve taken again. A held
    /// contact row the velocity solve would pull on is let go
    /// ([`Island::project_velocity_pushing`]).
    pub(super) fn rattle(
        &self,
        forces: &[LinearForce<V>],
        h: f64,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        if self.steps_densely(work) {
            return self.rattle_dense(forces, h, work);
        }
        let start = work.time;
        let stepped = self.time_steps();
        // The rows a dense island may let go for pulling once its solve
        // has a root: those set aside where the step began (held since
        // by it; a row held from an earlier step is the velocity solve's
        // to let go), each at most once a step, so that a row pulling by
        // rounding is not let go and held again without end.
        let mut let_go: Vec<bool> = if stepped {
            (0..self.rows())
                .map(|r| !(work.inactive[r] || work.stepped_holds.get(r) == Some(&true)))
                .collect()
        } else {
            Vec::new()
        };
        // A dense island finds the rows it holds before its first pass
        // ([`Island::predict_holds`]), and each pass starts from the
        // multipliers of the one before.
        let mut warm = false;
        if stepped {
            self.drift(forces, h, start, work);
            self.predict_holds(h, start, work);
            warm = true;
        }
        // Each pass holds one contact row more at least, or lets go one.
        let mut unsolved = None;
        for _ in 0..self.rows() + CONTACT_PASSES {
            self.evaluate_at_start(work, start);
            if self.rows() > 0 {
                self.factor(work, true)?;
            }
            self.drift(forces, h, start, work);
            match self.newton(work, Direction::First, warm) {
                Err(failed @ SolveError::NoConvergence { .. }) if self.let_go_pulling(work) => {
                    unsolved = Some(failed);
                    warm = false;
                    continue;
                }
                solved => solved?,
            }
            unsolved = None;
            warm = stepped;
            // A dense island's rows held from the step's start that would
            // pull are let go, and the solve taken again.
            let released = stepped && self.let_go_pulling_once(work, &mut let_go);
            if !self.hold_overlapping(work) && !released {
                break;
            }
        }
        if let Some(failed) = unsolved {
            return Err(failed);
        }
        let to_lambda = 2.0 / (h * h);
        work.reports.clear();
        work.reports.extend(work.lambda.iter().map(|&mu| RowReport {
            lambda: 0.5 * to_lambda * mu,
            ..RowReport::default()
        }));
        self.half_kick(forces, h, work);
        self.evaluate_at_new(work);
        self.project_velocity_pushing(work)?;
        let to_mu = 2.0 / h;
        for (report, nu) in work.reports.iter_mut().zip(&work.rhs) {
            report.lambda += 0.5 * to_mu * nu;
        }
        Ok(())
    }

    /// RATTLE's `v½ = (x − x₀)/h` and second half kick at the new
    /// positions `work.x`, into `work.v`: the velocities its velocity
    /// solve projects.
    pub(super) fn half_kick(&self, forces: &[LinearForce<V>], h: f64, work: &mut IslandWork<V>) {
        for i in 0..self.beads() {
            work.v[i] = (work.x[i] - work.x0[i]) / h;
        }
        self.applied(forces, &work.x, &work.v, &mut work.force);
        for i in 0..self.beads() {
            let m = self.inverse_mass[i].recip();
            work.v[i] = rattle_half_kick(work.v[i], work.force[i], m, h);
        }
    }

    /// RATTLE's drift from the step's start at `start`: each bead moved
    /// by its applied forces alone over `h` into `work.x` (velocities
    /// `work.v` the start's), the rows to be met at `start + h`.
    pub(super) fn drift(
        &self,
        forces: &[LinearForce<V>],
        h: f64,
        start: f64,
        work: &mut IslandWork<V>,
    ) {
        self.applied(forces, &work.x0, &work.v0, &mut work.force);
        work.x.clear();
        work.v.clear();
        for i in 0..self.beads() {
            let from = (work.x0[i], work.v0[i]);
            let m = self.inverse_mass[i].recip();
            work.x.push(rattle_drift(from, work.force[i], m, h));
            work.v.push(work.v0[i]);
        }
        work.time = start + h;
    }

    /// Lets go of every held contact row whose multiplier in `work.lambda`
    /// pulls its beads together, and, in an island that time-steps
    /// ([`Island::time_steps`]), every held one-sided wire row whose
    /// multiplier pulls its bead onto the wire: where Newton's method
    /// found no root with a pile's contacts all held (more of them than
    /// its beads can meet at once), those that would have to pull are not
    /// pressed. Whether there were any.
    fn let_go_pulling(&self, work: &mut IslandWork<V>) -> bool {
        let mut any = false;
        let stepped = self.time_steps();
        for r in 0..self.rows() {
            let (side, _) = self.sides[r];
            if (self.contacts[r] || (stepped && side != 0.0)) && self.pulls(r, work) {
                work.inactive[r] = true;
                any = true;
            }
        }
        any
    }

    /// Whether row `r` is held and its multiplier in `work.lambda` pulls
    /// (the sign its side cannot push with).
    fn pulls(&self, r: usize, work: &IslandWork<V>) -> bool {
        let side = self.sides[r].0;
        !work.inactive[r] && work.lambda.get(r).is_some_and(|&l| side * l < 0.0)
    }

    /// [`Island::let_go_pulling`] after a solve that found its root, in
    /// an island that time-steps: lets go of each held one-sided row whose
    /// multiplier pulls and that it has not let go before in this step
    /// nor held from an earlier one (marked in `let_go`). Whether there
    /// were any.
    fn let_go_pulling_once(&self, work: &mut IslandWork<V>, let_go: &mut [bool]) -> bool {
        let mut any = false;
        for (r, done) in let_go.iter_mut().enumerate() {
            if !*done && self.sides[r].0 != 0.0 && self.pulls(r, work) {
                work.inactive[r] = true;
                *done = true;
                any = true;
            }
        }
        any
    }

    /// [`Island::project_velocity`] with every held contact row pushing
    /// and none closing: the velocities projected from where they were
    /// onto the held rows, every contact row whose multiplier pulls let
    /// go and every one let go whose beads then close held again, all at
    /// once while that leaves fewer rows out of place (block principal
    /// pivoting, Júdice and Pires), and one row at a time by the
    /// least-index rule (Murty's principal pivoting, which ends where
    /// `J W Jᵀ` is positive definite) for a pass when it has not for
    /// [`BLOCK_CHANCES`] passes; at most [`CONTACT_PASSES`] projections
    /// more than twice the contact rows. A dense island
    /// ([`Island::time_steps`]) starts from the contacts Gauss–Seidel
    /// finds pushing ([`Island::predict_pushing`]).
    pub(super) fn project_velocity_pushing(
        &self,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        if !self.contacts.contains(&true) {
            return self.project_velocity(work);
        }
        let unprojected = work.v.clone();
        let (gradient, bias) = (work.gradient.clone(), work.bias.clone());
        let set_aside = work.inactive.clone();
        if self.time_steps() {
            // A dense island's pivoting starts from the contacts that push.
            self.predict_pushing(work);
        }
        let fastest = unprojected
            .iter()
            .map(|v| v.dot(*v).sqrt())
            .fold(0.0, f64::max);
        let contacts = self.contacts.iter().filter(|&&c| c).count();
        let (mut fewest, mut chances) = (usize::MAX, BLOCK_CHANCES);
        for _ in 0..2 * contacts + CONTACT_PASSES {
            self.project_velocity(work)?;
            // The contact rows out of place: held and pulling, or let go
            // here and closing.
            let out: Vec<usize> = (0..self.rows())
                .filter(|&r| {
                    self.contacts[r]
                        && !set_aside[r]
                        && if work.inactive[r] {
                            -self.rate(r, &gradient, &work.v, &bias) > PUSHING_SLACK * fastest
                        } else {
                            work.rhs[r] < 0.0
                        }
                })
                .collect();
            if out.is_empty() {
                return Ok(());
            }
            let flips = if out.len() < fewest {
                (fewest, chances) = (out.len(), BLOCK_CHANCES);
                &out[..]
            } else if chances > 0 {
                chances -= 1;
                &out[..]
            } else {
                &out[..1]
            };
            for &r in flips {
                work.inactive[r] = !work.inactive[r];
                let entries = self.row_start[r]..self.row_start[r + 1];
                if work.inactive[r] {
                    work.gradient[entries].fill(V::ZERO);
                    work.bias[r] = 0.0;
                } else {
                    work.gradient[entries.clone()].copy_from_slice(&gradient[entries]);
                    work.bias[r] = bias[r];
                }
            }
            work.v.clone_from(&unprojected);
        }
        Ok(())
    }
}

/// How many passes of [`Island::project_velocity_pushing`] may flip every
/// row out of place without leaving fewer out of place than ever before,
/// before one pass flips only the first.
const BLOCK_CHANCES: usize = 3;

/// A contact row let go whose beads close slower than this fraction of
/// the fastest bead's speed is not closing: rounding.
pub(super) const PUSHING_SLACK: f64 = 1e-12;

/// Which state a solve of eq. (12) is at.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Stage {
    /// The step's start, `work.x0, work.v0`.
    Start,
    /// A later stage, `work.x, work.v`.
    Later,
}
