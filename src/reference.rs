//! Reference answers for tests, benchmarks and the panel's plots, not part
//! of the simulation: exact results it is measured against, for a bead on
//! a frictionless vertical circle (a pendulum of length r): its period,
//! its angle, the force that holds it, and its separatrix.
//!
//! Released from rest at angle θ₀ from the bottom, the period is
//! `T = 4 sqrt(r/|g|) K(m)`, `m = sin²(θ₀/2)`, with `K` the complete elliptic
//! integral of the first kind in the *parameter* convention, computed as
//! `K(m) = π / (2 AGM(1, sqrt(1 - m)))`.

use std::f64::consts::FRAC_PI_2;

use bevy::math::{DQuat, DVec2, DVec3};

/// The complete elliptic integral of the first kind `K(m)`, parameter `m`
/// (not modulus), for `0 ≤ m < 1`. Returns NaN outside that range.
pub fn elliptic_k(m: f64) -> f64 {
    if !(0.0..1.0).contains(&m) {
        return f64::NAN;
    }
    let (mut a, mut b) = (1.0_f64, (1.0 - m).sqrt());
    // The AGM converges quadratically: 8 rounds reach full f64 precision for
    // m up to 1 - 1e-15.
    for _ in 0..8 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    FRAC_PI_2 / a
}

/// The exact period of a pendulum of length `radius` under gravity of
/// magnitude `gravity`, released from rest at `theta0` radians from the bottom.
pub fn pendulum_period(radius: f64, gravity: f64, theta0: f64) -> f64 {
    4.0 * (radius / gravity).sqrt() * elliptic_k((0.5 * theta0).sin().powi(2))
}

/// The point at angle `theta` from the bottom of a circle of radius `radius`
/// centred at the origin (counter-clockwise positive).
pub fn point_on_circle(radius: f64, theta: f64) -> DVec2 {
    DVec2::new(radius * theta.sin(), -radius * theta.cos())
}

/// Where a bead at `position` moving at `velocity` is on a circle about
/// `centre` in the plane, under gravity `gravity`: the angle `θ` from the
/// circle's lowest point (positive turning anticlockwise, in `(−π, π]`)
/// and `θ̇`. Measured from straight up where there is no gravity; none at
/// the centre.
pub fn circle_angle(
    centre: DVec2,
    gravity: DVec2,
    position: DVec2,
    velocity: DVec2,
) -> Option<(f64, f64)> {
    let r = position - centre;
    let rr = r.length_squared();
    if !(rr > 0.0 && rr.is_finite()) {
        return None;
    }
    let down = gravity.try_normalize().unwrap_or(DVec2::NEG_Y);
    let angle = down.perp_dot(r).atan2(down.dot(r));
    Some((angle, r.perp_dot(velocity) / rr))
}

/// Where a bead is along its wire, for plots: `s`, how far along the wire
/// it has come since `s` began (m), and its rate `ṡ` (m/s), with the
/// position and the unit tangent they were measured at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlongWire {
    /// How far along the wire, from where `s` began.
    pub s: f64,
    /// Its rate.
    pub s_dot: f64,
    /// Where the bead was.
    pub position: DVec2,
    /// The wire's unit tangent there, turned as `s` grows.
    pub tangent: DVec2,
}

/// A bead at `position` moving at `velocity` on a wire whose normal there
/// is `normal` (`∇C`), along the wire from `previous` (the last step's), or
/// at `s = 0` where there is none. Each step adds its chord measured along
/// the mean of the two tangents, so on a circle `s` is the arc `R θ` to a
/// relative `Δθ²/24` for steps of `Δθ`. The tangent keeps the turn of
/// `previous`'s; a first one points right (up, on an upright wire): on a
/// circle's bottom, anticlockwise, as θ grows. None where the normal
/// vanishes or is not finite.
pub fn along_wire(
    previous: Option<&AlongWire>,
    position: DVec2,
    velocity: DVec2,
    normal: DVec2,
) -> Option<AlongWire> {
    let mut tangent = normal.try_normalize()?.perp();
    let s = match previous {
        Some(p) => {
            if tangent.dot(p.tangent) < 0.0 {
                tangent = -tangent;
            }
            let mean = (tangent + p.tangent).try_normalize().unwrap_or(tangent);
            p.s + (position - p.position).dot(mean)
        }
        None => {
            if tangent.x < 0.0 || (tangent.x == 0.0 && tangent.y < 0.0) {
                tangent = -tangent;
            }
            0.0
        }
    };
    Some(AlongWire {
        s,
        s_dot: velocity.dot(tangent),
        position,
        tangent,
    })
}

