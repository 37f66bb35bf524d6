//! The Newton matrix `J₁ W J₀ᵀ` of RATTLE's position solve by faer's
//! sparse LU, for an island whose matrix is not a band.

use crate::geometry::Coordinates;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SparseColMatRef;
use faer::{Conj, MatMut, Par};

use super::{LuWork, NormalMatrix};

impl NormalMatrix {
    /// [`NormalMatrix::solve_unsymmetric`] by faer's sparse LU on the
    /// pattern of both triangles. Returns `false` where the matrix is
    /// singular or faer could not factor it.
    pub(super) fn solve_unsymmetric_sparse<V: Coordinates>(
        &self,
        inverse_mass: &[f64],
        now: &[V],
        first: &[V],
        inactive: &[bool],
        lu: &mut LuWork,
        rhs: &mut [f64],
    ) -> bool {
        let Some(u) = self.unsymmetric() else {
            return false;
        };
        lu.values.clear();
        lu.values.extend(
            u.source.iter().map(|&source| {
                self.unsymmetric_value(source, inverse_mass, (now, first), inactive)
            }),
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
}
