//! Drawing the scene: a camera that frames the wires, beads as meshes,
//! fading trails; the wires, links and forces through the debug renderer
//! in the scene's style. Simulation state is `f64`; it becomes `f32` here,
//! at the edge.

use std::collections::{HashMap, VecDeque};

use bevy::camera::ScalingMode;
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy_egui::PrimaryEguiContext;

use crate::controls::Presentation;
use crate::debug_render::{
    DebugRenderStyle, DebugRenderSystems, WireBeadDebugPlugin, wire_points, wire_pose,
};
use crate::geometry::{Pose, WireShape};
use crate::gui::bodies::BodyVisual;
use crate::{
    Bead, BeadParams, BeadPosition, BeadRadius, BeadSentBack, OnWire, Restart, Rod, Wire,
    WireBeadSystems, WireContact,
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
    /// Dynamic rigid bodies (features `avian2d`, `avian3d`).
    pub body: Color,
    /// Static and kinematic rigid bodies.
    pub fixed_body: Color,
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
    /// The window height (logical pixels) from which the plots sit in the
    /// panel, under its settings; in a shorter window (1280×800, a laptop)
    /// they take a column of their own left of the scene, so that nothing
    /// of them is below the fold.
    pub plots_in_panel_from: f32,
    /// Arrow length for a force equal to the bead's weight, as a fraction of
    /// the framed view's height.
    pub force_scale: f32,
}

/// How much larger the panel's text is in presentation mode.
pub const PRESENTATION_ZOOM: f32 = 1.3;

impl SceneStyle {
    /// The widths, in logical pixels, of the panel on the right and of the
    /// plots' column on the left (zero where the plots are in the panel)
    /// in a window `width` by `height`: the scene is framed in what is
    /// left. The plots take a column of their own in presentation mode,
    /// and in a window shorter than [`plots_in_panel_from`](Self::plots_in_panel_from)
    /// that is wide enough for three columns.
    pub fn side_widths(&self, presenting: bool, width: f32, height: f32) -> (f32, f32) {
        if presenting {
            // The panel's width at the larger text, with its margins.
            let side = (self.panel_width * PRESENTATION_ZOOM + 60.0).min(0.38 * width);
            (side, side)
        } else if height < self.plots_in_panel_from && width >= 3.0 * self.panel_width {
            (self.panel_width, self.panel_width)
        } else {
            (self.panel_width, 0.0)
        }
    }
}

impl Default for SceneStyle {
    fn default() -> Self {
        Self {
            background: Color::srgb(0.07, 0.08, 0.10),
            wire: Color::srgb(0.35, 0.80, 1.0),
            hatch: Color::srgb(0.24, 0.52, 0.66),
            bead: Color::srgb(1.0, 0.55, 0.10),
            body: Color::srgb(0.45, 0.62, 0.50),
            fixed_body: Color::srgb(0.30, 0.32, 0.36),
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
            plots_in_panel_from: 1100.0,
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
/// in flight off its wire there and the simulated time: `Trail` in the
/// plane, `Trail<Vec3>` in space.
#[derive(Component, Clone, Debug)]
pub struct Trail<P = Vec2>(pub VecDeque<(P, bool, f64)>);

impl<P> Default for Trail<P> {
    fn default() -> Self {
        Self(VecDeque::new())
    }
}

impl<P: Copy> Trail<P> {
    /// Appends where the bead is (in flight or not) at `time` and drops
    /// what is more than `keep` points old (keeping two at least). Back at
    /// an earlier time (a step back on the timeline), the trail goes on
    /// from there.
    pub fn record(&mut self, at: P, flying: bool, time: f64, keep: usize) {
        while self.0.back().is_some_and(|p| p.2 >= time) {
            self.0.pop_back();
        }
        self.0.push_back((at, flying, time));
        while self.0.len() > keep.max(2) {
            self.0.pop_front();
        }
    }

    /// Its points up to the time `now` (a step back on the timeline hides
    /// the rest), each in the trail's colour (the flight colour where the
    /// bead was off its wire) fading with age.
    pub fn coloured<'a>(
        &'a self,
        style: &'a SceneStyle,
        now: f64,
    ) -> impl Iterator<Item = (P, Color)> + 'a {
        let shown = self.0.iter().take_while(move |p| p.2 <= now);
        let n = shown.clone().count().max(1) as f32;
        shown.enumerate().map(move |(i, &(p, flying, _))| {
            let colour = if flying { style.flight } else { style.trail };
            (p, colour.with_alpha((i as f32 + 1.0) / n))
        })
    }
}

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
        if !app.is_plugin_added::<WireBeadDebugPlugin>() {
            app.add_plugins(WireBeadDebugPlugin);
        }
        app.init_resource::<SceneStyle>()
            .init_resource::<FramedView>()
            .add_systems(Startup, (spawn_camera, style_gizmos))
            .add_systems(FixedUpdate, record_trails.after(WireBeadSystems::Writeback))
            .add_systems(
                Update,
                (
                    add_bead_visuals,
                    clear_trails::<Vec2>,
                    frame_camera,
                    size_and_colour_beads,
                    style_debug_render,
                    draw_trails,
                )
                    .chain()
                    .before(DebugRenderSystems),
            );
    }
}

