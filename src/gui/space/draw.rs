//! Drawing a scene in space: each wire's polyline or mesh (made once, in
//! its local frame, carried by its `Transform`), beads as spheres, their
//! trails, rods, pins, springs, the constraint force and the drag spring.
//! `f64` becomes `f32` here, at the edge.

use bevy::asset::RenderAssetUsages;
use bevy::camera::visibility::RenderLayers;
use bevy::math::DVec3;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use bevy::render::render_resource::Face;

use super::shapes::{curve_points, fitted_surface_mesh};
use super::{Orbit, SPACE_LAYER, SpaceGizmos};
use crate::controls::Presentation;
use crate::debug_render::{DebugRenderStyle, Riding, carried_transform, force_unit};
use crate::geometry::{Side, SpaceShape};
use crate::gui::bodies::BodyVisual;
use crate::gui::render::{BeadSizes, SceneStyle, Trail};
use crate::{
    BeadDiagnostics, BeadMass, BeadParams, BeadPosition, BeadRadius, Diverged, OnWire, Pin,
    RailOrientation, Rod, SimParams, SpaceBead, SpaceWire, Spring, SpringAnchor, WireContact,
};

/// What the view draws of a wire in space, in its local frame: a curve's
/// points, or the mesh of a surface (on child entities).
#[derive(Component, Clone, Debug)]
pub enum WireDrawing {
    /// A curve's points along it.
    Curve(Vec<Vec3>),
    /// A surface, meshed; its points bound the view.
    Surface(Vec<Vec3>),
}

impl WireDrawing {
    /// The points that bound it.
    fn points(&self) -> &[Vec3] {
        match self {
            Self::Curve(points) | Self::Surface(points) => points,
        }
    }
}

/// Marks a bead in space's visuals as added.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct SpaceBeadVisual;

/// How far from a wire's origin it is drawn: `lengths` of its own length
/// and at least around its beads' starts.
fn reach(lengths: f64, scale: f64, starts: &[DVec3]) -> f64 {
    let beads = starts.iter().map(|p| p.length()).fold(0.0, f64::max);
    (lengths * scale).max(1.3 * beads).max(0.5)
}

/// Draws each new wire in space: traces a curve from where its beads
/// start (or about its origin), meshes a surface in a box about its
/// origin and its beads (two children, one for each side, so a one-sided
/// surface shows its open side in the wire's colour and its closed side
/// darker).
pub fn add_wire_drawings(
    wires: Query<(Entity, &SpaceWire, &Transform), Without<WireDrawing>>,
    beads: Query<(&BeadParams<DVec3>, &OnWire)>,
    style: Res<SceneStyle>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut commands: Commands,
) {
    for (entity, wire, transform) in &wires {
        let inverse = transform.to_matrix().as_dmat4().inverse();
        let starts: Vec<DVec3> = beads
            .iter()
            .filter(|(_, on)| on.0 == entity)
            .map(|(p, _)| inverse.transform_point3(p.initial_position))
            .collect();
        let drawing = match wire.shape() {
            SpaceShape::Curve(curve) => {
                let scale = curve.scale();
                let mut from = starts.clone();
                from.extend(
                    [DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE, DVec3::NEG_X].map(|d| d * scale),
                );
                let points = curve_points(curve.as_ref(), &from, reach(4.0, scale, &starts));
                WireDrawing::Curve(points.iter().map(|p| p.as_vec3()).collect())
            }
            SpaceShape::Surface(surface) => {
                let half = reach(1.3, surface.scale(), &starts);
                let mesh = fitted_surface_mesh(surface.as_ref(), half);
                let points = mesh.positions.iter().map(|&p| Vec3::from(p)).collect();
                let handle = meshes.add(
                    Mesh::new(
                        PrimitiveTopology::TriangleList,
                        RenderAssetUsages::default(),
                    )
                    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, mesh.positions)
                    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, mesh.normals)
                    .with_inserted_indices(Indices::U32(mesh.indices)),
                );
                let open = style.wire.with_alpha(0.35);
                let closed = style.hatch.darker(0.2).with_alpha(0.55);
                let (positive, negative) = match wire.surface().side {
                    Side::Both => (open, open),
                    Side::Positive => (open, closed),
                    Side::Negative => (closed, open),
                };
                // Front faces look at the positive side.
                for (colour, cull) in [(positive, Face::Back), (negative, Face::Front)] {
                    let material = materials.add(StandardMaterial {
                        base_color: colour,
                        alpha_mode: AlphaMode::Blend,
                        cull_mode: Some(cull),
                        perceptual_roughness: 0.8,
                        ..default()
                    });
                    commands.spawn((
                        Mesh3d(handle.clone()),
                        MeshMaterial3d(material),
                        Transform::default(),
                        Pickable::IGNORE,
                        RenderLayers::layer(SPACE_LAYER),
                        ChildOf(entity),
                    ));
                }
                WireDrawing::Surface(points)
            }
        };
        commands
            .entity(entity)
            .insert((drawing, Visibility::default()));
    }
}

