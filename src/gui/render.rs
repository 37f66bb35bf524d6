//! Drawing the scene: a camera that frames the wires, wires as gizmo
//! strokes, beads as meshes, fading trails, and force arrows. Simulation
//! state is `f64`; it becomes `f32` here, at the edge.

use std::collections::{HashMap, VecDeque};
use std::f64::consts::TAU;

use bevy::camera::ScalingMode;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::geometry::{ImplicitCurve, Placed, Pose, WireShape};
use crate::{
    Bead, BeadDiagnostics, DragTarget, OnWire, Pin, Restart, Rod, Spring, Wire, WireBeadSystems,
    WireContact, pose_of,
};

/// Colours and sizes of the scene.
#[derive(Resource, Clone, Debug)]
pub struct SceneStyle {
    /// Background.
    pub background: Color,
    /// Wire strokes.
    pub wire: Color,
    /// The hatching on the closed side of a one-sided wire.
    pub hatch: Color,
    /// Beads.
    pub bead: Color,
    /// A diverged bead.
    pub diverged: Color,
    /// Trails (faded toward the background with age).
    pub trail: Color,
    /// A bead in flight off its one-sided wire, and its trail there.
    pub flight: Color,
    /// The constraint force arrow.
    pub constraint_force: Color,
    /// The drag spring.
    pub drag: Color,
    /// Rods between beads.
    pub rod: Color,
    /// Pins: a small square at the point.
    pub pin: Color,
    /// Springs between beads, drawn as zigzags.
    pub spring: Color,
    /// Bead radius as a fraction of the framed view's height.
    pub bead_radius: f32,
    /// Seconds of trail kept.
    pub trail_seconds: f64,
    /// Pixels of the window's right edge covered by the panel: the wires are
    /// framed in the rest.
    pub panel_width: f32,
    /// Arrow length for a force equal to the bead's weight, as a fraction of
    /// the framed view's height.
    pub force_scale: f32,
}

impl Default for SceneStyle {
    fn default() -> Self {
        Self {
            background: Color::srgb(0.07, 0.08, 0.10),
            wire: Color::srgb(0.35, 0.80, 1.0),
            hatch: Color::srgb(0.24, 0.52, 0.66),
            bead: Color::srgb(1.0, 0.55, 0.10),
            diverged: Color::srgb(0.9, 0.1, 0.1),
            trail: Color::srgb(1.0, 0.85, 0.3),
            flight: Color::srgb(0.95, 0.35, 1.0),
            constraint_force: Color::srgb(0.4, 1.0, 0.4),
            drag: Color::srgb(1.0, 0.3, 0.8),
            rod: Color::srgb(0.92, 0.92, 0.92),
            pin: Color::srgb(1.0, 0.25, 0.25),
            spring: Color::srgb(0.75, 0.55, 1.0),
            bead_radius: 0.025,
            trail_seconds: 2.0,
            panel_width: 340.0,
            force_scale: 0.06,
        }
    }
}

/// The camera the scene is framed in.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct SceneCamera;

/// Marks a bead's visuals as added.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct BeadVisual;

/// A bead's recent positions, newest last, each with whether the bead was
/// in flight off its wire there.
#[derive(Component, Clone, Debug, Default)]
pub struct Trail(pub VecDeque<(Vec2, bool)>);

/// The world rectangle the camera frames (center, size), updated each frame.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct FramedView {
    /// Center of the framed rectangle.
    pub center: Vec2,
    /// Its size in world units.
    pub size: Vec2,
}

/// Draws the scene.
#[derive(Default)]
pub struct SceneRenderPlugin;

impl Plugin for SceneRenderPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SceneStyle>()
            .init_resource::<FramedView>()
            .add_systems(Startup, (spawn_camera, style_gizmos))
            .add_systems(FixedUpdate, record_trails.after(WireBeadSystems::Writeback))
            .add_systems(
                Update,
                (
                    add_bead_visuals,
                    clear_trails_on_restart,
                    frame_camera,
                    size_and_colour_beads,
                    draw_wires,
                    draw_trails,
                    draw_links,
                    draw_forces,
                )
                    .chain(),
            );
    }
}

fn spawn_camera(mut commands: Commands, style: Res<SceneStyle>) {
    commands.insert_resource(ClearColor(style.background));
    commands.spawn((
        Camera2d,
        SceneCamera,
        Projection::Orthographic(OrthographicProjection {
            scaling_mode: ScalingMode::WindowSize,
            ..OrthographicProjection::default_2d()
        }),
    ));
}

