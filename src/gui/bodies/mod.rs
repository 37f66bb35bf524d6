//! Rigid bodies in the window (features `gui` with `avian2d` or
//! `avian3d`): each body whose collider is a box, a ball or a capsule is
//! drawn filled (in the plane) or solid (in the 3D view), a dynamic body in
//! [`SceneStyle::body`](super::SceneStyle::body) and a static or kinematic
//! one in [`SceneStyle::fixed_body`](super::SceneStyle::fixed_body). The
//! mouse drags a dynamic body by the point it took: a [`SpringAnchor`]
//! at the cursor and a [`GrabPoint`] where the press landed, so that the
//! body turns as well as moves; letting go lets go.
//!
//! [`SpringAnchor`]: crate::SpringAnchor
//! [`GrabPoint`]: crate::GrabPoint

use bevy::math::NormedVectorSpace;
use bevy::prelude::*;

#[cfg(feature = "avian2d")]
mod plane;
#[cfg(feature = "avian3d")]
mod space;

/// A rigid body drawn: where it was when first drawn and how far it
/// reaches from its origin, for framing the view.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct BodyVisual {
    /// Its origin when first drawn.
    pub start: Vec3,
    /// The farthest point of its shape from its origin.
    pub reach: f32,
}

impl BodyVisual {
    /// The corners of the box round it at its start.
    pub fn bounds(&self) -> [Vec3; 2] {
        [
            self.start - Vec3::splat(self.reach),
            self.start + Vec3::splat(self.reach),
        ]
    }
}

/// A capsule collider's segment `a`–`b` with its `radius`, as a mesh
/// along `+y` must be placed: its middle, its axis (unit; `up` where the
/// segment is a point), its length, and how far the capsule reaches from
/// the body's origin.
#[cfg_attr(not(any(feature = "avian2d", feature = "avian3d")), allow(dead_code))]
fn capsule_placement<V: NormedVectorSpace<Scalar = f32>>(
    (a, b): (V, V),
    radius: f32,
    up: V,
) -> (V, V, f32, f32) {
    let length = (b - a).norm();
    let axis = if length > 0.0 { (b - a) / length } else { up };
    let reach = a.norm().max(b.norm()) + radius;
    ((a + b) * 0.5, axis, length, reach)
}

/// Draws and drags the bodies of each avian the build has and the app
/// runs (its `PhysicsPlugins` added, before or after this plugin).
#[derive(Default)]
pub struct BodyViewPlugin;

impl Plugin for BodyViewPlugin {
    fn build(&self, _app: &mut App) {}

    fn finish(&self, _app: &mut App) {
        #[cfg(feature = "avian2d")]
        if _app
            .world()
            .contains_resource::<Time<avian2d::prelude::Physics>>()
        {
            plane::build(_app);
        }
        #[cfg(feature = "avian3d")]
        if _app
            .world()
            .contains_resource::<Time<avian3d::prelude::Physics>>()
        {
            space::build(_app);
        }
    }
}
