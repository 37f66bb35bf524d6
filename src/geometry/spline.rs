//! [`Spline`]: Bevy's cubic curves as wires.

use std::sync::Arc;

use bevy::math::cubic_splines::CubicCurve;
use bevy::math::{DVec2, VectorSpace};
use serde::{Deserialize, Serialize};

use super::coordinates::norm;
use super::traced::delegate_curve;
use super::{Coordinates, Parametric, Traced};
use crate::validate::ParamError;

/// How a spline's points make its curve (Bevy's generators of
/// `bevy::math::cubic_splines`), in the plane (the default) or in space.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum SplineKind<V = DVec2> {
    /// Catmull–Rom: through every point (the cardinal spline of tension ½).
    #[default]
    CatmullRom,
    /// A cardinal spline of the given tension, through every point.
    Cardinal(f64),
    /// A uniform cubic B-spline: near the points, smooth to the second
    /// derivative.
    BSpline,
    /// Hermite: through every point with the given tangent at each.
    Hermite(Vec<V>),
    /// A curve's own polynomial coefficients `[a, b, c, d]` per segment
    /// (`a + b u + c u² + d u³`), as [`Spline::from_curve`] keeps a
    /// game's `CubicCurve`.
    Segments(Vec<[V; 4]>),
}

/// What a scene file says of a spline:
/// `Spline((points: [(0.0, 1.0), …], kind: CatmullRom, closed: false))`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct SplineSpec<V = DVec2> {
    /// How the points make the curve.
    pub kind: SplineKind<V>,
    /// The control points (none for `Segments`).
    pub points: Vec<V>,
    /// Whether the curve closes on itself (a cyclic spline).
    pub closed: bool,
}

/// A wire along a Bevy cubic curve (`CubicCurve<Vec2>`, from Hermite,
/// cardinal or B-spline points), by its signed distance (see [`Traced`]):
/// positive to the left of the direction the points run in (above a track
/// drawn left to right, inside a closed loop drawn counter-clockwise). An
/// open spline ends at its first and last points, a closed one goes round.
/// A scene's spline is computed as Bevy computes it, in `f64`; a game's
/// `CubicCurve` keeps its `f32` coefficients, held in `f64`.
///
/// `Spline<DVec3>` is the same curve in space (`CubicCurve<Vec3>`), a
/// wire by its offset along two normals (see
/// [`SpaceCurve`](super::SpaceCurve)).
#[derive(Clone, Serialize, Deserialize)]
#[serde(try_from = "SplineSpec<V>", into = "SplineSpec<V>")]
#[serde(bound(
    serialize = "V: Coordinates + Serialize",
    deserialize = "V: Coordinates + Deserialize<'de>"
))]
pub struct Spline<V: Coordinates = DVec2>(Arc<SplineInner<V>>);

/// What a [`Spline`] shares between its clones: kept behind one pointer so
/// that a [`WireShape`](super::WireShape) stays small.
struct SplineInner<V: Coordinates> {
    spec: SplineSpec<V>,
    traced: Traced<CubicPath<V>, V>,
}

impl<V: Coordinates> std::fmt::Debug for Spline<V> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.spec.fmt(f)
    }
}

impl<V: Coordinates> PartialEq for Spline<V> {
    fn eq(&self, other: &Self) -> bool {
        self.0.spec == other.0.spec
    }
}

impl<V: Coordinates> From<Spline<V>> for SplineSpec<V> {
    fn from(spline: Spline<V>) -> Self {
        spline.0.spec.clone()
    }
}

impl<V: Coordinates> TryFrom<SplineSpec<V>> for Spline<V> {
    type Error = ParamError;
    fn try_from(spec: SplineSpec<V>) -> Result<Self, ParamError> {
        Self::new(spec)
    }
}

/// Refused spline input.
fn refuse(what: &'static str) -> ParamError {
    ParamError::Incompatible(what)
}

/// Bevy's characteristic matrix of the cubic Hermite spline.
const HERMITE: [[f64; 4]; 4] = [
    [1., 0., 0., 0.],
    [0., 1., 0., 0.],
    [-3., -2., 3., -1.],
    [2., 1., -2., 1.],
];

