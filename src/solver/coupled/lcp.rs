//! A mixed linear complementarity problem `w = q + M z`, `M` symmetric
//! positive definite (../shared/PHYSICS.md, "Many contacts at once"),
//! solved as the convex problem it is, the least of `½ zᵀ M z + qᵀ z`
//! within each row's bound, by projected Newton steps (Bertsekas): the
//! rows at their bound that the gradient `w` presses against it stay
//! there, the others take the Newton step `M_FF d = −w_F`, and the step
//! is projected back within the bounds and halved until it lowers the
//! objective enough (Armijo's rule along the projection arc). Each step
//! lowers the objective, so the iteration cannot cycle as pivoting on
//! the rows out of place can in a jammed pile; a step that meets the
//! rows held exactly ends it. The Newton solve and the product `M z` are
//! the caller's, so the same iteration serves a position and a velocity
//! problem, each factoring its own matrix.

/// How one row's `z` and `w` are bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Bound {
    /// Met whatever the sign of its `z`: `w = 0`.
    Equal,
    /// One-sided, of side ±1: `side·z ≥ 0`, `side·w ≥ 0`, `z·w = 0`.
    Side(f64),
    /// Left out: `z = 0`, whatever its `w`.
    Out,
}

/// Why [`solve_lcp`] stopped without a solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum LcpError<E> {
    /// The caller's Newton solve failed.
    Solve(E),
    /// This many Newton steps did not reach the solution.
    Unsettled {
        /// Newton steps taken.
        steps: usize,
        /// The worst row's violation where they stopped: `|w|` of a row
        /// held, how far `w` of a row at its bound is on the wrong side.
        violation: f64,
    },
}

/// The least share of the decrease its first-order term promises that a
/// step must give (Armijo's rule).
const SUFFICIENT: f64 = 1e-4;

/// The most halvings of one step.
const HALVINGS: u32 = 40;

/// The largest `ε` of the `ε`-active set, as a fraction of the largest
/// `z` (see [`solve_lcp`]).
const BARELY: f64 = 1e-3;

/// Which rows a solution holds: those met whatever their sign, and the
/// one-sided rows whose `z` pushes.
pub(crate) fn held(bounds: &[Bound], z: &[f64]) -> impl Iterator<Item = bool> {
    bounds.iter().zip(z).map(|(bound, &z)| match *bound {
        Bound::Equal => true,
        Bound::Side(side) => side * z > 0.0,
        Bound::Out => false,
    })
}

