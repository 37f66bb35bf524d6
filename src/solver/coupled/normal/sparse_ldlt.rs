//! `LDLᵀ` of the scaled `A` by faer's sparse Cholesky, of all its rows or
//! of the rows held alone, their solves, and the scratch memory they need.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    LdltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

use crate::geometry::Coordinates;

use super::{DROPPED_PIVOT, Factored, HeldRows, NormalMatrix, REDUNDANT_PIVOT, Scratch};

/// How faer's `LDLᵀ` treats a pivot: at or below `smallest` it becomes
/// [`DROPPED_PIVOT`].
fn dropping(smallest: f64) -> LdltRegularization<'static, f64> {
    LdltRegularization {
        dynamic_regularization_signs: None,
        dynamic_regularization_delta: DROPPED_PIVOT,
        dynamic_regularization_epsilon: smallest,
    }
}

/// `LDLᵀ` of `a` under `symbolic` into `l_values`, each pivot at or below
/// `smallest` dropped ([`dropping`]): how many were (none counted below
/// [`REDUNDANT_PIVOT`], where the matrix is made compliant).
fn factor_dropping(
    symbolic: &SymbolicCholesky<usize>,
    a: SparseColMatRef<'_, usize, f64>,
    smallest: f64,
    memory: &mut MemBuffer,
    l_values: &mut Vec<f64>,
) -> Result<usize, usize> {
    l_values.clear();
    l_values.resize(symbolic.len_val(), 0.0);
    symbolic
        .factorize_numeric_ldlt(
            l_values,
            a,
            Side::Upper,
            dropping(smallest),
            Par::Seq,
            MemStack::new(memory),
            Default::default(),
        )
        .map_err(|_| 0usize)?;
    // A compliant matrix drops none worth counting (and counting reads
    // every entry of the factor).
    if smallest < REDUNDANT_PIVOT {
        return Ok(0);
    }
    Ok(l_values.iter().filter(|&&v| v == DROPPED_PIVOT).count())
}

/// The scratch memory faer's `LDLᵀ` under `symbolic` needs, to factor
/// and to solve.
fn ldlt_memory(symbolic: &SymbolicCholesky<usize>) -> MemBuffer {
    MemBuffer::new(
        symbolic
            .factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq)),
    )
}

/// Solves `L D Lᵀ x = b` in place in `x` with the factor `l_values` of
/// `symbolic`.
fn ldlt_solve(
    symbolic: &SymbolicCholesky<usize>,
    l_values: &[f64],
    memory: &mut MemBuffer,
    x: &mut [f64],
) {
    let n = x.len();
    LdltRef::new(symbolic, l_values).solve_in_place_with_conj(
        Conj::No,
        MatMut::from_column_major_slice_mut(x, n, 1),
        Par::Seq,
        MemStack::new(memory),
    );
}

impl NormalMatrix {
    /// `LDLᵀ` of the scaled `A` (filled into `f.values`) by faer's sparse
    /// Cholesky under `symbolic`'s ordering: a pivot at or below
    /// `smallest` ([`REDUNDANT_PIVOT`] unless the matrix is made compliant)
    /// is replaced by [`DROPPED_PIVOT`], and counted.
    pub(super) fn factor_sparse(
        &self,
        symbolic: &SymbolicCholesky<usize>,
        smallest: f64,
        f: &mut Factored,
    ) -> Result<(), usize> {
        let memory = self.scratch(symbolic, &mut f.scratch);
        let a = SparseColMatRef::new(self.pattern.as_ref(), &f.values);
        f.redundant = factor_dropping(symbolic, a, smallest, memory, &mut f.l_values)?;
        Ok(())
    }

    /// Fills, scales and factors `A` as [`NormalMatrix::factor_sparse`]
    /// does, for the held rows alone (those not `inactive`), in the order
    /// `symbolic` eliminates `A`'s rows restricted to them: a row set aside
    /// meets no other, so its elimination changes nothing in the others',
    /// and it keeps a unit scale. The pattern and its symbolic
    /// factorization are made again only where the rows set aside
    /// changed. A `compliance` is added to the held rows' scaled diagonal
    /// as [`NormalMatrix::factor_compliant`] does.
    pub(super) fn factor_held<V: Coordinates>(
        &self,
        symbolic: &SymbolicCholesky<usize>,
        (inverse_mass, gradient): (&[f64], &[V]),
        inactive: &[bool],
        compliance: Option<f64>,
        f: &mut Factored,
    ) -> Result<(), usize> {
        let set_aside = &inactive[..self.n.min(inactive.len())];
        let made = f
            .held
            .made_for
            .as_ref()
            .is_some_and(|(id, made)| *id == self.id && made[..] == *set_aside);
        if !made {
            self.held_pattern(symbolic, set_aside, &mut f.held)?;
        }
        let HeldRows {
            rows,
            source,
            symbolic,
            values,
            memory,
            ..
        } = &mut f.held;
        f.scale.clear();
        f.scale.resize(self.n, 1.0);
        for &r in rows.iter() {
            let k = self.diagonal[r];
            f.scale[r] = self.diagonal_scale(r, self.value(k, inverse_mass, gradient))?;
        }
        values.clear();
        let added = compliance.unwrap_or(0.0);
        values.extend(source.iter().map(|&(k, row, col)| {
            let value = self.value(k, inverse_mass, gradient) * (f.scale[row] * f.scale[col]);
            if row == col { value + added } else { value }
        }));
        let (Some((pattern, symbolic)), Some(memory)) = (symbolic, memory) else {
            // No row held, or one: solved in closed form.
            return Ok(());
        };
        let a = SparseColMatRef::new(pattern.as_ref(), values);
        let smallest = compliance.map_or(REDUNDANT_PIVOT, |c| 1e-3 * c);
        f.redundant = factor_dropping(symbolic, a, smallest, memory, &mut f.l_values)?;
        Ok(())
    }

