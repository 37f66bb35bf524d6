//! Constraint rows: what one constraint contributes to eq. (12), and the
//! [`Constraint`] trait for a game's own. Springs, which are forces and not
//! constraints, are here too, since they also join beads.

use std::fmt;
use std::sync::Arc;

use bevy::math::DVec2;

use super::error::IslandError;
use crate::geometry::{Coordinates, WireSpace, placed_geometry};

/// A constraint of a game's own among one or more beads: `C(x₁, …, xₖ) = 0`.
///
/// As [`ImplicitCurve`](crate::geometry::ImplicitCurve) is for wires: give `C`, its gradient with respect
/// to each bead's position, and the curvature term `J̇q̇` of `C̈`; the
/// island solver does the rest. The slices hold the positions (and
/// velocities) of the beads the constraint names, in the order it names
/// them. `value`, `gradient` and `curvature` must agree (`gradient` the
/// derivative of `value`, `curvature` the second derivative along `v`).
pub trait Constraint<V = DVec2>: Send + Sync {
    /// `C` at the beads' positions `x`.
    fn value(&self, x: &[V]) -> f64;
    /// `∂C/∂xᵢ` for each bead, written into `gradient` (as long as `x`).
    fn gradient(&self, x: &[V], gradient: &mut [V]);
    /// `J̇q̇ = Σᵢⱼ vᵢᵀ (∂²C/∂xᵢ∂xⱼ) vⱼ` at positions `x`, velocities `v`.
    fn curvature(&self, x: &[V], v: &[V]) -> f64;
    /// A characteristic length: the Newton tolerance and the divergence
    /// bound are in units of it.
    fn scale(&self) -> f64 {
        1.0
    }
}

/// What one row of an island is, in the plane (the default) or in space.
#[derive(Clone)]
pub enum RowKind<V: WireSpace = DVec2> {
    /// One bead on a wire placed by `pose`: `C = C_wire(x)`.
    Wire {
        /// The wire's shape.
        shape: V::Shape,
        /// Where it sits.
        pose: V::Pose,
    },
    /// Two beads at a fixed distance: `C = |x_a − x_b| − length`.
    Rod {
        /// The rod's length, positive.
        length: f64,
    },
    /// One bead on a line through a fixed point: `C = axis·x − offset`
    /// (`axis` a unit vector). A pin is two of these.
    Axis {
        /// The line's normal, of unit length.
        axis: V,
        /// `axis·p` for the point `p` the bead is held at.
        offset: f64,
    },
    /// A game's own constraint.
    Custom(Arc<dyn Constraint<V>>),
}

impl<V: WireSpace> fmt::Debug for RowKind<V> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Wire { shape, pose } => f
                .debug_struct("Wire")
                .field("shape", shape)
                .field("pose", pose)
                .finish(),
            Self::Rod { length } => f.debug_struct("Rod").field("length", length).finish(),
            Self::Axis { axis, offset } => f
                .debug_struct("Axis")
                .field("axis", axis)
                .field("offset", offset)
                .finish(),
            Self::Custom(_) => f.write_str("Custom(..)"),
        }
    }
}

impl<V: WireSpace> RowKind<V> {
    /// How many beads the row joins, where the kind fixes it.
    pub(crate) fn arity(&self) -> Option<usize> {
        match self {
            Self::Wire { .. } | Self::Axis { .. } => Some(1),
            Self::Rod { .. } => Some(2),
            Self::Custom(_) => None,
        }
    }

    /// The characteristic length of the row.
    pub(crate) fn scale(&self) -> f64 {
        match self {
            Self::Wire { shape, .. } => V::shape_scale(shape),
            Self::Rod { length } => *length,
            Self::Axis { .. } => 1.0,
            Self::Custom(c) => c.scale(),
        }
    }

