//! [`RestartPlugin`]: [`Restart`] applies the pending edits and returns
//! every bead to its initial state, as the assignment's space bar did.

use bevy::ecs::change_detection::Tick;
use bevy::ecs::system::SystemChangeTick;
use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use super::clock::SimClock;
use super::islands::Islands;
use super::schedule::WireBeadSystems;
use super::wires::prescribed;
use crate::dynamics::{
    BeadDiagnostics, BeadMotion, BeadMotionItem, BeadParams, Boarded, Dimension, Diverged,
    NextBeadParams, NextParams, NextWireShape, OnWire, PrescribedMotion, RailOrientation,
    SimParams, Wire, WireContact, WirePlace, WirePose, put_in_place,
};
use crate::geometry::{MovingTrack, Track};
use crate::solver::{RowReport, constraint_state_on};

/// Restarts the run: applies [`NextParams`] and every [`NextBeadParams`],
/// returns each bead to its initial state, clears divergence, and sets
/// `Time<Fixed>` to the timestep. Handled in
/// [`WireBeadSystems::Restart`](crate::WireBeadSystems::Restart), in
/// [`PreUpdate`], so the frame that sends it already steps with the new
/// parameters.
#[derive(Message, Clone, Copy, Debug, Default)]
pub struct Restart;

/// Handles [`Restart`] in [`WireBeadSystems::Restart`].
#[derive(Default)]
pub struct RestartPlugin;

impl Plugin for RestartPlugin {
    fn build(&self, app: &mut App) {
        app.add_message::<Restart>().add_systems(
            PreUpdate,
            (apply_restart, restart_in_space)
                .chain()
                .in_set(WireBeadSystems::Restart),
        );
    }
}

/// The diagnostics of a bead's current state on `track`, before any step.
fn diagnose<T: Track>(track: &T, bead: &BeadMotionItem<DVec2>, gravity: DVec2) -> BeadDiagnostics {
    let (c, c_dot) = constraint_state_on(track, 0.0, bead.state());
    let row = RowReport {
        c,
        c_dot,
        lambda: 0.0,
    };
    BeadDiagnostics::of(bead.state(), bead.mass(), gravity, row, default())
}

/// Handles [`Restart`]: applies the pending wire shapes and parameters and
/// returns every bead to its initial state.
fn apply_restart(
    mut restarts: MessageReader<Restart>,
    pending: Res<NextParams>,
    mut params: ResMut<SimParams>,
    mut time: ResMut<Time<Fixed>>,
    mut clock: ResMut<SimClock>,
    mut wires: Query<(
        Entity,
        &mut Wire,
        &mut Transform,
        &mut WirePose,
        Option<&NextWireShape>,
        Option<&PrescribedMotion>,
        Option<Ref<WirePlace>>,
    )>,
    mut beads: Query<(
        Entity,
        BeadMotion,
        &mut BeadParams,
        Option<&mut BeadDiagnostics>,
        Option<&mut WireContact>,
        Option<&OnWire>,
        Option<&NextBeadParams>,
    )>,
    mut islands: ResMut<Islands>,
    mut commands: Commands,
    ticks: SystemChangeTick,
) {
    if restarts.read().count() == 0 {
        return;
    }
    // Masses and wire shapes may change: the islands are built afresh.
    islands.mark_dirty();
    for (entity, mut wire, mut transform, mut pose, edit, motion, place) in &mut wires {
        if let Some(edit) = edit {
            *wire = wire.reshaped(edit.shape());
            commands.entity(entity).remove::<NextWireShape>();
        }
        rest_wire(
            (motion, place),
            (&mut transform, &mut pose),
            ticks.this_run(),
        );
    }
    *params = pending.get().clone();
    time.set_timestep_seconds(params.timestep);
    let overstep = time.overstep();
    time.discard_overstep(overstep);
    *clock = SimClock::default();
    for (entity, mut bead, mut bead_params, diagnostics, contact, on_wire, edit) in &mut beads {
        if !reset_bead(
            entity,
            &mut bead,
            &mut bead_params,
            edit,
            contact,
            &mut commands,
        ) {
            continue;
        }
        let wire = on_wire.and_then(|on| wires.get(on.0).ok());
        let Some((_, wire, _, pose, ..)) = wire else {
            if let Some(mut diagnostics) = diagnostics {
                *diagnostics = BeadDiagnostics::default();
            }
            continue;
        };
        let Ok(path) = pose.get() else { continue };
        // The initial velocity is relative to the wire's own at t = 0.
        bead.velocity.0 = bead_params.initial_velocity_on(&path.at(0.0).1);
        if let Some(mut diagnostics) = diagnostics {
            let track = MovingTrack {
                curve: wire.shape().curve(),
                path: &path,
            };
            *diagnostics = diagnose(&track, &bead, params.gravity);
        }
    }
}

