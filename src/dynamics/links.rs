//! What joins beads: [`Rod`], [`Pin`] and a game's own [`Joint`] are
//! constraints, [`Spring`] is a force. Each is a component on an entity of
//! its own that names the beads it joins; beads so joined are stepped
//! together as an island (see [`solver::Island`](crate::solver::Island)).
//!
//! The links are immutable components: to change one, insert a new one
//! (or remove it). The plugin rebuilds the islands when a link, a bead or
//! a wire is inserted or removed, and only then.

use std::fmt;
use std::sync::Arc;

use bevy::ecs::query::QueryFilter;
use bevy::math::DVec2;
use bevy::prelude::*;

use super::Dimension;
use super::dimension::placed_by;
use crate::geometry::Coordinates;
use crate::solver::Constraint;
use crate::validate::{ParamError, finite_vector, non_negative, positive};

/// What a step reports of one constraint: its drift, the drift's rate and
/// its multiplier. Kept on every [`Rod`], [`Pin`] and [`Joint`].
///
/// A pin's rows (two in the plane, three in space) are reported together:
/// `c` is the bead's distance from its point, `c_dot` the rate of that
/// distance, `lambda` the length of the pin's force `(λx, λy[, λz])`.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Component)]
pub struct ConstraintDiagnostics {
    /// `C` after the last step.
    pub c: f64,
    /// `Ċ` after the last step.
    pub c_dot: f64,
    /// λ of the last step (for RATTLE the mean of its position and velocity
    /// multipliers). A rod under tension has λ < 0.
    pub lambda: f64,
}

fn distinct(a: Entity, b: Entity, what: &'static str) -> Result<(), ParamError> {
    if a == b {
        Err(ParamError::Incompatible(what))
    } else {
        Ok(())
    }
}

/// A massless rigid rod: keeps two beads at a fixed distance,
/// `|x_a − x_b| = length`.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[component(immutable)]
#[reflect(Component)]
#[require(ConstraintDiagnostics)]
pub struct Rod {
    a: Entity,
    b: Entity,
    length: f64,
}

impl Rod {
    /// A rod of `length` between beads `a` and `b`, if the length is
    /// positive and finite and the beads differ.
    pub fn new(a: Entity, b: Entity, length: f64) -> Result<Self, ParamError> {
        distinct(a, b, "a rod must join two different beads")?;
        positive("rod length", length)?;
        Ok(Self { a, b, length })
    }

    /// The two beads.
    pub fn beads(&self) -> [Entity; 2] {
        [self.a, self.b]
    }

    /// The length.
    pub fn length(&self) -> f64 {
        self.length
    }
}

/// Holds a bead at a point: two rows, `x − p = 0`. The point is fixed in
/// the world ([`Pin::new`]) or fixed to another entity ([`Pin::on`]), whose
/// `Transform` places it each step.
///
/// A pin on an entity that moves is held where the entity is at each
/// step; its velocity does not enter the step (no `∂C/∂t` term), so the
/// bead's velocity follows the point's with a step's lag.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[component(immutable)]
#[reflect(Component)]
#[require(ConstraintDiagnostics)]
pub struct Pin<V: Coordinates = DVec2> {
    bead: Entity,
    at: V,
    anchor: Option<Entity>,
}

impl<V: Dimension> Pin<V> {
    /// A pin holding `bead` at the world point `at`, if it is finite.
    pub fn new(bead: Entity, at: V) -> Result<Self, ParamError> {
        finite_vector("pin point", at)?;
        Ok(Self {
            bead,
            at,
            anchor: None,
        })
    }

    /// A pin holding `bead` at `offset` in the frame of `anchor`'s
    /// `Transform` (in the plane its translation and its rotation about
    /// z; in space all of it), if the offset is finite and the anchor is
    /// not the bead.
    pub fn on(bead: Entity, anchor: Entity, offset: V) -> Result<Self, ParamError> {
        distinct(bead, anchor, "a pin cannot be anchored to its own bead")?;
        finite_vector("pin offset", offset)?;
        Ok(Self {
            bead,
            at: offset,
            anchor: Some(anchor),
        })
    }

