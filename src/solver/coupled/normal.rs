//! The island's matrix `A = J W Jᵀ` of eq. (10): its sparsity pattern and
//! symbolic factorization, built once per topology, and the numeric
//! factorization and solves of each step.
//!
//! `A` is symmetric positive semidefinite, with a nonzero `(r, s)` wherever
//! rows `r` and `s` share a bead. It is scaled to a unit diagonal
//! (`S A S`, `S = diag(1/√A_rr)`) and factored `LDLᵀ`. An island with no
//! friction is factored as a band matrix where that is cheap: where no two
//! rows more than [`MAX_BAND`] apart share a bead (a rope or chain listed
//! link by link, with its pin), in the rows' own order or else in a reverse
//! Cuthill–McKee order of them (a chain listed in any order, a ring of
//! rods), and for up to eight rows whatever the band (a small dense
//! matrix). The cost is linear in the rows, with no fill outside the band.
//! (Which rows of a redundant set carry the load decides which bead static
//! friction releases, so a rough island keeps the sparse order.) Otherwise
//! it is factored by faer's sparse Cholesky under an
//! approximate-minimum-degree ordering, which for a chain or tree of rods
//! eliminates leaf by leaf with no fill-in, so the cost is linear in the
//! number of rows (Baraff 1996). A closed loop adds a little fill and still
//! factors.
//!
//! Redundant constraints (the same rod twice; a chain pulled straight
//! between two pins) make `A` singular. A pivot that falls below
//! [`REDUNDANT_PIVOT`] of its row's scale is replaced by a huge one, which
//! drops that row from the solve: its λ is zero and the other rows carry
//! the load, so consistent redundant constraints hold with no NaN and no
//! panic, and [`NormalMatrix::factor`] counts them.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};

use bevy::math::DVec2;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    LdltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::linalg::lu::{NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

/// A scaled pivot at or below this is taken as a redundant row.
pub const REDUNDANT_PIVOT: f64 = 1e-10;
/// What a redundant row's pivot is replaced by: its λ becomes zero.
const DROPPED_PIVOT: f64 = 1e30;
/// Islands of at most this many rows factor `A` and the Newton matrix in
/// their rows' order whatever their band (as small dense matrices): for a
/// pendulum on a cart (two rows) the sparse machinery costs more than the
/// arithmetic.
const DENSE_ROWS: usize = 8;
/// The widest band (rows apart that share a bead) factored as a band
/// matrix: a pinned rope listed link by link has 2.
pub const MAX_BAND: usize = 4;

/// How a factorization is laid out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Layout {
    /// faer's sparse factorization, or a single row in closed form.
    #[default]
    Sparse,
    /// A band matrix: row `i`'s `D` and the `L` entries left of it.
    Band,
}

/// A band ordering of the rows: no two rows that share a bead are more
/// than `width` places apart.
#[derive(Clone, Debug)]
struct Band {
    width: usize,
    /// Each row's place in the band (`None`: its own index).
    position: Option<Vec<usize>>,
}

impl Band {
    /// Row `r`'s place in the band.
    #[inline(always)]
    fn at(&self, r: usize) -> usize {
        self.position.as_ref().map_or(r, |p| p[r])
    }

    /// `rhs` (by row) into `out` (by place in the band).
    fn gather(&self, rhs: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.resize(rhs.len(), 0.0);
        for (r, &b) in rhs.iter().enumerate() {
            out[self.at(r)] = b;
        }
    }

    /// `solved` (by place in the band) back into `rhs` (by row).
    fn scatter(&self, solved: &[f64], rhs: &mut [f64]) {
        for (r, b) in rhs.iter_mut().enumerate() {
            *b = solved[self.at(r)];
        }
    }
}

