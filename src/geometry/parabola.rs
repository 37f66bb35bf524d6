//! [`Parabola`].

use bevy::math::{DMat2, DVec2};
use serde::{Deserialize, Serialize};

use super::ImplicitCurve;

/// The parabola `y = x² / (4f)` with focal length `f` (opening up for
/// `f > 0`): `C = y - x²/(4f)`. Its scale is `f`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parabola {
    /// The focal length: the vertex's radius of curvature is `2f`.
    pub focal_length: f64,
}

impl ImplicitCurve for Parabola {
    fn value(&self, p: DVec2) -> f64 {
        p.y - p.x * p.x / (4.0 * self.focal_length)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        DVec2::new(-p.x / (2.0 * self.focal_length), 1.0)
    }
    fn hessian(&self, _p: DVec2) -> DMat2 {
        DMat2::from_diagonal(DVec2::new(-1.0 / (2.0 * self.focal_length), 0.0))
    }
    fn scale(&self) -> f64 {
        self.focal_length.abs()
    }
}
