//! What a step reports: [`BeadDiagnostics`] each step, and [`Diverged`]
//! with a [`BeadDiverged`] message when a bead stops.

use std::fmt;

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::geometry::Coordinates;
use crate::solver::{BeadState, RowReport, SolveError};

/// Per-bead diagnostics, updated after every step (on beads that have
/// them: see [`WireBeadPlugin::lean`](crate::WireBeadPlugin::lean)). The
/// time and the step count since the last restart are the
/// [`SimClock`](crate::SimClock)'s.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Component)]
pub struct BeadDiagnostics<V: Coordinates = DVec2> {
    /// The constraint value `C` (the drift off the wire).
    pub c: f64,
    /// Its rate `Ċ`.
    pub c_dot: f64,
    /// The constraint multiplier λ of the last step (for RATTLE the mean of
    /// its position and velocity multipliers).
    pub lambda: f64,
    /// The constraint force `λN` of the last step (for RATTLE the mean of
    /// its two multipliers' forces).
    pub constraint_force: V,
    /// `½ m |v|²`.
    pub kinetic: f64,
    /// `-m g·x`.
    pub potential: f64,
}

impl<V: Coordinates> BeadDiagnostics<V> {
    /// The diagnostics of a bead of `mass` at `state` under `gravity`: its
    /// wire row's `C`, `Ċ` and λ (all zero for a bead on no wire) and the
    /// constraint force on it. The one place the bead step, the island
    /// step and a restart fill them in.
    pub(crate) fn of(
        state: BeadState<V>,
        mass: f64,
        gravity: V,
        row: RowReport,
        constraint_force: V,
    ) -> Self {
        let (kinetic, potential) = state.energy(mass, gravity);
        Self {
            c: row.c,
            c_dot: row.c_dot,
            lambda: row.lambda,
            constraint_force,
            kinetic,
            potential,
        }
    }

    /// Kinetic plus potential energy.
    pub fn energy(&self) -> f64 {
        self.kinetic + self.potential
    }
}

/// Why a bead stopped.
#[derive(Clone, Debug, PartialEq)]
pub enum DivergenceReason {
    /// The step failed: a singular point, a Newton solve that did not
    /// converge, a non-finite result, or drift past the configured bound.
    Solve(SolveError),
    /// The state was already non-finite before the step (written from
    /// outside).
    NonFiniteState,
    /// The bead's wire entity has no [`Wire`](crate::Wire) or its
    /// `Transform` is not finite.
    InvalidWire(String),
    /// The constraints and springs that join the bead to others cannot be
    /// solved together (a mass or a value out of range).
    InvalidConstraint(String),
    /// Beads that touch kept striking within one step, or a step cut at
    /// an impact failed.
    Touch(String),
}

impl fmt::Display for DivergenceReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Solve(e) => e.fmt(f),
            Self::NonFiniteState => f.write_str("its position or velocity is not finite"),
            Self::InvalidWire(why) => write!(f, "its wire is invalid: {why}"),
            Self::InvalidConstraint(why) => write!(f, "its island is invalid: {why}"),
            Self::Touch(why) => write!(f, "its strikes did not settle: {why}"),
        }
    }
}

/// Marks a bead that diverged: it no longer moves until a restart.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct Diverged {
    /// Why.
    pub reason: DivergenceReason,
    /// The simulated time ([`SimClock`](crate::SimClock)) at the end of the
    /// step that found it.
    pub time: f64,
}

/// Sent when a bead diverges: which bead and why.
#[derive(Message, Clone, Debug)]
pub struct BeadDiverged {
    /// The bead.
    pub bead: Entity,
    /// Why it stopped.
    pub reason: DivergenceReason,
}
