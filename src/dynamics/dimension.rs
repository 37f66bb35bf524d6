//! [`Dimension`]: the plane's or space's components, so that each system
//! is written once and runs for both.

use bevy::math::{DQuat, DVec2, DVec3};
use bevy::prelude::*;
use bevy::reflect::{GetTypeRegistration, Typed};

use super::PrescribedMotion;
use super::wire::{WirePlace, WirePose};
use super::{Bead, BeadBundle, BeadParams, SimParams, SpaceBead, SpaceBeadBundle, SpaceWire, Wire};
use crate::geometry::{Placement, Pose, Pose3, SpaceShape, Surface, WirePath, WireSpace};
use crate::validate::ParamError;

/// The plane (`DVec2`) or space (`DVec3`) as the plugin keeps them: which
/// components a bead and a wire of that dimension have, and how a wire's
/// `Transform` and a bead's position meet the solver's `f64` values.
/// Implemented for those two only.
pub trait Dimension:
    WireSpace + Reflect + FromReflect + TypePath + Typed + GetTypeRegistration
{
    /// The bead's marker: [`Bead`] or [`SpaceBead`].
    type Bead: Component;
    /// Every component of a bead, as [`Dimension::bead`] makes them.
    type BeadBundle: Bundle;
    /// The wire: [`Wire`] or [`SpaceWire`].
    type Wire: Component + WireRows<Self>;
    /// The unit axes: a pin is a row along each.
    const AXES: &'static [Self];
    /// Gravity in these coordinates.
    fn gravity(params: &SimParams) -> Self;
    /// A bead at its initial state, if its parameters are valid
    /// ([`Bead::new`] or [`SpaceBead::new`]).
    fn bead(params: BeadParams<Self>) -> Result<Self::BeadBundle, ParamError>;
    /// A wire's pose from its `Transform`: in the plane its translation's
    /// x and y and its turn about z; in space all of it.
    fn pose_of(transform: &Transform) -> Result<Self::Pose, ParamError>;
    /// Writes a pose into a `Transform`, in `f32` at this edge.
    fn set_pose(transform: &mut Transform, pose: Self::Pose);
    /// The length of a pose's turn (of `(cos θ, sin θ)` in the plane, of
    /// the quaternion in space; a rotation's is one), and the pose with
    /// its turn divided by that length.
    fn unit_turn(pose: Self::Pose) -> (f64, Self::Pose);
    /// Writes a bead's position into its `Transform`'s translation, in
    /// `f32` at this edge (in the plane, `z` kept); a non-finite position
    /// is not written.
    fn place(transform: &mut Transform, position: Self);
}

/// What a wire component gives an island: the rows it puts on each bead it
/// holds and its surface.
pub trait WireRows<V: WireSpace> {
    /// One row in the plane; one (a surface) or two (a curve) in space.
    fn rows(&self) -> Vec<V::Shape>;
    /// Its surface: one-sided, rough or damped.
    fn surface(&self) -> &Surface;
    /// Whether a bead on it and joined to nothing takes a step of its own
    /// (with the batched step on circles and spheres): on one row, any
    /// wire in the plane and a surface in space. A bead on a curve in
    /// space, two rows, steps as an island of one.
    fn lone(&self) -> bool;
}

impl WireRows<DVec2> for Wire {
    fn rows(&self) -> Vec<crate::geometry::WireShape> {
        vec![self.shape().clone()]
    }
    fn surface(&self) -> &Surface {
        Wire::surface(self)
    }
    fn lone(&self) -> bool {
        true
    }
}

impl WireRows<DVec3> for SpaceWire {
    fn rows(&self) -> Vec<crate::geometry::SpaceRow> {
        self.shape().rows()
    }
    fn surface(&self) -> &Surface {
        SpaceWire::surface(self)
    }
    fn lone(&self) -> bool {
        matches!(self.shape(), SpaceShape::Surface(_))
    }
}

impl Dimension for DVec2 {
    type Bead = Bead;
    type BeadBundle = BeadBundle;
    type Wire = Wire;
    const AXES: &'static [Self] = &[DVec2::X, DVec2::Y];
    fn gravity(params: &SimParams) -> Self {
        params.gravity
    }
    fn bead(params: BeadParams) -> Result<BeadBundle, ParamError> {
        Bead::new(params)
    }
    fn pose_of(transform: &Transform) -> Result<Pose, ParamError> {
        Pose::from_translation_rotation(transform.translation, transform.rotation)
    }
    fn unit_turn(pose: Pose) -> (f64, Pose) {
        let length = pose.rotation.length();
        let rotation = pose.rotation / length;
        (length, Pose { rotation, ..pose })
    }
    fn set_pose(transform: &mut Transform, pose: Pose) {
        let origin = pose.origin.as_vec2();
        if origin.is_finite() && pose.rotation.is_finite() {
            transform.translation.x = origin.x;
            transform.translation.y = origin.y;
            transform.rotation = Quat::from_rotation_z(pose.rotation.to_angle() as f32);
        }
    }
    #[inline(always)]
    fn place(transform: &mut Transform, position: Self) {
        let at = position.as_vec2();
        if at.is_finite() {
            transform.translation.x = at.x;
            transform.translation.y = at.y;
        }
    }
}

