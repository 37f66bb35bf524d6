//! Simulation parameters, their validation, and the pending/applied split.
//!
//! As in the assignment's panel, edits do not touch the running simulation: they go
//! to [`NextParams`] (and a bead's [`NextBeadParams`](crate::NextBeadParams))
//! and a [`Restart`](crate::Restart) applies them. Every setter validates and
//! returns a [`ParamError`] that names the parameter and the value it got,
//! leaving the previous value in place.

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::solver::{Integrator, Method, Stabilization, StepSettings};
use crate::validate::{ParamError, finite, finite_vector, non_negative, positive};

/// The smallest timestep accepted, in seconds.
pub const MIN_TIMESTEP: f64 = 1e-6;
/// The largest timestep accepted, in seconds.
pub const MAX_TIMESTEP: f64 = 1.0;

/// The parameters shared by every bead: the applied set is this resource,
/// the edited set is [`NextParams`].
///
/// In a scene file the method is written as its two halves,
/// `integrator: Rk4, stabilization: Projection`; RATTLE takes no
/// stabilization (or `None`).
#[derive(Resource, Clone, Debug, PartialEq, Serialize, Deserialize, Reflect)]
#[reflect(Resource)]
#[serde(try_from = "SimParamsFile", into = "SimParamsFile")]
pub struct SimParams {
    /// The fixed timestep in seconds (`Time<Fixed>` is set to it).
    pub timestep: f64,
    /// Gravitational acceleration; `(0, -9.81)` is "down".
    pub gravity: DVec2,
    /// Gravity's `z` component, for beads in space (the plane is space's
    /// `z = 0`); zero by default.
    pub gravity_z: f64,
    /// Baumgarte's spring constant α (1/s²).
    pub alpha: f64,
    /// Baumgarte's damping constant β (1/s).
    pub beta: f64,
    /// The drag spring constant k (N/m): the drag force is `k (target - x)`.
    pub drag_stiffness: f64,
    /// How the state is advanced and drift corrected.
    pub method: Method,
    /// A bead whose `|C|` exceeds this many wire scales (a circle's radius)
    /// is marked diverged and stops.
    pub divergence_bound: f64,
}

impl Default for SimParams {
    fn default() -> Self {
        Self {
            timestep: 1.0 / 60.0,
            gravity: DVec2::new(0.0, -9.81),
            gravity_z: 0.0,
            alpha: 100.0,
            beta: 20.0,
            drag_stiffness: 20.0,
            method: Method::default(),
            divergence_bound: 1.0,
        }
    }
}

impl SimParams {
    /// Checks every field; the first problem found is returned.
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("timestep", self.timestep)?;
        // Time<Fixed> counts in nanoseconds: keep the step well above that.
        if !(MIN_TIMESTEP..=MAX_TIMESTEP).contains(&self.timestep) {
            return Err(ParamError::OutOfRange {
                name: "timestep",
                min: MIN_TIMESTEP,
                max: MAX_TIMESTEP,
                value: self.timestep,
            });
        }
        finite_vector("gravity", self.gravity)?;
        finite("gravity z", self.gravity_z)?;
        non_negative("alpha", self.alpha)?;
        non_negative("beta", self.beta)?;
        non_negative("drag stiffness k", self.drag_stiffness)?;
        positive("divergence bound", self.divergence_bound).map(drop)
    }

    /// Gravity in space: `(x, y, z)`.
    pub fn gravity_in_space(&self) -> DVec3 {
        self.gravity.extend(self.gravity_z)
    }

    /// The settings every bead's step shares.
    pub fn step_settings(&self) -> StepSettings {
        StepSettings {
            dt: self.timestep,
            method: self.method,
            alpha: self.alpha,
            beta: self.beta,
            drift_bound: self.divergence_bound,
        }
    }
}

/// [`SimParams`] as a scene file writes it: the method as an integrator
/// and an optional stabilization, every field optional.
#[derive(Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
#[serde(bound(
    serialize = "G: Gravity + Serialize",
    deserialize = "G: Gravity + Deserialize<'de>"
))]
struct SimParamsFile<G: Gravity = DVec2> {
    timestep: f64,
    gravity: G,
    alpha: f64,
    beta: f64,
    drag_stiffness: f64,
    integrator: Integrator,
    /// Written as a plain stabilization (`None` is [`Stabilization::None`]);
    /// absent, the integrator's default.
    #[serde(
        skip_serializing_if = "Option::is_none",
        serialize_with = "serialize_present",
        deserialize_with = "deserialize_present"
    )]
    stabilization: Option<Stabilization>,
    divergence_bound: f64,
}

