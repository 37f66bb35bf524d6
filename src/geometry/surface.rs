//! What a wire does to a bead besides holding it: [`Side`] (a one-sided
//! wire only pushes), restitution and [`Friction`], together a
//! [`Surface`].

use serde::{Deserialize, Serialize};

use crate::validate::{ParamError, non_negative, restitution};

/// Which way a wire may push its bead (scene field `side`).
///
/// The constraint force is `λ∇C`: a `Positive` wire only pushes toward
/// `C > 0` (λ ≥ 0), a `Negative` one only toward `C < 0` (λ ≤ 0). Each
/// shape's documentation says which side is positive; for a circle it is
/// the outside (a bead riding outside a circle is on a `Positive` wire, one
/// inside a loop on a `Negative` one), for a line and the curves given as
/// `y = f(x)` it is above.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Side {
    /// A wire a bead is threaded on: it pushes and pulls.
    #[default]
    Both,
    /// Pushes toward `C > 0` only.
    Positive,
    /// Pushes toward `C < 0` only.
    Negative,
}

impl Side {
    /// +1 for `Positive`, −1 for `Negative`, 0 for `Both`: the sign λ and
    /// a free bead's `C` keep while the bead is on its side.
    pub fn sign(self) -> f64 {
        match self {
            Self::Both => 0.0,
            Self::Positive => 1.0,
            Self::Negative => -1.0,
        }
    }

    /// The lowercase name: `both`, `positive`, `negative`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Both => "both",
            Self::Positive => "positive",
            Self::Negative => "negative",
        }
    }
}

/// Coulomb friction along a wire (scene field
/// `friction: (static: μs, kinetic: μk)`): a sliding bead feels
/// `μk |λ∇C|` against its velocity along the wire; a bead at rest stays at
/// rest while the force along the wire is at most `μs |λ∇C|`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Friction {
    /// μs.
    #[serde(rename = "static")]
    pub static_coefficient: f64,
    /// μk.
    #[serde(rename = "kinetic")]
    pub kinetic_coefficient: f64,
}

impl Friction {
    /// No friction.
    pub const NONE: Self = Self {
        static_coefficient: 0.0,
        kinetic_coefficient: 0.0,
    };

    /// Friction with coefficients μs (static) and μk (kinetic), if both
    /// are finite, not negative, and μk ≤ μs.
    pub fn new(static_coefficient: f64, kinetic_coefficient: f64) -> Result<Self, ParamError> {
        let friction = Self {
            static_coefficient,
            kinetic_coefficient,
        };
        friction.validate()?;
        Ok(friction)
    }

    /// Checks the coefficients (see [`Friction::new`]).
    pub fn validate(&self) -> Result<(), ParamError> {
        non_negative("static friction", self.static_coefficient)?;
        non_negative("kinetic friction", self.kinetic_coefficient)?;
        if self.kinetic_coefficient > self.static_coefficient {
            return Err(ParamError::Incompatible(
                "kinetic friction must not exceed static friction",
            ));
        }
        Ok(())
    }

    /// Whether there is any.
    pub fn is_some(&self) -> bool {
        self.static_coefficient > 0.0 || self.kinetic_coefficient > 0.0
    }
}

/// Everything a wire does to its beads besides holding them on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct Surface {
    /// Which way it pushes.
    pub side: Side,
    /// The share of the normal speed a bead landing on a one-sided wire
    /// keeps, bouncing off (0: it stays on; 1: a perfect bounce).
    pub restitution: f64,
    /// Coulomb friction along the wire.
    pub friction: Friction,
    /// Viscous damping along the wire, N·s/m: the force `−c v_t` on the
    /// velocity along the wire (relative to the wire).
    pub damping: f64,
}

impl Surface {
    /// Two-sided, frictionless, undamped: a plain wire.
    pub const PLAIN: Self = Self {
        side: Side::Both,
        restitution: 0.0,
        friction: Friction::NONE,
        damping: 0.0,
    };

    /// Checks every number: restitution in `[0, 1]`, friction as
    /// [`Friction::new`], damping not negative.
    pub fn validate(&self) -> Result<(), ParamError> {
        restitution(self.restitution)?;
        self.friction.validate()?;
        non_negative("damping along the wire", self.damping).map(drop)
    }

    /// Whether it does anything besides holding the bead two-sided.
    pub fn is_plain(&self) -> bool {
        self.side == Side::Both && !self.resists()
    }

    /// Whether it resists sliding (friction or damping).
    pub fn resists(&self) -> bool {
        self.friction.is_some() || self.damping > 0.0
    }
}
