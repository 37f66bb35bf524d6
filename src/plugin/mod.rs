//! [`WireBeadPlugin`]: registers the components, resources and messages and
//! schedules the step. One file per concern:
//!
//! | file | what it holds |
//! |---|---|
//! | `schedule` | [`WireBeadSystems`], the sets every system runs in |
//! | `restart` | [`Restart`], [`SimClock`] and the systems that apply edits |
//! | `forces` | the drag spring |
//! | `step` | placing the wires and stepping the beads |
//! | `islands` | [`Islands`]: beads joined by rods, pins, joints and springs, stepped together |
//! | `writeback` | `Transform`s from the `f64` state |
//! | `parallel` | [`ParallelStep`] and task-pool helpers |
//!
//! The systems themselves are private: a game orders its own systems
//! against the sets.

mod forces;
mod islands;
mod parallel;
mod restart;
mod schedule;
mod step;
mod writeback;

use bevy::prelude::*;

pub use islands::{IslandReport, Islands};
pub use parallel::{ParallelStep, compute_on_all_cores, use_single_threaded_executors};
pub use restart::{Restart, SimClock};
pub use schedule::WireBeadSystems;

use forces::apply_drag;
use islands::{any_island, islands_changed, prepare_islands, step_islands, topology_changed};
use restart::{apply_restart, apply_timestep};
use step::{prepare_step, step_beads, wire_added};
use writeback::write_transforms;

use crate::dynamics::{
    Bead, BeadDiagnostics, BeadDiverged, ConstraintDiagnostics, ContactChanged, DragTarget, Joint,
    OnWire, PendingBead, PendingParams, Pin, Rod, SimParams, Spring, Wire,
};
use bevy::ecs::lifecycle::{Add, Insert, Remove};
use writeback::LastStep;

/// Beads on wires: the simulation, headless. Add it to any app that has
/// `Time` (`MinimalPlugins` or `DefaultPlugins`).
///
/// The initial [`SimParams`] are the plugin's ([`WireBeadPlugin::new`]),
/// unless the app already has a `SimParams` resource: then that one is
/// kept, and the plugin says so in the log.
#[derive(Clone, Debug)]
pub struct WireBeadPlugin {
    params: SimParams,
    transforms_and_diagnostics: bool,
}

impl Default for WireBeadPlugin {
    fn default() -> Self {
        Self {
            params: SimParams::default(),
            transforms_and_diagnostics: true,
        }
    }
}

impl WireBeadPlugin {
    /// The plugin with the given initial parameters, if they are valid.
    pub fn new(params: SimParams) -> Result<Self, crate::ParamError> {
        params.validate()?;
        Ok(Self {
            params,
            ..Self::default()
        })
    }

    /// Lean beads: a [`Bead`] no longer brings a `Transform` (with its
    /// `GlobalTransform`) and [`BeadDiagnostics`] along. For crowds of
    /// beads: a lean bead takes about half the memory and steps faster. A
    /// bead given either component explicitly still has it kept up to
    /// date, so a game can render or watch a few of many.
    pub fn lean(self) -> Self {
        Self {
            transforms_and_diagnostics: false,
            ..self
        }
    }

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
        let mut pending = PendingParams::default();
        if let Err(err) = pending.set(applied) {
            error!("wirebead: the initial SimParams are invalid ({err}); using the defaults");
            app.insert_resource(SimParams::default());
        }
        app.insert_resource(pending);
    }
}

impl Plugin for WireBeadPlugin {
    fn build(&self, app: &mut App) {
        if self.transforms_and_diagnostics {
            for registered in [
                app.try_register_required_components::<Bead, Transform>(),
                app.try_register_required_components::<Bead, BeadDiagnostics>(),
            ] {
                if let Err(err) = registered {
                    warn!("wirebead: could not give beads their Transform and diagnostics: {err}");
                }
            }
        }
        self.insert_params(app);
        schedule::configure(app);
        app.init_resource::<ParallelStep>()
            .init_resource::<SimClock>()
            .init_resource::<LastStep>()
            .init_resource::<Islands>()
            .add_observer(wire_added)
            .add_observer(topology_changed::<Add, Bead>)
            .add_observer(topology_changed::<Remove, Bead>)
            .add_observer(topology_changed::<Insert, OnWire>)
            .add_observer(topology_changed::<Remove, OnWire>)
            .add_observer(topology_changed::<Insert, Wire>)
            .add_observer(topology_changed::<Remove, Wire>)
            .add_observer(topology_changed::<Insert, Rod>)
            .add_observer(topology_changed::<Remove, Rod>)
            .add_observer(topology_changed::<Insert, Pin>)
            .add_observer(topology_changed::<Remove, Pin>)
            .add_observer(topology_changed::<Insert, Spring>)
            .add_observer(topology_changed::<Remove, Spring>)
            .add_observer(topology_changed::<Insert, Joint>)
            .add_observer(topology_changed::<Remove, Joint>)
            .add_message::<Restart>()
            .add_message::<BeadDiverged>()
            .add_message::<ContactChanged>()
            .register_type::<Bead>()
            .register_type::<BeadDiagnostics>()
            .register_type::<DragTarget>()
            .register_type::<Rod>()
            .register_type::<Pin>()
            .register_type::<Spring>()
            .register_type::<ConstraintDiagnostics>()
            .register_type::<PendingBead>()
            .register_type::<SimParams>()
            .register_type::<ParallelStep>()
            .register_type::<SimClock>()
            .register_type::<PendingParams>()
            .add_systems(Startup, apply_timestep)
            .add_systems(PreUpdate, apply_restart.in_set(WireBeadSystems::Restart))
            .add_systems(
                FixedUpdate,
                (
                    (prepare_step, prepare_islands.run_if(islands_changed))
                        .chain()
                        .in_set(WireBeadSystems::Prepare),
                    apply_drag.in_set(WireBeadSystems::Forces),
                    (step_beads, step_islands.run_if(any_island)).in_set(WireBeadSystems::Step),
                    write_transforms.in_set(WireBeadSystems::Writeback),
                ),
            );
    }
}
