//! avian2d on the bead-on-a-circle job, and the app every job's avian side
//! is built in ([`physics_app`], [`warm_up`], [`timed_step`]).
//!
//! Each pendulum is a dynamic body (mass 1, no collider) held by a
//! [`DistanceJoint`] with `min = max = 0.8` and zero compliance to a static
//! anchor body, released from rest horizontally to the right of its anchor,
//! under the [`Gravity`] resource `(0, -10)`.
//!
//! # Configuration, as read from the avian2d 0.7.0 source
//!
//! - `PhysicsPlugins::default()` runs the physics in `FixedPostUpdate`
//!   (`src/lib.rs`, `impl Default for PhysicsPlugins`).
//! - Substeps: avian's default, `SubstepCount(6)`
//!   (`src/dynamics/solver/schedule.rs`, `impl Default for SubstepCount`),
//!   left untouched: avian is compared as shipped. The joint is solved by the
//!   XPBD joint solver (`xpbd_joints` feature) once per substep. The rope
//!   and carts jobs also run at larger counts, set by inserting the
//!   [`SubstepCount`] resource after the plugins.
//! - No damping: `LinearDamping`/`AngularDamping` are read as `Option`s and
//!   default to `0.0` when absent (`src/dynamics/integrator/mod.rs`,
//!   `pre_process_velocity_increments`), `JointDamping` only acts on joints
//!   that carry it (`src/dynamics/solver/plugin.rs`, `joint_damping`), and
//!   `MaxLinearSpeed` defaults to infinity. None of these is added here.
//! - No sleeping: every bead carries [`SleepingDisabled`]
//!   (`src/dynamics/rigid_body/sleeping.rs`; honoured by
//!   `src/dynamics/solver/islands/sleeping.rs`).
//! - No contacts: no body has a collider, so the broad and narrow phases have
//!   nothing to do. Mass comes from [`Mass`]/[`AngularInertia`] directly.
//! - Transform sync is switched off with [`PhysicsTransformConfig`]: the
//!   `Position -> Transform -> GlobalTransform -> Position` round trip goes
//!   through `f32`, and `transform_to_position` copies the transform back into
//!   `Position` whenever they differ by more than `1e-5` m
//!   (`src/physics_transform/mod.rs`). With anchors 3 m apart, `f32`
//!   rounding (half an ulp) exceeds that tolerance beyond x = 256 m (from
//!   about the 86th pendulum on), which would snap those `f64` positions to
//!   `f32` values between steps. The sync only feeds rendering; the solver
//!   works on `Position`/`Rotation` alone.

use std::time::Duration;

use avian2d::prelude::{
    AngularInertia, DistanceJoint, LinearVelocity, Mass, Position, RigidBody, SleepingDisabled,
    SubstepCount, Substeps,
};
use bevy::app::App;
use bevy::math::DVec2;
use bevy::prelude::{Component, Entity};
use bevy::time::Time;

/// Circle radius (the joint's fixed length), metres.
const RADIUS: f64 = 0.8;
/// Magnitude of gravity, m/s², pointing along -y.
const GRAVITY: f64 = 10.0;
/// Distance between neighbouring anchors along x, metres. More than twice
/// the radius, so no two pendulums ever come near each other.
const SPACING: f64 = 3.0;

/// What one avian2d run measured.
pub struct AvianRun {
    /// energy change E(end) - E(0) per unit mass, J/kg (E = |v|²/2 + |g| y)
    pub energy_change: f64,
    /// max over steps of | |x - anchor| - 0.8 | in metres (over all bodies)
    pub max_radial_error: f64,
    /// period estimated from the bead's crossings (see below), seconds; None if fewer than 2 crossings
    pub period: Option<f64>,
    /// wall-clock seconds spent in the stepping loop only (not app setup), for all steps
    pub wall_seconds: f64,
    /// number of bead-steps = n * steps
    pub bead_steps: u64,
}

/// Marks a pendulum's moving body and remembers where its anchor is.
#[derive(Component)]
struct AvianBead {
    /// World position of the static anchor this bead is jointed to.
    anchor: DVec2,
}

/// Energy per unit mass of a bead at `offset` from its anchor moving with
/// `velocity`: `|v|²/2 + |g| y`.
fn energy(offset: DVec2, velocity: DVec2) -> f64 {
    0.5 * velocity.length_squared() + GRAVITY * offset.y
}

