//! What the 3D view draws of a wire in space, as plain values: a curve
//! traced into a polyline from its own rows, a surface meshed from its
//! values by surface nets. Both in the wire's local frame; computed once a
//! wire, not each frame.

use bevy::math::DVec3;
use fast_surface_nets::ndshape::{ConstShape, ConstShape3u32};
use fast_surface_nets::{SurfaceNetsBuffer, surface_nets};

use crate::geometry::{ImplicitSurface, SpaceCurve};

/// The point of `curve` nearest `p` by Gauss–Newton steps on its two rows
/// (their normals are at right angles), near the parameter `hint`; none
/// where it does not converge or meets a singular point.
fn onto(curve: &dyn SpaceCurve, mut p: DVec3, hint: f64) -> Option<DVec3> {
    let tolerance = 1e-9 * curve.scale().max(1e-6);
    for _ in 0..30 {
        let [a, b] = curve.rows(p, hint);
        let (na, nb) = (a.normal.length_squared(), b.normal.length_squared());
        if !(na > 0.0 && nb > 0.0) {
            return None;
        }
        let step = a.normal * (a.c / na) + b.normal * (b.c / nb);
        p -= step;
        if !p.is_finite() {
            return None;
        }
        if a.c.hypot(b.c) <= tolerance {
            return Some(p);
        }
    }
    None
}

/// Points along `curve` in its local frame, for drawing: from the first
/// of `starts` that projects onto it (not onto its continuation past an
/// end), walked both ways in steps of about `reach / 300` until the curve
/// closes on itself, passes an end (an open spline's), or leaves the ball
/// of radius `reach` about the origin. A closed curve's last point is its
/// first. Empty if no start projects onto it.
pub fn curve_points(curve: &dyn SpaceCurve, starts: &[DVec3], reach: f64) -> Vec<DVec3> {
    let on_it = |p: &DVec3| p.is_finite() && curve.past_end(*p, f64::NAN) <= 0.0;
    let Some(first) = starts
        .iter()
        .find_map(|&s| onto(curve, s, f64::NAN).filter(on_it))
    else {
        return Vec::new();
    };
    let ds = (reach / 300.0).max(1e-6);
    let walk = |sign: f64| -> (Vec<DVec3>, bool) {
        let mut points = Vec::new();
        let (mut p, mut hint) = (first, curve.parameter(first, f64::NAN));
        let mut direction = curve.frame(p, hint).tangent * sign;
        while p.length() <= reach && points.len() < 6000 {
            let mut tangent = curve.frame(p, hint).tangent;
            if tangent.dot(direction) < 0.0 {
                tangent = -tangent;
            }
            if tangent == DVec3::ZERO {
                break;
            }
            let Some(next) = onto(curve, p + tangent * ds, hint) else {
                break;
            };
            if curve.past_end(next, hint) > 0.0 {
                break;
            }
            if points.len() > 4 && next.distance(first) < 0.75 * ds {
                points.push(first);
                return (points, true);
            }
            direction = tangent;
            hint = curve.parameter(next, hint);
            points.push(next);
            p = next;
        }
        (points, false)
    };
    let (ahead, closed) = walk(1.0);
    let mut points = vec![first];
    if closed {
        points.extend(ahead);
        return points;
    }
    let (behind, _) = walk(-1.0);
    behind
        .into_iter()
        .rev()
        .chain(points)
        .chain(ahead)
        .collect()
}

/// A surface's mesh for drawing: vertex positions and unit normals (along
/// `∇C`, toward its positive side) in its local frame, and triangles
/// wound so that their front faces the positive side.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceMesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals toward the positive side.
    pub normals: Vec<[f32; 3]>,
    /// Triangles, three indices each, counter-clockwise seen from the
    /// positive side.
    pub indices: Vec<u32>,
}

/// Grid points along each axis of the box a surface is meshed in, with one
/// of padding on each side.
type Grid = ConstShape3u32<50, 50, 50>;

/// The spacing of the grid in a cube of half-size `half`.
fn cell(half: f64) -> f64 {
    2.0 * half / f64::from(Grid::ARRAY[0] - 1)
}

