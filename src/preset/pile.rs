//! A pile of beads poured into a bowl: a scene made from a count, for
//! the tests and benchmarks that pour one.

use super::{PresetError, ScenePreset};

/// The radius of each bead of [`ScenePreset::pile`], m.
pub const PILE_RADIUS: f64 = 0.02;

impl ScenePreset {
    /// `beads` beads of 2 cm ([`PILE_RADIUS`]) and 1 kg poured into a
    /// one-sided bowl (a circle of radius 1 m that pushes inward) at
    /// `e = 0`, RATTLE at 240 Hz: `per_row` to a row across
    /// `x ∈ [−0.5, 0.5]`, each jittered by up to 1.5 mm so that no two
    /// rows stack exactly, the rows 2.3 radii apart upward from
    /// `y = −0.8`, all at rest; at least one to a row. The scene is
    /// checked as a scene file is ([`ScenePreset::from_ron`]).
    pub fn pile(beads: usize, per_row: usize) -> Result<Self, PresetError> {
        let r = PILE_RADIUS;
        let per_row = per_row.max(1);
        let listed: String = (0..beads)
            .map(|k| {
                let (i, j) = (k % per_row, k / per_row);
                let jitter = 0.003 * ((k * 7919 % 13) as f64 / 13.0 - 0.5);
                let x = -0.5 + (i as f64 + 0.5) / per_row as f64 + jitter;
                let y = -0.8 + 2.3 * r * j as f64;
                format!("(name: \"b{k}\", mass: 1.0, radius: {r}, initial_position: ({x}, {y})),")
            })
            .collect();
        Self::from_ron(&format!(
            "(name: \"pile\", params: (timestep: {}, integrator: Rattle), \
             contacts: (restitution: 0.0), wires: [(shape: Circle((radius: 1.0)), \
             side: Negative, beads: [{listed}])])",
            1.0 / 240.0
        ))
    }
}
