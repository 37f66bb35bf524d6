//! [`Bead`]: a particle's parameters and `f64` state, with the force
//! accumulated for the next step; its parameters for the next run and the
//! spring anchor that pulls it.

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::geometry::Twist;
use crate::solver::{BeadState, LinearForce};
use crate::validate::{ParamError, finite_vector, positive};

/// The per-bead parameters of the assignment's panel: mass, initial position and
/// initial velocity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Reflect)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct BeadParams {
    /// Mass in kg.
    pub mass: f64,
    /// Where a restart puts the bead.
    pub initial_position: DVec2,
    /// The velocity a restart gives it.
    pub initial_velocity: DVec2,
}

impl Default for BeadParams {
    fn default() -> Self {
        Self {
            mass: 1.0,
            initial_position: DVec2::new(0.0, -1.0),
            initial_velocity: DVec2::ZERO,
        }
    }
}

impl BeadParams {
    /// Checks every field; the first problem found is returned.
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("mass", self.mass)?;
        finite_vector("initial position", self.initial_position)?;
        finite_vector("initial velocity", self.initial_velocity).map(drop)
    }
}

/// A bead: its applied parameters, its `f64` state and the external force
/// accumulated for the next step.
///
/// The position and velocity may be written directly (a game teleporting a
/// bead); the step checks them and marks the bead
/// [`Diverged`](crate::Diverged) rather than propagate a non-finite value.
///
/// With [`WireBeadPlugin`](crate::WireBeadPlugin)'s defaults a bead also gets
/// a `Transform` (the plugin writes its position there) and
/// [`BeadDiagnostics`](crate::BeadDiagnostics);
/// [`WireBeadPlugin::lean`](crate::WireBeadPlugin::lean) leaves both out for
/// crowds of beads nobody looks at one by one.
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct Bead {
    params: BeadParams,
    /// Position in world coordinates.
    pub position: DVec2,
    /// Velocity.
    pub velocity: DVec2,
    /// The external force accumulated for the next step, gravity not
    /// included; consumed by the step.
    force: DVec2,
    /// The stiffness of that force (the sum of the spring constants in it).
    force_stiffness: f64,
}

impl Bead {
    /// A bead at its initial position with its initial velocity, if the
    /// parameters are valid.
    pub fn new(params: BeadParams) -> Result<Self, ParamError> {
        params.validate()?;
        Ok(Self::initial(params))
    }

    fn initial(params: BeadParams) -> Self {
        Self {
            params,
            position: params.initial_position,
            velocity: params.initial_velocity,
            force: DVec2::ZERO,
            force_stiffness: 0.0,
        }
    }

    /// A bead of the given mass at rest at `position`.
    pub fn at_rest(mass: f64, position: DVec2) -> Result<Self, ParamError> {
        Self::new(BeadParams {
            mass,
            initial_position: position,
            initial_velocity: DVec2::ZERO,
        })
    }

    /// The applied parameters (what a restart returns to).
    pub fn params(&self) -> &BeadParams {
        &self.params
    }

    /// The mass.
    pub fn mass(&self) -> f64 {
        self.params.mass
    }

    /// Position and velocity.
    pub fn state(&self) -> BeadState {
        BeadState {
            position: self.position,
            velocity: self.velocity,
        }
    }

    /// Adds a constant force for the next step (call it from a system in
    /// [`WireBeadSystems::Forces`](crate::WireBeadSystems::Forces)).
    pub fn add_force(&mut self, force: DVec2) {
        self.force += force;
    }

    /// Adds a spring `k (anchor - x)` for the next step.
    pub fn add_spring(&mut self, k: f64, anchor: DVec2) {
        self.force += k * (anchor - self.position);
        self.force_stiffness += k;
    }

    /// The force added for the next step so far (gravity not included;
    /// the step adds `m g` itself), and its stiffness: the sum of the
    /// spring constants added. Both are zero again after every step.
    pub fn accumulated_force(&self) -> (DVec2, f64) {
        (self.force, self.force_stiffness)
    }

    /// The force of the next step, eq. (5): gravity plus the accumulated
    /// force, linearized at the bead's position.
    #[inline(always)]
    pub(crate) fn step_force(&self, gravity: DVec2) -> LinearForce {
        LinearForce {
            force: self.force + self.mass() * gravity,
            stiffness: self.force_stiffness,
            at: self.position,
        }
    }

    /// Stores a step's new state and clears the consumed force.
    #[inline(always)]
    pub(crate) fn advance_to(&mut self, state: BeadState) {
        self.position = state.position;
        self.velocity = state.velocity;
        self.force = DVec2::ZERO;
        self.force_stiffness = 0.0;
    }

    /// Adds the velocity of a moving wire's point where the bead is (its
    /// initial velocity is relative to its wire at t = 0).
    pub(crate) fn ride(&mut self, twist: &Twist) {
        self.velocity += twist.velocity_at(self.position);
    }

    /// Applies `params` and returns the bead to its initial state.
    pub(crate) fn reset(&mut self, params: BeadParams) {
        *self = Self::initial(params);
    }
}

/// Edited [`BeadParams`] for one bead, applied (and removed) by the next
/// [`Restart`](crate::Restart). Construct it with [`NextBeadParams::new`] so that
/// an invalid edit never gets into the world.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct NextBeadParams(BeadParams);

impl NextBeadParams {
    /// A pending edit, if `params` is valid.
    pub fn new(params: BeadParams) -> Result<Self, ParamError> {
        params.validate()?;
        Ok(Self(params))
    }

    /// The edited parameters.
    pub fn get(&self) -> &BeadParams {
        &self.0
    }

    /// Edits in place; kept only if the result is valid.
    pub fn update(&mut self, edit: impl FnOnce(&mut BeadParams)) -> Result<(), ParamError> {
        super::params::edit_validated(&mut self.0, edit, BeadParams::validate)
    }
}

/// A point a spring pulls the bead toward while present: the force
/// `k (anchor - x)`, k being
/// [`SimParams::drag_stiffness`](crate::SimParams::drag_stiffness). The
/// assignment's mouse drag is one (the scene inserts it on grab, moves it
/// with the cursor, removes it on release); a game may pull a bead anywhere
/// with one.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct SpringAnchor(DVec2);

impl SpringAnchor {
    /// An anchor at `point`, if it is finite.
    pub fn new(point: DVec2) -> Result<Self, ParamError> {
        finite_vector("spring anchor", point).map(Self)
    }

    /// Where the spring pulls toward.
    pub fn get(&self) -> DVec2 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spring_anchor_off_the_map_is_refused_in_words() {
        assert_eq!(
            SpringAnchor::new(DVec2::new(f64::NAN, 0.0))
                .unwrap_err()
                .to_string(),
            "spring anchor must be finite, got (NaN, 0)"
        );
    }
}