/// The debug renderer draws the wires, links and forces: in the scene's
/// colours, sized to the framed view, beads left to their meshes.
fn style_debug_render(
    view: Res<FramedView>,
    style: Res<SceneStyle>,
    mut debug: ResMut<DebugRenderStyle>,
) {
    let (center, size) = (view.center.as_dvec2(), view.size.as_dvec2());
    *debug = DebugRenderStyle {
        wire: style.wire,
        hatch: style.hatch,
        bead: style.bead,
        diverged: style.diverged,
        rod: style.rod,
        pin: style.pin,
        spring: style.spring,
        constraint_force: style.constraint_force,
        drag: style.drag,
        beads: false,
        bead_radius: style.bead_radius * view.size.y,
        hatch_length: hatch_length(&view),
        force_scale: style.force_scale * view.size.y,
        bounds: (center - size, center + size),
        ..DebugRenderStyle::default()
    };
}

/// The length of a hatch stroke in world units, for the framed view.
pub fn hatch_length(view: &FramedView) -> f64 {
    0.018 * f64::from(view.size.y)
}

fn spawn_camera(mut commands: Commands, style: Res<SceneStyle>) {
    commands.insert_resource(ClearColor(style.background));
    commands.spawn((
        Camera2d,
        SceneCamera,
        PrimaryEguiContext,
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
            Trail::<Vec2>::default(),
            BeadVisual,
        ));
    }
}

/// Appends each bead's position to its trail and drops what is too old.
pub fn record_trails(
    params: Res<crate::SimParams>,
    style: Res<SceneStyle>,
    clock: Res<crate::SimClock>,
    mut beads: Query<(&BeadPosition, &mut Trail, Option<&WireContact>)>,
) {
    let keep = style.trail_points(params.timestep);
    for (bead, mut trail, contact) in &mut beads {
        let flying = contact.is_some_and(|c| !c.is_on());
        trail.record(bead.as_vec2(), flying, clock.time, keep);
    }
}

