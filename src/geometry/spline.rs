//! [`Spline`]: Bevy's cubic curves as wires.

use std::sync::Arc;

use bevy::math::cubic_splines::{
    CubicBSpline, CubicCardinalSpline, CubicCurve, CubicGenerator, CubicHermite,
    CyclicCubicGenerator,
};
use bevy::math::{DMat2, DVec2, Vec2};
use serde::{Deserialize, Serialize};

use super::{Geometry, ImplicitCurve, Parametric, Traced};
use crate::validate::ParamError;

/// How a spline's points make its curve (Bevy's generators of
/// `bevy::math::cubic_splines`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum SplineKind {
    /// Catmull–Rom: through every point (the cardinal spline of tension ½).
    #[default]
    CatmullRom,
    /// A cardinal spline of the given tension, through every point.
    Cardinal(f64),
    /// A uniform cubic B-spline: near the points, smooth to the second
    /// derivative.
    BSpline,
    /// Hermite: through every point with the given tangent at each.
    Hermite(Vec<DVec2>),
    /// A curve's own polynomial coefficients `[a, b, c, d]` per segment
    /// (`a + b u + c u² + d u³`), as [`Spline::from_curve`] keeps a
    /// game's `CubicCurve`.
    Segments(Vec<[DVec2; 4]>),
}

/// What a scene file says of a spline:
/// `Spline((points: [(0.0, 1.0), …], kind: CatmullRom, closed: false))`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SplineSpec {
    /// How the points make the curve.
    pub kind: SplineKind,
    /// The control points (none for `Segments`).
    pub points: Vec<DVec2>,
    /// Whether the curve closes on itself (a cyclic spline).
    pub closed: bool,
}

/// A wire along a Bevy cubic curve (`CubicCurve<Vec2>`, from Hermite,
/// cardinal or B-spline points), by its signed distance (see [`Traced`]):
/// positive to the left of the direction the points run in (above a track
/// drawn left to right, inside a closed loop drawn counter-clockwise). An
/// open spline ends at its first and last points, a closed one goes round.
/// The curve's coefficients are Bevy's (`f32`), held in `f64`.
#[derive(Clone, Serialize, Deserialize)]
#[serde(try_from = "SplineSpec", into = "SplineSpec")]
pub struct Spline {
    spec: SplineSpec,
    traced: Arc<Traced<CubicPath>>,
}

impl std::fmt::Debug for Spline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.spec.fmt(f)
    }
}

impl PartialEq for Spline {
    fn eq(&self, other: &Self) -> bool {
        self.spec == other.spec
    }
}

impl From<Spline> for SplineSpec {
    fn from(spline: Spline) -> Self {
        spline.spec
    }
}

impl TryFrom<SplineSpec> for Spline {
    type Error = ParamError;
    fn try_from(spec: SplineSpec) -> Result<Self, ParamError> {
        Self::new(spec)
    }
}

/// Refused spline input.
fn refuse(what: &'static str) -> ParamError {
    ParamError::Incompatible(what)
}

