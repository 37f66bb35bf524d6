//! [`ParamError`] and the checks every parameter type runs on itself.
//!
//! The bottom layer of the crate: plain values only, so the geometry, the
//! solver and the ECS types all report bad input in the same words.

use bevy::math::{DVec2, DVec3};

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
    #[error("{name} must be finite, got {components}")]
    VectorNotFinite {
        /// The parameter's name.
        name: &'static str,
        /// Its components, as `(x, y)` or `(x, y, z)`.
        components: String,
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
    /// Two choices that do not go together.
    #[error("{0}")]
    Incompatible(&'static str),
}

/// `value`, if it is positive and finite.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ParamError::NotPositive { name, value })
    }
}

/// `e`, if it is a restitution: finite, between 0 (nothing comes back)
/// and 1 (no energy lost).
pub(crate) fn restitution(e: f64) -> Result<f64, ParamError> {
    let e = finite("restitution", e)?;
    if (0.0..=1.0).contains(&e) {
        Ok(e)
    } else {
        Err(ParamError::OutOfRange {
            name: "restitution",
            min: 0.0,
            max: 1.0,
            value: e,
        })
    }
}

/// `value`, if it is zero or more and finite.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(ParamError::Negative { name, value })
    }
}

/// `value`, if it is finite.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ParamError::NotFinite { name, value })
    }
}

/// A vector's components, for [`finite_vector`]: `DVec2` or `DVec3`.
pub trait Components: Copy {
    /// `[x, y]` or `[x, y, z]`.
    fn components(&self) -> Vec<f64>;
    /// The components to edit in place, in the same order.
    fn components_mut(&mut self) -> Vec<&mut f64>;
}

impl Components for DVec2 {
    fn components(&self) -> Vec<f64> {
        self.to_array().to_vec()
    }
    fn components_mut(&mut self) -> Vec<&mut f64> {
        vec![&mut self.x, &mut self.y]
    }
}

impl Components for DVec3 {
    fn components(&self) -> Vec<f64> {
        self.to_array().to_vec()
    }
    fn components_mut(&mut self) -> Vec<&mut f64> {
        vec![&mut self.x, &mut self.y, &mut self.z]
    }
}

/// `v`, if every component is finite.
pub(crate) fn finite_vector<V: Components>(name: &'static str, v: V) -> Result<V, ParamError> {
    let components = v.components();
    if components.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        let listed: Vec<String> = components.iter().map(f64::to_string).collect();
        Err(ParamError::VectorNotFinite {
            name,
            components: format!("({})", listed.join(", ")),
        })
    }
}