/// The band ordering of a matrix of `n` rows whose upper entries are at
/// `(row[k], column[k])`: the rows' own order where its band is at most
/// [`MAX_BAND`] or there are at most [`DENSE_ROWS`] rows, else a reverse
/// Cuthill–McKee order where that band is at most [`MAX_BAND`].
fn band_of(column: &[usize], row: &[usize], n: usize) -> Option<Band> {
    let width = |at: &dyn Fn(usize) -> usize| {
        column
            .iter()
            .zip(row)
            .map(|(&c, &r)| at(c).abs_diff(at(r)))
            .max()
            .unwrap_or(0)
    };
    let own = width(&|r| r);
    if n <= DENSE_ROWS || own <= MAX_BAND {
        return Some(Band {
            width: own,
            position: None,
        });
    }
    let mut neighbours = vec![Vec::new(); n];
    for (&c, &r) in column.iter().zip(row) {
        if c != r {
            neighbours[c].push(r);
            neighbours[r].push(c);
        }
    }
    let position = cuthill_mckee(&neighbours);
    let reordered = width(&|r| position[r]);
    (reordered <= MAX_BAND).then_some(Band {
        width: reordered,
        position: Some(position),
    })
}

/// Solves the band matrix `m` of half-width `p` (largest entry `largest`)
/// in place of `rhs`: Gaussian elimination with partial pivoting among
/// the `p` rows below, which widens the upper band to `2p`. The row at
/// position `i` keeps columns `i − p ..= i + 2p` in `m[i·(3p+1)..]`. A
/// pivot below [`REDUNDANT_PIVOT`] of `largest` is a singular matrix:
/// `false`.
fn eliminate_band(p: usize, largest: f64, m: &mut [f64], rhs: &mut [f64]) -> bool {
    let (n, w) = (rhs.len(), 3 * p + 1);
    // Entry (i, c) of the row at position i.
    let at = |i: usize, c: usize| i * w + c + p - i;
    for j in 0..n {
        let below = (j + p).min(n - 1);
        let right = (j + 2 * p).min(n - 1);
        let mut pivot = j;
        for i in j + 1..=below {
            if m[at(i, j)].abs() > m[at(pivot, j)].abs() {
                pivot = i;
            }
        }
        if m[at(pivot, j)].abs() <= REDUNDANT_PIVOT * largest {
            return false;
        }
        if pivot != j {
            for c in j..=right {
                m.swap(at(j, c), at(pivot, c));
            }
            rhs.swap(j, pivot);
        }
        let d = m[at(j, j)];
        for i in j + 1..=below {
            let factor = m[at(i, j)] / d;
            if factor == 0.0 {
                continue;
            }
            for c in j..=right {
                m[at(i, c)] -= factor * m[at(j, c)];
            }
            rhs[i] -= factor * rhs[j];
        }
    }
    for i in (0..n).rev() {
        let mut x = rhs[i];
        for c in i + 1..=(i + 2 * p).min(n - 1) {
            x -= m[at(i, c)] * rhs[c];
        }
        rhs[i] = x / m[at(i, i)];
    }
    rhs.iter().all(|x| x.is_finite())
}

/// Solves `L D Lᵀ x = rhs` in place with the band factors of
/// [`NormalMatrix::factor_band`] (half-width `p`, rows in the band's order).
fn substitute_band(p: usize, a: &[f64], rhs: &mut [f64]) {
    let (n, w) = (rhs.len(), p + 1);
    for i in 0..n {
        for k in i.saturating_sub(p)..i {
            rhs[i] -= a[i * w + i - k] * rhs[k];
        }
    }
    for i in 0..n {
        rhs[i] /= a[i * w];
    }
    for i in (0..n).rev() {
        for k in i + 1..(i + p + 1).min(n) {
            rhs[i] -= a[k * w + k - i] * rhs[k];
        }
    }
}

/// Each row's place in a reverse Cuthill–McKee order of the rows, where
/// `neighbours[r]` are the rows that share a bead with row `r`: a
/// breadth-first walk from a row of fewest neighbours, each row's new
/// neighbours taken fewest first, reversed. For a chain of rods listed in
/// any order it gives back the chain's band; a ring of rods gets a band of
/// two.
fn cuthill_mckee(neighbours: &[Vec<usize>]) -> Vec<usize> {
    let n = neighbours.len();
    let degree = |r: usize| neighbours[r].len();
    let mut starts: Vec<usize> = (0..n).collect();
    starts.sort_by_key(|&r| degree(r));
    let mut placed = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut next = Vec::new();
    for start in starts {
        if placed[start] {
            continue;
        }
        placed[start] = true;
        order.push(start);
        let mut head = order.len() - 1;
        while head < order.len() {
            let r = order[head];
            head += 1;
            next.clear();
            next.extend(neighbours[r].iter().copied().filter(|&s| !placed[s]));
            next.sort_by_key(|&s| degree(s));
            for &s in &next {
                placed[s] = true;
                order.push(s);
            }
        }
    }
    let mut position = vec![0; n];
    for (place, &r) in order.iter().rev().enumerate() {
        position[r] = place;
    }
    position
}

