//! A dense island's RATTLE step as one complementarity problem at each
//! level (../shared/PHYSICS.md, "Many contacts at once"): positions by
//! chord steps, each a linear complementarity problem on `J₀ W J₀ᵀ`
//! solved by projected Newton steps ([`solve_lcp`]), then velocities by
//! one such problem on `J W Jᵀ` where the step ends. The rows are made slightly
//! compliant ([`COMPLIANCE`]), so that a jammed pile's redundant contacts
//! leave each problem one solution: the beads and the rows that press are
//! unique, every contact pushing only, and no pass holds rows one layer
//! of a pile at a time.

mod bordered;

use bordered::{Bordered, MOST_DIFFERING};

use super::integrators::PUSHING_SLACK;
use super::newton::{CHORD_ITERATIONS, CHORD_STALL, Direction};
use super::{Island, IslandWork, OFF_THE_WIRE, RowReport, TOUCHING};
use crate::geometry::WireSpace;
use crate::solver::coupled::lcp::{Bound, LcpError, held, solve_lcp};
use crate::solver::coupled::normal::Factored;
use crate::solver::newton::{NEWTON_TOLERANCE, newton_accepted, newton_within};
use crate::solver::settings::StepSettings;
use crate::solver::solve::{SolveError, singular};
use crate::solver::state::{BeadState, LinearForce};

/// The compliance of a dense island's rows, as a fraction of each row's
/// diagonal of `J W Jᵀ`: a held row meets `C + ε μ = 0`, `ε` this times
/// the diagonal. A row pressing with `μ` overlaps by this fraction of how
/// far `μ` alone would move its beads (some 1e-13 m at the foot of a pile
/// of 2 cm beads twenty deep at 60 Hz, some 1e-12 m where a landing
/// presses), within the touch settlement's tolerance for touching, and
/// `J W Jᵀ + E` is positive definite however many rows are redundant.
pub(super) const COMPLIANCE: f64 = 1e-11;

/// How many times Newton's tolerance (at the position level) and the
/// slack of a contact's closing speed (at the velocity level) a row set
/// aside may be violated by before it is held: below, rounding.
const SET_ASIDE_SLACK: f64 = 100.0;

/// The softest compliance a chord step's matrix is given.
const SOFTEST: f64 = 1e-4;

/// The stiffest compliance a chord step's matrix is given: stiffer, the
/// matrix of a jammed pile's redundant rows is so ill-conditioned that a
/// complementarity solve takes tens of Newton steps, each with rows
/// cut back to their bounds; the chord steps it damps reach the same
/// solution, of compliance [`COMPLIANCE`].
const STIFFEST: f64 = 1e-8;

/// The compliance of a chord step's matrix where the worst row's
/// residual is `taken` of its scale: a tenth of it, in whole powers of a
/// hundred (so that the matrix is factored again only as the residual
/// falls by that much), between [`STIFFEST`] and [`SOFTEST`]. Where a
/// pile's redundant rows disagree by what the chord's linearization
/// misses (of the order of the residual squared), a matrix this soft
/// keeps their multipliers from growing by the inverse of a tiny
/// compliance, with signs that flip from step to step.
fn softness(taken: f64) -> f64 {
    let wanted = (0.1 * taken).clamp(STIFFEST, SOFTEST);
    let decades = (wanted.log10() / 2.0).floor() * 2.0;
    10f64.powf(decades).max(STIFFEST)
}

/// How many Newton steps more than the rows a complementarity solve may
/// take.
const LCP_STEPS: usize = 16;

/// The buffers of one complementarity solve: the gradients of the rows
/// held (the others zeroed), which rows the factorization in hand holds
/// and at what compliance, the solves that border it for rows held that
/// differ from those in a few rows, and `W Jᵀ z`, bead by bead.
#[derive(Default)]
struct Linear<V> {
    masked: Vec<V>,
    set_aside: Vec<bool>,
    factored_for: Option<(Vec<bool>, f64)>,
    bordered: Bordered,
    moved: Vec<V>,
}

