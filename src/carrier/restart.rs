//! A rigid body put back where it started when the run restarts, as the
//! beads are: what both avian crates share, written once as a macro over
//! their same-named components.

/// Defines, in an avian adapter's module, `BodyStart` and the system
/// `restart_bodies` that puts each body that has one back at its start on
/// a [`Restart`](crate::Restart).
macro_rules! body_start {
    ($avian:ident) => {
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

        /// Puts each body that has a [`BodyStart`] back at its start on a
        /// restart, awake (a body asleep is woken).
        fn restart_bodies(
            mut restarts: bevy::prelude::MessageReader<$crate::Restart>,
            bodies: bevy::prelude::Query<(
                bevy::prelude::Entity,
                &BodyStart,
                bevy::prelude::Has<PathJoint>,
                bevy::prelude::Has<$avian::prelude::Sleeping>,
            )>,
            mut commands: bevy::prelude::Commands,
        ) {
            if restarts.read().count() == 0 {
                return;
            }
            for (entity, start, joined, asleep) in &bodies {
                let mut body = commands.entity(entity);
                body.try_insert((start.position, start.rotation, start.linear, start.angular));
                if joined {
                    body.try_insert(PathJointState::default());
                }
                if asleep {
                    commands.queue(WakeBody(entity));
                }
            }
        }
    };
}

pub(crate) use body_start;
