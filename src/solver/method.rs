//! How a step is taken: an [`Integrator`] and a [`Stabilization`], paired
//! into a [`Method`] that can only hold the pairs that mean something.

use std::fmt;
use std::str::FromStr;

use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

use crate::validate::ParamError;

/// How a bead's state is advanced over one fixed step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, Reflect)]
pub enum Integrator {
    /// `x += v dt; v += a dt`: first order, gains energy, the least stable.
    ExplicitEuler,
    /// `v += a dt; x += v dt`: the assignment's step, first order and symplectic
    /// for an unconstrained body.
    #[default]
    SemiImplicitEuler,
    /// Classical fourth-order Runge–Kutta on `(x, v)` with the constraint
    /// force solved at every stage.
    Rk4,
    /// RATTLE: symmetric, symplectic, second order; solves for the
    /// constraint force so that `C = 0` and `Ċ = 0` hold after the step.
    /// It enforces the constraint itself, so it takes no [`Stabilization`].
    Rattle,
}

/// How drift off the wire is corrected by the integrators that need it
/// (every one but RATTLE).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, Reflect)]
pub enum Stabilization {
    /// The assignment's: choose λ so that `C̈ = -αC - βĊ`.
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

            /// The kebab-case name used on the command line.
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

/// An integrator with the stabilization it uses: every explicit integrator
/// with any [`Stabilization`], and RATTLE on its own (it holds the
/// constraint itself, so a stabilization would mean nothing).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Reflect)]
pub enum Method {
    /// [`Integrator::ExplicitEuler`] with a stabilization.
    ExplicitEuler(Stabilization),
    /// [`Integrator::SemiImplicitEuler`] with a stabilization.
    SemiImplicitEuler(Stabilization),
    /// [`Integrator::Rk4`] with a stabilization.
    Rk4(Stabilization),
    /// [`Integrator::Rattle`].
    Rattle,
}

impl Default for Method {
    /// The assignment's: semi-implicit Euler with Baumgarte stabilization.
    fn default() -> Self {
        Self::SemiImplicitEuler(Stabilization::Baumgarte)
    }
}

impl Method {
    /// Every method: each explicit integrator with each stabilization, then
    /// RATTLE.
    pub const ALL: [Method; 10] = [
        Method::ExplicitEuler(Stabilization::Baumgarte),
        Method::ExplicitEuler(Stabilization::Projection),
        Method::ExplicitEuler(Stabilization::None),
        Method::SemiImplicitEuler(Stabilization::Baumgarte),
        Method::SemiImplicitEuler(Stabilization::Projection),
        Method::SemiImplicitEuler(Stabilization::None),
        Method::Rk4(Stabilization::Baumgarte),
        Method::Rk4(Stabilization::Projection),
        Method::Rk4(Stabilization::None),
        Method::Rattle,
    ];

    /// The method of an integrator and a stabilization. An explicit
    /// integrator without one takes Baumgarte's (the assignment's); RATTLE takes
    /// none, or [`Stabilization::None`], and refuses any other.
    pub fn new(
        integrator: Integrator,
        stabilization: Option<Stabilization>,
    ) -> Result<Self, ParamError> {
        let s = stabilization.unwrap_or_default();
        Ok(match integrator {
            Integrator::ExplicitEuler => Self::ExplicitEuler(s),
            Integrator::SemiImplicitEuler => Self::SemiImplicitEuler(s),
            Integrator::Rk4 => Self::Rk4(s),
            Integrator::Rattle => match stabilization {
                None | Some(Stabilization::None) => Self::Rattle,
                Some(_) => {
                    return Err(ParamError::Incompatible(
                        "rattle holds the constraint itself and takes no stabilization: leave it out or give none",
                    ));
                }
            },
        })
    }

    /// The integrator.
    pub fn integrator(self) -> Integrator {
        match self {
            Self::ExplicitEuler(_) => Integrator::ExplicitEuler,
            Self::SemiImplicitEuler(_) => Integrator::SemiImplicitEuler,
            Self::Rk4(_) => Integrator::Rk4,
            Self::Rattle => Integrator::Rattle,
        }
    }

    /// The stabilization; `None` for RATTLE, which takes none.
    pub fn stabilization(self) -> Option<Stabilization> {
        match self {
            Self::ExplicitEuler(s) | Self::SemiImplicitEuler(s) | Self::Rk4(s) => Some(s),
            Self::Rattle => None,
        }
    }

    /// The same integrator with another stabilization (RATTLE stays RATTLE).
    pub fn with_stabilization(self, stabilization: Stabilization) -> Self {
        match self {
            Self::ExplicitEuler(_) => Self::ExplicitEuler(stabilization),
            Self::SemiImplicitEuler(_) => Self::SemiImplicitEuler(stabilization),
            Self::Rk4(_) => Self::Rk4(stabilization),
            Self::Rattle => Self::Rattle,
        }
    }

    /// The same stabilization (or the default) with another integrator;
    /// RATTLE drops it.
    pub fn with_integrator(self, integrator: Integrator) -> Self {
        let s = self.stabilization().unwrap_or_default();
        match integrator {
            Integrator::ExplicitEuler => Self::ExplicitEuler(s),
            Integrator::SemiImplicitEuler => Self::SemiImplicitEuler(s),
            Integrator::Rk4 => Self::Rk4(s),
            Integrator::Rattle => Self::Rattle,
        }
    }

    /// Whether the integrator is one of the two Euler steps.
    pub fn is_euler(self) -> bool {
        matches!(self, Self::ExplicitEuler(_) | Self::SemiImplicitEuler(_))
    }

    /// Whether the step projects onto the wire after integrating.
    pub fn projects(self) -> bool {
        self.stabilization() == Some(Stabilization::Projection)
    }

    /// Whether the step ends with every held row on its constraint:
    /// RATTLE, or a step that projects.
    pub fn ends_on_constraints(self) -> bool {
        self.integrator() == Integrator::Rattle || self.projects()
    }
}

impl fmt::Display for Method {
    /// `rk4 + projection`, `rattle`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.stabilization() {
            Some(s) => write!(f, "{} + {s}", self.integrator()),
            None => write!(f, "{}", self.integrator()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn methods_are_the_meaningful_pairs() {
        for method in Method::ALL {
            let back = Method::new(method.integrator(), method.stabilization());
            assert_eq!(back, Ok(method));
        }
        assert_eq!(
            Method::new(Integrator::Rattle, Some(Stabilization::None)),
            Ok(Method::Rattle)
        );
        let err = Method::new(Integrator::Rattle, Some(Stabilization::Projection)).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("rattle holds the constraint itself")
        );
        assert_eq!(
            Method::new(Integrator::Rk4, None),
            Ok(Method::Rk4(Stabilization::Baumgarte))
        );
        assert_eq!(
            Method::Rk4(Stabilization::Projection).to_string(),
            "rk4 + projection"
        );
        assert_eq!(
            Method::Rattle.with_integrator(Integrator::Rk4),
            Method::Rk4(Stabilization::Baumgarte)
        );
    }
}
