//! The rigid bodies of a scene file (run by avian when the game builds
//! with `avian2d` or `avian3d`): their serde types, the checks of every
//! value, and a uniform solid's inertia.

use std::f64::consts::PI;

use bevy::math::{DQuat, DVec2, DVec3};
use serde::{Deserialize, Serialize};

use super::{given_some, written_some};
use crate::dynamics::Dimension;
use crate::geometry::{Pose, Pose3};
use crate::validate::{ParamError, finite, finite_vector, non_negative, positive};

/// A turn about `axis` (through a wire's or a body's origin) by `angle_degrees`,
/// right-handed: `rotation: (axis: (0.0, 1.0, 0.0), angle_degrees: 30.0)`.
/// None by default.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct RotationPreset {
    /// The axis, not zero (its length does not matter).
    pub axis: DVec3,
    /// The angle in degrees.
    pub angle_degrees: f64,
}

impl Default for RotationPreset {
    fn default() -> Self {
        Self {
            axis: DVec3::Z,
            angle_degrees: 0.0,
        }
    }
}

impl RotationPreset {
    /// The rotation as a unit quaternion, if the axis is not zero and
    /// everything is finite.
    pub fn quaternion(&self) -> Result<DQuat, ParamError> {
        finite_vector("rotation axis", self.axis)?;
        finite("rotation angle", self.angle_degrees)?;
        let axis = self
            .axis
            .try_normalize()
            .ok_or(ParamError::Incompatible("a rotation axis must not be zero"))?;
        Ok(DQuat::from_axis_angle(
            axis,
            self.angle_degrees.to_radians(),
        ))
    }
}

/// How a body of a scene moves: `Dynamic` (the default: forces and
/// contacts move it), `Static` (it never moves) or `Kinematic` (it moves
/// at its velocity and nothing pushes it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum BodyKind {
    /// Moved by forces, contacts and joints.
    #[default]
    Dynamic,
    /// Never moves.
    Static,
    /// Moves at its velocity; nothing pushes it.
    Kinematic,
}

/// A box of a scene: `(half_extents: (x, y))`, in space `(x, y, z)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxShape<V> {
    /// Half its side along each of its own axes, m.
    pub half_extents: V,
}

/// A ball of a scene (a disc in the plane): `(radius: r)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BallShape {
    /// Its radius, m.
    pub radius: f64,
}

/// A capsule of a scene, along its own y: `(radius: r, half_length: h)`,
/// the segment between its two round ends `2h` long.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CapsuleShape {
    /// Its radius, m.
    pub radius: f64,
    /// Half the length of its straight part, m.
    pub half_length: f64,
}

/// A body's shape, in its own frame, its centre at its origin.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum BodyShape<V> {
    /// `Box((half_extents: …))`.
    Box(BoxShape<V>),
    /// `Ball((radius: r))`.
    Ball(BallShape),
    /// `Capsule((radius: r, half_length: h))`, along local y.
    Capsule(CapsuleShape),
}

impl<V: Dimension> BodyShape<V> {
    /// Checks every size is positive and finite (a capsule's straight part
    /// may be zero: a ball).
    pub fn validate(&self) -> Result<(), ParamError> {
        match self {
            Self::Box(b) => {
                for (axis, name) in V::AXES.iter().zip(HALF_EXTENTS) {
                    positive(name, axis.dot(b.half_extents))?;
                }
                Ok(())
            }
            Self::Ball(b) => positive("ball radius", b.radius).map(drop),
            Self::Capsule(c) => {
                positive("capsule radius", c.radius)?;
                non_negative("capsule half length", c.half_length).map(drop)
            }
        }
    }
}

/// The names of a box's half extents, for its errors.
const HALF_EXTENTS: [&str; 3] = [
    "box half extent x",
    "box half extent y",
    "box half extent z",
];