fn style_gizmos(mut store: ResMut<GizmoConfigStore>) {
    let (config, _) = store.config_mut::<DefaultGizmoConfigGroup>();
    config.line.width = 3.0;
}

/// Gives new beads a mesh, a material and a trail.
pub fn add_bead_visuals(
    beads: Query<Entity, (With<Bead>, Without<BeadVisual>)>,
    style: Res<SceneStyle>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<ColorMaterial>>,
    mut commands: Commands,
) {
    for entity in &beads {
        commands.entity(entity).insert((
            Mesh2d(meshes.add(Circle::new(1.0))),
            MeshMaterial2d(materials.add(ColorMaterial::from_color(style.bead))),
            Trail::default(),
            BeadVisual,
        ));
    }
}

/// Appends each bead's position to its trail and drops what is too old.
pub fn record_trails(
    params: Res<crate::SimParams>,
    style: Res<SceneStyle>,
    mut beads: Query<(&Bead, &mut Trail, Option<&WireContact>)>,
) {
    let keep = (style.trail_seconds / params.timestep).ceil() as usize;
    for (bead, mut trail, contact) in &mut beads {
        let flying = contact.is_some_and(|c| !c.is_on());
        trail.0.push_back((bead.position.as_vec2(), flying));
        while trail.0.len() > keep.max(2) {
            trail.0.pop_front();
        }
    }
}

fn clear_trails_on_restart(mut restarts: MessageReader<Restart>, mut trails: Query<&mut Trail>) {
    if restarts.read().count() > 0 {
        for mut trail in &mut trails {
            trail.0.clear();
        }
    }
}

