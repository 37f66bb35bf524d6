//! [`Ellipse`].

use bevy::math::{DMat2, DVec2};
use serde::{Deserialize, Serialize};

use super::ImplicitCurve;

/// An axis-aligned ellipse with semi-axes `a` (local x) and `b` (local y):
/// `C = (ℓ/2)(x²/a² + y²/b² - 1)` with `ℓ = sqrt(ab)`, so that a circle
/// (`a = b`) has `|∇C| = 1` on the wire. Singular at the centre.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ellipse {
    /// Semi-axis along local x.
    pub a: f64,
    /// Semi-axis along local y.
    pub b: f64,
}

impl Ellipse {
    fn ell(&self) -> f64 {
        (self.a * self.b).sqrt()
    }
}

impl ImplicitCurve for Ellipse {
    fn value(&self, p: DVec2) -> f64 {
        0.5 * self.ell() * ((p.x / self.a).powi(2) + (p.y / self.b).powi(2) - 1.0)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.ell() * DVec2::new(p.x / (self.a * self.a), p.y / (self.b * self.b))
    }
    fn hessian(&self, _p: DVec2) -> DMat2 {
        DMat2::from_diagonal(
            self.ell() * DVec2::new(1.0 / (self.a * self.a), 1.0 / (self.b * self.b)),
        )
    }
    fn scale(&self) -> f64 {
        self.ell()
    }
    fn travel(&self) -> f64 {
        // Counter-clockwise: the gradient points out.
        1.0
    }
}
