//! Scene files in space (`dimension: 3`): [`SpaceScene`], every vector
//! with three components, wires that are curves or surfaces placed by a
//! position and a rotation about any axis.

use bevy::math::DVec3;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use super::error::PresetError;
use super::format::{
    BeadPreset, ConstraintPreset, ContactsPreset, NamedWire, RotationPreset, SceneJoin, SceneLink,
    ScenePath, SendBackPreset, SpaceBodyPreset, SpringPreset, catching_and_sending,
    check_beads_and_links, check_bodies, check_joins, checked_bodies, given_some, is_false,
    names_of, with_bodies, written_some,
};
use super::spawn::{FromPreset, spawn_beads_and_links};
use crate::dynamics::{
    CatchesBeads, PrescribedMotion, RailOrientation, SpaceParams, SpaceWire, WirePlace,
};
use crate::geometry::{
    Circle, Cone, Cycloid, Cylinder, Ellipse, Friction, Helix, Line, OnPlane, Oscillate, Parabola,
    Plane, Pose3, Side, Sine, SpaceMotion, SpaceShape, Sphere, Spline, Surface, Torus, WireShape,
};
use crate::validate::{ParamError, finite, finite_vector, positive};

/// A wire's shape in a scene file in space: a planar shape in the wire's
/// local xy-plane, a helix or a spline (curves), or a surface.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum SpaceShapePreset {
    /// `Circle((radius: r))`, in the local xy-plane.
    Circle(Circle),
    /// `Ellipse((a: a, b: b))`, in the local xy-plane.
    Ellipse(Ellipse),
    /// `Line(())`, the local x-axis.
    Line(Line),
    /// `Parabola((focal_length: f))`, in the local xy-plane.
    Parabola(Parabola),
    /// `Sine((amplitude: a, wavelength: l))`, in the local xy-plane.
    Sine(Sine),
    /// `Cycloid((radius: r))`, in the local xy-plane.
    Cycloid(Cycloid),
    /// `Helix((radius: r, pitch: p))`: `(r cos θ, p θ / 2π, r sin θ)`.
    Helix(Helix),
    /// `Spline((kind: …, points: [(x, y, z), …], closed: …))`.
    Spline(Spline<DVec3>),
    /// `Plane(())`: local `y = 0`, its positive side `+y`.
    Plane(()),
    /// `Sphere((radius: r))`, positive outside.
    Sphere(Sphere),
    /// `Cylinder((radius: r))` about the local y-axis, positive outside.
    Cylinder(Cylinder),
    /// `Cone((half_angle_degrees: a))`: apex at the origin, opening along
    /// `+y`, positive outside.
    Cone(ConePreset),
    /// `Torus((major_radius: R, minor_radius: r))` about the local
    /// y-axis, positive outside.
    Torus(Torus),
}

/// A cone as a scene file gives it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConePreset {
    /// The half angle in degrees, strictly between 0 and 90.
    pub half_angle_degrees: f64,
}

impl SpaceShapePreset {
    /// The planar shape, for the six that lie in the local xy-plane.
    fn planar(&self) -> Option<WireShape> {
        Some(match self {
            Self::Circle(c) => WireShape::Circle(*c),
            Self::Ellipse(e) => WireShape::Ellipse(*e),
            Self::Line(l) => WireShape::Line(*l),
            Self::Parabola(p) => WireShape::Parabola(*p),
            Self::Sine(s) => WireShape::Sine(*s),
            Self::Cycloid(c) => WireShape::Cycloid(c.clone()),
            _ => return None,
        })
    }

    /// Whether its sizes are valid: positive radii and pitch, a cone's
    /// angle strictly between 0° and 90°, a torus's tube inside its ring.
    pub fn validate(&self) -> Result<(), ParamError> {
        if let Some(planar) = self.planar() {
            return planar.validate();
        }
        match self {
            Self::Helix(h) => {
                positive("helix radius", h.radius)?;
                positive("helix pitch", h.pitch).map(drop)
            }
            Self::Sphere(s) => positive("radius", s.radius).map(drop),
            Self::Cylinder(c) => positive("radius", c.radius).map(drop),
            Self::Cone(c) => {
                let a = finite("cone half angle", c.half_angle_degrees)?;
                if a > 0.0 && a < 90.0 {
                    Ok(())
                } else {
                    Err(ParamError::OutOfRange {
                        name: "cone half angle (degrees)",
                        min: 0.0,
                        max: 90.0,
                        value: a,
                    })
                }
            }
            Self::Torus(t) => {
                positive("major radius", t.major_radius)?;
                positive("minor radius", t.minor_radius).map(drop)
            }
            _ => Ok(()),
        }
    }

