//! The coupled solve's cost on a chain: `cargo bench --bench chain`.
//!
//! `chain`: a rope of N rods hanging from a pin (N + 1 beads of 1 kg, the
//! first held by the pin's two rows, links of 0.1 m, |g| = 10), released
//! horizontal, stepped by RATTLE at 1/60 s through the pure `Island` (no
//! ECS). Each iteration runs the first `STEPS` steps from the release, so
//! every sample does the same work; throughput is rod-steps. Before the
//! timing, one run prints the largest relative stretch `max |C| / L`, the
//! most substeps a step took, and the energy change.

use std::hint::black_box;
use std::time::Duration;

use bevy::math::DVec2;
use criterion::{BatchSize, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use wirebead::solver::{
    BeadState, Island, IslandRow, IslandWork, LinearForce, Method, RowKind, StepSettings,
};

/// The link length.
const LINK: f64 = 0.1;
/// Steps per iteration: the first quarter second after the release.
const STEPS: usize = 15;
const SIZES: [usize; 5] = [10, 100, 1_000, 10_000, 100_000];

/// The rope: its island, its beads at rest along +x, their weights.
fn rope(n: usize) -> (Island, Vec<BeadState>, Vec<LinearForce>) {
    let mut rows: Vec<IslandRow> = [DVec2::X, DVec2::Y]
        .map(|axis| IslandRow {
            kind: RowKind::Axis { axis, offset: 0.0 },
            beads: vec![0],
        })
        .to_vec();
    rows.extend((0..n).map(|i| IslandRow {
        kind: RowKind::Rod { length: LINK },
        beads: vec![i, i + 1],
    }));
    let island = Island::new(&vec![1.0; n + 1], rows, vec![]).expect("a valid rope");
    let states = (0..=n)
        .map(|i| BeadState {
            position: DVec2::new(i as f64 * LINK, 0.0),
            velocity: DVec2::ZERO,
        })
        .collect();
    let forces = vec![LinearForce::constant(DVec2::new(0.0, -10.0)); n + 1];
    (island, states, forces)
}

fn settings() -> StepSettings {
    StepSettings {
        dt: 1.0 / 60.0,
        method: Method::Rattle,
        alpha: 0.0,
        beta: 0.0,
        drift_bound: 1.0,
    }
}

/// `STEPS` steps from `states`; the largest relative stretch and the most
/// substeps, or the step that failed and why.
fn run(
    island: &Island,
    states: &mut [BeadState],
    forces: &[LinearForce],
    work: &mut IslandWork,
) -> Result<(f64, u32), String> {
    let s = settings();
    let (mut stretch, mut substeps) = (0.0f64, 0);
    for k in 0..STEPS {
        island
            .step(states, forces, &s, work)
            .map_err(|e| format!("step {k}: {e}"))?;
        substeps = substeps.max(work.substeps());
        for w in states.windows(2) {
            stretch = stretch.max(((w[1].position - w[0].position).length() - LINK).abs() / LINK);
        }
    }
    Ok((stretch, substeps))
}

fn energy(states: &[BeadState]) -> f64 {
    states
        .iter()
        .map(|s| 0.5 * s.velocity.length_squared() + 10.0 * s.position.y)
        .sum()
}

fn chain(c: &mut Criterion) {
    let mut group = c.benchmark_group("chain");
    for n in SIZES {
        group.throughput(Throughput::Elements((n * STEPS) as u64));
        group.sample_size(10);
        group.warm_up_time(Duration::from_millis(500));
        group.measurement_time(Duration::from_secs(if n >= 10_000 { 20 } else { 5 }));
        let (island, start, forces) = rope(n);
        let mut work = IslandWork::default();
        let mut states = start.clone();
        match run(&island, &mut states, &forces, &mut work) {
            Ok((stretch, substeps)) => eprintln!(
                "chain/{n}: max |C|/L {stretch:.1e}, at most {substeps} substeps, energy change {:.3e} J over {STEPS} steps",
                energy(&states) - energy(&start)
            ),
            Err(why) => {
                eprintln!("chain/{n}: {why}; not timed");
                continue;
            }
        }
        group.bench_function(BenchmarkId::new("rattle-1/60", n), |b| {
            b.iter_batched_ref(
                || start.clone(),
                |states| black_box(run(&island, states, &forces, &mut work)),
                BatchSize::LargeInput,
            );
        });
    }
    group.finish();
}

criterion_group!(benches, chain);
criterion_main!(benches);
