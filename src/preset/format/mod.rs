//! The scene file's format: the serde types of `*.scene.ron`, the checks
//! of every value in them, and the links with their beads resolved.

mod bodies;
mod joins;
mod links;
mod paths;

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

pub use bodies::{
    BallShape, BodyKind, BodyPreset, BodyShape, BoxShape, CapsuleShape, RotationPreset, SceneBody,
    SpaceBodyPreset, plane_inertia, space_inertia,
};
pub(super) use joins::check_joins;
pub use joins::{CouplingPreset, HingePreset, SceneJoin};
pub use links::SceneLink;
pub(super) use links::{check_beads_and_links, names_of, resolve_links};
pub use paths::{
    ANCHOR_TOLERANCE, MotorPreset, PathPreset, PathRotationPreset, PositionMotorPreset, ScenePath,
    VelocityMotorPreset,
};
pub(super) use paths::{NamedWire, check_bodies, checked_bodies};

use super::error::PresetError;
use crate::dynamics::{BeadParams, BeadRadius, Contacts, SendsBeadsBack, SimParams};
use crate::geometry::{Coordinates, Friction, Pose, Side, Surface, WireMotion, WireShape};
use crate::validate::{ParamError, finite, finite_vector};

/// A bead of a scene file: its name (optional) and its parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
#[serde(bound(
    serialize = "V: Coordinates + Serialize",
    deserialize = "V: Coordinates + Deserialize<'de>"
))]
pub struct BeadPreset<V: Coordinates = DVec2> {
    /// The name links refer to it by; empty for none (it is then
    /// `bead<i>`, `i` its place in the file).
    pub name: String,
    /// Mass in kg.
    pub mass: f64,
    /// Where a restart puts the bead.
    pub initial_position: V,
    /// The velocity a restart gives it.
    pub initial_velocity: V,
    /// Its radius (see [`BeadRadius`](crate::BeadRadius)): 0, the
    /// default, touches nothing.
    #[serde(skip_serializing_if = "is_zero")]
    pub radius: f64,
}

/// Whether a value is zero (and goes unwritten).
fn is_zero(value: &f64) -> bool {
    *value == 0.0
}

impl<V: Coordinates> Default for BeadPreset<V> {
    fn default() -> Self {
        let params = BeadParams::default();
        Self {
            name: String::new(),
            mass: params.mass,
            initial_position: params.initial_position,
            initial_velocity: params.initial_velocity,
            radius: 0.0,
        }
    }
}

impl<V: Coordinates> BeadPreset<V> {
    /// The bead's parameters.
    pub fn params(&self) -> BeadParams<V> {
        BeadParams {
            mass: self.mass,
            initial_position: self.initial_position,
            initial_velocity: self.initial_velocity,
        }
    }

    /// Checks its parameters and radius.
    fn validate(&self) -> Result<(), ParamError> {
        self.params().validate()?;
        BeadRadius::new(self.radius).map(drop)
    }
}

/// How a scene's beads strike when they touch: `contacts: (restitution:
/// e, friction: μ)`, elastic (`e = 1`) and frictionless by default.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct ContactsPreset {
    /// The restitution of a strike, from 0 (the pair stays together) to 1.
    pub restitution: f64,
    /// Coulomb friction between beads that strike, zero or more.
    pub friction: f64,
}

impl Default for ContactsPreset {
    fn default() -> Self {
        let contacts = Contacts::default();
        Self {
            restitution: contacts.restitution(),
            friction: contacts.friction(),
        }
    }
}

impl ContactsPreset {
    /// As the resource, if valid.
    pub fn contacts(&self) -> Result<Contacts, PresetError> {
        Contacts::new(self.restitution)
            .and_then(|c| c.with_friction(self.friction))
            .map_err(PresetError::Contacts)
    }

    /// Whether it is the default (and goes unwritten).
    pub(super) fn is_default(&self) -> bool {
        *self == Self::default()
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
pub struct PinPreset<V = DVec2> {
    /// The bead's name.
    pub bead: String,
    /// The point.
    pub at: V,
}

/// A constraint of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(bound(
    serialize = "V: Coordinates + Serialize",
    deserialize = "V: Coordinates + Deserialize<'de>"
))]
pub enum ConstraintPreset<V: Coordinates = DVec2> {
    /// See [`Rod`](crate::Rod).
    Rod(RodPreset),
    /// See [`Pin`](crate::Pin).
    Pin(PinPreset<V>),
    /// A body's point held on a wire (see [`PathPreset`]).
    Path(PathPreset<V>),
    /// Two bodies joined at a point (see [`HingePreset`]).
    Hinge(HingePreset<V>),
    /// Two bodies joined by a rod (see [`CouplingPreset`]).
    Coupling(CouplingPreset<V>),
}

