//! [`TimelinePlugin`]: the run's states, step by step, in a bounded
//! history ([`Timeline`]): step back to any of them and run on from there,
//! the same run bit for bit until something is changed.
//!
//! Every step is deterministic, so a run taken again from a recorded state
//! with the same inputs is the same run. A frame holds everything a step
//! reads from the steps before it: each bead's position, velocity, wire
//! contact, diagnostics and `Transform`, whether it stopped; each wire's
//! pose; which wires a game is moving; the clock; and the islands with
//! what their work carries from step to step (which rows are held, the
//! beads' places along their wires, where friction holds them, how finely
//! the last step was cut).

use std::collections::VecDeque;

use bevy::ecs::system::SystemParam;
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use super::clock::SimClock;
use super::islands::Islands;
use super::restart::Restart;
use super::schedule::WireBeadSystems;
use super::wires::MovingWires;
use crate::dynamics::{
    BeadDiagnostics, BeadPosition, BeadVelocity, Dimension, Diverged, RailOrientation, SimParams,
    WireContact, WirePlace, WirePose,
};

/// Records every step in the [`Timeline`] and takes the run back to any
/// recorded step on a [`TimelineSeek`]. Needs
/// [`WireBeadPlugin`](crate::WireBeadPlugin). Not part of it: a game that
/// does not scrub its run keeps no history.
#[derive(Default)]
pub struct TimelinePlugin;

impl Plugin for TimelinePlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Timeline>()
            .add_message::<TimelineSeek>()
            .add_observer(beads_changed::<Add, crate::Bead>)
            .add_observer(beads_changed::<Remove, crate::Bead>)
            .add_observer(beads_changed::<Add, crate::SpaceBead>)
            .add_observer(beads_changed::<Remove, crate::SpaceBead>)
            // After the frame's fixed steps, so that none runs between the
            // step back and the pause.
            .add_systems(
                RunFixedMainLoop,
                seek.in_set(RunFixedMainLoopSystems::AfterFixedMainLoop),
            )
            .add_systems(
                PreUpdate,
                forget_on_restart.in_set(WireBeadSystems::Restart),
            )
            .add_systems(
                FixedUpdate,
                (
                    record_start
                        .run_if(|timeline: Res<Timeline>| timeline.frames.is_empty())
                        .before(WireBeadSystems::Prepare),
                    record_step.after(WireBeadSystems::Writeback),
                ),
            );
    }
}

/// Takes the run back (or forward) to a recorded step, and pauses it there
/// (`Time<Virtual>`); the next step runs on from it. Read after the
/// frame's fixed steps.
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimelineSeek {
    /// One step back from where the run is.
    Back,
    /// To the state after step `n` ([`SimClock::steps`]; 0 is the start),
    /// or the nearest recorded one.
    To(u64),
}

/// The run's recorded states, oldest first: one before the first step and
/// one after every step, up to [`Timeline::seconds`] of them (and at most
/// [`Timeline::max_bytes`] of memory), the oldest dropped first.
///
/// After a [`TimelineSeek`] the run is at a recorded step before the
/// newest. Each step from there is compared with the recorded one: where
/// they are the same (every bead's position and velocity bit for bit, its
/// contact, diagnostics and whether it stopped, and the clock) the
/// recording is kept and the run moves along it
/// ([`Timeline::matched`]); where they differ (the drag moved a bead, a
/// game changed something) the recording after that step is dropped and
/// the new run recorded in its place ([`Timeline::departed`]). A
/// [`Restart`] or a bead added or removed starts the recording anew.
#[derive(Resource)]
pub struct Timeline {
    frames: VecDeque<Frame>,
    /// The frame the run is at, while it is at one before the newest.
    at: Option<usize>,
    /// How many seconds of simulated time to keep.
    pub seconds: f64,
    /// The most memory the frames may take, roughly, in bytes.
    pub max_bytes: usize,
    bytes: usize,
    matched: u64,
    departed: Option<u64>,
}

impl Default for Timeline {
    fn default() -> Self {
        Self {
            frames: VecDeque::new(),
            at: None,
            seconds: 30.0,
            max_bytes: 256 << 20,
            bytes: 0,
            matched: 0,
            departed: None,
        }
    }
}

impl Timeline {
    /// How many steps are recorded (frames after the first).
    pub fn len(&self) -> usize {
        self.frames.len().saturating_sub(1)
    }

