//! An hourglass of beads in the plane: a scene made from a count.

use std::f64::consts::{FRAC_1_SQRT_2, PI};

use bevy::math::DVec2;

use super::pile::{CLEAR, GRID, jitter};
use super::{PresetError, ScenePreset};
use crate::geometry::{ImplicitCurve, Spline, SplineKind, SplineSpec};

/// The radius of each bead of an [`Hourglass`], m: grains of 1 cm.
pub const GRAIN_RADIUS: f64 = 0.01;

/// How far the centre line of the neck's two walls lies from the middle,
/// in grain radii: the beads' centres pass through an opening of twice
/// this, some four and a half grains across.
const NECK: f64 = 3.5;

/// An hourglass turned over: [`Hourglass::beads`] grains of 1 cm
/// ([`GRAIN_RADIUS`]) and 10 g at rest in the upper bulb, lowest first,
/// on a square grid 2.3 radii apart (each moved sideways by up to 0.75 mm
/// so that no two stack exactly), and a glass of two round bulbs joined
/// by funnels at 45° to a neck some four grains wide. The glass is one
/// closed, one-sided Catmull–Rom spline that pushes inward, at `e = 0`,
/// and its bulbs are as large as the grains need, with a tenth to spare. RATTLE, frictionless grains that strike at
/// `e = 0`.
///
/// ```
/// use wirebead::preset::Hourglass;
///
/// let scene = Hourglass { beads: 100, ..Hourglass::default() }.scene()?;
/// assert_eq!(scene.bead_names().len(), 100);
/// # Ok::<(), wirebead::preset::PresetError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hourglass {
    /// How many grains.
    pub beads: usize,
    /// The fixed timestep, s.
    pub timestep: f64,
}

impl Default for Hourglass {
    /// 2,000 grains, 240 Hz.
    fn default() -> Self {
        Self {
            beads: 2000,
            timestep: 1.0 / 240.0,
        }
    }
}

impl Hourglass {
    /// The most grains an hourglass is made for: its bulbs grow with the
    /// square root of the count (some 0.6 m for 2,000 grains, 4.3 m for
    /// 100,000).
    pub const MOST: usize = 100_000;

    /// The bulbs' radius for `beads` grains: a square grid of `GRID`
    /// filling nine tenths of a disc holds them with a tenth to spare,
    /// and never less than the neck's funnels need.
    fn bulb(beads: usize) -> f64 {
        let r = GRAIN_RADIUS;
        let area = beads as f64 * (GRID * r).powi(2) / 0.9;
        ((area / PI).sqrt() + CLEAR * r).max(20.0 * r)
    }

    /// The glass's outline, counter-clockwise (so that its inside is the
    /// spline's positive side), for bulbs of radius `bulb`: from the
    /// neck's right wall up the upper funnel, round the upper bulb and
    /// down its funnel to the neck's left wall, then the same mirrored
    /// below. Returns the points and the height of the upper bulb's
    /// centre.
    fn outline(bulb: f64) -> (Vec<DVec2>, f64) {
        let neck = NECK * GRAIN_RADIUS;
        // The bulb meets its funnel at 45° below its middle, where its
        // wall runs at 45° too.
        let joint = FRAC_1_SQRT_2 * bulb;
        let centre = 2.0 * joint - neck;
        let mut upper = vec![
            DVec2::new(neck, 0.0),
            DVec2::new(0.5 * (neck + joint), 0.5 * (centre - joint)),
        ];
        upper.extend((0..=18).map(|k| {
            let angle = (-45.0 + 15.0 * k as f64).to_radians();
            DVec2::new(bulb * angle.cos(), centre + bulb * angle.sin())
        }));
        upper.push(DVec2::new(-0.5 * (neck + joint), 0.5 * (centre - joint)));
        upper.push(DVec2::new(-neck, 0.0));
        // Below: the upper half mirrored, walked the other way, its neck
        // points already in.
        let lower: Vec<DVec2> = upper[1..upper.len() - 1]
            .iter()
            .rev()
            .map(|p| DVec2::new(p.x, -p.y))
            .collect();
        upper.extend(lower);
        (upper, centre)
    }

    /// The grains' starting places, lowest first, inside `glass` (its
    /// bulbs of radius `bulb`, its top at `top`) by more than `CLEAR`
    /// radii and above the neck; at most [`Hourglass::beads`].
    fn places(&self, glass: &Spline, (bulb, top): (f64, f64)) -> Vec<DVec2> {
        let r = GRAIN_RADIUS;
        let spacing = GRID * r;
        let mut places = Vec::new();
        let rows = (top / spacing).ceil() as usize;
        let across = (bulb / spacing).ceil() as i64;
        for j in 1..=rows {
            let y = j as f64 * spacing;
            for i in -across..=across {
                if places.len() == self.beads {
                    return places;
                }
                let k = places.len();
                let at = DVec2::new(i as f64 * spacing + jitter(k, 0.0015), y);
                if glass.value(at) > CLEAR * r {
                    places.push(at);
                }
            }
        }
        places
    }

    /// The scene, checked as a scene file is ([`ScenePreset::from_ron`]).
    /// More than [`Hourglass::MOST`] grains are refused as
    /// [`PresetError::HourglassTooLarge`]; a timestep that is not
    /// positive and finite as any scene file's is.
    pub fn scene(&self) -> Result<ScenePreset, PresetError> {
        if self.beads > Self::MOST {
            return Err(PresetError::HourglassTooLarge {
                beads: self.beads,
                most: Self::MOST,
            });
        }
        // Bulbs a tenth larger each time the grid's points in them are
        // too few (a few grains in the funnel's corners).
        let mut bulb = Self::bulb(self.beads);
        let (outline, places) = loop {
            let (outline, centre) = Self::outline(bulb);
            let spec = SplineSpec {
                kind: SplineKind::CatmullRom,
                points: outline.clone(),
                closed: true,
            };
            let glass =
                Spline::new(spec).map_err(|source| PresetError::Wire { index: 0, source })?;
            let places = self.places(&glass, (bulb, centre + bulb));
            if places.len() == self.beads {
                break (outline, places);
            }
            bulb *= 1.1;
        };
        let r = GRAIN_RADIUS;
        let listed: String = places
            .iter()
            .enumerate()
            .map(|(k, at)| {
                format!(
                    "(name: \"g{k}\", mass: 0.01, radius: {r:?}, initial_position: ({:?}, {:?})),",
                    at.x, at.y
                )
            })
            .collect();
        let points: String = outline
            .iter()
            .map(|p| format!("({:?}, {:?}),", p.x, p.y))
            .collect();
        ScenePreset::from_ron(&format!(
            "(name: \"hourglass\", params: (timestep: {:?}, integrator: Rattle), \
             contacts: (restitution: 0.0), wires: [(\
             shape: Spline((points: [{points}], kind: CatmullRom, closed: true)), \
             side: Positive, beads: [{listed}])])",
            self.timestep
        ))
    }
}
