//! A scene's run as a table: every bead's position, velocity and contact
//! after every step in the file's order of its beads, the energy and the
//! largest constraint error. The analysis tool's `simulate --scene` and the
//! panel's export (from the [`Timeline`]) write it as the same CSV.

use std::io::Write;

use bevy::math::{DVec2, DVec3};
use bevy::prelude::{Commands, Entity};

use super::{SceneFile, SceneLink, ScenePreset, SpaceScene};
use crate::dynamics::{Dimension, SimParams};
use crate::geometry::{
    ImplicitCurve, Placed, Pose, Pose3, SpaceMotion, SpaceShape, WireMotion, WireShape, WireSpace,
};
use crate::plugin::{RecordedBead, Timeline};

/// The plane or space as a scene's run is measured in it: how far a bead
/// is off its wire.
pub trait SceneSpace: Dimension {
    /// A wire as measured: its shape, resting pose and motion.
    type WireCheck: Clone + std::fmt::Debug + Send + Sync + 'static;
    /// `|C|` of a bead at `x` on `wire` at time `t`: in space, over a
    /// curve's two rows, the length of its offset.
    fn drift(wire: &Self::WireCheck, t: f64, x: Self) -> f64;
    /// A bead as `timeline` recorded it after step `step`.
    fn recorded(timeline: &Timeline, step: u64, bead: Entity) -> Option<RecordedBead<Self>>;
}

impl SceneSpace for DVec2 {
    type WireCheck = (WireShape, Pose, WireMotion);
    fn drift((shape, pose, motion): &Self::WireCheck, t: f64, x: Self) -> f64 {
        Placed {
            curve: shape.curve(),
            pose: motion.at(*pose, t).0,
        }
        .value(x)
        .abs()
    }
    fn recorded(timeline: &Timeline, step: u64, bead: Entity) -> Option<RecordedBead<Self>> {
        timeline.recorded(step, bead)
    }
}

impl SceneSpace for DVec3 {
    type WireCheck = (SpaceShape, Pose3, SpaceMotion);
    fn drift((shape, pose, motion): &Self::WireCheck, t: f64, x: Self) -> f64 {
        let local = motion.at(*pose, t).0.to_local(x);
        shape.rows().iter().fold(0.0, |offset, row| {
            offset.hypot(DVec3::shape_geometry(row, local, None).c)
        })
    }
    fn recorded(timeline: &Timeline, step: u64, bead: Entity) -> Option<RecordedBead<Self>> {
        timeline.space_recorded(step, bead)
    }
}

/// A scene file of either dimension, as its run is measured.
pub trait Scene {
    /// Its coordinates.
    type V: SceneSpace;
    /// Its parameters.
    fn params(&self) -> &SimParams;
    /// Its name.
    fn name(&self) -> &str;
    /// Each bead's name, in the file's order.
    fn bead_names(&self) -> Vec<String>;
    /// Spawns it; its beads in the file's order.
    fn spawn(&self, commands: &mut Commands) -> Vec<Entity>;
    /// Each bead's wire, mass, and the links.
    fn measure(&self) -> Result<Measure<Self::V>, String>;
}

