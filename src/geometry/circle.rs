//! [`Circle`]: the assignment's wire.

use bevy::math::{DMat2, DVec2};
use serde::{Deserialize, Serialize};

use super::{Geometry, ImplicitCurve};
use crate::lane::{Lane, LaneSpace, Sym2, Vector};

/// A circle of radius `r` about the local origin: `C = |x| - r`, the assignment's
/// wire. Singular at the centre.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Circle {
    /// The radius.
    pub radius: f64,
}

impl ImplicitCurve for Circle {
    fn value(&self, p: DVec2) -> f64 {
        p.length() - self.radius
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.geometry(p).normal
    }
    fn hessian(&self, p: DVec2) -> DMat2 {
        self.geometry(p).hessian
    }
    fn scale(&self) -> f64 {
        self.radius
    }
    fn travel(&self) -> f64 {
        // Counter-clockwise: the gradient points out.
        1.0
    }
    #[inline]
    fn geometry(&self, p: DVec2) -> Geometry {
        let g = round_geometry::<DVec2, f64>(p.one(), self.radius);
        if g.len == 0.0 {
            // ∇C is undefined at the centre; a zero normal is reported as singular.
            return Geometry {
                c: -self.radius,
                normal: DVec2::ZERO,
                hessian: DMat2::ZERO,
            };
        }
        let Sym2 { xx, xy, yy } = g.hessian;
        Geometry {
            c: g.c,
            normal: DVec2::from_one(g.normal),
            hessian: DMat2::from_cols(DVec2::new(xx, xy), DVec2::new(xy, yy)),
        }
    }
}

/// A circle's or a sphere's `C`, `∇C` and Hessian at `p` (relative to its
/// centre), on lanes: one formula for [`Circle::geometry`], the sphere's
/// and the batched step.
#[derive(Clone, Copy)]
pub(crate) struct RoundGeometry<T, V, H> {
    /// `|p|`: zero at the centre, where nothing else means anything.
    pub(crate) len: T,
    /// `C = |p| - r`.
    pub(crate) c: T,
    /// `∇C = p / |p|`.
    pub(crate) normal: V,
    /// `H = (I - n nᵀ) / |p|`.
    pub(crate) hessian: H,
}

/// `C = |p| − r` and `∇C = p / |p|` at `p` (relative to the centre) for a
/// circle in the plane or a sphere in space, on lanes: one formula for
/// both. The Hessian `(I − n nᵀ) / |p|` is assembled from `normal` and
/// `inverse` in each dimension's matrix.
#[derive(Clone, Copy)]
pub(crate) struct Round<T, V> {
    /// `|p|`: zero at the centre, where nothing else means anything.
    pub(crate) len: T,
    /// `C = |p| - r`.
    pub(crate) c: T,
    /// `∇C = p / |p|`.
    pub(crate) normal: V,
    /// `1 / |p|`.
    pub(crate) inverse: T,
}

/// See [`Round`].
#[inline(always)]
pub(crate) fn round<T: Lane, V: Vector<T>>(p: V, radius: T) -> Round<T, V> {
    let len = p.dot(p).sqrt();
    let inverse = len.splat(1.0) / len;
    Round {
        len,
        c: len - radius,
        normal: p.scale(inverse),
        inverse,
    }
}

/// See [`RoundGeometry`].
#[inline(always)]
pub(crate) fn round_geometry<S: LaneSpace, T: Lane>(
    p: S::Lanes<T>,
    radius: T,
) -> RoundGeometry<T, S::Lanes<T>, S::Sym<T>> {
    let Round {
        len,
        c,
        normal,
        inverse,
    } = round(p, radius);
    RoundGeometry {
        len,
        c,
        normal,
        hessian: S::round_hessian(normal, inverse),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_centre_has_zero_normal_not_nan() {
        let g = Circle { radius: 1.0 }.geometry(DVec2::ZERO);
        assert_eq!(g.normal, DVec2::ZERO);
        assert!(g.hessian.is_finite());
    }
}