/// One product `w_bead · g_i · g_j` that makes up an entry of `A`.
#[derive(Clone, Copy, Debug)]
struct Term {
    bead: usize,
    /// The gradient entry of the entry's row.
    left: usize,
    /// The gradient entry of the entry's column.
    right: usize,
}

/// faer's scratch memory, and the [`NormalMatrix::id`] it was made for.
#[derive(Default)]
struct Scratch {
    owner: u64,
    memory: Option<MemBuffer>,
}

/// `A`'s pattern (upper triangle, by columns) and its symbolic
/// factorization.
pub(crate) struct NormalMatrix {
    /// Unique among the matrices of a run, so scratch memory made for
    /// another matrix is never used for this one.
    id: u64,
    n: usize,
    pattern: SymbolicSparseColMat<usize>,
    /// Where each diagonal entry sits among the values.
    diagonal: Vec<usize>,
    /// The column of each value.
    column: Vec<usize>,
    /// The terms of value `k` are `terms[term_start[k]..term_start[k + 1]]`.
    term_start: Vec<usize>,
    terms: Vec<Term>,
    /// `None` for a single row, solved in closed form.
    symbolic: Option<SymbolicCholesky<usize>>,
    /// Where `A` may be factored as a band matrix: at most [`DENSE_ROWS`]
    /// rows, or a band of at most [`MAX_BAND`] in the rows' order or in a
    /// reverse Cuthill–McKee order of them.
    band: Option<Band>,
    /// The full pattern for the unsymmetric `J₁ W J₀ᵀ`, made when first
    /// needed; `None` inside if faer could not set it up.
    unsymmetric: OnceLock<Option<Unsymmetric>>,
}

/// The full (both triangles) pattern of `J₁ W J₀ᵀ` and its symbolic LU.
struct Unsymmetric {
    pattern: SymbolicSparseColMat<usize>,
    /// For each value: the upper-triangle entry it comes from, and whether
    /// it is that entry's mirror below the diagonal.
    source: Vec<(usize, bool)>,
    symbolic: SymbolicLu<usize>,
}

/// The numeric LU of `J₁ W J₀ᵀ` and its scratch memory, kept between
/// solves so that a Newton iteration allocates nothing.
#[derive(Default)]
pub(crate) struct LuWork {
    values: Vec<f64>,
    /// The right-hand side in a band's order of the rows.
    order: Vec<f64>,
    numeric: NumericLu<usize, f64>,
    scratch: Scratch,
}