/// The angular inertia about its centre of a uniform solid of `shape` and
/// `mass`, in the plane (a lamina: a rectangle, a disc, a stadium): a
/// rectangle `m (w² + h²) / 12`; a disc `m r² / 2`; a stadium its
/// rectangle and its two half discs, each moved out to its place.
pub fn plane_inertia(shape: &BodyShape<DVec2>, mass: f64) -> f64 {
    match shape {
        BodyShape::Box(b) => mass * b.half_extents.length_squared() / 3.0,
        BodyShape::Ball(b) => mass * b.radius * b.radius / 2.0,
        BodyShape::Capsule(c) => {
            let (r, h) = (c.radius, c.half_length);
            let (rectangle, disc) = (4.0 * r * h, PI * r * r);
            let m_rect = mass * rectangle / (rectangle + disc);
            let m_disc = mass * disc / (rectangle + disc);
            // Each half disc about its flat edge's centre, `m r² / 2` for
            // its half of the mass, taken to the body's centre through its
            // own centre of mass, `4r / 3π` out from that edge.
            let out = 4.0 * r / (3.0 * PI);
            m_rect * (r * r + h * h) / 3.0 + m_disc * (r * r / 2.0 + h * h + 2.0 * h * out)
        }
    }
}

/// The principal moments (about its own x, y and z) of a uniform solid
/// of `shape` and `mass` in space: a box `m (b² + c²) / 12` about each
/// axis; a ball `2 m r² / 5`; a capsule its cylinder and its two
/// hemispheres, each moved out to its place.
pub fn space_inertia(shape: &BodyShape<DVec3>, mass: f64) -> DVec3 {
    match shape {
        BodyShape::Box(b) => {
            let s = b.half_extents * b.half_extents;
            DVec3::new(s.y + s.z, s.x + s.z, s.x + s.y) * (mass / 3.0)
        }
        BodyShape::Ball(b) => DVec3::splat(0.4 * mass * b.radius * b.radius),
        BodyShape::Capsule(c) => {
            let (r, h) = (c.radius, c.half_length);
            let (cylinder, ball) = (2.0 * PI * r * r * h, 4.0 / 3.0 * PI * r * r * r);
            let m_cyl = mass * cylinder / (cylinder + ball);
            let m_ball = mass * ball / (cylinder + ball);
            let along = m_cyl * r * r / 2.0 + 0.4 * m_ball * r * r;
            // Each hemisphere about a diameter of its flat face, `2 m r² / 5`
            // for its half of the mass, taken to the body's centre through
            // its own centre of mass, `3r / 8` out from that face.
            let across = m_cyl * (3.0 * r * r + 4.0 * h * h) / 12.0
                + m_ball * (0.4 * r * r + h * h + 0.75 * h * r);
            DVec3::new(across, along, across)
        }
    }
}

/// A rigid body of a scene in the plane.
///
/// ```ron
/// (name: "cart", kind: Dynamic, shape: Box((half_extents: (0.2, 0.1))), mass: 2.0,
///  position: (1.0, 0.0), angle_degrees: 0.0, velocity: (0.0, 0.0),
///  angular_velocity: 0.0, restitution: 0.5, friction: 0.0)
/// ```
///
/// Everything but `name`, `shape`, `position` and, for a dynamic body,
/// `mass` has a default: dynamic, no turn, at rest, restitution 0,
/// friction 0.5, the inertia of a uniform solid of its shape.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyPreset {
    /// Its name: wires and joints name it.
    pub name: String,
    /// How it moves.
    #[serde(default, skip_serializing_if = "is_dynamic")]
    pub kind: BodyKind,
    /// Its shape: its collider in avian.
    pub shape: BodyShape<DVec2>,
    /// Its mass, kg; required for a dynamic body.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "written_some",
        deserialize_with = "given_some"
    )]
    pub mass: Option<f64>,
    /// Its angular inertia about its centre, kg·m²; a uniform solid's of
    /// its shape and mass where left out.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "written_some",
        deserialize_with = "given_some"
    )]
    pub inertia: Option<f64>,
    /// Where its centre starts.
    pub position: DVec2,
    /// Its turn, degrees counter-clockwise.
    #[serde(default)]
    pub angle_degrees: f64,
    /// Its velocity.
    #[serde(default)]
    pub velocity: DVec2,
    /// Its spin, rad/s counter-clockwise.
    #[serde(default)]
    pub angular_velocity: f64,
    /// The restitution of its contacts (a bead striking it takes the mean
    /// of this and the scene's `contacts.restitution`).
    #[serde(default)]
    pub restitution: f64,
    /// The friction of its contacts.
    #[serde(default = "default_friction")]
    pub friction: f64,
}

