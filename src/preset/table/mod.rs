//! A scene's run as a table: every bead's position, velocity and contact
//! after every step in the file's order of its beads, the energy and the
//! largest constraint error. The analysis tool's `simulate --scene` and the
//! panel's export (from the [`Timeline`]) write it as the same CSV.

use std::io::Write;

use bevy::math::{DQuat, DVec2, DVec3};
use bevy::prelude::{Commands, Entity, World};

use super::{SceneFile, ScenePreset, SpaceScene};
use crate::dynamics::{Dimension, SimParams};
use crate::geometry::{
    ImplicitCurve, Placed, Pose, Pose3, SpaceMotion, SpaceShape, WireMotion, WireShape, WireSpace,
};
use crate::plugin::{RecordedBead, RecordedBody, Timeline};

mod measure;

pub use measure::{BodyState, Measure};
use measure::{carried_by, recorded};

/// The plane or space as a scene's run is measured in it: how far a bead
/// is off its wire, and a rigid body's state as a row writes it.
pub trait SceneSpace: Dimension {
    /// A wire as measured: its shape, resting pose and motion.
    type WireCheck: Clone + std::fmt::Debug + Send + Sync + 'static;
    /// A body's turn: its angle (rad, counter-clockwise) in the plane, its
    /// unit quaternion in space.
    type Turn: Copy + std::fmt::Debug + PartialEq + Send + Sync + 'static;
    /// A body's principal moments of inertia: one in the plane, three
    /// (about its own x, y and z) in space.
    type Inertia: Copy + std::fmt::Debug + PartialEq + Send + Sync + 'static;
    /// The names of a body's turn's columns: `angle`, or `qx, qy, qz, qw`.
    const TURN_COLUMNS: &'static [&'static str];
    /// The names of its spin's: `w`, or `wx, wy, wz`.
    const SPIN_COLUMNS: &'static [&'static str];
    /// A turn's and a spin's values, in their columns' order.
    fn turn_and_spin(turn: Self::Turn, spin: Self::Angular) -> Vec<f64>;
    /// `½ ωᵀ I ω` of a body turned by `turn` spinning at `spin` (world
    /// frame), its principal moments `inertia`.
    fn spin_energy(inertia: Self::Inertia, turn: Self::Turn, spin: Self::Angular) -> f64;
    /// The state of the rigid body `body` in `world`; `None` where it is
    /// none (or the build has no avian of this dimension).
    fn body(world: &World, body: Entity) -> Option<BodyState<Self>>;
    /// Where a body of a row is.
    fn body_pose(body: &BodyState<Self>) -> Self::Pose;
    /// The wire of `check` on a body at `on` (its own place then in the
    /// body's frame).
    fn carried(check: &Self::WireCheck, on: &Self::Pose) -> Self::WireCheck;
    /// `|C|` of a bead at `x` on `wire` at time `t`: in space, over a
    /// curve's two rows, the length of its offset.
    fn drift(wire: &Self::WireCheck, t: f64, x: Self) -> f64;
    /// A bead as `timeline` recorded it after step `step`.
    fn recorded(timeline: &Timeline, step: u64, bead: Entity) -> Option<RecordedBead<Self>>;
    /// A rigid body's state as a [`Timeline`] recorded it, as
    /// [`SceneSpace::body`] reads it from the world; `None` where the
    /// build has no avian of this dimension.
    fn recorded_body(body: &RecordedBody) -> Option<BodyState<Self>>;
}

