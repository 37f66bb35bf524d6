//! Drag a bead with the mouse: on grab the bead gets a [`SpringAnchor`] at the
//! cursor, which follows the cursor until release. The simulation turns it
//! into the assignment's spring force `k (cursor - bead)`. Egui windows block
//! picking, so a drag over the panel never grabs a bead.
//!
//! A drag grabs the bead the picking ray hit or, failing that, the bead
//! whose drawn disc the press landed in (a forgiving grab for a small bead,
//! and robust when the window's hover state was reset by the press).
//!
//! The keyboard pulls too: while an arrow key is held, the selected bead
//! in the plane gets a [`SpringAnchor`] that starts where the bead is and
//! moves in the arrows' direction at a quarter of the view's height a second, a
//! cursor moved by the keys; letting go of the arrows lets go of the bead.

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use crate::gui::render::{SceneCamera, screen_to_world};
use crate::{BeadPosition, GrabPoint, SpringAnchor};

/// The bead the panel shows: the last one grabbed, or the first one.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SelectedBead(pub Option<Entity>);

/// The bead being dragged, if any.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Grabbed(pub Option<Entity>);

/// Drag beads with the mouse through Bevy's picking.
#[derive(Default)]
pub struct BeadDragPlugin;

impl Plugin for BeadDragPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SelectedBead>()
            .init_resource::<Grabbed>()
            .init_resource::<KeyPull>()
            .add_observer(start_drag)
            .add_observer(follow_drag)
            .add_observer(end_drag)
            .add_systems(Update, pull_with_arrows);
    }
}

/// The plane's camera.
pub(crate) type SceneCameras<'w, 's> =
    Query<'w, 's, (&'static Camera, &'static GlobalTransform), With<SceneCamera>>;

/// Where the pointer is in the plane, as a spring's anchor.
pub(crate) fn cursor_world(
    location: &bevy::picking::pointer::Location,
    cameras: &SceneCameras,
) -> Option<SpringAnchor> {
    let (camera, transform) = cameras.iter().next()?;
    let world = screen_to_world(camera, transform, location.position)?;
    SpringAnchor::new(world).ok()
}

/// Grabs a bead: selects it and sets its drag target at the cursor.
pub fn start_drag(
    event: On<Pointer<DragStart>>,
    beads: Query<(Entity, &BeadPosition, &Transform)>,
    windows: Query<(), With<Window>>,
    cameras: SceneCameras,
    mut grabbed: ResMut<Grabbed>,
    mut selected: ResMut<SelectedBead>,
    mut commands: Commands,
) {
    if event.event.button != PointerButton::Primary || grabbed.0.is_some() {
        return;
    }
    let Some(target) = cursor_world(&event.pointer_location, &cameras) else {
        return;
    };
    let bead = if beads.contains(event.entity) {
        Some(event.entity)
    } else if !windows.contains(event.entity) {
        // The press landed on something else that takes the pointer, such
        // as an egui window: never grab a bead through it.
        None
    } else {
        bead_under(&beads, target.get())
    };
    let Some(bead) = bead else { return };
    debug!("wirebead: grabbed bead {bead}");
    grabbed.0 = Some(bead);
    selected.0 = Some(bead);
    commands.entity(bead).insert(target);
}

/// The bead a press at `at` that missed every bead mesh takes: the
/// nearest whose drawn disc (scale = radius) is under it, with some slack.
pub(crate) fn bead_under(
    beads: &Query<(Entity, &BeadPosition, &Transform)>,
    at: DVec2,
) -> Option<Entity> {
    beads
        .iter()
        .map(|(e, b, t)| (e, (b.0 - at).length() / f64::from(t.scale.x.max(1e-6))))
        .filter(|(_, d)| *d <= 1.5)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(e, _)| e)
}

/// Moves the drag target with the cursor.
pub fn follow_drag(
    event: On<Pointer<Drag>>,
    cameras: SceneCameras,
    grabbed: Res<Grabbed>,
    mut targets: Query<&mut SpringAnchor>,
) {
    let Some(bead) = grabbed.0 else { return };
    if let (Ok(mut target), Some(next)) = (
        targets.get_mut(bead),
        cursor_world(&event.pointer_location, &cameras),
    ) {
        *target = next;
    }
}

/// Releases the bead, in the plane or in space: the spring force ends.
pub fn end_drag(
    _event: On<Pointer<DragEnd>>,
    mut grabbed: ResMut<Grabbed>,
    mut commands: Commands,
) {
    if let Some(bead) = grabbed.0.take()
        && let Ok(mut entity) = commands.get_entity(bead)
    {
        entity.remove::<(
            SpringAnchor,
            SpringAnchor<DVec3>,
            GrabPoint,
            GrabPoint<DVec3>,
        )>();
    }
}

/// The bead the arrow keys are pulling, if any.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct KeyPull(pub Option<Entity>);

/// How fast the arrow keys move the drag target, in view heights a
/// second.
pub const KEY_PULL_SPEED: f32 = 0.25;

/// The arrow keys and the directions they pull in.
const ARROWS: [(KeyCode, Vec2); 4] = [
    (KeyCode::ArrowRight, Vec2::X),
    (KeyCode::ArrowLeft, Vec2::NEG_X),
    (KeyCode::ArrowUp, Vec2::Y),
    (KeyCode::ArrowDown, Vec2::NEG_Y),
];

/// The direction the arrow keys held point in (zero for none, or for
/// opposite keys together).
pub fn arrow_direction(keys: &ButtonInput<KeyCode>) -> Vec2 {
    ARROWS
        .into_iter()
        .filter(|(key, _)| keys.pressed(*key))
        .map(|(_, direction)| direction)
        .sum::<Vec2>()
        .normalize_or_zero()
}

/// Pulls the selected bead in the plane with the arrow keys while no mouse
/// drag holds a bead: the target starts at the bead and moves with the
/// keys; it goes when no arrow is held.
#[allow(clippy::too_many_arguments)]
pub fn pull_with_arrows(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time<Real>>,
    view: Res<crate::gui::render::FramedView>,
    selected: Res<SelectedBead>,
    grabbed: Res<Grabbed>,
    mut pull: ResMut<KeyPull>,
    mut beads: Query<(&BeadPosition, Option<&mut SpringAnchor>)>,
    mut commands: Commands,
) {
    let direction = arrow_direction(&keys);
    let held = keys.any_pressed(ARROWS.map(|(key, _)| key));
    if !held || grabbed.0.is_some() {
        if let Some(bead) = pull.0.take()
            && grabbed.0 != Some(bead)
            && let Ok(mut entity) = commands.get_entity(bead)
        {
            entity.remove::<SpringAnchor>();
        }
        return;
    }
    let Some(bead) = selected.0 else { return };
    let Ok((position, anchor)) = beads.get_mut(bead) else {
        return;
    };
    let step = (direction * KEY_PULL_SPEED * view.size.y * time.delta_secs()).as_dvec2();
    match (pull.0 == Some(bead), anchor) {
        (true, Some(mut anchor)) => {
            if let Ok(next) = SpringAnchor::new(anchor.get() + step) {
                *anchor = next;
            }
        }
        _ => {
            if let Some(old) = pull.0.replace(bead)
                && old != bead
                && let Ok(mut entity) = commands.get_entity(old)
            {
                entity.remove::<SpringAnchor>();
            }
            if let Ok(start) = SpringAnchor::new(position.0 + step) {
                commands.entity(bead).insert(start);
            }
        }
    }
}
