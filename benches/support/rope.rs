//! The rope both rope benchmarks step: `benches/chain.rs` and the avian2d
//! comparison's `rope` job (`bench-avian`, which includes this file). N
//! rods of [`LINK`] hanging from a pin: N + 1 beads of 1 kg, bead 0 held by
//! the pin's two rows and row 2 + i the rod from bead i to bead i + 1,
//! released horizontal from rest under |g| = [`GRAVITY`].

#![allow(dead_code)]

use bevy::math::DVec2;
use wirebead::solver::{BeadState, Island, IslandRow, LinearForce, RowKind};

/// The link length, metres.
pub const LINK: f64 = 0.1;
/// Magnitude of gravity, m/s², pointing along -y.
pub const GRAVITY: f64 = 10.0;

/// The rope's island of `n` rods.
pub fn island(n: usize) -> Island {
    let mut rows: Vec<IslandRow> = [DVec2::X, DVec2::Y]
        .map(|axis| IslandRow {
            kind: RowKind::Axis { axis, offset: 0.0 },
            beads: vec![0],
        })
        .to_vec();
    rows.extend((0..n).map(|i| IslandRow {
        kind: RowKind::Rod { length: LINK },
        beads: vec![i, i + 1],
    }));
    Island::new(&vec![1.0; n + 1], rows, vec![]).expect("a valid rope")
}

/// The rope at the release: its beads at rest at `(LINK i, 0)`.
pub fn released(n: usize) -> Vec<BeadState> {
    (0..=n)
        .map(|i| BeadState {
            position: DVec2::new(i as f64 * LINK, 0.0),
            velocity: DVec2::ZERO,
        })
        .collect()
}

/// The beads' weights.
pub fn weights(n: usize) -> Vec<LinearForce> {
    vec![LinearForce::constant(DVec2::new(0.0, -GRAVITY)); n + 1]
}

/// The largest relative stretch of the rope's links; infinite if a
/// position is not finite.
pub fn max_stretch(states: &[BeadState]) -> f64 {
    states.windows(2).fold(0.0, |worst: f64, w| {
        let stretch = ((w[1].position - w[0].position).length() - LINK).abs() / LINK;
        if stretch.is_finite() {
            worst.max(stretch)
        } else {
            f64::INFINITY
        }
    })
}

/// The rope's total energy, J: beads of 1 kg, `|v|²/2 + |g| y` each.
pub fn energy(states: &[BeadState]) -> f64 {
    states
        .iter()
        .map(|s| 0.5 * s.velocity.length_squared() + GRAVITY * s.position.y)
        .sum()
}