/// One level's problem: its rows' bounds, diagonals of `J W Jᵀ` (a row's
/// compliance is a fraction of its own) and slacks (how far a row set
/// aside may be violated by rounding).
struct Problem<'a> {
    bounds: &'a [Bound],
    diagonal: &'a [f64],
    slack: &'a [f64],
}

impl<V: WireSpace> Island<V> {
    /// Whether the island's RATTLE steps are dense ([`Island::step_dense`])
    /// with its rows as `work` has them: it time-steps
    /// ([`Island::time_steps`]), has no friction, every one-sided wire row
    /// lands at `e = 0` (contacts that strike with `e > 0` are the touch
    /// settlement's), and every bead on a wire that ends has left it (a
    /// marble off the end of its rail; the instant a bead passes an end is
    /// located, which a dense step does not do).
    pub(crate) fn steps_densely(&self, work: &IslandWork<V>) -> bool {
        self.time_steps()
            && !self.is_rough()
            && (!self.has_ends()
                || (0..self.rows()).all(|r| !self.ends(r) || work.inactive.get(r) == Some(&true)))
            && self
                .sides
                .iter()
                .zip(&self.contacts)
                .all(|(&(side, e), &contact)| contact || side == 0.0 || e == 0.0)
    }

    /// A dense island's step: RATTLE with every row at once
    /// ([`Island::rattle_dense`]), halved where its position solve finds
    /// no root. A one-sided wire row set aside where the step began and
    /// held where it ends reports its bead landed at the step's end, with
    /// the speed it closed on its wire at the start; one held and then set
    /// aside reports its bead left.
    pub(super) fn step_dense(
        &self,
        time: f64,
        states: &mut [BeadState<V>],
        forces: &[LinearForce<V>],
        settings: &StepSettings,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        work.events.clear();
        self.begin(time, states, work);
        let set_aside = work.inactive.clone();
        let start = states.to_vec();
        self.substeps(time, states, forces, settings, work)?;
        let end = time + settings.dt;
        for (r, &was_aside) in set_aside.iter().enumerate() {
            if self.contacts[r] || self.sides[r].0 == 0.0 {
                continue;
            }
            let held = !work.inactive[r];
            if was_aside && held {
                self.report_landed_at_end(r, (time, end), (&start, states), work);
            } else if !was_aside && !held {
                self.report_left(r, end, states, work);
            }
        }
        self.follow(end, states, work);
        Ok(())
    }

    /// RATTLE on a dense island, from `work.x0, work.v0` over `h`: every
    /// one-sided row that may press (held where the step begins, or
    /// meeting at `e = 0`) is a row of one complementarity problem.
    ///
    /// Positions: the beads drift by their forces to `x̃` and are pushed
    /// back along the start's gradients, `x = x̃ + W J₀ᵀ μ`, until each
    /// two-sided row is met (`C + ε μ = 0`) and each one-sided one is met
    /// where it pushes and open where it does not. Each chord step solves
    /// the problem linearized about the last iterate on the factored
    /// `J₀ W J₀ᵀ + E'` (`E'` softer than `E` while the residual is large,
    /// [`softness`]), by projected Newton steps from the last iterate's
    /// multipliers (the first chord step's from the last step's forces of
    /// the rows it held), and the iteration stops by Newton's test row by
    /// row.
    /// Velocities: `v½ = (x − x₀)/h` and the second half kick, then one
    /// complementarity problem on the rows held and those in touch:
    /// `J v + ε ν = 0` where `ν` pushes, `J v ≥ 0` where it is zero. A row
    /// is held after the step where either multiplier pushes; the report
    /// is their mean, as RATTLE's.
    pub(super) fn rattle_dense(
        &self,
        forces: &[LinearForce<V>],
        h: f64,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        let set_aside = work.inactive.clone();
        let stepped = self.rattle_rows(forces, h, &set_aside, work);
        if stepped.is_err() {
            // Taken again from where it began, halved.
            work.inactive = set_aside;
        }
        stepped
    }

