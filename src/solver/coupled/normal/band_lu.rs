//! The Newton matrix `J₁ W J₀ᵀ` of RATTLE's position solve as a band
//! matrix, solved by Gaussian elimination with partial pivoting.

use crate::geometry::Coordinates;

use super::order::Band;
use super::{NormalMatrix, REDUNDANT_PIVOT};

impl NormalMatrix {
    /// [`NormalMatrix::solve_unsymmetric`] for a band matrix: filled in the
    /// band's order of the rows, solved by [`eliminate_band`] (in `order`
    /// where the band reorders the rows).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn solve_unsymmetric_band<V: Coordinates>(
        &self,
        band: &Band,
        inverse_mass: &[f64],
        now: &[V],
        first: &[V],
        inactive: &[bool],
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
            let upper = self.unsymmetric_value((k, false), inverse_mass, (now, first), inactive);
            m[i * w + c + p - i] = upper;
            largest = largest.max(upper.abs());
            if row != col {
                let lower = self.unsymmetric_value((k, true), inverse_mass, (now, first), inactive);
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