/// The world rectangle `(min, max)` that shows a wire whole (or a stretch of
/// it, for unbounded shapes), in world coordinates.
pub fn wire_bounds(shape: &WireShape, pose: &Pose) -> (DVec2, DVec2) {
    let points = wire_points(shape, pose, None);
    points.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

/// Points along a wire in world coordinates. Closed shapes are sampled whole;
/// open ones over `half_span` on each side of their origin (default: a few
/// wire scales).
pub fn wire_points(shape: &WireShape, pose: &Pose, half_span: Option<f64>) -> Vec<DVec2> {
    let n = 256;
    let local: Vec<DVec2> = match shape {
        WireShape::Circle(c) => (0..=n)
            .map(|i| DVec2::from_angle(TAU * i as f64 / n as f64) * c.radius)
            .collect(),
        WireShape::Ellipse(e) => (0..=n)
            .map(|i| {
                let a = TAU * i as f64 / n as f64;
                DVec2::new(e.a * a.cos(), e.b * a.sin())
            })
            .collect(),
        WireShape::Cycloid(c) => c.polyline().collect(),
        WireShape::Spline(s) => s.polyline().collect(),
        open => {
            let scale = open.curve().scale();
            let span = half_span.unwrap_or(match open {
                WireShape::Sine(s) => 1.5 * s.wavelength,
                WireShape::Parabola(p) => 3.0 * p.focal_length.abs(),
                _ => 2.0 * scale,
            });
            (0..=n)
                .map(|i| {
                    let x = -span + 2.0 * span * i as f64 / n as f64;
                    match open {
                        WireShape::Sine(s) => {
                            DVec2::new(x, s.amplitude * (TAU * x / s.wavelength).sin())
                        }
                        WireShape::Parabola(p) => DVec2::new(x, x * x / (4.0 * p.focal_length)),
                        _ => DVec2::new(x, 0.0),
                    }
                })
                .collect()
        }
    };
    local.into_iter().map(|p| pose.to_world(p)).collect()
}

fn wire_pose(transform: &Transform) -> Pose {
    pose_of(transform).unwrap_or_default()
}

/// Frames every wire (and every bead's start) in the part of the window
/// left of the panel, whatever their size.
pub fn frame_camera(
    wires: Query<(&Wire, &Transform)>,
    beads: Query<&Bead>,
    rods: Query<&Rod>,
    on_wire: Query<(), With<OnWire>>,
    windows: Query<&Window>,
    style: Res<SceneStyle>,
    mut view: ResMut<FramedView>,
    mut cameras: Query<(&mut Transform, &mut Projection), (With<SceneCamera>, Without<Wire>)>,
) {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for (wire, transform) in &wires {
        let (a, b) = wire_bounds(wire.shape(), &wire_pose(transform));
        lo = lo.min(a);
        hi = hi.max(b);
    }
    for bead in &beads {
        lo = lo.min(bead.params().initial_position);
        hi = hi.max(bead.params().initial_position);
    }
    // Beads hanging on rods swing out as far as the rods reach: a rod
    // with a bead on no wire widens the view by its length.
    let reach: f64 = rods
        .iter()
        .filter(|rod| rod.beads().iter().any(|b| !on_wire.contains(*b)))
        .map(Rod::length)
        .sum();
    lo -= DVec2::splat(reach);
    hi += DVec2::splat(reach);
    if !(lo.is_finite() && hi.is_finite()) {
        return;
    }
    let center = ((lo + hi) * 0.5).as_vec2();
    let size = ((hi - lo).as_vec2() * 1.25).max(Vec2::splat(0.5));
    let Some(window) = windows.iter().next() else {
        return;
    };
    let free = Vec2::new(
        (window.width() - style.panel_width).max(100.0),
        window.height().max(100.0),
    );
    let world_per_px = (size.x / free.x).max(size.y / free.y);
    *view = FramedView {
        center,
        size: free * world_per_px,
    };
    for (mut transform, mut projection) in &mut cameras {
        transform.translation.x = center.x + 0.5 * style.panel_width * world_per_px;
        transform.translation.y = center.y;
        if let Projection::Orthographic(ortho) = projection.as_mut() {
            ortho.scaling_mode = ScalingMode::WindowSize;
            ortho.scale = world_per_px;
        }
    }
}

/// Sizes each bead to the view, no wider than 40 % of the shortest rod it
/// hangs on (so a rope of short rods reads as a rope), and colours the
/// diverged ones.
fn size_and_colour_beads(
    view: Res<FramedView>,
    style: Res<SceneStyle>,
    rods: Query<&Rod>,
    mut beads: Query<
        (
            Entity,
            &mut Transform,
            &MeshMaterial2d<ColorMaterial>,
            Has<crate::Diverged>,
            Option<&WireContact>,
        ),
        With<Bead>,
    >,
    mut materials: ResMut<Assets<ColorMaterial>>,
) {
    let radius = style.bead_radius * view.size.y;
    let mut shortest: HashMap<Entity, f32> = HashMap::new();
    for rod in &rods {
        for bead in rod.beads() {
            let limit = shortest.entry(bead).or_insert(f32::INFINITY);
            *limit = limit.min(0.4 * rod.length() as f32);
        }
    }
    for (entity, mut transform, material, diverged, contact) in &mut beads {
        let r = shortest
            .get(&entity)
            .map_or(radius, |&limit| radius.min(limit));
        transform.scale = Vec3::splat(r);
        transform.translation.z = 1.0;
        if let Some(mut m) = materials.get_mut(&material.0) {
            let colour = if diverged {
                style.diverged
            } else if contact.is_some_and(|c| !c.is_on()) {
                style.flight
            } else {
                style.bead
            };
            if m.color != colour {
                m.color = colour;
            }
        }
    }
}

/// Draws every wire as a gizmo stroke.
pub fn draw_wires(
    wires: Query<(&Wire, &Transform)>,
    view: Res<FramedView>,
    style: Res<SceneStyle>,
    mut gizmos: Gizmos,
) {
    for (wire, transform) in &wires {
        let pose = wire_pose(transform);
        match wire.shape() {
            WireShape::Custom(curve) => {
                // A game's own curve: traced where it crosses the view.
                let center = view.center.as_dvec2();
                let half = view.size.as_dvec2();
                let placed = Placed {
                    curve: curve.as_ref(),
                    pose,
                };
                for (a, b) in implicit_segments(&placed, center - half, center + half, [192, 128]) {
                    gizmos.line_2d(a.as_vec2(), b.as_vec2(), style.wire);
                }
            }
            shape => {
                // Open wires run past the edges of the view.
                let span =
                    (view.size.length() as f64) + (pose.origin - view.center.as_dvec2()).length();
                let points = wire_points(shape, &pose, Some(span));
                gizmos.linestrip_2d(points.iter().map(|p| p.as_vec2()), style.wire);
                let side = wire.surface().side.sign();
                if side != 0.0 {
                    let placed = Placed {
                        curve: shape.curve(),
                        pose,
                    };
                    hatch(&mut gizmos, &placed, &points, side, &view, style.hatch);
                }
            }
        }
    }
}

/// Marks the closed side of a one-sided wire: short slanted strokes on the
/// side it does not push toward (like the hatching of a wall in a
/// drawing), so the open side is the clear one.
fn hatch(
    gizmos: &mut Gizmos,
    curve: &dyn ImplicitCurve,
    points: &[DVec2],
    side: f64,
    view: &FramedView,
    colour: Color,
) {
    let length = hatch_length(view);
    let mut travelled = 0.0;
    for pair in points.windows(2) {
        travelled += (pair[1] - pair[0]).length();
        if travelled < 1.5 * length {
            continue;
        }
        travelled = 0.0;
        let p = pair[1];
        let end = hatch_point(curve, p, side, length);
        gizmos.line_2d(p.as_vec2(), end.as_vec2(), colour);
    }
}

/// The length of a hatch stroke in world units, for the framed view.
pub fn hatch_length(view: &FramedView) -> f64 {
    0.018 * f64::from(view.size.y)
}

/// The far end of the hatch stroke from `p` on a wire that pushes toward
/// `side` (a stroke of `length` toward the other side, slanted along the
/// wire): a negative `side` gives the mirror stroke, on the open side.
pub fn hatch_point(curve: &dyn ImplicitCurve, p: DVec2, side: f64, length: f64) -> DVec2 {
    let normal = curve.gradient(p).normalize_or_zero();
    let along = DVec2::new(-normal.y, normal.x);
    p - side * length * normal + 0.5 * length * along
}

/// The zero set of `curve` inside the rectangle `lo..hi`, as line segments:
/// marching squares on a grid of `cells` (x, y), the crossings on each cell
/// edge placed by linear interpolation of `C`. Draws any [`ImplicitCurve`]
/// without knowing its shape.
pub fn implicit_segments(
    curve: &dyn ImplicitCurve,
    lo: DVec2,
    hi: DVec2,
    cells: [usize; 2],
) -> Vec<(DVec2, DVec2)> {
    let [nx, ny] = cells.map(|n| n.max(1));
    let step = (hi - lo) / DVec2::new(nx as f64, ny as f64);
    let node = |i: usize, j: usize| lo + step * DVec2::new(i as f64, j as f64);
    let values: Vec<f64> = (0..=ny)
        .flat_map(|j| (0..=nx).map(move |i| (i, j)))
        .map(|(i, j)| curve.value(node(i, j)))
        .collect();
    let value = |i: usize, j: usize| values[j * (nx + 1) + i];
    let crossing = |(pa, va): (DVec2, f64), (pb, vb): (DVec2, f64)| {
        let differ = (va < 0.0) != (vb < 0.0);
        (differ && va.is_finite() && vb.is_finite()).then(|| pa + (pb - pa) * (va / (va - vb)))
    };
    let mut segments = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                .map(|(a, b)| (node(a, b), value(a, b)));
            let points: Vec<DVec2> = (0..4)
                .filter_map(|k| crossing(corners[k], corners[(k + 1) % 4]))
                .collect();
            // Two crossings make one segment; a saddle's four make two.
            for pair in points.chunks_exact(2) {
                segments.push((pair[0], pair[1]));
            }
        }
    }
    segments
}