impl Spline {
    /// The spline `spec` describes, if its points make a curve.
    pub fn new(spec: SplineSpec) -> Result<Self, ParamError> {
        if spec.points.iter().any(|p| !p.is_finite()) {
            return Err(refuse("a spline's points must be finite"));
        }
        let points: Vec<Vec2> = spec.points.iter().map(|p| p.as_vec2()).collect();
        let too_few = |_| {
            refuse(
                "a spline needs more points (a cubic spline needs at least two, a B-spline four)",
            )
        };
        let curve = match &spec.kind {
            SplineKind::CatmullRom | SplineKind::Cardinal(_) => {
                let tension = match spec.kind {
                    SplineKind::Cardinal(t) => t as f32,
                    _ => 0.5,
                };
                if !tension.is_finite() {
                    return Err(refuse("a cardinal spline's tension must be finite"));
                }
                let spline = CubicCardinalSpline::new(tension, points);
                if spec.closed {
                    spline.to_curve_cyclic().map_err(too_few)?
                } else {
                    spline.to_curve().map_err(too_few)?
                }
            }
            SplineKind::BSpline => {
                let spline = CubicBSpline::new(points);
                if spec.closed {
                    spline.to_curve_cyclic().map_err(too_few)?
                } else {
                    spline.to_curve().map_err(too_few)?
                }
            }
            SplineKind::Hermite(tangents) => {
                if tangents.len() != points.len() || tangents.iter().any(|t| !t.is_finite()) {
                    return Err(refuse(
                        "a Hermite spline needs one finite tangent for each point",
                    ));
                }
                let spline = CubicHermite::new(points, tangents.iter().map(|t| t.as_vec2()));
                if spec.closed {
                    spline.to_curve_cyclic().map_err(too_few)?
                } else {
                    spline.to_curve().map_err(too_few)?
                }
            }
            SplineKind::Segments(segments) => {
                if segments.is_empty() || segments.iter().flatten().any(|c| !c.is_finite()) {
                    return Err(refuse(
                        "a spline's segments must be finite, and one at least",
                    ));
                }
                return Ok(Self::from_segments(segments.clone(), spec.closed));
            }
        };
        let mut made = Self::from_curve(&curve);
        made.spec = SplineSpec {
            closed: spec.closed,
            ..spec
        };
        Ok(made)
    }

    /// A wire along a game's own curve (its segments' coefficients, kept
    /// in `f64`). It is closed if it ends where it starts (within 1e-6 of
    /// its size).
    pub fn from_curve(curve: &CubicCurve<Vec2>) -> Self {
        let segments: Vec<[DVec2; 4]> = curve
            .segments()
            .iter()
            .map(|s| s.coeff.map(|c| c.as_dvec2()))
            .collect();
        let start = segments[0][0];
        let [a, b, c, d] = segments[segments.len() - 1];
        let end = a + b + c + d;
        let size = segments
            .iter()
            .map(|s| (s[1] + s[2] + s[3]).length())
            .sum::<f64>();
        let closed = (end - start).length() <= 1e-6 * size.max(f64::MIN_POSITIVE);
        Self::from_segments(segments, closed)
    }

    fn from_segments(segments: Vec<[DVec2; 4]>, closed: bool) -> Self {
        let path = CubicPath {
            segments: segments.clone(),
            closed,
        };
        Self {
            spec: SplineSpec {
                kind: SplineKind::Segments(segments),
                points: Vec::new(),
                closed,
            },
            traced: Arc::new(Traced::new(path)),
        }
    }

    /// What it was made from.
    pub fn spec(&self) -> &SplineSpec {
        &self.spec
    }

    /// Points along the curve, for drawing.
    pub fn polyline(&self) -> impl Iterator<Item = DVec2> + '_ {
        self.traced.polyline()
    }

    /// The curve's point at parameter `s` (segment `floor(s)`).
    pub fn point(&self, s: f64) -> DVec2 {
        self.traced.path().eval(s)[0]
    }

    /// Its lowest sampled point.
    pub fn lowest(&self) -> DVec2 {
        self.polyline()
            .min_by(|a, b| a.y.total_cmp(&b.y))
            .unwrap_or_default()
    }
}

/// A chain of cubic segments in `f64`, `s ∈ [0, n]`.
#[derive(Clone, Debug)]
pub struct CubicPath {
    segments: Vec<[DVec2; 4]>,
    closed: bool,
}

impl Parametric for CubicPath {
    fn domain(&self) -> (f64, f64) {
        (0.0, self.segments.len() as f64)
    }
    fn closed(&self) -> bool {
        self.closed
    }
    fn eval(&self, s: f64) -> [DVec2; 3] {
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

impl ImplicitCurve for Spline {
    fn value(&self, p: DVec2) -> f64 {
        self.traced.value(p)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.traced.gradient(p)
    }
    fn hessian(&self, p: DVec2) -> DMat2 {
        self.traced.hessian(p)
    }
    fn scale(&self) -> f64 {
        self.traced.scale()
    }
    fn geometry(&self, p: DVec2) -> Geometry {
        self.traced.geometry(p)
    }
    fn has_ends(&self) -> bool {
        self.traced.has_ends()
    }
    fn past_end(&self, p: DVec2) -> f64 {
        self.traced.past_end(p)
    }
}
