//! [`WireBeadSystems`]: the sets the plugin's systems run in, so a game can
//! order its own systems against them.

use bevy::prelude::*;

/// The plugin's system sets. `Prepare → Forces → Step → Writeback` run
/// chained in [`FixedUpdate`]; `Restart` runs in [`PreUpdate`].
///
/// A game adds its own forces with
/// `app.add_systems(FixedUpdate, my_force.in_set(WireBeadSystems::Forces))`,
/// adding to each bead through the [`BeadForces`](crate::BeadForces)
/// query: [`add_force`](crate::BeadForcesItem::add_force) or
/// [`add_spring`](crate::BeadForcesItem::add_spring).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WireBeadSystems {
    /// [`PreUpdate`]: handles [`Restart`](crate::Restart), applying the
    /// pending edits. Keyboard controls and scene presets that send it run
    /// before this set, so the frame that asks for a restart already steps
    /// with the new parameters.
    Restart,
    /// [`FixedUpdate`]: places each wire for the step (reads its `Transform`
    /// once) and advances the [`SimClock`](crate::SimClock).
    ///
    /// A wire with a [`PrescribedMotion`](crate::PrescribedMotion) gets its
    /// `Transform` written here, at the pose for the step's end.
    ///
    /// A game that moves a wire itself writes its `Transform` before this
    /// set, at the pose the wire has at the end of the coming step
    /// (`SimClock::time + timestep`). The plugin keeps the poses of the last
    /// three steps and takes the quadratic through them as the wire's
    /// motion within the step: the pose is then right to third order in the
    /// timestep, the wire's velocity to second and its acceleration to
    /// first. A bead's trajectory follows the prescribed motion's to second
    /// order (measured in the tests). A wire moved once, then left, is
    /// taken to have moved at constant speed during that one step.
    Prepare,
    /// [`FixedUpdate`]: accumulates the external forces other than gravity:
    /// the drag spring, the game's own.
    Forces,
    /// [`FixedUpdate`]: solves eq. (3) for each bead's constraint force
    /// under gravity plus the accumulated forces, integrates, applies
    /// post-stabilization, checks for divergence, updates the diagnostics
    /// and the `Transform`. One pass over the beads: the solve and the
    /// integrators are separate pure functions in
    /// [`solver`](crate::solver), but a second pass would read every bead
    /// from memory again.
    Step,
    /// [`FixedUpdate`]: writes each bead's `f64` position into its
    /// `Transform` where the bead changed other than by the step (the step
    /// writes the `Transform` of each bead it steps, in the same pass).
    Writeback,
}

/// Orders the sets: the fixed-step ones chained, `Restart` in `PreUpdate`.
pub(super) fn configure(app: &mut App) {
    app.configure_sets(
        FixedUpdate,
        (
            WireBeadSystems::Prepare,
            WireBeadSystems::Forces,
            WireBeadSystems::Step,
            WireBeadSystems::Writeback,
        )
            .chain(),
    )
    .configure_sets(PreUpdate, WireBeadSystems::Restart);
}