/// A rigid body of a scene in space: as [`BodyPreset`], turned by
/// `rotation: (axis: (x, y, z), angle_degrees: a)` as a wire is, its
/// spin a vector (rad/s, right-handed) and its inertia, where given, its
/// three principal moments about its own axes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpaceBodyPreset {
    /// Its name: wires and joints name it.
    pub name: String,
    /// How it moves.
    #[serde(default, skip_serializing_if = "is_dynamic")]
    pub kind: BodyKind,
    /// Its shape: its collider in avian.
    pub shape: BodyShape<DVec3>,
    /// Its mass, kg; required for a dynamic body.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "written_some",
        deserialize_with = "given_some"
    )]
    pub mass: Option<f64>,
    /// Its principal moments of inertia about its own x, y and z, kg·m²;
    /// a uniform solid's of its shape and mass where left out.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "written_some",
        deserialize_with = "given_some"
    )]
    pub inertia: Option<DVec3>,
    /// Where its centre starts.
    pub position: DVec3,
    /// Its turn.
    #[serde(default)]
    pub rotation: RotationPreset,
    /// Its velocity.
    #[serde(default)]
    pub velocity: DVec3,
    /// Its spin, rad/s about the vector's axis, right-handed.
    #[serde(default)]
    pub angular_velocity: DVec3,
    /// The restitution of its contacts.
    #[serde(default)]
    pub restitution: f64,
    /// The friction of its contacts.
    #[serde(default = "default_friction")]
    pub friction: f64,
}

/// A body's friction where the file gives none.
fn default_friction() -> f64 {
    0.5
}

/// Whether a body is dynamic (and its kind goes unwritten).
fn is_dynamic(kind: &BodyKind) -> bool {
    *kind == BodyKind::Dynamic
}

