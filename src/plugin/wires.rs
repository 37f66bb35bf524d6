//! [`WirePosePlugin`]: places every wire for the step, in
//! [`WireBeadSystems::Prepare`]. It reads each changed wire `Transform`
//! once, so the beads do not; writes the `Transform` of a wire on a
//! prescribed motion or at a [`WirePlace`]; and takes in the pose of a
//! wire the game moves.
//! Each system runs for the plane's wires and for space's.

use std::marker::PhantomData;

use bevy::ecs::entity::EntityHashSet;
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use super::clock::{SimClock, advance_clock};
use super::schedule::WireBeadSystems;
use crate::dynamics::{
    Dimension, PrescribedMotion, SimParams, WirePlace, WirePose, placement, put_in_place, wire_pose,
};
use crate::geometry::WirePath;

/// Places the wires for each step: a wire's pose when it is added, its
/// prescribed motion, or the motion a game gives it by writing its
/// `Transform`.
#[derive(Default)]
pub struct WirePosePlugin;

impl Plugin for WirePosePlugin {
    fn build(&self, app: &mut App) {
        add_wire_poses::<DVec2>(app);
        add_wire_poses::<DVec3>(app);
    }
}

/// The systems that place the wires of one dimension.
fn add_wire_poses<V: Dimension>(app: &mut App) {
    app.init_resource::<MovingWires<V>>()
        .add_observer(wire_added::<V>)
        .add_observer(place_inserted::<V>)
        .add_observer(motion_added::<V>)
        .add_systems(
            FixedUpdate,
            (
                follow_places::<V>,
                place_wires::<V>.run_if(wires_to_place::<V>),
            )
                .chain()
                .before(advance_clock)
                .in_set(WireBeadSystems::Prepare),
        );
}

/// The wires a game moved that have not come to rest: placed again each
/// step until they do.
#[derive(Resource)]
pub(crate) struct MovingWires<V>(EntityHashSet, PhantomData<V>);

impl<V> Clone for MovingWires<V> {
    fn clone(&self) -> Self {
        Self(self.0.clone(), PhantomData)
    }
}

impl<V> Default for MovingWires<V> {
    fn default() -> Self {
        Self(EntityHashSet::default(), PhantomData)
    }
}

/// Whether any wire needs placing: one on a prescribed motion, one whose
/// `Transform` changed, or one still moving. Where none does (every wire
/// at rest) the step skips [`place_wires`] altogether.
fn wires_to_place<V: Dimension>(
    driven: Query<(), With<PrescribedMotion<V>>>,
    moved: Query<
        (),
        (
            With<V::Wire>,
            Without<PrescribedMotion<V>>,
            Changed<Transform>,
        ),
    >,
    moving: Res<MovingWires<V>>,
) -> bool {
    !driven.is_empty() || !moving.0.is_empty() || !moved.is_empty()
}

/// Places every wire for the coming step, from [`SimClock::time`] to one
/// timestep later (the clock advances after this).
///
/// A wire on a [`PrescribedMotion`] is on its motion about its resting
/// pose, and its `Transform` is written where the step ends. A wire whose
/// `Transform` the game wrote is followed (see [`Dimension::followed`]);
/// the rest stay where they are, unvisited.
pub(crate) fn place_wires<V: Dimension>(
    params: Res<SimParams>,
    clock: Res<SimClock>,
    mut driven: Query<(
        &PrescribedMotion<V>,
        &mut Transform,
        &mut WirePose<V>,
        Option<&WirePlace<V>>,
    )>,
    mut followed: Query<
        (Ref<Transform>, &mut WirePose<V>, Option<&mut WirePlace<V>>),
        (With<V::Wire>, Without<PrescribedMotion<V>>),
    >,
    moved: Query<
        Entity,
        (
            With<V::Wire>,
            Without<PrescribedMotion<V>>,
            Changed<Transform>,
        ),
    >,
    mut moving: ResMut<MovingWires<V>>,
) {
    let (start, h) = (clock.time, params.timestep);
    for (motion, mut transform, mut pose, place) in &mut driven {
        let placed = prescribed(motion, &pose, &transform, place);
        pose.set_if_neq(placed);
        if let Some(path) = placed.path() {
            V::set_pose(&mut transform, path.at(start + h).0);
        }
    }
    let mut still_moving = EntityHashSet::default();
    let before = moving.0.iter().copied().filter(|&e| !moved.contains(e));
    for entity in moved.iter().chain(before) {
        let Ok((transform, mut pose, place)) = followed.get_mut(entity) else {
            continue;
        };
        let Ok(now) = wire_pose(&transform, place.as_deref()) else {
            pose.set_if_neq(WirePose::from_transform(&transform));
            continue;
        };
        // A `Transform` the game moved off the wire's place: the place
        // follows it, without looking changed (which would move the
        // `Transform` back to it).
        if let Some(mut place) = place
            && place.0 != now
        {
            place.bypass_change_detection().0 = now;
        }
        let (path, moves) = WirePath::followed(pose.path(), now, start, h);
        if moves {
            still_moving.insert(entity);
        }
        pose.set_if_neq(WirePose::on(path));
    }
    moving.0 = still_moving;
}

