//! Solves of a dense island's complementarity problem with rows held that
//! differ in a few rows from those its factorization was made for.
//!
//! A projected Newton step ([`solve_lcp`]) solves `K_F d = b` on the rows
//! `F` it holds (`K_F` the compliant `J W Jᵀ + E` on them, a unit diagonal
//! elsewhere), and from one step to the next `F` gains or loses a row or
//! two. A factorization `K_B` of nearby rows `B` answers it by bordering:
//! with `A = F \ B` the rows added and `R = B \ F` those removed,
//!
//! ```text
//! [ K_B   C     E_R ] [x]   [b_B∩F]
//! [ Cᵀ    M_AA  0   ] [a] = [b_A  ]
//! [ E_Rᵀ  0     0   ] [y]   [0    ]
//! ```
//!
//! `C` the columns `A` of the matrix on the rows `B`, `E_R` the unit
//! columns of the rows removed (their multipliers `y` hold them at zero).
//! Its Schur complement `S = D − Uᵀ K_B⁻¹ U` (`U = [C E_R]`) is as small
//! as the rows that differ: each of `U`'s columns costs one solve with
//! `K_B`, kept while `B` stays, and each step one more solve and `S`'s
//! dense `LU`. The answer is `d = x` on `B ∩ F`, `a` on `A`, zero
//! elsewhere: `K_F`'s own solution, to rounding.
//!
//! [`solve_lcp`]: crate::solver::coupled::lcp::solve_lcp

use faer::Mat;
use faer::linalg::solvers::Solve;

/// The most rows by which the rows held may differ from the factored
/// ones before the matrix is factored again: each costs a solve with the
/// factorization, and the bordered system grows as their square.
pub(super) const MOST_DIFFERING: usize = 16;

/// One row by which the rows held differ from the factored ones: its
/// column of `U` and `K_B⁻¹` of it.
struct Differing {
    row: usize,
    /// Held now and set aside in the factorization (else the reverse).
    added: bool,
    /// A row added: the nonzero entries `(r, M_rs)` of its column of the
    /// compliant matrix, its diagonal among them.
    entries: Vec<(usize, f64)>,
    /// `K_B⁻¹` of the row's column of `U`.
    solved: Vec<f64>,
}

impl Differing {
    /// `uᵀ v` of this row's column `u` of `U` (its entries on the rows
    /// `base` holds, or its unit vector).
    fn dot(&self, base: &[bool], v: &[f64]) -> f64 {
        if self.added {
            self.entries
                .iter()
                .filter(|&&(r, _)| base[r])
                .map(|&(r, m)| m * v[r])
                .sum()
        } else {
            v[self.row]
        }
    }

    /// The entry of its column of the compliant matrix in row `r`.
    fn entry(&self, r: usize) -> f64 {
        self.entries
            .iter()
            .find(|&&(s, _)| s == r)
            .map_or(0.0, |&(_, m)| m)
    }
}

/// The columns of `U` and their solves, for one factorization: cleared
/// whenever the matrix is factored again.
#[derive(Default)]
pub(super) struct Bordered {
    differing: Vec<Differing>,
}

impl Bordered {
    /// Forgets every column: the factorization they were solved with is
    /// gone.
    pub(super) fn clear(&mut self) {
        self.differing.clear();
    }

