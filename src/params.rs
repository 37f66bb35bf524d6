//! Simulation parameters, their validation, and the pending/applied split.
//!
//! As in the seed's panel, edits do not touch the running simulation: they go
//! to [`PendingParams`] (and a bead's [`PendingBead`]) and a
//! [`Restart`](crate::Restart) applies them. Every setter validates and
//! returns a [`ParamError`] that names the parameter and the value it got,
//! leaving the previous value in place.

use std::fmt;
use std::str::FromStr;

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// What is wrong with a parameter, in words, with the value it got.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// A quantity that must be positive was zero, negative or not finite.
    #[error("{name} must be positive and finite, got {value}")]
    NotPositive {
        /// The parameter's name.
        name: &'static str,
        /// The value it got.
        value: f64,
    },
    /// A quantity that must be zero or more was negative or not finite.
    #[error("{name} must be zero or more and finite, got {value}")]
    Negative {
        /// The parameter's name.
        name: &'static str,
        /// The value it got.
        value: f64,
    },
    /// A quantity outside its allowed range.
    #[error("{name} must be between {min} and {max}, got {value}")]
    OutOfRange {
        /// The parameter's name.
        name: &'static str,
        /// The smallest allowed value.
        min: f64,
        /// The largest allowed value.
        max: f64,
        /// The value it got.
        value: f64,
    },
    /// A quantity was NaN or infinite.
    #[error("{name} must be finite, got {value}")]
    NotFinite {
        /// The parameter's name.
        name: &'static str,
        /// The value it got.
        value: f64,
    },
    /// A vector had a NaN or infinite component.
    #[error("{name} must be finite, got ({x}, {y})")]
    VectorNotFinite {
        /// The parameter's name.
        name: &'static str,
        /// Its x component.
        x: f64,
        /// Its y component.
        y: f64,
    },
    /// A name that is not one of the choices.
    #[error("unknown {kind} {got:?}; expected one of: {expected}")]
    UnknownChoice {
        /// What was being chosen.
        kind: &'static str,
        /// What was given.
        got: String,
        /// The accepted names, comma-separated.
        expected: String,
    },
}

pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<(), ParamError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ParamError::NotPositive { name, value })
    }
}

fn check_non_negative(name: &'static str, value: f64) -> Result<(), ParamError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ParamError::Negative { name, value })
    }
}

pub(crate) fn check_vector(name: &'static str, v: DVec2) -> Result<(), ParamError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ParamError::VectorNotFinite {
            name,
            x: v.x,
            y: v.y,
        })
    }
}

/// How a bead's state is advanced over one fixed step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, Reflect)]
pub enum Integrator {
    /// `x += v dt; v += a dt`: first order, gains energy, the least stable.
    ExplicitEuler,
    /// `v += a dt; x += v dt`: the seed's step, first order and symplectic
    /// for an unconstrained body.
    #[default]
    SemiImplicitEuler,
    /// Classical fourth-order Runge–Kutta on `(x, v)` with the constraint
    /// force solved at every stage.
    Rk4,
    /// RATTLE: symmetric, symplectic, second order; solves for the
    /// constraint force so that `C = 0` and `Ċ = 0` hold after the step.
    /// It enforces the constraint itself: the stabilization setting adds
    /// nothing to it.
    Rattle,
}

/// How drift off the wire is corrected.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, Reflect)]
pub enum Stabilization {
    /// The seed's: choose λ so that `C̈ = -αC - βĊ`.
    #[default]
    Baumgarte,
    /// Post-stabilization: after an unstabilized step, project the position
    /// onto `C = 0` along the normal and remove the normal velocity.
    Projection,
    /// Neither: λ keeps `C̈ = 0` and drift accumulates.
    None,
}

macro_rules! named_choices {
    ($ty:ty, $kind:literal, [$($variant:ident => $name:literal),+ $(,)?]) => {
        impl $ty {
            /// Every choice, in the order a menu shows them.
            pub const ALL: &'static [$ty] = &[$(<$ty>::$variant),+];

            /// The kebab-case name used on the command line and in scene files.
            pub fn name(self) -> &'static str {
                match self { $(<$ty>::$variant => $name),+ }
            }
        }

        impl fmt::Display for $ty {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }

        impl FromStr for $ty {
            type Err = ParamError;
            fn from_str(s: &str) -> Result<Self, ParamError> {
                match s {
                    $($name => Ok(<$ty>::$variant),)+
                    _ => Err(ParamError::UnknownChoice {
                        kind: $kind,
                        got: s.to_owned(),
                        expected: [$($name),+].join(", "),
                    }),
                }
            }
        }
    };
}

named_choices!(Integrator, "integrator", [
    ExplicitEuler => "explicit-euler",
    SemiImplicitEuler => "semi-implicit-euler",
    Rk4 => "rk4",
    Rattle => "rattle",
]);

named_choices!(Stabilization, "stabilization", [
    Baumgarte => "baumgarte",
    Projection => "projection",
    None => "none",
]);

/// The smallest timestep accepted, in seconds.
pub const MIN_TIMESTEP: f64 = 1e-6;
/// The largest timestep accepted, in seconds.
pub const MAX_TIMESTEP: f64 = 1.0;