/// Checks what a body of either dimension has: a name, a valid shape, a
/// mass where it is dynamic (and a positive one wherever given), its
/// restitution in `[0, 1]` and a friction of zero or more, each vector
/// finite.
fn check_body<V: Dimension>(
    (name, kind, shape): (&str, BodyKind, &BodyShape<V>),
    mass: Option<f64>,
    (restitution, friction): (f64, f64),
    vectors: &[(&'static str, V)],
) -> Result<(), ParamError> {
    if name.is_empty() {
        return Err(ParamError::Incompatible("a body needs a name"));
    }
    shape.validate()?;
    match mass {
        Some(mass) => positive("body mass", mass).map(drop)?,
        None if kind == BodyKind::Dynamic => {
            return Err(ParamError::Incompatible("a dynamic body needs a mass"));
        }
        None => {}
    }
    finite("body restitution", restitution)?;
    if !(0.0..=1.0).contains(&restitution) {
        return Err(ParamError::Incompatible(
            "a body's restitution must be from 0 to 1",
        ));
    }
    non_negative("body friction", friction)?;
    for &(what, value) in vectors {
        finite_vector(what, value)?;
    }
    Ok(())
}

/// A rigid body of a scene in either dimension ([`BodyPreset`],
/// [`SpaceBodyPreset`]), as a scene's checks and runs see it.
pub trait SceneBody {
    /// Where it starts: a [`Pose`] or a [`Pose3`].
    type Pose;
    /// Its principal moments: one in the plane, three in space.
    type Inertia;
    /// Its name.
    fn name(&self) -> &str;
    /// How it moves.
    fn kind(&self) -> BodyKind;
    /// Checks every value.
    fn validate(&self) -> Result<(), ParamError>;
    /// Where it starts: its centre and turn (unturned where the turn is
    /// invalid, which [`SceneBody::validate`] refuses).
    fn pose(&self) -> Self::Pose;
    /// Its mass and principal moments (as given, or a uniform solid's);
    /// `None` for a body given no mass (static or kinematic).
    fn mass_properties(&self) -> Option<(f64, Self::Inertia)>;
}

impl SceneBody for BodyPreset {
    type Pose = Pose;
    type Inertia = f64;

    fn name(&self) -> &str {
        &self.name
    }

    fn kind(&self) -> BodyKind {
        self.kind
    }

    fn validate(&self) -> Result<(), ParamError> {
        check_body(
            (&self.name, self.kind, &self.shape),
            self.mass,
            (self.restitution, self.friction),
            &[
                ("body position", self.position),
                ("body velocity", self.velocity),
            ],
        )?;
        finite("body angle", self.angle_degrees)?;
        finite("body angular velocity", self.angular_velocity)?;
        if let Some(inertia) = self.inertia {
            positive("body inertia", inertia)?;
        }
        Ok(())
    }

    fn mass_properties(&self) -> Option<(f64, f64)> {
        let mass = self.mass?;
        let inertia = self
            .inertia
            .unwrap_or_else(|| plane_inertia(&self.shape, mass));
        Some((mass, inertia))
    }

    fn pose(&self) -> Pose {
        Pose::new(self.position, self.angle_degrees.to_radians())
    }
}

impl SceneBody for SpaceBodyPreset {
    type Pose = Pose3;
    type Inertia = DVec3;

    fn name(&self) -> &str {
        &self.name
    }

    fn kind(&self) -> BodyKind {
        self.kind
    }

    fn validate(&self) -> Result<(), ParamError> {
        check_body(
            (&self.name, self.kind, &self.shape),
            self.mass,
            (self.restitution, self.friction),
            &[
                ("body position", self.position),
                ("body velocity", self.velocity),
                ("body angular velocity", self.angular_velocity),
            ],
        )?;
        self.rotation.quaternion()?;
        if let Some(inertia) = self.inertia {
            for (name, moment) in ["body inertia x", "body inertia y", "body inertia z"]
                .into_iter()
                .zip(inertia.to_array())
            {
                positive(name, moment)?;
            }
        }
        Ok(())
    }

    fn mass_properties(&self) -> Option<(f64, DVec3)> {
        let mass = self.mass?;
        let inertia = self
            .inertia
            .unwrap_or_else(|| space_inertia(&self.shape, mass));
        Some((mass, inertia))
    }

    fn pose(&self) -> Pose3 {
        Pose3 {
            origin: self.position,
            rotation: self.rotation.quaternion().unwrap_or_default(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The uniform solids' inertias against their textbook values and
    /// against each other: a capsule with no straight part is a ball, one
    /// with a tiny radius a rod `m L² / 12`.
    #[test]
    fn a_uniform_solids_inertia_is_the_textbook_ones() {
        let boxed = BodyShape::Box(BoxShape {
            half_extents: DVec2::new(0.2, 0.1),
        });
        assert!((plane_inertia(&boxed, 2.0) - 2.0 * (0.16 + 0.04) / 12.0).abs() < 1e-15);
        fn capsule<V>(radius: f64, half_length: f64) -> BodyShape<V> {
            BodyShape::Capsule(CapsuleShape {
                radius,
                half_length,
            })
        }
        let disc = BodyShape::Ball(BallShape { radius: 0.5 });
        assert!((plane_inertia(&capsule(0.5, 0.0), 3.0) - plane_inertia(&disc, 3.0)).abs() < 1e-15);
        let rod = plane_inertia(&capsule(1e-6, 1.0), 3.0);
        assert!((rod - 3.0 * 4.0 / 12.0).abs() < 1e-5, "{rod}");
        let cube = BodyShape::Box(BoxShape {
            half_extents: DVec3::new(0.5, 1.0, 1.5),
        });
        let moments = space_inertia(&cube, 6.0);
        let expected = DVec3::new(4.0 + 9.0, 1.0 + 9.0, 1.0 + 4.0) * 6.0 / 12.0;
        assert!((moments - expected).length() < 1e-14, "{moments}");
        let ball = space_inertia(&BodyShape::Ball(BallShape { radius: 0.5 }), 3.0);
        let round = space_inertia(&capsule(0.5, 0.0), 3.0);
        assert!((ball - round).length() < 1e-15);
        let rod = space_inertia(&capsule(1e-6, 1.0), 3.0);
        assert!((rod.x - 1.0).abs() < 1e-5 && rod.y < 1e-11, "{rod}");
    }

    /// A capsule's inertia in the plane is the sum of its parts taken by
    /// numerical integration over its area (a 2,000 by 2,000 grid).
    #[test]
    fn a_stadiums_inertia_is_its_areas_second_moment() {
        let (r, h, mass) = (0.3, 0.5, 2.0);
        let n = 2000;
        let (w, t) = (2.0 * r, 2.0 * (h + r));
        let (mut area, mut moment) = (0.0, 0.0);
        for i in 0..n {
            for j in 0..n {
                let x = -r + (i as f64 + 0.5) * w / n as f64;
                let y = -(h + r) + (j as f64 + 0.5) * t / n as f64;
                let inside = y.abs() <= h || x * x + (y.abs() - h).powi(2) <= r * r;
                if inside {
                    area += 1.0;
                    moment += x * x + y * y;
                }
            }
        }
        let numeric = mass * moment / area;
        let shape = BodyShape::Capsule(CapsuleShape {
            radius: r,
            half_length: h,
        });
        let exact = plane_inertia(&shape, mass);
        assert!(
            (numeric / exact - 1.0).abs() < 1e-4,
            "{numeric} against {exact}"
        );
    }

    /// Each bad value of a body is refused in words.
    #[test]
    fn a_bad_body_is_refused_in_words() {
        let good = BodyPreset {
            name: "cart".into(),
            kind: BodyKind::Dynamic,
            shape: BodyShape::Ball(BallShape { radius: 0.1 }),
            mass: Some(2.0),
            inertia: None,
            position: DVec2::ZERO,
            angle_degrees: 0.0,
            velocity: DVec2::ZERO,
            angular_velocity: 0.0,
            restitution: 0.5,
            friction: 0.5,
        };
        assert!(good.validate().is_ok());
        let said = |body: BodyPreset| body.validate().unwrap_err().to_string();
        assert!(
            said(BodyPreset {
                mass: None,
                ..good.clone()
            })
            .contains("needs a mass")
        );
        assert!(
            said(BodyPreset {
                mass: Some(-1.0),
                ..good.clone()
            })
            .contains("mass")
        );
        assert!(
            said(BodyPreset {
                name: String::new(),
                ..good.clone()
            })
            .contains("name")
        );
        assert!(
            said(BodyPreset {
                restitution: 1.5,
                ..good.clone()
            })
            .contains("restitution")
        );
        assert!(
            said(BodyPreset {
                shape: BodyShape::Box(BoxShape {
                    half_extents: DVec2::new(0.1, 0.0)
                }),
                ..good.clone()
            })
            .contains("box half extent y")
        );
        assert!(
            said(BodyPreset {
                position: DVec2::new(f64::NAN, 0.0),
                ..good.clone()
            })
            .contains("position")
        );
        assert!(
            BodyPreset {
                kind: BodyKind::Static,
                mass: None,
                ..good
            }
            .validate()
            .is_ok()
        );
    }
}
