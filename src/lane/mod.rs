//! The number type the step's formulas are written over: [`Lane`] is `f64`
//! for one bead, or [`F64x8`] for eight beads side by side, so each formula
//! is written once and both paths compute the same bits.
//!
//! [`F64x8`] holds two four-lane AVX2 registers and exists only inside a
//! function that pulp runs with AVX2 enabled: it carries pulp's `V3` token,
//! which only [`V3::try_new`] hands out on a processor that has the
//! instructions, and works through pulp's safe wrappers of the intrinsics. Every operation used here (`+ - * /`, `sqrt`,
//! comparisons) is correctly rounded IEEE arithmetic in both the scalar and
//! the vector instructions, and nothing is fused into an FMA, so a lane of
//! [`F64x8`] computes bit for bit what `f64` computes.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
pub(crate) use avx2::{F64x8, avx2};

/// A number or a vector of numbers the step's formulas run on.
pub trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Per-lane truth values.
    type Mask: Mask;
    /// `v` in every lane.
    fn splat(self, v: f64) -> Self;
    /// The square root, correctly rounded.
    fn sqrt(self) -> Self;
    /// `1 / self`, as `f64::recip` computes it.
    fn recip(self) -> Self;
    /// Neither NaN nor infinite.
    fn is_finite(self) -> Self::Mask;
    /// `self != 0`.
    fn is_nonzero(self) -> Self::Mask;
    /// `self > other` (false where either is NaN).
    fn gt(self, other: Self) -> Self::Mask;
    /// `|self|`.
    fn abs(self) -> Self;
    /// The larger of `self` and `other`, as `f64::max` gives it where
    /// neither is NaN.
    fn max(self, other: Self) -> Self;
    /// `|self| <= bound` (false where either is NaN).
    fn abs_le(self, bound: Self) -> Self::Mask;
    /// `a` in the lanes where `mask` holds, `b` in the others.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
}

/// Per-lane truth values: `bool` for one bead, a mask for eight.
pub trait Mask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    /// Whether any lane holds.
    fn any(self) -> bool;
}

impl Mask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
}

impl Lane for f64 {
    type Mask = bool;
    #[inline(always)]
    fn splat(self, v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn recip(self) -> Self {
        f64::recip(self)
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    #[inline(always)]
    fn is_nonzero(self) -> bool {
        self != 0.0
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64::max(self, other)
    }
    #[inline(always)]
    fn abs_le(self, bound: Self) -> bool {
        self.abs() <= bound
    }
    #[inline(always)]
    fn select(mask: bool, a: Self, b: Self) -> Self {
        if mask { a } else { b }
    }
}

/// How many beads the batched step takes at once.
pub const LANES: usize = 8;

/// A vector of lanes in the plane or in space: what the step's formulas
/// take positions, velocities, forces and normals as, so that each is
/// written once for both dimensions. [`V2`] and [`V3`] implement it; every
/// operation is componentwise or a sum in the order glam sums it.
pub trait Vector<T: Lane>: Copy + Add<Output = Self> + Sub<Output = Self> {
    /// `self · other`, as glam's `dot` sums it.
    fn dot(self, other: Self) -> T;
    /// `t self`.
    fn scale(self, t: T) -> Self;
    /// `self + t d`, as glam evaluates `a + t * d`.
    fn plus(self, t: T, d: Self) -> Self;
    /// `self / t`, as glam divides a vector by a number.
    fn div(self, t: T) -> Self;
    /// `a` in the lanes where `mask` holds, `b` in the others.
    fn select(mask: T::Mask, a: Self, b: Self) -> Self;
    /// Every component finite.
    fn is_finite(self) -> T::Mask;
    /// The size of the largest component: how far from the origin
    /// rounding the coordinates reaches.
    fn reach(self) -> T;
}

/// A 2-vector of lanes: `x` and `y` of one bead, or of eight.
#[derive(Clone, Copy)]
pub(crate) struct V2<T> {
    pub(crate) x: T,
    pub(crate) y: T,
}

impl<T: Lane> V2<T> {
    /// `(x, y)`.
    #[inline(always)]
    pub(crate) fn new(x: T, y: T) -> Self {
        Self { x, y }
    }
}

impl<T: Lane> Vector<T> for V2<T> {
    #[inline(always)]
    fn dot(self, other: Self) -> T {
        self.x * other.x + self.y * other.y
    }
    #[inline(always)]
    fn scale(self, t: T) -> Self {
        Self::new(t * self.x, t * self.y)
    }
    #[inline(always)]
    fn plus(self, t: T, d: Self) -> Self {
        Self::new(self.x + t * d.x, self.y + t * d.y)
    }
    #[inline(always)]
    fn div(self, t: T) -> Self {
        Self::new(self.x / t, self.y / t)
    }
    #[inline(always)]
    fn select(mask: T::Mask, a: Self, b: Self) -> Self {
        Self::new(T::select(mask, a.x, b.x), T::select(mask, a.y, b.y))
    }
    #[inline(always)]
    fn is_finite(self) -> T::Mask {
        self.x.is_finite() & self.y.is_finite()
    }
    #[inline(always)]
    fn reach(self) -> T {
        self.x.abs().max(self.y.abs())
    }
}

impl<T: Lane> Add for V2<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y)
    }
}