/// The bead's state relative to its anchor: (offset, velocity).
fn bead_state(app: &App, bead: Entity, anchor: DVec2) -> (DVec2, DVec2) {
    let world = app.world();
    let position = world.get::<Position>(bead).expect("bead has a Position").0;
    let velocity = world
        .get::<LinearVelocity>(bead)
        .expect("bead has a LinearVelocity")
        .0;
    (position - anchor, velocity)
}

/// The app every avian job is built in, for one dimension: [`physics_app`],
/// [`warm_up`] and [`timed_step`] over `$avian` (avian2d or avian3d), whose
/// plugins, resources and clock have the same names in both.
macro_rules! harness {
    ($avian:ident, $vector:ty) => {
        use std::time::{Duration, Instant};

        use $avian::physics_transform::PhysicsTransformConfig;
        use $avian::prelude::{Gravity, Physics, PhysicsPlugins, SubstepCount};
        use bevy::app::{App, PluginGroup, PluginsState, TaskPoolOptions, TaskPoolPlugin};
        use bevy::prelude::MinimalPlugins;
        use bevy::tasks::ComputeTaskPool;
        use bevy::time::{Fixed, Time, TimeUpdateStrategy, Virtual};

        /// A headless app with avian and no bodies yet, ready for spawning and
        /// then [`warm_up`]: gravity `gravity`, `substeps` substeps per step
        /// (`None`: avian's default, 6), transform sync off (see the module docs),
        /// and exactly one physics step of `step` per [`App::update`].
        ///
        /// # Stepping: exactly one physics step of `step` per `App::update`
        ///
        /// - `Time<Fixed>` gets the timestep `step`, and
        ///   `TimeUpdateStrategy::FixedTimesteps(1)` makes bevy's `time_system`
        ///   advance `Time<Real>` by exactly `timestep * 1` per update, whatever the
        ///   wall clock does (`bevy_time-0.19.1/src/lib.rs`, `time_system`).
        /// - `Time<Virtual>` follows with the same raw delta: at relative speed 1 it
        ///   skips the `f64` rescaling, and `max_delta` (raised here to at least
        ///   `2 * step`) does not clamp it (`bevy_time-0.19.1/src/virt.rs`,
        ///   `advance_with_raw_delta`).
        /// - `run_fixed_main_schedule` adds that delta to the fixed overstep and
        ///   runs `FixedMain` while a whole timestep can be taken off it; `Duration`
        ///   is integer nanoseconds, so the overstep goes from 0 to exactly `step`
        ///   and back to 0: one run of `FixedMain` (`bevy_time-0.19.1/src/fixed.rs`).
        /// - avian's `run_physics_schedule` sits in `FixedPostUpdate`; it advances
        ///   `Time<Physics>` by the generic `Time` delta (there `Time<Fixed>`, i.e.
        ///   `step`) and runs `PhysicsSchedule` once, which runs the substep
        ///   schedule `SubstepCount` times (`avian2d-0.7.0/src/schedule/mod.rs`,
        ///   `src/dynamics/solver/schedule.rs`).
        /// - The very first update takes no step: `Time<Real>::update_with_duration`
        ///   only records its first instant, so the first delta is zero
        ///   (`bevy_time-0.19.1/src/real.rs`). [`warm_up`] spends that update;
        ///   avian's own integrator test does the same.
        ///
        /// [`timed_step`] checks every later update against `Time<Physics>`.
        pub fn physics_app(
            step: Duration,
            threads: Option<usize>,
            gravity: $vector,
            substeps: Option<u32>,
        ) -> App {
            physics_app_with(step, threads, gravity, substeps, |_| {})
        }

        /// [`physics_app`] with more plugins, added by `more` after avian's.
        #[allow(dead_code)]
        pub fn physics_app_with(
            step: Duration,
            threads: Option<usize>,
            gravity: $vector,
            substeps: Option<u32>,
            more: impl FnOnce(&mut App),
        ) -> App {
            let mut app = App::new();

            // Bevy's task pools are process-wide and created once: a later
            // `TaskPoolPlugin` with other options keeps the existing pools.
            if let Some(k) = threads
                && let Some(pool) = ComputeTaskPool::try_get()
            {
                eprintln!(
                    "warning: run_avian asked for {k} thread(s), but the task pools already exist \
                     (compute pool: {} threads) and will be reused",
                    pool.thread_num()
                );
            }
            let minimal = match threads {
                Some(k) => MinimalPlugins.set(TaskPoolPlugin {
                    task_pool_options: TaskPoolOptions::with_num_threads(k),
                }),
                None => MinimalPlugins.build(),
            };

            // Must be in place before `PhysicsPlugins` is added: the plugin only
            // `init_resource`s it, and reads `position_to_transform` at build time.
            app.insert_resource(PhysicsTransformConfig {
                propagate_before_physics: false,
                transform_to_position: false,
                position_to_transform: false,
                transform_to_collider_scale: false,
            });
            app.add_plugins((minimal, PhysicsPlugins::default()));
            more(&mut app);

            app.insert_resource(Gravity(gravity));
            if let Some(k) = substeps {
                // Replaces the default that `SolverSchedulePlugin` `init_resource`d.
                app.insert_resource(SubstepCount(k));
            }
            app.insert_resource(Time::<Fixed>::from_duration(step));
            app.insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
            {
                let mut virtual_time = app.world_mut().resource_mut::<Time<Virtual>>();
                let max_delta = virtual_time.max_delta().max(step * 2);
                virtual_time.set_max_delta(max_delta);
            }

            // What `App::run` does through the schedule runner before the first update.
            while app.plugins_state() == PluginsState::Adding {
                bevy::tasks::tick_global_task_pools_on_main_thread();
            }
            app.finish();
            app.cleanup();
            app
        }

        /// The first update of an app from [`physics_app`], after the bodies are
        /// spawned: runs the startup schedules and takes no physics step.
        ///
        /// # Panics
        ///
        /// If that update did step the physics.
        pub fn warm_up(app: &mut App) {
            app.update();
            assert_eq!(
                app.world().resource::<Time<Physics>>().elapsed(),
                Duration::ZERO,
                "the warm-up update must not step the physics"
            );
        }

        /// Update `k` (counted from 1) of an app from [`physics_app`]: one physics
        /// step of `step`. Returns the wall seconds of the `App::update` call alone.
        ///
        /// # Panics
        ///
        /// If the update did not advance the physics clock by one step.
        pub fn timed_step(app: &mut App, step: Duration, k: usize) -> f64 {
            let before = app.world().resource::<Time<Physics>>().elapsed();
            let start = Instant::now();
            app.update();
            let seconds = start.elapsed().as_secs_f64();

            // One update, one physics step: the physics clock moved by one
            // timestep (give or take the nanosecond rounding avian's
            // relative-speed scaling may add), not zero and not two.
            let advanced = app.world().resource::<Time<Physics>>().elapsed() - before;
            assert!(
                advanced > step / 2 && advanced < step * 3 / 2,
                "update {k} advanced the physics clock by {advanced:?}, expected one step of {step:?}"
            );
            seconds
        }
    };
}

