//! [`Wire`]: a shape placed by its entity's `Transform`; [`OnWire`] puts a
//! bead on it.

use std::sync::Arc;

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use crate::geometry::not_placeable;
use crate::geometry::{
    Circle, Coordinates, Ellipse, ImplicitCurve, ImplicitSurface, Line, Parabola, Pose, Pose3,
    Sine, SpaceCurve, SpaceMotion, SpaceShape, Surface, WireMotion, WirePath, WireShape, WireSpace,
};
use crate::solver::{Contact, ContactEvent};
use crate::validate::ParamError;

/// A wire: a shape placed in the plane by the entity's `Transform`
/// (translation x, y and rotation about z; the wire should be a top-level
/// entity, since the plugin reads `Transform`, not `GlobalTransform`).
///
/// Built only through validating constructors, so a wire in the world always
/// has valid dimensions.
#[derive(Component, Clone, Debug)]
#[require(Transform, WirePose)]
pub struct Wire {
    shape: WireShape,
    /// None for a plain wire: most wires are, and stay small.
    surface: SurfaceSlot,
}

impl Wire {
    /// A wire of any shape, if its dimensions are valid.
    pub fn new(shape: WireShape) -> Result<Self, ParamError> {
        shape.validate()?;
        Ok(Self {
            shape,
            surface: SurfaceSlot::default(),
        })
    }

    /// The wire with `surface`: one-sided, bouncy, rough or damped (see
    /// [`Surface`]), if its numbers are valid.
    pub fn with_surface(self, surface: Surface) -> Result<Self, ParamError> {
        let surface = SurfaceSlot::new(surface)?;
        Ok(Self { surface, ..self })
    }

    /// What the wire does besides holding its beads.
    pub fn surface(&self) -> &Surface {
        self.surface.get()
    }

    /// The wire with `shape` in place of its own, its surface kept (the
    /// shape was validated when `shape` was made a [`NextWireShape`]).
    pub(crate) fn reshaped(&self, shape: &WireShape) -> Self {
        Self {
            shape: shape.clone(),
            surface: self.surface.clone(),
        }
    }

    /// A circle of the given radius about the entity's origin.
    pub fn circle(radius: f64) -> Result<Self, ParamError> {
        Self::new(WireShape::Circle(Circle { radius }))
    }

    /// An ellipse with semi-axes `a` (local x) and `b` (local y).
    pub fn ellipse(a: f64, b: f64) -> Result<Self, ParamError> {
        Self::new(WireShape::Ellipse(Ellipse { a, b }))
    }

    /// The infinite line along the entity's local x axis.
    pub fn line() -> Self {
        Self {
            shape: WireShape::Line(Line),
            surface: SurfaceSlot::default(),
        }
    }

    /// The parabola `y = x²/(4f)`.
    pub fn parabola(focal_length: f64) -> Result<Self, ParamError> {
        Self::new(WireShape::Parabola(Parabola { focal_length }))
    }

    /// The sine track `y = A sin(2πx/λ)`.
    pub fn sine(amplitude: f64, wavelength: f64) -> Result<Self, ParamError> {
        Self::new(WireShape::Sine(Sine {
            amplitude,
            wavelength,
        }))
    }

    /// A wire along a curve of the game's own.
    pub fn custom(curve: impl ImplicitCurve + Send + Sync + 'static) -> Self {
        Self {
            shape: WireShape::Custom(Arc::new(curve)),
            surface: SurfaceSlot::default(),
        }
    }

    /// The shape.
    pub fn shape(&self) -> &WireShape {
        &self.shape
    }
}

/// Where a wire is, in `f64`: its origin and turn as the solver takes
/// them ([`Pose`] in the plane, [`Pose3`] in space), where a `Transform`
/// holds them in `f32`. A wire with one is placed exactly there: the
/// plugin writes its `Transform` from it (at that edge, in `f32`), and
/// takes the place, not the `Transform`, while the `Transform` still
/// shows it. Scene files place their wires so.
///
/// A game moves such a wire by writing either: the place (followed
/// exactly, as a moved `Transform` is followed), or the `Transform` (the
/// place then follows the `Transform`). On a wire with a
/// [`PrescribedMotion`] it is the pose the motion is about. A turn whose
/// length is one to within 1e-6 (one read from an `f32` rotation) is
/// taken as the exact rotation nearest it. A place that is not finite, or
/// whose turn is not a rotation (a zero quaternion, one of length 2), is
/// not taken: the `Transform` places the wire, with a one-line warning
/// each time such a place is written.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct WirePlace<V: WireSpace = DVec2>(pub V::Pose);