    /// [`Island::rattle_dense`], the rows `set_aside` where it begins.
    fn rattle_rows(
        &self,
        forces: &[LinearForce<V>],
        h: f64,
        set_aside: &[bool],
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        let rows = self.rows();
        let start = work.time;
        work.inactive.clear();
        work.inactive.resize(rows, false);
        // A bead behind a wire that catches it (a marble under another
        // track, or outside the bowl) does not land on it from there.
        let behind = |r: usize| {
            let at = work.x0[self.entry_bead[self.row_start[r]]];
            self.catching[r] && self.behind_at(r, at, start)
        };
        let bounds: Vec<Bound> = (0..rows)
            .map(|r| match self.sides[r] {
                (0.0, _) if set_aside[r] => Bound::Out,
                (0.0, _) => Bound::Equal,
                (_, _) if set_aside[r] && behind(r) => Bound::Out,
                (side, e) if e == 0.0 || !set_aside[r] => Bound::Side(side),
                _ => Bound::Out,
            })
            .collect();
        self.evaluate_at_start(work, start);
        let diagonal = self.diagonal(&work.first_gradient);
        // From the last step's forces (`μ = λ h²/2`, `ν = λ h/2`) of the
        // rows it held: its position and velocity solves' own, or the mean
        // it reported (an island built again).
        let forces_then: Vec<(f64, f64)> = if work.pressing.len() == rows {
            work.pressing.clone()
        } else if work.reports.len() == rows {
            work.reports.iter().map(|r| (r.lambda, r.lambda)).collect()
        } else {
            vec![(0.0, 0.0); rows]
        };
        let held_then = |r: usize, force: f64| if set_aside[r] { 0.0 } else { force };
        let mut mu: Vec<f64> = (0..rows)
            .map(|r| 0.5 * h * h * held_then(r, forces_then[r].0))
            .collect();
        let warm_nu: Vec<f64> = (0..rows)
            .map(|r| 0.5 * h * held_then(r, forces_then[r].1))
            .collect();
        self.drift(forces, h, start, work);
        let drift = work.x.clone();
        let slack: Vec<f64> = (0..rows)
            .map(|r| {
                SET_ASIDE_SLACK * NEWTON_TOLERANCE * self.rows[r].scale().max(self.reach(r, &drift))
            })
            .collect();
        let problem = Problem {
            bounds: &bounds,
            diagonal: &diagonal,
            slack: &slack,
        };
        let mut linear = Linear::default();
        self.solve_positions(&problem, &drift, &mut mu, &mut linear, work)?;
        let active: Vec<bool> = held(&bounds, &mu).collect();

        self.half_kick(forces, h, work);
        work.inactive.fill(false);
        self.evaluate_at_new(work);
        let velocity_bounds: Vec<Bound> = (0..rows)
            .map(|r| match bounds[r] {
                Bound::Side(side) if !active[r] && !self.in_touch(r, side, work) => Bound::Out,
                bound => bound,
            })
            .collect();
        let diagonal = self.diagonal(&work.gradient);
        let q: Vec<f64> = (0..rows)
            .map(|r| self.rate(r, &work.gradient, &work.v, &work.bias))
            .collect();
        let fastest = work.v.iter().map(|v| v.dot(*v).sqrt()).fold(0.0, f64::max);
        let slack = vec![SET_ASIDE_SLACK * PUSHING_SLACK * fastest; rows];
        let problem = Problem {
            bounds: &velocity_bounds,
            diagonal: &diagonal,
            slack: &slack,
        };
        let mut nu = warm_nu;
        linear.factored_for = None;
        self.solve_velocities(&problem, (&q, fastest), &mut nu, &mut linear, work)?;
        let pushing: Vec<bool> = held(&velocity_bounds, &nu).collect();
        self.push(&work.gradient, &nu, &mut work.v);
        work.reports.clear();
        work.reports.extend((0..rows).map(|r| RowReport {
            lambda: mu[r] / (h * h) + nu[r] / h,
            ..RowReport::default()
        }));
        for r in 0..rows {
            work.inactive[r] = !(active[r] || pushing[r]);
        }
        work.pressing.clear();
        work.pressing.extend(
            mu.iter()
                .zip(&nu)
                .map(|(&m, &n)| (2.0 * m / (h * h), 2.0 * n / h)),
        );
        Ok(())
    }