impl<T: Lane> Sub for V2<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y)
    }
}

impl From<bevy::math::DVec2> for V2<f64> {
    #[inline(always)]
    fn from(v: bevy::math::DVec2) -> Self {
        Self::new(v.x, v.y)
    }
}

impl From<V2<f64>> for bevy::math::DVec2 {
    #[inline(always)]
    fn from(v: V2<f64>) -> Self {
        Self::new(v.x, v.y)
    }
}

/// glam's vectors are vectors of one lane: the scalar paths pass them to
/// the formulas as they are. Each operation is glam's own, which sums and
/// rounds as [`V2`] and [`V3`] do.
macro_rules! glam_vector {
    ($($v:ty),*) => {$(
        impl Vector<f64> for $v {
            #[inline(always)]
            fn dot(self, other: Self) -> f64 {
                <$v>::dot(self, other)
            }
            #[inline(always)]
            fn scale(self, t: f64) -> Self {
                t * self
            }
            #[inline(always)]
            fn plus(self, t: f64, d: Self) -> Self {
                self + t * d
            }
            #[inline(always)]
            fn div(self, t: f64) -> Self {
                self / t
            }
            #[inline(always)]
            fn select(mask: bool, a: Self, b: Self) -> Self {
                if mask { a } else { b }
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                <$v>::is_finite(self)
            }
            #[inline(always)]
            fn reach(self) -> f64 {
                self.abs().max_element()
            }
        }
    )*};
}

glam_vector!(bevy::math::DVec2, bevy::math::DVec3);

/// A 3-vector of lanes: `x`, `y` and `z` of one bead in space, or of
/// eight.
#[derive(Clone, Copy)]
pub(crate) struct V3<T> {
    pub(crate) x: T,
    pub(crate) y: T,
    pub(crate) z: T,
}

impl<T: Lane> V3<T> {
    /// `(x, y, z)`.
    #[inline(always)]
    pub(crate) fn new(x: T, y: T, z: T) -> Self {
        Self { x, y, z }
    }
}

impl<T: Lane> Vector<T> for V3<T> {
    #[inline(always)]
    fn dot(self, other: Self) -> T {
        self.x * other.x + self.y * other.y + self.z * other.z
    }
    #[inline(always)]
    fn scale(self, t: T) -> Self {
        Self::new(t * self.x, t * self.y, t * self.z)
    }
    #[inline(always)]
    fn plus(self, t: T, d: Self) -> Self {
        Self::new(self.x + t * d.x, self.y + t * d.y, self.z + t * d.z)
    }
    #[inline(always)]
    fn div(self, t: T) -> Self {
        Self::new(self.x / t, self.y / t, self.z / t)
    }
    #[inline(always)]
    fn select(mask: T::Mask, a: Self, b: Self) -> Self {
        Self::new(
            T::select(mask, a.x, b.x),
            T::select(mask, a.y, b.y),
            T::select(mask, a.z, b.z),
        )
    }
    #[inline(always)]
    fn is_finite(self) -> T::Mask {
        self.x.is_finite() & self.y.is_finite() & self.z.is_finite()
    }
    #[inline(always)]
    fn reach(self) -> T {
        self.x.abs().max(self.y.abs()).max(self.z.abs())
    }
}

impl<T: Lane> Add for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<T: Lane> Sub for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl From<bevy::math::DVec3> for V3<f64> {
    #[inline(always)]
    fn from(v: bevy::math::DVec3) -> Self {
        Self::new(v.x, v.y, v.z)
    }
}

impl From<V3<f64>> for bevy::math::DVec3 {
    #[inline(always)]
    fn from(v: V3<f64>) -> Self {
        Self::new(v.x, v.y, v.z)
    }
}

/// The symmetric 2×2 Hessian `H` of a constraint, as its three entries.
#[derive(Clone, Copy)]
pub(crate) struct Sym2<T> {
    pub(crate) xx: T,
    pub(crate) xy: T,
    pub(crate) yy: T,
}

impl<T: Lane> Sym2<T> {
    /// `H v`, as glam's `DMat2 * DVec2` sums it.
    #[inline(always)]
    pub(crate) fn apply(self, v: V2<T>) -> V2<T> {
        V2::new(self.xx * v.x + self.xy * v.y, self.xy * v.x + self.yy * v.y)
    }
}