    /// The shape as a wire: a curve or a surface.
    pub fn shape(&self) -> SpaceShape {
        match self {
            Self::Helix(h) => SpaceShape::curve(*h),
            Self::Spline(s) => SpaceShape::curve(s.clone()),
            Self::Plane(()) => SpaceShape::surface(Plane),
            Self::Sphere(s) => SpaceShape::surface(*s),
            Self::Cylinder(c) => SpaceShape::surface(*c),
            Self::Cone(c) => SpaceShape::surface(Cone {
                half_angle: c.half_angle_degrees.to_radians(),
            }),
            Self::Torus(t) => SpaceShape::surface(*t),
            planar => SpaceShape::curve(OnPlane(planar.planar().unwrap_or(WireShape::Line(Line)))),
        }
    }
}

/// A spin as a scene file in space gives it:
/// `Spin((angular_velocity: w, axis: (0.0, 1.0, 0.0)))`, right-handed
/// about `axis` (by default `(0, 0, 1)`, the plane's counter-clockwise
/// turn).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpinPreset {
    /// Radians per second.
    pub angular_velocity: f64,
    /// The axis through the wire's origin, not zero.
    #[serde(default = "z_axis")]
    pub axis: DVec3,
}

fn z_axis() -> DVec3 {
    DVec3::Z
}

/// How a wire in space moves about its resting pose.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum SpaceMotionPreset {
    /// It stays where it is placed.
    #[default]
    Fixed,
    /// `Oscillate((amplitude: (ax, ay, az), frequency: f))`.
    Oscillate(Oscillate<DVec3>),
    /// See [`SpinPreset`].
    Spin(SpinPreset),
}

impl SpaceMotionPreset {
    /// The motion.
    pub fn motion(&self) -> SpaceMotion {
        match *self {
            Self::Fixed => SpaceMotion::Fixed,
            Self::Oscillate(o) => SpaceMotion::Oscillate(o),
            Self::Spin(s) => SpaceMotion::Spin {
                angular_velocity: s.angular_velocity,
                axis: s.axis,
            },
        }
    }
}

/// One wire of a scene in space and the beads on it.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpaceWirePreset {
    /// The name path joints refer to it by (empty, the default, for none).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub name: String,
    /// The body it rides, by name (empty, the default, for none): its
    /// `position` and `rotation` are then in the body's frame.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub body: String,
    /// The shape, in the wire's frame.
    pub shape: SpaceShapePreset,
    /// Where the wire's origin sits.
    #[serde(default)]
    pub position: DVec3,
    /// How it is turned about its origin.
    #[serde(default)]
    pub rotation: RotationPreset,
    /// How it moves about that pose. Its beads' initial velocities are
    /// relative to the wire's own at `t = 0`.
    #[serde(default)]
    pub motion: SpaceMotionPreset,
    /// Which way it pushes (see [`Side`]).
    #[serde(default)]
    pub side: Side,
    /// On a one-sided wire, the share of the normal speed a landing bead
    /// bounces off with.
    #[serde(default)]
    pub restitution: f64,
    /// Coulomb friction along it.
    #[serde(default)]
    pub friction: Friction,
    /// Viscous damping along it, N·s/m.
    #[serde(default)]
    pub damping: f64,
    /// On a curve, a rail: each bead on it turns with the track as a cart
    /// does, up as near this `up` as the track allows where it starts
    /// (see [`RailOrientation`]).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "written_some",
        deserialize_with = "given_some"
    )]
    pub rail: Option<RailPreset>,
    /// Whether it catches every bead with a radius that flies onto it, not
    /// only its own (a marble run's bowl; see [`CatchesBeads`]): `false`
    /// by default, and only on a one-sided surface.
    #[serde(default, skip_serializing_if = "is_false")]
    pub catches: bool,
    /// Whether it sends its beads back to a point of it once they have
    /// left it and settled: `sends_back: (to: (x, y, z), speed: v,
    /// after: t)` (see [`SendsBeadsBack`](crate::SendsBeadsBack)); not by
    /// default.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "written_some",
        deserialize_with = "given_some"
    )]
    pub sends_back: Option<SendBackPreset<DVec3>>,
    /// The beads on it.
    #[serde(default)]
    pub beads: Vec<BeadPreset<DVec3>>,
}