/// Empties every trail (in the plane or in space) when the run restarts,
/// and the trail of each bead sent back to its wire (which jumped there).
pub(crate) fn clear_trails<P: Send + Sync + 'static>(
    mut restarts: MessageReader<Restart>,
    mut sent: MessageReader<BeadSentBack>,
    mut trails: Query<&mut Trail<P>>,
) {
    if restarts.read().count() > 0 {
        for mut trail in &mut trails {
            trail.0.clear();
        }
    }
    for back in sent.read() {
        if let Ok(mut trail) = trails.get_mut(back.bead) {
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

/// The longest total length of `rods` joined into one chain (or tree):
/// how far a bead at one end may swing from the other. The rods are
/// grouped as the islands group links ([`islands`](crate::solver::islands)).
fn longest_chain<'a>(rods: impl Iterator<Item = &'a Rod>) -> f64 {
    let mut index: HashMap<Entity, usize> = HashMap::new();
    let rods: Vec<(f64, [usize; 2])> = rods
        .map(|rod| {
            let ends = rod.beads().map(|bead| {
                let next = index.len();
                *index.entry(bead).or_insert(next)
            });
            (rod.length(), ends)
        })
        .collect();
    let groups = crate::solver::islands(index.len(), rods.iter().map(|(_, ends)| &ends[..]));
    let mut group_of = vec![0; index.len()];
    for (g, beads) in groups.iter().enumerate() {
        for &bead in beads {
            group_of[bead] = g;
        }
    }
    let mut lengths = vec![0.0; groups.len()];
    for (length, ends) in &rods {
        lengths[group_of[ends[0]]] += length;
    }
    lengths.into_iter().fold(0.0, f64::max)
}

/// Frames every wire (and every bead's and body's start) in the part of
/// the window left of the panel, whatever their size.
pub fn frame_camera(
    wires: Query<(&Wire, &Transform)>,
    beads: Query<&BeadParams>,
    bodies: Query<&BodyVisual>,
    rods: Query<&Rod>,
    on_wire: Query<(), With<OnWire>>,
    windows: Query<&Window>,
    style: Res<SceneStyle>,
    presentation: Option<Res<Presentation>>,
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
        lo = lo.min(bead.initial_position);
        hi = hi.max(bead.initial_position);
    }
    for body in &bodies {
        let [a, b] = body.bounds();
        lo = lo.min(a.truncate().as_dvec2());
        hi = hi.max(b.truncate().as_dvec2());
    }
    // Beads hanging on rods swing out as far as the rods reach: the
    // longest chain of rods with a bead on no wire widens the view by its
    // length.
    let reach = longest_chain(
        rods.iter()
            .filter(|rod| rod.beads().iter().any(|b| !on_wire.contains(*b))),
    );
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
    let presenting = presentation.is_some_and(|p| p.0);
    let (right, left) = style.side_widths(presenting, window.width(), window.height());
    let free = Vec2::new(
        (window.width() - right - left).max(100.0),
        window.height().max(100.0),
    );
    let world_per_px = (size.x / free.x).max(size.y / free.y);
    *view = FramedView {
        center,
        size: free * world_per_px,
    };
    for (mut transform, mut projection) in &mut cameras {
        transform.translation.x = center.x + 0.5 * (right - left) * world_per_px;
        transform.translation.y = center.y;
        if let Projection::Orthographic(ortho) = projection.as_mut() {
            ortho.scaling_mode = ScalingMode::WindowSize;
            ortho.scale = world_per_px;
        }
    }
}

/// Sizes each bead to the view, no wider than 40 % of the shortest rod it
/// hangs on (so a rope of short rods reads as a rope), a bead with a
/// radius at its radius, and colours the diverged ones.
fn size_and_colour_beads(
    view: Res<FramedView>,
    style: Res<SceneStyle>,
    rods: Query<&Rod>,
    radii: Query<&BeadRadius>,
    mut beads: Query<
        (
            Entity,
            &mut Transform,
            &MeshMaterial2d<ColorMaterial>,
            Has<crate::Diverged>,
            Option<&WireContact>,
            Option<&BeadRadius>,
        ),
        With<Bead>,
    >,
    mut materials: ResMut<Assets<ColorMaterial>>,
) {
    let radius = style.bead_radius * view.size.y;
    let limits = BeadSizes::new(&rods, radii.iter());
    for (entity, mut transform, material, diverged, contact, own) in &mut beads {
        transform.scale = Vec3::splat(limits.drawn(entity, own, radius));
        transform.translation.z = 1.0;
        if let Some(mut m) = materials.get_mut(&material.0) {
            let colour = style.bead_colour(diverged, contact);
            if m.color != colour {
                m.color = colour;
            }
        }
    }
}

/// How wide each bead may be drawn: no wider than 40 % of the shortest rod
/// it hangs on, so that a rope of short rods reads as a rope, and, where
/// beads have radii, a bead without one no wider than the smallest of
/// them, so that the beads that touch read as the balls.
pub(crate) struct BeadSizes {
    shortest: HashMap<Entity, f32>,
    smallest: f32,
}

impl BeadSizes {
    /// The limits the rods and the radii set.
    pub(crate) fn new<'a>(
        rods: &Query<&Rod>,
        radii: impl IntoIterator<Item = &'a BeadRadius>,
    ) -> Self {
        let mut shortest: HashMap<Entity, f32> = HashMap::new();
        for rod in rods {
            for bead in rod.beads() {
                let limit = shortest.entry(bead).or_insert(f32::INFINITY);
                *limit = limit.min(0.4 * rod.length() as f32);
            }
        }
        let smallest = radii
            .into_iter()
            .map(|r| r.get() as f32)
            .filter(|&r| r > 0.0)
            .fold(f32::INFINITY, f32::min);
        Self { shortest, smallest }
    }

    /// The radius `bead` is drawn at, `radius` at most.
    pub(crate) fn radius(&self, bead: Entity, radius: f32) -> f32 {
        self.shortest
            .get(&bead)
            .map_or(radius, |&limit| radius.min(limit))
    }

    /// The radius `bead` is drawn at: its own where it has one (beads that
    /// touch are drawn touching), else [`BeadSizes::radius`], no wider
    /// than the smallest bead that has one.
    pub(crate) fn drawn(&self, bead: Entity, own: Option<&BeadRadius>, radius: f32) -> f32 {
        match own.map(BeadRadius::get) {
            Some(r) if r > 0.0 => r as f32,
            _ => self.radius(bead, radius).min(self.smallest),
        }
    }
}