    /// RATTLE's position solve of [`Island::rattle_dense`]: chord steps
    /// from `mu` (the warm start) until every row is
    /// within Newton's tolerance, or the worst is accepted as a stalled
    /// Newton solve's is (a contact's without the slack an exact solve
    /// gives it: the problem has a root however many rows are redundant). Two chord steps that do not shrink the worst
    /// row by a tenth, or [`CHORD_ITERATIONS`], mean no root near: the
    /// step is halved. Returns with `work.x` on the rows, `work.inactive`
    /// the rows set aside.
    fn solve_positions(
        &self,
        problem: &Problem<'_>,
        drift: &[V],
        mu: &mut Vec<f64>,
        linear: &mut Linear<V>,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        let rows = self.rows();
        let mut active: Vec<bool> = Vec::with_capacity(rows);
        let (mut previous, mut stalls) = (f64::INFINITY, 0);
        let mut q = vec![0.0; rows];
        for i in 0..=CHORD_ITERATIONS {
            work.x.clear();
            work.x.extend_from_slice(drift);
            self.push(&work.first_gradient, mu, &mut work.x);
            self.evaluate_positions(work);
            active.clear();
            active.extend(held(problem.bounds, mu));
            let last = i == CHORD_ITERATIONS;
            let (mut within, mut worst) = (true, 0.0f64);
            for r in 0..rows {
                let met = work.c[r] + COMPLIANCE * problem.diagonal[r] * mu[r];
                let residual = match problem.bounds[r] {
                    Bound::Out => continue,
                    Bound::Side(side) if !active[r] => (-side * work.c[r]).max(0.0),
                    _ => met.abs(),
                };
                let scale = self.rows[r].scale().max(f64::MIN_POSITIVE);
                worst = worst.max(residual / scale);
                within = within && newton_within(residual, scale, self.reach(r, &work.x));
            }
            if within || newton_accepted(worst, previous, 1.0, last) {
                for (aside, held) in work.inactive.iter_mut().zip(active.iter()) {
                    *aside = !held;
                }
                return self.same_branch(work, Direction::First, worst);
            }
            if last || !worst.is_finite() {
                return Err(SolveError::NoConvergence {
                    iterations: CHORD_ITERATIONS,
                    residual: worst,
                });
            }
            if worst > CHORD_STALL * previous {
                stalls += 1;
                if stalls == 2 {
                    return Err(SolveError::NoConvergence {
                        iterations: i,
                        residual: worst,
                    });
                }
            } else {
                stalls = 0;
            }
            previous = worst;
            // The problem linearized about μ on the chord: w = q + M μ',
            // M = J₀ W J₀ᵀ + E', q = C + ε μ − M μ, E' the compliance made
            // softer while the residual is large ([`softness`]): the
            // steps it damps leave the solution as it was.
            let soft = softness(worst);
            self.kick(&work.first_gradient, mu, &mut linear.moved);
            for (r, q) in q.iter_mut().enumerate() {
                let extra = (soft - COMPLIANCE) * problem.diagonal[r] * mu[r];
                *q = work.c[r] - self.along(r, &work.first_gradient, &linear.moved) - extra;
            }
            let x0 = &work.x0;
            self.complementarity(
                (&work.first_gradient, &q),
                (problem, soft),
                mu,
                linear,
                (&mut work.factored, x0),
            )?;
        }
        unreachable!("the last chord step returns")
    }