impl Scene for ScenePreset {
    type V = DVec2;
    fn params(&self) -> &SimParams {
        &self.params
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn bead_names(&self) -> Vec<String> {
        ScenePreset::bead_names(self)
    }
    fn spawn(&self, commands: &mut Commands) -> Vec<Entity> {
        ScenePreset::spawn(self, commands)
    }
    fn measure(&self) -> Result<Measure<DVec2>, String> {
        let wires = self.wires.iter().map(|wire| {
            let pose = Pose::new(wire.position, wire.angle_degrees.to_radians());
            ((wire.shape.clone(), pose, wire.motion), wire.beads.len())
        });
        Ok(Measure::new(
            wires,
            self.links().map_err(|e| e.to_string())?,
            self.all_beads().map(|b| b.mass).collect(),
            self.params.gravity,
        ))
    }
}

impl Scene for SpaceScene {
    type V = DVec3;
    fn params(&self) -> &SimParams {
        &self.params.0
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn bead_names(&self) -> Vec<String> {
        SpaceScene::bead_names(self)
    }
    fn spawn(&self, commands: &mut Commands) -> Vec<Entity> {
        SpaceScene::spawn(self, commands)
    }
    fn measure(&self) -> Result<Measure<DVec3>, String> {
        let mut wires = Vec::new();
        for wire in &self.wires {
            let pose = wire.pose().map_err(|e| e.to_string())?;
            let check = (wire.shape.shape(), pose, wire.motion.motion());
            wires.push((check, wire.beads.len()));
        }
        Ok(Measure::new(
            wires.into_iter(),
            self.links().map_err(|e| e.to_string())?,
            self.all_beads().map(|b| b.mass).collect(),
            self.params.0.gravity_in_space(),
        ))
    }
}

/// One constraint to measure, with beads as indices in the file's order.
#[derive(Clone, Debug)]
enum Check<V: SceneSpace> {
    /// A bead on a wire.
    Wire(usize, V::WireCheck),
    Rod(usize, usize, f64),
    Pin(usize, V),
}

/// What a scene's rows are measured against: its constraints, springs and
/// masses.
#[derive(Clone, Debug)]
pub struct Measure<V: SceneSpace> {
    checks: Vec<Check<V>>,
    springs: Vec<(usize, usize, f64, f64)>,
    masses: Vec<f64>,
    gravity: V,
}

/// `|v|`.
fn length<V: SceneSpace>(v: V) -> f64 {
    v.dot(v).sqrt()
}

impl<V: SceneSpace> Measure<V> {
    /// A scene's measure: each wire with its number of beads (the wires'
    /// beads come first in the file's order), the links, every bead's
    /// mass and gravity.
    pub(crate) fn new(
        wires: impl Iterator<Item = (V::WireCheck, usize)>,
        links: Vec<SceneLink<V>>,
        masses: Vec<f64>,
        gravity: V,
    ) -> Self {
        let mut checks = Vec::new();
        let mut bead = 0;
        for (wire, count) in wires {
            for _ in 0..count {
                checks.push(Check::Wire(bead, wire.clone()));
                bead += 1;
            }
        }
        let mut springs = Vec::new();
        for link in links {
            match link {
                SceneLink::Rod { a, b, length } => checks.push(Check::Rod(a, b, length)),
                SceneLink::Pin { bead, at } => checks.push(Check::Pin(bead, at)),
                SceneLink::Spring { a, b, spring } => {
                    springs.push((a, b, spring.rest_length, spring.stiffness))
                }
            }
        }
        Self {
            checks,
            springs,
            masses,
            gravity,
        }
    }

    /// The largest `|C|` at time `t` of every constraint, wires included
    /// (a bead in flight off its wire left out).
    pub fn max_abs_c(&self, t: f64, x: &[V], on: &[bool]) -> f64 {
        self.checks
            .iter()
            .map(|check| match check {
                Check::Wire(b, _) if !on[*b] => 0.0,
                Check::Wire(b, wire) => V::drift(wire, t, x[*b]),
                Check::Rod(a, b, rod) => (length(x[*a] - x[*b]) - rod).abs(),
                Check::Pin(b, at) => length(x[*b] - *at),
            })
            .fold(0.0, f64::max)
    }

    /// Kinetic plus gravitational energy of every bead.
    pub fn energy(&self, x: &[V], v: &[V]) -> f64 {
        self.masses
            .iter()
            .zip(x.iter().zip(v))
            .map(|(m, (x, v))| 0.5 * m * v.dot(*v) - m * self.gravity.dot(*x))
            .sum()
    }

    /// The row of the beads' state at time `t`: every bead's position
    /// and velocity in the file's order, and whether each is held on its
    /// wire.
    pub fn row(&self, t: f64, positions: Vec<V>, velocities: Vec<V>, on: Vec<bool>) -> SceneRow<V> {
        SceneRow {
            t,
            energy: self.energy(&positions, &velocities),
            spring_energy: self.spring_energy(&positions),
            max_abs_c: self.max_abs_c(t, &positions, &on),
            positions,
            velocities,
            on,
        }
    }

