//! [`Pose`] places a shape in the plane and [`Pose3`] in space;
//! [`Placed`] and [`PlacedSurface`] evaluate it there, by one formula
//! (`placed_geometry`): `C_w(x) = C(Rᵀ(x − o))`, `∇C_w = R ∇C`,
//! `H_w = R H Rᵀ`.

use bevy::math::{DMat2, DMat3, DQuat, DVec2, DVec3, Quat, Vec3};

use super::{Coordinates, Geometry, ImplicitCurve, ImplicitSurface};
use crate::validate::ParamError;

/// A rigid placement in the plane ([`Pose`]) or in space ([`Pose3`]):
/// what placing a shape asks of it, `C(Rᵀ(x − o))`, `R ∇C` and `R H Rᵀ`.
pub trait Placement<V: Coordinates> {
    /// The local origin in world coordinates.
    fn origin(&self) -> V;
    /// A world point in the local frame.
    fn to_local(&self, p: V) -> V;
    /// A local point in world coordinates.
    fn to_world(&self, p: V) -> V;
    /// A local direction in world coordinates.
    fn rotate(&self, d: V) -> V;
    /// A local Hessian in world coordinates: `R H Rᵀ`.
    fn rotate_hessian(&self, h: &V::Hessian) -> V::Hessian;
    /// Whether the placement only translates (the rotation is exactly
    /// none).
    fn is_unrotated(&self) -> bool;
}

/// The geometry at the world point `p` of a shape whose geometry in its
/// local frame is `local`, placed by `pose`: `C(Rᵀ(p − o))`, `R ∇C`,
/// `R H Rᵀ`; an unrotated placement only translates.
#[inline(always)]
pub(crate) fn placed_geometry<V: Coordinates>(
    pose: &impl Placement<V>,
    p: V,
    local: impl Fn(V) -> Geometry<V>,
) -> Geometry<V> {
    if pose.is_unrotated() {
        // The common case needs no rotation, only the translation.
        local(p - pose.origin())
    } else {
        rotated_geometry(pose, p, local)
    }
}

/// [`placed_geometry`] with a rotation, kept out of the common path.
#[inline(never)]
fn rotated_geometry<V: Coordinates>(
    pose: &impl Placement<V>,
    p: V,
    local: impl Fn(V) -> Geometry<V>,
) -> Geometry<V> {
    let g = local(pose.to_local(p));
    Geometry {
        c: g.c,
        normal: pose.rotate(g.normal),
        hessian: pose.rotate_hessian(&g.hessian),
    }
}

/// Where a wire sits in the plane: a translation and a rotation, in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// The local origin in world coordinates.
    pub origin: DVec2,
    /// `(cos θ, sin θ)` of the rotation from local to world.
    pub rotation: DVec2,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    /// No translation, no rotation.
    pub const IDENTITY: Self = Self {
        origin: DVec2::ZERO,
        rotation: DVec2::X,
    };

    /// A pose from an origin and a rotation angle in radians.
    pub fn new(origin: DVec2, angle: f64) -> Self {
        Self {
            origin,
            rotation: DVec2::from_angle(angle),
        }
    }

    /// The in-plane part of a 3D placement (a `Transform`'s translation and
    /// rotation): the translation's x and y and the rotation about z.
    /// Returns an error if either is not finite.
    pub fn from_translation_rotation(
        translation: Vec3,
        rotation: Quat,
    ) -> Result<Self, ParamError> {
        let axis = rotation * Vec3::X;
        let origin = DVec2::new(f64::from(translation.x), f64::from(translation.y));
        let rotation = DVec2::new(f64::from(axis.x), f64::from(axis.y));
        if !origin.is_finite() || !rotation.is_finite() || rotation.length_squared() == 0.0 {
            return Err(not_placeable());
        }
        Ok(Self {
            origin,
            rotation: rotation.normalize(),
        })
    }

    fn matrix(&self) -> DMat2 {
        let (c, s) = (self.rotation.x, self.rotation.y);
        DMat2::from_cols(DVec2::new(c, s), DVec2::new(-s, c))
    }

    /// A world point in the local frame.
    pub fn to_local(&self, p: DVec2) -> DVec2 {
        self.matrix().transpose() * (p - self.origin)
    }

    /// A local point in world coordinates.
    pub fn to_world(&self, p: DVec2) -> DVec2 {
        self.origin + self.matrix() * p
    }

    /// Whether the pose only translates (the rotation is exactly none).
    pub fn is_unrotated(&self) -> bool {
        self.rotation == DVec2::X
    }

    /// A local direction in world coordinates.
    pub fn rotate(&self, d: DVec2) -> DVec2 {
        self.matrix() * d
    }

    /// The pose in world coordinates of `inner`, a pose in this one's
    /// frame (a wire placed on a body that sits at `self`).
    pub fn compose(&self, inner: &Pose) -> Pose {
        Pose {
            origin: self.to_world(inner.origin),
            rotation: self.rotate(inner.rotation),
        }
    }
}