/// The pendulum's separatrix on a circle of `radius` under gravity of
/// size `g`: `θ̇ = ±√(2 g / R · (1 + cos θ))`, the motion that just comes
/// to rest at the top, as two branches of `points` points each over
/// `θ ∈ [−π, π]`.
pub fn separatrix(g: f64, radius: f64, points: usize) -> [Vec<[f64; 2]>; 2] {
    let points = points.max(2);
    let upper: Vec<[f64; 2]> = (0..points)
        .map(|k| {
            let theta =
                -std::f64::consts::PI + std::f64::consts::TAU * k as f64 / (points - 1) as f64;
            [
                theta,
                (2.0 * g / radius * (1.0 + theta.cos())).max(0.0).sqrt(),
            ]
        })
        .collect();
    let lower = upper.iter().map(|&[t, w]| [t, -w]).collect();
    [upper, lower]
}

/// The force with which a frictionless circle of `radius` holds a bead
/// of `mass` at angle `theta` from its lowest point, toward its centre,
/// under gravity of size `g`, the bead having started at `start`
/// (`(θ0, θ̇0)`) and been left alone since: energy kept gives
/// `R θ̇² = R θ̇0² + 2 g (cos θ − cos θ0)`, so
/// `N = m (R θ̇0² + g (3 cos θ − 2 cos θ0))`, the pendulum's
/// `m g (3 cos θ − 2 cos θ0)` when let go from rest.
pub fn circle_normal_force(mass: f64, g: f64, radius: f64, start: (f64, f64), theta: f64) -> f64 {
    let (theta0, rate0) = start;
    mass * (radius * rate0 * rate0 + g * (3.0 * theta.cos() - 2.0 * theta0.cos()))
}