impl<V: Coordinates> ConstraintPreset<V> {
    /// `rod`, `pin`, `path`, `hinge` or `coupling`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Rod(_) => "rod",
            Self::Pin(_) => "pin",
            Self::Path(_) => "path",
            Self::Hinge(_) => "hinge",
            Self::Coupling(_) => "coupling",
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
    /// The name path joints refer to it by (empty, the default, for none).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub name: String,
    /// The body it rides, by name (empty, the default, for none): its
    /// `position` and `angle_degrees` are then in the body's frame.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub body: String,
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
    /// Whether it catches every bead with a radius that flies onto it, not
    /// only its own (a marble run's track; see [`CatchesBeads`](crate::CatchesBeads)): `false`
    /// by default, and only on a one-sided wire.
    #[serde(default, skip_serializing_if = "is_false")]
    pub catches: bool,
    /// Whether it sends its beads back to a point of it once they have
    /// left it and settled (see [`SendsBeadsBack`](crate::SendsBeadsBack)):
    /// `sends_back: (to: (x, y), speed: v, after: t)`; not by default.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "written_some",
        deserialize_with = "given_some"
    )]
    pub sends_back: Option<SendBackPreset<DVec2>>,
    /// The beads on it.
    #[serde(default)]
    pub beads: Vec<BeadPreset>,
}

/// Where a wire sends its settled beads back to: `(to: point, speed: v,
/// after: t)`, a bead off the wire slower than `v` m/s for `t` s put at
/// rest at `to` (see [`SendsBeadsBack`](crate::SendsBeadsBack)).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SendBackPreset<V> {
    /// The point of the wire a bead is put at.
    pub to: V,
    /// The speed below which a bead is settling, m/s.
    pub speed: f64,
    /// How long it must stay below it, s.
    pub after: f64,
}

impl<V: crate::dynamics::Dimension> SendBackPreset<V> {
    /// The component, if the numbers are valid.
    pub fn component(&self) -> Result<SendsBeadsBack<V>, ParamError> {
        SendsBeadsBack::new(self.to, self.speed, self.after)
    }
}

/// Checks what a wire does with beads that are not on it, in either
/// dimension: one that catches them is one-sided, and the numbers it
/// sends its beads back by are valid.
pub(super) fn catching_and_sending<V: crate::dynamics::Dimension>(
    (catches, side): (bool, Side),
    sends_back: Option<&SendBackPreset<V>>,
) -> Result<(), ParamError> {
    if let Some(back) = sends_back {
        back.component()?;
    }
    if catches && side == Side::Both {
        return Err(ParamError::Incompatible(
            "a wire that catches beads must be one-sided (side: Positive or Negative)",
        ));
    }
    Ok(())
}

/// An optional section as a file writes it: `field: (…)`, not
/// `Some((…))`.
pub(super) fn written_some<T: Serialize, S: serde::Serializer>(
    value: &Option<T>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    match value {
        Some(value) => value.serialize(serializer),
        None => serializer.serialize_none(),
    }
}

/// An optional section as a file gives it: present, or left out.
pub(super) fn given_some<'de, T: Deserialize<'de>, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> Result<Option<T>, D::Error> {
    T::deserialize(deserializer).map(Some)
}

