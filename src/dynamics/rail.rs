//! [`RailOrientation`]: a bead on a curve in space that turns with its
//! track, as a cart on a rail does.

use bevy::math::{DQuat, DVec3};
use bevy::prelude::*;

use crate::geometry::{Pose3, SpaceCurve};
use crate::validate::{ParamError, finite_vector};

/// Turns a bead in space on a curve (a [`SpaceWire::curve`](crate::SpaceWire::curve))
/// with its track: each step the plugin writes the bead's `Transform`
/// rotation so that a model's forward (Bevy's `−z`) runs along the
/// curve's tangent (the way its parameter grows) and its up (`+y`) along
/// the curve's rotation-minimizing normal, rolled once, where the bead
/// starts, as near `up` as it goes. A cart so turned stays upright on a
/// flat turn, leans with a banked one and goes upside down through a loop.
/// Opt-in per bead; a bead on a surface or on no wire is left as it is.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct RailOrientation {
    up: DVec3,
    /// The roll about the tangent, fixed where the bead starts (NaN until
    /// then).
    roll: f64,
    /// The curve's parameter where the bead was: the branch it is on.
    along: f64,
    /// The last rotation, in `f64`.
    rotation: DQuat,
}

impl RailOrientation {
    /// Turning with the track, up as near `up` as the track allows, if
    /// `up` is finite and not zero.
    pub fn new(up: DVec3) -> Result<Self, ParamError> {
        finite_vector("rail up", up)?;
        if up == DVec3::ZERO {
            return Err(ParamError::Incompatible("a rail's up must not be zero"));
        }
        Ok(Self {
            up,
            roll: f64::NAN,
            along: f64::NAN,
            rotation: DQuat::IDENTITY,
        })
    }

    /// The up it was asked for.
    pub fn up(&self) -> DVec3 {
        self.up
    }

    /// The rotation the last step gave the bead, in `f64` (its
    /// `Transform` holds it in `f32`).
    pub fn rotation(&self) -> DQuat {
        self.rotation
    }

    /// The rotation of a bead at `x` on `curve` placed by `pose`; none
    /// where the curve has no frame there (a singular point). The roll is
    /// fixed the first time, where the bead started: `start()` gives the
    /// curve's pose then and the bead's position.
    pub(crate) fn orient(
        &mut self,
        curve: &(dyn SpaceCurve + Send + Sync),
        pose: &Pose3,
        x: DVec3,
        start: impl FnOnce() -> (Pose3, DVec3),
    ) -> Option<DQuat> {
        let local = pose.to_local(x);
        let frame = curve.frame(local, self.along);
        if frame.tangent == DVec3::ZERO || frame.normal == DVec3::ZERO {
            return None;
        }
        if self.roll.is_nan() {
            let (start_pose, start) = start();
            let at = curve.frame(start_pose.to_local(start), self.along);
            self.roll = at.roll_toward(start_pose.rotation.inverse() * self.up);
        }
        self.along = curve.parameter(local, self.along);
        let rotation = pose.rotation * frame.rolled(self.roll).rotation();
        rotation.is_finite().then(|| {
            self.rotation = rotation;
            rotation
        })
    }

    /// Forgets the roll and the branch: a restart fixes them again where
    /// the bead starts.
    pub(crate) fn restart(&mut self) {
        self.roll = f64::NAN;
        self.along = f64::NAN;
    }
}
