//! The built-in surfaces in space: a plane, a sphere, and the surfaces of
//! revolution about the local `y`-axis (cylinder, cone, torus).

use bevy::math::{DMat3, DVec3};
use serde::{Deserialize, Serialize};

use super::{ImplicitSurface, Meridian, revolution};
use crate::geometry::Geometry;
use crate::geometry::circle::round_geometry;
use crate::lane::{LaneSpace, Sym3};

/// The plane `y = 0` of the wire's local frame, its positive side `+y`:
/// `C = y`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Plane;

impl ImplicitSurface for Plane {
    fn geometry(&self, p: DVec3) -> Geometry<DVec3> {
        Geometry {
            c: p.y,
            normal: DVec3::Y,
            hessian: DMat3::ZERO,
        }
    }
}

/// A sphere of `radius` about the local origin, positive outside:
/// `C = |x| − r`. Singular at the centre.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sphere {
    /// The radius.
    pub radius: f64,
}

impl ImplicitSurface for Sphere {
    fn scale(&self) -> f64 {
        self.radius
    }
    fn sphere_radius(&self) -> Option<f64> {
        Some(self.radius)
    }
    /// `∇C = x/|x|`, `H = (I − n nᵀ)/|x|`: the circle's formula in
    /// space. At the centre the normal is zero (a singular point).
    fn geometry(&self, p: DVec3) -> Geometry<DVec3> {
        let g = round_geometry::<DVec3, f64>(p.one(), self.radius);
        if g.len == 0.0 {
            return Geometry {
                c: -self.radius,
                normal: DVec3::ZERO,
                hessian: DMat3::ZERO,
            };
        }
        let Sym3 {
            xx,
            xy,
            xz,
            yy,
            yz,
            zz,
        } = g.hessian;
        Geometry {
            c: g.c,
            normal: DVec3::from_one(g.normal),
            hessian: DMat3::from_cols(
                DVec3::new(xx, xy, xz),
                DVec3::new(xy, yy, yz),
                DVec3::new(xz, yz, zz),
            ),
        }
    }
}

/// A cylinder of `radius` about the local `y`-axis, positive outside:
/// `C = ρ − r`. Singular on the axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cylinder {
    /// The radius.
    pub radius: f64,
}

impl Cylinder {
    fn meridian(&self, rho: f64, _y: f64) -> Meridian {
        Meridian {
            g: rho - self.radius,
            g_rho: 1.0,
            g_y: 0.0,
            g_rho_rho: 0.0,
            g_rho_y: 0.0,
            g_y_y: 0.0,
        }
    }
}

/// A cone with its apex at the local origin, opening along `+y` at
/// `half_angle` (radians) from the axis, positive outside:
/// `C = ρ cos a − y sin a`, the signed distance from the cone's lines
/// for a point beside them. Singular at the apex.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cone {
    /// The half angle, in radians, strictly between 0 and π/2.
    pub half_angle: f64,
}

impl Cone {
    fn meridian(&self, rho: f64, y: f64) -> Meridian {
        let (sin, cos) = self.half_angle.sin_cos();
        Meridian {
            g: rho * cos - y * sin,
            g_rho: cos,
            g_y: -sin,
            g_rho_rho: 0.0,
            g_rho_y: 0.0,
            g_y_y: 0.0,
        }
    }
}

/// A torus around the local `y`-axis: the circle of `major_radius` in the
/// local xz-plane swept by a disc of `minor_radius`, positive outside:
/// `C = √((ρ − R)² + y²) − r`. Singular on its core circle.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Torus {
    /// `R`: from the axis to the tube's centre.
    pub major_radius: f64,
    /// `r`: the tube's radius.
    pub minor_radius: f64,
}

impl Torus {
    fn meridian(&self, rho: f64, y: f64) -> Meridian {
        let u = rho - self.major_radius;
        let d = u.hypot(y);
        let d3 = d * d * d;
        Meridian {
            g: d - self.minor_radius,
            g_rho: u / d,
            g_y: y / d,
            g_rho_rho: y * y / d3,
            g_rho_y: -u * y / d3,
            g_y_y: u * u / d3,
        }
    }
}