impl Dimension for DVec3 {
    type Bead = SpaceBead;
    type BeadBundle = SpaceBeadBundle;
    type Wire = SpaceWire;
    const AXES: &'static [Self] = &[DVec3::X, DVec3::Y, DVec3::Z];
    fn gravity(params: &SimParams) -> Self {
        params.gravity_in_space()
    }
    fn bead(params: BeadParams<DVec3>) -> Result<SpaceBeadBundle, ParamError> {
        SpaceBead::new(params)
    }
    fn pose_of(transform: &Transform) -> Result<Pose3, ParamError> {
        Pose3::from_translation_rotation(transform.translation, transform.rotation)
    }
    fn unit_turn(pose: Pose3) -> (f64, Pose3) {
        let length = pose.rotation.length();
        let rotation = pose.rotation / length;
        (length, Pose3 { rotation, ..pose })
    }
    fn set_pose(transform: &mut Transform, pose: Pose3) {
        let origin = pose.origin.as_vec3();
        let rotation: DQuat = pose.rotation;
        if origin.is_finite() && rotation.is_finite() {
            transform.translation = origin;
            transform.rotation = rotation.as_quat();
        }
    }
    #[inline(always)]
    fn place(transform: &mut Transform, position: Self) {
        let at = position.as_vec3();
        if at.is_finite() {
            transform.translation = at;
        }
    }
}

impl<V: Dimension> WirePose<V> {
    /// The wire held at `transform`, or none if it is not finite.
    pub(crate) fn from_transform(transform: &Transform) -> Self {
        Self::placed(transform, None)
    }

    /// The wire held where [`wire_pose`] puts it, or none if neither its
    /// place nor its `transform` is finite.
    pub(crate) fn placed(transform: &Transform, place: Option<&WirePlace<V>>) -> Self {
        Self::new(wire_pose(transform, place).ok().map(WirePath::Fixed))
    }
}

/// A wire's pose: its [`WirePlace`] while its `transform` shows that
/// place (as [`Dimension::set_pose`] writes it, in `f32`), else the
/// `transform`'s own; an error if that is not finite.
pub(crate) fn wire_pose<V: Dimension>(
    transform: &Transform,
    place: Option<&WirePlace<V>>,
) -> Result<V::Pose, ParamError> {
    match place.and_then(WirePlace::taken) {
        Some(pose) if shown::<V>(transform, pose) == *transform => Ok(pose),
        _ => V::pose_of(transform),
    }
}

/// `transform` moved to `pose`, in `f32`.
fn shown<V: Dimension>(transform: &Transform, pose: V::Pose) -> Transform {
    let mut shown = *transform;
    V::set_pose(&mut shown, pose);
    shown
}

/// How far the length of a place's turn may be from one: a turn read from
/// a `Transform` (an `f32` rotation, whose length is one to some 1e-7)
/// places a wire; one of length 2 does not.
const TURN_SLACK: f64 = 1e-6;

/// `pose` as a wire's place: its turn made exactly a rotation (divided by
/// its length, which is one to within [`TURN_SLACK`]), or why it places no
/// wire, in words: its origin is not finite, or its turn is no rotation.
pub(crate) fn placement<V: Dimension>(pose: V::Pose) -> Result<V::Pose, ParamError> {
    let origin = pose.origin().xyz();
    if !origin.is_finite() {
        return Err(ParamError::VectorNotFinite {
            name: "a wire place's origin",
            components: format!("({}, {}, {})", origin.x, origin.y, origin.z),
        });
    }
    let (length, turned) = V::unit_turn(pose);
    if (length - 1.0).abs() <= TURN_SLACK {
        Ok(turned)
    } else {
        Err(ParamError::OutOfRange {
            name: "the length of a wire place's turn",
            min: 1.0 - TURN_SLACK,
            max: 1.0 + TURN_SLACK,
            value: length,
        })
    }
}

impl<V: Dimension> WirePlace<V> {
    /// The pose this place puts its wire at ([`placement`]), if it places
    /// one.
    pub(crate) fn taken(&self) -> Option<V::Pose> {
        placement::<V>(self.0).ok()
    }
}

/// A wire put at `at` (a place as [`placement`] takes it): its
/// `transform` written from it and its `pose` there, on its `motion`
/// about it if it has one.
pub(crate) fn put_in_place<V: Dimension>(
    at: V::Pose,
    motion: Option<&PrescribedMotion<V>>,
    transform: &mut Mut<Transform>,
    pose: &mut Mut<WirePose<V>>,
) {
    let moved = shown::<V>(transform, at);
    transform.set_if_neq(moved);
    let placed = match motion {
        Some(motion) => WirePose::on(WirePath::Prescribed {
            base: at,
            motion: motion.motion(),
        }),
        None => WirePose::on(WirePath::Fixed(at)),
    };
    pose.set_if_neq(placed);
}

/// A point in the frame of `transform`, in the world: `offset` placed by
/// the entity's pose (see [`Dimension::pose_of`]); `None` if the
/// transform is not finite.
pub(crate) fn placed_by<V: Dimension>(transform: &Transform, offset: V) -> Option<V> {
    V::pose_of(transform).ok().map(|pose| pose.to_world(offset))
}