impl Placement<DVec2> for Pose {
    fn origin(&self) -> DVec2 {
        self.origin
    }
    fn to_local(&self, p: DVec2) -> DVec2 {
        Pose::to_local(self, p)
    }
    fn to_world(&self, p: DVec2) -> DVec2 {
        Pose::to_world(self, p)
    }
    fn rotate(&self, d: DVec2) -> DVec2 {
        Pose::rotate(self, d)
    }
    fn rotate_hessian(&self, h: &DMat2) -> DMat2 {
        let r = self.matrix();
        r * *h * r.transpose()
    }
    fn is_unrotated(&self) -> bool {
        Pose::is_unrotated(self)
    }
}

/// Where a wire sits in space: a translation and a rotation, in `f64`.
/// Planar shapes lie in the local xy-plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose3 {
    /// The local origin in world coordinates.
    pub origin: DVec3,
    /// The rotation from local to world (a unit quaternion).
    pub rotation: DQuat,
}

impl Default for Pose3 {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// A `Transform` that places no wire: not finite.
pub(crate) fn not_placeable() -> ParamError {
    ParamError::NotFinite {
        name: "wire transform",
        value: f64::NAN,
    }
}

impl Pose3 {
    /// No translation, no rotation.
    pub const IDENTITY: Self = Self {
        origin: DVec3::ZERO,
        rotation: DQuat::IDENTITY,
    };

    /// A 3D placement (a `Transform`'s translation and rotation), the
    /// rotation normalized. Returns an error if either is not finite.
    pub fn from_translation_rotation(
        translation: Vec3,
        rotation: Quat,
    ) -> Result<Self, ParamError> {
        let origin = translation.as_dvec3();
        let rotation = rotation.as_dquat();
        if !origin.is_finite() || !rotation.is_finite() || rotation.length_squared() == 0.0 {
            return Err(not_placeable());
        }
        Ok(Self {
            origin,
            rotation: rotation.normalize(),
        })
    }

    /// A pose turned right-handed by `angle` radians about `axis` (any
    /// length but zero) through `origin`. Returns an error if the axis is
    /// zero or anything is not finite.
    pub fn from_axis_angle(origin: DVec3, axis: DVec3, angle: f64) -> Result<Self, ParamError> {
        let finite = origin.is_finite() && axis.is_finite() && angle.is_finite();
        if !finite {
            return Err(ParamError::NotFinite {
                name: "wire pose",
                value: f64::NAN,
            });
        }
        let length = axis.length();
        if length == 0.0 {
            return Err(ParamError::NotPositive {
                name: "rotation axis length",
                value: 0.0,
            });
        }
        Ok(Self {
            origin,
            rotation: DQuat::from_axis_angle(axis / length, angle),
        })
    }

    /// The rotation as a matrix.
    pub fn matrix(&self) -> DMat3 {
        DMat3::from_quat(self.rotation)
    }

    /// A world point in the local frame.
    pub fn to_local(&self, p: DVec3) -> DVec3 {
        self.matrix().transpose() * (p - self.origin)
    }

    /// A local point in world coordinates.
    pub fn to_world(&self, p: DVec3) -> DVec3 {
        self.origin + self.matrix() * p
    }

    /// A local direction in world coordinates.
    pub fn rotate(&self, d: DVec3) -> DVec3 {
        self.matrix() * d
    }