/// A wire back where a run starts: one on a prescribed motion at its
/// resting pose, one the game moved at rest where it is. A place the game
/// wrote after the wire's `Transform` (`now` the restart's tick), which no
/// step has followed yet, is where it rests.
fn rest_wire<V: Dimension>(
    (motion, place): (Option<&PrescribedMotion<V>>, Option<Ref<WirePlace<V>>>),
    (transform, pose): (&mut Mut<Transform>, &mut Mut<WirePose<V>>),
    now: Tick,
) {
    let written = place.as_ref().filter(|place| {
        place
            .last_changed()
            .is_newer_than(transform.last_changed(), now)
    });
    if let Some(at) = written.and_then(|place| place.taken()) {
        put_in_place(at, motion, transform, pose);
    }
    let place = place.as_deref();
    match motion {
        Some(motion) => {
            **pose = prescribed(motion, pose, transform, place);
            if let Ok(path) = pose.get() {
                V::set_pose(transform, path.at(0.0).0);
            }
        }
        None => **pose = WirePose::placed(transform, place),
    }
}

/// A bead back at its [`BeadParams`], its pending [`NextBeadParams`]
/// applied first, its contact and divergence cleared; false, with a
/// one-line warning, if its parameters are invalid (written directly, not
/// through [`NextBeadParams`]): it keeps its state.
fn reset_bead<V: Dimension>(
    entity: Entity,
    bead: &mut BeadMotionItem<V>,
    params: &mut Mut<BeadParams<V>>,
    edit: Option<&NextBeadParams<V>>,
    contact: Option<Mut<WireContact>>,
    commands: &mut Commands,
) -> bool {
    if let Some(edit) = edit {
        params.set_if_neq(*edit.get());
        commands.entity(entity).remove::<NextBeadParams<V>>();
    }
    if let Err(err) = params.validate() {
        warn!(
            "wirebead: bead {entity} was not restarted: its BeadParams are invalid ({err}); it keeps its state"
        );
        return false;
    }
    bead.reset(params);
    if let Some(mut contact) = contact {
        contact.set_if_neq(WireContact::default());
    }
    commands.entity(entity).remove::<(Diverged, Boarded)>();
    true
}

/// Handles [`Restart`] for beads and wires in space, after
/// [`apply_restart`] applied the parameters: each wire at its resting
/// pose, each bead at its [`BeadParams<DVec3>`](BeadParams), its pending
/// [`NextBeadParams<DVec3>`](NextBeadParams) applied first (its initial
/// velocity relative to its wire's own at t = 0), its diagnostics those of
/// its new state until the first step fills in its rows.
fn restart_in_space(
    mut restarts: MessageReader<Restart>,
    params: Res<SimParams>,
    mut wires: Query<(
        &mut Transform,
        &mut WirePose<DVec3>,
        Option<&PrescribedMotion<DVec3>>,
        Option<Ref<WirePlace<DVec3>>>,
    )>,
    mut beads: Query<(
        Entity,
        BeadMotion<DVec3>,
        &mut BeadParams<DVec3>,
        Option<&NextBeadParams<DVec3>>,
        Option<&mut BeadDiagnostics<DVec3>>,
        Option<&mut WireContact>,
        Option<&OnWire>,
        Option<&mut RailOrientation>,
    )>,
    mut islands: ResMut<Islands<DVec3>>,
    mut commands: Commands,
    ticks: SystemChangeTick,
) {
    if restarts.read().count() == 0 {
        return;
    }
    islands.mark_dirty();
    for (mut transform, mut pose, motion, place) in &mut wires {
        rest_wire(
            (motion, place),
            (&mut transform, &mut pose),
            ticks.this_run(),
        );
    }
    let gravity = DVec3::gravity(&params);
    for (entity, mut bead, mut bead_params, edit, diagnostics, contact, on_wire, rail) in &mut beads
    {
        if !reset_bead(
            entity,
            &mut bead,
            &mut bead_params,
            edit,
            contact,
            &mut commands,
        ) {
            continue;
        }
        if let Some(mut rail) = rail {
            rail.restart();
        }
        let path = on_wire.and_then(|on| wires.get(on.0).ok()?.1.get().ok());
        if let Some(path) = path {
            let twist = path.at(0.0).1;
            bead.velocity.0 = bead_params.initial_velocity_on(&twist);
        }
        if let Some(mut diagnostics) = diagnostics {
            let state = bead.state();
            *diagnostics = BeadDiagnostics::of(
                state,
                bead.mass(),
                gravity,
                RowReport::default(),
                DVec3::ZERO,
            );
        }
    }
}