/// The harness of avian3d's jobs.
pub mod space {
    use bevy::math::DVec3;
    harness!(avian3d, DVec3);
}

/// The harness of avian2d's jobs.
mod plane {
    use bevy::math::DVec2;
    harness!(avian2d, DVec2);
}
pub use plane::{physics_app, physics_app_with, timed_step, warm_up};

/// avian2d's default number of substeps per step (`impl Default for
/// SubstepCount`, `src/dynamics/solver/schedule.rs`): 6.
pub fn default_substeps() -> u32 {
    SubstepCount::default().0
}

/// The substep counts a job runs avian2d at: its default first, then each
/// of `extra` not already listed.
pub fn substep_counts(extra: &[u32]) -> Vec<u32> {
    let mut counts = vec![default_substeps()];
    for &k in extra {
        if !counts.contains(&k) {
            counts.push(k);
        }
    }
    counts
}

/// A count the command line gives, which must be at least 1.
pub fn positive(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("{text:?} is not a whole number ({e})")),
    }
}

/// A command-line number that must be positive and finite.
pub fn positive_f64(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        Ok(x) => Err(format!("must be positive and finite, got {x}")),
        Err(e) => Err(format!("{text:?} is not a number ({e})")),
    }
}

/// Builds a headless app with avian2d and `n` pendulums ([`physics_app`]
/// at avian's default substeps), warmed up. Returns the app and the first
/// pendulum's bead.
fn build_app(n: usize, step: Duration, threads: Option<usize>) -> (App, Entity) {
    let mut app = physics_app(step, threads, DVec2::new(0.0, -GRAVITY), None);

    let mut first = None;
    for i in 0..n {
        let anchor = DVec2::new(SPACING * i as f64, 0.0);
        let anchor_body = app
            .world_mut()
            .spawn((RigidBody::Static, Position(anchor)))
            .id();
        let bead = app
            .world_mut()
            .spawn((
                RigidBody::Dynamic,
                Position(anchor + DVec2::new(RADIUS, 0.0)),
                LinearVelocity(DVec2::ZERO),
                Mass(1.0),
                // The joint acts at the centre of mass (both local anchors are
                // zero), so it exerts no torque and the inertia never matters;
                // it only has to be finite and non-zero to keep avian quiet.
                AngularInertia(1.0),
                SleepingDisabled,
                AvianBead { anchor },
            ))
            .id();
        app.world_mut().spawn(
            DistanceJoint::new(anchor_body, bead)
                .with_limits(RADIUS, RADIUS)
                .with_compliance(0.0),
        );
        first.get_or_insert(bead);
    }

    // Warm-up: runs the startup schedules; takes no physics step (see above).
    warm_up(&mut app);

    (app, first.expect("at least one pendulum"))
}