/// Places a wire the moment it is added, at its [`WirePlace`] if it has
/// one, else where its `Transform` puts it, so that a game moving it from
/// its first step on moves it from there.
fn wire_added<V: Dimension>(add: On<Add, V::Wire>, mut wires: Query<PlacedWire<V>>) {
    if let Ok((place, motion, mut transform, mut pose)) = wires.get_mut(add.entity) {
        match place.and_then(WirePlace::taken) {
            Some(at) => put_in_place(at, motion, &mut transform, &mut pose),
            None => *pose = WirePose::from_transform(&transform),
        }
    }
}

/// A wire's place, motion, `Transform` and pose, as [`put_in_place`]
/// takes them.
type PlacedWire<V> = (
    Option<&'static WirePlace<V>>,
    Option<&'static PrescribedMotion<V>>,
    &'static mut Transform,
    &'static mut WirePose<V>,
);

/// Puts a wire at the [`WirePlace`] inserted on it.
fn place_inserted<V: Dimension>(insert: On<Insert, WirePlace<V>>, mut wires: Query<PlacedWire<V>>) {
    if let Ok((place, motion, mut transform, mut pose)) = wires.get_mut(insert.entity)
        && let Some(at) = place.and_then(WirePlace::taken)
    {
        put_in_place(at, motion, &mut transform, &mut pose);
    }
}

/// Moves the `Transform` of each wire whose [`WirePlace`] the game wrote
/// there, so that [`place_wires`] follows it (from the place itself, in
/// `f64`); a wire on a prescribed motion moves about its new place. A
/// place that places no wire ([`placement`]), at spawn or written later,
/// is warned of here, once each time it is written (the observers that
/// place a wire the moment it or its place is added pass over such a
/// place without a word).
fn follow_places<V: Dimension>(
    mut wires: Query<
        (
            Entity,
            &WirePlace<V>,
            Option<&PrescribedMotion<V>>,
            &mut Transform,
            &mut WirePose<V>,
        ),
        (With<V::Wire>, Changed<WirePlace<V>>),
    >,
) {
    for (entity, place, motion, mut transform, mut pose) in &mut wires {
        let at = match placement::<V>(place.0) {
            Ok(at) => at,
            Err(why) => {
                warn!(
                    "wirebead: wire {entity} was not put at its WirePlace: {why}; its Transform places it"
                );
                continue;
            }
        };
        match motion {
            Some(_) => put_in_place(at, motion, &mut transform, &mut pose),
            // Marked changed even where the place moved by less than the
            // `f32` step of its coordinates, so that it is followed.
            None => V::set_pose(&mut transform, at),
        }
    }
}

/// Puts a wire on its prescribed motion the moment the motion is
/// inserted, so that an island built before the first step (at spawn)
/// starts its beads on the moving wire.
fn motion_added<V: Dimension>(
    insert: On<Insert, PrescribedMotion<V>>,
    mut wires: Query<(
        &PrescribedMotion<V>,
        &Transform,
        &mut WirePose<V>,
        Option<&WirePlace<V>>,
    )>,
) {
    if let Ok((motion, transform, mut pose, place)) = wires.get_mut(insert.entity) {
        let placed = prescribed(motion, &pose, transform, place);
        pose.set_if_neq(placed);
    }
}

/// A wire on `motion` about its resting pose: the one `pose` already
/// holds, else (when the motion first applies) its place or its
/// `Transform`'s (see [`wire_pose`]).
pub(crate) fn prescribed<V: Dimension>(
    motion: &PrescribedMotion<V>,
    pose: &WirePose<V>,
    transform: &Transform,
    place: Option<&WirePlace<V>>,
) -> WirePose<V> {
    let base = match pose.path().and_then(|path| path.base()) {
        Some(base) => Ok(base),
        None => wire_pose(transform, place),
    };
    match base {
        Ok(base) => WirePose::on(WirePath::Prescribed {
            base,
            motion: motion.motion(),
        }),
        Err(_) => WirePose::from_transform(transform),
    }
}
