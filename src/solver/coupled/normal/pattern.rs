//! The sparsity patterns of the island's matrices, built once per topology:
//! `A`'s upper triangle with its symbolic Cholesky, both triangles of the
//! Newton matrix `J₁ W J₀ᵀ` with its symbolic LU, and their values.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::geometry::Coordinates;
use faer::Side;
use faer::sparse::SymbolicSparseColMat;
use faer::sparse::linalg::cholesky::{SymmetricOrdering, factorize_symbolic_cholesky};
use faer::sparse::linalg::lu::factorize_symbolic_lu;

use super::order::band_of;
use super::{NormalMatrix, Term, Unsymmetric};

impl NormalMatrix {
    /// The pattern of `J W Jᵀ` for rows whose gradient entries are
    /// `entries[row_start[r]..row_start[r + 1]]`, each naming a bead, and
    /// its symbolic factorization; `None` if faer could not allocate it.
    pub(crate) fn new(row_start: &[usize], entry_bead: &[usize], beads: usize) -> Option<Self> {
        let n = row_start.len() - 1;
        // The entries on each bead, by (row, entry).
        let mut on_bead: Vec<Vec<(usize, usize)>> = vec![Vec::new(); beads];
        for r in 0..n {
            for e in row_start[r]..row_start[r + 1] {
                on_bead[entry_bead[e]].push((r, e));
            }
        }
        // Every term, keyed by (column, row) with row ≤ column.
        let mut keyed = Vec::new();
        for entries in &on_bead {
            for &(r, er) in entries {
                for &(s, es) in entries {
                    if r <= s {
                        let bead = entry_bead[er];
                        keyed.push((
                            s,
                            r,
                            Term {
                                bead,
                                left: er,
                                right: es,
                            },
                        ));
                    }
                }
            }
        }
        keyed.sort_by_key(|&(col, row, _)| (col, row));
        let mut col_ptr = vec![0; n + 1];
        let mut row_idx = Vec::new();
        let mut term_start = Vec::new();
        let mut terms = Vec::with_capacity(keyed.len());
        let mut diagonal = vec![0; n];
        let mut last = None;
        for (col, row, term) in keyed {
            if last != Some((col, row)) {
                if row == col {
                    diagonal[col] = row_idx.len();
                }
                row_idx.push(row);
                term_start.push(terms.len());
                col_ptr[col + 1] = row_idx.len();
                last = Some((col, row));
            }
            terms.push(term);
        }
        term_start.push(terms.len());
        for c in 0..n {
            col_ptr[c + 1] = col_ptr[c + 1].max(col_ptr[c]);
        }
        let column: Vec<usize> = (0..n)
            .flat_map(|col| (col_ptr[col]..col_ptr[col + 1]).map(move |_| col))
            .collect();
        let band = band_of(&column, &row_idx, n);
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let symbolic = if n > 1 {
            let symbolic = factorize_symbolic_cholesky(
                pattern.as_ref(),
                Side::Upper,
                SymmetricOrdering::Amd,
                Default::default(),
            );
            Some(symbolic.ok()?)
        } else {
            None
        };
        static NEXT_ID: AtomicU64 = AtomicU64::new(1);
        Some(Self {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            n,
            pattern,
            diagonal,
            column,
            term_start,
            terms,
            symbolic,
            band,
            unsymmetric: OnceLock::new(),
        })
    }

    /// The stored entries of the upper triangle: `(column, value index, row)`.
    pub(super) fn upper_entries(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        self.column
            .iter()
            .zip(self.pattern.row_idx())
            .enumerate()
            .map(|(k, (&col, &row))| (col, k, row))
    }

    /// The pattern of both triangles and its symbolic LU.
    pub(super) fn unsymmetric(&self) -> Option<&Unsymmetric> {
        self.unsymmetric
            .get_or_init(|| {
                let mut keyed = Vec::new();
                for (col, k, row) in self.upper_entries() {
                    keyed.push((col, row, k, false));
                    if row != col {
                        keyed.push((row, col, k, true));
                    }
                }
                keyed.sort_by_key(|&(col, row, _, _)| (col, row));
                let mut full_col_ptr = vec![0; self.n + 1];
                for &(col, ..) in &keyed {
                    full_col_ptr[col + 1] += 1;
                }
                for c in 0..self.n {
                    full_col_ptr[c + 1] += full_col_ptr[c];
                }
                let full_row_idx = keyed.iter().map(|&(_, row, ..)| row).collect();
                let source = keyed.iter().map(|&(.., k, mirror)| (k, mirror)).collect();
                let pattern = SymbolicSparseColMat::new_checked(
                    self.n,
                    self.n,
                    full_col_ptr,
                    None,
                    full_row_idx,
                );
                let symbolic = factorize_symbolic_lu(pattern.as_ref(), Default::default()).ok()?;
                Some(Unsymmetric {
                    pattern,
                    source,
                    symbolic,
                })
            })
            .as_ref()
    }

    /// The value of `J_now W J_firstᵀ` at the upper entry `k`, or at its
    /// mirror below the diagonal; a row set aside (`inactive`, no
    /// gradient) has a unit diagonal, so its step is its right-hand side
    /// (zero, its `C`).
    pub(super) fn unsymmetric_value<V: Coordinates>(
        &self,
        (k, mirror): (usize, bool),
        inverse_mass: &[f64],
        (now, first): (&[V], &[V]),
        inactive: &[bool],
    ) -> f64 {
        let col = self.column[k];
        if self.diagonal[col] == k && inactive.get(col) == Some(&true) {
            return 1.0;
        }
        self.terms[self.term_start[k]..self.term_start[k + 1]]
            .iter()
            .map(|t| {
                let (row, col) = if mirror {
                    (t.right, t.left)
                } else {
                    (t.left, t.right)
                };
                inverse_mass[t.bead] * now[row].dot(first[col])
            })
            .sum()
    }
}
