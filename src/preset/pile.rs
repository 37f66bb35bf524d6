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
    /// checked as a scene file is ([`ScenePreset::from_ron`]). A pile
    /// whose rows would rise past the bowl (more than some 800 beads in
    /// rows of 23) is refused as [`PresetError::PileTooLarge`], which says
    /// how many fit.
    pub fn pile(beads: usize, per_row: usize) -> Result<Self, PresetError> {
        let r = PILE_RADIUS;
        let per_row = per_row.max(1);
        let at = |k: usize| {
            let (i, j) = (k % per_row, k / per_row);
            let jitter = 0.003 * ((k * 7919 % 13) as f64 / 13.0 - 0.5);
            let x = -0.5 + (i as f64 + 0.5) / per_row as f64 + jitter;
            (x, -0.8 + 2.3 * r * j as f64)
        };
        // Inside the bowl by more than a radius, or the wire would pull
        // the bead in from behind it.
        let inside = |k: usize| {
            let (x, y) = at(k);
            x.hypot(y) < 1.0 - r
        };
        if let Some(outside) = (0..beads).find(|&k| !inside(k)) {
            let row = outside / per_row;
            let rows_inside = (0..)
                .take_while(|&j| (j * per_row..(j + 1) * per_row).all(inside))
                .count();
            return Err(PresetError::PileTooLarge {
                beads,
                per_row,
                row,
                most: rows_inside * per_row,
            });
        }
        let listed: String = (0..beads)
            .map(|k| {
                let (x, y) = at(k);
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
