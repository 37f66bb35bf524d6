//! [`WirePosePlugin`]: places every wire for the step, in
//! [`WireBeadSystems::Prepare`]. It reads each changed wire `Transform`
//! once, so the beads do not; writes the `Transform` of a wire on a
//! prescribed motion; and takes in the pose of a wire the game moves.

use bevy::ecs::entity::EntityHashSet;
use bevy::prelude::*;

use super::clock::{SimClock, advance_clock};
use super::schedule::WireBeadSystems;
use crate::dynamics::{PrescribedMotion, SimParams, Wire, WirePose, pose_of};
use crate::geometry::{Pose, PoseHistory, PosePath};

/// Places the wires for each step: a wire's pose when it is added, its
/// prescribed motion, or the motion a game gives it by writing its
/// `Transform`.
#[derive(Default)]
pub struct WirePosePlugin;

impl Plugin for WirePosePlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<MovingWires>()
            .add_observer(wire_added)
            .add_systems(
                FixedUpdate,
                place_wires
                    .run_if(wires_to_place)
                    .before(advance_clock)
                    .in_set(WireBeadSystems::Prepare),
            );
    }
}

/// The wires a game moved that have not come to rest: placed again each
/// step until they do.
#[derive(Resource, Default)]
pub(crate) struct MovingWires(EntityHashSet);

/// Whether any wire needs placing: one on a prescribed motion, one whose
/// `Transform` changed, or one still moving. Where none does (every wire
/// at rest) the step skips [`place_wires`] altogether.
fn wires_to_place(
    driven: Query<(), With<PrescribedMotion>>,
    moved: Query<(), (With<Wire>, Without<PrescribedMotion>, Changed<Transform>)>,
    moving: Res<MovingWires>,
) -> bool {
    !driven.is_empty() || !moving.0.is_empty() || !moved.is_empty()
}

/// Places every wire for the coming step, from [`SimClock::time`] to one
/// timestep later (the clock advances after this).
pub(crate) fn place_wires(
    params: Res<SimParams>,
    clock: Res<SimClock>,
    mut driven: Query<(&PrescribedMotion, &mut Transform, &mut WirePose)>,
    mut followed: Query<(Ref<Transform>, &mut WirePose), (With<Wire>, Without<PrescribedMotion>)>,
    moved: Query<Entity, (With<Wire>, Without<PrescribedMotion>, Changed<Transform>)>,
    mut moving: ResMut<MovingWires>,
) {
    let (start, h) = (clock.time, params.timestep);
    let end = start + h;
    for (motion, mut transform, mut pose) in &mut driven {
        let placed = prescribed(motion, &pose, &transform);
        pose.set_if_neq(placed);
        if let Ok(path) = placed.get() {
            set_pose(&mut transform, path.pose(end));
        }
    }
    // Only the wires whose `Transform` changed, and the ones that were
    // still moving: the rest stay where they are, unvisited.
    let mut still_moving = EntityHashSet::default();
    let before = moving.0.iter().copied().filter(|&e| !moved.contains(e));
    for entity in moved.iter().chain(before) {
        let Ok((transform, mut pose)) = followed.get_mut(entity) else {
            continue;
        };
        let Ok(now) = pose_of(&transform) else {
            pose.set_if_neq(WirePose::from_transform(&transform));
            continue;
        };
        let mut history = match pose.get() {
            Ok(PosePath::Fixed(at)) if at == now => continue,
            Ok(PosePath::Fixed(at)) => PoseHistory::at_rest(f64::NEG_INFINITY, at),
            Ok(PosePath::Followed(history)) => history,
            Ok(path @ PosePath::Prescribed { .. }) => PoseHistory::at_rest(start, path.pose(start)),
            Err(_) => PoseHistory::at_rest(start, now),
        };
        history.push(end, h, now);
        let path = if history.is_at_rest() {
            PosePath::Fixed(now)
        } else {
            still_moving.insert(entity);
            PosePath::Followed(history)
        };
        pose.set_if_neq(WirePose::on(path));
    }
    moving.0 = still_moving;
}

/// Places a wire where its `Transform` puts it the moment it is added, so
/// that a game moving it from its first step on moves it from there.
fn wire_added(add: On<Add, Wire>, mut wires: Query<(&Transform, &mut WirePose)>) {
    if let Ok((transform, mut pose)) = wires.get_mut(add.entity) {
        *pose = WirePose::from_transform(transform);
    }
}

/// A wire on `motion` about its resting pose: the one `pose` already
/// holds, else its `Transform`'s (when the motion first applies).
pub(crate) fn prescribed(
    motion: &PrescribedMotion,
    pose: &WirePose,
    transform: &Transform,
) -> WirePose {
    let base = match pose.get() {
        Ok(PosePath::Prescribed { base, .. }) => Ok(base),
        _ => pose_of(transform),
    };
    match base {
        Ok(base) => WirePose::on(PosePath::Prescribed {
            base,
            motion: motion.motion(),
        }),
        Err(_) => WirePose::from_transform(transform),
    }
}

/// Writes an in-plane pose into a `Transform` (x, y and the rotation about
/// z; z kept), converted to `f32` at this edge.
pub(crate) fn set_pose(transform: &mut Transform, pose: Pose) {
    let origin = pose.origin.as_vec2();
    if origin.is_finite() && pose.rotation.is_finite() {
        transform.translation.x = origin.x;
        transform.translation.y = origin.y;
        transform.rotation = Quat::from_rotation_z(pose.rotation.to_angle() as f32);
    }
}