/// Six times Bevy's characteristic matrix of the uniform B-spline.
const B_SPLINE: [[f64; 4]; 4] = [
    [1.0, 4.0, 1.0, 0.0],
    [-3.0, 0.0, 3.0, 0.0],
    [3.0, -6.0, 3.0, 0.0],
    [-1.0, 3.0, -3.0, 1.0],
];

/// A segment's coefficients: the characteristic matrix times the points.
fn coefficients<V: Coordinates>(p: [V; 4], matrix: [[f64; 4]; 4]) -> [V; 4] {
    matrix.map(|row| p[0] * row[0] + p[1] * row[1] + p[2] * row[2] + p[3] * row[3])
}

/// Bevy's cardinal spline of tension `s` through `points`: open, with the
/// ends mirrored (`P₋₁ = 2P₀ − P₁`); closed, with its segments in the
/// order `to_curve_cyclic` gives them (the first from the first point to
/// the second).
fn cardinal<V: Coordinates>(s: f64, points: &[V], closed: bool) -> Result<Vec<[V; 4]>, ParamError> {
    let n = points.len();
    if n < 2 {
        return Err(refuse("a cardinal spline needs two points at least"));
    }
    let matrix = [
        [0., 1., 0., 0.],
        [-s, 0., s, 0.],
        [2. * s, s - 3., 3. - 2. * s, -s],
        [-s, 2. - s, s - 2., s],
    ];
    if closed {
        let at = |i: usize| points[i % n];
        let first = coefficients([points[n - 1], points[0], at(1), at(2)], matrix);
        let later =
            (0..n - 1).map(|i| coefficients([at(i), at(i + 1), at(i + 2), at(i + 3)], matrix));
        return Ok(std::iter::once(first).chain(later).collect());
    }
    let mut extended = Vec::with_capacity(n + 2);
    extended.push(points[0] * 2.0 - points[1]);
    extended.extend_from_slice(points);
    extended.push(points[n - 1] * 2.0 - points[n - 2]);
    Ok(extended
        .windows(4)
        .map(|w| coefficients([w[0], w[1], w[2], w[3]], matrix))
        .collect())
}

impl<V: Coordinates> Spline<V> {
    /// The spline `spec` describes, if its points make a curve: Bevy's
    /// generator of that kind (`CubicCardinalSpline`, `CubicBSpline`,
    /// `CubicHermite`, with `to_curve` or, closed, `to_curve_cyclic`),
    /// computed in `f64` with the same characteristic matrices, end
    /// mirroring and segment order, so a scene's points lie on the wire
    /// exactly.
    pub fn new(spec: SplineSpec<V>) -> Result<Self, ParamError> {
        let points = &spec.points;
        if points.iter().any(|p| !p.is_finite()) {
            return Err(refuse("a spline's points must be finite"));
        }
        let segments = match &spec.kind {
            SplineKind::CatmullRom => cardinal(0.5, points, spec.closed)?,
            SplineKind::Cardinal(tension) => {
                if !tension.is_finite() {
                    return Err(refuse("a cardinal spline's tension must be finite"));
                }
                cardinal(*tension, points, spec.closed)?
            }
            SplineKind::BSpline => {
                let matrix = B_SPLINE.map(|row| row.map(|c| c / 6.0));
                let n = points.len();
                if (spec.closed && n < 2) || (!spec.closed && n < 4) {
                    return Err(refuse(
                        "a B-spline needs four points at least (two when closed)",
                    ));
                }
                let count = if spec.closed { n } else { n - 3 };
                (0..count)
                    .map(|i| coefficients(std::array::from_fn(|k| points[(i + k) % n]), matrix))
                    .collect()
            }
            SplineKind::Hermite(tangents) => {
                if tangents.len() != points.len() || tangents.iter().any(|t| !t.is_finite()) {
                    return Err(refuse(
                        "a Hermite spline needs one finite tangent for each point",
                    ));
                }
                let n = points.len();
                if n < 2 {
                    return Err(refuse("a Hermite spline needs two points at least"));
                }
                let count = if spec.closed { n } else { n - 1 };
                (0..count)
                    .map(|i| {
                        let j = (i + 1) % n;
                        coefficients([points[i], tangents[i], points[j], tangents[j]], HERMITE)
                    })
                    .collect()
            }
            SplineKind::Segments(segments) => {
                if segments.is_empty() || segments.iter().flatten().any(|c| !c.is_finite()) {
                    return Err(refuse(
                        "a spline's segments must be finite, and one at least",
                    ));
                }
                segments.clone()
            }
        };
        Ok(Self::from_segments(segments, spec.closed, Some(spec)))
    }

