//! The 3D view (feature `gui`): scenes in space open in a perspective
//! camera that orbits the scene (drag empty space, or anything with a
//! button other than the first, to turn; the wheel to zoom); wires in
//! space are drawn as lines (curves) or translucent meshes (surfaces, the
//! open side of a one-sided one in the wire's colour and the closed side
//! darker), beads as spheres the mouse can drag, with trails, rods, pins,
//! springs and the constraint force `λ∇C` as arrows. Scenes in the plane
//! keep the 2D view.
//!
//! | file | what it holds |
//! |---|---|
//! | `mod` | the plugin, the camera and its orbit, which view is shown |
//! | `draw` | wires, beads, trails, links and forces in space |
//! | `shapes` | a curve traced into a polyline, a surface meshed: plain values |

mod draw;
pub mod shapes;

use bevy::camera::visibility::RenderLayers;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::input::mouse::{AccumulatedMouseScroll, MouseScrollUnit};
use bevy::math::DVec3;
use bevy::prelude::*;
use bevy_egui::input::EguiWantsInput;

use super::drag::Grabbed;
use super::render::{SceneCamera, SceneStyle, clear_trails};
use crate::{SpaceBead, SpaceWire, SpringAnchor};
pub use draw::WireDrawing;

/// The render layer of everything the 3D view draws, so that the plane's
/// camera does not draw it and the space camera draws nothing of the
/// plane's.
pub const SPACE_LAYER: usize = 1;

/// The gizmos of the 3D view: drawn by its camera alone.
#[derive(Default, Reflect, GizmoConfigGroup)]
pub struct SpaceGizmos;

/// The 3D view's camera.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct SpaceCamera;

/// Where the 3D view's camera looks from: it orbits `focus` at `distance`,
/// turned `yaw` about the vertical and tilted `pitch` above the horizon.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// The point it looks at.
    pub focus: Vec3,
    /// Its turn about the vertical, radians.
    pub yaw: f32,
    /// Its tilt above the horizon, radians.
    pub pitch: f32,
    /// Its distance from the focus.
    pub distance: f32,
    /// The radius of the sphere that holds the scene: what the beads and
    /// arrows are sized to.
    pub size: f32,
    /// How far the camera sits to the right of its orbit (and looks to the
    /// right of the focus), as a fraction of its distance, so that the
    /// focus shows left of the panel.
    pub shift: f32,
}

impl Default for Orbit {
    fn default() -> Self {
        Self {
            focus: Vec3::ZERO,
            yaw: 0.5,
            pitch: 0.35,
            distance: 6.0,
            size: 1.0,
            shift: 0.0,
        }
    }
}

impl Orbit {
    /// The camera's transform.
    pub fn transform(&self) -> Transform {
        let turn = Quat::from_euler(EulerRot::YXZ, self.yaw, -self.pitch, 0.0);
        let aside = turn * Vec3::X * (self.shift * self.distance);
        Transform::from_translation(self.focus + aside + turn * Vec3::Z * self.distance)
            .looking_at(self.focus + aside, turn * Vec3::Y)
    }
}

/// The 3D view.
#[derive(Default)]
pub struct SpaceViewPlugin;

impl Plugin for SpaceViewPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Orbit>()
            .init_resource::<crate::debug_render::DebugRenderStyle>()
            .init_gizmo_group::<SpaceGizmos>()
            .add_systems(Startup, (spawn_space_camera, style_space_gizmos))
            .add_systems(
                FixedUpdate,
                draw::record_trails.after(crate::WireBeadSystems::Writeback),
            )
            .add_systems(
                Update,
                (
                    show_view,
                    clear_trails::<Vec3>,
                    draw::add_wire_drawings,
                    draw::add_bead_visuals,
                    draw::frame_scene,
                    zoom,
                    draw::size_and_colour_beads,
                    draw::draw_wires,
                    draw::draw_links,
                    draw::draw_trails,
                )
                    .chain(),
            )
            .add_observer(start_drag)
            .add_observer(follow_drag)
            .add_observer(turn);
    }
}

fn spawn_space_camera(mut commands: Commands, style: Res<SceneStyle>, orbit: Res<Orbit>) {
    commands.spawn((
        Camera3d::default(),
        Camera {
            // Below the plane's camera, which draws the panel on top.
            order: -1,
            is_active: false,
            clear_color: ClearColorConfig::Custom(style.background),
            ..default()
        },
        Projection::Perspective(PerspectiveProjection {
            fov: 0.8,
            ..default()
        }),
        Tonemapping::None,
        orbit.transform(),
        SpaceCamera,
        RenderLayers::layer(SPACE_LAYER),
    ));
    commands.spawn((
        DirectionalLight {
            illuminance: 6000.0,
            ..default()
        },
        Transform::from_xyz(3.0, 8.0, 5.0).looking_at(Vec3::ZERO, Vec3::Y),
        RenderLayers::layer(SPACE_LAYER),
    ));
    commands.insert_resource(GlobalAmbientLight {
        brightness: 400.0,
        ..default()
    });
}

fn style_space_gizmos(mut store: ResMut<GizmoConfigStore>) {
    let (config, _) = store.config_mut::<SpaceGizmos>();
    config.line.width = 3.0;
    config.render_layers = RenderLayers::layer(SPACE_LAYER);
}