impl SceneSpace for DVec2 {
    type WireCheck = (WireShape, Pose, WireMotion);
    type Turn = f64;
    type Inertia = f64;
    const TURN_COLUMNS: &'static [&'static str] = &["angle"];
    const SPIN_COLUMNS: &'static [&'static str] = &["w"];
    fn turn_and_spin(turn: f64, spin: f64) -> Vec<f64> {
        vec![turn, spin]
    }
    fn spin_energy(inertia: f64, _: f64, spin: f64) -> f64 {
        0.5 * inertia * spin * spin
    }
    #[cfg(feature = "avian2d")]
    fn body(world: &World, body: Entity) -> Option<BodyState<Self>> {
        super::bodies_plane::body_state(world, body).map(BodyState::from)
    }
    #[cfg(not(feature = "avian2d"))]
    fn body(_: &World, _: Entity) -> Option<BodyState<Self>> {
        None
    }
    #[cfg(feature = "avian2d")]
    fn recorded_body(body: &RecordedBody) -> Option<BodyState<Self>> {
        Some(super::bodies_plane::recorded_state(body).into())
    }
    #[cfg(not(feature = "avian2d"))]
    fn recorded_body(_: &RecordedBody) -> Option<BodyState<Self>> {
        None
    }
    fn body_pose(body: &BodyState<Self>) -> Pose {
        Pose::new(body.position, body.turn)
    }
    fn carried((shape, pose, motion): &Self::WireCheck, on: &Pose) -> Self::WireCheck {
        (shape.clone(), on.compose(pose), *motion)
    }
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
    type Turn = DQuat;
    type Inertia = DVec3;
    const TURN_COLUMNS: &'static [&'static str] = &["qx", "qy", "qz", "qw"];
    const SPIN_COLUMNS: &'static [&'static str] = &["wx", "wy", "wz"];
    fn turn_and_spin(turn: DQuat, spin: DVec3) -> Vec<f64> {
        let mut values = turn.to_array().to_vec();
        values.extend(spin.to_array());
        values
    }
    fn spin_energy(inertia: DVec3, turn: DQuat, spin: DVec3) -> f64 {
        let own = turn.inverse() * spin;
        0.5 * inertia.dot(own * own)
    }
    #[cfg(feature = "avian3d")]
    fn body(world: &World, body: Entity) -> Option<BodyState<Self>> {
        super::bodies_space::body_state(world, body).map(BodyState::from)
    }
    #[cfg(not(feature = "avian3d"))]
    fn body(_: &World, _: Entity) -> Option<BodyState<Self>> {
        None
    }
    #[cfg(feature = "avian3d")]
    fn recorded_body(body: &RecordedBody) -> Option<BodyState<Self>> {
        Some(super::bodies_space::recorded_state(body).into())
    }
    #[cfg(not(feature = "avian3d"))]
    fn recorded_body(_: &RecordedBody) -> Option<BodyState<Self>> {
        None
    }
    fn body_pose(body: &BodyState<Self>) -> Pose3 {
        Pose3 {
            origin: body.position,
            rotation: body.turn,
        }
    }
    fn carried((shape, pose, motion): &Self::WireCheck, on: &Pose3) -> Self::WireCheck {
        (shape.clone(), on.compose(pose), *motion)
    }
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
    /// Spawns it; its beads and its bodies in the file's order.
    fn spawn_all(&self, commands: &mut Commands) -> (Vec<Entity>, Vec<Entity>);
    /// Each bead's wire, mass, and the links.
    fn measure(&self) -> Result<Measure<Self::V>, String>;
    /// Each rigid body's name, in the file's order, and whether a run
    /// records it (a dynamic or kinematic body; a static one never moves).
    fn body_names(&self) -> Vec<(String, bool)>;
    /// Spawns it; its beads, and the bodies a run records, in the file's
    /// order.
    fn spawn_recorded(&self, commands: &mut Commands) -> (Vec<Entity>, Vec<Entity>) {
        let (beads, bodies) = self.spawn_all(commands);
        let recorded = bodies
            .into_iter()
            .zip(self.body_names())
            .filter_map(|(body, (_, recorded))| recorded.then_some(body))
            .collect();
        (beads, recorded)
    }
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
    fn spawn_all(&self, commands: &mut Commands) -> (Vec<Entity>, Vec<Entity>) {
        ScenePreset::spawn_all(self, commands)
    }
    fn body_names(&self) -> Vec<(String, bool)> {
        recorded(&self.bodies)
    }
    fn measure(&self) -> Result<Measure<DVec2>, String> {
        let wires: Vec<_> = self
            .wires
            .iter()
            .map(|wire| {
                let pose = Pose::new(wire.position, wire.angle_degrees.to_radians());
                let check = (wire.shape.clone(), pose, wire.motion);
                let (check, carrier) = carried_by::<DVec2, _>(check, &self.bodies, &wire.body);
                (check, carrier, wire.beads.len())
            })
            .collect();
        let measure = Measure::new(
            &wires,
            self.links().map_err(|e| e.to_string())?,
            self.all_beads().map(|b| b.mass).collect(),
            self.params.gravity,
        );
        let paths = self.paths().map_err(|e| e.to_string())?;
        Ok(measure.with_scene_bodies(&wires, &paths, &self.bodies))
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
    fn spawn_all(&self, commands: &mut Commands) -> (Vec<Entity>, Vec<Entity>) {
        SpaceScene::spawn_all(self, commands)
    }
    fn body_names(&self) -> Vec<(String, bool)> {
        recorded(&self.bodies)
    }
    fn measure(&self) -> Result<Measure<DVec3>, String> {
        let mut wires = Vec::new();
        for wire in &self.wires {
            let pose = wire.pose().map_err(|e| e.to_string())?;
            let check = (wire.shape.shape(), pose, wire.motion.motion());
            let (check, carrier) = carried_by::<DVec3, _>(check, &self.bodies, &wire.body);
            wires.push((check, carrier, wire.beads.len()));
        }
        let measure = Measure::new(
            &wires,
            self.links().map_err(|e| e.to_string())?,
            self.all_beads().map(|b| b.mass).collect(),
            self.params.0.gravity_in_space(),
        );
        let paths = self.paths().map_err(|e| e.to_string())?;
        Ok(measure.with_scene_bodies(&wires, &paths, &self.bodies))
    }
}