    /// Whether nothing is recorded yet.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// The first and last recorded steps ([`SimClock::steps`]) and their
    /// times, if any is recorded.
    pub fn span(&self) -> Option<(SimClock, SimClock)> {
        Some((self.frames.front()?.clock, self.frames.back()?.clock))
    }

    /// The step the run is at: a recorded one before the newest after a
    /// [`TimelineSeek`], else `None` (the run is at its newest step).
    pub fn at(&self) -> Option<SimClock> {
        self.at.map(|i| self.frames[i].clock)
    }

    /// Steps run on from a recorded one since the last seek that came out
    /// the same as the recorded ones, bit for bit.
    pub fn matched(&self) -> u64 {
        self.matched
    }

    /// The step, since the last seek, at which the run first came out
    /// different from the recording (so the recording after it was
    /// dropped), if one did.
    pub fn departed(&self) -> Option<u64> {
        self.departed
    }

    /// Roughly how much memory the frames take, in bytes.
    pub fn bytes(&self) -> usize {
        self.bytes
    }

    /// A bead's recorded position and velocity after step `step`
    /// ([`SimClock::steps`]), in the plane.
    pub fn bead(&self, step: u64, bead: Entity) -> Option<(DVec2, DVec2)> {
        self.recorded(step, bead).map(|b| (b.position, b.velocity))
    }

    /// A bead's recorded position and velocity after step `step`, in space.
    pub fn space_bead(&self, step: u64, bead: Entity) -> Option<(DVec3, DVec3)> {
        self.space_recorded(step, bead)
            .map(|b| (b.position, b.velocity))
    }

    /// A bead in the plane as recorded after step `step`.
    pub fn recorded(&self, step: u64, bead: Entity) -> Option<RecordedBead<DVec2>> {
        let frame = self.frame(step)?;
        frame.plane.bead(bead, frame.clock.time)
    }

    /// A bead in space as recorded after step `step`.
    pub fn space_recorded(&self, step: u64, bead: Entity) -> Option<RecordedBead<DVec3>> {
        let frame = self.frame(step)?;
        frame.space.bead(bead, frame.clock.time)
    }

    /// Forgets everything recorded.
    pub fn clear(&mut self) {
        self.frames.clear();
        self.at = None;
        self.bytes = 0;
        self.matched = 0;
        self.departed = None;
    }

    fn index(&self, step: u64) -> Option<usize> {
        let first = self.frames.front()?.clock.steps;
        let i = usize::try_from(step.checked_sub(first)?).ok()?;
        (i < self.frames.len()).then_some(i)
    }

    fn frame(&self, step: u64) -> Option<&Frame> {
        self.frames.get(self.index(step)?)
    }

    /// Adds the state after a step: compared with the recorded next one
    /// while the run is at a recorded step, else appended (dropping the
    /// oldest beyond the limits).
    fn record(&mut self, frame: Frame, timestep: f64) {
        if let Some(i) = self.at {
            if self.frames[i + 1].same(&frame) {
                self.matched += 1;
                self.at = (i + 2 < self.frames.len()).then_some(i + 1);
                return;
            }
            self.departed.get_or_insert(frame.clock.steps);
            for dropped in self.frames.drain(i + 1..) {
                self.bytes -= dropped.bytes;
            }
            self.at = None;
        }
        self.bytes += frame.bytes;
        self.frames.push_back(frame);
        let keep = (self.seconds / timestep).ceil().max(1.0) as usize + 1;
        while self.frames.len() > 2 && (self.frames.len() > keep || self.bytes > self.max_bytes) {
            if let Some(dropped) = self.frames.pop_front() {
                self.bytes -= dropped.bytes;
            }
        }
    }
}

/// One bead as a [`Timeline`] recorded it after a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordedBead<V> {
    /// The time after the step ([`SimClock::time`]).
    pub time: f64,
    /// Its position.
    pub position: V,
    /// Its velocity.
    pub velocity: V,
    /// Whether it was held on its wire (not in flight off a one-sided
    /// wire, and on a wire at all).
    pub on_wire: bool,
    /// When it diverged, if it had.
    pub diverged: Option<f64>,
}

/// The whole state after one step.
struct Frame {
    clock: SimClock,
    plane: Scene<DVec2>,
    space: Scene<DVec3>,
    bytes: usize,
}

impl Frame {
    /// Whether `other` is the same state (see [`Timeline`]).
    fn same(&self, other: &Frame) -> bool {
        self.clock.steps == other.clock.steps
            && self.clock.time.to_bits() == other.clock.time.to_bits()
            && self.plane.same(&other.plane)
            && self.space.same(&other.space)
    }
}

