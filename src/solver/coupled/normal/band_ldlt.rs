//! `LDLᵀ` of the scaled `A` as a band matrix, in the band's order of the
//! rows, and its solve.

use super::order::Band;
use super::{DROPPED_PIVOT, Factored, NormalMatrix};

impl NormalMatrix {
    /// `LDLᵀ` of the scaled `A` as a band matrix of half-width `p`, its
    /// rows in the band's order: row `i` at `a[i·(p+1)..]`, `D_ii` first,
    /// then `L_{i,i−1}` to `L_{i,i−p}`. A pivot at or below `smallest`
    /// ([`REDUNDANT_PIVOT`](super::REDUNDANT_PIVOT) unless the matrix is
    /// made compliant) is
    /// replaced by [`DROPPED_PIVOT`], as the sparse factorization does.
    /// Returns how many were.
    pub(super) fn factor_band(
        &self,
        band: &Band,
        values: &[f64],
        a: &mut Vec<f64>,
        smallest: f64,
    ) -> usize {
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
            if d.abs() <= smallest {
                d = DROPPED_PIVOT;
                dropped += 1;
            }
            a[j * w] = d;
        }
        dropped
    }

    /// [`NormalMatrix::solve`] with the band `LDLᵀ` of
    /// [`NormalMatrix::factor_band`].
    pub(super) fn solve_band(&self, band: &Band, f: &mut Factored, rhs: &mut [f64]) {
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