/// One row of a scene run: after a step, or at t = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneRow<V: SceneSpace = DVec2> {
    /// Time.
    pub t: f64,
    /// Every bead's position, in the file's order.
    pub positions: Vec<V>,
    /// Every bead's velocity.
    pub velocities: Vec<V>,
    /// Whether each bead is held on its wire (false in flight off a
    /// one-sided wire, and for a bead on no wire).
    pub on: Vec<bool>,
    /// Each recorded body's state (a dynamic or kinematic body), in the
    /// file's order.
    pub bodies: Vec<BodyState<V>>,
    /// Kinetic plus gravitational energy of all beads and bodies.
    pub energy: f64,
    /// The energy stored in the springs (not a CSV column; the analysis
    /// tool's `compare` adds it to `energy`).
    pub spring_energy: f64,
    /// The largest `|C|` of all constraints, wires included.
    pub max_abs_c: f64,
}

/// What a scene run produced.
#[derive(Clone, Debug, Default)]
pub struct SceneRun<V: SceneSpace = DVec2> {
    /// Every bead's name, in the file's order.
    pub names: Vec<String>,
    /// Every recorded body's name, in the file's order.
    pub body_names: Vec<String>,
    /// One row per step from t = 0, up to a divergence.
    pub rows: Vec<SceneRow<V>>,
    /// When a bead diverged, and why, if one did.
    pub diverged: Option<(f64, String)>,
}

/// Writes a scene run as CSV: `t`, then for each bead in the file's order
/// `<name>.x,<name>.y,<name>.vx,<name>.vy,<name>.on` in the plane, or
/// `<name>.x,<name>.y,<name>.z,<name>.vx,<name>.vy,<name>.vz,<name>.on` in
/// space (`on` 1 while held on its wire, 0 in flight off a one-sided wire
/// or on no wire), then for each dynamic or kinematic body
/// `<name>.x,<name>.y,<name>.angle,<name>.vx,<name>.vy,<name>.w` (the
/// angle in radians, counter-clockwise) in the plane, or
/// `<name>.x,<name>.y,<name>.z,<name>.qx,<name>.qy,<name>.qz,<name>.qw,<name>.vx,<name>.vy,<name>.vz,<name>.wx,<name>.wy,<name>.wz`
/// in space, then `energy,max_abs_c` (the energy the beads' and the
/// bodies' kinetic and gravitational energy).
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
    for name in &run.body_names {
        let columns = axes
            .iter()
            .map(|a| a.to_string())
            .chain(V::TURN_COLUMNS.iter().map(|c| c.to_string()))
            .chain(axes.iter().map(|a| format!("v{a}")))
            .chain(V::SPIN_COLUMNS.iter().map(|c| c.to_string()));
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
        for body in &row.bodies {
            let values = V::turn_and_spin(body.turn, body.spin);
            let (turn, spin) = values.split_at(V::TURN_COLUMNS.len());
            record.extend(&body.position.xyz().to_array()[..V::DIMENSION]);
            record.extend(turn);
            record.extend(&body.velocity.xyz().to_array()[..V::DIMENSION]);
            record.extend(spin);
        }
        record.extend([row.energy, row.max_abs_c]);
        writer.write_record(record.iter().map(|v| format!("{v:e}")))?;
    }
    writer.flush()?;
    Ok(())
}

/// The run the [`Timeline`] holds of `scene`, whose beads are `beads` and
/// whose recorded bodies are `bodies` in the file's order: a row for every
/// recorded step, from the oldest kept, up to a bead that stopped. None if
/// a bead or a body is missing from the first recorded step.
pub fn recorded_run<S: Scene>(
    scene: &S,
    (beads, bodies): (&[Entity], &[Entity]),
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
        let Some(clock) = timeline.clock(step) else {
            break;
        };
        for &bead in beads {
            let Some(recorded) = S::V::recorded(timeline, step, bead) else {
                break 'steps;
            };
            if let Some(at) = recorded.diverged {
                diverged = Some((at, "a bead diverged".to_owned()));
                break 'steps;
            }
            x.push(recorded.position);
            v.push(recorded.velocity);
            on.push(recorded.on_wire);
        }
        let states = bodies
            .iter()
            .map(|&body| S::V::recorded_body(timeline.body(step, body)?))
            .collect::<Option<Vec<_>>>();
        let Some(states) = states else {
            break 'steps;
        };
        rows.push(measure.row(clock.time, (x, v, on), states));
    }
    let body_names = scene.body_names().into_iter();
    (!rows.is_empty()).then(|| SceneRun {
        names: scene.bead_names(),
        body_names: body_names
            .filter_map(|(name, recorded)| recorded.then_some(name))
            .collect(),
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
    entities: (&[Entity], &[Entity]),
    timeline: &Timeline,
) -> Result<usize, String> {
    fn write<S: Scene>(
        out: impl Write,
        scene: &S,
        entities: (&[Entity], &[Entity]),
        timeline: &Timeline,
    ) -> Result<usize, String> {
        let run = recorded_run(scene, entities, timeline)
            .ok_or("nothing of this scene is recorded yet")?;
        write_scene_csv(out, &run).map_err(|e| e.to_string())?;
        Ok(run.rows.len())
    }
    match scene {
        SceneFile::Plane(scene) => write(out, scene, entities, timeline),
        SceneFile::Space(scene) => write(out, scene, entities, timeline),
    }
}
