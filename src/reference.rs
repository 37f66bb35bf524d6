//! Reference answers for tests and benchmarks, not part of the simulation:
//! exact results it is measured against, the period of a bead on a
//! frictionless vertical circle (a pendulum of length r).
//!
//! Released from rest at angle θ₀ from the bottom, the period is
//! `T = 4 sqrt(r/|g|) K(m)`, `m = sin²(θ₀/2)`, with `K` the complete elliptic
//! integral of the first kind in the *parameter* convention, computed as
//! `K(m) = π / (2 AGM(1, sqrt(1 - m)))`.

use std::f64::consts::FRAC_PI_2;

use bevy::math::DVec2;

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

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

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
}
