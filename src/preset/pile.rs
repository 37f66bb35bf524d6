//! A pile of beads poured into a bowl: a scene made from a count, for
//! the tests and benchmarks that pour one, in the plane or in space.

use super::{PresetError, SceneFile, ScenePreset};

/// The radius of each bead of [`ScenePreset::pile`], m.
pub const PILE_RADIUS: f64 = 0.02;

/// The grid a preset's beads start on, in radii between centres.
pub(super) const GRID: f64 = 2.3;

/// How far inside its wire a preset's bead starts, in radii: the wire is
/// the line of the beads' centres, so a bead starts clear of it.
pub(super) const CLEAR: f64 = 1.5;

/// How far bead `k` of a preset's grid is moved sideways, within half of
/// `width` either way, so that no two stack exactly.
pub(super) fn jitter(k: usize, width: f64) -> f64 {
    width * ((k * 7919 % 13) as f64 / 13.0 - 0.5)
}

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
            let x = -0.5 + (i as f64 + 0.5) / per_row as f64 + jitter(k, 0.003);
            (x, -0.8 + GRID * r * j as f64)
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

/// A pour of beads of 2 cm ([`PILE_RADIUS`]) and 1 kg into a one-sided
/// bowl at `e = 0`, RATTLE: in the plane a circle, in space a sphere, of
/// [`Pour::bowl`] that pushes inward. The beads start at rest on a square
/// (cubic) grid 2.3 radii apart, the lowest points of it that lie inside
/// the bowl by more than a radius and a half, each moved sideways by up
/// to 1.5 mm so that no two stack exactly: the bottom of the bowl fills
/// first, and a pour of 1,000 beads in a bowl of 1 m fills it to about
/// its middle in the plane.
///
/// ```
/// use wirebead::preset::Pour;
///
/// let scene = Pour { beads: 200, space: true, ..Pour::default() }.scene()?;
/// assert!(scene.in_space());
/// # Ok::<(), wirebead::preset::PresetError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pour {
    /// How many beads.
    pub beads: usize,
    /// In space (a sphere) rather than in the plane (a circle).
    pub space: bool,
    /// The bowl's radius, m.
    pub bowl: f64,
    /// The fixed timestep, s.
    pub timestep: f64,
}

impl Default for Pour {
    /// 1,000 beads in the plane, a bowl of 1 m, 60 Hz.
    fn default() -> Self {
        Self {
            beads: 1000,
            space: false,
            bowl: 1.0,
            timestep: 1.0 / 60.0,
        }
    }
}

impl Pour {
    /// The beads' starting places, lowest first: `[x, y, z]`, `z` zero in
    /// the plane. Fewer than [`Pour::beads`] where the bowl holds fewer.
    /// Each row of the grid is walked only across the bowl's width at
    /// its height, and the walk stops at the last bead, so that a bowl of
    /// any size costs no more than its beads and its rows below them.
    pub(super) fn places(&self) -> Vec<[f64; 3]> {
        let r = PILE_RADIUS;
        let spacing = GRID * r;
        let inside = self.bowl - CLEAR * r;
        let mut places: Vec<[f64; 3]> = Vec::new();
        if !(inside > 0.0 && inside.is_finite()) {
            return places;
        }
        // The grid's points within `half` of the middle along one axis.
        let across = |half: f64| {
            let n = (half / spacing).floor() as i64;
            -n..=n
        };
        // The half-width of a slice at `offset` from the middle of a
        // disc of radius `radius`.
        let width = |radius: f64, offset: f64| {
            ((radius - offset.abs()) * (radius + offset.abs()))
                .max(0.0)
                .sqrt()
        };
        for j in across(inside) {
            let y = j as f64 * spacing;
            let row = width(inside, y);
            for i in across(row) {
                let depth = if self.space {
                    width(row, i as f64 * spacing)
                } else {
                    0.0
                };
                for l in across(depth) {
                    if places.len() == self.beads {
                        return places;
                    }
                    let k = places.len();
                    let x = i as f64 * spacing + jitter(k, 0.003);
                    let z = if self.space {
                        l as f64 * spacing + jitter(k + 5, 0.003)
                    } else {
                        0.0
                    };
                    if x.hypot(y).hypot(z) < inside {
                        places.push([x, y, z]);
                    }
                }
            }
        }
        places
    }

    /// The scene, checked as a scene file is ([`SceneFile::from_ron`]). A
    /// pour of more beads than the bowl holds is refused as
    /// [`PresetError::PourTooLarge`], which says how many fit; a timestep
    /// that is not positive and finite as any scene file's is.
    pub fn scene(&self) -> Result<SceneFile, PresetError> {
        let places = self.places();
        if places.len() < self.beads {
            return Err(PresetError::PourTooLarge {
                beads: self.beads,
                bowl: self.bowl,
                most: places.len(),
            });
        }
        let r = PILE_RADIUS;
        let listed: String = places
            .iter()
            .enumerate()
            .map(|(k, &[x, y, z])| {
                let at = if self.space {
                    format!("({x:?}, {y:?}, {z:?})")
                } else {
                    format!("({x:?}, {y:?})")
                };
                format!("(name: \"b{k}\", mass: 1.0, radius: {r:?}, initial_position: {at}),")
            })
            .collect();
        let (dimension, shape) = if self.space {
            ("dimension: 3, ", "Sphere")
        } else {
            ("", "Circle")
        };
        SceneFile::from_ron(&format!(
            "(name: \"pour\", {dimension}params: (timestep: {:?}, integrator: Rattle), \
             contacts: (restitution: 0.0), wires: [(shape: {shape}((radius: {:?})), \
             side: Negative, beads: [{listed}])])",
            self.timestep, self.bowl
        ))
    }
}