/// A wire as a frame holds it: its pose, `Transform` and place.
type WireFrame<V> = (Entity, WirePose<V>, Transform, Option<WirePlace<V>>);

/// One dimension's part of a frame.
struct Scene<V: Dimension> {
    beads: Vec<BeadFrame<V>>,
    wires: Vec<WireFrame<V>>,
    moving: MovingWires<V>,
    islands: Islands<V>,
}

impl<V: Dimension> Scene<V> {
    fn bead(&self, bead: Entity, time: f64) -> Option<RecordedBead<V>> {
        let i = self.beads.binary_search_by_key(&bead, |b| b.entity).ok()?;
        let b = &self.beads[i];
        Some(RecordedBead {
            time,
            position: b.position,
            velocity: b.velocity,
            on_wire: b.contact.is_some_and(|c| c.is_on()),
            diverged: b.diverged.as_ref().map(|d| d.time),
        })
    }

    fn same(&self, other: &Self) -> bool {
        self.beads.len() == other.beads.len()
            && self.beads.iter().zip(&other.beads).all(|(a, b)| a.same(b))
    }

    /// Roughly how much memory it takes.
    fn bytes(&self) -> usize {
        self.beads.len() * size_of::<BeadFrame<V>>()
            + self.wires.len() * size_of::<WireFrame<V>>()
            + self.islands.bytes()
    }
}

/// One bead as a frame holds it.
#[derive(Clone, Debug)]
struct BeadFrame<V: Dimension> {
    entity: Entity,
    position: V,
    velocity: V,
    contact: Option<WireContact>,
    diagnostics: Option<BeadDiagnostics<V>>,
    diverged: Option<Diverged>,
    transform: Option<Transform>,
    rail: Option<RailOrientation>,
}

impl<V: Dimension> BeadFrame<V> {
    /// The same bead in the same state: position and velocity bit for bit.
    fn same(&self, other: &Self) -> bool {
        let bits = |v: V| v.xyz().to_array().map(f64::to_bits);
        let contact = |c: &Option<WireContact>| c.map(|c| (c.contact, c.along.to_bits()));
        self.entity == other.entity
            && bits(self.position) == bits(other.position)
            && bits(self.velocity) == bits(other.velocity)
            && contact(&self.contact) == contact(&other.contact)
            && self.diagnostics == other.diagnostics
            && self.diverged == other.diverged
    }
}

/// A bead's recorded columns.
type BeadColumns<V> = (
    Entity,
    &'static mut BeadPosition<V>,
    &'static mut BeadVelocity<V>,
    Option<&'static mut WireContact>,
    Option<&'static mut BeadDiagnostics<V>>,
    Option<&'static Diverged>,
    Option<&'static mut Transform>,
    Option<&'static mut RailOrientation>,
);

/// One dimension's state in the world, to record or restore.
#[derive(SystemParam)]
struct SceneState<'w, 's, V: Dimension> {
    beads: Query<'w, 's, BeadColumns<V>, With<<V as Dimension>::Bead>>,
    wires: Query<
        'w,
        's,
        (
            Entity,
            &'static mut WirePose<V>,
            &'static mut Transform,
            Option<&'static mut WirePlace<V>>,
        ),
        (
            With<<V as Dimension>::Wire>,
            Without<<V as Dimension>::Bead>,
        ),
    >,
    moving: ResMut<'w, MovingWires<V>>,
    islands: ResMut<'w, Islands<V>>,
}

impl<V: Dimension> SceneState<'_, '_, V> {
    fn capture(&self) -> Scene<V> {
        let mut beads: Vec<BeadFrame<V>> = self
            .beads
            .iter()
            .map(
                |(entity, position, velocity, contact, diagnostics, diverged, transform, rail)| {
                    BeadFrame {
                        entity,
                        position: position.0,
                        velocity: velocity.0,
                        contact: contact.copied(),
                        diagnostics: diagnostics.copied(),
                        diverged: diverged.cloned(),
                        transform: transform.copied(),
                        rail: rail.copied(),
                    }
                },
            )
            .collect();
        beads.sort_unstable_by_key(|b| b.entity);
        Scene {
            beads,
            wires: self
                .wires
                .iter()
                .map(|(entity, pose, transform, place)| (entity, *pose, *transform, place.copied()))
                .collect(),
            moving: self.moving.clone(),
            islands: self.islands.clone(),
        }
    }