    /// The bead.
    pub fn bead(&self) -> Entity {
        self.bead
    }

    /// The point: in the world, or in the anchor's frame.
    pub fn at(&self) -> V {
        self.at
    }

    /// The entity the point is fixed to, if any.
    pub fn anchor(&self) -> Option<Entity> {
        self.anchor
    }

    /// The point in the world now: the fixed point, or the offset placed by
    /// the anchor's `Transform` read from `transforms`; `None` where the
    /// anchor has no finite `Transform` there.
    pub fn locate<F: QueryFilter>(&self, transforms: &Query<&Transform, F>) -> Option<V> {
        match self.anchor {
            None => Some(self.at),
            Some(anchor) => placed_by(transforms.get(anchor).ok()?, self.at),
        }
    }
}

/// A spring between two beads: a force, not a constraint. On bead `a`,
/// with `d = x_a − x_b` and `u = d/|d|`,
/// `f = −(stiffness (|d| − rest_length) + damping (v_a − v_b)·u) u`, and
/// the opposite on `b`.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[component(immutable)]
#[reflect(Component)]
pub struct Spring {
    a: Entity,
    b: Entity,
    rest_length: f64,
    stiffness: f64,
    damping: f64,
}

impl Spring {
    /// A spring between beads `a` and `b`, if they differ and the rest
    /// length, stiffness and damping are zero or more and finite.
    pub fn new(
        a: Entity,
        b: Entity,
        rest_length: f64,
        stiffness: f64,
        damping: f64,
    ) -> Result<Self, ParamError> {
        distinct(a, b, "a spring must join two different beads")?;
        non_negative("spring rest length", rest_length)?;
        non_negative("spring stiffness", stiffness)?;
        non_negative("spring damping", damping)?;
        Ok(Self {
            a,
            b,
            rest_length,
            stiffness,
            damping,
        })
    }

    /// The two beads.
    pub fn beads(&self) -> [Entity; 2] {
        [self.a, self.b]
    }

    /// Rest length, stiffness and damping.
    pub fn law(&self) -> (f64, f64, f64) {
        (self.rest_length, self.stiffness, self.damping)
    }
}

/// A constraint of the game's own among one or more beads, given by its
/// [`Constraint`] implementation; the beads are handed to it in the order
/// named here.
#[derive(Component, Clone)]
#[component(immutable)]
#[require(ConstraintDiagnostics)]
pub struct Joint<V: Dimension = DVec2> {
    beads: Vec<Entity>,
    constraint: Arc<dyn Constraint<V>>,
}

impl<V: Dimension> fmt::Debug for Joint<V> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Joint")
            .field("beads", &self.beads)
            .finish_non_exhaustive()
    }
}

impl<V: Dimension> Joint<V> {
    /// A joint among `beads` (at least one, all different).
    pub fn new(
        beads: Vec<Entity>,
        constraint: impl Constraint<V> + 'static,
    ) -> Result<Self, ParamError> {
        if beads.is_empty() {
            return Err(ParamError::Incompatible(
                "a joint must name at least one bead",
            ));
        }
        for (i, bead) in beads.iter().enumerate() {
            if beads[..i].contains(bead) {
                return Err(ParamError::Incompatible(
                    "a joint must name each bead only once",
                ));
            }
        }
        Ok(Self {
            beads,
            constraint: Arc::new(constraint),
        })
    }

    /// The beads, in the order the constraint takes them.
    pub fn beads(&self) -> &[Entity] {
        &self.beads
    }

    /// The constraint.
    pub fn constraint(&self) -> &Arc<dyn Constraint<V>> {
        &self.constraint
    }
}