/// Shows the 3D view while anything is in space: its camera on, and the
/// plane's camera (which also draws the panel) drawing over it without
/// clearing it.
fn show_view(
    in_space: Query<(), Or<(With<SpaceBead>, With<SpaceWire>)>>,
    mut space: Query<&mut Camera, (With<SpaceCamera>, Without<SceneCamera>)>,
    mut plane: Query<&mut Camera, (With<SceneCamera>, Without<SpaceCamera>)>,
) {
    let on = !in_space.is_empty();
    for mut camera in &mut space {
        if camera.is_active != on {
            camera.is_active = on;
        }
    }
    let clear = if on {
        ClearColorConfig::None
    } else {
        ClearColorConfig::Default
    };
    for mut camera in &mut plane {
        if std::mem::discriminant(&camera.clear_color) != std::mem::discriminant(&clear) {
            camera.clear_color = clear;
        }
    }
}

/// Turns the camera with a drag of empty space (any button), or of
/// anything with a button other than the first; the panel takes the
/// pointer over itself, so a drag there turns nothing.
fn turn(
    event: On<Pointer<Drag>>,
    windows: Query<(), With<Window>>,
    grabbed: Res<Grabbed>,
    mut orbit: ResMut<Orbit>,
) {
    let empty = windows.contains(event.entity);
    if grabbed.0.is_none() && (empty || event.event.button != PointerButton::Primary) {
        orbit.yaw -= event.event.delta.x * 0.006;
        orbit.pitch = (orbit.pitch + event.event.delta.y * 0.006).clamp(-1.5, 1.5);
    }
}

/// Zooms with the wheel outside the panel, and puts the camera where the
/// orbit says.
fn zoom(
    scroll: Res<AccumulatedMouseScroll>,
    egui: Option<Res<EguiWantsInput>>,
    mut orbit: ResMut<Orbit>,
    mut cameras: Query<&mut Transform, With<SpaceCamera>>,
) {
    let over_panel = egui.is_some_and(|e| e.wants_any_pointer_input());
    if !over_panel {
        let lines = match scroll.unit {
            MouseScrollUnit::Line => scroll.delta.y,
            MouseScrollUnit::Pixel => scroll.delta.y / 60.0,
        };
        if lines != 0.0 {
            let size = orbit.size;
            orbit.distance = (orbit.distance * 0.9f32.powf(lines)).clamp(0.2 * size, 40.0 * size);
        }
    }
    for mut transform in &mut cameras {
        let wanted = orbit.transform();
        if *transform != wanted {
            *transform = wanted;
        }
    }
}

/// The point on the plane through `bead` facing the camera under the
/// pointer: where the drag spring pulls.
pub(crate) fn drag_target(
    camera: (&Camera, &GlobalTransform),
    pointer: Vec2,
    bead: DVec3,
) -> Option<SpringAnchor<DVec3>> {
    let (camera, transform) = camera;
    let ray = camera.viewport_to_world(transform, pointer).ok()?;
    let facing = InfinitePlane3d::new(transform.forward());
    let at = ray.plane_intersection_point(bead.as_vec3(), facing)?;
    SpringAnchor::new(at.as_dvec3()).ok()
}

/// The 3D view's camera.
pub(crate) type SpaceCameras<'w, 's> =
    Query<'w, 's, (&'static Camera, &'static GlobalTransform), With<SpaceCamera>>;

/// How far `p` lies from the ray.
fn off_ray(ray: Ray3d, p: Vec3) -> f32 {
    let along = (p - ray.origin).dot(*ray.direction).max(0.0);
    p.distance(ray.get_point(along))
}

/// Grabs a bead in space the pointer pressed on: selects it and sets its
/// drag target on the plane through it facing the camera. A press that
/// hit nothing (a small bead, or the press came before the pointer's
/// hover) takes the nearest bead whose drawn sphere the pointer's ray
/// passes through, with some slack.
fn start_drag(
    event: On<Pointer<DragStart>>,
    beads: Query<(Entity, &crate::BeadPosition<DVec3>, &Transform), With<SpaceBead>>,
    windows: Query<(), With<Window>>,
    cameras: SpaceCameras,
    mut grabbed: ResMut<Grabbed>,
    mut selected: ResMut<super::drag::SelectedBead>,
    mut commands: Commands,
) {
    if event.event.button != PointerButton::Primary || grabbed.0.is_some() {
        return;
    }
    let Some((camera, transform)) = cameras.iter().next() else {
        return;
    };
    let pointer = event.pointer_location.position;
    let bead = if beads.contains(event.entity) {
        Some(event.entity)
    } else if windows.contains(event.entity) {
        let Ok(ray) = camera.viewport_to_world(transform, pointer) else {
            return;
        };
        beads
            .iter()
            .map(|(e, b, t)| (e, off_ray(ray, b.0.as_vec3()) / t.scale.x.max(1e-6)))
            .filter(|(_, d)| *d <= 1.5)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(e, _)| e)
    } else {
        None
    };
    let Some((bead, position, _)) = bead.and_then(|b| beads.get(b).ok()) else {
        return;
    };
    let Some(target) = drag_target((camera, transform), pointer, position.0) else {
        return;
    };
    grabbed.0 = Some(bead);
    selected.0 = Some(bead);
    commands.entity(bead).insert(target);
}

/// Moves the drag target of the bead in space being dragged with the
/// pointer.
fn follow_drag(
    event: On<Pointer<Drag>>,
    cameras: SpaceCameras,
    grabbed: Res<Grabbed>,
    mut beads: Query<(&crate::BeadPosition<DVec3>, &mut SpringAnchor<DVec3>)>,
) {
    let Some(bead) = grabbed.0 else { return };
    let (Ok((position, mut target)), Some(camera)) = (beads.get_mut(bead), cameras.iter().next())
    else {
        return;
    };
    if let Some(next) = drag_target(camera, event.pointer_location.position, position.0) {
        *target = next;
    }
}