impl WirePlace {
    /// A wire in the plane placed at `pose`.
    pub fn new(pose: Pose) -> Self {
        Self(pose)
    }
}

impl WirePlace<DVec3> {
    /// A wire in space placed at `pose`.
    pub fn in_space(pose: Pose3) -> Self {
        Self(pose)
    }
}

/// Moves a wire along a prescribed motion about its [`WirePlace`], or
/// without one the pose its `Transform` has when the motion first applies
/// (its resting pose, to which a [`Restart`](crate::Restart) returns it).
/// A place written later moves that resting pose at once, with no
/// motion of its own. The plugin writes the wire's `Transform` each
/// step, and the beads on it feel the motion exactly: its
/// velocity and acceleration enter the constraint force (the `∂C/∂t`
/// terms), with no differencing.
///
/// A wire without this component whose `Transform` the game writes is
/// followed instead: see [`WireBeadSystems::Prepare`](crate::WireBeadSystems::Prepare).
///
/// `PrescribedMotion<DVec3>` moves a [`SpaceWire`] by a
/// [`SpaceMotion`](crate::geometry::SpaceMotion): an oscillation along a
/// 3D amplitude or a spin about any axis through its origin.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct PrescribedMotion<V: WireSpace = DVec2>(V::Motion);

impl PrescribedMotion {
    /// The motion of a wire in the plane, if its numbers are valid.
    pub fn new(motion: WireMotion) -> Result<Self, ParamError> {
        Self::validated(motion)
    }
}

impl PrescribedMotion<DVec3> {
    /// The motion of a wire in space, if its numbers are valid (a spin's
    /// axis not zero).
    pub fn in_space(motion: SpaceMotion) -> Result<Self, ParamError> {
        Self::validated(motion)
    }
}

impl<V: WireSpace> PrescribedMotion<V> {
    /// The motion, if its numbers are valid.
    fn validated(motion: V::Motion) -> Result<Self, ParamError> {
        V::validate_motion(&motion)?;
        Ok(Self(motion))
    }

    /// The motion.
    pub fn motion(&self) -> V::Motion {
        self.0
    }
}

/// Where a wire is over time, kept by the plugin in
/// [`WireBeadSystems::Prepare`](crate::WireBeadSystems::Prepare): fixed,
/// prescribed, or followed from the poses the game writes; none if its
/// `Transform` is not finite.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub(crate) struct WirePose<V: WireSpace = DVec2>(Option<WirePath<V>>);

impl<V: WireSpace> Default for WirePose<V> {
    fn default() -> Self {
        Self(Some(WirePath::Fixed(V::Pose::default())))
    }
}

impl<V: WireSpace> WirePose<V> {
    /// A wire on `path`, or none if its transform is not finite.
    pub(crate) fn new(path: Option<WirePath<V>>) -> Self {
        Self(path)
    }

    /// A wire on `path`.
    pub(crate) fn on(path: WirePath<V>) -> Self {
        Self(Some(path))
    }

    /// The path, if the wire's transform is finite.
    pub(crate) fn path(&self) -> Option<WirePath<V>> {
        self.0
    }

    /// The path, or the error that the wire's transform is not finite.
    pub(crate) fn get(&self) -> Result<WirePath<V>, ParamError> {
        self.0.ok_or_else(not_placeable)
    }
}

/// The in-plane pose of a wire's `Transform`, or an error if it is not
/// finite.
pub fn pose_of(transform: &Transform) -> Result<Pose, ParamError> {
    Pose::from_translation_rotation(transform.translation, transform.rotation)
}

/// A wire's surface, boxed and kept only where it is not plain (as on most
/// wires), so that a wire stays small.
#[derive(Clone, Debug, Default)]
struct SurfaceSlot(Option<Box<Surface>>);

impl SurfaceSlot {
    /// `surface`, if its numbers are valid.
    fn new(surface: Surface) -> Result<Self, ParamError> {
        surface.validate()?;
        Ok(Self((surface != Surface::PLAIN).then(|| Box::new(surface))))
    }

    /// The surface: plain where none was given.
    fn get(&self) -> &Surface {
        self.0.as_deref().unwrap_or(&Surface::PLAIN)
    }
}

