//! A rigid body put back where it started when the run restarts, as the
//! beads are, and where the [`Timeline`](crate::plugin::Timeline) recorded
//! it when the run is taken back to a step: what both avian crates share,
//! written once as a macro over their same-named components.

/// Defines, in an avian adapter's module, `BodyStart`, the system
/// `restart_bodies` that puts each body that has one back at its start on
/// a [`Restart`](crate::Restart), and the systems that record avian's
/// moving bodies in the [`Timeline`](crate::plugin::Timeline)
/// (`record_bodies`) and put them back where it recorded them on a
/// [`TimelineSeek`](crate::plugin::TimelineSeek) (`seek_bodies`), added
/// by `add_timeline_systems(app)`. `$dimension` is 2 or 3; `$record`
/// turns a body's state into a
/// [`RecordedBody`](crate::plugin::RecordedBody) and `$recorded` back.
macro_rules! body_start {
    ($avian:ident, $dimension:expr, record: $record:path, recorded: $recorded:path) => {
        /// Where a rigid body started and how it moved then: a
        /// [`Restart`](crate::Restart) puts it back so, its path joint (if
        /// it has one) met afresh, as the beads are put back at their
        /// start. A scene file's bodies have one; a game's bodies have
        /// none unless it gives them one.
        #[derive(bevy::prelude::Component, Clone, Copy, Debug, PartialEq)]
        pub struct BodyStart {
            /// Its origin.
            pub position: $avian::prelude::Position,
            /// Its turn.
            pub rotation: $avian::prelude::Rotation,
            /// Its velocity.
            pub linear: $avian::prelude::LinearVelocity,
            /// Its spin.
            pub angular: $avian::prelude::AngularVelocity,
        }

        /// What a body is put back with: whether it has a path joint and
        /// is asleep.
        type PutBack = (
            bevy::prelude::Entity,
            bevy::prelude::Has<PathJoint>,
            bevy::prelude::Has<$avian::prelude::Sleeping>,
        );

        /// Puts `entity` back with `state` (its position, rotation and
        /// velocities, and on a seek its `Transform`), its path joint (if
        /// it has one) as `joint` says, or met afresh; awake.
        fn put_back(
            commands: &mut bevy::prelude::Commands,
            (entity, joined, asleep): (bevy::prelude::Entity, bool, bool),
            state: impl bevy::prelude::Bundle,
            joint: Option<&PathJointState>,
        ) {
            let mut body = commands.entity(entity);
            body.try_insert(state);
            if joined {
                body.try_insert(joint.cloned().unwrap_or_default());
            }
            if asleep {
                commands.queue(WakeBody(entity));
            }
        }

        /// Puts each body that has a [`BodyStart`] back at its start on a
        /// restart, awake (a body asleep is woken).
        fn restart_bodies(
            mut restarts: bevy::prelude::MessageReader<$crate::Restart>,
            bodies: bevy::prelude::Query<(&BodyStart, PutBack)>,
            mut commands: bevy::prelude::Commands,
        ) {
            if restarts.read().count() == 0 {
                return;
            }
            for (start, body) in &bodies {
                let state = (start.position, start.rotation, start.linear, start.angular);
                put_back(&mut commands, body, state, None);
            }
        }

        /// What the timeline records of a body.
        type Recorded = (
            bevy::prelude::Entity,
            &'static $avian::prelude::RigidBody,
            &'static $avian::prelude::Position,
            &'static $avian::prelude::Rotation,
            &'static $avian::prelude::LinearVelocity,
            &'static $avian::prelude::AngularVelocity,
            &'static bevy::prelude::Transform,
        );

        /// What the timeline keeps of the path joints: each one's state,
        /// by its body, in the order of the bodies.
        type RecordedJoints = Vec<(bevy::prelude::Entity, PathJointState)>;

        /// Records every body that is not static in the timeline's frame
        /// of the step just taken (or checks it against the one recorded),
        /// with its path joint's state.
        fn record_bodies(
            mut timeline: bevy::prelude::ResMut<$crate::plugin::Timeline>,
            clock: bevy::prelude::Res<$crate::SimClock>,
            bodies: bevy::prelude::Query<Recorded>,
            joints: bevy::prelude::Query<(bevy::prelude::Entity, &PathJointState)>,
        ) {
            let recorded = bodies
                .iter()
                .filter(|(_, kind, ..)| !kind.is_static())
                .map(
                    |(entity, _, position, rotation, linear, angular, transform)| {
                        $record(entity, (position, rotation, linear, angular), *transform)
                    },
                )
                .collect();
            let mut states: RecordedJoints =
                joints.iter().map(|(e, state)| (e, state.clone())).collect();
            states.sort_unstable_by_key(|(e, _)| *e);
            let bytes = states.len() * size_of::<(bevy::prelude::Entity, PathJointState)>();
            let kept = (
                Box::new(states) as Box<dyn std::any::Any + Send + Sync>,
                bytes,
            );
            timeline.record_bodies(($dimension, clock.steps), recorded, kept);
        }

        /// Puts each body back where the timeline recorded it at the step
        /// a seek took the run to, its path joint as it was then.
        fn seek_bodies(
            mut seeks: bevy::prelude::MessageReader<$crate::plugin::TimelineSeek>,
            timeline: bevy::prelude::Res<$crate::plugin::Timeline>,
            clock: bevy::prelude::Res<$crate::SimClock>,
            bodies: bevy::prelude::Query<PutBack>,
            mut commands: bevy::prelude::Commands,
        ) {
            if seeks.read().count() == 0 {
                return;
            }
            let Some((recorded, joints)) = timeline.bodies($dimension, clock.steps) else {
                return;
            };
            let joints = joints.downcast_ref::<RecordedJoints>();
            for body in recorded {
                let Ok(put) = bodies.get(body.entity) else {
                    continue;
                };
                let joint = joints.and_then(|joints| {
                    let i = joints
                        .binary_search_by_key(&body.entity, |(e, _)| *e)
                        .ok()?;
                    Some(&joints[i].1)
                });
                put_back(&mut commands, put, $recorded(body), joint);
            }
        }

        /// Records the bodies with the [`Timeline`](crate::plugin::Timeline),
        /// where the app has one: where the run starts, after each of
        /// avian's steps, and puts them back on a seek.
        fn add_timeline_systems(app: &mut bevy::prelude::App) {
            use bevy::prelude::*;
            let has_timeline = resource_exists::<$crate::plugin::Timeline>;
            app.add_systems(
                FixedUpdate,
                record_bodies
                    .after($crate::plugin::TimelineSystems::Start)
                    .before($crate::WireBeadSystems::Prepare)
                    .run_if(has_timeline)
                    .run_if(
                        |timeline: Option<Res<$crate::plugin::Timeline>>,
                         clock: Res<$crate::SimClock>| {
                            timeline.is_some_and(|t| t.wants_bodies($dimension, clock.steps))
                        },
                    ),
            )
            .add_systems(
                FixedLast,
                record_bodies
                    .after($crate::plugin::TimelineSystems::Step)
                    .run_if(has_timeline),
            )
            .add_systems(
                RunFixedMainLoop,
                seek_bodies
                    .in_set(RunFixedMainLoopSystems::AfterFixedMainLoop)
                    .after($crate::plugin::TimelineSystems::Seek)
                    .run_if(has_timeline),
            );
        }
    };
}

pub(crate) use body_start;
