//! Curves given by a parametrization `γ(s)`, made wires by their signed
//! distance: [`Parametric`], [`Traced`].
//!
//! `C(x) = n̂(s*)·(x − γ(s*))`, with `s*` the parameter of the point of the
//! curve nearest `x` and `n̂` the unit normal to the left of the direction
//! of travel. Then `∇C = n̂(s*)` exactly (a unit vector: `C` reads as a
//! distance), and with the signed curvature `κ`,
//!
//! ```text
//! H = −κ / (1 − κ C) · t̂ t̂ᵀ
//! ```
//!
//! `C` vanishes exactly on the curve, so every method holds a bead on it as
//! it holds one on a circle: to rounding for RATTLE and projection. The
//! nearest point is found by Newton's method on `(γ(s) − x)·γ′(s) = 0`
//! from the nearest of a polyline of samples, kept inside the samples'
//! bracket, to the last bit. The form is singular where `1 − κ C` vanishes
//! (at a centre of curvature, far off the curve) and where `γ′` does (a
//! cusp): there the normal is reported as zero, a singular point.
//!
//! An open curve goes on past its ends along its end tangents, so `C` stays
//! smooth; [`ImplicitCurve::past_end`] says how far past an end the nearest
//! point lies, and a lone bead that passes an end leaves the wire there
//! (see [`crate::solver::step_surface`]). A closed curve has no end.

use bevy::math::{DMat2, DVec2};

use super::coordinates::norm;
use super::frames::{perpendicular, rotation_minimizing};
use super::{Coordinates, Geometry, ImplicitCurve};

/// A curve `γ(s)` over a parameter interval, in the plane (the default)
/// or in space.
pub trait Parametric<V: Coordinates = DVec2> {
    /// The parameter's interval `[start, end]`.
    fn domain(&self) -> (f64, f64);
    /// Whether `γ(end) = γ(start)` and the curve goes on round.
    fn closed(&self) -> bool;
    /// `γ(s)`, `γ′(s)` and `γ″(s)`.
    fn eval(&self, s: f64) -> [V; 3];
}

/// How many samples per unit of parameter the polyline takes.
const SAMPLES_PER_UNIT: f64 = 24.0;

/// How far in parameter from a hint the nearest-point search looks.
const HINT_WINDOW: f64 = 0.75;

/// A [`Parametric`] curve as a wire: by its signed distance in the plane,
/// by its offset along two normals in space (see
/// [`SpaceCurve`](super::SpaceCurve)).
#[derive(Clone, Debug)]
pub struct Traced<P, V: Coordinates = DVec2> {
    path: P,
    /// `(s, γ(s))` along the curve.
    samples: Vec<(f64, V)>,
    /// The rotation-minimizing normal at each sample (see
    /// [`Traced::with_up`]).
    normals: Vec<V>,
    /// The longest distance between neighbouring samples.
    spacing: f64,
    scale: f64,
}

/// The point of a curve nearest some `x`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Nearest<V> {
    /// `s*`.
    pub(crate) s: f64,
    /// `γ(s*)`, `γ′(s*)`, `γ″(s*)` (or, past an end, the end's point and
    /// tangent and no curvature).
    pub(crate) at: [V; 3],
    /// How far past an end along its tangent line the nearest point of the
    /// extended curve lies; zero or less on the curve.
    pub(crate) past: f64,
}

impl<V: Coordinates, P: Parametric<V>> Traced<P, V> {
    /// The curve `path` as a wire, with a polyline of samples to start the
    /// nearest-point search from; its rail normal starts as near `+y` as
    /// there is.
    pub fn new(path: P) -> Self {
        Self::with_up(path, V::from_xyz(bevy::math::DVec3::Y))
    }

    /// The curve `path` as a wire whose rotation-minimizing normal (the
    /// first of its two rows in space, and the up of a rail's frame)
    /// starts as near `up` as there is at the curve's start. On a closed
    /// curve the turn it gathers round the loop is spread over the loop.
    pub fn with_up(path: P, up: V) -> Self {
        let (start, end) = path.domain();
        let n = (((end - start) * SAMPLES_PER_UNIT).ceil() as usize).clamp(16, 1 << 16);
        let (mut samples, mut tangents) = (Vec::with_capacity(n + 1), Vec::with_capacity(n + 1));
        for i in 0..=n {
            let s = start + (end - start) * i as f64 / n as f64;
            let [point, d1, _] = path.eval(s);
            samples.push((s, point));
            tangents.push(d1 / norm(d1).max(f64::MIN_POSITIVE));
        }
        let gaps = || samples.windows(2).map(|w| norm(w[1].1 - w[0].1));
        let length: f64 = gaps().sum();
        let spacing = gaps().fold(0.0, f64::max);
        let scale = (length / (end - start).max(1.0)).max(f64::MIN_POSITIVE);
        let points: Vec<V> = samples.iter().map(|(_, p)| *p).collect();
        let normals = rotation_minimizing(&points, &tangents, up, path.closed());
        Self {
            path,
            samples,
            normals,
            spacing,
            scale,
        }
    }

