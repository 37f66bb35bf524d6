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
//! the last step was cut). With avian's path joints
//! ([`PathJointPlugin`](crate::avian::PathJointPlugin) of either
//! dimension) a frame holds each of avian's moving bodies too, after
//! avian's step: where it is, how it is turned, how it moves and its
//! `Transform` ([`RecordedBody`]).

use std::any::Any;
use std::collections::VecDeque;

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use super::clock::SimClock;
use super::restart::Restart;
use super::schedule::WireBeadSystems;
use crate::dynamics::SimParams;

mod frame;

use frame::{BodiesFrame, Frame, Scenes, part};
pub use frame::{RecordedBead, RecordedBody};

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
                seek.in_set(RunFixedMainLoopSystems::AfterFixedMainLoop)
                    .in_set(TimelineSystems::Seek),
            )
            .add_systems(
                PreUpdate,
                forget_on_restart.in_set(WireBeadSystems::Restart),
            )
            .add_systems(
                FixedUpdate,
                record_start
                    .run_if(|timeline: Res<Timeline>| timeline.frames.is_empty())
                    .in_set(TimelineSystems::Start)
                    .before(WireBeadSystems::Prepare),
            )
            // When the whole step is done, avian's too: a bead riding a
            // body's wire is where avian took it.
            .add_systems(FixedLast, record_step.in_set(TimelineSystems::Step));
    }
}

/// Where the timeline records the run's start and takes the run to a
/// recorded step, for what records more with it (avian's bodies).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum TimelineSystems {
    /// Records the state before the first step (`FixedUpdate`).
    Start,
    /// Records the state after a step (`FixedLast`).
    Step,
    /// Takes the run to a recorded step (`RunFixedMainLoop`).
    Seek,
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

    /// The clock after step `step`, if it is recorded.
    pub fn clock(&self, step: u64) -> Option<SimClock> {
        self.frame(step).map(|frame| frame.clock)
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

    /// A rigid body of avian as recorded after step `step`, if the frame
    /// holds one (an app with avian's path joints records every body that
    /// is not static).
    pub fn body(&self, step: u64, body: Entity) -> Option<&RecordedBody> {
        let frame = self.frame(step)?;
        frame.bodies.iter().flatten().find_map(|part| {
            let i = part.bodies.binary_search_by_key(&body, |b| b.entity).ok()?;
            Some(&part.bodies[i])
        })
    }

    #[cfg_attr(
        not(any(feature = "avian2d", feature = "avian3d")),
        allow(dead_code, reason = "the avian adapters record the bodies")
    )]
    /// Whether the frame of step `step` still waits for the bodies of the
    /// dimension `dimension` (2 or 3).
    pub(crate) fn wants_bodies(&self, dimension: usize, step: u64) -> bool {
        self.frame(step)
            .is_some_and(|frame| frame.bodies[part(dimension)].is_none())
    }

    #[cfg_attr(
        not(any(feature = "avian2d", feature = "avian3d")),
        allow(dead_code, reason = "the avian adapters record the bodies")
    )]
    /// The bodies of the dimension `dimension` recorded after step `step`,
    /// and what was recorded of their joints.
    pub(crate) fn bodies(
        &self,
        dimension: usize,
        step: u64,
    ) -> Option<(&[RecordedBody], &dyn Any)> {
        let part = self.frame(step)?.bodies[part(dimension)].as_ref()?;
        Some((&part.bodies, &*part.joints))
    }

    #[cfg_attr(
        not(any(feature = "avian2d", feature = "avian3d")),
        allow(dead_code, reason = "the avian adapters record the bodies")
    )]
    /// Adds the bodies of the dimension `dimension` (2 or 3) after step
    /// `step`, once avian has stepped them, to that step's frame, with
    /// what the adapter keeps of their joints (`joints`, of `bytes`).
    /// Where the frame holds them already (the run is going along its
    /// recording after a seek) they are compared: bodies that came out
    /// different replace them and drop the recording after the step, as
    /// beads that depart do.
    pub(crate) fn record_bodies(
        &mut self,
        (dimension, step): (usize, u64),
        mut bodies: Vec<RecordedBody>,
        (joints, bytes): (Box<dyn Any + Send + Sync>, usize),
    ) {
        let Some(i) = self.index(step) else {
            return;
        };
        bodies.sort_unstable_by_key(|b| b.entity);
        let bytes = bytes + bodies.len() * size_of::<RecordedBody>();
        match &self.frames[i].bodies[part(dimension)] {
            Some(recorded) if recorded.bodies == bodies => return,
            Some(recorded) => {
                self.bytes -= recorded.bytes;
                self.frames[i].bytes -= recorded.bytes;
                self.departed.get_or_insert(step);
                self.matched = self.matched.saturating_sub(1);
                for dropped in self.frames.drain(i + 1..) {
                    self.bytes -= dropped.bytes;
                }
                self.at = None;
            }
            None => {}
        }
        let frame = &mut self.frames[i];
        frame.bodies[part(dimension)] = Some(BodiesFrame {
            bodies,
            joints,
            bytes,
        });
        frame.bytes += bytes;
        self.bytes += bytes;
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
        bodies: [None, None],
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
