//! Rotation-minimizing normals along a sampled curve: the normal a rail
//! carries without turning it about the curve, by double reflection
//! (Wang, Jüttler, Zheng and Liu, "Computation of rotation minimizing
//! frames", 2008), fourth order in the sample spacing.

use super::Coordinates;
use super::coordinates::norm;

/// `v` less its component along the unit vector `t`, made unit; zero if
/// nothing is left.
pub(crate) fn perpendicular<V: Coordinates>(v: V, t: V) -> V {
    let across = v - t * v.dot(t);
    let size = norm(across);
    if size > 1e-9 * norm(v) && size > 0.0 {
        across / size
    } else {
        V::ZERO
    }
}

/// A unit normal to `t` as near `up` as there is: `up`'s part across `t`,
/// or, where `up` runs along `t`, that of the first axis that does not.
fn start_normal<V: Coordinates>(t: V, up: V) -> V {
    let axes = [
        bevy::math::DVec3::Y,
        bevy::math::DVec3::X,
        bevy::math::DVec3::Z,
    ];
    std::iter::once(up)
        .chain(axes.map(V::from_xyz))
        .map(|v| perpendicular(v, t))
        .find(|n| n.dot(*n) > 0.0)
        .unwrap_or(V::ZERO)
}

/// The rotation-minimizing normal at each of `points` (with unit
/// `tangents` there), starting from the normal nearest `up`. On a closed
/// curve (the last point the first) the turn the normal gathers round the
/// loop is spread evenly back over it, so that it closes.
pub(crate) fn rotation_minimizing<V: Coordinates>(
    points: &[V],
    tangents: &[V],
    up: V,
    closed: bool,
) -> Vec<V> {
    let Some(&t0) = tangents.first() else {
        return Vec::new();
    };
    let mut normals = Vec::with_capacity(points.len());
    normals.push(start_normal(t0, up));
    for i in 0..points.len() - 1 {
        let r = normals[i];
        let (t, next) = (tangents[i], tangents[i + 1]);
        let v1 = points[i + 1] - points[i];
        let c1 = v1.dot(v1);
        let normal = if c1 > 0.0 {
            let reflected = r - v1 * (2.0 / c1 * v1.dot(r));
            let t_reflected = t - v1 * (2.0 / c1 * v1.dot(t));
            let v2 = next - t_reflected;
            let c2 = v2.dot(v2);
            if c2 > 0.0 {
                reflected - v2 * (2.0 / c2 * v2.dot(reflected))
            } else {
                reflected
            }
        } else {
            r
        };
        let normal = perpendicular(normal, next);
        normals.push(if normal.dot(normal) > 0.0 {
            normal
        } else {
            start_normal(next, r)
        });
    }
    let last = normals.len() - 1;
    if closed && last > 0 {
        let (first, end) = (normals[0], normals[last]);
        let gap = V::binormal(t0, end).dot(first).atan2(end.dot(first));
        for (i, (n, t)) in normals.iter_mut().zip(tangents).enumerate() {
            let turn = gap * i as f64 / last as f64;
            *n = *n * turn.cos() + V::binormal(*t, *n) * turn.sin();
        }
    }
    normals
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::math::DVec3;
    use std::f64::consts::TAU;

    /// `n + 1` points of a curve over `θ ∈ [0, 2π]` and its unit tangents,
    /// from `curve(θ) = (γ, γ′)`.
    fn sampled(n: usize, curve: impl Fn(f64) -> (DVec3, DVec3)) -> (Vec<DVec3>, Vec<DVec3>) {
        (0..=n)
            .map(|i| {
                let (p, d) = curve(TAU * i as f64 / n as f64);
                (p, d.normalize())
            })
            .unzip()
    }

    /// Along a helix the rotation-minimizing normal turns about the
    /// tangent against the Frenet normal at the torsion's rate: after one
    /// turn of a helix of radius 1 and pitch 2π (torsion ½, arc length
    /// 2π√2), it has turned π√2 from where the Frenet frame's normal is.
    #[test]
    fn a_helixs_rotation_minimizing_normal_turns_by_its_torsion() {
        let n = 4000;
        let (points, tangents) = sampled(n, |th| {
            (
                DVec3::new(th.cos(), th, th.sin()),
                DVec3::new(-th.sin(), 1.0, th.cos()),
            )
        });
        // Start along the Frenet normal, towards the axis.
        let normals = rotation_minimizing(&points, &tangents, DVec3::new(-1.0, 0.0, 0.0), false);
        let frenet = DVec3::new(-1.0, 0.0, 0.0);
        let end = normals[n];
        let binormal = tangents[n].cross(frenet);
        let angle = end.dot(binormal).atan2(end.dot(frenet)).abs();
        let expected = std::f64::consts::PI * 2f64.sqrt() - TAU;
        let wrapped = (angle - expected.abs()).abs();
        assert!(wrapped < 1e-9, "turned {angle}, against {expected}");
        for (r, t) in normals.iter().zip(&tangents) {
            assert!(r.dot(*t).abs() < 1e-14 && (r.length() - 1.0).abs() < 1e-14);
        }
    }

    /// On a closed loop the normals close: the last is the first.
    #[test]
    fn a_closed_loops_normals_close() {
        let n = 600;
        // A loop out of its plane: a saddle.
        let (points, tangents) = sampled(n, |th| {
            (
                DVec3::new(th.cos(), 0.3 * (2.0 * th).sin(), th.sin()),
                DVec3::new(-th.sin(), 0.6 * (2.0 * th).cos(), th.cos()),
            )
        });
        let normals = rotation_minimizing(&points, &tangents, DVec3::Y, true);
        assert!((normals[n] - normals[0]).length() < 1e-12);
    }
}
