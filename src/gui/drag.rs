//! Drag a bead with the mouse: on grab the bead gets a [`DragTarget`] at the
//! cursor, which follows the cursor until release. The simulation turns it
//! into the seed's spring force `k (cursor - bead)`. Egui windows block
//! picking, so a drag over the panel never grabs a bead.

use bevy::prelude::*;

use crate::components::{Bead, DragTarget};
use crate::gui::render::{SceneCamera, screen_to_world};

/// The bead the panel shows: the last one grabbed, or the first one.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SelectedBead(pub Option<Entity>);

/// Drag beads with the mouse through Bevy's picking.
#[derive(Default)]
pub struct BeadDragPlugin;

impl Plugin for BeadDragPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SelectedBead>()
            .add_observer(start_drag)
            .add_observer(follow_drag)
            .add_observer(end_drag);
    }
}

fn cursor_world(
    location: &bevy::picking::pointer::Location,
    cameras: &Query<(&Camera, &GlobalTransform), With<SceneCamera>>,
) -> Option<DragTarget> {
    let (camera, transform) = cameras.iter().next()?;
    let world = screen_to_world(camera, transform, location.position)?;
    DragTarget::new(world).ok()
}

/// Grabs a bead: selects it and sets its drag target at the cursor.
pub fn start_drag(
    event: On<Pointer<DragStart>>,
    beads: Query<(), With<Bead>>,
    cameras: Query<(&Camera, &GlobalTransform), With<SceneCamera>>,
    mut selected: ResMut<SelectedBead>,
    mut commands: Commands,
) {
    if event.event.button != PointerButton::Primary || !beads.contains(event.entity) {
        return;
    }
    selected.0 = Some(event.entity);
    if let Some(target) = cursor_world(&event.pointer_location, &cameras) {
        commands.entity(event.entity).insert(target);
    }
}

/// Moves the drag target with the cursor.
pub fn follow_drag(
    event: On<Pointer<Drag>>,
    cameras: Query<(&Camera, &GlobalTransform), With<SceneCamera>>,
    mut targets: Query<&mut DragTarget>,
) {
    if let (Ok(mut target), Some(next)) = (
        targets.get_mut(event.entity),
        cursor_world(&event.pointer_location, &cameras),
    ) {
        *target = next;
    }
}

/// Releases the bead: the spring force ends.
pub fn end_drag(event: On<Pointer<DragEnd>>, mut commands: Commands) {
    if let Ok(mut entity) = commands.get_entity(event.entity) {
        entity.remove::<DragTarget>();
    }
}
