//! [`Line`].

use bevy::math::{DMat2, DVec2};
use serde::{Deserialize, Serialize};

use super::ImplicitCurve;

/// The infinite straight line along the local x axis: `C = y`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Line;

impl ImplicitCurve for Line {
    fn value(&self, p: DVec2) -> f64 {
        p.y
    }
    fn gradient(&self, _p: DVec2) -> DVec2 {
        DVec2::Y
    }
    fn hessian(&self, _p: DVec2) -> DMat2 {
        DMat2::ZERO
    }
}