    /// `K_F⁻¹ b` into `out` for the rows `free` held (`b` zero on the rows
    /// set aside) with the factorization of the rows `base`: `column(s)`
    /// gives the nonzero entries of the compliant matrix's column `s`,
    /// `solve` solves with the factorization in place. `false` where the
    /// bordered system is singular to rounding (then `out` is unchanged).
    pub(super) fn solve(
        &mut self,
        (free, base): (&[bool], &[bool]),
        b: &[f64],
        out: &mut Vec<f64>,
        mut column: impl FnMut(usize) -> Vec<(usize, f64)>,
        mut solve: impl FnMut(&mut [f64]),
    ) -> bool {
        let n = free.len();
        let rows: Vec<usize> = (0..n).filter(|&r| free[r] != base[r]).collect();
        for &r in &rows {
            if self.differing.iter().any(|d| d.row == r) {
                continue;
            }
            let added = free[r];
            let mut solved = vec![0.0; n];
            let entries = if added {
                let entries = column(r);
                for &(s, m) in &entries {
                    if base[s] {
                        solved[s] = m;
                    }
                }
                entries
            } else {
                solved[r] = 1.0;
                Vec::new()
            };
            solve(&mut solved);
            self.differing.push(Differing {
                row: r,
                added,
                entries,
                solved,
            });
        }
        let used: Vec<&Differing> = rows
            .iter()
            .filter_map(|&r| self.differing.iter().find(|d| d.row == r))
            .collect();
        let k = used.len();
        let s = Mat::from_fn(k, k, |i, j| {
            let (di, dj) = (used[i], used[j]);
            let d = if di.added && dj.added {
                dj.entry(di.row)
            } else {
                0.0
            };
            d - di.dot(base, &dj.solved)
        });
        let mut y: Vec<f64> = (0..n)
            .map(|r| if base[r] && free[r] { b[r] } else { 0.0 })
            .collect();
        solve(&mut y);
        let mut t = Mat::from_fn(k, 1, |i, _| {
            let d = used[i];
            let wanted = if d.added { b[d.row] } else { 0.0 };
            wanted - d.dot(base, &y)
        });
        if k > 0 {
            s.partial_piv_lu().solve_in_place(t.as_mut());
        }
        if (0..k).any(|i| !t[(i, 0)].is_finite()) {
            return false;
        }
        for (i, d) in used.iter().enumerate() {
            let ti = t[(i, 0)];
            for (x, z) in y.iter_mut().zip(&d.solved) {
                *x -= ti * z;
            }
        }
        out.clear();
        out.extend((0..n).map(|r| if base[r] && free[r] { y[r] } else { 0.0 }));
        for (i, d) in used.iter().enumerate() {
            if d.added {
                out[d.row] = t[(i, 0)];
            }
        }
        out.iter().all(|x| x.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::Bordered;
    use crate::solver::coupled::lcp::tests::newton;
    use proptest::prelude::*;

    /// `m` on the rows `held` solved for `x` in place, zero elsewhere (a
    /// right-hand side zero off them, as every one here is: `K`'s own
    /// solve, its unit diagonal off the rows held).
    fn solve_held(m: &[Vec<f64>], held: &[bool], x: &mut [f64]) {
        let minus: Vec<f64> = x.iter().map(|v| -v).collect();
        let mut solved = Vec::new();
        newton(m, held, &minus, &mut solved);
        x.copy_from_slice(&solved);
    }

    proptest! {
        /// For a positive definite matrix of up to 14 rows, rows factored
        /// and rows held drawn apart in up to six rows, the bordered solve
        /// agrees with solving the rows held directly to 1e-9 of the
        /// answer's size, through several solves with the same
        /// factorization as the rows held change.
        #[test]
        fn bordering_a_factorization_solves_the_rows_held(
            n in 3usize..14,
            entries in prop::collection::vec(-1.0f64..1.0, 14 * 14),
            base_draw in prop::collection::vec(any::<bool>(), 14),
            flips in prop::collection::vec(prop::collection::vec(0usize..14, 0..6), 1..4),
            rhs in prop::collection::vec(-1.0f64..1.0, 14),
        ) {
            // M = BᵀB + I: positive definite.
            let m: Vec<Vec<f64>> = (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| {
                            let s: f64 = (0..n)
                                .map(|k| entries[k * 14 + i] * entries[k * 14 + j])
                                .sum();
                            s + if i == j { 1.0 } else { 0.0 }
                        })
                        .collect()
                })
                .collect();
            let base: Vec<bool> = base_draw[..n].to_vec();
            let mut bordered = Bordered::default();
            for flip in &flips {
                let mut free = base.clone();
                for &f in flip {
                    if f < n {
                        free[f] = !free[f];
                    }
                }
                let b: Vec<f64> = (0..n).map(|r| if free[r] { rhs[r] } else { 0.0 }).collect();
                let mut wanted = b.clone();
                solve_held(&m, &free, &mut wanted);
                let mut got = Vec::new();
                let solved = bordered.solve(
                    (&free, &base),
                    &b,
                    &mut got,
                    |s| (0..n).map(|r| (r, m[r][s])).collect(),
                    |x| solve_held(&m, &base, x),
                );
                prop_assert!(solved);
                let size = wanted.iter().fold(1.0f64, |a, x| a.max(x.abs()));
                for r in 0..n {
                    prop_assert!(
                        (got[r] - wanted[r]).abs() <= 1e-9 * size,
                        "row {r}: {} against {}", got[r], wanted[r]
                    );
                }
            }
        }
    }
}