/// Gravity as a scene file writes it: two components in the plane, three
/// in space.
trait Gravity: Copy {
    /// `params`' gravity.
    fn of(params: &SimParams) -> Self;
    /// The in-plane components and `z`.
    fn components(self) -> (DVec2, f64);
}

impl Gravity for DVec2 {
    fn of(params: &SimParams) -> Self {
        params.gravity
    }
    fn components(self) -> (DVec2, f64) {
        (self, 0.0)
    }
}

impl Gravity for DVec3 {
    fn of(params: &SimParams) -> Self {
        params.gravity_in_space()
    }
    fn components(self) -> (DVec2, f64) {
        (self.truncate(), self.z)
    }
}

/// [`SimParams`] as a scene file in space writes them: as in the plane,
/// with gravity's three components, `gravity: (0.0, -9.81, 0.0)`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SimParamsFile<DVec3>", into = "SimParamsFile<DVec3>")]
pub struct SpaceParams(pub SimParams);

impl TryFrom<SimParamsFile<DVec3>> for SpaceParams {
    type Error = ParamError;
    fn try_from(file: SimParamsFile<DVec3>) -> Result<Self, ParamError> {
        SimParams::try_from(file).map(Self)
    }
}

impl From<SpaceParams> for SimParamsFile<DVec3> {
    fn from(params: SpaceParams) -> Self {
        params.0.into()
    }
}

fn serialize_present<S: serde::Serializer>(
    value: &Option<Stabilization>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    value.unwrap_or_default().serialize(serializer)
}

fn deserialize_present<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> Result<Option<Stabilization>, D::Error> {
    Stabilization::deserialize(deserializer).map(Some)
}

impl<G: Gravity> Default for SimParamsFile<G> {
    /// The defaults, with the stabilization left to the integrator: a file
    /// that names only `integrator: Rattle` means RATTLE.
    fn default() -> Self {
        Self {
            stabilization: None,
            ..SimParams::default().into()
        }
    }
}

impl<G: Gravity> From<SimParams> for SimParamsFile<G> {
    fn from(p: SimParams) -> Self {
        Self {
            timestep: p.timestep,
            gravity: G::of(&p),
            alpha: p.alpha,
            beta: p.beta,
            drag_stiffness: p.drag_stiffness,
            integrator: p.method.integrator(),
            stabilization: p.method.stabilization(),
            divergence_bound: p.divergence_bound,
        }
    }
}

impl<G: Gravity> TryFrom<SimParamsFile<G>> for SimParams {
    type Error = ParamError;
    fn try_from(f: SimParamsFile<G>) -> Result<Self, ParamError> {
        let (gravity, gravity_z) = f.gravity.components();
        Ok(Self {
            timestep: f.timestep,
            gravity,
            gravity_z,
            alpha: f.alpha,
            beta: f.beta,
            drag_stiffness: f.drag_stiffness,
            method: Method::new(f.integrator, f.stabilization)?,
            divergence_bound: f.divergence_bound,
        })
    }
}

/// Edits a copy, validates it, and keeps it only if it is valid.
pub(crate) fn edit_validated<T: Clone>(
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
pub struct NextParams(SimParams);

impl NextParams {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{BeadParams, NextBeadParams};

    #[test]
    fn errors_name_the_parameter_and_value() {
        let mut pending = NextParams::default();
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
        let err = NextBeadParams::new(BeadParams {
            mass: -2.0,
            ..default()
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "mass must be positive and finite, got -2");
    }

    #[test]
    fn scene_files_write_the_method_as_integrator_and_stabilization() {
        let p: SimParams = ron::from_str("(integrator: Rattle)").unwrap();
        assert_eq!(p.method, Method::Rattle);
        let p: SimParams = ron::from_str("(integrator: Rk4, stabilization: Projection)").unwrap();
        assert_eq!(p.method, Method::Rk4(Stabilization::Projection));
        let p: SimParams = ron::from_str("(integrator: Rk4, stabilization: None)").unwrap();
        assert_eq!(p.method, Method::Rk4(Stabilization::None));
        let p: SimParams = ron::from_str("(integrator: Rattle, stabilization: None)").unwrap();
        assert_eq!(p.method, Method::Rattle);
        let p: SimParams = ron::from_str("(alpha: 5.0)").unwrap();
        assert_eq!((p.method, p.alpha), (Method::default(), 5.0));
        let err = ron::from_str::<SimParams>("(integrator: Rattle, stabilization: Baumgarte)")
            .unwrap_err();
        assert!(
            err.to_string()
                .contains("rattle holds the constraint itself"),
            "{err}"
        );
        let text = ron::to_string(&p).unwrap();
        assert_eq!(ron::from_str::<SimParams>(&text).unwrap(), p);
    }
}