/// Gives new beads in space a sphere (a cart, a box long along its
/// forward `−z`, where it turns with its rail), a material and a trail.
pub fn add_bead_visuals(
    beads: Query<(Entity, Has<RailOrientation>), (With<SpaceBead>, Without<SpaceBeadVisual>)>,
    style: Res<SceneStyle>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut commands: Commands,
) {
    for (entity, cart) in &beads {
        let mesh = if cart {
            meshes.add(Cuboid::new(1.4, 0.9, 2.4))
        } else {
            meshes.add(Sphere::new(1.0).mesh().uv(24, 12))
        };
        commands.entity(entity).insert((
            Mesh3d(mesh),
            MeshMaterial3d(materials.add(StandardMaterial {
                base_color: style.bead,
                perceptual_roughness: 0.5,
                ..default()
            })),
            Visibility::default(),
            RenderLayers::layer(SPACE_LAYER),
            Trail::<Vec3>::default(),
            SpaceBeadVisual,
        ));
    }
}

/// Frames the scene when its wires, beads or bodies change: the camera
/// looks at the middle of everything drawn and every bead's and body's
/// start, from far
/// enough to see it all beside the panel. The turn the user gave it is
/// kept.
pub fn frame_scene(
    added: Query<(), Or<(Added<WireDrawing>, Added<SpaceBead>, Added<BodyVisual>)>>,
    wires: Query<(&WireDrawing, &Transform)>,
    beads: Query<&BeadParams<DVec3>>,
    bodies: Query<&BodyVisual>,
    pins: Query<&Pin<DVec3>>,
    rods: Query<&Rod>,
    on_wire: Query<(), With<OnWire>>,
    transforms: Query<&Transform>,
    windows: Query<&Window>,
    style: Res<SceneStyle>,
    presentation: Option<Res<Presentation>>,
    mut orbit: ResMut<Orbit>,
) {
    let toggled = presentation.as_ref().is_some_and(|p| p.is_changed());
    if added.is_empty() && !toggled {
        return;
    }
    let presenting = presentation.is_some_and(|p| p.0);
    let mut points: Vec<Vec3> = beads.iter().map(|b| b.initial_position.as_vec3()).collect();
    points.extend(
        pins.iter()
            .filter_map(|p| p.locate(&transforms))
            .map(|p| p.as_vec3()),
    );
    points.extend(bodies.iter().flat_map(BodyVisual::bounds));
    for (drawing, transform) in &wires {
        points.extend(
            drawing
                .points()
                .iter()
                .map(|&p| transform.transform_point(p)),
        );
    }
    let points: Vec<Vec3> = points.into_iter().filter(|p| p.is_finite()).collect();
    if points.is_empty() {
        return;
    }
    let (lo, hi) = points
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    // Beads hanging on rods swing out as far as the rods reach: a rod
    // with a bead on no wire widens the view by its length.
    let swing: f32 = rods
        .iter()
        .filter(|rod| rod.beads().iter().any(|b| !on_wire.contains(*b)))
        .map(|rod| rod.length() as f32)
        .sum();
    let (lo, hi) = (lo - Vec3::splat(swing), hi + Vec3::splat(swing));
    let centre = (lo + hi) * 0.5;
    let radius = (0.5 * (hi - lo).length()).max(0.25);
    // Far enough that the sphere round the scene fits the height, and the
    // width left of the panel.
    let (width, height) = windows
        .iter()
        .next()
        .map_or((1280.0, 800.0), |w| (w.width(), w.height()));
    let (right, left) = style.side_widths(presenting, width, height);
    let free = (width - right - left).max(100.0) / height.max(100.0);
    let half_fov = 0.4f32;
    let across = (half_fov.tan() * free).atan();
    orbit.distance = 1.1 * radius / half_fov.min(across).sin();
    orbit.focus = centre;
    // Half the panel's width, at the focus: the scene sits in the free
    // part of the window.
    orbit.shift = (right - left) * half_fov.tan() / height.max(100.0);
    orbit.size = radius;
}

/// Sizes each bead in space to the scene, no wider than 40 % of the
/// shortest rod it hangs on (a bead with a radius at its radius), and
/// colours it: diverged, in flight, or on its wire.
pub fn size_and_colour_beads(
    orbit: Res<Orbit>,
    style: Res<SceneStyle>,
    rods: Query<&Rod>,
    radii: Query<&BeadRadius>,
    mut beads: Query<
        (
            Entity,
            &mut Transform,
            &MeshMaterial3d<StandardMaterial>,
            Has<Diverged>,
            Option<&WireContact>,
            Option<&BeadRadius>,
        ),
        With<SpaceBead>,
    >,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let radius = 1.6 * style.bead_radius * orbit.size;
    let limits = BeadSizes::new(&rods, radii.iter());
    for (entity, mut transform, material, diverged, contact, own) in &mut beads {
        let r = limits.drawn(entity, own, radius);
        if transform.scale != Vec3::splat(r) {
            transform.scale = Vec3::splat(r);
        }
        let colour = style.bead_colour(diverged, contact);
        if let Some(mut m) = materials.get_mut(&material.0)
            && m.base_color != colour
        {
            m.base_color = colour;
        }
    }
}