    /// Makes `held`'s pattern for the rows not in `set_aside`: `A`'s upper
    /// entries between two held rows, and its symbolic factorization in
    /// `symbolic`'s order of `A`'s rows restricted to the held ones.
    fn held_pattern(
        &self,
        symbolic: &SymbolicCholesky<usize>,
        set_aside: &[bool],
        held: &mut HeldRows,
    ) -> Result<(), usize> {
        let mut position = vec![usize::MAX; self.n];
        held.rows.clear();
        for (r, slot) in position.iter_mut().enumerate() {
            if set_aside.get(r) != Some(&true) {
                *slot = held.rows.len();
                held.rows.push(r);
            }
        }
        let m = held.rows.len();
        // `A`'s entries come by column, each column's by row; the held
        // rows keep their order, so the held entries do too. Only the
        // held columns are read.
        let (a_col_ptr, a_row_idx) = (self.pattern.col_ptr(), self.pattern.row_idx());
        let mut col_ptr = Vec::with_capacity(m + 1);
        col_ptr.push(0);
        let mut row_idx = Vec::new();
        held.source.clear();
        for &col in &held.rows {
            for (k, &row) in a_row_idx
                .iter()
                .enumerate()
                .take(a_col_ptr[col + 1])
                .skip(a_col_ptr[col])
            {
                let r = position[row];
                if r != usize::MAX {
                    row_idx.push(r);
                    held.source.push((k, row, col));
                }
            }
            col_ptr.push(row_idx.len());
        }
        held.made_for = Some((self.id, set_aside.to_vec()));
        held.symbolic = None;
        held.memory = None;
        if m < 2 {
            return Ok(());
        }
        let forward: Vec<usize> = match symbolic.perm() {
            Some(order) => order
                .arrays()
                .0
                .iter()
                .map(|&r| position[r])
                .filter(|&p| p != usize::MAX)
                .collect(),
            None => (0..m).collect(),
        };
        let mut inverse = vec![0; m];
        for (i, &p) in forward.iter().enumerate() {
            inverse[p] = i;
        }
        let pattern = SymbolicSparseColMat::new_checked(m, m, col_ptr, None, row_idx);
        let order = SymmetricOrdering::Custom(PermRef::new_checked(&forward, &inverse, m));
        let first = held.rows[0];
        let symbolic =
            factorize_symbolic_cholesky(pattern.as_ref(), Side::Upper, order, Default::default())
                .map_err(|_| first)?;
        held.memory = Some(ldlt_memory(&symbolic));
        held.symbolic = Some((pattern, symbolic));
        Ok(())
    }

    /// [`NormalMatrix::solve`] with the held rows' `LDLᵀ` of
    /// [`NormalMatrix::factor_held`]; a row set aside (a unit diagonal)
    /// keeps its right-hand side.
    pub(super) fn solve_held(&self, f: &mut Factored, rhs: &mut [f64]) {
        for (b, s) in rhs.iter_mut().zip(&f.scale) {
            *b *= s;
        }
        let HeldRows {
            rows,
            symbolic,
            values,
            rhs: part,
            memory,
            ..
        } = &mut f.held;
        part.clear();
        part.extend(rows.iter().map(|&r| rhs[r]));
        match (symbolic, memory) {
            (Some((_, symbolic)), Some(memory)) => {
                ldlt_solve(symbolic, &f.l_values, memory, part);
            }
            _ => {
                if let (Some(b), Some(d)) = (part.first_mut(), values.first()) {
                    *b /= d;
                }
            }
        }
        for (&r, b) in rows.iter().zip(part.iter()) {
            rhs[r] = *b;
        }
        for (b, s) in rhs.iter_mut().zip(&f.scale) {
            *b *= s;
        }
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
        let memory = self.scratch(symbolic, &mut f.scratch);
        ldlt_solve(symbolic, &f.l_values, memory, rhs);
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
        scratch.memory.get_or_insert_with(|| ldlt_memory(symbolic))
    }
}