    /// RATTLE's velocity solve of [`Island::rattle_dense`]: the
    /// complementarity problem `w = q + (J W Jᵀ + E) ν` of `problem`
    /// (`q` the rows' `J v` less their bias), from `nu`, by proximal
    /// steps as the position solve's chord steps: each solves the problem
    /// on a softer matrix ([`softness`]) from the last `ν`, until every
    /// row held is met and every row set aside opens to the problem's
    /// slack, or for [`CHORD_ITERATIONS`] steps (the rows met as well as
    /// rounding lets them). Returns with `nu` the multipliers.
    fn solve_velocities(
        &self,
        problem: &Problem<'_>,
        (q, fastest): (&[f64], f64),
        nu: &mut Vec<f64>,
        linear: &mut Linear<V>,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        let rows = self.rows();
        let mut shifted = vec![0.0; rows];
        let mut w = vec![0.0; rows];
        for _ in 0..CHORD_ITERATIONS {
            self.kick(&work.gradient, nu, &mut linear.moved);
            let mut worst = 0.0f64;
            let mut settled = true;
            for r in 0..rows {
                w[r] = q[r]
                    + self.along(r, &work.gradient, &linear.moved)
                    + COMPLIANCE * problem.diagonal[r] * nu[r];
                let off = match problem.bounds[r] {
                    Bound::Out => 0.0,
                    Bound::Side(side) if side * nu[r] <= 0.0 => (-side * w[r]).max(0.0),
                    _ => w[r].abs(),
                };
                worst = worst.max(off);
                settled &= off <= problem.slack[r];
            }
            if settled {
                break;
            }
            // q' = w − (J W Jᵀ + E') ν = q − (E' − E) ν: the problem on
            // the softer matrix whose solution at ν is where it is now.
            let soft = softness(worst / fastest.max(f64::MIN_POSITIVE));
            for r in 0..rows {
                shifted[r] = q[r] - (soft - COMPLIANCE) * problem.diagonal[r] * nu[r];
            }
            let x = &work.x;
            self.complementarity(
                (&work.gradient, &shifted),
                (problem, soft),
                nu,
                linear,
                (&mut work.factored, x),
            )?;
        }
        Ok(())
    }