/// A factored `A`, kept between solves within a step.
#[derive(Default)]
pub(crate) struct Factored {
    values: Vec<f64>,
    scale: Vec<f64>,
    l_values: Vec<f64>,
    scratch: Scratch,
    /// How many rows the factorization dropped as redundant.
    pub(crate) redundant: usize,
    /// How `l_values` holds the factorization.
    layout: Layout,
    /// The right-hand side in a band's order of the rows.
    order: Vec<f64>,
}

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
    fn upper_entries(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        self.column
            .iter()
            .zip(self.pattern.row_idx())
            .enumerate()
            .map(|(k, (&col, &row))| (col, k, row))
    }

    /// The pattern of both triangles and its symbolic LU.
    fn unsymmetric(&self) -> Option<&Unsymmetric> {
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

    /// Solves `J_now W J_firstᵀ x = rhs` in place (the exact Newton matrix
    /// of RATTLE's position solve): in the rows' order where `natural` and
    /// the matrix is a band, else by faer's sparse LU. Returns
    /// `false` where the matrix is singular or faer could not factor it.
    pub(crate) fn solve_unsymmetric(
        &self,
        inverse_mass: &[f64],
        now: &[DVec2],
        first: &[DVec2],
        lu: &mut LuWork,
        rhs: &mut [f64],
        natural: bool,
    ) -> bool {
        if let (true, Some(band)) = (natural, &self.band) {
            let LuWork { values, order, .. } = lu;
            return self.solve_unsymmetric_band(band, inverse_mass, now, first, values, order, rhs);
        }
        let Some(u) = self.unsymmetric() else {
            return false;
        };
        lu.values.clear();
        lu.values.extend(
            u.source
                .iter()
                .map(|&(k, mirror)| self.unsymmetric_value(k, mirror, inverse_mass, now, first)),
        );
        if lu.scratch.owner != self.id {
            lu.scratch.memory = None;
            lu.scratch.owner = self.id;
        }
        let memory = lu.scratch.memory.get_or_insert_with(|| {
            MemBuffer::new(
                u.symbolic
                    .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default())
                    .or(u.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq)),
            )
        });
        let stack = MemStack::new(memory);
        let matrix = SparseColMatRef::new(u.pattern.as_ref(), &lu.values);
        let Ok(factored) = u.symbolic.factorize_numeric_lu(
            &mut lu.numeric,
            matrix,
            Par::Seq,
            stack,
            Default::default(),
        ) else {
            return false;
        };
        factored.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, self.n, 1),
            Par::Seq,
            stack,
        );
        rhs.iter().all(|x| x.is_finite())
    }

    /// The value of `J_now W J_firstᵀ` at the upper entry `k`, or at its
    /// mirror below the diagonal.
    fn unsymmetric_value(
        &self,
        k: usize,
        mirror: bool,
        inverse_mass: &[f64],
        now: &[DVec2],
        first: &[DVec2],
    ) -> f64 {
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

    /// [`NormalMatrix::solve_unsymmetric`] for a band matrix: filled in the
    /// band's order of the rows, solved by [`eliminate_band`] (in `order`
    /// where the band reorders the rows).
    #[allow(clippy::too_many_arguments)]
    fn solve_unsymmetric_band(
        &self,
        band: &Band,
        inverse_mass: &[f64],
        now: &[DVec2],
        first: &[DVec2],
        m: &mut Vec<f64>,
        order: &mut Vec<f64>,
        rhs: &mut [f64],
    ) -> bool {
        let (n, p) = (self.n, band.width);
        let w = 3 * p + 1;
        m.clear();
        m.resize(n * w, 0.0);
        let mut largest = 0.0f64;
        for (col, k, row) in self.upper_entries() {
            let (i, c) = (band.at(row), band.at(col));
            let upper = self.unsymmetric_value(k, false, inverse_mass, now, first);
            m[i * w + c + p - i] = upper;
            largest = largest.max(upper.abs());
            if row != col {
                let lower = self.unsymmetric_value(k, true, inverse_mass, now, first);
                m[c * w + i + p - c] = lower;
                largest = largest.max(lower.abs());
            }
        }
        if !(largest.is_finite() && largest > 0.0) {
            return false;
        }
        if band.position.is_none() {
            return eliminate_band(p, largest, m, rhs);
        }
        band.gather(rhs, order);
        let solved = eliminate_band(p, largest, m, order);
        band.scatter(order, rhs);
        solved
    }

    /// `LDLᵀ` of the scaled `A` as a band matrix of half-width `p`, its
    /// rows in the band's order: row `i` at `a[i·(p+1)..]`, `D_ii` first,
    /// then `L_{i,i−1}` to `L_{i,i−p}`. A pivot at or below [`REDUNDANT_PIVOT`] is replaced by
    /// [`DROPPED_PIVOT`], as the sparse factorization does. Returns how
    /// many were.
    fn factor_band(&self, band: &Band, values: &[f64], a: &mut Vec<f64>) -> usize {
        let (n, p) = (self.n, band.width);
        let w = p + 1;
        a.clear();
        a.resize(n * w, 0.0);
        for (col, k, row) in self.upper_entries() {
            let (i, j) = (band.at(row), band.at(col));
            let (low, high) = (i.min(j), i.max(j));
            a[high * w + high - low] = values[k];
        }
        let mut dropped = 0;
        for j in 0..n {
            let low = j.saturating_sub(p);
            for k in low..j {
                let mut v = a[j * w + j - k];
                for m in low.max(k.saturating_sub(p))..k {
                    v -= a[j * w + j - m] * a[k * w + k - m] * a[m * w];
                }
                a[j * w + j - k] = v / a[k * w];
            }
            let mut d = a[j * w];
            for k in low..j {
                let l = a[j * w + j - k];
                d -= l * l * a[k * w];
            }
            if d.abs() <= REDUNDANT_PIVOT {
                d = DROPPED_PIVOT;
                dropped += 1;
            }
            a[j * w] = d;
        }
        dropped
    }

    /// [`NormalMatrix::solve`] with the band `LDLᵀ` of
    /// [`NormalMatrix::factor_band`].
    fn solve_band(&self, band: &Band, f: &mut Factored, rhs: &mut [f64]) {
        for (b, s) in rhs.iter_mut().zip(&f.scale) {
            *b *= s;
        }
        if band.position.is_none() {
            substitute_band(band.width, &f.l_values, rhs);
        } else {
            band.gather(rhs, &mut f.order);
            substitute_band(band.width, &f.l_values, &mut f.order);
            band.scatter(&f.order, rhs);
        }
        for (b, s) in rhs.iter_mut().zip(&f.scale) {
            *b *= s;
        }
    }

    /// Fills and factors `A = J W Jᵀ`, in the rows' order where `natural`
    /// and the matrix is a band. Returns the index of a row whose
    /// diagonal vanishes (a singular point: no direction to push along) as
    /// the error.
    pub(crate) fn factor(
        &self,
        inverse_mass: &[f64],
        gradient: &[DVec2],
        inactive: &[bool],
        natural: bool,
        f: &mut Factored,
    ) -> Result<(), usize> {
        let nnz = self.term_start.len() - 1;
        f.values.clear();
        f.values.extend((0..nnz).map(|k| {
            self.terms[self.term_start[k]..self.term_start[k + 1]]
                .iter()
                .map(|t| inverse_mass[t.bead] * gradient[t.left].dot(gradient[t.right]))
                .sum::<f64>()
        }));
        f.scale.clear();
        for (r, &k) in self.diagonal.iter().enumerate() {
            if inactive.get(r) == Some(&true) {
                // A row set aside (a one-sided wire the bead has left): its
                // gradient is zero, so it meets no other row; a unit
                // diagonal gives it λ = 0.
                f.values[k] = 1.0;
                f.scale.push(1.0);
                continue;
            }
            let d = f.values[k];
            if !(d.is_finite() && d > 1e-300) {
                return Err(r);
            }
            f.scale.push(d.sqrt().recip());
        }
        f.redundant = 0;
        f.layout = Layout::Sparse;
        let Some(symbolic) = &self.symbolic else {
            // A single row: solved in closed form.
            return Ok(());
        };
        for (col, k, row) in self.upper_entries() {
            f.values[k] *= f.scale[row] * f.scale[col];
        }
        if let (true, Some(band)) = (natural, &self.band) {
            f.layout = Layout::Band;
            f.redundant = self.factor_band(band, &f.values, &mut f.l_values);
            return Ok(());
        }
        f.l_values.clear();
        f.l_values.resize(symbolic.len_val(), 0.0);
        let memory = self.scratch(symbolic, &mut f.scratch);
        let a = SparseColMatRef::new(self.pattern.as_ref(), &f.values);
        symbolic
            .factorize_numeric_ldlt(
                &mut f.l_values,
                a,
                Side::Upper,
                LdltRegularization {
                    dynamic_regularization_signs: None,
                    dynamic_regularization_delta: DROPPED_PIVOT,
                    dynamic_regularization_epsilon: REDUNDANT_PIVOT,
                },
                Par::Seq,
                MemStack::new(memory),
                Default::default(),
            )
            .map_err(|_| 0usize)?;
        f.redundant = f.l_values.iter().filter(|&&v| v == DROPPED_PIVOT).count();
        Ok(())
    }

    /// Solves `A λ = rhs` in place with the last factorization.
    pub(crate) fn solve(&self, f: &mut Factored, rhs: &mut [f64]) {
        if let (Layout::Band, Some(band)) = (f.layout, &self.band) {
            return self.solve_band(band, f, rhs);
        }
        let Some(symbolic) = &self.symbolic else {
            if let (Some(b), Some(&k)) = (rhs.first_mut(), self.diagonal.first()) {
                *b /= f.values[k];
            }
            return;
        };
        for (b, s) in rhs.iter_mut().zip(&f.scale) {
            *b *= s;
        }
        let ldlt = LdltRef::new(symbolic, &f.l_values);
        let memory = self.scratch(symbolic, &mut f.scratch);
        ldlt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, self.n, 1),
            Par::Seq,
            MemStack::new(memory),
        );
        for (b, s) in rhs.iter_mut().zip(&f.scale) {
            *b *= s;
        }
    }

    /// The scratch memory faer's factorization and solve need, made once
    /// for this matrix.
    fn scratch<'a>(
        &self,
        symbolic: &SymbolicCholesky<usize>,
        scratch: &'a mut Scratch,
    ) -> &'a mut MemBuffer {
        if scratch.owner != self.id {
            scratch.memory = None;
            scratch.owner = self.id;
        }
        scratch.memory.get_or_insert_with(|| {
            MemBuffer::new(
                symbolic
                    .factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default())
                    .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq)),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pinned chain of `links` rods bent at the beads, and a second set
    /// of gradients turned a little from the first: rows 0 and 1 pin bead
    /// 0, row 2 + i joins beads i and i + 1.
    fn chain(links: usize) -> Rows {
        let mut row_start = vec![0, 1, 2];
        let mut entry_bead = vec![0, 0];
        let mut first = vec![DVec2::X, DVec2::Y];
        let mut now = vec![DVec2::X, DVec2::Y];
        for i in 0..links {
            entry_bead.extend([i, i + 1]);
            let n = DVec2::from_angle(0.4 * i as f64);
            let turned = DVec2::from_angle(0.4 * i as f64 + 0.05);
            first.extend([-n, n]);
            now.extend([-turned, turned]);
            row_start.push(entry_bead.len());
        }
        let inverse_mass = (0..=links).map(|i| 1.0 / (1.0 + i as f64)).collect();
        (row_start, entry_bead, first, now, inverse_mass)
    }

    /// Rows as [`chain`] gives them: row starts, each entry's bead, the
    /// first and the current gradients, the inverse masses.
    type Rows = (Vec<usize>, Vec<usize>, Vec<DVec2>, Vec<DVec2>, Vec<f64>);

    /// A ring of `beads` rods, each bead joined to the next and the last to
    /// the first, with gradients as [`chain`]'s.
    fn ring(beads: usize) -> Rows {
        let (mut row_start, mut entry_bead, mut first, mut now) = (vec![0], vec![], vec![], vec![]);
        for i in 0..beads {
            entry_bead.extend([i, (i + 1) % beads]);
            let n = DVec2::from_angle(0.4 * i as f64);
            let turned = DVec2::from_angle(0.4 * i as f64 + 0.05);
            first.extend([-n, n]);
            now.extend([-turned, turned]);
            row_start.push(entry_bead.len());
        }
        let inverse_mass = (0..beads).map(|i| 1.0 / (1.0 + i as f64)).collect();
        (row_start, entry_bead, first, now, inverse_mass)
    }

    /// The same rows listed in another order: row `r` becomes row
    /// `(r · stride) mod n` (`stride` prime to the number of rows `n`).
    fn shuffled((row_start, entry_bead, first, now, inverse_mass): Rows, stride: usize) -> Rows {
        let n = row_start.len() - 1;
        let mut from = vec![usize::MAX; n];
        for r in 0..n {
            from[(r * stride) % n] = r;
        }
        assert!(!from.contains(&usize::MAX), "{stride} is not prime to {n}");
        let (mut starts, mut beads, mut firsts, mut nows) = (vec![0], vec![], vec![], vec![]);
        for &r in &from {
            let entries = row_start[r]..row_start[r + 1];
            beads.extend_from_slice(&entry_bead[entries.clone()]);
            firsts.extend_from_slice(&first[entries.clone()]);
            nows.extend_from_slice(&now[entries]);
            starts.push(beads.len());
        }
        (starts, beads, firsts, nows, inverse_mass)
    }

    /// Solves `J W Jᵀ x = b` and `J_now W J_firstᵀ x = b` for `rows` in
    /// the rows' order or a band's (`natural`) and in faer's sparse order,
    /// and checks the two agree to 1e-12; returns the layout of the
    /// natural order's factorization and whether its band reorders the
    /// rows.
    fn natural_matches_sparse_for(rows: &Rows, what: &str) -> (Layout, bool) {
        let (row_start, entry_bead, first, now, inverse_mass) = rows;
        let matrix = NormalMatrix::new(row_start, entry_bead, inverse_mass.len()).unwrap();
        let n = row_start.len() - 1;
        let rhs: Vec<f64> = (0..n).map(|r| (r as f64 * 0.7).sin() - 0.2).collect();
        let inactive = vec![false; n];
        let mut solved = [rhs.clone(), rhs.clone()];
        let mut layout = Layout::Sparse;
        for (natural, x) in [true, false].into_iter().zip(&mut solved) {
            let mut f = Factored::default();
            matrix
                .factor(inverse_mass, first, &inactive, natural, &mut f)
                .unwrap();
            assert_eq!(f.redundant, 0, "{what}");
            if natural {
                layout = f.layout;
            }
            matrix.solve(&mut f, x);
        }
        let mut unsymmetric = [rhs.clone(), rhs.clone()];
        for (natural, x) in [true, false].into_iter().zip(&mut unsymmetric) {
            let mut lu = LuWork::default();
            assert!(matrix.solve_unsymmetric(inverse_mass, now, first, &mut lu, x, natural));
        }
        for [a, b] in [solved, unsymmetric] {
            for (a, b) in a.iter().zip(&b) {
                assert!(
                    (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                    "{what}: {a} against {b}"
                );
            }
        }
        let reordered = matrix.band.as_ref().is_some_and(|b| b.position.is_some());
        (layout, reordered)
    }

    /// [`natural_matches_sparse_for`] a chain of `links` rods in order.
    fn natural_matches_sparse(links: usize) -> Layout {
        natural_matches_sparse_for(&chain(links), &format!("{links} links")).0
    }

    #[test]
    fn small_matrices_in_the_rows_order_match_the_sparse_ones() {
        for links in [1, 3, 6] {
            assert_eq!(natural_matches_sparse(links), Layout::Band);
        }
    }

    #[test]
    fn band_solves_of_a_long_chain_match_the_sparse_ones() {
        // The pin's rows and the first rod share bead 0: a band of 2.
        for links in [7, 40, 500] {
            assert_eq!(natural_matches_sparse(links), Layout::Band);
        }
    }

    #[test]
    fn a_chain_listed_out_of_order_and_a_ring_are_solved_as_bands_once_reordered() {
        for links in [40, 500] {
            // Out of order the rows' own band is wide; reordered it is 2.
            let rows = shuffled(chain(links), 11);
            let what = format!("{links} links out of order");
            assert_eq!(
                natural_matches_sparse_for(&rows, &what),
                (Layout::Band, true)
            );
        }
        for beads in [9, 40, 300] {
            let what = format!("a ring of {beads} rods");
            assert_eq!(
                natural_matches_sparse_for(&ring(beads), &what),
                (Layout::Band, true)
            );
        }
        // A chain in order keeps its own order.
        assert_eq!(
            natural_matches_sparse_for(&chain(40), "40 links"),
            (Layout::Band, false)
        );
    }

    #[test]
    fn a_band_matrix_drops_a_redundant_row_and_refuses_a_singular_newton_matrix() {
        // A pinned chain of 20 rods, rod 10 listed twice.
        let (mut row_start, mut entry_bead, mut gradient, _, _) = chain(20);
        let twin = 2 + 10;
        let entries = row_start[twin]..row_start[twin + 1];
        let (beads, grads): (Vec<_>, Vec<_>) = entries
            .clone()
            .map(|e| (entry_bead[e], gradient[e]))
            .unzip();
        entry_bead.splice(entries.end..entries.end, beads);
        gradient.splice(entries.end..entries.end, grads);
        row_start.insert(twin + 1, entries.end);
        for start in &mut row_start[twin + 2..] {
            *start += 2;
        }
        let rows = row_start.len() - 1;
        let matrix = NormalMatrix::new(&row_start, &entry_bead, 21).unwrap();
        let band = matrix.band.as_ref().expect("a band");
        assert_eq!((band.width, band.position.is_none()), (2, true));
        let inverse_mass = vec![1.0; 21];
        let mut f = Factored::default();
        matrix
            .factor(&inverse_mass, &gradient, &vec![false; rows], true, &mut f)
            .unwrap();
        assert_eq!((f.layout, f.redundant), (Layout::Band, 1));
        // Every rod asks for the same push; the twins share one rod's.
        let mut rhs: Vec<f64> = (0..rows).map(|r| if r < 2 { 0.0 } else { 0.3 }).collect();
        let b = rhs.clone();
        matrix.solve(&mut f, &mut rhs);
        assert!(rhs.iter().all(|x| x.is_finite()), "{rhs:?}");
        assert_eq!(
            rhs[twin + 1],
            0.0,
            "the redundant row carries {}",
            rhs[twin + 1]
        );
        // A λ that meets every row: J W Jᵀ λ = b.
        let mut pushed = vec![DVec2::ZERO; 21];
        for r in 0..rows {
            for e in row_start[r]..row_start[r + 1] {
                pushed[entry_bead[e]] += rhs[r] * gradient[e];
            }
        }
        for r in 0..rows {
            let met: f64 = (row_start[r]..row_start[r + 1])
                .map(|e| gradient[e].dot(pushed[entry_bead[e]]))
                .sum();
            assert!(
                (met - b[r]).abs() <= 1e-12,
                "row {r}: {met} against {}",
                b[r]
            );
        }
        let mut lu = LuWork::default();
        assert!(!matrix.solve_unsymmetric(
            &inverse_mass,
            &gradient,
            &gradient,
            &mut lu,
            &mut rhs,
            true
        ));
    }

    #[test]
    fn a_small_matrix_drops_a_redundant_row_and_refuses_a_singular_newton_matrix() {
        // The same rod twice between a pinned bead and a free one.
        let row_start = [0, 1, 2, 4, 6];
        let entry_bead = [0, 0, 0, 1, 0, 1];
        let n = DVec2::new(0.6, 0.8);
        let gradient = [DVec2::X, DVec2::Y, -n, n, -n, n];
        let matrix = NormalMatrix::new(&row_start, &entry_bead, 2).unwrap();
        let mut f = Factored::default();
        matrix
            .factor(&[1.0, 1.0], &gradient, &[false; 4], true, &mut f)
            .unwrap();
        assert_eq!((f.layout, f.redundant), (Layout::Band, 1));
        // A consistent right-hand side: the two rods ask for the same.
        let mut rhs = vec![0.0, 0.0, 0.3, 0.3];
        matrix.solve(&mut f, &mut rhs);
        assert!(rhs.iter().all(|x| x.is_finite()), "{rhs:?}");
        // With the pin rows taking bead 0's share the system reduces to
        // λ₂ + λ₃ = 0.3: one rod carries it, the dropped one nothing.
        let pushed = rhs[2] + rhs[3];
        assert!((pushed - 0.3).abs() <= 1e-12, "the rods carry {pushed}");
        assert_eq!(rhs[3], 0.0, "the redundant row carries {}", rhs[3]);
        let mut lu = LuWork::default();
        let mut rhs = vec![0.0, 0.0, 0.3, 0.3];
        assert!(!matrix.solve_unsymmetric(
            &[1.0, 1.0],
            &gradient,
            &gradient,
            &mut lu,
            &mut rhs,
            true
        ));
    }
}
