//! The path joints of a scene file, which hold a body's point on a wire:
//! how the body may turn, what drives it, and the checks of a scene's
//! bodies against its wires and joints.

use bevy::math::DVec2;
use serde::{Deserialize, Serialize};

use super::{ConstraintPreset, SceneBody, given_some, written_some};
use crate::dynamics::Dimension;
use crate::geometry::{Coordinates, Placement, WireSpace};
use crate::preset::error::PresetError;
use crate::solver::PathMotor;
use crate::validate::{ParamError, finite, finite_vector, non_negative, positive};

/// How a body held by a path joint of a scene may turn: in the plane
/// `Free` or `Tangent` (its local +x along the wire's tangent); in space
/// `Free`, `AroundTangent`, `AroundNormal`, `AroundBinormal`, `ToPath` (+x
/// along the tangent, +y along the rail's up) or `Fixed`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum PathRotationPreset {
    /// As it likes: only its anchor is held.
    #[default]
    Free,
    /// In the plane: turned with the wire's tangent.
    Tangent,
    /// In space: only about the tangent.
    AroundTangent,
    /// In space: only about the normal.
    AroundNormal,
    /// In space: only about the binormal.
    AroundBinormal,
    /// In space: turned with the rail's frame.
    ToPath,
    /// In space: not at all.
    Fixed,
}

impl PathRotationPreset {
    /// Whether a scene in the plane (`plane`) or in space may have it.
    pub fn fits(self, plane: bool) -> bool {
        match self {
            Self::Free => true,
            Self::Tangent => plane,
            _ => !plane,
        }
    }
}

/// A velocity motor of a scene: `(speed: v, max_force: f)`, the speed
/// along the wire's own direction (a line's +x, a circle
/// counter-clockwise, a spline's parameter).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VelocityMotorPreset {
    /// The speed it holds, m/s.
    pub speed: f64,
    /// The largest force it gives, N.
    pub max_force: f64,
}

/// A position motor of a scene: `(target: point, frequency: f,
/// damping_ratio: ζ, max_force: F)`, the anchor drawn along the wire to
/// `target` (a point of the wire, in its frame) as by a spring of
/// frequency `f` Hz and damping ratio `ζ` (1, critical, where left out).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionMotorPreset<V> {
    /// The point of the wire the anchor is drawn to, wire's frame.
    pub target: V,
    /// The spring's frequency, Hz.
    pub frequency: f64,
    /// Its damping ratio.
    #[serde(default = "critical")]
    pub damping_ratio: f64,
    /// The largest force it gives, N.
    pub max_force: f64,
}

/// A damping ratio where the file gives none: critical.
fn critical() -> f64 {
    1.0
}

/// What drives a body of a scene along its wire.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum MotorPreset<V> {
    /// `Velocity((speed: v, max_force: f))`.
    Velocity(VelocityMotorPreset),
    /// `Position((target: …, frequency: f, damping_ratio: ζ, max_force: F))`.
    Position(PositionMotorPreset<V>),
}

impl<V: Coordinates> MotorPreset<V> {
    /// The motor, if its numbers are valid: finite, a force limit of zero
    /// or more, a positive frequency.
    pub fn motor(&self) -> Result<PathMotor<V>, ParamError> {
        match *self {
            Self::Velocity(m) => {
                finite("motor speed", m.speed)?;
                non_negative("motor force limit", m.max_force)?;
                Ok(PathMotor::Velocity {
                    speed: m.speed,
                    max_force: m.max_force,
                })
            }
            Self::Position(m) => {
                finite_vector("motor target", m.target)?;
                positive("motor frequency", m.frequency)?;
                non_negative("motor damping ratio", m.damping_ratio)?;
                non_negative("motor force limit", m.max_force)?;
                Ok(PathMotor::Position {
                    target: m.target,
                    frequency: m.frequency,
                    damping_ratio: m.damping_ratio,
                    max_force: m.max_force,
                })
            }
        }
    }
}

