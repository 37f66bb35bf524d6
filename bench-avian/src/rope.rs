//! The rope job: a rope of N rods hanging from a pin, released horizontal.
//!
//! N + 1 point masses of 1 kg start at rest at `(0.1 i, 0)`, i = 0..=N;
//! the first is held where it is, consecutive ones are joined at a fixed
//! distance of 0.1 m, gravity is `(0, -10)`, dt = 1/60 s.
//!
//! - Ours: the pure [`Island`] (no ECS) exactly as `benches/chain.rs`
//!   builds it: two [`RowKind::Axis`] rows pin bead 0, one
//!   [`RowKind::Rod`] row per link, stepped by RATTLE with
//!   [`Island::step`]. A step that fails ends the run, and the note says
//!   at which step and why.
//! - avian2d: body 0 static, bodies 1..=N dynamic (mass 1, rotation locked
//!   with [`LockedAxes::ROTATION_LOCKED`]), one [`DistanceJoint`] per link
//!   with `min = max = 0.1`, zero compliance and both anchors at the body
//!   centres, no colliders, sleeping disabled, built and stepped by
//!   [`avian_side::physics_app`] and [`avian_side::timed_step`]. Run at
//!   avian's default substeps (6) and at each count of `--substeps`.
//!
//! Measured per run: wall ns per rod-step (the stepping calls alone, over
//! N × steps), the largest relative stretch `| |x_{i+1} - x_i| - 0.1 | / 0.1`
//! over all links and steps, and the change of the rope's total energy
//! (kinetic plus potential, J) from the release to the end.

use std::time::{Duration, Instant};

use avian2d::prelude::{
    AngularInertia, DistanceJoint, LinearVelocity, LockedAxes, Mass, Position, RigidBody,
    SleepingDisabled,
};
use bevy::app::App;
use bevy::math::DVec2;
use bevy::prelude::Entity;
use clap::Args;
use wirebead::solver::{BeadState, IslandWork, Method, StepSettings};

use crate::avian_side;

// The rope `benches/chain.rs` steps, shared with it.
#[path = "../../benches/support/rope.rs"]
mod chain_rope;
use chain_rope::{GRAVITY, LINK, energy, max_stretch, released};

/// The timestep, seconds.
const DT: f64 = 1.0 / 60.0;
/// The substep count whose ratio to ours is always printed, if it was run.
const AVIAN_REFERENCE_SUBSTEPS: u32 = 50;

/// Options of the rope job.
#[derive(Args, Debug)]
pub struct RopeArgs {
    /// Steps of 1/60 s to simulate.
    #[arg(long, default_value_t = 600, value_parser = avian_side::positive)]
    pub steps: usize,
    /// Rope sizes N (number of rods), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "10,100,1000", value_parser = avian_side::positive)]
    pub sizes: Vec<usize>,
    /// avian2d substep counts to run besides its default (6), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "20,50,100,200", value_parser = clap::value_parser!(u32).range(1..))]
    pub substeps: Vec<u32>,
}

/// What one run measured.
struct RopeRun {
    /// avian2d's substep count, or `None` for ours.
    avian_substeps: Option<u32>,
    /// Wall nanoseconds per rod-step in the stepping calls.
    ns_per_rod_step: f64,
    /// Largest relative stretch `|C| / L` over all links and steps.
    max_stretch: f64,
    /// Total energy at the end minus at the release, J.
    energy_change: f64,
    /// Failures and substeps, in words.
    note: String,
}

impl RopeRun {
    /// The table's first column.
    fn name(&self) -> String {
        match self.avian_substeps {
            None => "wirebead RATTLE, pure Island".to_string(),
            Some(k) => format!("avian2d 0.7 DistanceJoint, {k} substeps"),
        }
    }
}

/// Our rope of `n` rods for `steps` steps of RATTLE at 1/60 s.
fn run_ours(n: usize, steps: usize) -> RopeRun {
    let (island, forces) = (chain_rope::island(n), chain_rope::weights(n));
    let settings = StepSettings {
        dt: DT,
        method: Method::Rattle,
        alpha: 0.0,
        beta: 0.0,
        drift_bound: 1.0,
    };
    let mut work = IslandWork::default();
    let mut states = released(n);
    let e0 = energy(&states);
    let (mut stretch, mut substeps, mut seconds, mut taken) = (0.0f64, 0, 0.0, 0);
    let mut failure = None;
    for k in 1..=steps {
        let start = Instant::now();
        let stepped = island.step(&mut states, &forces, &settings, &mut work);
        seconds += start.elapsed().as_secs_f64();
        taken = k;
        if let Err(e) = stepped {
            failure = Some(format!("failed at step {k}: {e}"));
            break;
        }
        substeps = substeps.max(work.substeps());
        stretch = stretch.max(max_stretch(&states));
    }
    let note = match failure {
        None => format!("most substeps in a step: {substeps}"),
        Some(why) => format!("{why}; most substeps in a step before it: {substeps}"),
    };
    RopeRun {
        avian_substeps: None,
        ns_per_rod_step: seconds * 1e9 / (n * taken.max(1)) as f64,
        max_stretch: stretch,
        energy_change: energy(&states) - e0,
        note,
    }
}

/// Reads the avian rope's bodies into `states`, in order along the rope.
fn read_avian(app: &App, bodies: &[Entity], states: &mut Vec<BeadState>) {
    let world = app.world();
    states.clear();
    states.extend(bodies.iter().map(|&body| {
        BeadState {
            position: world.get::<Position>(body).expect("a Position").0,
            velocity: world
                .get::<LinearVelocity>(body)
                .map_or(DVec2::ZERO, |v| v.0),
        }
    }));
}

