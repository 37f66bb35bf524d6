//! avian2d's bodies in the plane's view: filled shapes the mouse drags.

// Avian's numbers are `f32` or `f64` as the game builds it.
#![allow(clippy::unnecessary_cast, clippy::useless_conversion)]

use avian2d::math::{AdjustPrecision, AsF32};
use avian2d::prelude::*;
use bevy::math::DVec2;
use bevy::prelude::*;

use super::{BodyVisual, capsule_placement};
use crate::gui::drag::{Grabbed, SceneCameras, bead_under, cursor_world};
use crate::gui::render::SceneStyle;
use crate::{BeadPosition, GrabPoint, SimParams, WireBeadSystems};

pub(super) fn build(app: &mut App) {
    app.add_systems(
        PreUpdate,
        follow_gravity
            .after(WireBeadSystems::Restart)
            .run_if(resource_changed::<SimParams>),
    )
    .add_systems(Update, add_body_visuals)
    .add_observer(start_drag);
}

/// The mesh of a collider's shape about the body's origin, and how far
/// it reaches from it; `None` for a shape other than a box, a ball or a
/// capsule.
fn shape_mesh(collider: &Collider) -> Option<(Mesh, f32)> {
    let shape = collider.shape_scaled();
    if let Some(cuboid) = shape.as_cuboid() {
        let half = cuboid.half_extents.f32();
        return Some((Rectangle::from_size(2.0 * half).into(), half.length()));
    }
    if let Some(ball) = shape.as_ball() {
        let radius = ball.radius as f32;
        return Some((Circle::new(radius).mesh().resolution(48).into(), radius));
    }
    let capsule = shape.as_capsule()?;
    let radius = capsule.radius as f32;
    let (a, b) = (capsule.segment.a.f32(), capsule.segment.b.f32());
    let (middle, axis, length, reach) = capsule_placement((a, b), radius, Vec2::Y);
    let mesh = Mesh::from(Capsule2d::new(radius, length))
        .rotated_by(Quat::from_rotation_arc_2d(Vec2::Y, axis))
        .translated_by(middle.extend(0.0));
    Some((mesh, reach))
}

/// Gives each new body with a drawable collider its filled shape,
/// under the beads.
fn add_body_visuals(
    bodies: Query<(Entity, &Collider, &RigidBody, &Position), Without<BodyVisual>>,
    style: Res<SceneStyle>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<ColorMaterial>>,
    mut commands: Commands,
) {
    for (entity, collider, kind, position) in &bodies {
        let Some((mesh, reach)) = shape_mesh(collider) else {
            continue;
        };
        let colour = style.body_colour(kind.is_dynamic());
        commands.entity(entity).insert((
            Mesh2d(meshes.add(mesh)),
            MeshMaterial2d(materials.add(ColorMaterial::from_color(colour))),
            BodyVisual {
                start: position.0.f32().extend(0.0),
                reach,
            },
        ));
    }
}

/// Takes hold of the dynamic body the press landed on (its mesh picked,
/// or, where the press missed every mesh and no bead is under it, the
/// body whose collider holds the point): a spring from the cursor pulls
/// the point taken.
#[allow(clippy::too_many_arguments)]
fn start_drag(
    event: On<Pointer<DragStart>>,
    bodies: Query<(&Position, &Rotation, &RigidBody), With<BodyVisual>>,
    beads: Query<(Entity, &BeadPosition, &Transform)>,
    windows: Query<(), With<Window>>,
    cameras: SceneCameras,
    spatial: SpatialQuery,
    mut grabbed: ResMut<Grabbed>,
    mut commands: Commands,
) {
    if event.event.button != PointerButton::Primary || grabbed.0.is_some() {
        return;
    }
    let Some(target) = cursor_world(&event.pointer_location, &cameras) else {
        return;
    };
    let at = target.get();
    let body = if bodies.contains(event.entity) {
        Some(event.entity)
    } else if windows.contains(event.entity) && bead_under(&beads, at).is_none() {
        spatial
            .point_intersections(at.adjust_precision(), &SpatialQueryFilter::default())
            .into_iter()
            .find(|b| bodies.contains(*b))
    } else {
        None
    };
    let Some((body, (position, rotation, kind))) =
        body.and_then(|b| Some((b, bodies.get(b).ok()?)))
    else {
        return;
    };
    if !kind.is_dynamic() {
        return;
    }
    let origin = DVec2::from(position.0);
    let turn = f64::from(rotation.as_radians());
    let local = DVec2::from_angle(-turn).rotate(at - origin);
    let Ok(grab) = GrabPoint::new(local) else {
        return;
    };
    grabbed.0 = Some(body);
    commands.entity(body).insert((target, grab));
}

/// Gives avian2d the gravity the panel set (applied when the run starts
/// again), so that bodies fall as beads do.
fn follow_gravity(params: Res<SimParams>, mut gravity: ResMut<Gravity>) {
    gravity.0 = params.gravity.adjust_precision();
}

#[cfg(test)]
mod tests {
    use avian2d::math::Vector;
    use bevy::math::DVec2;

    use super::*;

    /// A restart that applies the panel's gravity gives it to avian too.
    #[test]
    fn avian_falls_with_the_gravity_the_panel_set() {
        let mut app = App::new();
        app.init_resource::<SimParams>()
            .insert_resource(Gravity(Vector::ZERO))
            .add_systems(Update, follow_gravity.run_if(resource_changed::<SimParams>));
        app.world_mut().resource_mut::<SimParams>().gravity = DVec2::new(1.0, -3.0);
        app.update();
        assert_eq!(app.world().resource::<Gravity>().0, Vector::new(1.0, -3.0));
    }
}
