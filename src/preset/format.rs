//! The scene file's format: the serde types of `*.scene.ron`, the checks
//! of every value in them, and the links with their beads resolved.

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use super::error::PresetError;
use crate::dynamics::{BeadParams, SimParams};
use crate::geometry::{Friction, Side, Surface, WireMotion, WireShape};
use crate::validate::{ParamError, finite, finite_vector, non_negative, positive};

/// A bead of a scene file: its name (optional) and its parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct BeadPreset {
    /// The name links refer to it by; empty for none (it is then
    /// `bead<i>`, `i` its place in the file).
    pub name: String,
    /// Mass in kg.
    pub mass: f64,
    /// Where a restart puts the bead.
    pub initial_position: DVec2,
    /// The velocity a restart gives it.
    pub initial_velocity: DVec2,
}

impl Default for BeadPreset {
    fn default() -> Self {
        let params = BeadParams::default();
        Self {
            name: String::new(),
            mass: params.mass,
            initial_position: params.initial_position,
            initial_velocity: params.initial_velocity,
        }
    }
}

impl BeadPreset {
    /// The bead's parameters.
    pub fn params(&self) -> BeadParams {
        BeadParams {
            mass: self.mass,
            initial_position: self.initial_position,
            initial_velocity: self.initial_velocity,
        }
    }
}

/// A rod of a scene file: `|x_a − x_b| = length`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RodPreset {
    /// The first bead's name.
    pub a: String,
    /// The second bead's name.
    pub b: String,
    /// The rod's length.
    pub length: f64,
}

/// A pin of a scene file: a bead held at a point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinPreset {
    /// The bead's name.
    pub bead: String,
    /// The point.
    pub at: DVec2,
}

/// A constraint of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ConstraintPreset {
    /// See [`Rod`](crate::Rod).
    Rod(RodPreset),
    /// See [`Pin`](crate::Pin).
    Pin(PinPreset),
}

impl ConstraintPreset {
    /// `rod` or `pin`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Rod(_) => "rod",
            Self::Pin(_) => "pin",
        }
    }
}

/// A spring of a scene file (see [`Spring`](crate::Spring)).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringPreset {
    /// The first bead's name.
    pub a: String,
    /// The second bead's name.
    pub b: String,
    /// Rest length.
    pub rest_length: f64,
    /// Stiffness (N/m).
    pub stiffness: f64,
    /// Damping along the spring (N·s/m).
    #[serde(default)]
    pub damping: f64,
}

/// One wire of a preset and the beads on it.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WirePreset {
    /// The shape, in the wire's frame.
    pub shape: WireShape,
    /// Where the wire's origin sits.
    #[serde(default)]
    pub position: DVec2,
    /// The wire's rotation, in degrees counter-clockwise.
    #[serde(default)]
    pub angle_degrees: f64,
    /// How it moves about that pose: `Fixed` (the default),
    /// `Oscillate((amplitude: (ax, ay), frequency: f))` or
    /// `Spin((angular_velocity: w))`. Its beads' initial velocities are
    /// relative to the wire's own at `t = 0`.
    #[serde(default)]
    pub motion: WireMotion,
    /// Which way it pushes: `Both` (the default), `Positive` or `Negative`
    /// (see [`Side`]).
    #[serde(default)]
    pub side: Side,
    /// On a one-sided wire, the share of the normal speed a landing bead
    /// bounces off with (0, the default: it stays on).
    #[serde(default)]
    pub restitution: f64,
    /// Coulomb friction along it, `(static: μs, kinetic: μk)`; none by
    /// default.
    #[serde(default)]
    pub friction: Friction,
    /// Viscous damping along it, N·s/m; none by default.
    #[serde(default)]
    pub damping: f64,
    /// The beads on it.
    #[serde(default)]
    pub beads: Vec<BeadPreset>,
}

impl WirePreset {
    /// Its side, restitution, friction and damping.
    pub fn surface(&self) -> Surface {
        Surface {
            side: self.side,
            restitution: self.restitution,
            friction: self.friction,
            damping: self.damping,
        }
    }
}

/// A whole scene: parameters, wires and beads.
#[derive(Asset, TypePath, Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenePreset {
    /// A human-readable name.
    pub name: String,
    /// The parameters (missing fields take their defaults).
    #[serde(default)]
    pub params: SimParams,
    /// The wires.
    #[serde(default)]
    pub wires: Vec<WirePreset>,
    /// The free beads, on no wire.
    #[serde(default)]
    pub beads: Vec<BeadPreset>,
    /// Rods and pins.
    #[serde(default)]
    pub constraints: Vec<ConstraintPreset>,
    /// Springs between beads.
    #[serde(default)]
    pub springs: Vec<SpringPreset>,
}

impl ScenePreset {
    /// Parses and validates a preset.
    pub fn from_ron(text: &str) -> Result<Self, PresetError> {
        let mut de = ron::Deserializer::from_str(text)?;
        let preset: Self = match serde_path_to_error::deserialize(&mut de) {
            Ok(preset) => preset,
            Err(err) => {
                let item = err.path().to_string();
                return Err(PresetError::at(item, de.span_error(err.into_inner())));
            }
        };
        de.end().map_err(|e| de.span_error(e))?;
        preset.validate()?;
        Ok(preset)
    }