    /// The linear complementarity problem `w = q + (J W Jᵀ + E) z` of
    /// `problem` (`J` the rows' `gradient`, `E` their compliances), by
    /// projected Newton steps ([`solve_lcp`]) from `z`. Returns with `z`
    /// the solution. A set of free rows is factored
    /// ([`NormalMatrix::factor_compliant`]) and kept in `linear` for the
    /// next solve with the same gradients and compliance; a Newton step
    /// whose free rows differ from those in at most [`MOST_DIFFERING`] is
    /// solved with it bordered ([`Bordered`]). A row whose diagonal
    /// vanishes is a singular point, at its bead in `x`.
    ///
    /// [`NormalMatrix::factor_compliant`]: crate::solver::coupled::normal::NormalMatrix::factor_compliant
    fn complementarity(
        &self,
        (gradient, q): (&[V], &[f64]),
        (problem, soft): (&Problem<'_>, f64),
        z: &mut Vec<f64>,
        linear: &mut Linear<V>,
        (factored, x): (&mut Factored, &[V]),
    ) -> Result<(), SolveError> {
        let rows = self.rows();
        let mut w = Vec::with_capacity(rows);
        let Linear {
            masked,
            set_aside,
            factored_for,
            bordered,
            moved,
        } = linear;
        let apply = |z: &[f64], w: &mut Vec<f64>| {
            self.kick(gradient, z, moved);
            w.clear();
            w.extend((0..rows).map(|r| {
                q[r] + self.along(r, gradient, moved) + soft * problem.diagonal[r] * z[r]
            }));
        };
        let mut column_moved = Vec::new();
        let mut column = |s: usize| -> Vec<(usize, f64)> {
            column_moved.clear();
            column_moved.resize(self.beads(), V::ZERO);
            self.move_along(gradient, s, 1.0, &mut column_moved);
            (0..rows)
                .filter_map(|r| {
                    let m = self.along(r, gradient, &column_moved)
                        + if r == s {
                            soft * problem.diagonal[r]
                        } else {
                            0.0
                        };
                    (m != 0.0).then_some((r, m))
                })
                .collect()
        };
        // The Newton step on the rows `free` holds: with the factorization
        // in hand where it was made for those rows, bordered where they
        // differ from its own in a few, else with a new one.
        let newton = |free: &[bool], w: &[f64], d: &mut Vec<f64>| {
            let b: Vec<f64> = (0..rows)
                .map(|r| if free[r] { -w[r] } else { 0.0 })
                .collect();
            let near = factored_for.as_ref().filter(|(held, s)| {
                *s == soft
                    && held.iter().zip(free).filter(|(h, f)| h != f).count() <= MOST_DIFFERING
            });
            let current = match near {
                Some((held, _)) if held[..] == *free => true,
                Some((held, _)) => {
                    let solve = |x: &mut [f64]| self.normal.solve(factored, x);
                    if bordered.solve((free, held), &b, d, &mut column, solve) {
                        return Ok(());
                    }
                    false
                }
                None => false,
            };
            if !current {
                masked.clear();
                masked.extend_from_slice(gradient);
                set_aside.clear();
                for (r, &f) in free.iter().enumerate() {
                    set_aside.push(!f);
                    if !f {
                        masked[self.row_start[r]..self.row_start[r + 1]].fill(V::ZERO);
                    }
                }
                bordered.clear();
                self.normal
                    .factor_compliant(&self.inverse_mass, masked, set_aside, soft, factored)
                    .map_err(|r| singular(x[self.entry_bead[self.row_start[r]]]))?;
                *factored_for = Some((free.to_vec(), soft));
            }
            d.clear();
            d.extend_from_slice(&b);
            self.normal.solve(factored, d);
            for (d, &f) in d.iter_mut().zip(free) {
                if !f {
                    *d = 0.0;
                }
            }
            Ok(())
        };
        let diagonal: Vec<f64> = problem.diagonal.iter().map(|d| d * (1.0 + soft)).collect();
        match solve_lcp(
            (problem.bounds, &diagonal),
            problem.slack,
            (z, &mut w),
            rows + LCP_STEPS,
            apply,
            newton,
        ) {
            Ok(_) => Ok(()),
            Err(LcpError::Solve(error)) => Err(error),
            Err(LcpError::Unsettled { steps, violation }) => Err(SolveError::NoConvergence {
                iterations: u32::try_from(steps).unwrap_or(u32::MAX),
                residual: violation,
            }),
        }
    }

    /// `W Jᵀ z` into `out`, bead by bead (`J` the rows' `gradient`).
    fn kick(&self, gradient: &[V], z: &[f64], out: &mut Vec<V>) {
        out.clear();
        out.resize(self.beads(), V::ZERO);
        self.push(gradient, z, out);
    }

    /// Each row's diagonal of `J W Jᵀ` with the rows' `gradient`.
    fn diagonal(&self, gradient: &[V]) -> Vec<f64> {
        (0..self.rows())
            .map(|r| self.normal.diagonal_value(r, &self.inverse_mass, gradient))
            .collect()
    }

    /// Whether one-sided row `r` (of `side`) is in touch at `work.x`
    /// (evaluated into `work.c`): a contact's beads within [`TOUCHING`]
    /// of their reach, a bead on its wire within [`OFF_THE_WIRE`] of its
    /// scale, or either past it.
    fn in_touch(&self, r: usize, side: f64, work: &IslandWork<V>) -> bool {
        match self.contact_gap(r, &work.x) {
            Some((gap, reach)) => gap <= TOUCHING * reach,
            None => side * work.c[r] <= OFF_THE_WIRE * self.rows[r].scale(),
        }
    }
}
