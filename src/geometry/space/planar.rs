//! A planar curve in space, as two surfaces whose intersection it is: the
//! plane it lies in ([`Flat`], the local `z = 0`) and the curve drawn out
//! along the plane's normal ([`Extruded`], `C(x, y)` whatever `z`). A bead
//! held by both rows (an island of two rows on one bead) is held on the
//! curve; their normals are at right angles, so the two rows never pull
//! against each other.

use bevy::math::{DMat2, DMat3, DVec2, DVec3};

use super::ImplicitSurface;
use crate::geometry::{Geometry, ImplicitCurve};

/// The plane `z = 0` of the wire's local frame, the plane its planar
/// shapes lie in: `C = z`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Flat;

impl ImplicitSurface for Flat {
    fn geometry(&self, p: DVec3) -> Geometry<DVec3> {
        Geometry {
            c: p.z,
            normal: DVec3::Z,
            hessian: DMat3::ZERO,
        }
    }
}

/// A curve of the plane drawn out along `z`: `C(x, y, z) = C_curve(x, y)`,
/// its gradient and Hessian the curve's with a zero `z` row and column.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Extruded<C>(pub C);

impl<C: ImplicitCurve> ImplicitSurface for Extruded<C> {
    fn value(&self, p: DVec3) -> f64 {
        self.0.value(p.truncate())
    }
    fn scale(&self) -> f64 {
        self.0.scale()
    }
    fn geometry(&self, p: DVec3) -> Geometry<DVec3> {
        extrude(self.0.geometry(p.truncate()))
    }
}

/// A curve's geometry at `(x, y)` as its extrusion's at `(x, y, z)`.
pub(crate) fn extrude(g: Geometry) -> Geometry<DVec3> {
    Geometry {
        c: g.c,
        normal: g.normal.extend(0.0),
        hessian: lift(g.hessian),
    }
}

/// A 2×2 matrix as the upper left of a 3×3 one.
fn lift(h: DMat2) -> DMat3 {
    DMat3::from_cols(
        h.x_axis.extend(0.0),
        h.y_axis.extend(0.0),
        DVec2::ZERO.extend(0.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Ellipse;

    /// An extruded ellipse has the ellipse's `C` at every `z`, and a zero
    /// `z` row and column in its Hessian.
    #[test]
    fn an_extruded_curve_is_the_curve_at_every_height() {
        let ellipse = Ellipse { a: 1.5, b: 0.7 };
        let p = DVec2::new(0.4, -0.6);
        let curve = ellipse.geometry(p);
        for z in [-2.0, 0.0, 3.5] {
            let g = Extruded(ellipse).geometry(p.extend(z));
            assert_eq!(g.c, curve.c);
            assert_eq!(g.normal, curve.normal.extend(0.0));
            assert_eq!(g.hessian.z_axis, DVec3::ZERO);
            assert_eq!(g.hessian.row(2), DVec3::ZERO);
        }
    }
}
