//! [`Sine`].

use std::f64::consts::TAU;

use bevy::math::{DMat2, DVec2};
use serde::{Deserialize, Serialize};

use super::ImplicitCurve;

/// A sine track `y = A sin(2π x / λ)`: `C = y - A sin(kx)`, `k = 2π/λ`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sine {
    /// The amplitude `A`.
    pub amplitude: f64,
    /// The wavelength `λ`.
    pub wavelength: f64,
}

impl Sine {
    fn k(&self) -> f64 {
        TAU / self.wavelength
    }
}

impl ImplicitCurve for Sine {
    fn value(&self, p: DVec2) -> f64 {
        p.y - self.amplitude * (self.k() * p.x).sin()
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        let k = self.k();
        DVec2::new(-self.amplitude * k * (k * p.x).cos(), 1.0)
    }
    fn hessian(&self, p: DVec2) -> DMat2 {
        let k = self.k();
        DMat2::from_diagonal(DVec2::new(self.amplitude * k * k * (k * p.x).sin(), 0.0))
    }
    fn scale(&self) -> f64 {
        self.wavelength
    }
}