/// A wire in space: a surface ([`SpaceShape::Surface`], one constraint
/// row on each bead it holds) or a curve ([`SpaceShape::Curve`], two),
/// placed by the entity's `Transform` (translation and rotation; the wire
/// should be a top-level entity), moved by a
/// [`PrescribedMotion<DVec3>`](PrescribedMotion), whose velocity and
/// acceleration its beads feel exactly. A wire whose `Transform` the game
/// writes is followed, as in the plane: its motion is the quadratic through
/// its last three poses (see [`SpaceHistory`](crate::geometry::SpaceHistory)).
/// Beads go on it with [`OnWire`]; a [`SpaceBead`](crate::SpaceBead) on it
/// steps in an island of its own or with the beads it is joined to.
#[derive(Component, Clone, Debug)]
#[require(Transform, WirePose<DVec3>)]
pub struct SpaceWire {
    shape: SpaceShape,
    surface: SurfaceSlot,
}

impl SpaceWire {
    /// A wire of this shape, its surface plain.
    pub fn new(shape: SpaceShape) -> Self {
        Self {
            shape,
            surface: SurfaceSlot::default(),
        }
    }

    /// A surface as a wire.
    pub fn surface_of(surface: impl ImplicitSurface + Send + Sync + 'static) -> Self {
        Self::new(SpaceShape::surface(surface))
    }

    /// A curve as a wire.
    pub fn curve(curve: impl SpaceCurve + Send + Sync + 'static) -> Self {
        Self::new(SpaceShape::curve(curve))
    }

    /// The wire with a surface (one-sided, rough, damped), if it is valid.
    pub fn with_surface(self, surface: Surface) -> Result<Self, ParamError> {
        let surface = SurfaceSlot::new(surface)?;
        Ok(Self { surface, ..self })
    }

    /// The wire's surface.
    pub fn surface(&self) -> &Surface {
        self.surface.get()
    }

    /// The shape.
    pub fn shape(&self) -> &SpaceShape {
        &self.shape
    }
}

/// An edited shape for a wire, applied (and removed) by the next
/// [`Restart`](crate::Restart). Built only from a valid shape.
#[derive(Component, Clone, Debug)]
pub struct NextWireShape(Wire);

impl NextWireShape {
    /// A pending edit, if `shape` is valid.
    pub fn new(shape: WireShape) -> Result<Self, ParamError> {
        Wire::new(shape).map(Self)
    }

    /// The edited shape.
    pub fn shape(&self) -> &WireShape {
        self.0.shape()
    }

    /// The wire it will become.
    pub fn wire(&self) -> &Wire {
        &self.0
    }
}

/// Puts a bead on a wire. Several beads may share one wire; despawning the
/// wire despawns its beads.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
#[relationship(relationship_target = WireBeads)]
#[require(WireContact)]
pub struct OnWire(pub Entity);

/// Whether a bead is held on its wire or flying off a one-sided one (see
/// [`Surface`]), and, on a spline or cycloid, where along the curve it
/// was last (so a curve that crosses itself keeps the bead on its branch).
/// Kept by the plugin; a [`Restart`](crate::Restart) puts every bead back
/// on its wire.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct WireContact {
    pub(crate) contact: Contact,
    /// The curve parameter at the end of the last step; NaN if unknown.
    pub(crate) along: f32,
}

impl Default for WireContact {
    fn default() -> Self {
        Self {
            contact: Contact::OnWire,
            along: f32::NAN,
        }
    }
}

impl WireContact {
    /// On the wire.
    pub fn is_on(&self) -> bool {
        self.contact == Contact::OnWire
    }

    /// The contact.
    pub fn get(&self) -> Contact {
        self.contact
    }

    /// On a spline or cycloid, its parameter where the bead was after the
    /// last step (a spline's segment `i` spans `[i, i + 1]`); NaN before
    /// the first step and on other wires.
    pub fn along(&self) -> f64 {
        f64::from(self.along)
    }
}

/// Sent when a bead leaves a wire (a one-sided one that would have to
/// pull, or any past its end) or lands on a one-sided one, its own or one
/// that catches it (also logged, one line).
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct ContactChanged<V: Coordinates = DVec2> {
    /// The bead.
    pub bead: Entity,
    /// What happened, when and where.
    pub event: ContactEvent<V>,
}

/// The beads on a wire, kept by Bevy from their [`OnWire`].
#[derive(Component, Debug, Default)]
#[relationship_target(relationship = OnWire, linked_spawn)]
pub struct WireBeads(Vec<Entity>);

