//! `LDLᵀ` of the scaled `A` by faer's sparse Cholesky, its solve, and the
//! scratch memory they need.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::SparseColMatRef;
use faer::sparse::linalg::cholesky::{LdltRef, SymbolicCholesky};
use faer::{Conj, MatMut, Par, Side};

use super::{DROPPED_PIVOT, Factored, NormalMatrix, REDUNDANT_PIVOT, Scratch};

impl NormalMatrix {
    /// `LDLᵀ` of the scaled `A` (filled into `f.values`) by faer's sparse
    /// Cholesky under `symbolic`'s ordering: a pivot at or below
    /// [`REDUNDANT_PIVOT`] is replaced by [`DROPPED_PIVOT`], and counted.
    pub(super) fn factor_sparse(
        &self,
        symbolic: &SymbolicCholesky<usize>,
        f: &mut Factored,
    ) -> Result<(), usize> {
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

    /// [`NormalMatrix::solve`] with faer's sparse `LDLᵀ` of
    /// [`NormalMatrix::factor_sparse`].
    pub(super) fn solve_sparse(
        &self,
        symbolic: &SymbolicCholesky<usize>,
        f: &mut Factored,
        rhs: &mut [f64],
    ) {
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