    /// A wire along a game's own curve (its segments' coefficients, kept
    /// in `f64`): a `CubicCurve<Vec2>` in the plane, a `CubicCurve<Vec3>`
    /// in space. It is closed if it ends where it starts (within 1e-6 of
    /// its size).
    pub fn from_curve<P>(curve: &CubicCurve<P>) -> Self
    where
        P: VectorSpace<Scalar = f32>,
        V: From<P>,
    {
        let segments: Vec<[V; 4]> = curve
            .segments()
            .iter()
            .map(|s| s.coeff.map(V::from))
            .collect();
        let start = segments[0][0];
        let [a, b, c, d] = segments[segments.len() - 1];
        let end = a + b + c + d;
        let size = segments
            .iter()
            .map(|s| norm(s[1] + s[2] + s[3]))
            .sum::<f64>();
        let closed = norm(end - start) <= 1e-6 * size.max(f64::MIN_POSITIVE);
        Self::from_segments(segments, closed, None)
    }

    /// A spline of these segments, described by `spec` (by the segments
    /// themselves if none).
    fn from_segments(segments: Vec<[V; 4]>, closed: bool, spec: Option<SplineSpec<V>>) -> Self {
        let path = CubicPath {
            segments: segments.clone(),
            closed,
        };
        let spec = spec.unwrap_or(SplineSpec {
            kind: SplineKind::Segments(segments),
            points: Vec::new(),
            closed,
        });
        Self(Arc::new(SplineInner {
            spec,
            traced: Traced::new(path),
        }))
    }

    /// What it was made from.
    pub fn spec(&self) -> &SplineSpec<V> {
        &self.0.spec
    }

    /// The curve as a wire.
    pub(crate) fn traced(&self) -> &Traced<CubicPath<V>, V> {
        &self.0.traced
    }

    /// Its segments' coefficients, as [`SplineKind::Segments`].
    pub fn traced_segments(&self) -> SplineKind<V> {
        SplineKind::Segments(self.traced().path().segments.clone())
    }

    /// Points along the curve, for drawing.
    pub fn polyline(&self) -> impl Iterator<Item = V> + '_ {
        self.traced().polyline()
    }

    /// The curve's point at parameter `s` (segment `floor(s)`).
    pub fn point(&self, s: f64) -> V {
        self.traced().path().eval(s)[0]
    }

    /// Its lowest sampled point.
    pub fn lowest(&self) -> V {
        self.polyline()
            .min_by(|a, b| a.xyz().y.total_cmp(&b.xyz().y))
            .unwrap_or_default()
    }
}

/// A chain of cubic segments in `f64`, `s ∈ [0, n]`.
#[derive(Clone, Debug)]
pub struct CubicPath<V = DVec2> {
    segments: Vec<[V; 4]>,
    closed: bool,
}

impl<V: Coordinates> Parametric<V> for CubicPath<V> {
    fn domain(&self) -> (f64, f64) {
        (0.0, self.segments.len() as f64)
    }
    fn closed(&self) -> bool {
        self.closed
    }
    fn eval(&self, s: f64) -> [V; 3] {
        let last = self.segments.len() - 1;
        let i = (s.floor().max(0.0) as usize).min(last);
        let u = s - i as f64;
        let [a, b, c, d] = self.segments[i];
        [
            a + (b + (c + d * u) * u) * u,
            b + (c * 2.0 + d * (3.0 * u)) * u,
            c * 2.0 + d * (6.0 * u),
        ]
    }
}

