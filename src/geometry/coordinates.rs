//! [`Coordinates`]: the plane's `DVec2` or space's `DVec3`, the vector
//! type a lone bead's step is written over, so that each formula serves
//! both dimensions.

use std::fmt::Debug;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

use bevy::math::{DMat2, DMat3, DVec2, DVec3};

use crate::lane::Vector;
use crate::validate::Components;

/// The coordinates a bead moves in: [`DVec2`] in the plane, [`DVec3`] in
/// space. The solver's types ([`BeadState`](crate::solver::BeadState),
/// [`Geometry`](super::Geometry), [`Twist`](super::Twist), …) take it as a
/// parameter that defaults to the plane. Implemented for those two only.
pub trait Coordinates:
    Vector<f64>
    + Components
    + Copy
    + Default
    + Debug
    + PartialEq
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Neg<Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign<f64>
{
    /// The Hessian of a constraint: `DMat2` or `DMat3`.
    type Hessian: Copy + Debug + PartialEq + Send + Sync + 'static;
    /// An angular velocity or acceleration: counter-clockwise radians per
    /// second (`f64`) in the plane, a vector along the axis in space.
    type Angular: Copy + Debug + Default + PartialEq + Send + Sync + 'static;
    /// How many components: 2 or 3.
    const DIMENSION: usize;
    /// The zero vector.
    const ZERO: Self;
    /// `H v`, as glam multiplies a matrix by a vector.
    fn hessian_times(hessian: &Self::Hessian, v: Self) -> Self;
    /// `ω × r`: the velocity a turn at `ω` gives the point `r` from its
    /// axis (`ω J r` in the plane).
    fn turn(omega: Self::Angular, r: Self) -> Self;
    /// `−ω × (ω × r)`, the centripetal pull's opposite: `ω² r` in the
    /// plane, `|ω|² r − ω (ω·r)` in space.
    fn centripetal(omega: Self::Angular, r: Self) -> Self;
    /// `2 ω`.
    fn twice(omega: Self::Angular) -> Self::Angular;
    /// The components, `z` zero in the plane.
    fn xyz(self) -> DVec3;
    /// The outer product `a bᵀ`.
    fn outer(a: Self, b: Self) -> Self::Hessian;
    /// A curve's second normal where `tangent` and `normal` are its unit
    /// tangent and first normal: `tangent × normal` in space; zero in the
    /// plane, where a curve has one normal.
    fn binormal(tangent: Self, normal: Self) -> Self;
    /// The point of `v`: `v` itself in space, its `x` and `y` in the
    /// plane.
    fn from_xyz(v: DVec3) -> Self;
}

/// `|v|`, as glam computes a length.
#[inline]
pub(crate) fn norm<V: Coordinates>(v: V) -> f64 {
    v.dot(v).sqrt()
}

impl Coordinates for DVec2 {
    type Hessian = DMat2;
    type Angular = f64;
    const DIMENSION: usize = 2;
    const ZERO: Self = DVec2::ZERO;
    #[inline(always)]
    fn hessian_times(hessian: &DMat2, v: Self) -> Self {
        *hessian * v
    }
    #[inline(always)]
    fn turn(omega: f64, r: Self) -> Self {
        omega * r.perp()
    }
    #[inline(always)]
    fn centripetal(omega: f64, r: Self) -> Self {
        omega * omega * r
    }
    #[inline(always)]
    fn twice(omega: f64) -> f64 {
        2.0 * omega
    }
    #[inline(always)]
    fn xyz(self) -> DVec3 {
        self.extend(0.0)
    }
    #[inline(always)]
    fn outer(a: Self, b: Self) -> DMat2 {
        DMat2::from_cols(a * b.x, a * b.y)
    }
    #[inline(always)]
    fn binormal(_tangent: Self, _normal: Self) -> Self {
        DVec2::ZERO
    }
    #[inline(always)]
    fn from_xyz(v: DVec3) -> Self {
        v.truncate()
    }
}

impl Coordinates for DVec3 {
    type Hessian = DMat3;
    type Angular = DVec3;
    const DIMENSION: usize = 3;
    const ZERO: Self = DVec3::ZERO;
    #[inline(always)]
    fn hessian_times(hessian: &DMat3, v: Self) -> Self {
        *hessian * v
    }
    #[inline(always)]
    fn turn(omega: DVec3, r: Self) -> Self {
        omega.cross(r)
    }
    #[inline(always)]
    fn centripetal(omega: DVec3, r: Self) -> Self {
        omega.length_squared() * r - omega.dot(r) * omega
    }
    #[inline(always)]
    fn twice(omega: DVec3) -> DVec3 {
        2.0 * omega
    }
    #[inline(always)]
    fn xyz(self) -> DVec3 {
        self
    }
    #[inline(always)]
    fn outer(a: Self, b: Self) -> DMat3 {
        DMat3::from_cols(a * b.x, a * b.y, a * b.z)
    }
    #[inline(always)]
    fn binormal(tangent: Self, normal: Self) -> Self {
        tangent.cross(normal)
    }
    #[inline(always)]
    fn from_xyz(v: DVec3) -> Self {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// In space, a turn about z acts on the xy-plane as the plane's turn
    /// does, and the centripetal term of a point off the axis is `ω² ρ`.
    #[test]
    fn a_turn_about_z_is_the_planes_turn() {
        let (w, r) = (1.5, DVec2::new(0.3, -0.7));
        let r3 = r.extend(0.0);
        let omega = DVec3::new(0.0, 0.0, w);
        assert_eq!(DVec3::turn(omega, r3).truncate(), DVec2::turn(w, r));
        assert!(
            (DVec3::centripetal(omega, r3).truncate() - DVec2::centripetal(w, r)).length() < 1e-15
        );
        // Along the axis there is no pull.
        let up = DVec3::new(0.0, 0.0, 2.0);
        assert_eq!(DVec3::centripetal(omega, up), DVec3::ZERO);
    }
}