impl SceneStyle {
    /// How many points of a trail are kept: its seconds at `timestep`.
    pub fn trail_points(&self, timestep: f64) -> usize {
        (self.trail_seconds / timestep).ceil() as usize
    }

    /// A rigid body's colour: a dynamic body's, or a static or kinematic
    /// one's.
    pub fn body_colour(&self, dynamic: bool) -> Color {
        if dynamic { self.body } else { self.fixed_body }
    }

    /// A bead's colour: diverged, in flight off its one-sided wire, or on
    /// it.
    pub fn bead_colour(&self, diverged: bool, contact: Option<&WireContact>) -> Color {
        if diverged {
            self.diverged
        } else if contact.is_some_and(|c| !c.is_on()) {
            self.flight
        } else {
            self.bead
        }
    }
}

/// Draws each trail fading with age, in the flight colour where the bead
/// was off its wire.
fn draw_trails(
    beads: Query<&Trail>,
    style: Res<SceneStyle>,
    clock: Res<crate::SimClock>,
    mut gizmos: Gizmos,
) {
    for trail in &beads {
        gizmos.linestrip_gradient_2d(trail.coloured(&style, clock.time));
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
    use super::SceneStyle;

    /// The plots take a column of their own in a window too short for them
    /// under the panel's settings, or in presentation mode; not where the
    /// window is tall, or too narrow for three columns.
    #[test]
    fn the_plots_go_beside_the_scene_in_a_short_window() {
        let style = SceneStyle::default();
        assert_eq!(style.side_widths(false, 1280.0, 1750.0), (340.0, 0.0));
        assert_eq!(style.side_widths(false, 1280.0, 800.0), (340.0, 340.0));
        assert_eq!(style.side_widths(false, 900.0, 800.0), (340.0, 0.0));
        let (right, left) = style.side_widths(true, 1280.0, 1750.0);
        assert_eq!(right, left);
        assert!(right > 340.0 && right <= 0.38 * 1280.0, "{right}");
    }
}
