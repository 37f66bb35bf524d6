//! Eq. (17)'s friction and damping along a wire, written once over
//! [`Lane`] for a lone bead and for an island's rough rows: how hard the
//! wire presses, whether static friction holds, kinetic friction against
//! the sliding, viscous damping.
//!
//! What an island decides differently: whether a bead sticks. A lone
//! bead compares the applied force along the wire with static friction;
//! an island holds the bead with a stick row and compares that row's
//! multiplier (from the island's matrix solve) instead, by the same
//! [`holds`].

use crate::geometry::Friction;
use crate::lane::{Lane, Vector};

/// `|λ ∇C|`: how hard a wire of normal `∇C` (of squared length `nn`)
/// presses on its bead under the multiplier `lambda`.
#[inline(always)]
pub(crate) fn press<T: Lane>(lambda: T, nn: T) -> T {
    lambda.abs() * nn.sqrt()
}

/// Whether static friction holds a bead pulled along the wire with a force
/// of size `pull` while the wire presses with `press`: `pull ≤ μs press`.
#[inline(always)]
pub(crate) fn holds(friction: &Friction, pull: f64, press: f64) -> bool {
    pull <= friction.static_coefficient * press
}

/// Kinetic friction `−μk press d / |d|` against the direction `d` (of
/// length `length`, not zero) a bead slides or is pulled in.
#[inline(always)]
pub(crate) fn kinetic<T: Lane, V: Vector<T>>(friction: &Friction, press: T, d: V, length: T) -> V {
    d.scale(-(press.splat(friction.kinetic_coefficient) * press / length))
}

/// Viscous damping `−c v_t` on the velocity `sliding` along the wire.
#[inline(always)]
pub(crate) fn damping<T: Lane, V: Vector<T>>(c: f64, sliding: V) -> V {
    let speed_squared = sliding.dot(sliding);
    sliding.scale(speed_squared.splat(-c))
}