/// The parameters shared by every bead: the applied set is this resource,
/// the edited set is [`PendingParams`].
#[derive(Resource, Clone, Debug, PartialEq, Serialize, Deserialize, Reflect)]
#[reflect(Resource)]
#[serde(default)]
pub struct SimParams {
    /// The fixed timestep in seconds (`Time<Fixed>` is set to it).
    pub timestep: f64,
    /// Gravitational acceleration; `(0, -9.81)` is "down".
    pub gravity: DVec2,
    /// Baumgarte's spring constant α (1/s²).
    pub alpha: f64,
    /// Baumgarte's damping constant β (1/s).
    pub beta: f64,
    /// The drag spring constant k (N/m): the drag force is `k (target - x)`.
    pub drag_stiffness: f64,
    /// How the state is advanced.
    pub integrator: Integrator,
    /// How drift is corrected.
    pub stabilization: Stabilization,
    /// A bead whose `|C|` exceeds this many wire scales (a circle's radius)
    /// is marked diverged and stops.
    pub divergence_bound: f64,
}

impl Default for SimParams {
    fn default() -> Self {
        Self {
            timestep: 1.0 / 60.0,
            gravity: DVec2::new(0.0, -9.81),
            alpha: 100.0,
            beta: 20.0,
            drag_stiffness: 20.0,
            integrator: Integrator::default(),
            stabilization: Stabilization::default(),
            divergence_bound: 1.0,
        }
    }
}

impl SimParams {
    /// Checks every field; the first problem found is returned.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("timestep", self.timestep)?;
        // Time<Fixed> counts in nanoseconds: keep the step well above that.
        if !(MIN_TIMESTEP..=MAX_TIMESTEP).contains(&self.timestep) {
            return Err(ParamError::OutOfRange {
                name: "timestep",
                min: MIN_TIMESTEP,
                max: MAX_TIMESTEP,
                value: self.timestep,
            });
        }
        check_vector("gravity", self.gravity)?;
        check_non_negative("alpha", self.alpha)?;
        check_non_negative("beta", self.beta)?;
        check_non_negative("drag stiffness k", self.drag_stiffness)?;
        check_positive("divergence bound", self.divergence_bound)
    }
}

/// The per-bead parameters of the seed's panel: mass, initial position and
/// initial velocity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Reflect)]
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
        check_positive("mass", self.mass)?;
        check_vector("initial position", self.initial_position)?;
        check_vector("initial velocity", self.initial_velocity)
    }
}

/// Edits a copy, validates it, and keeps it only if it is valid.
fn edit_validated<T: Clone>(
    target: &mut T,
    edit: impl FnOnce(&mut T),
    validate: impl FnOnce(&T) -> Result<(), ParamError>,
) -> Result<(), ParamError> {
    let mut next = target.clone();
    edit(&mut next);
    validate(&next)?;
    *target = next;
    Ok(())
}

/// The edited [`SimParams`], applied by the next [`Restart`](crate::Restart).
#[derive(Resource, Clone, Debug, Default, PartialEq, Reflect)]
#[reflect(Resource)]
pub struct PendingParams(SimParams);

impl PendingParams {
    /// The edited parameters.
    pub fn get(&self) -> &SimParams {
        &self.0
    }

    /// Replaces the edited parameters if `params` is valid; otherwise returns
    /// the error and keeps the previous edit.
    pub fn set(&mut self, params: SimParams) -> Result<(), ParamError> {
        self.update(|p| *p = params)
    }

    /// Edits the parameters in place; the edit is kept only if the result is
    /// valid.
    pub fn update(&mut self, edit: impl FnOnce(&mut SimParams)) -> Result<(), ParamError> {
        edit_validated(&mut self.0, edit, SimParams::validate)
    }
}

/// Edited [`BeadParams`] for one bead, applied (and removed) by the next
/// [`Restart`](crate::Restart). Construct it with [`PendingBead::new`] so that
/// an invalid edit never gets into the world.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct PendingBead(BeadParams);

impl PendingBead {
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
        edit_validated(&mut self.0, edit, BeadParams::validate)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_parameter_and_value() {
        let mut pending = PendingParams::default();
        let err = pending.update(|p| p.timestep = 0.0).unwrap_err();
        assert_eq!(
            err.to_string(),
            "timestep must be positive and finite, got 0"
        );
        let err = pending.update(|p| p.alpha = -3.0).unwrap_err();
        assert_eq!(
            err.to_string(),
            "alpha must be zero or more and finite, got -3"
        );
        let err = pending.update(|p| p.gravity.y = f64::NAN).unwrap_err();
        assert_eq!(err.to_string(), "gravity must be finite, got (0, NaN)");
        assert_eq!(
            pending.get(),
            &SimParams::default(),
            "a refused edit changes nothing"
        );
        let err = PendingBead::new(BeadParams {
            mass: -2.0,
            ..default()
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "mass must be positive and finite, got -2");
    }

    #[test]
    fn choices_round_trip_through_their_names() {
        for &i in Integrator::ALL {
            assert_eq!(i.name().parse::<Integrator>(), Ok(i));
        }
        for &s in Stabilization::ALL {
            assert_eq!(s.name().parse::<Stabilization>(), Ok(s));
        }
        let err = "verlet".parse::<Integrator>().unwrap_err();
        assert_eq!(
            err.to_string(),
            "unknown integrator \"verlet\"; expected one of: explicit-euler, semi-implicit-euler, rk4, rattle"
        );
    }
}