    /// The curve's rotation-minimizing normal at parameter `s`, across the
    /// unit tangent `tangent` there: the samples' normals interpolated and
    /// made perpendicular to it.
    pub(crate) fn normal_at(&self, s: f64, tangent: V) -> V {
        let (start, end) = self.path.domain();
        let last = self.samples.len() - 1;
        let at = ((s - start) / (end - start) * last as f64).clamp(0.0, last as f64);
        let i = (at.floor() as usize).min(last.saturating_sub(1));
        let u = at - i as f64;
        let j = (i + 1).min(last);
        let blend = self.normals[i] * (1.0 - u) + self.normals[j] * u;
        perpendicular(blend, tangent)
    }

    /// The characteristic length: its length per unit of parameter.
    pub fn length_scale(&self) -> f64 {
        self.scale
    }

    /// The parametrized curve.
    pub fn path(&self) -> &P {
        &self.path
    }

    /// The sample points, in order (for drawing).
    pub fn polyline(&self) -> impl Iterator<Item = V> + '_ {
        self.samples.iter().map(|(_, p)| *p)
    }

    /// The sample nearest `x` among those within [`HINT_WINDOW`] of the
    /// parameter `hint` (on a curve that crosses itself, the branch the
    /// bead is on); none if the hint is not finite or the window's nearest
    /// sample is at its edge (the bead went farther: the whole curve is
    /// searched).
    fn windowed_sample(&self, x: V, hint: f64) -> Option<usize> {
        let last = self.samples.len() - 1;
        let distance = |i: usize| {
            let d = self.samples[i].1 - x;
            d.dot(d)
        };
        if !hint.is_finite() {
            return None;
        }
        let (start, end) = self.path.domain();
        let per_unit = last as f64 / (end - start);
        let centre = ((hint - start) * per_unit).round() as i64;
        let reach = (HINT_WINDOW * per_unit).ceil() as i64;
        let closed = self.path.closed();
        let index = |k: i64| {
            if closed {
                Some(k.rem_euclid(last as i64) as usize)
            } else {
                usize::try_from(k).ok().filter(|&i| i <= last)
            }
        };
        let best = (centre - reach..=centre + reach)
            .filter_map(|k| index(k).map(|i| (k, i)))
            .min_by(|a, b| distance(a.1).total_cmp(&distance(b.1)));
        match best {
            Some((k, i)) if (k - centre).abs() < reach || i == 0 || i == last => Some(i),
            _ => None,
        }
    }

    /// The nearest point to `x`: from the hint's window if it has one,
    /// else refined from every sample that is a local minimum of the
    /// distance within one sample spacing of the nearest (near a crossing,
    /// both branches), the nearest of those.
    pub(crate) fn nearest(&self, x: V, hint: f64) -> Nearest<V> {
        if let Some(i) = self.windowed_sample(x, hint) {
            return self.refine(x, i);
        }
        let distance: Vec<f64> = self.samples.iter().map(|(_, p)| norm(*p - x)).collect();
        let best = distance.iter().copied().fold(f64::INFINITY, f64::min);
        let last = distance.len() - 1;
        let closed = self.path.closed();
        let minimum = |i: usize| {
            let before = match (i, closed) {
                (0, true) => distance[last - 1],
                (0, false) => f64::INFINITY,
                _ => distance[i - 1],
            };
            let after = match (i == last, closed) {
                (true, true) => distance[1],
                (true, false) => f64::INFINITY,
                _ => distance[i + 1],
            };
            distance[i] <= before && distance[i] <= after
        };
        (0..=last)
            .filter(|&i| distance[i] <= best + self.spacing && minimum(i))
            .map(|i| self.refine(x, i))
            .min_by(|a, b| norm(a.at[0] - x).total_cmp(&norm(b.at[0] - x)))
            .unwrap_or_else(|| self.refine(x, 0))
    }

    /// The curve's parameter at the point nearest `x`, searched near
    /// `hint` (within 0.75 of it, else anywhere).
    pub fn parameter(&self, x: V, hint: f64) -> f64 {
        self.nearest(x, hint).s
    }

    /// The nearest point of the curve (extended past its ends) to `x`,
    /// refined by Newton's method from sample `closest`.
    fn refine(&self, x: V, closest: usize) -> Nearest<V> {
        let (start, end) = self.path.domain();
        let last = self.samples.len() - 1;
        let closed = self.path.closed();
        let period = end - start;
        let (mut lo, mut hi) = (
            self.samples[closest.saturating_sub(1)].0,
            self.samples[(closest + 1).min(last)].0,
        );
        if closed && closest == 0 {
            lo = self.samples[last - 1].0 - period;
        }
        if closed && closest == last {
            hi = self.samples[1].0 + period;
        }
        let mut s = self.samples[closest].0;
        let f = |s: f64| {
            let [p, d1, d2] = self.path.eval(wrap(s, start, period, closed));
            ((p - x).dot(d1), d1.dot(d1) + (p - x).dot(d2))
        };
        for _ in 0..60 {
            let (value, slope) = f(s);
            if value == 0.0 {
                break;
            }
            if value > 0.0 {
                hi = s;
            } else {
                lo = s;
            }
            let mut next = s - value / slope;
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if next == s || hi - lo <= 4.0 * f64::EPSILON * s.abs().max(1.0) {
                s = next;
                break;
            }
            s = next;
        }
        if !closed {
            // Past an end: the nearest point of the end's tangent line.
            for (bound, sign) in [(start, -1.0), (end, 1.0)] {
                let [p, d1, _] = self.path.eval(bound);
                let along = (x - p).dot(d1) / d1.dot(d1).max(f64::MIN_POSITIVE);
                if sign * along > 0.0 && (s - bound).abs() <= 1e-9 * period.max(1.0) {
                    return Nearest {
                        s: bound,
                        at: [p, d1, V::ZERO],
                        past: sign * along * norm(d1),
                    };
                }
            }
        }
        let s = wrap(s, start, period, closed);
        let at = self.path.eval(s);
        let past = if closed {
            f64::NEG_INFINITY
        } else {
            -((s - start).min(end - s))
        };
        Nearest { s, at, past }
    }
}

