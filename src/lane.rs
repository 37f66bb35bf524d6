//! The number type the step's formulas are written over: [`Lane`] is `f64`
//! for one bead, or [`F64x8`] for eight beads side by side, so each formula
//! is written once and both paths compute the same bits.
//!
//! [`F64x8`] holds two of pulp's four-lane AVX2 vectors and exists only
//! inside a function that pulp runs with AVX2 enabled (it carries pulp's
//! `V3` token, which only [`V3::try_new`] hands out on a processor that has
//! the instructions). Every operation used here (`+ - * /`, `sqrt`,
//! comparisons) is correctly rounded IEEE arithmetic in both the scalar and
//! the vector instructions, and nothing is fused into an FMA, so a lane of
//! [`F64x8`] computes bit for bit what `f64` computes.

use std::ops::{Add, BitAnd, Div, Mul, Neg, Sub};

use pulp::x86::V3;
use pulp::{Simd, f64x4, m64x4};

/// A number or a vector of numbers the step's formulas run on.
pub(crate) trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Per-lane truth values.
    type Mask: Copy + BitAnd<Output = Self::Mask>;
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
    /// `|self| <= bound` (false where either is NaN).
    fn abs_le(self, bound: Self) -> Self::Mask;
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
    fn abs_le(self, bound: Self) -> bool {
        self.abs() <= bound
    }
}

/// How many beads the batched step takes at once.
pub const LANES: usize = 8;

/// Eight `f64`s in two AVX2 registers, with the token that proves the
/// processor runs AVX2.
#[derive(Clone, Copy)]
pub(crate) struct F64x8 {
    simd: V3,
    v: [f64x4; 2],
}

/// Eight truth values, one per lane of an [`F64x8`].
#[derive(Clone, Copy)]
pub(crate) struct M64x8 {
    simd: V3,
    m: [m64x4; 2],
}

impl F64x8 {
    /// The lanes of `a`.
    #[inline(always)]
    pub(crate) fn load(simd: V3, a: &[f64; LANES]) -> Self {
        Self {
            simd,
            v: [f64x4(a[0], a[1], a[2], a[3]), f64x4(a[4], a[5], a[6], a[7])],
        }
    }

    /// The lanes as an array.
    #[inline(always)]
    pub(crate) fn store(self) -> [f64; LANES] {
        let [a, b] = self.v;
        [a.0, a.1, a.2, a.3, b.0, b.1, b.2, b.3]
    }

    #[inline(always)]
    fn map2(self, other: Self, f: impl Fn(V3, f64x4, f64x4) -> f64x4) -> Self {
        let s = self.simd;
        Self {
            simd: s,
            v: [f(s, self.v[0], other.v[0]), f(s, self.v[1], other.v[1])],
        }
    }

    #[inline(always)]
    fn map(self, f: impl Fn(V3, f64x4) -> f64x4) -> Self {
        let s = self.simd;
        Self {
            simd: s,
            v: [f(s, self.v[0]), f(s, self.v[1])],
        }
    }

    #[inline(always)]
    fn compare(self, other: Self, f: impl Fn(V3, f64x4, f64x4) -> m64x4) -> M64x8 {
        let s = self.simd;
        M64x8 {
            simd: s,
            m: [f(s, self.v[0], other.v[0]), f(s, self.v[1], other.v[1])],
        }
    }
}

impl M64x8 {
    /// The truth values as an array.
    #[inline(always)]
    pub(crate) fn store(self) -> [bool; LANES] {
        let [a, b] = self.m;
        [a.0, a.1, a.2, a.3, b.0, b.1, b.2, b.3].map(|m| m.is_set())
    }
}

impl BitAnd for M64x8 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, other: Self) -> Self {
        let s = self.simd;
        Self {
            simd: s,
            m: [
                s.and_m64s(self.m[0], other.m[0]),
                s.and_m64s(self.m[1], other.m[1]),
            ],
        }
    }
}

impl Add for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn add(self, other: Self) -> Self {
        self.map2(other, |s, a, b| s.add_f64s(a, b))
    }
}

impl Sub for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, other: Self) -> Self {
        self.map2(other, |s, a, b| s.sub_f64s(a, b))
    }
}

impl Mul for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, other: Self) -> Self {
        self.map2(other, |s, a, b| s.mul_f64s(a, b))
    }
}

impl Div for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn div(self, other: Self) -> Self {
        self.map2(other, |s, a, b| s.div_f64s(a, b))
    }
}

impl Neg for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        // Flips the sign bit, as `-x` does for an f64.
        self.map(|s, a| s.xor_f64s(a, s.splat_f64s(-0.0)))
    }
}

impl Lane for F64x8 {
    type Mask = M64x8;
    #[inline(always)]
    fn splat(self, v: f64) -> Self {
        self.map(|s, _| s.splat_f64s(v))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(|s, a| s.sqrt_f64s(a))
    }
    #[inline(always)]
    fn recip(self) -> Self {
        self.splat(1.0) / self
    }
    #[inline(always)]
    fn is_finite(self) -> M64x8 {
        let infinity = self.splat(f64::INFINITY);
        self.compare(infinity, |s, a, inf| s.less_than_f64s(s.abs_f64s(a), inf))
    }
    #[inline(always)]
    fn is_nonzero(self) -> M64x8 {
        let zero = self.splat(0.0);
        self.compare(zero, |s, a, z| s.not_m64s(s.equal_f64s(a, z)))
    }
    #[inline(always)]
    fn gt(self, other: Self) -> M64x8 {
        self.compare(other, |s, a, b| s.greater_than_f64s(a, b))
    }
    #[inline(always)]
    fn abs_le(self, bound: Self) -> M64x8 {
        self.compare(bound, |s, a, b| s.less_than_or_equal_f64s(s.abs_f64s(a), b))
    }
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

    /// `self · other`, as glam's `dot` sums it.
    #[inline(always)]
    pub(crate) fn dot(self, other: Self) -> T {
        self.x * other.x + self.y * other.y
    }

    /// `t self`.
    #[inline(always)]
    pub(crate) fn scale(self, t: T) -> Self {
        Self::new(t * self.x, t * self.y)
    }

    /// `self + t d`, as glam evaluates `a + t * d`.
    #[inline(always)]
    pub(crate) fn plus(self, t: T, d: Self) -> Self {
        Self::new(self.x + t * d.x, self.y + t * d.y)
    }

    /// Both components finite.
    #[inline(always)]
    pub(crate) fn is_finite(self) -> T::Mask {
        self.x.is_finite() & self.y.is_finite()
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

/// The processor's AVX2 token, if it has AVX2 (checked once, cached by
/// pulp).
#[inline]
pub(crate) fn avx2() -> Option<V3> {
    V3::try_new()
}