/// Draws each trail fading with age, in the flight colour where the bead
/// was off its wire.
fn draw_trails(beads: Query<&Trail>, style: Res<SceneStyle>, mut gizmos: Gizmos) {
    for trail in &beads {
        let n = trail.0.len().max(1) as f32;
        gizmos.linestrip_gradient_2d(trail.0.iter().enumerate().map(|(i, (p, flying))| {
            let colour = if *flying { style.flight } else { style.trail };
            (*p, colour.with_alpha((i as f32 + 1.0) / n))
        }));
    }
}

/// Draws rods as lines between their beads, pins as small squares at
/// their points and springs as zigzags.
pub fn draw_links(
    beads: Query<&Bead>,
    rods: Query<&Rod>,
    pins: Query<&Pin>,
    transforms: Query<&Transform>,
    springs: Query<&Spring>,
    view: Res<FramedView>,
    style: Res<SceneStyle>,
    mut gizmos: Gizmos,
) {
    let at = |e: Entity| beads.get(e).ok().map(|b| b.position.as_vec2());
    for rod in &rods {
        if let (Some(a), Some(b)) = (at(rod.beads()[0]), at(rod.beads()[1])) {
            gizmos.line_2d(a, b, style.rod);
        }
    }
    let side = 1.2 * style.bead_radius * view.size.y;
    for at in pins.iter().filter_map(|pin| pin.locate(&transforms)) {
        gizmos.rect_2d(
            Isometry2d::from_translation(at.as_vec2()),
            Vec2::splat(side),
            style.pin,
        );
    }
    let width = 0.6 * style.bead_radius * view.size.y;
    for spring in &springs {
        if let (Some(a), Some(b)) = (at(spring.beads()[0]), at(spring.beads()[1])) {
            gizmos.linestrip_2d(zigzag(a, b, 12, width), style.spring);
        }
    }
}