    /// `C`, its gradient (into `gradient`, one entry per bead of `beads`)
    /// and, where `rates`, `J̇q̇` (else zero), where the island's beads are
    /// at `x` with velocities `v`.
    /// `scratch` gathers a custom constraint's beads; `hint` is a wire's
    /// curve parameter where its bead was (see [`ImplicitCurve::parameter`](crate::geometry::ImplicitCurve::parameter)).
    #[inline]
    pub(crate) fn evaluate(
        &self,
        beads: &[usize],
        x: &[V],
        v: &[V],
        gradient: &mut [V],
        scratch: &mut Vec<V>,
        hint: f64,
        rates: bool,
    ) -> (f64, f64) {
        match self {
            Self::Wire { shape, pose } => {
                let (p, u) = (x[beads[0]], v[beads[0]]);
                let g =
                    placed_geometry(pose, p, |local| V::shape_geometry(shape, local, Some(hint)));
                gradient[0] = g.normal;
                let bend = if rates {
                    u.dot(V::hessian_times(&g.hessian, u))
                } else {
                    0.0
                };
                (g.c, bend)
            }
            Self::Rod { length } => {
                let (a, b) = (beads[0], beads[1]);
                let d = x[a] - x[b];
                let distance = d.dot(d).sqrt();
                let n = d / distance;
                gradient[0] = n;
                gradient[1] = -n;
                if !rates {
                    return (distance - length, 0.0);
                }
                let relative = v[a] - v[b];
                let along = n.dot(relative);
                (
                    distance - length,
                    (relative.dot(relative) - along * along) / distance,
                )
            }
            Self::Axis { axis, offset } => {
                gradient[0] = *axis;
                (axis.dot(x[beads[0]]) - offset, 0.0)
            }
            Self::Custom(constraint) => {
                scratch.clear();
                scratch.extend(beads.iter().map(|&i| x[i]));
                scratch.extend(beads.iter().map(|&i| v[i]));
                let (xs, vs) = scratch.split_at(beads.len());
                constraint.gradient(xs, gradient);
                let bend = if rates {
                    constraint.curvature(xs, vs)
                } else {
                    0.0
                };
                (constraint.value(xs), bend)
            }
        }
    }
}

/// A spring between two beads of an island: a force, not a constraint.
/// On bead `a`, with `d = x_a − x_b` and `u = d/|d|`:
/// `f = −(k (|d| − L) + c (v_a − v_b)·u) u`; bead `b` feels `−f`. Two beads
/// at the same point feel no force from it (there is no direction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpringLink {
    /// The first bead (its index in the island).
    pub a: usize,
    /// The second bead.
    pub b: usize,
    /// Rest length `L`, zero or more.
    pub rest_length: f64,
    /// Stiffness `k` (N/m), zero or more.
    pub stiffness: f64,
    /// Damping `c` along the spring (N·s/m), zero or more.
    pub damping: f64,
}

impl SpringLink {
    /// The force on bead `a` where the beads are at `x` with velocities
    /// `v`; an error names the bead `x` or `v` has no entry for.
    pub fn force<V: Coordinates>(&self, x: &[V], v: &[V]) -> Result<V, IslandError> {
        self.holds("positions", x.len())?;
        self.holds("velocities", v.len())?;
        Ok(self.pull(x, v))
    }

    /// The energy stored in the spring where the beads are at `x`; an
    /// error names the bead `x` has no entry for.
    pub fn energy<V: Coordinates>(&self, x: &[V]) -> Result<f64, IslandError> {
        self.holds("positions", x.len())?;
        Ok(self.stored(x[self.a], x[self.b]))
    }

    /// Whether a slice of `len` entries, `what` in words, has both ends.
    fn holds(&self, what: &str, len: usize) -> Result<(), IslandError> {
        match [self.a, self.b].into_iter().find(|&bead| bead >= len) {
            Some(bead) => Err(IslandError::MissingBead {
                item: format!(
                    "the spring from bead {} to bead {} ({what})",
                    self.a, self.b
                ),
                bead,
                beads: len,
            }),
            None => Ok(()),
        }
    }

    /// [`SpringLink::force`] where `x` and `v` are known to hold both
    /// ends.
    #[inline]
    pub(crate) fn pull<V: Coordinates>(&self, x: &[V], v: &[V]) -> V {
        let d = x[self.a] - x[self.b];
        let distance = d.dot(d).sqrt();
        if distance.is_nan() || distance <= 0.0 {
            return V::ZERO;
        }
        let u = d / distance;
        let stretch = distance - self.rest_length;
        let rate = (v[self.a] - v[self.b]).dot(u);
        u * -(self.stiffness * stretch + self.damping * rate)
    }

    /// The energy stored in the spring with its ends at `a` and `b`.
    pub(crate) fn stored<V: Coordinates>(&self, a: V, b: V) -> f64 {
        let d = a - b;
        let stretch = d.dot(d).sqrt() - self.rest_length;
        0.5 * self.stiffness * stretch * stretch
    }
}