/// Implements [`ImplicitCurve`] for a shape by handing every call to the
/// curve `$target` (`$this` the shape), with `$scale` its characteristic
/// length: a traced shape's [`Traced`], or a [`WireShape`](super::WireShape)'s
/// own curve.
macro_rules! delegate_curve {
    ($shape:ty, |$this:ident| $target:expr, $scale:expr) => {
        impl $crate::geometry::ImplicitCurve for $shape {
            fn value(&self, p: DVec2) -> f64 {
                let $this = self;
                $target.value(p)
            }
            fn gradient(&self, p: DVec2) -> DVec2 {
                let $this = self;
                $target.gradient(p)
            }
            fn hessian(&self, p: DVec2) -> bevy::math::DMat2 {
                let $this = self;
                $target.hessian(p)
            }
            fn scale(&self) -> f64 {
                let $this = self;
                $scale
            }
            fn geometry(&self, p: DVec2) -> $crate::geometry::Geometry {
                let $this = self;
                $target.geometry(p)
            }
            fn has_ends(&self) -> bool {
                let $this = self;
                $target.has_ends()
            }
            fn past_end(&self, p: DVec2) -> f64 {
                let $this = self;
                $target.past_end(p)
            }
            fn parameter(&self, p: DVec2, hint: f64) -> f64 {
                let $this = self;
                $crate::geometry::ImplicitCurve::parameter($target, p, hint)
            }
            fn geometry_near(&self, p: DVec2, hint: f64) -> $crate::geometry::Geometry {
                let $this = self;
                $target.geometry_near(p, hint)
            }
            fn past_end_near(&self, p: DVec2, hint: f64) -> f64 {
                let $this = self;
                $target.past_end_near(p, hint)
            }
        }
    };
}
pub(crate) use delegate_curve;

/// `s` brought into `[start, start + period)` on a closed curve.
fn wrap(s: f64, start: f64, period: f64, closed: bool) -> f64 {
    if closed {
        start + (s - start).rem_euclid(period)
    } else {
        s
    }
}