/// A path joint of a scene: `Path((body: "cart", wire: "hoop", anchor:
/// point, rotation: Free, motor: …, friction: f))`, the point `anchor` of
/// the body (in its frame) held on the wire. The anchor is the body's
/// centre, the rotation `Free`, and there is no motor and no friction
/// where left out.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(bound(
    serialize = "V: Coordinates + Serialize",
    deserialize = "V: Coordinates + Deserialize<'de>"
))]
pub struct PathPreset<V: Coordinates = DVec2> {
    /// The body's name.
    pub body: String,
    /// The wire's name.
    pub wire: String,
    /// The point held, in the body's frame.
    #[serde(default)]
    pub anchor: V,
    /// How the body may turn.
    #[serde(default)]
    pub rotation: PathRotationPreset,
    /// What drives it along the wire.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "written_some",
        deserialize_with = "given_some"
    )]
    pub motor: Option<MotorPreset<V>>,
    /// The largest force that holds it against sliding while no motor
    /// drives it, N.
    #[serde(default)]
    pub friction: f64,
}

impl<V: Coordinates> PathPreset<V> {
    /// Checks its own numbers, and that its rotation is of the scene's
    /// dimension (`plane`).
    pub fn validate(&self, plane: bool) -> Result<(), ParamError> {
        finite_vector("path anchor", self.anchor)?;
        if !self.rotation.fits(plane) {
            return Err(ParamError::Incompatible(if plane {
                "that rotation is of space: a path joint in the plane is Free or Tangent"
            } else {
                "Tangent is of the plane: a path joint in space is Free, AroundTangent, AroundNormal, AroundBinormal, ToPath or Fixed"
            }));
        }
        if let Some(motor) = &self.motor {
            motor.motor()?;
        }
        non_negative("path friction", self.friction).map(drop)
    }
}

/// How far a wire's anchor may start off it, m.
pub const ANCHOR_TOLERANCE: f64 = 1e-6;

/// A wire as a scene's bodies are checked against it: its name (empty for
/// none), the name of the body it rides (empty for none), its place (in
/// that body's frame where it rides one) and its rows.
pub(in crate::preset) struct NamedWire<'a, V: WireSpace> {
    /// Its name.
    pub name: &'a str,
    /// The body it rides.
    pub body: &'a str,
    /// Its place.
    pub place: V::Pose,
    /// Its rows: one in the plane, one or two in space.
    pub rows: Vec<V::Shape>,
}

/// A path joint of a scene with its body and wire found: indices into
/// the scene's `bodies` and `wires`, its numbers checked.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenePath<V = DVec2> {
    /// The body's index.
    pub body: usize,
    /// The wire's index.
    pub wire: usize,
    /// The point held, in the body's frame.
    pub anchor: V,
    /// How the body may turn.
    pub rotation: PathRotationPreset,
    /// What drives it, if anything.
    pub motor: Option<PathMotor<V>>,
    /// Its friction force limit, N.
    pub friction: f64,
}

/// Each of a scene's bodies checked, with its name and where it starts.
pub(in crate::preset) fn checked_bodies<B: SceneBody>(
    bodies: &[B],
) -> Result<Vec<(&str, B::Pose)>, PresetError> {
    bodies
        .iter()
        .enumerate()
        .map(|(index, body)| {
            body.validate().map_err(|source| PresetError::Body {
                index,
                name: body.name().to_owned(),
                source,
            })?;
            Ok((body.name(), body.pose()))
        })
        .collect()
}

/// How far the point `local` (in a wire's frame) is off the wire of
/// `rows`: each row's `|C| / |∇C|`, the rows' together.
fn off_wire<V: WireSpace>(rows: &[V::Shape], local: V) -> f64 {
    rows.iter().fold(0.0, |off, row| {
        let g = V::shape_geometry(row, local, None);
        off.hypot(g.c.abs() / g.normal.dot(g.normal).sqrt())
    })
}

