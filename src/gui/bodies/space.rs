//! avian3d's bodies in the 3D view: solid shapes the mouse drags.

// Avian's numbers are `f32` or `f64` as the game builds it.
#![allow(clippy::unnecessary_cast)]

use avian3d::math::{AdjustPrecision, AsF32};
use avian3d::prelude::*;
use bevy::camera::visibility::RenderLayers;
use bevy::math::DVec3;
use bevy::prelude::*;

use super::{BodyVisual, capsule_placement};
use crate::avian3d::{rotation_of, vector_of};
use crate::gui::drag::Grabbed;
use crate::gui::render::SceneStyle;
use crate::gui::space::{SPACE_LAYER, SpaceCameras, drag_target};
use crate::{GrabPoint, SimParams, SpringAnchor, WireBeadSystems};

pub(super) fn build(app: &mut App) {
    app.add_systems(
        PreUpdate,
        follow_gravity
            .after(WireBeadSystems::Restart)
            .run_if(resource_changed::<SimParams>),
    )
    .add_systems(Update, add_body_visuals)
    .add_observer(start_drag)
    .add_observer(follow_drag);
}

/// The mesh of a collider's shape about the body's origin, and how far
/// it reaches from it; `None` for a shape other than a box, a ball or a
/// capsule.
fn shape_mesh(collider: &Collider) -> Option<(Mesh, f32)> {
    let shape = collider.shape_scaled();
    if let Some(cuboid) = shape.as_cuboid() {
        let half = cuboid.half_extents.f32();
        return Some((Cuboid::from_size(2.0 * half).into(), half.length()));
    }
    if let Some(ball) = shape.as_ball() {
        let radius = ball.radius as f32;
        return Some((Sphere::new(radius).mesh().uv(32, 16), radius));
    }
    let capsule = shape.as_capsule()?;
    let radius = capsule.radius as f32;
    let (a, b) = (capsule.segment.a.f32(), capsule.segment.b.f32());
    let (middle, axis, length, reach) = capsule_placement((a, b), radius, Vec3::Y);
    let mesh = Mesh::from(Capsule3d::new(radius, length))
        .rotated_by(Quat::from_rotation_arc(Vec3::Y, axis))
        .translated_by(middle);
    Some((mesh, reach))
}

/// Gives each new body with a drawable collider its solid shape in the
/// 3D view.
fn add_body_visuals(
    bodies: Query<(Entity, &Collider, &RigidBody, &Position), Without<BodyVisual>>,
    style: Res<SceneStyle>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut commands: Commands,
) {
    for (entity, collider, kind, position) in &bodies {
        let Some((mesh, reach)) = shape_mesh(collider) else {
            continue;
        };
        let colour = style.body_colour(kind.is_dynamic());
        commands.entity(entity).insert((
            Mesh3d(meshes.add(mesh)),
            MeshMaterial3d(materials.add(StandardMaterial {
                base_color: colour,
                perceptual_roughness: 0.6,
                ..default()
            })),
            RenderLayers::layer(SPACE_LAYER),
            BodyVisual {
                start: position.0.f32(),
                reach,
            },
        ));
    }
}

/// The point of a body, `local` in its frame, in the world.
fn world_point(position: &Position, rotation: &Rotation, local: DVec3) -> DVec3 {
    vector_of(position.0) + rotation_of(rotation.0) * local
}

/// Takes hold of the dynamic body whose shape the press landed on, at
/// the point it landed: a spring from the pointer, on the plane through
/// that point facing the camera, pulls it.
fn start_drag(
    event: On<Pointer<DragStart>>,
    bodies: Query<(&Position, &Rotation, &RigidBody), With<BodyVisual>>,
    cameras: SpaceCameras,
    mut grabbed: ResMut<Grabbed>,
    mut commands: Commands,
) {
    if event.event.button != PointerButton::Primary || grabbed.0.is_some() {
        return;
    }
    let body = event.entity;
    let (Ok((position, rotation, kind)), Some(at)) = (bodies.get(body), event.event.hit.position)
    else {
        return;
    };
    let Some(camera) = cameras.iter().next() else {
        return;
    };
    if !kind.is_dynamic() {
        return;
    }
    let at = at.as_dvec3();
    let origin = world_point(position, rotation, DVec3::ZERO);
    let turn = rotation_of(rotation.0);
    let (Ok(grab), Some(target)) = (
        GrabPoint::new(turn.inverse() * (at - origin)),
        drag_target(camera, event.pointer_location.position, at),
    ) else {
        return;
    };
    grabbed.0 = Some(body);
    commands.entity(body).insert((target, grab));
}

/// Moves the spring's anchor of the body being dragged with the pointer,
/// on the plane through the point taken facing the camera.
fn follow_drag(
    event: On<Pointer<Drag>>,
    cameras: SpaceCameras,
    grabbed: Res<Grabbed>,
    mut bodies: Query<(
        &Position,
        &Rotation,
        &GrabPoint<DVec3>,
        &mut SpringAnchor<DVec3>,
    )>,
) {
    let Some(body) = grabbed.0 else { return };
    let (Ok((position, rotation, grab, mut target)), Some(camera)) =
        (bodies.get_mut(body), cameras.iter().next())
    else {
        return;
    };
    let at = world_point(position, rotation, grab.get());
    if let Some(next) = drag_target(camera, event.pointer_location.position, at) {
        *target = next;
    }
}

/// Gives avian3d the gravity the panel set (applied when the run starts
/// again), so that bodies fall as beads do.
fn follow_gravity(params: Res<SimParams>, mut gravity: ResMut<Gravity>) {
    gravity.0 = params.gravity_in_space().adjust_precision();
}

#[cfg(test)]
mod tests {
    use avian3d::math::Vector;
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
        app.world_mut().resource_mut::<SimParams>().gravity_z = 2.0;
        app.update();
        assert_eq!(
            app.world().resource::<Gravity>().0,
            Vector::new(1.0, -3.0, 2.0)
        );
    }
}