/// `surface` meshed where it crosses the cube of half-size `half` about
/// `centre` (local coordinates), by surface nets on a 50³ grid of its
/// values; the vertices' normals from its gradient. Empty where it does
/// not cross the cube; an unbounded surface is cut at the cube's faces.
pub fn surface_mesh(surface: &dyn ImplicitSurface, centre: DVec3, half: f64) -> SurfaceMesh {
    let n = Grid::ARRAY[0];
    let cell = cell(half);
    let lo = centre - DVec3::splat(half);
    let at =
        |g: [f32; 3]| lo + DVec3::new(f64::from(g[0]), f64::from(g[1]), f64::from(g[2])) * cell;
    let mut values = vec![0f32; Grid::USIZE];
    for (i, value) in values.iter_mut().enumerate() {
        let g = Grid::delinearize(i as u32).map(|k| k as f32);
        let c = surface.value(at(g)) as f32;
        *value = if c.is_finite() { c } else { f32::MAX };
    }
    let mut buffer = SurfaceNetsBuffer::default();
    surface_nets(&values, &Grid {}, [0; 3], [n - 1; 3], &mut buffer);
    let points: Vec<DVec3> = buffer.positions.iter().map(|&g| at(g)).collect();
    let normals: Vec<DVec3> = points
        .iter()
        .map(|&p| surface.gradient(p).normalize_or_zero())
        .collect();
    let mut indices = buffer.indices;
    for triangle in indices.chunks_exact_mut(3) {
        let [a, b, c] = [0, 1, 2].map(|k| points[triangle[k] as usize]);
        let facing = (b - a).cross(c - a);
        let outward: DVec3 = triangle.iter().map(|&k| normals[k as usize]).sum();
        if facing.dot(outward) < 0.0 {
            triangle.swap(1, 2);
        }
    }
    SurfaceMesh {
        positions: points.iter().map(|p| p.as_vec3().to_array()).collect(),
        normals: normals.iter().map(|p| p.as_vec3().to_array()).collect(),
        indices,
    }
}

