//! The test harness, not part of the simulation a game adds: an app with
//! `MinimalPlugins` and the plugin, stepped by hand, exactly `n` fixed
//! steps at a time. The tests, the benchmarks, the avian2d comparison and
//! the analysis tool all build their apps here.
//!
//! ```
//! use bevy::math::DVec2;
//! use wirebead::headless::{Headless, run_steps};
//! use wirebead::prelude::*;
//!
//! let mut app = Headless::new(WireBeadPlugin::default()).single_threaded().build();
//! let wire = app.world_mut().spawn(Wire::circle(1.0).unwrap()).id();
//! let bead = Bead::at_rest(1.0, DVec2::new(1.0, 0.0)).unwrap();
//! let bead = app.world_mut().spawn((bead, OnWire(wire))).id();
//! run_steps(&mut app, 30); // half a second: near the bottom
//! assert!(app.world().get::<BeadPosition>(bead).unwrap().y < -0.5);
//! ```

use std::path::PathBuf;
use std::time::Duration;

use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;

use bevy::math::DVec3;

use crate::dynamics::{BeadPosition, BeadVelocity, Dimension, SimParams};
use crate::plugin::{
    ParallelStep, WireBeadPlugin, compute_on_all_cores, use_single_threaded_executors,
};
use crate::preset::ScenePresetPlugin;
use crate::solver::BeadState;

/// Builds a headless app: [`Headless::new`], the options, [`Headless::build`].
#[derive(Clone, Debug)]
pub struct Headless {
    plugin: WireBeadPlugin,
    single_threaded: bool,
    parallel: Option<ParallelStep>,
    assets: Option<PathBuf>,
    bodies: Option<bool>,
    timeline: bool,
}

impl Headless {
    /// An app with `plugin`, Bevy's default executors, and a compute pool
    /// with a thread for every core ([`compute_on_all_cores`]). Bevy's task
    /// pools belong to the process and the first app made sets them up, so
    /// every headless app asks for the same pools: whichever test of a
    /// binary runs first, a step that splits over threads has every core.
    pub fn new(plugin: WireBeadPlugin) -> Self {
        Self {
            plugin,
            single_threaded: false,
            parallel: None,
            assets: None,
            bodies: None,
            timeline: false,
        }
    }

    /// Single-threaded executors: for runs of a few beads, where waking the
    /// thread pool for each tiny system costs more than the step.
    pub fn single_threaded(self) -> Self {
        Self {
            single_threaded: true,
            ..self
        }
    }

    /// When the step splits over threads.
    pub fn parallel(self, parallel: ParallelStep) -> Self {
        Self {
            parallel: Some(parallel),
            ..self
        }
    }

    /// The [`TimelinePlugin`](crate::plugin::TimelinePlugin), which
    /// records every step (added before avian's plugins finish their
    /// set-up, so that it records their bodies too).
    pub fn timeline(self) -> Self {
        Self {
            timeline: true,
            ..self
        }
    }

    /// Bevy's `AssetPlugin` reading from `dir`, and the
    /// [`ScenePresetPlugin`].
    pub fn assets(self, dir: impl Into<PathBuf>) -> Self {
        Self {
            assets: Some(dir.into()),
            ..self
        }
    }

    /// Avian's physics for a scene's rigid bodies, in the plane or
    /// (`in_space`) in space: avian's `PhysicsPlugins` and our
    /// `PathJointPlugin` of that dimension, where the build has its avian
    /// (see [`runs_bodies`]).
    pub fn bodies(self, in_space: bool) -> Self {
        Self {
            bodies: Some(in_space),
            ..self
        }
    }

    /// The app, after its first update (which starts the clocks and runs
    /// `Startup`, but no fixed step). Each later `app.update()` runs one
    /// fixed step until [`run_steps`] says otherwise.
    pub fn build(self) -> App {
        let mut app = App::new();
        let minimal = MinimalPlugins.set(TaskPoolPlugin {
            task_pool_options: compute_on_all_cores(),
        });
        app.add_plugins((minimal, self.plugin));
        if let Some(dir) = self.assets {
            app.add_plugins((
                AssetPlugin {
                    file_path: dir.to_string_lossy().into_owned(),
                    ..default()
                },
                ScenePresetPlugin,
            ));
        }
        if let Some(parallel) = self.parallel {
            app.insert_resource(parallel);
        }
        if self.timeline {
            app.add_plugins(crate::plugin::TimelinePlugin);
        }
        match self.bodies {
            #[cfg(feature = "avian2d")]
            Some(false) => {
                app.add_plugins((
                    avian2d::prelude::PhysicsPlugins::default(),
                    crate::avian::PathJointPlugin,
                ));
            }
            #[cfg(feature = "avian3d")]
            Some(true) => {
                app.add_plugins((
                    avian3d::prelude::PhysicsPlugins::default(),
                    crate::avian3d::PathJointPlugin,
                ));
            }
            _ => {}
        }
        if self.bodies.is_some() {
            // As `App::run` does: avian's plugins finish their set-up.
            app.finish();
            app.cleanup();
        }
        app.insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
        // Enough for any batch of steps `run_steps` asks for at once.
        app.world_mut()
            .resource_mut::<Time<Virtual>>()
            .set_max_delta(Duration::from_secs(1_000_000));
        if self.single_threaded {
            use_single_threaded_executors(&mut app);
        }
        app.update();
        app
    }
}

/// Whether this build runs rigid bodies in the plane or (`in_space`) in
/// space: whether it has the feature `avian2d` or `avian3d`.
pub fn runs_bodies(in_space: bool) -> bool {
    (in_space && cfg!(feature = "avian3d")) || (!in_space && cfg!(feature = "avian2d"))
}

/// Runs exactly `n` fixed steps in one update (and `n` per update after
/// it).
pub fn run_steps(app: &mut App, n: u32) {
    app.insert_resource(TimeUpdateStrategy::FixedTimesteps(n));
    app.update();
}

/// Runs for `seconds` of simulated time, rounded to whole steps of the
/// applied timestep.
pub fn run_for(app: &mut App, seconds: f64) {
    let dt = app.world().resource::<SimParams>().timestep;
    run_steps(app, (seconds / dt).round() as u32);
}

/// Runs updates with no fixed step (loading assets, handling messages).
pub fn idle(app: &mut App) {
    run_steps(app, 0);
}

/// A bead's position and velocity, or `None` if `bead` is not a bead.
pub fn bead_state(world: &World, bead: Entity) -> Option<BeadState> {
    state_in(world, bead)
}

/// [`bead_state`] of a bead in space.
pub fn space_bead_state(world: &World, bead: Entity) -> Option<BeadState<DVec3>> {
    state_in(world, bead)
}

/// The state of a bead of either dimension.
fn state_in<V: Dimension>(world: &World, bead: Entity) -> Option<BeadState<V>> {
    let bead = world.get_entity(bead).ok()?;
    Some(BeadState {
        position: bead.get::<BeadPosition<V>>()?.0,
        velocity: bead.get::<BeadVelocity<V>>()?.0,
    })
}
