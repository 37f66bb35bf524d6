//! [`WireBeadPlugin`]: registers the components, resources and messages and
//! schedules the step in [`FixedUpdate`].

use bevy::prelude::*;

use crate::components::{Bead, BeadDiagnostics, DivergenceReason, DragTarget};
use crate::params::{ParamError, PendingBead, PendingParams, SimParams};
use crate::systems;

/// The simulation step, in order. All run in [`FixedUpdate`], chained.
///
/// A game adds its own forces with
/// `app.add_systems(FixedUpdate, my_force.in_set(WireBeadSystems::Forces))`,
/// calling [`Bead::add_force`] or [`Bead::add_spring`].
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WireBeadSystems {
    /// Places each wire for the step (reads its `Transform` once) and
    /// advances the [`SimClock`].
    Prepare,
    /// Accumulates the external forces other than gravity: the drag spring,
    /// the game's own.
    Forces,
    /// Solves eq. 1.9 for each bead's constraint force under gravity plus
    /// the accumulated forces, integrates, applies post-stabilization,
    /// checks for divergence, updates the diagnostics and the `Transform`.
    /// One pass over the beads: the solve and the integrators are separate
    /// pure functions in [`solver`](crate::solver), but a second pass would
    /// read every bead from memory again (RK4 and RATTLE solve at each of
    /// their stages anyway).
    Step,
    /// Writes each bead's `f64` position into its `Transform` where the
    /// bead changed other than by the step (the step writes the `Transform`
    /// of each bead it steps, in the same pass).
    Writeback,
}

/// Simulated time since the last [`Restart`]: steps taken and seconds.
/// Advanced in [`WireBeadSystems::Prepare`], so during a step it already
/// reads the time the step reaches.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Resource)]
pub struct SimClock {
    /// Steps since the last restart.
    pub steps: u64,
    /// Seconds since the last restart.
    pub time: f64,
}

/// Restarts the run: applies [`PendingParams`] and every [`PendingBead`],
/// returns each bead to its initial state, clears divergence, and sets
/// `Time<Fixed>` to the timestep. Handled in [`PreUpdate`], so the frame
/// that sends it already steps with the new parameters.
#[derive(Message, Clone, Copy, Debug, Default)]
pub struct Restart;

/// When the step's per-bead systems run in parallel: a system whose query
/// has at least `threshold` beads splits them over the compute task pool
/// (with the `parallel` feature, which enables Bevy's `multi_threaded`);
/// below it, it loops in its own thread, where waking the pool would cost
/// more than the work. [`ParallelStep::OFF`] keeps every loop sequential.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Resource)]
pub struct ParallelStep {
    /// The fewest beads a system splits over threads.
    pub threshold: usize,
}

impl ParallelStep {
    /// Never parallel.
    pub const OFF: Self = Self {
        threshold: usize::MAX,
    };
}

impl Default for ParallelStep {
    /// Parallel from 4,096 beads up.
    fn default() -> Self {
        Self { threshold: 4096 }
    }
}

/// Task pool options whose compute pool has a thread for every core.
///
/// Bevy's default gives the compute pool the cores left after one IO and one
/// async-compute thread: one thread on a two-core machine, where
/// [`ParallelStep`] then has nothing to split over. The IO and async pools
/// mostly sleep, so sharing the cores with them costs little:
///
/// ```
/// use bevy::prelude::*;
/// App::new().add_plugins(MinimalPlugins.set(TaskPoolPlugin {
///     task_pool_options: wirebead::plugin::compute_on_all_cores(),
/// }));
/// ```
pub fn compute_on_all_cores() -> TaskPoolOptions {
    let mut options = TaskPoolOptions::default();
    options.compute.min_threads = bevy::tasks::available_parallelism();
    options
}

/// Sent when a bead diverges: which bead and why.
#[derive(Message, Clone, Debug)]
pub struct BeadDiverged {
    /// The bead.
    pub bead: Entity,
    /// Why it stopped.
    pub reason: DivergenceReason,
}

/// Beads on wires: the simulation, headless. Add it to any app that has
/// `Time` (`MinimalPlugins` or `DefaultPlugins`).
#[derive(Clone, Debug)]
pub struct WireBeadPlugin {
    params: SimParams,
    extras: bool,
}

impl Default for WireBeadPlugin {
    fn default() -> Self {
        Self {
            params: SimParams::default(),
            extras: true,
        }
    }
}

impl WireBeadPlugin {
    /// The plugin with the given initial parameters, if they are valid.
    pub fn new(params: SimParams) -> Result<Self, ParamError> {
        params.validate()?;
        Ok(Self {
            params,
            ..Self::default()
        })
    }

    /// Lean beads: a [`Bead`] no longer brings a `Transform` (with its
    /// `GlobalTransform`) and [`BeadDiagnostics`] along. For crowds of
    /// beads: a lean bead takes about a third of the memory and steps
    /// faster. A bead given either component explicitly still has it kept
    /// up to date, so a game can render or watch a few of many.
    pub fn lean(self) -> Self {
        Self {
            extras: false,
            ..self
        }
    }
}

impl Plugin for WireBeadPlugin {
    fn build(&self, app: &mut App) {
        if self.extras {
            for registered in [
                app.try_register_required_components::<Bead, Transform>(),
                app.try_register_required_components::<Bead, BeadDiagnostics>(),
            ] {
                if let Err(err) = registered {
                    warn!("wirebead: could not give beads their Transform and diagnostics: {err}");
                }
            }
        }
        if !app.world().contains_resource::<SimParams>() {
            app.insert_resource(self.params.clone());
        }
        let applied = app.world().resource::<SimParams>().clone();
        let mut pending = PendingParams::default();
        if let Err(err) = pending.set(applied) {
            error!("wirebead: the initial SimParams are invalid ({err}); using the defaults");
            app.insert_resource(SimParams::default());
        }
        app.insert_resource(pending)
            .init_resource::<ParallelStep>()
            .init_resource::<SimClock>()
            .init_resource::<systems::LastStep>()
            .add_message::<Restart>()
            .add_message::<BeadDiverged>()
            .register_type::<Bead>()
            .register_type::<BeadDiagnostics>()
            .register_type::<DragTarget>()
            .register_type::<PendingBead>()
            .register_type::<SimParams>()
            .register_type::<ParallelStep>()
            .register_type::<SimClock>()
            .register_type::<PendingParams>()
            .configure_sets(
                FixedUpdate,
                (
                    WireBeadSystems::Prepare,
                    WireBeadSystems::Forces,
                    WireBeadSystems::Step,
                    WireBeadSystems::Writeback,
                )
                    .chain(),
            )
            .add_systems(Startup, systems::apply_timestep)
            .add_systems(PreUpdate, systems::apply_restart)
            .add_systems(
                FixedUpdate,
                (
                    systems::prepare_step.in_set(WireBeadSystems::Prepare),
                    systems::apply_drag.in_set(WireBeadSystems::Forces),
                    systems::step_beads.in_set(WireBeadSystems::Step),
                    systems::write_transforms.in_set(WireBeadSystems::Writeback),
                ),
            );
    }
}

/// Gives every schedule of `app` a single-threaded executor. For headless
/// runs of a few beads (tests, the analysis tool), where waking the thread
/// pool for each tiny system costs more than the step itself. Call it after
/// adding the plugins.
pub fn use_single_threaded_executors(app: &mut App) {
    let mut schedules = app.world_mut().resource_mut::<Schedules>();
    for (_, schedule) in schedules.iter_mut() {
        schedule.set_executor(bevy::ecs::schedule::SingleThreadedExecutor::new());
    }
}
