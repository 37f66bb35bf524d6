//! [`WireBeadDebugPlugin`] (feature `debug-render`): wires, beads, rods,
//! pins, springs and forces drawn with Bevy's gizmos, as avian's
//! `PhysicsDebugPlugin` draws bodies and joints. Needs no egui and no
//! window of ours: add it to a game that renders, or to any app with
//! Bevy's `GizmoPlugin`. Sizes are in world units, set in
//! [`DebugRenderStyle`]; simulation state becomes `f32` here, at the edge.

use std::f64::consts::TAU;

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::dynamics::Rod;
use crate::dynamics::{
    BeadDiagnostics, BeadMass, BeadPosition, Diverged, OnWire, Pin, SimParams, Spring,
    SpringAnchor, Wire, pose_of,
};
use crate::geometry::{ImplicitCurve, Placed, Pose, WireShape};

/// Draws the simulation with gizmos each frame, in [`DebugRenderSystems`].
#[derive(Default)]
pub struct WireBeadDebugPlugin;

impl Plugin for WireBeadDebugPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<DebugRenderStyle>().add_systems(
            Update,
            (draw_wires, draw_beads, draw_links, draw_forces).in_set(DebugRenderSystems),
        );
    }
}

/// The set the debug drawing runs in, in `Update`: a game that moves the
/// view orders its own systems before it.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DebugRenderSystems;

/// What the debug renderer draws and how: colours, and sizes in world
/// units.
#[derive(Resource, Clone, Debug)]
pub struct DebugRenderStyle {
    /// Wire strokes.
    pub wire: Color,
    /// The hatching on the closed side of a one-sided wire.
    pub hatch: Color,
    /// Beads, drawn as circles.
    pub bead: Color,
    /// A diverged bead.
    pub diverged: Color,
    /// Rods between beads.
    pub rod: Color,
    /// Pins: a small square at the point.
    pub pin: Color,
    /// Springs between beads, drawn as zigzags.
    pub spring: Color,
    /// The constraint force arrow on a bead on a wire.
    pub constraint_force: Color,
    /// The drag spring, from a bead to its [`SpringAnchor`].
    pub drag: Color,
    /// Whether beads are drawn (off where they have meshes of their own).
    pub beads: bool,
    /// Bead radius.
    pub bead_radius: f32,
    /// The length of a hatch stroke.
    pub hatch_length: f64,
    /// Arrow length for a force equal to the bead's weight.
    pub force_scale: f32,
    /// The most beads a scene may have for their constraint forces to be
    /// drawn: a pile's, one arrow of its weight on every bead, would cover
    /// it.
    pub force_arrows_up_to: usize,
    /// The world rectangle `(min, max)` an open wire is drawn across and a
    /// game's own curve traced in.
    pub bounds: (DVec2, DVec2),
}

impl Default for DebugRenderStyle {
    fn default() -> Self {
        Self {
            wire: Color::srgb(0.35, 0.80, 1.0),
            hatch: Color::srgb(0.24, 0.52, 0.66),
            bead: Color::srgb(1.0, 0.55, 0.10),
            diverged: Color::srgb(0.9, 0.1, 0.1),
            rod: Color::srgb(0.92, 0.92, 0.92),
            pin: Color::srgb(1.0, 0.25, 0.25),
            spring: Color::srgb(0.75, 0.55, 1.0),
            constraint_force: Color::srgb(0.4, 1.0, 0.4),
            drag: Color::srgb(1.0, 0.3, 0.8),
            beads: true,
            bead_radius: 0.05,
            hatch_length: 0.04,
            force_scale: 0.15,
            force_arrows_up_to: 64,
            bounds: (DVec2::splat(-5.0), DVec2::splat(5.0)),
        }
    }
}

impl DebugRenderStyle {
    /// Whether a scene of `beads` beads has its constraint forces drawn:
    /// at most [`DebugRenderStyle::force_arrows_up_to`].
    pub fn draws_force_arrows(&self, beads: usize) -> bool {
        beads <= self.force_arrows_up_to
    }
}

