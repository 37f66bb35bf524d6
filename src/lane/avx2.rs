//! [`F64x8`]: eight lanes in two AVX2 registers (x86-64 only).

use std::arch::x86_64::{__m256d, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _CMP_NEQ_UQ};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use pulp::cast;
use pulp::x86::V3;

use super::{LANES, Lane, Mask};

/// Eight `f64`s in two AVX2 registers, with the token that proves the
/// processor runs AVX2 (the intrinsics are pulp's safe wrappers, callable
/// only through the token).
#[derive(Clone, Copy)]
pub(crate) struct F64x8 {
    simd: V3,
    v: [__m256d; 2],
}

/// Eight truth values, one per lane of an [`F64x8`]: all bits set or none.
#[derive(Clone, Copy)]
pub(crate) struct M64x8 {
    simd: V3,
    m: [__m256d; 2],
}

/// The same AVX intrinsic on each half (no closure, so every call is
/// inlined into pulp's AVX2 function).
macro_rules! halves {
    ($s:ident, $op:ident $(::<$c:ident>)? ($($arg:expr),*)) => {
        [$s.avx.$op$(::<$c>)?($($arg[0]),*), $s.avx.$op$(::<$c>)?($($arg[1]),*)]
    };
}

impl F64x8 {
    /// The lanes of `a`.
    #[inline(always)]
    pub(crate) fn load(simd: V3, a: &[f64; LANES]) -> Self {
        Self {
            simd,
            v: [
                cast::<[f64; 4], __m256d>([a[0], a[1], a[2], a[3]]),
                cast::<[f64; 4], __m256d>([a[4], a[5], a[6], a[7]]),
            ],
        }
    }

    /// The lanes as an array.
    #[inline(always)]
    pub(crate) fn store(self) -> [f64; LANES] {
        let [a, b] = self.v.map(cast::<__m256d, [f64; 4]>);
        [a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]]
    }

    #[inline(always)]
    fn with(self, v: [__m256d; 2]) -> Self {
        Self { simd: self.simd, v }
    }

    #[inline(always)]
    fn mask(self, m: [__m256d; 2]) -> M64x8 {
        M64x8 { simd: self.simd, m }
    }
}

impl M64x8 {
    /// The truth values as an array.
    #[inline(always)]
    pub(crate) fn store(self) -> [bool; LANES] {
        let s = self.simd;
        let [a, b] = halves!(s, _mm256_movemask_pd(self.m));
        std::array::from_fn(|i| (if i < 4 { a >> i } else { b >> (i - 4) }) & 1 == 1)
    }
}

impl BitAnd for M64x8 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, other: Self) -> Self {
        let s = self.simd;
        Self {
            simd: s,
            m: halves!(s, _mm256_and_pd(self.m, other.m)),
        }
    }
}

impl BitOr for M64x8 {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, other: Self) -> Self {
        let s = self.simd;
        Self {
            simd: s,
            m: halves!(s, _mm256_or_pd(self.m, other.m)),
        }
    }
}

impl Not for M64x8 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        let s = self.simd;
        let all = [cast::<[u64; 4], __m256d>([u64::MAX; 4]); 2];
        Self {
            simd: s,
            m: halves!(s, _mm256_xor_pd(self.m, all)),
        }
    }
}

impl Mask for M64x8 {
    #[inline(always)]
    fn any(self) -> bool {
        let s = self.simd;
        let [a, b] = halves!(s, _mm256_movemask_pd(self.m));
        (a | b) != 0
    }
}

impl Add for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn add(self, other: Self) -> Self {
        let s = self.simd;
        self.with(halves!(s, _mm256_add_pd(self.v, other.v)))
    }
}

impl Sub for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, other: Self) -> Self {
        let s = self.simd;
        self.with(halves!(s, _mm256_sub_pd(self.v, other.v)))
    }
}

impl Mul for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, other: Self) -> Self {
        let s = self.simd;
        self.with(halves!(s, _mm256_mul_pd(self.v, other.v)))
    }
}

impl Div for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn div(self, other: Self) -> Self {
        let s = self.simd;
        self.with(halves!(s, _mm256_div_pd(self.v, other.v)))
    }
}

impl Neg for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        // Flips the sign bit, as `-x` does for an f64.
        let s = self.simd;
        let sign = [s.avx._mm256_set1_pd(-0.0); 2];
        self.with(halves!(s, _mm256_xor_pd(self.v, sign)))
    }
}

impl Lane for F64x8 {
    type Mask = M64x8;
    #[inline(always)]
    fn splat(self, v: f64) -> Self {
        self.with([self.simd.avx._mm256_set1_pd(v); 2])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let s = self.simd;
        self.with(halves!(s, _mm256_sqrt_pd(self.v)))
    }
    #[inline(always)]
    fn recip(self) -> Self {
        self.splat(1.0) / self
    }
    #[inline(always)]
    fn is_finite(self) -> M64x8 {
        // |x| < ∞, false for NaN (an ordered comparison).
        let s = self.simd;
        let abs = halves!(s, _mm256_andnot_pd([s.avx._mm256_set1_pd(-0.0); 2], self.v));
        let infinity = [s.avx._mm256_set1_pd(f64::INFINITY); 2];
        self.mask(halves!(s, _mm256_cmp_pd::<_CMP_LT_OQ>(abs, infinity)))
    }
    #[inline(always)]
    fn is_nonzero(self) -> M64x8 {
        // Unordered not-equal: true for NaN, as `x != 0.0` is.
        let s = self.simd;
        let zero = [s.avx._mm256_set1_pd(0.0); 2];
        self.mask(halves!(s, _mm256_cmp_pd::<_CMP_NEQ_UQ>(self.v, zero)))
    }
    #[inline(always)]
    fn gt(self, other: Self) -> M64x8 {
        let s = self.simd;
        self.mask(halves!(s, _mm256_cmp_pd::<_CMP_GT_OQ>(self.v, other.v)))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // Clears the sign bit, as `f64::abs` does.
        let s = self.simd;
        self.with(halves!(
            s,
            _mm256_andnot_pd([s.avx._mm256_set1_pd(-0.0); 2], self.v)
        ))
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        let s = self.simd;
        self.with(halves!(s, _mm256_max_pd(self.v, other.v)))
    }
    #[inline(always)]
    fn abs_le(self, bound: Self) -> M64x8 {
        let s = self.simd;
        let abs = halves!(s, _mm256_andnot_pd([s.avx._mm256_set1_pd(-0.0); 2], self.v));
        self.mask(halves!(s, _mm256_cmp_pd::<_CMP_LE_OQ>(abs, bound.v)))
    }
    #[inline(always)]
    fn select(mask: M64x8, a: Self, b: Self) -> Self {
        // blendv takes each lane from its second operand where the mask's
        // sign bit is set.
        let s = a.simd;
        a.with(halves!(s, _mm256_blendv_pd(b.v, a.v, mask.m)))
    }
}

/// The processor's AVX2 token, if it has AVX2 (checked once, cached by
/// pulp).
#[inline]
pub(crate) fn avx2() -> Option<V3> {
    V3::try_new()
}
