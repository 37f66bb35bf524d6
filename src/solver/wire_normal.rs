//! The wire's normal `N = ∇C` where a bead is: whether it is usable, and a
//! vector split into its part across the wire (along `N`) and its part
//! along the wire. Written once over [`Lane`], for one bead, for the
//! batched lanes and for an island's rows.

use crate::lane::{Lane, Vector};

/// The smallest `|N|²` a solve divides by: below it (or where it is not
/// finite) the normal vanishes and the bead is at a singular point of its
/// wire. The same bound holds a Newton step's slope `N·d` along the
/// direction `d` it moves in (`d` a normal too, so the slope is of the
/// order of `|N|²`).
pub(crate) const USABLE_NORMAL: f64 = 1e-24;

/// Whether `nn`, a `|N|²` or the size `|N·d|` of a Newton slope, is large
/// enough to divide by: finite and past [`USABLE_NORMAL`].
#[inline(always)]
pub(crate) fn usable<T: Lane>(nn: T) -> T::Mask {
    nn.is_finite() & nn.gt(nn.splat(USABLE_NORMAL))
}

/// The part of `v` across the wire: its component along `n`, whose
/// squared length is `nn`.
#[inline(always)]
pub(crate) fn across<T: Lane, V: Vector<T>>(n: V, nn: T, v: V) -> V {
    n.scale(n.dot(v) / nn)
}

/// The part of `v` along the wire: `v` without its component along `n`,
/// whose squared length is `nn`.
#[inline(always)]
pub(crate) fn along<T: Lane, V: Vector<T>>(n: V, nn: T, v: V) -> V {
    v - across(n, nn, v)
}