/// Where a wire's `Transform` puts it (the identity for a pose that is not
/// in the plane).
pub fn wire_pose(transform: &Transform) -> Pose {
    pose_of(transform).unwrap_or_default()
}

/// What a wire rides: the body of its `WireOnBody`, with the avian
/// features.
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
pub(crate) type Riding = Option<&'static crate::dynamics::WireOnBody>;
/// What a wire rides: nothing, without the avian features.
#[cfg(not(any(feature = "avian2d", feature = "avian3d")))]
pub(crate) type Riding = ();

/// Where the body a wire rides puts the wire's frame (the identity for a
/// wire that rides none).
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
fn carrier_pose(riding: Option<&crate::dynamics::WireOnBody>, bodies: &Query<&Transform>) -> Pose {
    riding
        .and_then(|on| bodies.get(on.0).ok())
        .map_or(Pose::IDENTITY, wire_pose)
}

/// Where the body a wire rides puts the wire's frame: no wire rides one
/// without the avian features.
#[cfg(not(any(feature = "avian2d", feature = "avian3d")))]
fn carrier_pose(_: (), _: &Query<&Transform>) -> Pose {
    Pose::IDENTITY
}

/// Where a wire is in the world, in space as in the plane: its own
/// `Transform` (`transform`), which is its place in the frame of the body
/// it rides where it rides one, composed with that body's.
#[cfg(all(feature = "gui", any(feature = "avian2d", feature = "avian3d")))]
pub(crate) fn carried_transform(
    transform: &Transform,
    riding: Option<&crate::dynamics::WireOnBody>,
    bodies: &Query<&Transform>,
) -> Transform {
    riding
        .and_then(|on| bodies.get(on.0).ok())
        .map_or(*transform, |body| body.mul_transform(*transform))
}

/// Where a wire is in the world: where its `Transform` puts it, no wire
/// riding a body without the avian features.
#[cfg(all(feature = "gui", not(any(feature = "avian2d", feature = "avian3d"))))]
pub(crate) fn carried_transform(transform: &Transform, _: (), _: &Query<&Transform>) -> Transform {
    *transform
}

/// Draws every wire as a gizmo stroke, a one-sided one hatched on its
/// closed side; a wire that rides a body (`WireOnBody`) where the body
/// carries it.
pub fn draw_wires(
    wires: Query<(&Wire, &Transform, Riding)>,
    bodies: Query<&Transform>,
    style: Res<DebugRenderStyle>,
    mut gizmos: Gizmos,
) {
    let (lo, hi) = style.bounds;
    for (wire, transform, riding) in &wires {
        let pose = carrier_pose(riding, &bodies).compose(&wire_pose(transform));
        match wire.shape() {
            WireShape::Custom(curve) => {
                // A game's own curve: traced where it crosses the bounds.
                let placed = Placed {
                    curve: curve.as_ref(),
                    pose,
                };
                for (a, b) in implicit_segments(&placed, lo, hi, [192, 128]) {
                    gizmos.line_2d(a.as_vec2(), b.as_vec2(), style.wire);
                }
            }
            shape => {
                // Open wires run past the edges of the bounds.
                let centre = 0.5 * (lo + hi);
                let span = 0.5 * (hi - lo).length() + (pose.origin - centre).length();
                let points = wire_points(shape, &pose, Some(span));
                gizmos.linestrip_2d(points.iter().map(|p| p.as_vec2()), style.wire);
                let side = wire.surface().side.sign();
                if side != 0.0 {
                    let placed = Placed {
                        curve: shape.curve(),
                        pose,
                    };
                    hatch(&mut gizmos, &placed, &points, side, &style);
                }
            }
        }
    }
}

/// Draws each bead as a circle, in the diverged colour once it stopped.
pub fn draw_beads(
    beads: Query<(&BeadPosition, Has<Diverged>)>,
    style: Res<DebugRenderStyle>,
    mut gizmos: Gizmos,
) {
    if !style.beads {
        return;
    }
    for (bead, diverged) in &beads {
        let colour = if diverged { style.diverged } else { style.bead };
        let at = Isometry2d::from_translation(bead.as_vec2());
        gizmos.circle_2d(at, style.bead_radius, colour);
    }
}