/// Solves the problem of `bounds` from `z` (the warm start, moved within
/// the bounds first), `diagonal` the diagonal of `M`. A row barely held
/// (`z` within `ε` of its bound, `ε` the smaller of a thousandth of the
/// largest `z` and how far one diagonal step would take any row) that
/// the gradient presses past its bound is put there before each step
/// where that lowers the objective (Bertsekas' `ε`-active set): a jammed
/// pile's rows that carry almost nothing are not freed and cut back step
/// after step. `apply(z, w)`
/// puts `w = q + M z` into `w`;
/// `newton(free, w, d)` puts into `d` the Newton step of the rows `free`,
/// `M_FF d_F = −w_F`, zero elsewhere (it may keep the factorization of a
/// set of free rows for the next call with the same set). A row at its
/// bound is violated where `side·w < −slack[row]`. Returns how many
/// Newton steps it took, at most `max_steps`, with `z` and `w` the
/// solution's.
pub(crate) fn solve_lcp<E>(
    (bounds, diagonal): (&[Bound], &[f64]),
    slack: &[f64],
    (z, w): (&mut Vec<f64>, &mut Vec<f64>),
    max_steps: usize,
    mut apply: impl FnMut(&[f64], &mut Vec<f64>),
    mut newton: impl FnMut(&[bool], &[f64], &mut Vec<f64>) -> Result<(), E>,
) -> Result<usize, LcpError<E>> {
    let rows = bounds.len();
    z.resize(rows, 0.0);
    for (z, &bound) in z.iter_mut().zip(bounds) {
        *z = if z.is_finite() {
            within(bound, *z)
        } else {
            0.0
        };
    }
    let project = |r: usize, value: f64| within(bounds[r], value);
    apply(z, w);
    let mut free = vec![false; rows];
    let (mut d, mut trial, mut w_trial) = (Vec::new(), Vec::new(), Vec::new());
    // A step taken whole that no bound cut met the rows it held.
    let mut exact = false;
    for steps in 0..=max_steps {
        let (mut largest, mut natural) = (0.0f64, 0.0f64);
        for r in 0..rows {
            largest = largest.max(z[r].abs());
            let stepped = project(r, z[r] - w[r] / diagonal[r]);
            natural = natural.max((z[r] - stepped).abs());
        }
        let epsilon = natural.min(BARELY * largest);
        // Each such row alone lowers the objective where its own diagonal
        // step would take it past its bound (`side·w ≥ side·z·M_rr`); all
        // of them at once are put there only where that lowers it too, so
        // that no step raises the objective and the iteration cannot
        // cycle.
        let mut barely = false;
        for r in 0..rows {
            if let Bound::Side(side) = bounds[r]
                && side * z[r] > 0.0
                && side * z[r] <= epsilon
                && side * w[r] >= side * z[r] * diagonal[r]
            {
                if !barely {
                    trial.clear();
                    trial.extend_from_slice(z);
                    barely = true;
                }
                trial[r] = 0.0;
            }
        }
        if barely {
            apply(&trial, &mut w_trial);
            if objective_change((z, w), (&trial, &w_trial)) < 0.0 {
                std::mem::swap(z, &mut trial);
                std::mem::swap(w, &mut w_trial);
                exact = false;
            }
        }
        // The rows at their bound that the gradient presses against it.
        let mut violated = false;
        for r in 0..rows {
            free[r] = match bounds[r] {
                Bound::Equal => true,
                Bound::Out => false,
                Bound::Side(side) => {
                    let pushed = side * w[r] < -slack[r];
                    violated |= z[r] == 0.0 && pushed;
                    z[r] != 0.0 || pushed
                }
            };
        }
        if exact && !violated {
            return Ok(steps);
        }
        if steps == max_steps {
            break;
        }
        newton(&free, w, &mut d).map_err(LcpError::Solve)?;
        let mut alpha = 1.0;
        let mut taken = false;
        // The longest part of the step along `d` that keeps every row
        // within its bound, and the row that meets its bound there (none
        // where the whole step keeps them all).
        let mut meets: Option<(f64, usize)> = None;
        for r in 0..rows {
            if let Bound::Side(side) = bounds[r]
                && side * (z[r] + d[r]) < 0.0
            {
                let part = ((side * z[r]) / (-side * d[r])).max(0.0);
                if meets.is_none_or(|(least, _)| part < least) {
                    meets = Some((part, r));
                }
            }
        }
        let to_bound = meets.filter(|&(part, _)| part > 0.0);
        for trial_step in 0..=HALVINGS + 1 {
            // The whole step projected onto the bounds; where that does not
            // descend enough, the part of it that keeps every row within
            // its bound, that row put on its bound (a descent whatever the
            // conditioning: `d` is the least of the objective along itself
            // at 1, with the other rows where they are); where no row
            // meets its bound or that part is nothing, halvings along the
            // projection arc.
            let bounded = if trial_step == 1 { to_bound } else { None };
            match (trial_step, bounded) {
                (0, _) => {}
                (1, Some((part, _))) => alpha = part,
                (1, None) => continue,
                (k, _) => alpha = 0.5f64.powi(i32::try_from(k - 1).unwrap_or(i32::MAX)),
            }
            let mut cut = false;
            trial.clear();
            trial.extend((0..rows).map(|r| {
                let moved = z[r] + alpha * d[r];
                let projected = project(r, moved);
                cut |= projected != moved;
                projected
            }));
            if let Some((_, r)) = bounded {
                trial[r] = 0.0;
                cut = true;
            }
            apply(&trial, &mut w_trial);
            let change = objective_change((z, w), (&trial, &w_trial));
            let first: f64 = (0..rows).map(|r| (trial[r] - z[r]) * w[r]).sum();
            if change <= SUFFICIENT * first || first == 0.0 || (bounded.is_some() && change <= 0.0)
            {
                exact = alpha == 1.0 && !cut;
                taken = true;
                break;
            }
        }
        if !taken {
            let violation = violation(bounds, z, w);
            return Err(LcpError::Unsettled { steps, violation });
        }
        std::mem::swap(z, &mut trial);
        std::mem::swap(w, &mut w_trial);
    }
    Err(LcpError::Unsettled {
        steps: max_steps,
        violation: violation(bounds, z, w),
    })
}