/// A zigzag of `turns` teeth of half-width `width` from `a` to `b`, with a
/// straight lead at each end.
pub fn zigzag(a: Vec2, b: Vec2, turns: usize, width: f32) -> Vec<Vec2> {
    let d = b - a;
    let normal = d.perp().normalize_or_zero() * width;
    let (start, end) = (a + 0.1 * d, a + 0.9 * d);
    let mut points = vec![a, start];
    for i in 0..turns {
        let t = (i as f32 + 0.5) / turns as f32;
        let side = if i % 2 == 0 { 1.0 } else { -1.0 };
        points.push(start.lerp(end, t) + side * normal);
    }
    points.extend([end, b]);
    points
}

/// Draws the constraint force on each bead on a wire (on a bead hanging
/// from rods it lies along them and would hide them; the panel lists every
/// rod's λ), and the drag spring.
fn draw_forces(
    beads: Query<(
        &Bead,
        Option<&BeadDiagnostics>,
        Option<&DragTarget>,
        Has<OnWire>,
    )>,
    params: Res<crate::SimParams>,
    view: Res<FramedView>,
    style: Res<SceneStyle>,
    mut gizmos: Gizmos,
) {
    let g = params.gravity.length().max(1e-3) as f32;
    for (bead, diagnostics, drag, on_wire) in &beads {
        // Forces are drawn in units of the bead's weight.
        let per_newton = style.force_scale * view.size.y / (bead.mass() as f32 * g);
        let at = bead.position.as_vec2();
        let force = diagnostics
            .filter(|_| on_wire)
            .map_or(Vec2::ZERO, |d| d.constraint_force.as_vec2())
            * per_newton;
        if force.length() > 1e-4 * view.size.y {
            gizmos.arrow_2d(at, at + force, style.constraint_force);
        }
        if let Some(target) = drag {
            gizmos.line_2d(at, target.get().as_vec2(), style.drag);
            gizmos.circle_2d(
                Isometry2d::from_translation(target.get().as_vec2()),
                0.5 * style.bead_radius * view.size.y,
                style.drag,
            );
        }
    }
}

/// The world position under a screen position, through the scene camera.
pub fn screen_to_world(
    camera: &Camera,
    camera_transform: &GlobalTransform,
    screen: Vec2,
) -> Option<DVec2> {
    camera
        .viewport_to_world_2d(camera_transform, screen)
        .ok()
        .map(|p| p.as_dvec2())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Circle;

    /// Marching squares on a moved circle: every segment end lies on the
    /// circle to within the interpolation error, and the segments add up to
    /// its circumference.
    #[test]
    fn implicit_segments_trace_a_circle() {
        let circle = Circle { radius: 1.5 };
        let pose = Pose::new(DVec2::new(2.0, -1.0), 0.3);
        let placed = Placed {
            curve: &circle,
            pose,
        };
        let segments = implicit_segments(
            &placed,
            DVec2::new(-1.0, -4.0),
            DVec2::new(5.0, 2.0),
            [120, 120],
        );
        assert!(segments.len() > 100, "{} segments", segments.len());
        let cell = 6.0 / 120.0;
        for (a, b) in &segments {
            for p in [a, b] {
                let off = ((*p - pose.origin).length() - 1.5).abs();
                assert!(off < 0.05 * cell, "a point {off:.2e} off the circle");
            }
        }
        let length: f64 = segments.iter().map(|(a, b)| (*b - *a).length()).sum();
        let circumference = TAU * 1.5;
        assert!(
            (length - circumference).abs() < 1e-3 * circumference,
            "traced length {length} against {circumference}"
        );
    }
}