/// Draws rods as lines between their beads, pins as small squares at
/// their points and springs as zigzags.
pub fn draw_links(
    beads: Query<&BeadPosition>,
    rods: Query<&Rod>,
    pins: Query<&Pin>,
    transforms: Query<&Transform>,
    springs: Query<&Spring>,
    style: Res<DebugRenderStyle>,
    mut gizmos: Gizmos,
) {
    let at = |e: Entity| beads.get(e).ok().map(|b| b.as_vec2());
    for rod in &rods {
        if let (Some(a), Some(b)) = (at(rod.beads()[0]), at(rod.beads()[1])) {
            gizmos.line_2d(a, b, style.rod);
        }
    }
    let side = 1.2 * style.bead_radius;
    for at in pins.iter().filter_map(|pin| pin.locate(&transforms)) {
        gizmos.rect_2d(
            Isometry2d::from_translation(at.as_vec2()),
            Vec2::splat(side),
            style.pin,
        );
    }
    let width = 0.6 * style.bead_radius;
    for spring in &springs {
        if let (Some(a), Some(b)) = (at(spring.beads()[0]), at(spring.beads()[1])) {
            gizmos.linestrip_2d(zigzag(a, b, 12, width), style.spring);
        }
    }
}

/// Draws the constraint force on each bead on a wire (on a bead hanging
/// from rods it lies along them and would hide them), in units of the
/// bead's weight, where the scene has at most
/// [`DebugRenderStyle::force_arrows_up_to`] beads, and the drag spring.
pub fn draw_forces(
    beads: Query<(
        &BeadPosition,
        &BeadMass,
        Option<&BeadDiagnostics>,
        Option<&SpringAnchor>,
        Has<OnWire>,
    )>,
    params: Res<SimParams>,
    style: Res<DebugRenderStyle>,
    mut gizmos: Gizmos,
) {
    let largest = beads
        .iter()
        .filter_map(|(_, _, d, _, on_wire)| d.filter(|_| on_wire))
        .map(|d| d.constraint_force.length())
        .fold(0.0, f64::max);
    let arrows = style.draws_force_arrows(beads.iter().len());
    for (bead, mass, diagnostics, drag, on_wire) in &beads {
        let per_newton =
            style.force_scale * force_unit(params.gravity.length(), mass.get(), largest);
        let at = bead.as_vec2();
        let force = diagnostics
            .filter(|_| on_wire && arrows)
            .map_or(Vec2::ZERO, |d| d.constraint_force.as_vec2())
            * per_newton;
        if force.is_finite() && force.length() > 1e-3 * style.force_scale {
            gizmos.arrow_2d(at, at + force, style.constraint_force);
        }
        if let Some(target) = drag {
            gizmos.line_2d(at, target.get().as_vec2(), style.drag);
            gizmos.circle_2d(
                Isometry2d::from_translation(target.get().as_vec2()),
                0.5 * style.bead_radius,
                style.drag,
            );
        }
    }
}

/// How long an arrow for one newton is, as a share of an arrow for the
/// bead's weight (`mass` under `gravity`); with no gravity to weigh by, of
/// an arrow for the `largest` constraint force in the scene.
pub fn force_unit(gravity: f64, mass: f64, largest: f64) -> f32 {
    let unit = if gravity > 1e-9 {
        mass * gravity
    } else {
        largest
    };
    if unit > 0.0 && unit.is_finite() {
        unit.recip() as f32
    } else {
        0.0
    }
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

/// Marks the closed side of a one-sided wire: short slanted strokes on the
/// side it does not push toward (like the hatching of a wall in a
/// drawing), so the open side is the clear one.
fn hatch(
    gizmos: &mut Gizmos,
    curve: &dyn ImplicitCurve,
    points: &[DVec2],
    side: f64,
    style: &DebugRenderStyle,
) {
    let (length, colour) = (style.hatch_length, style.hatch);
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