/// `value` moved within `bound`: zero where it is on the wrong side of a
/// one-sided bound or left out.
fn within(bound: Bound, value: f64) -> f64 {
    match bound {
        Bound::Side(side) if side * value < 0.0 => 0.0,
        Bound::Out => 0.0,
        _ => value,
    }
}

/// How much the objective changes from `z` to `trial`, `w` and `w_trial`
/// the gradients there: `Δᵀ (w + w_trial) / 2`, `Δ = trial − z`, exact
/// for a quadratic.
fn objective_change((z, w): (&[f64], &[f64]), (trial, w_trial): (&[f64], &[f64])) -> f64 {
    (0..z.len())
        .map(|r| 0.5 * (trial[r] - z[r]) * (w[r] + w_trial[r]))
        .sum()
}

/// The worst row's violation at `(z, w)` (see [`LcpError::Unsettled`]).
fn violation(bounds: &[Bound], z: &[f64], w: &[f64]) -> f64 {
    bounds
        .iter()
        .zip(z.iter().zip(w))
        .map(|(bound, (&z, &w))| match *bound {
            Bound::Out => 0.0,
            Bound::Side(side) if side * z <= 0.0 => (-side * w).max(0.0),
            _ => w.abs(),
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
pub(in crate::solver::coupled) mod tests {
    use super::{Bound, LcpError, held, solve_lcp, within};
    use proptest::prelude::*;

    /// `w = q + M z`.
    fn apply(m: &[Vec<f64>], q: &[f64], z: &[f64], w: &mut Vec<f64>) {
        w.clear();
        w.extend((0..q.len()).map(|i| q[i] + (0..q.len()).map(|j| m[i][j] * z[j]).sum::<f64>()));
    }

    /// `M_FF d_F = −w_F` by Gaussian elimination with partial pivoting,
    /// zero elsewhere.
    pub(in crate::solver::coupled) fn newton(
        m: &[Vec<f64>],
        free: &[bool],
        w: &[f64],
        d: &mut Vec<f64>,
    ) {
        let rows: Vec<usize> = (0..w.len()).filter(|&r| free[r]).collect();
        let k = rows.len();
        let mut a: Vec<Vec<f64>> = rows
            .iter()
            .map(|&i| {
                let mut row: Vec<f64> = rows.iter().map(|&j| m[i][j]).collect();
                row.push(-w[i]);
                row
            })
            .collect();
        for c in 0..k {
            let p = (c..k)
                .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
                .unwrap_or(c);
            a.swap(c, p);
            let pivot = a[c].clone();
            for row in a.iter_mut().skip(c + 1) {
                let f = row[c] / pivot[c];
                for (value, p) in row.iter_mut().zip(&pivot).skip(c) {
                    *value -= f * p;
                }
            }
        }
        let mut x = vec![0.0; k];
        for c in (0..k).rev() {
            let s: f64 = (c + 1..k).map(|j| a[c][j] * x[j]).sum();
            x[c] = (a[c][k] - s) / a[c][c];
        }
        d.clear();
        d.resize(w.len(), 0.0);
        for (&r, &v) in rows.iter().zip(&x) {
            d[r] = v;
        }
    }

    /// Solves `(m, q)` of `bounds` from `z`.
    fn solve(
        m: &[Vec<f64>],
        q: &[f64],
        bounds: &[Bound],
        z: &mut Vec<f64>,
        w: &mut Vec<f64>,
    ) -> Result<usize, LcpError<()>> {
        solve_watched(m, q, bounds, z, w).0
    }

    /// `½ zᵀ M z + qᵀ z = ½ zᵀ (w + q)` where the gradient is `w`, `z`
    /// found from it as `M⁻¹ (w − q)`.
    fn objective_at(m: &[Vec<f64>], q: &[f64], w: &[f64]) -> f64 {
        let shifted: Vec<f64> = q.iter().zip(w).map(|(q, w)| q - w).collect();
        let mut z = Vec::new();
        newton(m, &vec![true; q.len()], &shifted, &mut z);
        (0..q.len()).map(|r| 0.5 * z[r] * (w[r] + q[r])).sum()
    }

    /// [`solve`], with the objective where it starts (within the bounds)
    /// and where each Newton step is taken from.
    fn solve_watched(
        m: &[Vec<f64>],
        q: &[f64],
        bounds: &[Bound],
        z: &mut Vec<f64>,
        w: &mut Vec<f64>,
    ) -> (Result<usize, LcpError<()>>, Vec<f64>) {
        let diagonal: Vec<f64> = (0..q.len()).map(|r| m[r][r]).collect();
        let moved: Vec<f64> = z
            .iter()
            .zip(bounds)
            .map(|(&z, &bound)| within(bound, z))
            .collect();
        let mut start = Vec::new();
        apply(m, q, &moved, &mut start);
        let mut objectives = vec![objective_at(m, q, &start)];
        let solved = solve_lcp(
            (bounds, &diagonal),
            &vec![0.0; q.len()],
            (z, w),
            100,
            |z, w| apply(m, q, z, w),
            |free, w, d| {
                objectives.push(objective_at(m, q, w));
                newton(m, free, w, d);
                Ok(())
            },
        );
        (solved, objectives)
    }

    /// Whether each of `objectives` is no higher than the one before, to
    /// rounding.
    fn descending(objectives: &[f64]) -> bool {
        objectives
            .windows(2)
            .all(|pair| pair[1] <= pair[0] + 1e-12 * pair[0].abs().max(1.0))
    }

    /// `BᵀB + δI`, positive definite.
    fn gram(b: &[Vec<f64>], delta: f64) -> Vec<Vec<f64>> {
        let n = b[0].len();
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let s: f64 = b.iter().map(|row| row[i] * row[j]).sum();
                        s + if i == j { delta } else { 0.0 }
                    })
                    .collect()
            })
            .collect()
    }

    /// Whether `(z, w)` meets `bounds` to `tol`.
    fn complementary(bounds: &[Bound], z: &[f64], w: &[f64], tol: f64) -> bool {
        bounds.iter().enumerate().all(|(r, b)| match *b {
            Bound::Equal => w[r].abs() <= tol,
            Bound::Out => z[r] == 0.0,
            Bound::Side(s) => s * z[r] >= -tol && s * w[r] >= -tol && (z[r] * w[r]).abs() <= tol,
        })
    }

    proptest! {
        /// On positive definite problems of up to seven rows, every kind
        /// of bound mixed and any warm start, the iteration ends at the
        /// one solution: complementary to 1e-9, and the same `z` to 1e-9
        /// as trying every set of held rows.
        #[test]
        fn projected_newton_finds_the_one_solution_of_a_positive_definite_problem(
            b in prop::collection::vec(prop::collection::vec(-1.0f64..1.0, 7), 3..9),
            q in prop::collection::vec(-1.0f64..1.0, 7),
            kinds in prop::collection::vec(0u8..4, 7),
            start in prop::collection::vec(-1.0f64..1.0, 7),
            n in 1usize..=7,
        ) {
            let b: Vec<Vec<f64>> = b.iter().map(|row| row[..n].to_vec()).collect();
            let m = gram(&b, 0.05);
            let q = &q[..n];
            let bounds: Vec<Bound> = kinds[..n]
                .iter()
                .map(|k| match k {
                    0 => Bound::Equal,
                    1 => Bound::Out,
                    2 => Bound::Side(1.0),
                    _ => Bound::Side(-1.0),
                })
                .collect();
            let (mut z, mut w) = (start[..n].to_vec(), Vec::new());
            let (steps, objectives) = solve_watched(&m, q, &bounds, &mut z, &mut w);
            prop_assert!(steps.is_ok(), "{steps:?}");
            prop_assert!(descending(&objectives), "{objectives:?}");
            prop_assert!(complementary(&bounds, &z, &w, 1e-9), "z {z:?} w {w:?}");
            // Every guess: the complementary one is the same.
            for mask in 0u32..1 << n {
                let guess: Vec<bool> = (0..n).map(|r| mask >> r & 1 == 1).collect();
                if bounds.iter().zip(&guess).any(|(b, &g)| {
                    (*b == Bound::Equal && !g) || (*b == Bound::Out && g)
                }) {
                    continue;
                }
                let (mut d, mut ww) = (Vec::new(), Vec::new());
                apply(&m, q, &vec![0.0; n], &mut ww);
                newton(&m, &guess, &ww, &mut d);
                apply(&m, q, &d, &mut ww);
                if complementary(&bounds, &d, &ww, 0.0) {
                    for r in 0..n {
                        prop_assert!((d[r] - z[r]).abs() <= 1e-9, "row {r}: {} against {}", z[r], d[r]);
                    }
                }
            }
            let holds: Vec<bool> = held(&bounds, &z).collect();
            for (r, bound) in bounds.iter().enumerate() {
                prop_assert_eq!(holds[r], *bound == Bound::Equal || matches!(*bound, Bound::Side(s) if s * z[r] > 0.0));
            }
        }
    }

    /// A row barely held that its gradient presses toward its bound too
    /// weakly for the bound to be nearer its least (`z = 4e-4`,
    /// `w = 1e-4`, `M_rr = 1`: put on its bound, the objective would rise
    /// by 4e-8) is left free: the objective falls at every step, and the
    /// iteration ends at the solution.
    #[test]
    fn a_row_barely_held_is_put_on_its_bound_only_where_that_descends() {
        let m = vec![vec![1.0, 0.5], vec![0.5, 1.0]];
        let q = [-0.9995, -0.5003];
        let bounds = [Bound::Side(1.0); 2];
        let (mut z, mut w) = (vec![1.0, 4e-4], Vec::new());
        let (steps, objectives) = solve_watched(&m, &q, &bounds, &mut z, &mut w);
        assert!(steps.is_ok(), "{steps:?}");
        assert!(objectives.len() >= 2, "{objectives:?}");
        assert!(descending(&objectives), "{objectives:?}");
        assert!(complementary(&bounds, &z, &w, 1e-12), "z {z:?}, w {w:?}");
    }

    /// Five contacts on two beads' worth of freedom (a jammed corner: the
    /// same row three times and one the sum of two others), made positive
    /// definite by a compliance of 1e-10 of the diagonal, each overlapping
    /// by its own amount so that no `z` meets them all: the iteration
    /// settles with every row pushing or open, and the deepest overlap
    /// along each axis met to 1e-9.
    #[test]
    fn a_redundant_set_made_compliant_settles() {
        let j = [[1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
        let c = 1e-10;
        let m: Vec<Vec<f64>> = (0..5)
            .map(|i| {
                (0..5)
                    .map(|k| {
                        let d = j[i][0] * j[k][0] + j[i][1] * j[k][1];
                        d + if i == k { c * d } else { 0.0 }
                    })
                    .collect()
            })
            .collect();
        let q = [-1.0, -1.1, -0.9, -0.5, -1.4];
        let bounds = [Bound::Side(1.0); 5];
        let (mut z, mut w) = (vec![0.0; 5], Vec::new());
        let steps = solve(&m, &q, &bounds, &mut z, &mut w);
        assert!(steps.is_ok(), "{steps:?}");
        assert!(complementary(&bounds, &z, &w, 1e-9), "z {z:?}, w {w:?}");
        let moved = [
            (0..5).map(|r| j[r][0] * z[r]).sum::<f64>(),
            (0..5).map(|r| j[r][1] * z[r]).sum::<f64>(),
        ];
        assert!((moved[0] - 1.1).abs() <= 1e-9, "{moved:?}");
        assert!((moved[1] - 0.5).abs() <= 1e-9, "{moved:?}");
    }

    /// A Newton solve that fails is reported as the caller's error, and a
    /// budget too small to settle as unsettled.
    #[test]
    fn a_failed_solve_and_a_short_budget_are_reported() {
        let bounds = [Bound::Side(1.0), Bound::Side(1.0)];
        let m = vec![vec![1.0, 0.5], vec![0.5, 1.0]];
        let q = [-1.0, -1.0];
        let (mut z, mut w) = (vec![0.0; 2], Vec::new());
        let failed = solve_lcp(
            (&bounds, &[1.0; 2]),
            &[0.0; 2],
            (&mut z, &mut w),
            5,
            |z, w| apply(&m, &q, z, w),
            |_, _, _| Err("singular"),
        );
        assert_eq!(failed, Err(LcpError::Solve("singular")));
        let short = solve_lcp::<()>(
            (&bounds, &[1.0; 2]),
            &[0.0; 2],
            (&mut z, &mut w),
            0,
            |z, w| apply(&m, &q, z, w),
            |free, w, d| {
                newton(&m, free, w, d);
                Ok(())
            },
        );
        assert_eq!(
            short,
            Err(LcpError::Unsettled {
                steps: 0,
                violation: 1.0
            })
        );
    }
}
