//! Wires in space that are surfaces: `C(x) = 0` for a point `x` in three
//! dimensions, one constraint row, as a curve is in the plane. The
//! solver's one-row step ([`step_on`](crate::solver::step_on)) runs on
//! them unchanged, through [`FixedTrack`](super::FixedTrack) and its
//! [`Track<DVec3>`](super::Track) implementation.
//!
//! Each built-in surface is written in its own local frame and scaled so
//! that `|∇C| = 1` on the surface, so `C` reads as a distance in world
//! units, as every curve's does in the plane:
//!
//! | surface | `C(x)` | positive side |
//! |---|---|---|
//! | [`Plane`] | `y` | `+y` |
//! | [`Sphere`] | `\|x\| − r` | outside |
//! | [`Cylinder`] | `ρ − r`, `ρ = √(x² + z²)` (axis `y`) | outside |
//! | [`Cone`] | `ρ cos a − y sin a` (apex at the origin, opening along `+y`) | outside |
//! | [`Torus`] | `√((ρ − R)² + y²) − r` (around `y`) | outside |
//!
//! The cylinder, the cone and the torus are surfaces of revolution about
//! the local `y`-axis, `C = g(ρ, y)`; their gradient and Hessian follow
//! from `g`'s derivatives by the chain rule in one place
//! (`revolution`).

mod curve;
mod helicoid;
mod motion;
mod planar;
mod shapes;

use bevy::math::{DMat3, DVec3};

use super::{Coordinates, Geometry};

pub use curve::{CurveFrame, Helix, OnPlane, SpaceCurve};
pub use helicoid::Helicoid;
pub use motion::SpaceMotion;
pub use planar::{Extruded, Flat};
pub use shapes::{Cone, Cylinder, Plane, Sphere, Torus};

/// A surface in space given implicitly by `C(x) = 0`.
///
/// Implement this to put beads on a surface of your own: `geometry` gives
/// the value `C`, the gradient `∇C` and the Hessian at a point, which
/// must agree (the gradient of the value, the Jacobian of the gradient);
/// the solver divides by `|∇C|²`, so a point where the gradient vanishes
/// is a singular point and is reported as such.
pub trait ImplicitSurface {
    /// `C(x)`, `∇C(x)` and the Hessian of `C` at `x`.
    fn geometry(&self, p: DVec3) -> Geometry<DVec3>;
    /// A characteristic length (a sphere's radius): drift is reported
    /// relative to it and solver tolerances scale with it.
    fn scale(&self) -> f64 {
        1.0
    }
    /// `C(x)`; override where it is cheaper alone.
    fn value(&self, p: DVec3) -> f64 {
        self.geometry(p).c
    }
    /// `∇C(x)`.
    fn gradient(&self, p: DVec3) -> DVec3 {
        self.geometry(p).normal
    }
    /// The Hessian of `C` at `x`.
    fn hessian(&self, p: DVec3) -> DMat3 {
        self.geometry(p).hessian
    }
    /// The radius, if this is [`Sphere`] (`C = |x| − r` exactly as it
    /// computes it): a bead alone on a sphere that stays put then takes
    /// the batched step, eight beads at a time. None for any other
    /// surface.
    fn sphere_radius(&self) -> Option<f64> {
        None
    }
}

/// `g(ρ, y)` and its derivatives at one point, for a surface of
/// revolution about the `y`-axis.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Meridian {
    /// `g`.
    pub(crate) g: f64,
    /// `∂g/∂ρ`.
    pub(crate) g_rho: f64,
    /// `∂g/∂y`.
    pub(crate) g_y: f64,
    /// `∂²g/∂ρ²`.
    pub(crate) g_rho_rho: f64,
    /// `∂²g/∂ρ∂y`.
    pub(crate) g_rho_y: f64,
    /// `∂²g/∂y²`.
    pub(crate) g_y_y: f64,
}

/// The geometry of `C(x) = g(ρ, y)`, `ρ = √(x² + z²)`, where `meridian`
/// gives `g` and its derivatives at `(ρ, y)` of `p`: `∇C = g_ρ ∇ρ + g_y e_y`
/// and `H = g_ρ Hρ + g_ρρ ∇ρ∇ρᵀ + g_ρy (∇ρ e_yᵀ + e_y ∇ρᵀ) + g_yy e_y e_yᵀ`,
/// with `∇ρ = (x, 0, z)/ρ` and `Hρ = (I_xz − ∇ρ∇ρᵀ)/ρ`. On the axis
/// (`ρ = 0`), where `ρ` has no gradient, its terms are left out.
pub(crate) fn revolution(p: DVec3, meridian: impl Fn(f64, f64) -> Meridian) -> Geometry<DVec3> {
    let rho = p.x.hypot(p.z);
    let m = meridian(rho, p.y);
    let (d_rho, h_rho) = if rho > 0.0 {
        let d = DVec3::new(p.x / rho, 0.0, p.z / rho);
        let xz = DMat3::from_diagonal(DVec3::new(1.0, 0.0, 1.0));
        (d, (xz - DVec3::outer(d, d)) * (1.0 / rho))
    } else {
        (DVec3::ZERO, DMat3::ZERO)
    };
    let e_y = DVec3::Y;
    Geometry {
        c: m.g,
        normal: m.g_rho * d_rho + m.g_y * e_y,
        hessian: h_rho * m.g_rho
            + DVec3::outer(d_rho, d_rho) * m.g_rho_rho
            + (DVec3::outer(d_rho, e_y) + DVec3::outer(e_y, d_rho)) * m.g_rho_y
            + DVec3::outer(e_y, e_y) * m.g_y_y,
    }
}
