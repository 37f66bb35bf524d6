//! The island's matrix `A = J W Jᵀ` of eq. (12): its sparsity pattern and
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
//!
//! A row set aside (a contact whose beads are apart or let go) has no
//! gradient and its λ is its right-hand side. Where rows are set aside and
//! `A` is factored sparse, only the held rows are factored: `A` on them,
//! in `A`'s own minimum-degree order restricted to them, its symbolic
//! factorization made again only when the rows set aside change. A pile's
//! island joins every pair of beads near each other by a contact row, most
//! of them set aside, so its cost is that of the rows held. The exact
//! Newton matrix gives a row set aside a unit diagonal, so its LU stays
//! regular and the row's step is its right-hand side.
//!
//! | file | what it holds |
//! |---|---|
//! | `mod` | what the matrix and its factorizations hold; filling, scaling and factoring `A`, and which solver takes each solve |
//! | `pattern` | the sparsity patterns (`A`'s upper triangle, both triangles of the Newton matrix) and their symbolic factorizations |
//! | `order` | the band ordering: the rows' own, or reverse Cuthill–McKee |
//! | `band_ldlt` | `LDLᵀ` of `A` as a band matrix, and its solve |
//! | `band_lu` | the Newton matrix `J₁ W J₀ᵀ` as a band matrix, solved by Gaussian elimination |
//! | `sparse_ldlt` | `LDLᵀ` of `A` by faer's sparse Cholesky, of all rows or of the held rows alone, and its solves |
//! | `sparse_lu` | the Newton matrix solved by faer's sparse LU |

use std::sync::OnceLock;

use crate::geometry::Coordinates;
use faer::dyn_stack::MemBuffer;
use faer::sparse::SymbolicSparseColMat;
use faer::sparse::linalg::cholesky::SymbolicCholesky;
use faer::sparse::linalg::lu::{NumericLu, SymbolicLu};

use order::Band;

mod band_ldlt;
mod band_lu;
mod order;
mod pattern;
mod sparse_ldlt;
mod sparse_lu;
#[cfg(test)]
mod tests;

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
    /// faer's sparse factorization of the held rows alone
    /// ([`HeldRows`]); a row set aside has λ = its right-hand side.
    Held,
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

/// A clone starts with no memory: it is made again when first needed.
impl Clone for Scratch {
    fn clone(&self) -> Self {
        Self::default()
    }
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
#[derive(Clone, Default)]
pub(crate) struct LuWork {
    values: Vec<f64>,
    /// The right-hand side in a band's order of the rows.
    order: Vec<f64>,
    numeric: NumericLu<usize, f64>,
    scratch: Scratch,
}

/// `A` on the rows held (those not set aside) alone, in the order of
/// `A`'s own elimination restricted to them, and the symbolic
/// factorization of that pattern, made again only when the rows held
/// change. A pile's island joins every pair of beads near each other by a
/// contact row, most of them set aside; their rows meet no other, and
/// leaving them out of the factorization leaves the held rows' solve as
/// it is and its cost that of the rows held.
#[derive(Default)]
struct HeldRows {
    /// The matrix ([`NormalMatrix::id`]) and the rows set aside the
    /// pattern was made for.
    made_for: Option<(u64, Vec<bool>)>,
    /// The rows held, by their index in `A`.
    rows: Vec<usize>,
    /// Each held value's index among `A`'s values, and its row and
    /// column in `A`.
    source: Vec<(usize, usize, usize)>,
    /// The pattern of the held rows' upper triangle and its symbolic
    /// factorization (`None` for no held row or one).
    symbolic: Option<(SymbolicSparseColMat<usize>, SymbolicCholesky<usize>)>,
    values: Vec<f64>,
    rhs: Vec<f64>,
    memory: Option<MemBuffer>,
}

/// A clone starts with no pattern: it is made again, the same, for the
/// rows held when first needed.
impl Clone for HeldRows {
    fn clone(&self) -> Self {
        Self::default()
    }
}

/// A factored `A`, kept between solves within a step.
#[derive(Clone, Default)]
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
    /// The held rows' factorization, where rows are set aside.
    held: HeldRows,
}

impl NormalMatrix {
    /// Fills and factors `A = J W Jᵀ`, in the rows' order where `natural`
    /// and the matrix is a band. Returns the index of a row whose
    /// diagonal vanishes (a singular point: no direction to push along) as
    /// the error.
    pub(crate) fn factor<V: Coordinates>(
        &self,
        inverse_mass: &[f64],
        gradient: &[V],
        inactive: &[bool],
        natural: bool,
        f: &mut Factored,
    ) -> Result<(), usize> {
        self.factor_with((inverse_mass, gradient), inactive, natural, None, f)
    }

    /// `A + E` on the rows held, `E` the `compliance` times `A`'s diagonal
    /// (a row set aside keeps a unit diagonal, its gradient zero), factored
    /// as [`NormalMatrix::factor`] factors `A` in the rows' own order: as
    /// a band where `A` is one, else the held rows alone. `A + E` is
    /// positive definite however many of the rows are redundant: a pivot
    /// is dropped only below a thousandth of the compliance.
    pub(crate) fn factor_compliant<V: Coordinates>(
        &self,
        inverse_mass: &[f64],
        gradient: &[V],
        inactive: &[bool],
        compliance: f64,
        f: &mut Factored,
    ) -> Result<(), usize> {
        self.factor_with(
            (inverse_mass, gradient),
            inactive,
            true,
            Some(compliance),
            f,
        )
    }