/// Runs `n` independent avian2d pendulums for `steps` steps of `dt` seconds.
///
/// Pendulum 0 is sampled after every step for the energy change and the
/// period; the radial error is the maximum over all `n` pendulums and all
/// steps. The pendulums carry no colliders, so there are no contacts.
///
/// - Anchor `i` is at `(3 i, 0)`; its bead starts at rest at `(3 i + 0.8, 0)`.
/// - `dt` reaches bevy as a `Duration`, i.e. rounded to whole nanoseconds
///   (1/60 s becomes 16 666 667 ns), and avian splits each step into
///   `SubstepCount` (default 6) substeps, again rounded to nanoseconds. Sample times are therefore the time
///   avian actually integrated: the sum over steps of
///   `SubstepCount × Time<Substeps>::delta`.
/// - The period comes from the bead's upward zero crossings of x relative to
///   its anchor, with [`wirebead::reference::period_from_crossings`], the same
///   estimator the wirebead rows use.
/// - `wall_seconds` sums the `App::update` calls only; sampling and checks
///   are outside the timed region. An update also runs bevy's frame
///   schedules (time, fixed-loop bookkeeping), which is part of using avian.
/// - `threads`: `Some(k)` builds the app with
///   `TaskPoolPlugin { task_pool_options: TaskPoolOptions::with_num_threads(k) }`,
///   `None` with bevy's default. The pools are process-wide, so this only
///   takes effect if no app created them earlier in the process (a warning
///   is printed otherwise).
///
/// # Panics
///
/// If `n` is zero, `dt` is not a positive finite number, `threads` is
/// `Some(0)`, or an update does not advance the physics by exactly one step.
pub fn run_avian(n: usize, dt: f64, steps: usize, threads: Option<usize>) -> AvianRun {
    assert!(n >= 1, "run_avian needs at least one pendulum");
    assert!(
        dt.is_finite() && dt > 0.0,
        "run_avian needs a positive finite dt, got {dt}"
    );
    assert!(threads != Some(0), "run_avian needs at least one thread");
    let step = Duration::from_secs_f64(dt);
    assert!(!step.is_zero(), "dt = {dt} s rounds to zero nanoseconds");

    let (mut app, first) = build_app(n, step, threads);
    let anchor0 = app
        .world()
        .get::<AvianBead>(first)
        .expect("first pendulum's bead")
        .anchor;
    let SubstepCount(substeps) = *app.world().resource::<SubstepCount>();
    let mut beads = app.world_mut().query::<(&AvianBead, &Position)>();

    let (offset, velocity) = bead_state(&app, first, anchor0);
    let e0 = energy(offset, velocity);
    let mut samples = Vec::with_capacity(steps + 1);
    samples.push((0.0, offset.x));
    let mut max_radial_error: f64 = 0.0;
    let mut sim_time = 0.0;
    let mut wall_seconds = 0.0;

    for k in 1..=steps {
        wall_seconds += timed_step(&mut app, step, k);
        sim_time += f64::from(substeps) * app.world().resource::<Time<Substeps>>().delta_secs_f64();

        for (bead, position) in beads.iter(app.world()) {
            let error = ((position.0 - bead.anchor).length() - RADIUS).abs();
            max_radial_error = max_radial_error.max(error);
        }
        let (offset, _) = bead_state(&app, first, anchor0);
        samples.push((sim_time, offset.x));
    }

    let (offset, velocity) = bead_state(&app, first, anchor0);
    AvianRun {
        energy_change: energy(offset, velocity) - e0,
        max_radial_error,
        period: wirebead::reference::period_from_crossings(&samples),
        wall_seconds,
        bead_steps: n as u64 * steps as u64,
    }
}
