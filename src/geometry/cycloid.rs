//! [`Cycloid`]: the tautochrone.

use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use bevy::math::DVec2;
use serde::{Deserialize, Serialize};

use super::traced::delegate_curve;
use super::{Parametric, Traced};

/// One arch of a cycloid hanging cusps up, vertex at the local origin:
/// `x = r(φ − sin φ) − πr`, `y = r(1 + cos φ)`, `φ ∈ [0, 2π]`, `r` the
/// generating circle's radius; cusps at `(±πr, 2r)`. A bead released from
/// rest anywhere on it reaches the bottom after `π sqrt(r/g)` (the
/// tautochrone). A wire by its signed distance (see [`Traced`]); positive
/// above. The cusps are its ends and singular points.
#[derive(Clone, Serialize, Deserialize)]
#[serde(from = "CycloidSpec", into = "CycloidSpec")]
pub struct Cycloid {
    radius: f64,
    traced: Arc<Traced<CycloidArch>>,
}

/// What a scene file says of a cycloid.
#[derive(Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CycloidSpec {
    radius: f64,
}

impl From<CycloidSpec> for Cycloid {
    fn from(spec: CycloidSpec) -> Self {
        Self::new(spec.radius)
    }
}

impl From<Cycloid> for CycloidSpec {
    fn from(cycloid: Cycloid) -> Self {
        Self {
            radius: cycloid.radius,
        }
    }
}

impl std::fmt::Debug for Cycloid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cycloid")
            .field("radius", &self.radius)
            .finish()
    }
}

impl PartialEq for Cycloid {
    fn eq(&self, other: &Self) -> bool {
        self.radius == other.radius
    }
}

impl Cycloid {
    /// The arch of generating radius `radius` (checked by
    /// [`WireShape::validate`](super::WireShape::validate)).
    pub fn new(radius: f64) -> Self {
        Self {
            radius,
            traced: Arc::new(Traced::new(CycloidArch { radius })),
        }
    }

    /// The generating circle's radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The point at parameter `φ`.
    pub fn point(&self, phi: f64) -> DVec2 {
        CycloidArch {
            radius: self.radius,
        }
        .eval(phi)[0]
    }

    /// The arch as a wire.
    fn traced(&self) -> &Traced<CycloidArch> {
        &self.traced
    }

    /// Points along the arch, for drawing.
    pub fn polyline(&self) -> impl Iterator<Item = DVec2> + '_ {
        self.traced().polyline()
    }
}

/// The parametrization of [`Cycloid`].
#[derive(Clone, Copy, Debug)]
pub struct CycloidArch {
    radius: f64,
}

impl Parametric for CycloidArch {
    fn domain(&self) -> (f64, f64) {
        (0.0, TAU)
    }
    fn closed(&self) -> bool {
        false
    }
    fn eval(&self, phi: f64) -> [DVec2; 3] {
        let r = self.radius;
        let (sin, cos) = phi.sin_cos();
        [
            DVec2::new(r * (phi - sin) - PI * r, r * (1.0 + cos)),
            DVec2::new(r * (1.0 - cos), -r * sin),
            DVec2::new(r * sin, -r * cos),
        ]
    }
}

delegate_curve!(Cycloid, |this| this.traced(), this.radius);
