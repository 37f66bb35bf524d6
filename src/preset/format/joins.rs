//! The joins of a scene file between two bodies, each one of avian's
//! joints: a hinge, the two joined at a point and free to turn there (a
//! door on its post), and a coupling, a rod between a point of each (two
//! cars of a train).

use bevy::math::DVec2;
use serde::{Deserialize, Serialize};

use super::paths::body_named;
use super::{ConstraintPreset, given_some, written_some};
use crate::geometry::Coordinates;
use crate::geometry::Placement;
use crate::preset::error::PresetError;
use crate::validate::{ParamError, finite_vector};

/// A hinge of a scene: `Hinge((a: "post", b: "door", at: point, axis:
/// direction))`, the bodies `a` and `b` joined at the point `at` (where
/// they start, in the world) by avian's `RevoluteJoint`, free to turn
/// about it: in the plane about `z` (no `axis`), in space about `axis` (a
/// world direction where they start) or, with none, every way (avian's
/// `SphericalJoint`, a ball joint). The two bodies do not collide with
/// each other.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(bound(
    serialize = "V: Coordinates + Serialize",
    deserialize = "V: Coordinates + Deserialize<'de>"
))]
pub struct HingePreset<V: Coordinates = DVec2> {
    /// The first body's name.
    pub a: String,
    /// The second body's name.
    pub b: String,
    /// The point they turn about where they start, world frame.
    pub at: V,
    /// In space, the direction they turn about; none for every way.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "written_some",
        deserialize_with = "given_some"
    )]
    pub axis: Option<V>,
}

impl<V: Coordinates> HingePreset<V> {
    /// Checks its numbers: a finite point, and a finite axis that is not
    /// zero, given only in space (`plane` false).
    pub fn validate(&self, plane: bool) -> Result<(), ParamError> {
        finite_vector("hinge point", self.at)?;
        match self.axis {
            Some(_) if plane => Err(ParamError::Incompatible(
                "a hinge in the plane turns about z: it takes no axis",
            )),
            Some(axis) => {
                finite_vector("hinge axis", axis)?;
                if axis.dot(axis) > 0.0 {
                    Ok(())
                } else {
                    Err(ParamError::Incompatible("a hinge's axis must not be zero"))
                }
            }
            None => Ok(()),
        }
    }
}

/// A coupling of a scene: `Coupling((a: "car 1", b: "car 2", anchor_a:
/// point, anchor_b: point))`, a rod between the point `anchor_a` of body
/// `a` and `anchor_b` of body `b` (each in its body's frame; its centre
/// where left out), as long as they are apart where the bodies start, free
/// to turn at both ends: avian's `DistanceJoint`. The two bodies do not
/// collide with each other.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(bound(
    serialize = "V: Coordinates + Serialize",
    deserialize = "V: Coordinates + Deserialize<'de>"
))]
pub struct CouplingPreset<V: Coordinates = DVec2> {
    /// The first body's name.
    pub a: String,
    /// The second body's name.
    pub b: String,
    /// The rod's end on the first body, in its frame.
    #[serde(default)]
    pub anchor_a: V,
    /// The rod's end on the second body, in its frame.
    #[serde(default)]
    pub anchor_b: V,
}

/// A join of a scene with its bodies found (indices into the scene's
/// `bodies`), its numbers checked.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneJoin<V = DVec2> {
    /// A hinge: the bodies turn about the point `at` (world frame, where
    /// they start), about `axis` (of unit length) in space if it has one.
    Hinge {
        /// The bodies.
        bodies: [usize; 2],
        /// The point.
        at: V,
        /// The axis, if one.
        axis: Option<V>,
    },
    /// A coupling: a rod of `length` between the points `anchors` of the
    /// bodies, each in its body's frame.
    Coupling {
        /// The bodies.
        bodies: [usize; 2],
        /// The rod's ends.
        anchors: [V; 2],
        /// Its length, m.
        length: f64,
    },
}

impl<V> SceneJoin<V> {
    /// The two bodies joined.
    pub fn bodies(&self) -> [usize; 2] {
        match self {
            Self::Hinge { bodies, .. } | Self::Coupling { bodies, .. } => *bodies,
        }
    }
}

/// A scene's hinges and couplings, each with its two bodies found
/// (`bodies`, by name, with where each starts) and its numbers checked.
pub(in crate::preset) fn check_joins<V: Coordinates, P: Placement<V>>(
    bodies: &[(&str, P)],
    constraints: &[ConstraintPreset<V>],
) -> Result<Vec<SceneJoin<V>>, PresetError> {
    let plane = V::DIMENSION == 2;
    let mut joins = Vec::new();
    for (index, constraint) in constraints.iter().enumerate() {
        let (a, b) = match constraint {
            ConstraintPreset::Hinge(hinge) => (&hinge.a, &hinge.b),
            ConstraintPreset::Coupling(coupling) => (&coupling.a, &coupling.b),
            _ => continue,
        };
        let item = || format!("constraint {index} ({})", constraint.kind());
        let problem = |problem: String| PresetError::Link {
            item: item(),
            problem,
        };
        let pair = [body_named(bodies, &item, a)?, body_named(bodies, &item, b)?];
        if pair[0] == pair[1] {
            return Err(problem(format!("joins body {a:?} to itself")));
        }
        joins.push(match constraint {
            ConstraintPreset::Hinge(hinge) => {
                hinge.validate(plane).map_err(|e| problem(e.to_string()))?;
                SceneJoin::Hinge {
                    bodies: pair,
                    at: hinge.at,
                    axis: hinge.axis.map(|axis| axis * (1.0 / axis.dot(axis).sqrt())),
                }
            }
            ConstraintPreset::Coupling(coupling) => {
                let anchors = [coupling.anchor_a, coupling.anchor_b];
                for anchor in anchors {
                    finite_vector("coupling anchor", anchor).map_err(|e| problem(e.to_string()))?;
                }
                let ends = [0, 1].map(|i| bodies[pair[i]].1.to_world(anchors[i]));
                let apart = ends[1] - ends[0];
                SceneJoin::Coupling {
                    bodies: pair,
                    anchors,
                    length: apart.dot(apart).sqrt(),
                }
            }
            _ => continue,
        });
    }
    Ok(joins)
}
