//! Newton's method on `C`, written once over [`Lane`] for one bead and
//! for the batched lanes: the root along a fixed direction (RATTLE's
//! position solve, eq. 8), the walk along the local gradient onto `C = 0`
//! (projection, eq. 9), the velocity's normal part removed after it, and
//! the stopping test.
//!
//! An island solves for all its rows at once: each of its Newton steps is
//! a matrix solve for the multipliers (`J W Jᵀ`, or `J W J₀ᵀ` for RATTLE),
//! so its iteration is its own; it stops by the same [`newton_within`] and
//! [`newton_accepted`].

use crate::lane::{Lane, Mask, Vector};

use super::wire_normal::{across, usable};

/// Tolerance on `|C|` for the Newton solves (RATTLE, projection), in units
/// of the wire's scale or of the point's largest coordinate, whichever is
/// larger: a few ulps, which Newton's quadratic convergence reaches in two
/// or three iterations, and below which rounding the coordinates keeps `C`
/// from going.
pub const NEWTON_TOLERANCE: f64 = 4.0 * f64::EPSILON;
/// Where rounding keeps `|C|` from reaching [`NEWTON_TOLERANCE`] (a bead
/// far from the origin beside its wire's scale), a residual below this (in
/// wire scales) is accepted once an iteration no longer halves it, or after
/// the last iteration.
pub const NEWTON_ACCEPT: f64 = 1e-10;
/// The most Newton iterations a solve takes before it gives up.
pub(crate) const NEWTON_MAX_ITERATIONS: u32 = 20;

/// Whether the residual `|C|` of a Newton solve is within
/// [`NEWTON_TOLERANCE`] of the constraint's `scale` or of the `reach` of
/// the point it is evaluated at (rounding keeps `C` from going below a few
/// ulps of them).
#[inline(always)]
pub(crate) fn newton_within<T: Lane>(residual: T, scale: T, reach: T) -> T::Mask {
    residual.abs_le(residual.splat(NEWTON_TOLERANCE) * scale.max(reach))
}

/// Whether a Newton solve that has not reached [`newton_within`] takes
/// its residual `|C|` anyway: within [`NEWTON_ACCEPT`] of the constraint's
/// `scale` and stalled (no smaller than half the `previous` residual), or
/// at the `last` iteration.
#[inline(always)]
pub(crate) fn newton_accepted<T: Lane>(residual: T, previous: T, scale: T, last: bool) -> T::Mask {
    let accepted = residual.abs_le(residual.splat(NEWTON_ACCEPT) * scale);
    if last {
        accepted
    } else {
        accepted & residual.gt(residual.splat(0.5) * previous)
    }
}

/// Whether a Newton solve on one constraint is done at residual `|C|`,
/// after the `previous` residual, at a point of the given `reach`:
/// [`newton_within`] or [`newton_accepted`]. An island, with a residual
/// for each row, asks [`newton_within`] of every row and
/// [`newton_accepted`] of its worst row relative to that row's scale.
#[inline(always)]
pub(crate) fn newton_done<T: Lane>(
    residual: T,
    previous: T,
    scale: T,
    reach: T,
    last: bool,
) -> T::Mask {
    newton_within(residual, scale, reach) | newton_accepted(residual, previous, scale, last)
}

/// A wire at one time as the Newton iterations see it, on lanes: `C` and
/// `∇C` at a point, whether its normal is usable there, and its own
/// velocity.
pub(crate) trait WireAt<T: Lane> {
    /// The vectors it takes and gives: in the plane or in space.
    type V: Vector<T>;
    /// The wire at a point: `C`, `∇C`, and what a caller reuses.
    type At: Copy;
    /// The wire at `p`.
    fn at(&self, p: Self::V) -> Self::At;
    /// `C` at a point.
    fn c(at: &Self::At) -> T;
    /// `∇C` at a point.
    fn normal(at: &Self::At) -> Self::V;
    /// `|∇C|²` at a point, and whether the normal there is usable.
    fn normal_length_squared(at: &Self::At) -> (T, T::Mask) {
        let n = Self::normal(at);
        let nn = n.dot(n);
        (nn, usable(nn))
    }
    /// `a` in the lanes where `mask` holds, `b` in the others.
    fn select(mask: T::Mask, a: Self::At, b: Self::At) -> Self::At;
    /// The velocity of the wire's point at `p` (zero on a fixed wire).
    fn velocity(&self, p: Self::V) -> Self::V;
}

/// Where a Newton iteration ended, in each lane.
#[derive(Clone, Copy)]
pub(crate) struct Root<T: Lane, P, A> {
    /// The root: the step `s` along the direction, or the point.
    pub(crate) root: P,
    /// The wire at the root (in the lanes `found`).
    pub(crate) at: A,
    /// The lanes that reached the tolerance.
    pub(crate) found: T::Mask,
    /// The lanes that took every iteration without reaching it; the
    /// others that did not find it stopped at a singular point (where
    /// the root holds the last point) or never started.
    pub(crate) running: T::Mask,
    /// The last `|C|`.
    pub(crate) residual: T,
}