/// A wire's rail: `rail: (up: (0.0, 1.0, 0.0))`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RailPreset {
    /// The direction a cart's up is rolled toward where it starts.
    pub up: DVec3,
}

impl SpaceWirePreset {
    /// Its side, restitution, friction and damping.
    pub fn surface(&self) -> Surface {
        Surface {
            side: self.side,
            restitution: self.restitution,
            friction: self.friction,
            damping: self.damping,
        }
    }

    /// Its resting pose, if its position and rotation are valid.
    pub fn pose(&self) -> Result<Pose3, ParamError> {
        let origin = finite_vector("wire position", self.position)?;
        Ok(Pose3 {
            origin,
            rotation: self.rotation.quaternion()?,
        })
    }

    /// Checks its shape, pose, motion, surface, rail and what it does with
    /// beads not on it.
    fn validate(&self) -> Result<(), ParamError> {
        self.shape.validate()?;
        self.pose()?;
        self.motion.motion().validate()?;
        if let Some(rail) = self.rail {
            if matches!(self.shape.shape(), SpaceShape::Surface(_)) {
                return Err(ParamError::Incompatible(
                    "a rail is a curve: a surface has no track to turn with",
                ));
            }
            RailOrientation::new(rail.up)?;
        }
        catching_and_sending((self.catches, self.side), self.sends_back.as_ref())?;
        self.surface().validate()
    }
}

/// A whole scene in space: `dimension: 3`, parameters (gravity with three
/// components), wires, free beads, rods, pins and springs.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpaceScene {
    /// A human-readable name.
    pub name: String,
    /// Always 3.
    pub dimension: u8,
    /// The parameters (missing fields take their defaults).
    #[serde(default)]
    pub params: SpaceParams,
    /// The wires.
    #[serde(default)]
    pub wires: Vec<SpaceWirePreset>,
    /// The free beads, on no wire.
    #[serde(default)]
    pub beads: Vec<BeadPreset<DVec3>>,
    /// Rods and pins (`at: (x, y, z)`).
    #[serde(default)]
    pub constraints: Vec<ConstraintPreset<DVec3>>,
    /// Springs between beads.
    #[serde(default)]
    pub springs: Vec<SpringPreset>,
    /// How beads with radii strike.
    #[serde(default, skip_serializing_if = "ContactsPreset::is_default")]
    pub contacts: ContactsPreset,
    /// Rigid bodies, run by avian (feature `avian3d`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bodies: Vec<SpaceBodyPreset>,
}

impl SpaceScene {
    /// Checks the parameters, every wire, every bead and every link.
    pub fn validate(&self) -> Result<(), PresetError> {
        if self.dimension != 3 {
            return Err(PresetError::Params(ParamError::Incompatible(
                "a scene in space says dimension: 3",
            )));
        }
        finite_vector("gravity", self.params.0.gravity_in_space()).map_err(PresetError::Params)?;
        self.params.0.validate().map_err(PresetError::Params)?;
        self.contacts.contacts()?;
        for (index, wire) in self.wires.iter().enumerate() {
            wire.validate()
                .map_err(|source| PresetError::Wire { index, source })?;
        }
        let wires: Vec<&[BeadPreset<DVec3>]> =
            self.wires.iter().map(|w| w.beads.as_slice()).collect();
        let beads = check_beads_and_links(&wires, &self.beads, &self.constraints, &self.springs);
        with_bodies(beads, self.bodies.is_empty())?;
        self.paths()?;
        self.joins().map(drop)
    }

    /// The hinges and couplings with their bodies found (see
    /// [`ScenePreset::joins`](super::ScenePreset::joins)).
    pub fn joins(&self) -> Result<Vec<SceneJoin<DVec3>>, PresetError> {
        check_joins(&checked_bodies(&self.bodies)?, &self.constraints)
    }

    /// The path joints with their bodies and wires found (see
    /// [`ScenePreset::paths`](super::ScenePreset::paths)).
    pub fn paths(&self) -> Result<Vec<ScenePath<DVec3>>, PresetError> {
        let bodies = checked_bodies(&self.bodies)?;
        let mut wires = Vec::new();
        for (index, wire) in self.wires.iter().enumerate() {
            wires.push(NamedWire {
                name: &wire.name,
                body: &wire.body,
                place: wire
                    .pose()
                    .map_err(|source| PresetError::Wire { index, source })?,
                rows: wire.shape.shape().rows(),
            });
        }
        check_bodies(&bodies, &wires, &self.constraints)
    }