    /// [`NormalMatrix::factor`], `compliance` (if any) added to the scaled
    /// diagonal of the rows held.
    fn factor_with<V: Coordinates>(
        &self,
        (inverse_mass, gradient): (&[f64], &[V]),
        inactive: &[bool],
        natural: bool,
        compliance: Option<f64>,
        f: &mut Factored,
    ) -> Result<(), usize> {
        f.redundant = 0;
        if inactive.contains(&true)
            && let Some(symbolic) = &self.symbolic
            && !(natural && self.band.is_some())
        {
            f.layout = Layout::Held;
            let a = (inverse_mass, gradient);
            return self.factor_held(symbolic, a, inactive, compliance, f);
        }
        let nnz = self.term_start.len() - 1;
        f.values.clear();
        f.values
            .extend((0..nnz).map(|k| self.value(k, inverse_mass, gradient)));
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
            f.scale.push(self.diagonal_scale(r, f.values[k])?);
        }
        f.layout = Layout::Sparse;
        let Some(symbolic) = &self.symbolic else {
            // A single row: solved in closed form.
            if let (Some(c), Some(&k)) = (compliance, self.diagonal.first())
                && inactive.first() != Some(&true)
            {
                f.values[k] *= 1.0 + c;
            }
            return Ok(());
        };
        for (col, k, row) in self.upper_entries() {
            f.values[k] *= f.scale[row] * f.scale[col];
        }
        let smallest = match compliance {
            Some(c) => {
                for (r, &k) in self.diagonal.iter().enumerate() {
                    if inactive.get(r) != Some(&true) {
                        f.values[k] += c;
                    }
                }
                1e-3 * c
            }
            None => REDUNDANT_PIVOT,
        };
        if let (true, Some(band)) = (natural, &self.band) {
            f.layout = Layout::Band;
            f.redundant = self.factor_band(band, &f.values, &mut f.l_values, smallest);
            return Ok(());
        }
        self.factor_sparse(symbolic, smallest, f)
    }

    /// `A`'s diagonal value of row `r`, `Σ w_bead |g|²` over its entries.
    pub(crate) fn diagonal_value<V: Coordinates>(
        &self,
        r: usize,
        inverse_mass: &[f64],
        gradient: &[V],
    ) -> f64 {
        self.value(self.diagonal[r], inverse_mass, gradient)
    }

    /// `A`'s value `k` (upper triangle): the sum of its terms
    /// `w_bead · g_i · g_j`.
    fn value<V: Coordinates>(&self, k: usize, inverse_mass: &[f64], gradient: &[V]) -> f64 {
        self.terms[self.term_start[k]..self.term_start[k + 1]]
            .iter()
            .map(|t| inverse_mass[t.bead] * gradient[t.left].dot(gradient[t.right]))
            .sum()
    }

    /// Row `r`'s scale `1/√A_rr` from its diagonal `d`; a vanishing
    /// diagonal (a singular point) is the error, naming the row.
    fn diagonal_scale(&self, r: usize, d: f64) -> Result<f64, usize> {
        if d.is_finite() && d > 1e-300 {
            Ok(d.sqrt().recip())
        } else {
            Err(r)
        }
    }

    /// Solves `A λ = rhs` in place with the last factorization.
    pub(crate) fn solve(&self, f: &mut Factored, rhs: &mut [f64]) {
        if let (Layout::Band, Some(band)) = (f.layout, &self.band) {
            return self.solve_band(band, f, rhs);
        }
        if f.layout == Layout::Held {
            return self.solve_held(f, rhs);
        }
        let Some(symbolic) = &self.symbolic else {
            if let (Some(b), Some(&k)) = (rhs.first_mut(), self.diagonal.first()) {
                *b /= f.values[k];
            }
            return;
        };
        self.solve_sparse(symbolic, f, rhs);
    }

    /// Solves `J_now W J_firstᵀ x = rhs` in place (the exact Newton matrix
    /// of RATTLE's position solve): in the rows' order where `natural` and
    /// the matrix is a band, else by faer's sparse LU. A row set aside
    /// (`inactive`, no gradient) steps by its right-hand side. Returns
    /// `false` where the matrix is singular or faer could not factor it.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn solve_unsymmetric<V: Coordinates>(
        &self,
        inverse_mass: &[f64],
        now: &[V],
        first: &[V],
        inactive: &[bool],
        lu: &mut LuWork,
        rhs: &mut [f64],
        natural: bool,
    ) -> bool {
        if let (true, Some(band)) = (natural, &self.band) {
            let LuWork { values, order, .. } = lu;
            return self.solve_unsymmetric_band(
                band,
                inverse_mass,
                now,
                first,
                inactive,
                values,
                order,
                rhs,
            );
        }
        self.solve_unsymmetric_sparse(inverse_mass, now, first, inactive, lu, rhs)
    }
}
