//! The simulation as a group of small plugins, each owning its resources,
//! observers and systems; [`WireBeadPlugin`] adds them all in one line.
//!
//! | plugin | file | what it adds |
//! |---|---|---|
//! | [`ParamsPlugin`] | `params` | [`SimParams`] and the pending edits, the sets' order, [`ParallelStep`], a bead's `Transform` and diagnostics |
//! | [`ClockPlugin`] | `clock` | [`SimClock`] and the fixed timestep |
//! | [`WirePosePlugin`] | `wires` | each wire placed for the step: its prescribed motion, or the game's moves |
//! | [`SpringAnchorPlugin`] | `forces` | the spring toward a bead's [`SpringAnchor`](crate::SpringAnchor) (the assignment's drag) |
//! | [`BeadStepPlugin`] | `step` | the step of each bead alone on a wire, batched and in parallel |
//! | [`IslandPlugin`] | `islands` | [`Islands`]: beads joined by rods, pins, joints and springs, stepped together |
//! | [`RestartPlugin`] | `restart` | [`Restart`]: the pending edits applied, every bead back to its start |
//! | [`WritebackPlugin`] | `writeback` | `Transform`s from the `f64` state; the [`SceneEnergy`] where the app asks for it (`energy`) |
//!
//! Shared pieces live in leaf files: `schedule` ([`WireBeadSystems`]),
//! `parallel` ([`ParallelStep`]), `report` (divergence and contact
//! reports). The systems themselves are private: a game orders its own
//! systems against the sets.

mod clock;
mod energy;
mod forces;
mod islands;
mod parallel;
mod params;
mod report;
mod restart;
mod schedule;
mod step;
mod timeline;
mod wires;
mod writeback;

use bevy::app::PluginGroupBuilder;
use bevy::prelude::*;

pub use clock::{ClockPlugin, SimClock};
pub use energy::SceneEnergy;
pub use forces::SpringAnchorPlugin;
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
pub(crate) use islands::{BodyImpulse, WorldBodies, WorldBody};
pub use islands::{IslandPlugin, IslandReport, Islands, PressedPair};
pub use parallel::{ParallelStep, StepSplit, compute_on_all_cores, use_single_threaded_executors};
pub use params::ParamsPlugin;
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
pub(crate) use report::Divergences;
pub use restart::{Restart, RestartPlugin};
pub use schedule::WireBeadSystems;
pub use step::BeadStepPlugin;
pub(crate) use timeline::TimelineSystems;
pub use timeline::{RecordedBead, RecordedBody, Timeline, TimelinePlugin, TimelineSeek};
pub use wires::WirePosePlugin;
pub use writeback::WritebackPlugin;

use crate::dynamics::SimParams;

/// Beads on wires: the simulation, headless. Add it to any app that has
/// `Time` (`MinimalPlugins` or `DefaultPlugins`). A group of the plugins in
/// the table above; like any Bevy plugin group it can be built and one of
/// them replaced or disabled:
///
/// ```
/// use bevy::prelude::*;
/// use wirebead::plugin::SpringAnchorPlugin;
/// use wirebead::prelude::*;
///
/// App::new().add_plugins((
///     MinimalPlugins,
///     WireBeadPlugin::default().build().disable::<SpringAnchorPlugin>(),
/// ));
/// ```
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
    pub fn new(params: SimParams) -> Result<Self, crate::validate::ParamError> {
        params.validate()?;
        Ok(Self {
            params,
            ..Self::default()
        })
    }

    /// Lean beads: a [`Bead`](crate::Bead) no longer brings a `Transform` (with its
    /// `GlobalTransform`) and [`BeadDiagnostics`](crate::BeadDiagnostics) along. For crowds of
    /// beads: a lean bead takes about half the memory and steps faster. A
    /// bead given either component explicitly still has it kept up to
    /// date, so a game can render or watch a few of many.
    pub fn lean(self) -> Self {
        Self {
            transforms_and_diagnostics: false,
            ..self
        }
    }
}

impl PluginGroup for WireBeadPlugin {
    fn build(self) -> PluginGroupBuilder {
        PluginGroupBuilder::start::<Self>()
            .add(ParamsPlugin {
                params: self.params,
                transforms_and_diagnostics: self.transforms_and_diagnostics,
            })
            .add(ClockPlugin)
            .add(WirePosePlugin)
            .add(SpringAnchorPlugin)
            .add(BeadStepPlugin)
            .add(IslandPlugin)
            .add(RestartPlugin)
            .add(WritebackPlugin)
    }
}