/// Draws each curve in space where its `Transform` puts it now (in the
/// frame of the body it rides, if it rides one).
pub fn draw_wires(
    wires: Query<(&WireDrawing, &Transform, Riding)>,
    bodies: Query<&Transform>,
    style: Res<SceneStyle>,
    mut gizmos: Gizmos<SpaceGizmos>,
) {
    for (drawing, transform, riding) in &wires {
        if let WireDrawing::Curve(points) = drawing {
            let placed = carried_transform(transform, riding, &bodies);
            gizmos.linestrip(
                points.iter().map(|&p| placed.transform_point(p)),
                style.wire,
            );
        }
    }
}

/// Draws rods as lines, pins as small crosses, springs as thin lines,
/// the constraint force on each bead on a wire as an arrow (in units of
/// its weight) where the scene has few enough beads
/// ([`DebugRenderStyle::draws_force_arrows`]), and the drag spring.
pub fn draw_links(
    beads: Query<(
        &BeadPosition<DVec3>,
        &BeadMass,
        Option<&BeadDiagnostics<DVec3>>,
        Option<&SpringAnchor<DVec3>>,
        Has<OnWire>,
    )>,
    rods: Query<&Rod>,
    pins: Query<&Pin<DVec3>>,
    springs: Query<&Spring>,
    transforms: Query<&Transform>,
    params: Res<SimParams>,
    orbit: Res<Orbit>,
    (style, debug): (Res<SceneStyle>, Res<DebugRenderStyle>),
    mut gizmos: Gizmos<SpaceGizmos>,
) {
    let at = |e: Entity| beads.get(e).ok().map(|b| b.0.0.as_vec3());
    for rod in &rods {
        if let (Some(a), Some(b)) = (at(rod.beads()[0]), at(rod.beads()[1])) {
            gizmos.line(a, b, style.rod);
        }
    }
    let side = 0.05 * orbit.size;
    for pin in pins.iter().filter_map(|pin| pin.locate(&transforms)) {
        let p = pin.as_vec3();
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            gizmos.line(p - axis * side, p + axis * side, style.pin);
        }
    }
    for spring in &springs {
        if let (Some(a), Some(b)) = (at(spring.beads()[0]), at(spring.beads()[1])) {
            gizmos.line(a, b, style.spring);
        }
    }
    let g = params.gravity_in_space().length();
    let scale = 2.0 * style.force_scale * orbit.size;
    let largest = beads
        .iter()
        .filter_map(|(_, _, d, _, on_wire)| d.filter(|_| on_wire))
        .map(|d| d.constraint_force.length())
        .fold(0.0, f64::max);
    let arrows = debug.draws_force_arrows(beads.iter().len());
    for (bead, mass, diagnostics, drag, on_wire) in &beads {
        let p = bead.0.as_vec3();
        let force = diagnostics
            .filter(|_| on_wire && arrows)
            .map_or(Vec3::ZERO, |d| d.constraint_force.as_vec3())
            * (scale * force_unit(g, mass.get(), largest));
        if force.is_finite() && force.length() > 1e-3 * scale {
            gizmos.arrow(p, p + force, style.constraint_force);
        }
        if let Some(target) = drag {
            gizmos.line(p, target.get().as_vec3(), style.drag);
        }
    }
}

/// Appends each bead in space's position to its trail and drops what is
/// too old.
pub fn record_trails(
    params: Res<SimParams>,
    style: Res<SceneStyle>,
    clock: Res<crate::SimClock>,
    mut beads: Query<(&BeadPosition<DVec3>, &mut Trail<Vec3>, Option<&WireContact>)>,
) {
    let keep = style.trail_points(params.timestep);
    for (bead, mut trail, contact) in &mut beads {
        let flying = contact.is_some_and(|c| !c.is_on());
        trail.record(bead.0.as_vec3(), flying, clock.time, keep);
    }
}

/// Draws each trail fading with age, in the flight colour where the bead
/// was off its wire.
pub fn draw_trails(
    beads: Query<&Trail<Vec3>>,
    style: Res<SceneStyle>,
    clock: Res<crate::SimClock>,
    mut gizmos: Gizmos<SpaceGizmos>,
) {
    for trail in &beads {
        gizmos.linestrip_gradient(trail.coloured(&style, clock.time));
    }
}