/// Fixes the wire it is on to the rigid body `0` (a door, a cart, a free
/// body): the wire's place (its `Transform`, or its
/// [`WirePlace`]) is then in the body's frame, from the
/// body's origin, and the wire moves and turns with the body. A
/// path joint on it (`wirebead::avian::PathJoint`,
/// `wirebead::avian3d::PathJoint`) holds its own body against the carrier: the
/// joint's push, its motor, its friction and its ends act on both, so the
/// pair keeps its momentum and its angular momentum, and a body held on a
/// hoop fixed to a free body swings the two about their common centre of
/// mass. Joints on one carrier are solved one after another each
/// substep, as avian solves its own joints. The place is read each
/// substep: a place that moves on the body moves the wire there, but only
/// the body's own motion counts in the wire's velocity (put a moving
/// track on a body of its own). A carrier that is no other rigid body
/// (or the joint's own body) leaves the wire where its place puts it, in
/// the world, and the joint says so once in the log.
///
/// A bead of ours on a carried wire rides it the same way: the avian
/// plugin of its dimension makes it a point body of avian (its mass, its
/// rotation locked, no collider), held on the wire by a path joint, as
/// soon as it is on the wire (and again at each restart). Its initial
/// velocity is relative to the carrier's point where it starts, as on any
/// moving wire; gravity is the plugin's ([`SimParams`](crate::SimParams))
/// and the forces of [`WireBeadSystems::Forces`](crate::WireBeadSystems::Forces)
/// act on it for the step. Avian steps it with its carrier; after avian's
/// step its [`BeadPosition`](crate::BeadPosition),
/// [`BeadVelocity`](crate::BeadVelocity) and
/// [`BeadDiagnostics`](crate::BeadDiagnostics) are avian's (move such a
/// bead through its body's `Position` and `LinearVelocity`; the
/// timeline does not take avian's bodies back). A bead that cannot ride
/// this way is stopped before the step ([`Diverged`](crate::Diverged),
/// its wire invalid) and says why in words: one joined to other beads or
/// with a radius, one on a one-sided, rough or damped wire, one whose
/// wire rides an entity that is no rigid body. Avian sleeps bodies
/// one by one, and a body asleep keeps no velocity: a carrier and each
/// body (or bead) held on its wire are given `SleepingDisabled`, so that
/// neither falls asleep while the other moves and takes the pair's
/// momentum with it.
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Component)]
pub struct WireOnBody(#[entities] pub Entity);

/// Marks a bead of ours on a wire carried by a body (see `WireOnBody`):
/// avian steps it, and the plugin's own step and islands leave it alone.
/// Kept by the avian plugins as beads and wires come and go.
#[derive(Component, Clone, Copy, Debug, Default)]
pub(crate) struct RidingBody;

/// Marks a bead riding a body that has been made a body of avian's, from
/// where it was then: taken off by a restart, which boards it afresh.
#[derive(Component, Clone, Copy, Debug, Default)]
pub(crate) struct Boarded;

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;

    use super::*;
    use crate::geometry::{Friction, Oscillate, Surface, WireMotion};

    #[test]
    fn a_wire_with_no_size_is_refused_in_words() {
        let refused = |wire: Result<Wire, ParamError>| wire.unwrap_err().to_string();
        assert_eq!(
            refused(Wire::circle(0.0)),
            "radius must be positive and finite, got 0"
        );
        assert_eq!(
            refused(Wire::ellipse(1.0, -1.0)),
            "semi-axis b must be positive and finite, got -1"
        );
        assert_eq!(
            refused(Wire::sine(f64::NAN, 1.0)),
            "amplitude must be finite, got NaN"
        );
    }

    #[test]
    fn bad_surfaces_and_motions_are_refused_in_words() {
        let shake = |amplitude, frequency| {
            PrescribedMotion::new(WireMotion::Oscillate(Oscillate {
                amplitude,
                frequency,
            }))
            .unwrap_err()
            .to_string()
        };
        assert_eq!(
            shake(DVec2::new(f64::NAN, 0.0), 1.0),
            "oscillation amplitude must be finite, got (NaN, 0)"
        );
        assert_eq!(
            shake(DVec2::Y, 0.0),
            "oscillation frequency must be positive and finite, got 0"
        );
        let surface =
            |surface: Surface| Wire::line().with_surface(surface).unwrap_err().to_string();
        assert_eq!(
            surface(Surface {
                restitution: 1.5,
                ..Surface::PLAIN
            }),
            "restitution must be between 0 and 1, got 1.5"
        );
        assert_eq!(
            Friction::new(0.2, 0.5).unwrap_err().to_string(),
            "kinetic friction must not exceed static friction"
        );
        assert_eq!(
            surface(Surface {
                damping: -1.0,
                ..Surface::PLAIN
            }),
            "damping along the wire must be zero or more and finite, got -1"
        );
    }
}