delegate_curve!(Spline, |this| this.traced(), this.traced().scale());

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::ImplicitCurve;
    use bevy::math::Vec2;
    use bevy::math::cubic_splines::{
        CubicBSpline, CubicCardinalSpline, CubicGenerator, CubicHermite, CyclicCubicGenerator,
    };

    #[test]
    fn a_spline_without_enough_finite_points_is_refused_in_words() {
        let spline = |points: Vec<DVec2>| {
            Spline::new(SplineSpec {
                kind: SplineKind::CatmullRom,
                points,
                closed: false,
            })
            .unwrap_err()
            .to_string()
        };
        assert_eq!(
            spline(vec![DVec2::ZERO]),
            "a cardinal spline needs two points at least"
        );
        assert_eq!(
            spline(vec![DVec2::ZERO, DVec2::new(f64::NAN, 1.0)]),
            "a spline's points must be finite"
        );
    }

    /// Every kind, open and closed, has the coefficients Bevy's own
    /// generator gives (in `f32`), and a scene's points lie on the curve.
    #[test]
    fn splines_match_bevys_generators() {
        let points: Vec<DVec2> = [(0.0, 0.0), (1.0, 2.0), (3.0, 1.5), (4.0, -1.0), (6.0, 0.5)]
            .map(|(x, y)| DVec2::new(x, y))
            .to_vec();
        let tangents: Vec<DVec2> = points.iter().map(|p| DVec2::new(1.0, -p.y)).collect();
        let f32s = |v: &[DVec2]| v.iter().map(|p| p.as_vec2()).collect::<Vec<_>>();
        for closed in [false, true] {
            let bevy = |curve: CubicCurve<Vec2>| -> Vec<[DVec2; 4]> {
                curve
                    .segments()
                    .iter()
                    .map(|s| s.coeff.map(|c| c.as_dvec2()))
                    .collect()
            };
            let cardinal = CubicCardinalSpline::new(0.3, f32s(&points));
            let catmull = CubicCardinalSpline::new_catmull_rom(f32s(&points));
            let b = CubicBSpline::new(f32s(&points));
            let hermite = CubicHermite::new(f32s(&points), f32s(&tangents));
            let cases = [
                (
                    SplineKind::Cardinal(0.3),
                    if closed {
                        cardinal.to_curve_cyclic()
                    } else {
                        cardinal.to_curve()
                    }
                    .unwrap(),
                ),
                (
                    SplineKind::CatmullRom,
                    if closed {
                        catmull.to_curve_cyclic()
                    } else {
                        catmull.to_curve()
                    }
                    .unwrap(),
                ),
                (
                    SplineKind::BSpline,
                    if closed {
                        b.to_curve_cyclic()
                    } else {
                        b.to_curve()
                    }
                    .unwrap(),
                ),
                (
                    SplineKind::Hermite(tangents.clone()),
                    if closed {
                        hermite.to_curve_cyclic()
                    } else {
                        hermite.to_curve()
                    }
                    .unwrap(),
                ),
            ];
            for (kind, curve) in cases {
                let ours = Spline::new(SplineSpec {
                    kind: kind.clone(),
                    points: points.clone(),
                    closed,
                })
                .unwrap();
                let SplineKind::Segments(mine) = &ours.traced_segments() else {
                    unreachable!()
                };
                let theirs = bevy(curve);
                assert_eq!(mine.len(), theirs.len(), "{kind:?} closed {closed}");
                for (a, b) in mine.iter().flatten().zip(theirs.iter().flatten()) {
                    assert!(
                        (*a - *b).length() < 1e-5,
                        "{kind:?} closed {closed}: {a} vs {b}"
                    );
                }
                if !matches!(kind, SplineKind::BSpline) {
                    for p in &points[1..points.len() - 1] {
                        assert!(ours.value(*p).abs() < 1e-12, "{kind:?}: {p} off the curve");
                    }
                }
            }
        }
    }
}