    /// The pose in world coordinates of `inner`, a pose in this one's
    /// frame (a wire placed on a body that sits at `self`).
    pub fn compose(&self, inner: &Pose3) -> Pose3 {
        Pose3 {
            origin: self.to_world(inner.origin),
            rotation: (self.rotation * inner.rotation).normalize(),
        }
    }
}

impl Placement<DVec3> for Pose3 {
    fn origin(&self) -> DVec3 {
        self.origin
    }
    fn to_local(&self, p: DVec3) -> DVec3 {
        Pose3::to_local(self, p)
    }
    fn to_world(&self, p: DVec3) -> DVec3 {
        Pose3::to_world(self, p)
    }
    fn rotate(&self, d: DVec3) -> DVec3 {
        Pose3::rotate(self, d)
    }
    fn rotate_hessian(&self, h: &DMat3) -> DMat3 {
        let r = self.matrix();
        r * *h * r.transpose()
    }
    fn is_unrotated(&self) -> bool {
        self.rotation == DQuat::IDENTITY
    }
}

/// A surface placed in space by a [`Pose3`]: itself an
/// [`ImplicitSurface`] in world coordinates.
pub struct PlacedSurface<'a, S: ImplicitSurface + ?Sized = dyn ImplicitSurface + 'a> {
    /// The surface in its local frame.
    pub surface: &'a S,
    /// Where it sits.
    pub pose: Pose3,
}

impl<S: ImplicitSurface + ?Sized> ImplicitSurface for PlacedSurface<'_, S> {
    fn value(&self, p: DVec3) -> f64 {
        self.surface.value(self.pose.to_local(p))
    }
    fn gradient(&self, p: DVec3) -> DVec3 {
        self.pose
            .rotate(self.surface.gradient(self.pose.to_local(p)))
    }
    fn hessian(&self, p: DVec3) -> DMat3 {
        self.pose
            .rotate_hessian(&self.surface.hessian(self.pose.to_local(p)))
    }
    fn scale(&self) -> f64 {
        self.surface.scale()
    }
    #[inline(always)]
    fn geometry(&self, p: DVec3) -> Geometry<DVec3> {
        placed_geometry(&self.pose, p, |local| self.surface.geometry(local))
    }
}

/// A curve placed in the world by a [`Pose`]: itself an [`ImplicitCurve`] in
/// world coordinates. `C` is the curve's type: `dyn ImplicitCurve` by
/// default, or a concrete shape so the step's loops inline it.
pub struct Placed<'a, C: ImplicitCurve + ?Sized = dyn ImplicitCurve + 'a> {
    /// The curve in its local frame.
    pub curve: &'a C,
    /// Where it sits.
    pub pose: Pose,
}

impl<C: ImplicitCurve + ?Sized> Clone for Placed<'_, C> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<C: ImplicitCurve + ?Sized> Copy for Placed<'_, C> {}

impl<C: ImplicitCurve + ?Sized> ImplicitCurve for Placed<'_, C> {
    fn value(&self, p: DVec2) -> f64 {
        self.curve.value(self.pose.to_local(p))
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.pose.rotate(self.curve.gradient(self.pose.to_local(p)))
    }
    fn hessian(&self, p: DVec2) -> DMat2 {
        self.pose
            .rotate_hessian(&self.curve.hessian(self.pose.to_local(p)))
    }
    fn scale(&self) -> f64 {
        self.curve.scale()
    }
    fn has_ends(&self) -> bool {
        self.curve.has_ends()
    }
    fn travel(&self) -> f64 {
        self.curve.travel()
    }
    fn past_end(&self, p: DVec2) -> f64 {
        self.curve.past_end(self.pose.to_local(p))
    }
    #[inline(always)]
    fn geometry(&self, p: DVec2) -> Geometry {
        placed_geometry(&self.pose, p, |local| self.curve.geometry(local))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn pose_round_trips() {
        let pose = Pose::new(DVec2::new(2.0, -3.0), 1.1);
        let p = DVec2::new(0.25, 4.5);
        let back = pose.to_world(pose.to_local(p));
        assert_relative_eq!(back.x, p.x, epsilon = 1e-14);
        assert_relative_eq!(back.y, p.y, epsilon = 1e-14);
    }
}
