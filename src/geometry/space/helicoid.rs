//! [`Helicoid`]: the surface a helix's radius sweeps, a spiral ramp
//! about the local `y`-axis. A helix is where it meets a [`Cylinder`]
//! (two rows of one bead).
//!
//! [`Cylinder`]: super::Cylinder

use std::f64::consts::TAU;

use bevy::math::{DMat3, DVec3};
use serde::{Deserialize, Serialize};

use super::ImplicitSurface;
use crate::geometry::Geometry;

/// The helicoid about the local `y`-axis rising `pitch` per turn: the
/// points `(ρ cos θ, p θ / 2π, ρ sin θ)` for every `ρ` and `θ`, one sheet
/// every `pitch` in `y`. `C = y − p φ / 2π` (φ the azimuth `atan2(z, x)`),
/// taken to the nearest sheet: `C` is the height above the sheet nearest
/// the point, so no branch needs remembering. Singular on the axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Helicoid {
    /// The rise per turn, positive.
    pub pitch: f64,
}

impl ImplicitSurface for Helicoid {
    fn scale(&self) -> f64 {
        self.pitch
    }
    /// With `k = p / 2π` and `ρ² = x² + z²`: `∇C = (k z/ρ², 1, −k x/ρ²)`,
    /// and the Hessian has `∂²C/∂x² = −2k xz/ρ⁴`, `∂²C/∂z² = 2k xz/ρ⁴`,
    /// `∂²C/∂x∂z = k (x² − z²)/ρ⁴`, zero in the `y` row and column.
    fn geometry(&self, p: DVec3) -> Geometry<DVec3> {
        let k = self.pitch / TAU;
        let raw = p.y - k * p.z.atan2(p.x);
        let c = raw - self.pitch * (raw / self.pitch).round();
        let rho2 = p.x * p.x + p.z * p.z;
        let rho4 = rho2 * rho2;
        let (xx, zz, xz) = (
            -2.0 * k * p.x * p.z / rho4,
            2.0 * k * p.x * p.z / rho4,
            k * (p.x * p.x - p.z * p.z) / rho4,
        );
        Geometry {
            c,
            normal: DVec3::new(k * p.z / rho2, 1.0, -k * p.x / rho2),
            hessian: DMat3::from_cols(
                DVec3::new(xx, 0.0, xz),
                DVec3::ZERO,
                DVec3::new(xz, 0.0, zz),
            ),
        }
    }
}
