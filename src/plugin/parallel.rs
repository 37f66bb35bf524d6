//! [`ParallelStep`]: when the step's per-bead loops split over threads.

use bevy::prelude::*;
use bevy::tasks::ComputeTaskPool;

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

    /// The compute task pool and its thread count where a system with
    /// `beads` beads splits them over threads: at or above the threshold,
    /// with a pool of more than one thread. `None`: it loops in its own
    /// thread.
    pub(crate) fn pool(&self, beads: usize) -> Option<(&'static ComputeTaskPool, usize)> {
        let pool = ComputeTaskPool::try_get().filter(|_| beads >= self.threshold)?;
        let threads = pool.thread_num();
        (threads > 1).then_some((pool, threads))
    }
}

/// How the last step split its work: for the lone beads and for the
/// islands, the compute pool's threads it split over (0 when it looped in
/// its own thread) and the runs or chunks it made. For tuning
/// [`ParallelStep::threshold`], and the proof in the tests that a step was
/// split.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
#[reflect(Resource)]
pub struct StepSplit {
    /// Threads the last bead step split over (0: none).
    pub bead_threads: usize,
    /// Runs of lone beads the last bead step made.
    pub bead_runs: usize,
    /// Threads the last island step split over (0: none).
    pub island_threads: usize,
    /// Chunks of islands the last island step made.
    pub island_chunks: usize,
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