/// One row of a traced curve: `C = n̂·d`, the offset `d = x − γ(s*)` from
/// the nearest point taken along a unit normal `n̂` of the curve there,
/// with `γ′` and `γ″` at `s*`. Then `∇C = n̂` and
/// `H = −(n̂·γ″) / (|γ′|² − d·γ″) t̂ t̂ᵀ`, for the normal carried along the
/// curve without turning about it (in the plane, the only normal: there
/// `n̂·γ″ = κ|γ′|²` and this is `−κ/(1 − κC) t̂t̂ᵀ`). Singular, the normal
/// reported as zero, where `γ′` vanishes (a cusp) or `|γ′|² − d·γ″` does
/// (a centre of curvature).
pub(crate) fn offset_row<V: Coordinates>(
    normal: V,
    offset: V,
    d1: V,
    d2: V,
    scale: f64,
) -> Geometry<V> {
    let speed2 = d1.dot(d1);
    let speed = speed2.sqrt();
    let stretch = speed2 - offset.dot(d2);
    let c = normal.dot(offset);
    if !(speed > 1e-12 * scale && stretch > 1e-9 * speed2 && normal.is_finite()) {
        // A cusp, or a centre of curvature: no normal to push along.
        return Geometry {
            c,
            normal: V::ZERO,
            hessian: V::outer(V::ZERO, V::ZERO),
        };
    }
    let tangent = d1 / speed;
    let k = -normal.dot(d2) / stretch;
    Geometry {
        c,
        normal,
        hessian: V::outer(tangent, tangent * k),
    }
}

impl<P: Parametric> ImplicitCurve for Traced<P> {
    fn value(&self, p: DVec2) -> f64 {
        self.geometry(p).c
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.geometry(p).normal
    }
    fn hessian(&self, p: DVec2) -> DMat2 {
        self.geometry(p).hessian
    }
    fn scale(&self) -> f64 {
        self.scale
    }
    fn geometry(&self, p: DVec2) -> Geometry {
        self.geometry_near(p, f64::NAN)
    }
    fn geometry_near(&self, p: DVec2, hint: f64) -> Geometry {
        let Nearest {
            at: [point, d1, d2],
            ..
        } = self.nearest(p, hint);
        let tangent = d1 / norm(d1);
        let normal = DVec2::new(-tangent.y, tangent.x);
        offset_row(normal, p - point, d1, d2, self.scale)
    }
    fn has_ends(&self) -> bool {
        !self.path.closed()
    }
    fn past_end(&self, p: DVec2) -> f64 {
        self.past_end_near(p, f64::NAN)
    }
    fn past_end_near(&self, p: DVec2, hint: f64) -> f64 {
        self.nearest(p, hint).past
    }
    fn parameter(&self, p: DVec2, hint: f64) -> f64 {
        Traced::parameter(self, p, hint)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The unit circle, counter-clockwise: inside is positive.
    struct Round;

    impl Parametric for Round {
        fn domain(&self) -> (f64, f64) {
            (0.0, std::f64::consts::TAU)
        }
        fn closed(&self) -> bool {
            true
        }
        fn eval(&self, s: f64) -> [DVec2; 3] {
            let (sin, cos) = s.sin_cos();
            [
                DVec2::new(cos, sin),
                DVec2::new(-sin, cos),
                DVec2::new(-cos, -sin),
            ]
        }
    }

    /// A traced circle is the circle's signed distance `1 − |x|`, with its
    /// gradient and Hessian, to rounding.
    #[test]
    fn a_traced_circle_is_its_signed_distance() {
        let traced = Traced::new(Round);
        for p in [
            DVec2::new(0.3, 0.5),
            DVec2::new(-1.2, 0.1),
            DVec2::new(0.05, -1.01),
            DVec2::new(1.0, -1e-9),
        ] {
            let g = traced.geometry(p);
            let r = p.length();
            assert_relative_eq!(g.c, 1.0 - r, epsilon = 1e-14);
            assert_relative_eq!(g.normal.x, -p.x / r, epsilon = 1e-13);
            assert_relative_eq!(g.normal.y, -p.y / r, epsilon = 1e-13);
            let t = DVec2::new(-p.y, p.x) / r;
            let h = -DMat2::from_cols(t * t.x, t * t.y) / r;
            for (a, b) in [(g.hessian.x_axis, h.x_axis), (g.hessian.y_axis, h.y_axis)] {
                assert_relative_eq!(a.x, b.x, epsilon = 1e-12);
                assert_relative_eq!(a.y, b.y, epsilon = 1e-12);
            }
        }
        // The centre is every point's centre of curvature: singular.
        assert_eq!(traced.geometry(DVec2::ZERO).normal, DVec2::ZERO);
    }
}
