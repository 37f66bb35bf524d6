//! [`Pose`] places a shape in the plane; [`Placed`] evaluates it there.

use bevy::math::{DMat2, DVec2, Quat, Vec3};

use super::{Geometry, ImplicitCurve};
use crate::validate::ParamError;

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
            return Err(ParamError::NotFinite {
                name: "wire transform",
                value: f64::NAN,
            });
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
        let r = self.pose.matrix();
        r * self.curve.hessian(self.pose.to_local(p)) * r.transpose()
    }
    fn scale(&self) -> f64 {
        self.curve.scale()
    }
    fn has_ends(&self) -> bool {
        self.curve.has_ends()
    }
    fn past_end(&self, p: DVec2) -> f64 {
        self.curve.past_end(self.pose.to_local(p))
    }
    #[inline(always)]
    fn geometry(&self, p: DVec2) -> Geometry {
        if self.pose.is_unrotated() {
            // The common case needs no rotation, only the translation.
            self.curve.geometry(p - self.pose.origin)
        } else {
            self.rotated_geometry(p)
        }
    }
}

impl<C: ImplicitCurve + ?Sized> Placed<'_, C> {
    #[inline(never)]
    fn rotated_geometry(&self, p: DVec2) -> Geometry {
        let local = self.curve.geometry(self.pose.to_local(p));
        let r = self.pose.matrix();
        Geometry {
            c: local.c,
            normal: r * local.normal,
            hessian: r * local.hessian * r.transpose(),
        }
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