/// The [`ImplicitSurface`] of a surface of revolution from its meridian.
macro_rules! of_revolution {
    ($($shape:ty => $scale:expr),*) => {$(
        impl ImplicitSurface for $shape {
            fn value(&self, p: DVec3) -> f64 {
                self.meridian(p.x.hypot(p.z), p.y).g
            }
            fn scale(&self) -> f64 {
                let scale: fn(&Self) -> f64 = $scale;
                scale(self)
            }
            fn geometry(&self, p: DVec3) -> Geometry<DVec3> {
                revolution(p, |rho, y| self.meridian(rho, y))
            }
        }
    )*};
}

of_revolution!(
    Cylinder => |c| c.radius,
    Cone => |_| 1.0,
    Torus => |t| t.minor_radius
);

#[cfg(test)]
mod tests {
    use super::*;

    /// Central differences of `value` give `gradient`, and of `gradient`
    /// give `hessian`, at points off each surface's singular set.
    fn check_derivatives(surface: &dyn ImplicitSurface, points: &[DVec3]) {
        let h = 1e-6;
        for &p in points {
            let g = surface.geometry(p);
            assert!((g.c - surface.value(p)).abs() < 1e-15);
            for (axis, e) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
                let dc = (surface.value(p + h * e) - surface.value(p - h * e)) / (2.0 * h);
                assert!(
                    (dc - g.normal[axis]).abs() < 1e-8,
                    "∂C/∂x{axis} at {p}: {dc} against {}",
                    g.normal[axis]
                );
                let dn = (surface.gradient(p + h * e) - surface.gradient(p - h * e)) / (2.0 * h);
                let column = g.hessian.col(axis);
                assert!(
                    (dn - column).length() < 1e-7,
                    "H column {axis} at {p}: {dn} against {column}"
                );
            }
        }
    }

    const POINTS: [DVec3; 4] = [
        DVec3::new(0.7, 0.4, -0.3),
        DVec3::new(-1.2, -0.5, 0.9),
        DVec3::new(0.1, 1.3, 0.6),
        DVec3::new(2.1, -0.2, -1.4),
    ];

    #[test]
    fn gradients_and_hessians_are_the_derivatives_of_the_values() {
        check_derivatives(&Plane, &POINTS);
        check_derivatives(&Sphere { radius: 1.3 }, &POINTS);
        check_derivatives(&Cylinder { radius: 0.8 }, &POINTS);
        check_derivatives(&Cone { half_angle: 0.5 }, &POINTS);
        check_derivatives(
            &Torus {
                major_radius: 1.5,
                minor_radius: 0.4,
            },
            &POINTS,
        );
        check_derivatives(&crate::geometry::Helicoid { pitch: 0.9 }, &POINTS);
    }

    /// On each surface `C = 0` and `|∇C| = 1`: `C` reads as a distance.
    #[test]
    fn on_each_surface_c_is_zero_and_the_normal_a_unit() {
        let a = 0.4_f64;
        let cases: [(&dyn ImplicitSurface, DVec3); 5] = [
            (&Plane, DVec3::new(3.0, 0.0, -2.0)),
            (&Sphere { radius: 2.0 }, DVec3::new(1.2, -1.6, 0.0)),
            (&Cylinder { radius: 0.5 }, DVec3::new(0.3, 7.0, -0.4)),
            (
                &Cone { half_angle: a },
                DVec3::new(a.sin(), a.cos(), 0.0) * 2.0,
            ),
            (
                &Torus {
                    major_radius: 2.0,
                    minor_radius: 0.5,
                },
                DVec3::new(0.0, 0.3, 2.4),
            ),
        ];
        for (surface, p) in cases {
            let g = surface.geometry(p);
            assert!(g.c.abs() < 1e-15, "C = {} at {p}", g.c);
            assert!((g.normal.length() - 1.0).abs() < 1e-15);
        }
    }
}