/// Whether a flag is off (and goes unwritten).
pub(super) fn is_false(flag: &bool) -> bool {
    !flag
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
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenePreset {
    /// A human-readable name.
    pub name: String,
    /// `2`, or left out: a scene in the plane (a scene in space says `3`;
    /// see [`SpaceScene`](super::SpaceScene)).
    #[serde(default = "plane", skip_serializing_if = "is_plane")]
    pub dimension: u8,
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
    /// How beads with radii strike.
    #[serde(default, skip_serializing_if = "ContactsPreset::is_default")]
    pub contacts: ContactsPreset,
    /// Rigid bodies, run by avian (features `avian2d`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bodies: Vec<BodyPreset>,
}

impl ScenePreset {
    /// Parses and validates a scene in the plane; a scene in space is
    /// refused (read it with [`SceneFile::from_ron`](super::SceneFile::from_ron)).
    pub fn from_ron(text: &str) -> Result<Self, PresetError> {
        match dimension_of(text) {
            2 => {}
            3 => return Err(PresetError::InSpace),
            other => return Err(PresetError::Dimension(other)),
        }
        let preset: Self = parse(text)?;
        preset.validate()?;
        Ok(preset)
    }

    /// Checks the parameters, every wire and every bead.
    pub fn validate(&self) -> Result<(), PresetError> {
        match self.dimension {
            2 => {}
            3 => return Err(PresetError::InSpace),
            other => return Err(PresetError::Dimension(other)),
        }
        self.params.validate().map_err(PresetError::Params)?;
        self.contacts.contacts()?;
        for (index, wire) in self.wires.iter().enumerate() {
            wire.shape
                .validate()
                .map_err(|source| PresetError::Wire { index, source })?;
            finite_vector("wire position", wire.position)
                .and_then(|_| finite("wire angle", wire.angle_degrees))
                .and_then(|_| wire.motion.validate())
                .and_then(|_| wire.surface().validate())
                .map_err(|source| PresetError::Wire { index, source })?;
            catching_and_sending((wire.catches, wire.side), wire.sends_back.as_ref())
                .map_err(|source| PresetError::Wire { index, source })?;
        }
        let wires: Vec<&[BeadPreset]> = self.wires.iter().map(|w| w.beads.as_slice()).collect();
        let beads = check_beads_and_links(&wires, &self.beads, &self.constraints, &self.springs);
        with_bodies(beads, self.bodies.is_empty())?;
        self.paths()?;
        self.joins().map(drop)
    }

    /// The hinges and couplings with their bodies found, each checked.
    pub fn joins(&self) -> Result<Vec<SceneJoin>, PresetError> {
        check_joins(&checked_bodies(&self.bodies)?, &self.constraints)
    }

    /// The path joints with their bodies and wires found, each body, wire
    /// name and anchor checked.
    pub fn paths(&self) -> Result<Vec<ScenePath>, PresetError> {
        let bodies = checked_bodies(&self.bodies)?;
        let wires: Vec<NamedWire<DVec2>> = self
            .wires
            .iter()
            .map(|wire| NamedWire {
                name: &wire.name,
                body: &wire.body,
                place: Pose::new(wire.position, wire.angle_degrees.to_radians()),
                rows: vec![wire.shape.clone()],
            })
            .collect();
        check_bodies(&bodies, &wires, &self.constraints)
    }

    /// Every bead of the file in order: the wires' beads, then the free
    /// ones.
    pub fn all_beads(&self) -> impl Iterator<Item = &BeadPreset> {
        self.wires.iter().flat_map(|w| &w.beads).chain(&self.beads)
    }

    /// Each bead's name, in the file's order: its own, or `bead<i>`.
    pub fn bead_names(&self) -> Vec<String> {
        names_of(self.all_beads())
    }

    /// The constraints, then the springs, with the beads they name as
    /// indices into [`ScenePreset::all_beads`], every value checked.
    pub fn links(&self) -> Result<Vec<SceneLink>, PresetError> {
        resolve_links(&self.constraints, &self.springs, &self.bead_names())
    }
}

/// A scene's beads and links checked, where a scene with bodies may have
/// no bead (`no_bodies` false).
pub(super) fn with_bodies<T>(
    checked: Result<T, PresetError>,
    no_bodies: bool,
) -> Result<(), PresetError> {
    match checked {
        Err(PresetError::Empty) if !no_bodies => Ok(()),
        checked => checked.map(drop),
    }
}

/// The one field read before the rest: which kind of scene a file is.
#[derive(Deserialize)]
struct Dimension {
    #[serde(default = "plane")]
    dimension: u8,
}

/// A scene file's `dimension`: 2 (the plane) where it gives none, and
/// where the file is too broken to tell (the full parse then says where).
pub(super) fn dimension_of(text: &str) -> u8 {
    parse::<Dimension>(text).map_or(2, |probe| probe.dimension)
}

/// A scene file's dimension when it gives none: the plane.
pub(super) fn plane() -> u8 {
    2
}

/// Whether a dimension is the plane's (and goes unwritten).
fn is_plane(dimension: &u8) -> bool {
    *dimension == 2
}

/// A scene file's text as `T`, the error naming the item and the place
/// in the file where it is wrong.
pub(super) fn parse<T: serde::de::DeserializeOwned>(text: &str) -> Result<T, PresetError> {
    let mut de = ron::Deserializer::from_str(text)?;
    let parsed: T = match serde_path_to_error::deserialize(&mut de) {
        Ok(parsed) => parsed,
        Err(err) => {
            let item = err.path().to_string();
            return Err(PresetError::at(item, de.span_error(err.into_inner())));
        }
    };
    de.end().map_err(|e| de.span_error(e))?;
    Ok(parsed)
}