    fn restore(&mut self, scene: &Scene<V>, commands: &mut Commands) {
        for b in &scene.beads {
            let Ok((
                entity,
                mut position,
                mut velocity,
                contact,
                diagnostics,
                diverged,
                transform,
                rail,
            )) = self.beads.get_mut(b.entity)
            else {
                continue;
            };
            position.set_if_neq(BeadPosition(b.position));
            velocity.set_if_neq(BeadVelocity(b.velocity));
            if let (Some(mut now), Some(then)) = (contact, b.contact) {
                *now = then;
            }
            if let (Some(mut now), Some(then)) = (diagnostics, b.diagnostics) {
                now.set_if_neq(then);
            }
            if let (Some(mut now), Some(then)) = (transform, b.transform) {
                now.set_if_neq(then);
            }
            if let (Some(mut now), Some(then)) = (rail, b.rail) {
                *now = then;
            }
            match (diverged, &b.diverged) {
                (Some(_), None) => {
                    commands.entity(entity).remove::<Diverged>();
                }
                (None, Some(then)) => {
                    commands.entity(entity).insert(then.clone());
                }
                _ => {}
            }
        }
        for (entity, pose, transform, place) in &scene.wires {
            if let Ok((_, mut now, mut shown, placed)) = self.wires.get_mut(*entity) {
                now.set_if_neq(*pose);
                shown.set_if_neq(*transform);
                if let (Some(mut placed), Some(place)) = (placed, place) {
                    placed.set_if_neq(*place);
                }
            }
        }
        *self.moving = scene.moving.clone();
        *self.islands = scene.islands.clone();
    }
}

/// The plane's and space's states (they share `Transform`).
type Scenes<'w, 's> = ParamSet<
    'w,
    's,
    (
        SceneState<'static, 'static, DVec2>,
        SceneState<'static, 'static, DVec3>,
    ),
>;

/// Records the state before the first step.
fn record_start(
    timeline: ResMut<Timeline>,
    clock: Res<SimClock>,
    params: Res<SimParams>,
    scenes: Scenes,
) {
    record_step(timeline, clock, params, scenes);
}

/// Records the state after each step (or checks it against the recorded
/// one).
fn record_step(
    mut timeline: ResMut<Timeline>,
    clock: Res<SimClock>,
    params: Res<SimParams>,
    mut scenes: Scenes,
) {
    let plane = scenes.p0().capture();
    let space = scenes.p1().capture();
    let bytes = size_of::<Frame>() + plane.bytes() + space.bytes();
    let frame = Frame {
        clock: *clock,
        plane,
        space,
        bytes,
    };
    timeline.record(frame, params.timestep);
}

/// Takes the run to the step asked for and pauses it there.
fn seek(
    mut requests: MessageReader<TimelineSeek>,
    mut timeline: ResMut<Timeline>,
    mut clock: ResMut<SimClock>,
    mut time: ResMut<Time<Virtual>>,
    mut scenes: Scenes,
    mut commands: Commands,
) {
    let Some(request) = requests.read().last().copied() else {
        return;
    };
    let Some(newest) = timeline.frames.len().checked_sub(1) else {
        return;
    };
    let now = timeline.at.unwrap_or(newest);
    let i = match request {
        TimelineSeek::Back => now.saturating_sub(1),
        TimelineSeek::To(step) => {
            let first = timeline.frames[0].clock.steps;
            usize::try_from(step.saturating_sub(first)).map_or(newest, |i| i.min(newest))
        }
    };
    time.pause();
    let frame = &timeline.frames[i];
    *clock = frame.clock;
    scenes.p0().restore(&frame.plane, &mut commands);
    scenes.p1().restore(&frame.space, &mut commands);
    timeline.at = (i < newest).then_some(i);
    timeline.matched = 0;
    timeline.departed = None;
}

/// A restart begins a new run: the recording starts again.
fn forget_on_restart(mut restarts: MessageReader<Restart>, mut timeline: ResMut<Timeline>) {
    if restarts.read().count() > 0 {
        timeline.clear();
    }
}

/// A bead added or removed: the recorded states no longer fit the world.
fn beads_changed<E: EntityEvent, B: Bundle>(_: On<E, B>, timeline: Option<ResMut<Timeline>>) {
    if let Some(mut timeline) = timeline {
        timeline.clear();
    }
}