    /// Every bead of the file in order: the wires' beads, then the free
    /// ones.
    pub fn all_beads(&self) -> impl Iterator<Item = &BeadPreset<DVec3>> {
        self.wires.iter().flat_map(|w| &w.beads).chain(&self.beads)
    }

    /// Each bead's name, in the file's order: its own, or `bead<i>`.
    pub fn bead_names(&self) -> Vec<String> {
        names_of(self.all_beads())
    }

    /// The links with their beads resolved (see
    /// [`ScenePreset::links`](super::ScenePreset::links)).
    pub fn links(&self) -> Result<Vec<SceneLink<DVec3>>, PresetError> {
        super::format::resolve_links(&self.constraints, &self.springs, &self.bead_names())
    }

    /// Spawns the scene: its wires, beads (named) and links, each marked
    /// [`FromPreset`]. The beads in the file's order.
    pub fn spawn(&self, commands: &mut Commands) -> Vec<Entity> {
        self.spawn_all(commands).0
    }

    /// [`SpaceScene::spawn`], and the bodies in avian3d (feature
    /// `avian3d`; without it they are left out, with a warning): the beads
    /// and the bodies in the file's order.
    pub fn spawn_all(&self, commands: &mut Commands) -> (Vec<Entity>, Vec<Entity>) {
        let mut wires = Vec::new();
        for wire in &self.wires {
            let Ok(pose) = wire.pose() else { continue };
            let component = SpaceWire::new(wire.shape.shape()).with_surface(wire.surface());
            let motion = wire.motion.motion();
            let wire_entity = component.ok().map(|component| {
                // In `f64` to the solver; the plugin writes the `Transform`.
                let mut entity = commands.spawn((component, WirePlace::in_space(pose), FromPreset));
                if let Ok(prescribed) = PrescribedMotion::in_space(motion)
                    && motion != SpaceMotion::Fixed
                {
                    entity.insert(prescribed);
                }
                if wire.catches {
                    entity.insert(CatchesBeads);
                }
                if let Some(Ok(back)) = wire.sends_back.map(|b| b.component()) {
                    entity.insert(back);
                }
                entity.id()
            });
            let (_, twist) = motion.at(pose, 0.0);
            wires.push((wire_entity, twist, wire.beads.as_slice()));
        }
        let links = self.links().unwrap_or_default();
        if let Ok(contacts) = self.contacts.contacts() {
            commands.insert_resource(contacts);
        }
        let spawned: Vec<Option<Entity>> = wires.iter().map(|w| w.0).collect();
        let bodies = self.spawn_bodies(&spawned, commands);
        let beads = spawn_beads_and_links(&wires, &self.beads, links, self.bead_names(), commands);
        // The beads of a rail turn with it.
        let mut first = 0;
        for wire in &self.wires {
            let on = &beads[first..first + wire.beads.len()];
            first += wire.beads.len();
            let Some(Ok(rail)) = wire.rail.map(|r| RailOrientation::new(r.up)) else {
                continue;
            };
            for &bead in on.iter().filter(|b| **b != Entity::PLACEHOLDER) {
                commands.entity(bead).insert(rail);
            }
        }
        (beads, bodies)
    }

    /// Spawns the bodies in avian3d, puts the wires that ride them on
    /// them (`wires` the spawned wires) and the path joints on them,
    /// spawns the hinges and couplings, and sets avian's gravity to the
    /// scene's.
    #[cfg(feature = "avian3d")]
    fn spawn_bodies(&self, wires: &[Option<Entity>], commands: &mut Commands) -> Vec<Entity> {
        if self.bodies.is_empty() {
            return Vec::new();
        }
        use avian3d::math::AdjustPrecision;
        commands.insert_resource(avian3d::prelude::Gravity(
            self.params.0.gravity_in_space().adjust_precision(),
        ));
        let bodies = super::bodies_space::spawn_bodies(&self.bodies, commands);
        super::spawn::join_bodies(
            (wires, &bodies),
            (self.wires.iter().map(|w| w.body.as_str()), &self.bodies),
            (
                &self.paths().unwrap_or_default(),
                super::bodies_space::joint,
            ),
            (&self.joins().unwrap_or_default(), super::bodies_space::join),
            commands,
        );
        bodies
    }

    /// Says that the bodies are left out: this build has no avian3d.
    #[cfg(not(feature = "avian3d"))]
    fn spawn_bodies(&self, _: &[Option<Entity>], _: &mut Commands) -> Vec<Entity> {
        super::spawn::bodies_left_out(&self.name, self.bodies.len(), "avian3d")
    }
}
