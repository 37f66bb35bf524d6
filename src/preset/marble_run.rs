//! A marble run in space that runs for ever: marbles roll down a rail,
//! drop off its end into a bowl, and each, once it settles, is sent back
//! to the top.

use std::f64::consts::{PI, TAU};

use bevy::math::DVec3;

use super::pile::{PILE_RADIUS, Pour};
use super::{PresetError, SceneFile, SpaceScene};

/// The radius of a [`MarbleRun`]'s bowl, m.
pub const MARBLE_BOWL: f64 = 0.6;

/// How far the rail's spiral is from the bowl's vertical axis, m.
const SPIRAL: f64 = 0.4;

/// The turns of the rail's spiral.
const TURNS: f64 = 1.5;

/// The rail's spiral: a point every eighth of a turn, [`TURNS`] down from
/// `y = 0.3` to `y = −0.15`.
const SPIRAL_POINTS: usize = 13;

/// How the rail turns in from its spiral toward the bowl's axis at its
/// end: two more points at one azimuth, a sixth of a turn past the
/// spiral's last, at these distances from the axis and heights. A
/// marble leaves it along the line through the axis, so that it brings
/// the pile no turn about it (a frictionless pile fed marbles all turning
/// one way would spin up, and its marbles would never settle).
const TURN_IN: [(f64, f64); 2] = [(0.28, -0.18), (0.1, -0.21)];

/// How many of the rail's points a marble starts at.
const ON_THE_RAIL: usize = SPIRAL_POINTS - 1;

/// A marble run in space: [`MarbleRun::marbles`] marbles of 2 cm
/// ([`PILE_RADIUS`]) and 10 g on an open Catmull–Rom rail that spirals a
/// turn and a half down inside a bowl (a one-sided sphere of
/// [`MARBLE_BOWL`] that pushes inward and catches every marble) and turns
/// in toward the bowl's axis at its end. Twelve start at rest on the
/// rail, one at each point of its spiral but the last; the rest start on
/// a grid at the bottom of the bowl, off the rail. Each marble rolls down
/// the rail, flies off its end, drops into the bowl, and once it has lain
/// slower than 25 cm/s for 0.2 s the rail sends it back to its top
/// ([`SendsBeadsBack`](crate::SendsBeadsBack)), as soon as no marble is
/// there: the run goes on for ever. Everything meets at `e = 0`, without
/// friction; RATTLE.
///
/// ```
/// use wirebead::preset::MarbleRun;
///
/// let scene = MarbleRun { marbles: 40, ..MarbleRun::default() }.scene()?;
/// assert_eq!(scene.bead_names().len(), 40);
/// # Ok::<(), wirebead::preset::PresetError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarbleRun {
    /// How many marbles.
    pub marbles: usize,
    /// The fixed timestep, s.
    pub timestep: f64,
}

impl Default for MarbleRun {
    /// 200 marbles, 240 Hz.
    fn default() -> Self {
        Self {
            marbles: 200,
            timestep: 1.0 / 240.0,
        }
    }
}

impl MarbleRun {
    /// The most marbles a run is made for: the bottom of its bowl holds
    /// them below the rail's end.
    pub const MOST: usize = 1000;

    /// The mass of each marble, kg.
    pub const MASS: f64 = 0.01;

    /// The rail's points, top first: where the rail starts is where a
    /// settled marble is sent back to; it spirals a turn and a half down
    /// and turns in toward the bowl's axis at its end.
    pub fn rail() -> Vec<DVec3> {
        (0..SPIRAL_POINTS)
            .map(|k| {
                let turned = k as f64 / (SPIRAL_POINTS - 1) as f64;
                let (sin, cos) = (TURNS * TAU * turned).sin_cos();
                DVec3::new(SPIRAL * cos, 0.3 - 0.45 * turned, SPIRAL * sin)
            })
            .chain(TURN_IN.map(|(from_axis, y)| {
                let (sin, cos) = (TURNS * TAU + PI / 6.0).sin_cos();
                DVec3::new(from_axis * cos, y, from_axis * sin)
            }))
            .collect()
    }

    /// The scene, checked as a scene file is
    /// ([`SceneFile::from_ron`]). More marbles than [`MarbleRun::MOST`]
    /// is refused as [`PresetError::MarbleRunTooLarge`]; a timestep that is
    /// not positive and finite as any scene file's is.
    pub fn scene(&self) -> Result<SpaceScene, PresetError> {
        if self.marbles > Self::MOST {
            return Err(PresetError::MarbleRunTooLarge {
                marbles: self.marbles,
                most: Self::MOST,
            });
        }
        let rail = Self::rail();
        let on_rail = self.marbles.min(ON_THE_RAIL);
        let in_bowl = Pour {
            beads: self.marbles - on_rail,
            space: true,
            bowl: MARBLE_BOWL,
            timestep: self.timestep,
        }
        .places();
        let r = PILE_RADIUS;
        let at = |p: DVec3| format!("({:?}, {:?}, {:?})", p.x, p.y, p.z);
        let marbles: String = rail[..on_rail]
            .iter()
            .copied()
            .chain(in_bowl.iter().map(|&[x, y, z]| DVec3::new(x, y, z)))
            .enumerate()
            .map(|(k, p)| {
                format!(
                    "(name: \"marble {}\", mass: {:?}, radius: {r:?}, initial_position: {}),",
                    k + 1,
                    Self::MASS,
                    at(p)
                )
            })
            .collect();
        let points: String = rail.iter().map(|&p| at(p) + ", ").collect();
        let text = format!(
            "(name: \"Marble run in space\", dimension: 3, \
             params: (timestep: {:?}, integrator: Rattle, gravity: (0.0, -9.81, 0.0)), \
             contacts: (restitution: 0.0), wires: [\
             (shape: Sphere((radius: {MARBLE_BOWL:?})), side: Negative, catches: true), \
             (shape: Spline((kind: CatmullRom, points: [{points}], closed: false)), \
             sends_back: (to: {}, speed: 0.25, after: 0.2), beads: [{marbles}])])",
            self.timestep,
            at(rail[0]),
        );
        match SceneFile::from_ron(&text)? {
            SceneFile::Space(scene) => Ok(scene),
            SceneFile::Plane(_) => Err(PresetError::Dimension(2)),
        }
    }
}