/// avian2d's rope of `n` rods at `substeps` substeps per step, for `steps`
/// steps of 1/60 s (rounded by bevy to whole nanoseconds).
fn run_avian(n: usize, substeps: u32, steps: usize) -> RopeRun {
    let step = Duration::from_secs_f64(DT);
    let mut app = avian_side::physics_app(step, None, DVec2::new(0.0, -GRAVITY), Some(substeps));
    let mut bodies = Vec::with_capacity(n + 1);
    bodies.push(
        app.world_mut()
            .spawn((RigidBody::Static, Position(DVec2::ZERO)))
            .id(),
    );
    for i in 1..=n {
        let body = app.world_mut().spawn((
            RigidBody::Dynamic,
            Position(DVec2::new(i as f64 * LINK, 0.0)),
            LinearVelocity(DVec2::ZERO),
            Mass(1.0),
            // Both anchors sit at the centre of mass, so the joints exert
            // no torque; the rotation is locked as well, and the inertia
            // only has to be finite and non-zero to keep avian quiet.
            AngularInertia(1.0),
            LockedAxes::ROTATION_LOCKED,
            SleepingDisabled,
        ));
        bodies.push(body.id());
    }
    for pair in bodies.windows(2) {
        app.world_mut().spawn(
            DistanceJoint::new(pair[0], pair[1])
                .with_limits(LINK, LINK)
                .with_compliance(0.0),
        );
    }
    avian_side::warm_up(&mut app);

    let mut states = Vec::with_capacity(n + 1);
    read_avian(&app, &bodies, &mut states);
    let e0 = energy(&states);
    let (mut stretch, mut seconds) = (0.0f64, 0.0);
    for k in 1..=steps {
        seconds += avian_side::timed_step(&mut app, step, k);
        read_avian(&app, &bodies, &mut states);
        stretch = stretch.max(max_stretch(&states));
    }
    let finite = states
        .iter()
        .all(|s| s.position.is_finite() && s.velocity.is_finite());
    RopeRun {
        avian_substeps: Some(substeps),
        ns_per_rod_step: seconds * 1e9 / (n * steps.max(1)) as f64,
        max_stretch: stretch,
        energy_change: energy(&states) - e0,
        note: if finite {
            String::new()
        } else {
            "the state became non-finite".to_string()
        },
    }
}

/// Runs the rope job and prints its table and ratios.
pub fn run(args: &RopeArgs) {
    let counts = avian_side::substep_counts(&args.substeps);
    let default = counts[0];
    // (N, ours, avian runs in the order of `counts`)
    let mut results = Vec::new();
    for &n in &args.sizes {
        let ours = run_ours(n, args.steps);
        eprintln!("done: N = {n}, {}", ours.name());
        let mut avian = Vec::new();
        for &k in &counts {
            avian.push(run_avian(n, k, args.steps));
            eprintln!("done: N = {n}, avian2d at {k} substeps");
        }
        results.push((n, ours, avian));
    }

    println!(
        "Rope of N rods of {LINK} m hanging from a pin, N + 1 beads of 1 kg released horizontal from rest, |g| = {GRAVITY} m/s², dt = 1/60 s, {} steps.\n",
        args.steps
    );
    println!("| engine/config | N | ns per rod-step | max \\|C\\|/L | energy change (J) | note |");
    println!("|---|---|---|---|---|---|");
    for (n, ours, avian) in &results {
        let best = smallest_stretch(avian);
        for (i, r) in std::iter::once(ours).chain(avian).enumerate() {
            let mut note = r.note.clone();
            if i > 0 && best == Some(i - 1) {
                if !note.is_empty() {
                    note.push_str("; ");
                }
                note.push_str("smallest stretch of the avian2d runs");
            }
            println!(
                "| {} | {n} | {:.1} | {:.2e} | {:+.3e} | {} |",
                r.name(),
                r.ns_per_rod_step,
                r.max_stretch,
                r.energy_change,
                note.replace('|', "\\|")
            );
        }
    }

    println!("\nTime per rod-step, avian2d / ours:\n");
    for (n, ours, avian) in &results {
        let ratio = |r: &RopeRun| r.ns_per_rod_step / ours.ns_per_rod_step;
        let mut parts = Vec::new();
        if let Some(shipped) = avian.iter().find(|r| r.avian_substeps == Some(default)) {
            parts.push(format!(
                "{default} substeps (default) {:.2}×",
                ratio(shipped)
            ));
        }
        if let Some(best) = smallest_stretch(avian).map(|i| &avian[i]) {
            parts.push(format!(
                "{} substeps (smallest stretch, {:.1e}) {:.2}×",
                best.avian_substeps.unwrap_or_default(),
                best.max_stretch,
                ratio(best)
            ));
        }
        if let Some(reference) = avian
            .iter()
            .find(|r| r.avian_substeps == Some(AVIAN_REFERENCE_SUBSTEPS))
        {
            parts.push(format!(
                "{AVIAN_REFERENCE_SUBSTEPS} substeps {:.2}×",
                ratio(reference)
            ));
        }
        let caveat = if ours.note.starts_with("failed") {
            " (ours stopped early: see its note)"
        } else {
            ""
        };
        println!("- N = {n}: {}{caveat}", parts.join(", "));
    }
}

/// The index of the avian run with the smallest stretch, the fewest
/// substeps on a tie.
fn smallest_stretch(avian: &[RopeRun]) -> Option<usize> {
    (0..avian.len()).min_by(|&a, &b| {
        let (ra, rb) = (&avian[a], &avian[b]);
        ra.max_stretch
            .total_cmp(&rb.max_stretch)
            .then(ra.avian_substeps.cmp(&rb.avian_substeps))
    })
}