/// Checks a scene's bodies (`(name, where it starts)` each, checked
/// each on its own already) against its wires and path joints: the
/// bodies' and the wires' names distinct, each wire's body and each
/// joint's body and wire there, each joint's numbers, and each anchor on
/// its wire where it starts (to [`ANCHOR_TOLERANCE`]). The joints, found.
pub(in crate::preset) fn check_bodies<V: Dimension>(
    bodies: &[(&str, V::Pose)],
    wires: &[NamedWire<V>],
    constraints: &[ConstraintPreset<V>],
) -> Result<Vec<ScenePath<V>>, PresetError> {
    let plane = V::AXES.len() == 2;
    for (i, (name, _)) in bodies.iter().enumerate() {
        if bodies[..i].iter().any(|(other, _)| other == name) {
            return Err(PresetError::DuplicateBody((*name).to_owned()));
        }
    }
    let body_named = |item: &dyn Fn() -> String, name: &str| body_named(bodies, item, name);
    for (index, wire) in wires.iter().enumerate() {
        if !wire.name.is_empty() && wires[..index].iter().any(|w| w.name == wire.name) {
            return Err(PresetError::DuplicateWire(wire.name.to_owned()));
        }
        if !wire.body.is_empty() {
            body_named(&|| wire_item(index, wire.name), wire.body)?;
        }
    }
    let mut paths = Vec::new();
    for (index, constraint) in constraints.iter().enumerate() {
        let ConstraintPreset::Path(path) = constraint else {
            continue;
        };
        let item = || format!("constraint {index} (path)");
        let problem = |e: ParamError| PresetError::Link {
            item: item(),
            problem: e.to_string(),
        };
        path.validate(plane).map_err(problem)?;
        let body = body_named(&item, &path.body)?;
        let wire = wires
            .iter()
            .position(|w| !w.name.is_empty() && w.name == path.wire)
            .ok_or_else(|| PresetError::Link {
                item: item(),
                problem: format!("no wire is named {:?}", path.wire),
            })?;
        let on = &wires[wire];
        let anchor = bodies[body].1.to_world(path.anchor);
        let carrier = (!on.body.is_empty())
            .then(|| bodies.iter().find(|(n, _)| *n == on.body))
            .flatten();
        let in_carrier = carrier.map_or(anchor, |(_, pose)| pose.to_local(anchor));
        let off = off_wire::<V>(&on.rows, on.place.to_local(in_carrier));
        // A NaN distance (a NaN place) is off too.
        if off.is_nan() || off > ANCHOR_TOLERANCE {
            return Err(PresetError::Link {
                item: item(),
                problem: format!(
                    "the anchor of body {:?} starts {off:.3e} m off wire {:?} (at most {ANCHOR_TOLERANCE:e} m)",
                    path.body, path.wire
                ),
            });
        }
        paths.push(ScenePath {
            body,
            wire,
            anchor: path.anchor,
            rotation: path.rotation,
            motor: path
                .motor
                .as_ref()
                .map(MotorPreset::motor)
                .transpose()
                .map_err(problem)?,
            friction: path.friction,
        });
    }
    Ok(paths)
}

/// The index of the body named `name` among `bodies`, or the error of
/// `item` that names none.
pub(super) fn body_named<P>(
    bodies: &[(&str, P)],
    item: &dyn Fn() -> String,
    name: &str,
) -> Result<usize, PresetError> {
    bodies
        .iter()
        .position(|(n, _)| *n == name)
        .ok_or_else(|| PresetError::Link {
            item: item(),
            problem: format!("no body is named {name:?}"),
        })
}

/// A wire in words: `wire 2`, or `wire 2 ("hoop")` where it has a name.
fn wire_item(index: usize, name: &str) -> String {
    if name.is_empty() {
        format!("wire {index}")
    } else {
        format!("wire {index} ({name:?})")
    }
}