    /// Checks the parameters, every wire and every bead.
    pub fn validate(&self) -> Result<(), PresetError> {
        self.params.validate().map_err(PresetError::Params)?;
        for (index, wire) in self.wires.iter().enumerate() {
            wire.shape
                .validate()
                .map_err(|source| PresetError::Wire { index, source })?;
            finite_vector("wire position", wire.position)
                .and_then(|_| finite("wire angle", wire.angle_degrees))
                .and_then(|_| wire.motion.validate())
                .and_then(|_| wire.surface().validate())
                .map_err(|source| PresetError::Wire { index, source })?;
            for (bead, preset) in wire.beads.iter().enumerate() {
                preset
                    .params()
                    .validate()
                    .map_err(|source| PresetError::Bead {
                        wire: index,
                        bead,
                        source,
                    })?;
            }
        }
        let names = self.bead_names();
        let free_names = &names[self.wire_bead_count()..];
        for (bead, name) in self.beads.iter().zip(free_names) {
            bead.params()
                .validate()
                .map_err(|source| PresetError::FreeBead {
                    name: name.clone(),
                    source,
                })?;
        }
        for (i, name) in names.iter().enumerate() {
            if names[..i].contains(name) {
                return Err(PresetError::DuplicateName(name.clone()));
            }
        }
        self.resolve_links(&names)?;
        if names.is_empty() {
            return Err(PresetError::Empty);
        }
        Ok(())
    }

    /// Every bead of the file in order: the wires' beads, then the free
    /// ones.
    pub fn all_beads(&self) -> impl Iterator<Item = &BeadPreset> {
        self.wires.iter().flat_map(|w| &w.beads).chain(&self.beads)
    }

    fn wire_bead_count(&self) -> usize {
        self.wires.iter().map(|w| w.beads.len()).sum()
    }

    /// Each bead's name, in the file's order: its own, or `bead<i>`.
    pub fn bead_names(&self) -> Vec<String> {
        self.all_beads()
            .enumerate()
            .map(|(i, b)| {
                if b.name.is_empty() {
                    format!("bead{i}")
                } else {
                    b.name.clone()
                }
            })
            .collect()
    }

    /// The constraints, then the springs, with the beads they name as
    /// indices into [`ScenePreset::all_beads`], every value checked.
    pub fn links(&self) -> Result<Vec<SceneLink>, PresetError> {
        self.resolve_links(&self.bead_names())
    }

    pub(super) fn resolve_links(&self, names: &[String]) -> Result<Vec<SceneLink>, PresetError> {
        let find = |item: &dyn Fn() -> String, name: &str| {
            names
                .iter()
                .position(|n| n == name)
                .ok_or_else(|| PresetError::Link {
                    item: item(),
                    problem: format!("no bead is named {name:?}"),
                })
        };
        let problem = |item: String| {
            move |e: ParamError| PresetError::Link {
                item,
                problem: e.to_string(),
            }
        };
        let mut links = Vec::new();
        for (index, constraint) in self.constraints.iter().enumerate() {
            let item = || format!("constraint {index} ({})", constraint.kind());
            links.push(match constraint {
                ConstraintPreset::Rod(rod) => {
                    let (a, b) = (find(&item, &rod.a)?, find(&item, &rod.b)?);
                    if a == b {
                        return Err(problem(item())(ParamError::Incompatible(
                            "a rod must join two different beads",
                        )));
                    }
                    positive("rod length", rod.length).map_err(problem(item()))?;
                    SceneLink::Rod {
                        a,
                        b,
                        length: rod.length,
                    }
                }
                ConstraintPreset::Pin(pin) => {
                    let bead = find(&item, &pin.bead)?;
                    finite_vector("pin point", pin.at).map_err(problem(item()))?;
                    SceneLink::Pin { bead, at: pin.at }
                }
            });
        }
        for (index, spring) in self.springs.iter().enumerate() {
            let item = || format!("spring {index}");
            let (a, b) = (find(&item, &spring.a)?, find(&item, &spring.b)?);
            if a == b {
                return Err(problem(item())(ParamError::Incompatible(
                    "a spring must join two different beads",
                )));
            }
            for (name, value) in [
                ("spring rest length", spring.rest_length),
                ("spring stiffness", spring.stiffness),
                ("spring damping", spring.damping),
            ] {
                non_negative(name, value).map_err(problem(item()))?;
            }
            links.push(SceneLink::Spring {
                a,
                b,
                spring: spring.clone(),
            });
        }
        Ok(links)
    }
}

/// A link of a scene with its beads as indices into
/// [`ScenePreset::all_beads`].
#[derive(Clone, Debug, PartialEq)]
pub enum SceneLink {
    /// A rod between beads `a` and `b`.
    Rod {
        /// The first bead.
        a: usize,
        /// The second bead.
        b: usize,
        /// Its length.
        length: f64,
    },
    /// A pin holding `bead` at `at`.
    Pin {
        /// The bead.
        bead: usize,
        /// The point.
        at: DVec2,
    },
    /// A spring between beads `a` and `b`.
    Spring {
        /// The first bead.
        a: usize,
        /// The second bead.
        b: usize,
        /// Its law.
        spring: SpringPreset,
    },
}
