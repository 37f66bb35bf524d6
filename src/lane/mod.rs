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

/// A symmetric Hessian on lanes, applied to a vector as glam's matrix
/// times a vector sums it.
pub(crate) trait Symmetric<V>: Copy {
    /// `H v`.
    fn apply(self, v: V) -> V;
}

/// The symmetric 2×2 Hessian `H` of a constraint, as its three entries.
#[derive(Clone, Copy)]
pub(crate) struct Sym2<T> {
    pub(crate) xx: T,
    pub(crate) xy: T,
    pub(crate) yy: T,
}

impl<T: Lane> Symmetric<V2<T>> for Sym2<T> {
    /// As glam's `DMat2 * DVec2` sums it.
    #[inline(always)]
    fn apply(self, v: V2<T>) -> V2<T> {
        V2::new(self.xx * v.x + self.xy * v.y, self.xy * v.x + self.yy * v.y)
    }
}

/// The symmetric 3×3 Hessian `H` of a constraint in space, as its six
/// entries.
#[derive(Clone, Copy)]
pub(crate) struct Sym3<T> {
    pub(crate) xx: T,
    pub(crate) xy: T,
    pub(crate) xz: T,
    pub(crate) yy: T,
    pub(crate) yz: T,
    pub(crate) zz: T,
}

impl<T: Lane> Symmetric<V3<T>> for Sym3<T> {
    /// As glam's `DMat3 * DVec3` sums it: column by column.
    #[inline(always)]
    fn apply(self, v: V3<T>) -> V3<T> {
        V3::new(
            self.xx * v.x + self.xy * v.y + self.xz * v.z,
            self.xy * v.x + self.yy * v.y + self.yz * v.z,
            self.xz * v.x + self.yz * v.y + self.zz * v.z,
        )
    }
}

/// The plane (`DVec2`) or space (`DVec3`) as the batched step takes it:
/// a vector of lanes, a symmetric Hessian, and [`LANES`] vectors stored as
/// one column of lanes per component, so that one batched step serves
/// circles in the plane and spheres in space.
pub(crate) trait LaneSpace: Vector<f64> + Copy {
    /// A vector of lanes: [`V2`] or [`V3`].
    type Lanes<T: Lane>: Vector<T>;
    /// A symmetric Hessian on lanes: [`Sym2`] or [`Sym3`].
    type Sym<T: Lane>: Symmetric<Self::Lanes<T>>;
    /// [`LANES`] vectors, one column of lanes per component.
    type Columns: Copy + Default + PartialEq + std::fmt::Debug + Send + Sync;
    /// `t` in every component.
    fn splat<T: Lane>(t: T) -> Self::Lanes<T>;
    /// The vector as one lane.
    fn one(self) -> Self::Lanes<f64>;
    /// One lane's vector as glam's.
    fn from_one(v: Self::Lanes<f64>) -> Self;
    /// Puts `v` into lane `lane` of `columns`.
    fn set(columns: &mut Self::Columns, lane: usize, v: Self);
    /// Lane `lane` of `columns`.
    fn get(columns: &Self::Columns, lane: usize) -> Self;
    /// The columns as a vector of AVX2 lanes.
    #[cfg(target_arch = "x86_64")]
    fn load(simd: pulp::x86::V3, columns: &Self::Columns) -> Self::Lanes<F64x8>;
    /// A vector of AVX2 lanes as columns.
    #[cfg(target_arch = "x86_64")]
    fn store(v: Self::Lanes<F64x8>) -> Self::Columns;
    /// `(I − n nᵀ) s`: the Hessian of a circle or a sphere, `n` its unit
    /// normal and `s` the reciprocal of the distance from its centre.
    fn round_hessian<T: Lane>(n: Self::Lanes<T>, s: T) -> Self::Sym<T>;
}

impl LaneSpace for bevy::math::DVec2 {
    type Lanes<T: Lane> = V2<T>;
    type Sym<T: Lane> = Sym2<T>;
    type Columns = [[f64; LANES]; 2];
    #[inline(always)]
    fn splat<T: Lane>(t: T) -> V2<T> {
        V2::new(t, t)
    }
    #[inline(always)]
    fn one(self) -> V2<f64> {
        self.into()
    }
    #[inline(always)]
    fn from_one(v: V2<f64>) -> Self {
        v.into()
    }
    #[inline(always)]
    fn set(columns: &mut Self::Columns, lane: usize, v: Self) {
        (columns[0][lane], columns[1][lane]) = (v.x, v.y);
    }
    #[inline(always)]
    fn get(columns: &Self::Columns, lane: usize) -> Self {
        Self::new(columns[0][lane], columns[1][lane])
    }
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn load(simd: pulp::x86::V3, [x, y]: &Self::Columns) -> V2<F64x8> {
        V2::new(F64x8::load(simd, x), F64x8::load(simd, y))
    }
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn store(v: V2<F64x8>) -> Self::Columns {
        [v.x.store(), v.y.store()]
    }
    #[inline(always)]
    fn round_hessian<T: Lane>(n: V2<T>, s: T) -> Sym2<T> {
        let one = s.splat(1.0);
        Sym2 {
            xx: (one - n.x * n.x) * s,
            xy: (-n.x * n.y) * s,
            yy: (one - n.y * n.y) * s,
        }
    }
}

impl LaneSpace for bevy::math::DVec3 {
    type Lanes<T: Lane> = V3<T>;
    type Sym<T: Lane> = Sym3<T>;
    type Columns = [[f64; LANES]; 3];
    #[inline(always)]
    fn splat<T: Lane>(t: T) -> V3<T> {
        V3::new(t, t, t)
    }
    #[inline(always)]
    fn one(self) -> V3<f64> {
        self.into()
    }
    #[inline(always)]
    fn from_one(v: V3<f64>) -> Self {
        v.into()
    }
    #[inline(always)]
    fn set(columns: &mut Self::Columns, lane: usize, v: Self) {
        (columns[0][lane], columns[1][lane], columns[2][lane]) = (v.x, v.y, v.z);
    }
    #[inline(always)]
    fn get(columns: &Self::Columns, lane: usize) -> Self {
        Self::new(columns[0][lane], columns[1][lane], columns[2][lane])
    }
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn load(simd: pulp::x86::V3, [x, y, z]: &Self::Columns) -> V3<F64x8> {
        V3::new(
            F64x8::load(simd, x),
            F64x8::load(simd, y),
            F64x8::load(simd, z),
        )
    }
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn store(v: V3<F64x8>) -> Self::Columns {
        [v.x.store(), v.y.store(), v.z.store()]
    }
    #[inline(always)]
    fn round_hessian<T: Lane>(n: V3<T>, s: T) -> Sym3<T> {
        let one = s.splat(1.0);
        Sym3 {
            xx: (one - n.x * n.x) * s,
            xy: (-n.x * n.y) * s,
            xz: (-n.x * n.z) * s,
            yy: (one - n.y * n.y) * s,
            yz: (-n.y * n.z) * s,
            zz: (one - n.z * n.z) * s,
        }
    }
}
