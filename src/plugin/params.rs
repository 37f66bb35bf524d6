//! [`ParamsPlugin`]: what every other plugin of the group reads: the
//! applied and pending parameters, how beads that touch strike
//! ([`Contacts`]), the order of the step's sets, the
//! compute-pool setting, and what a bead brings along.

use bevy::math::DVec3;
use bevy::prelude::*;

use super::parallel::{ParallelStep, StepSplit};
use super::schedule;
use crate::dynamics::{
    Bead, BeadDiagnostics, BeadDiverged, BeadForce, BeadMass, BeadParams, BeadPosition, BeadRadius,
    BeadStruckBody, BeadVelocity, BeadsStruck, ContactChanged, Contacts, NextBeadParams,
    NextParams, Restitution, SimParams, SpaceBead,
};

/// The parameters ([`SimParams`], [`NextParams`]), the step's sets in
/// order, [`ParallelStep`], and each bead's `Transform` and
/// [`BeadDiagnostics`] (unless the beads are lean).
#[derive(Clone, Debug)]
pub struct ParamsPlugin {
    /// The initial parameters, unless the app has its own.
    pub params: SimParams,
    /// Whether a bead brings a `Transform` and [`BeadDiagnostics`].
    pub transforms_and_diagnostics: bool,
}

impl Default for ParamsPlugin {
    fn default() -> Self {
        Self {
            params: SimParams::default(),
            transforms_and_diagnostics: true,
        }
    }
}

impl ParamsPlugin {
    /// Inserts the initial parameters (or keeps the app's own, saying so)
    /// and a pending copy of them.
    fn insert_params(&self, app: &mut App) {
        match app.world().get_resource::<SimParams>() {
            None => {
                app.insert_resource(self.params.clone());
            }
            Some(existing) if *existing != self.params => {
                info!(
                    "wirebead: the app's own SimParams resource was kept; the plugin's parameters were not applied"
                );
            }
            Some(_) => {}
        }
        let applied = app.world().resource::<SimParams>().clone();
        let mut pending = NextParams::default();
        if let Err(err) = pending.set(applied) {
            error!("wirebead: the initial SimParams are invalid ({err}); using the defaults");
            app.insert_resource(SimParams::default());
        }
        app.insert_resource(pending);
    }
}

impl Plugin for ParamsPlugin {
    fn build(&self, app: &mut App) {
        if self.transforms_and_diagnostics {
            for registered in [
                app.try_register_required_components::<Bead, Transform>(),
                app.try_register_required_components::<Bead, BeadDiagnostics>(),
                app.try_register_required_components::<SpaceBead, Transform>(),
                app.try_register_required_components::<SpaceBead, BeadDiagnostics<DVec3>>(),
            ] {
                if let Err(err) = registered {
                    warn!("wirebead: could not give beads their Transform and diagnostics: {err}");
                }
            }
        }
        self.insert_params(app);
        schedule::configure(app);
        app.init_resource::<ParallelStep>()
            .init_resource::<StepSplit>()
            .register_type::<StepSplit>()
            .init_resource::<Contacts>()
            .register_type::<Contacts>()
            .register_type::<BeadRadius>()
            .register_type::<Restitution>()
            .add_message::<BeadsStruck>()
            .add_message::<BeadStruckBody>()
            .add_message::<BeadDiverged>()
            .add_message::<ContactChanged>()
            .add_message::<ContactChanged<DVec3>>()
            .register_type::<Bead>()
            .register_type::<BeadPosition>()
            .register_type::<BeadVelocity>()
            .register_type::<BeadMass>()
            .register_type::<BeadForce>()
            .register_type::<BeadParams>()
            .register_type::<BeadDiagnostics>()
            .register_type::<SpaceBead>()
            .register_type::<BeadPosition<DVec3>>()
            .register_type::<BeadVelocity<DVec3>>()
            .register_type::<BeadForce<DVec3>>()
            .register_type::<BeadParams<DVec3>>()
            .register_type::<BeadDiagnostics<DVec3>>()
            .register_type::<NextBeadParams>()
            .register_type::<NextBeadParams<DVec3>>()
            .register_type::<SimParams>()
            .register_type::<ParallelStep>()
            .register_type::<NextParams>();
    }
}