/// `surface` meshed in the cube of half-size `half` about its origin, or,
/// where it reaches the cube's faces there but fits whole in twice the
/// cube (a torus larger than its beads' reach), in that: a bounded surface
/// is drawn whole, an unbounded one cut at the smaller cube.
pub fn fitted_surface_mesh(surface: &dyn ImplicitSurface, half: f64) -> SurfaceMesh {
    let touches = |mesh: &SurfaceMesh, half: f64| {
        mesh.positions.iter().any(|p| {
            let reach = p.iter().fold(0.0f64, |m, c| m.max(f64::from(c.abs())));
            reach >= half - 1.5 * cell(half)
        })
    };
    let mesh = surface_mesh(surface, DVec3::ZERO, half);
    if touches(&mesh, half) {
        let larger = surface_mesh(surface, DVec3::ZERO, 2.0 * half);
        if !larger.positions.is_empty() && !touches(&larger, 2.0 * half) {
            return larger;
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Circle, Helix, OnPlane, Sphere, Torus};

    #[test]
    fn a_circle_in_space_is_traced_closed_and_on_it() {
        let circle = OnPlane(Circle { radius: 1.5 });
        let points = curve_points(&circle, &[DVec3::new(2.0, 0.1, 0.3)], 20.0);
        assert!(points.len() > 20, "{} points", points.len());
        assert_eq!(points.first(), points.last(), "closed");
        for p in &points {
            assert!(
                (p.truncate().length() - 1.5).abs() < 1e-8 && p.z.abs() < 1e-8,
                "{p}"
            );
        }
        // Round once: the points' turn about z adds up to 2π.
        let turn: f64 = points
            .windows(2)
            .map(|w| w[0].truncate().angle_to(w[1].truncate()))
            .sum();
        assert!((turn.abs() - std::f64::consts::TAU).abs() < 1e-6, "{turn}");
    }

    #[test]
    fn an_open_helix_is_traced_both_ways_out_to_the_reach() {
        let helix = Helix {
            radius: 1.0,
            pitch: 1.0,
        };
        let reach = 5.0;
        let points = curve_points(&helix, &[DVec3::new(1.0, 0.0, 0.0)], reach);
        let ds = reach / 300.0;
        for p in &points {
            let [a, b] = helix.rows(*p, f64::NAN);
            assert!(a.c.hypot(b.c) < 1e-8);
            assert!(p.length() <= reach + ds, "{p}");
        }
        // Both ways from the start, nearly to the ball's edge, in steps
        // of about ds.
        let (low, high) = points
            .iter()
            .fold((0.0f64, 0.0f64), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
        assert!(low < -4.8 && high > 4.8, "{low} {high}");
        for w in points.windows(2) {
            assert!((w[0].distance(w[1]) - ds).abs() < 0.05 * ds);
        }
    }

    /// An open spline is traced from end to end and no farther: every
    /// point on it, the first and last within a step of its ends.
    #[test]
    fn an_open_spline_is_traced_to_its_ends_and_no_farther() {
        use crate::geometry::{Spline, SplineKind, SplineSpec};
        let points = vec![
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 0.5, 0.5),
            DVec3::new(2.0, 0.0, 0.0),
        ];
        let spline = Spline::<DVec3>::new(SplineSpec {
            kind: SplineKind::CatmullRom,
            points: points.clone(),
            closed: false,
        })
        .expect("a spline");
        let reach = 30.0;
        let traced = curve_points(&spline, &[points[1]], reach);
        let ds = reach / 300.0;
        for p in &traced {
            assert!(spline.past_end(*p, f64::NAN) <= 0.0, "{p} past an end");
        }
        let ends = [traced[0], traced[traced.len() - 1]];
        assert!(ends[0].distance(points[0]).min(ends[0].distance(points[2])) <= ds);
        assert!(ends[1].distance(points[0]).min(ends[1].distance(points[2])) <= ds);
        assert!(ends[0].distance(ends[1]) > 2.0, "both ways");
    }

    #[test]
    fn no_start_near_a_curve_traces_nothing() {
        let circle = OnPlane(Circle { radius: 1.0 });
        assert!(curve_points(&circle, &[DVec3::ZERO], 10.0).is_empty());
    }

    #[test]
    fn a_sphere_meshes_on_itself_facing_out() {
        let sphere = Sphere { radius: 0.8 };
        let mesh = surface_mesh(&sphere, DVec3::ZERO, 1.0);
        assert!(mesh.indices.len() > 3000, "{} indices", mesh.indices.len());
        // Surface nets place vertices within a grid cell of the surface.
        let cell = 2.0 / 49.0;
        for p in &mesh.positions {
            let r = bevy::math::Vec3::from(*p).length();
            assert!((f64::from(r) - 0.8).abs() < cell, "{r}");
        }
        // Every triangle faces outward.
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] =
                [0, 1, 2].map(|k| bevy::math::Vec3::from(mesh.positions[t[k] as usize]));
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
        }
    }

    #[test]
    fn a_bounded_surface_is_meshed_whole_and_an_unbounded_one_cut() {
        let torus = Torus {
            major_radius: 1.5,
            minor_radius: 0.5,
        };
        // The torus reaches 2 from its axis: a cube of half 1.2 cuts it,
        // the fitted mesh holds it whole.
        let whole = fitted_surface_mesh(&torus, 1.2);
        let reach = whole
            .positions
            .iter()
            .map(|p| p[0].abs().max(p[2].abs()))
            .fold(0.0f32, f32::max);
        assert!((reach - 2.0).abs() < 0.1, "{reach}");
        let plane = fitted_surface_mesh(&crate::geometry::Plane, 1.0);
        let reach = plane
            .positions
            .iter()
            .map(|p| p[0].abs())
            .fold(0.0f32, f32::max);
        assert!(reach <= 1.0, "{reach}");
    }

    #[test]
    fn a_torus_out_of_the_box_meshes_to_nothing() {
        let torus = Torus {
            major_radius: 1.0,
            minor_radius: 0.2,
        };
        let far = surface_mesh(&torus, DVec3::new(10.0, 0.0, 0.0), 1.0);
        assert!(far.indices.is_empty() && far.positions.is_empty());
        assert!(!surface_mesh(&torus, DVec3::ZERO, 1.5).indices.is_empty());
    }
}