/// What a Newton iteration moves, and how it moves it.
trait Walk<T: Lane, W: WireAt<T>> {
    /// The point the wire is evaluated at.
    fn point(&self) -> W::V;
    /// One Newton step from the point, where the wire is `g` and `C` is
    /// `c`, in the lanes `active`; returns the lanes it could take it in
    /// (the others stay where they are).
    fn step(&mut self, g: &W::At, c: T, active: T::Mask) -> T::Mask;
}

/// Newton's method on `C` from `walk`'s point, where the wire is `start`,
/// in the lanes `active` at the start, for a wire of size `scale`, until
/// [`newton_done`]: the wire where each lane stopped and why.
#[inline(always)]
fn newton<T: Lane, W: WireAt<T>, K: Walk<T, W>>(
    wire: &W,
    mut walk: K,
    start: W::At,
    scale: T,
    active: T::Mask,
) -> Root<T, K, W::At> {
    let mut active = active;
    let mut found = active & !active;
    let mut previous = scale.splat(f64::INFINITY);
    let mut p = walk.point();
    let mut g = start;
    let mut end = start;
    for i in 0..=NEWTON_MAX_ITERATIONS {
        let c = W::c(&g);
        let last = i == NEWTON_MAX_ITERATIONS;
        let done = active & newton_done(c.abs(), previous, scale, p.reach(), last);
        previous = c.abs();
        end = W::select(done, g, end);
        found = found | done;
        active = active & !done;
        if last || !active.any() {
            break;
        }
        active = walk.step(&g, c, active);
        p = walk.point();
        g = wire.at(p);
    }
    Root {
        root: walk,
        at: end,
        found,
        running: active,
        residual: previous,
    }
}

/// The walk of [`newton_along`]: `base + s dir`.
struct Along<V, T> {
    base: V,
    dir: V,
    s: T,
}

impl<T: Lane, W: WireAt<T>> Walk<T, W> for Along<W::V, T> {
    #[inline(always)]
    fn point(&self) -> W::V {
        self.base.plus(self.s, self.dir)
    }
    #[inline(always)]
    fn step(&mut self, g: &W::At, c: T, active: T::Mask) -> T::Mask {
        let slope = W::normal(g).dot(self.dir);
        let active = active & usable(slope.abs());
        self.s = T::select(active, self.s - c / slope, self.s);
        active
    }
}

/// The walk of [`newton_onto`]: along the local gradient.
struct Onto<V> {
    x: V,
}

impl<T: Lane, W: WireAt<T>> Walk<T, W> for Onto<W::V> {
    #[inline(always)]
    fn point(&self) -> W::V {
        self.x
    }
    #[inline(always)]
    fn step(&mut self, g: &W::At, c: T, active: T::Mask) -> T::Mask {
        let (nn, usable) = W::normal_length_squared(g);
        let active = active & usable;
        self.x = W::V::select(active, self.x - W::normal(g).scale(c / nn), self.x);
        active
    }
}

impl<T: Lane, P, A> Root<T, P, A> {
    /// The same ending with `root` as its root.
    #[inline(always)]
    fn with<Q>(self, root: Q) -> Root<T, Q, A> {
        Root {
            root,
            at: self.at,
            found: self.found,
            running: self.running,
            residual: self.residual,
        }
    }
}

/// Newton's method on `s ↦ C(base + s dir)`: the root `s`, in the lanes
/// `active` at the start, for a wire of size `scale`. A lane stops where
/// the slope `∇C·dir` is not usable; its point is then `base + s dir`.
#[inline(always)]
pub(crate) fn newton_along<T: Lane, W: WireAt<T>>(
    wire: &W,
    base: W::V,
    dir: W::V,
    scale: T,
    active: T::Mask,
) -> Root<T, T, W::At> {
    let walk = Along {
        base,
        dir,
        s: scale.splat(0.0),
    };
    // At s = 0 too the point is `base + 0 dir` (a zero's sign can differ
    // from `base`'s).
    let start = wire.at(Walk::<T, W>::point(&walk));
    let r = newton(wire, walk, start, scale, active);
    let s = r.root.s;
    r.with(s)
}

/// Newton steps along the local gradient from `x` (where the wire is
/// `start`) onto `C = 0`, in the lanes `active` at the start, for a wire
/// of size `scale`: the point reached. A lane stops where the normal is
/// not usable, its point left where it was.
#[inline(always)]
pub(crate) fn newton_onto<T: Lane, W: WireAt<T>>(
    wire: &W,
    x: W::V,
    start: W::At,
    scale: T,
    active: T::Mask,
) -> Root<T, W::V, W::At> {
    let r = newton(wire, Onto { x }, start, scale, active);
    let x = r.root.x;
    r.with(x)
}

/// `v` at `p` (where the wire is `at`) without the part of its normal
/// component that the wire does not share: `∇C·(v − w) = 0` afterwards;
/// and the lanes where the normal is usable.
#[inline(always)]
pub(crate) fn tangential<T: Lane, W: WireAt<T>>(
    wire: &W,
    at: &W::At,
    p: W::V,
    v: W::V,
) -> (W::V, T::Mask) {
    let (nn, ok) = W::normal_length_squared(at);
    let w = wire.velocity(p);
    (v - across(W::normal(at), nn, v - w), ok)
}
