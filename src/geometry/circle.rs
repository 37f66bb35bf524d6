//! [`Circle`]: the assignment's wire.

use bevy::math::{DMat2, DVec2};
use serde::{Deserialize, Serialize};

use super::{Geometry, ImplicitCurve};

/// A circle of radius `r` about the local origin: `C = |x| - r`, the assignment's
/// wire. Singular at the centre.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
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
    #[inline]
    fn geometry(&self, p: DVec2) -> Geometry {
        let len = p.length();
        if len == 0.0 {
            // ∇C is undefined at the centre; a zero normal is reported as singular.
            return Geometry {
                c: -self.radius,
                normal: DVec2::ZERO,
                hessian: DMat2::ZERO,
            };
        }
        let inv = 1.0 / len;
        let n = p * inv;
        // H = (I - n nᵀ) / |x|
        let hessian = DMat2::from_cols(
            DVec2::new(1.0 - n.x * n.x, -n.x * n.y) * inv,
            DVec2::new(-n.x * n.y, 1.0 - n.y * n.y) * inv,
        );
        Geometry {
            c: len - self.radius,
            normal: n,
            hessian,
        }
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