/// Measures the period of an oscillating signal from its upward zero
/// crossings, linearly interpolated between samples `(t, value)`.
/// Returns the mean spacing of successive crossings, or `None` with fewer
/// than two.
pub fn period_from_crossings(samples: &[(f64, f64)]) -> Option<f64> {
    let crossings: Vec<f64> = samples
        .windows(2)
        .filter(|w| w[0].1 < 0.0 && w[1].1 >= 0.0)
        .map(|w| {
            let (t0, y0) = w[0];
            let (t1, y1) = w[1];
            t0 + (t1 - t0) * (-y0) / (y1 - y0)
        })
        .collect();
    (crossings.len() >= 2)
        .then(|| (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64)
}

/// A bead of mass `m` on a hoop centred on a free body of mass `big_m`
/// (no gravity, frictionless; ../shared/PHYSICS.md, "Bodies beside
/// beads"): where the bead and the body's centre are at time `t`, from the
/// bead at `bead` moving at `bead_v` and the body's centre at `body` moving
/// at `body_v`, the bead's velocity relative to the body across the line
/// between them. The hoop's push passes through the body's centre, so the
/// body never turns; the two turn about their common centre of mass, which
/// drifts at the pair's mean velocity, at `Ω = (r × u) / |r|²` (`r` the
/// bead less the body's centre, `u` its relative velocity), the bead
/// `M/(m+M)` of `r` from it and the body `m/(m+M)` on the other side.
pub fn bead_on_a_free_hoop(
    (m, big_m): (f64, f64),
    (bead, bead_v): (DVec3, DVec3),
    (body, body_v): (DVec3, DVec3),
    t: f64,
) -> (DVec3, DVec3) {
    let total = m + big_m;
    let centre = (m * bead + big_m * body) / total + (m * bead_v + big_m * body_v) / total * t;
    let r = bead - body;
    let turn = r.cross(bead_v - body_v) / r.length_squared();
    let r = DQuat::from_scaled_axis(turn * t) * r;
    (centre + big_m / total * r, centre - m / total * r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    /// The two-body answer keeps the hoop's radius between the two and
    /// moves their centre of mass uniformly, to 1e-14; a quarter of the
    /// relative turn (`Ω = u / R`) puts the bead a quarter round.
    #[test]
    fn a_bead_on_a_free_hoop_turns_about_the_pairs_centre_of_mass() {
        let (m, big_m) = (1.0, 3.0);
        let bead = (DVec3::X, DVec3::new(0.0, 1.5, 0.0));
        let body = (DVec3::ZERO, DVec3::ZERO);
        for t in [0.0, 0.7, 3.1] {
            let (b, c) = bead_on_a_free_hoop((m, big_m), bead, body, t);
            assert_relative_eq!((b - c).length(), 1.0, epsilon = 1e-14);
            let centre = (m * b + big_m * c) / (m + big_m);
            let expected = (m * bead.0 + m * bead.1 * t) / (m + big_m);
            assert!((centre - expected).length() <= 1e-14);
        }
        let (b, c) = bead_on_a_free_hoop((m, big_m), bead, body, FRAC_PI_2 / 1.5);
        assert!((b - c - DVec3::Y).length() <= 1e-14, "{}", b - c);
    }

    #[test]
    fn elliptic_k_matches_known_values() {
        assert_relative_eq!(elliptic_k(0.0), FRAC_PI_2, epsilon = 1e-15);
        // K(1/2) = Γ(1/4)² / (4 sqrt(π))
        assert_relative_eq!(elliptic_k(0.5), 1.854_074_677_301_372, epsilon = 1e-14);
        assert_relative_eq!(elliptic_k(0.9), 2.578_092_113_348_173, epsilon = 1e-14);
        assert!(elliptic_k(1.0).is_nan());
    }

    #[test]
    fn small_amplitude_period_is_two_pi_sqrt_l_over_g() {
        let t = pendulum_period(2.0, 9.81, 1e-6);
        assert_relative_eq!(t, 2.0 * PI * (2.0_f64 / 9.81).sqrt(), max_relative = 1e-12);
    }

    #[test]
    fn the_angle_on_a_circle_is_measured_from_its_lowest_point() {
        let g = DVec2::new(0.0, -9.81);
        let c = DVec2::new(1.0, 2.0);
        let (bottom, _) = circle_angle(c, g, c + DVec2::new(0.0, -0.5), DVec2::X).unwrap();
        assert!(bottom.abs() <= 1e-15);
        let (right, w) =
            circle_angle(c, g, c + DVec2::new(0.5, 0.0), DVec2::new(0.0, 1.0)).unwrap();
        assert!(
            (right - std::f64::consts::FRAC_PI_2).abs() <= 1e-15,
            "{right}"
        );
        assert!((w - 2.0).abs() <= 1e-15, "turns at {w} rad/s");
        let (top, _) = circle_angle(c, g, c + DVec2::new(0.0, 0.5), DVec2::ZERO).unwrap();
        assert!((top.abs() - std::f64::consts::PI).abs() <= 1e-15);
        assert!(circle_angle(c, g, c, DVec2::X).is_none());
    }

    /// On the separatrix the energy per unit mass, `½ R² θ̇² − g R cos θ`,
    /// is the top's at rest, `g R`, to rounding.
    #[test]
    fn the_separatrix_has_the_energy_of_rest_at_the_top() {
        let (g, r) = (9.81, 0.75);
        let [upper, lower] = separatrix(g, r, 61);
        assert_eq!(upper.len(), 61);
        for &[theta, w] in upper.iter().chain(&lower) {
            let energy = 0.5 * r * r * w * w - g * r * theta.cos();
            assert!((energy - g * r).abs() <= 1e-12, "at θ = {theta}: {energy}");
        }
        assert!(upper[30][1] > 0.0 && lower[30][1] < 0.0);
    }

    /// Let go from rest level with the centre, a pendulum's bob pulls on
    /// it with three times its weight at the bottom and nothing where it
    /// started; sent round from the bottom at `v`, the circle holds it
    /// with `m v² / R + m g` there.
    #[test]
    fn the_circle_holds_the_bead_as_energy_kept_says() {
        let (m, g, r) = (2.0, 9.81, 0.5);
        let half_pi = std::f64::consts::FRAC_PI_2;
        assert!((circle_normal_force(m, g, r, (half_pi, 0.0), 0.0) - 3.0 * m * g).abs() <= 1e-12);
        assert!(circle_normal_force(m, g, r, (half_pi, 0.0), half_pi).abs() <= 1e-12);
        let v = 4.0;
        let bottom = circle_normal_force(m, g, r, (0.0, v / r), 0.0);
        assert!(
            (bottom - (m * v * v / r + m * g)).abs() <= 1e-12,
            "{bottom}"
        );
    }

    #[test]
    fn crossings_of_a_sine_give_its_period() {
        let samples: Vec<(f64, f64)> = (0..2000)
            .map(|i| {
                let t = i as f64 * 0.01;
                (t, (2.0 * PI * t / 1.7).sin())
            })
            .collect();
        assert_relative_eq!(
            period_from_crossings(&samples).unwrap(),
            1.7,
            max_relative = 1e-4
        );
    }

    /// On a unit circle, steps of 0.05 rad anticlockwise from the bottom:
    /// `s` is the arc to the chord's `Δθ²/24`, `ṡ` is `R ω`, and the
    /// tangent keeps its turn past the side of the circle.
    #[test]
    fn along_a_circle_s_is_its_arc() {
        let (radius, step, omega) = (2.0, 0.05_f64, 1.5);
        let mut along = None;
        for k in 0..=100 {
            let theta = step * k as f64;
            let out = DVec2::new(theta.sin(), -theta.cos());
            let position = radius * out;
            let velocity = radius * omega * out.perp();
            along = super::along_wire(along.as_ref(), position, velocity, out);
        }
        let along = along.expect("a tangent");
        let arc = radius * step * 100.0;
        assert!(
            ((along.s - arc) / arc).abs() <= step * step / 24.0 * 1.01,
            "s = {} against the arc {arc}",
            along.s
        );
        assert!(
            (along.s_dot - radius * omega).abs() < 1e-12,
            "{}",
            along.s_dot
        );
        assert!(super::along_wire(None, DVec2::ZERO, DVec2::X, DVec2::ZERO).is_none());
        // On a level line, s grows to the right.
        let first = super::along_wire(None, DVec2::ZERO, DVec2::X, DVec2::Y).unwrap();
        let next = super::along_wire(Some(&first), DVec2::X, DVec2::X, DVec2::NEG_Y).unwrap();
        assert_eq!((first.s_dot, next.s, next.s_dot), (1.0, 1.0, 1.0));
    }
}