    /// The energy stored in the springs.
    pub fn spring_energy(&self, x: &[V]) -> f64 {
        self.springs
            .iter()
            .map(|&(a, b, rest, k)| {
                let stretch = length(x[a] - x[b]) - rest;
                0.5 * k * stretch * stretch
            })
            .sum()
    }
}

/// One row of a scene run: after a step, or at t = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneRow<V = DVec2> {
    /// Time.
    pub t: f64,
    /// Every bead's position, in the file's order.
    pub positions: Vec<V>,
    /// Every bead's velocity.
    pub velocities: Vec<V>,
    /// Whether each bead is held on its wire (false in flight off a
    /// one-sided wire, and for a bead on no wire).
    pub on: Vec<bool>,
    /// Kinetic plus gravitational energy of all beads.
    pub energy: f64,
    /// The energy stored in the springs (not a CSV column; the analysis
    /// tool's `compare` adds it to `energy`).
    pub spring_energy: f64,
    /// The largest `|C|` of all constraints, wires included.
    pub max_abs_c: f64,
}

/// What a scene run produced.
#[derive(Clone, Debug, Default)]
pub struct SceneRun<V = DVec2> {
    /// Every bead's name, in the file's order.
    pub names: Vec<String>,
    /// One row per step from t = 0, up to a divergence.
    pub rows: Vec<SceneRow<V>>,
    /// When a bead diverged, and why, if one did.
    pub diverged: Option<(f64, String)>,
}

/// Writes a scene run as CSV: `t`, then for each bead in the file's order
/// `<name>.x,<name>.y,<name>.vx,<name>.vy,<name>.on` in the plane, or
/// `<name>.x,<name>.y,<name>.z,<name>.vx,<name>.vy,<name>.vz,<name>.on` in
/// space (`on` 1 while held on its wire, 0 in flight off a one-sided wire
/// or on no wire), then `energy,max_abs_c`.
pub fn write_scene_csv<V: SceneSpace>(out: impl Write, run: &SceneRun<V>) -> csv::Result<()> {
    let mut writer = csv::Writer::from_writer(out);
    let axes = &["x", "y", "z"][..V::DIMENSION];
    let mut header = vec!["t".to_owned()];
    for name in &run.names {
        let columns = axes
            .iter()
            .map(|a| a.to_string())
            .chain(axes.iter().map(|a| format!("v{a}")))
            .chain(["on".to_owned()]);
        header.extend(columns.map(|c| format!("{name}.{c}")));
    }
    header.extend(["energy".to_owned(), "max_abs_c".to_owned()]);
    writer.write_record(&header)?;
    for row in &run.rows {
        let mut record = vec![row.t];
        for ((x, v), on) in row.positions.iter().zip(&row.velocities).zip(&row.on) {
            record.extend(&x.xyz().to_array()[..V::DIMENSION]);
            record.extend(&v.xyz().to_array()[..V::DIMENSION]);
            record.push(f64::from(u8::from(*on)));
        }
        record.extend([row.energy, row.max_abs_c]);
        writer.write_record(record.iter().map(|v| format!("{v:e}")))?;
    }
    writer.flush()?;
    Ok(())
}

/// The run the [`Timeline`] holds of `scene`, whose beads are `beads` in
/// the file's order: a row for every recorded step, from the oldest kept,
/// up to a bead that stopped. None if a bead is missing from the first
/// recorded step.
pub fn recorded_run<S: Scene>(
    scene: &S,
    beads: &[Entity],
    timeline: &Timeline,
) -> Option<SceneRun<S::V>> {
    let measure = scene.measure().ok()?;
    let (first, last) = timeline.span()?;
    let mut rows = Vec::new();
    let mut diverged = None;
    'steps: for step in first.steps..=last.steps {
        let mut x = Vec::with_capacity(beads.len());
        let mut v = Vec::with_capacity(beads.len());
        let mut on = Vec::with_capacity(beads.len());
        let mut t = 0.0;
        for &bead in beads {
            let Some(recorded) = S::V::recorded(timeline, step, bead) else {
                break 'steps;
            };
            if let Some(at) = recorded.diverged {
                diverged = Some((at, "a bead diverged".to_owned()));
                break 'steps;
            }
            t = recorded.time;
            x.push(recorded.position);
            v.push(recorded.velocity);
            on.push(recorded.on_wire);
        }
        rows.push(measure.row(t, x, v, on));
    }
    (!rows.is_empty()).then(|| SceneRun {
        names: scene.bead_names(),
        rows,
        diverged,
    })
}

/// [`recorded_run`] of a scene file of either dimension, written as CSV
/// ([`write_scene_csv`]) to `out`: the number of rows, or why nothing was
/// written.
pub fn write_recorded_csv(
    out: impl Write,
    scene: &SceneFile,
    beads: &[Entity],
    timeline: &Timeline,
) -> Result<usize, String> {
    fn write<S: Scene>(
        out: impl Write,
        scene: &S,
        beads: &[Entity],
        timeline: &Timeline,
    ) -> Result<usize, String> {
        let run =
            recorded_run(scene, beads, timeline).ok_or("nothing of this scene is recorded yet")?;
        write_scene_csv(out, &run).map_err(|e| e.to_string())?;
        Ok(run.rows.len())
    }
    match scene {
        SceneFile::Plane(scene) => write(out, scene, beads, timeline),
        SceneFile::Space(scene) => write(out, scene, beads, timeline),
    }
}
