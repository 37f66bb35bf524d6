//! The step's cost per bead: `cargo bench --bench step`.
//!
//! - `scale`: the plugin as a game gets it (Bevy's executor, parallel loops
//!   from `ParallelStep::default()`), N beads each on its own circle or all
//!   on one, N = 1 … 1,000,000, full beads (the default) and lean ones
//!   (`WireBeadPlugin::lean`). Throughput is bead-steps per second.
//! - `overhead`: at each N and for each kind of bead, the same math as one
//!   fused loop over a `Vec` of plain structs (the floor), against the
//!   plugin single-threaded and parallel.

use std::hint::black_box;
use std::time::Duration;

use bevy::prelude::*;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

mod support;
use support::{Kind, Layout, RawLoop, Threads, plugin_app};

const SIZES: [usize; 4] = [1, 1_000, 100_000, 1_000_000];

fn configure(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    n: usize,
) {
    group.throughput(Throughput::Elements(n as u64));
    if n >= 100_000 {
        group.sample_size(10);
        group.warm_up_time(Duration::from_secs(1));
        group.measurement_time(Duration::from_secs(4));
    } else {
        group.sample_size(30);
        group.warm_up_time(Duration::from_millis(500));
        group.measurement_time(Duration::from_secs(2));
    }
}

fn scale(c: &mut Criterion) {
    let mut group = c.benchmark_group("scale");
    for n in SIZES {
        configure(&mut group, n);
        for kind in [Kind::Full, Kind::Lean] {
            for layout in [Layout::OwnWires, Layout::SharedWire] {
                let mut app = plugin_app(n, layout, Threads::Parallel, kind);
                let name = format!("{}/{}", kind.name(), layout.name());
                group.bench_function(BenchmarkId::new(name, n), |b| {
                    b.iter(|| app.world_mut().run_schedule(FixedUpdate));
                });
            }
        }
    }
    group.finish();
}

fn overhead(c: &mut Criterion) {
    let mut group = c.benchmark_group("overhead");
    for n in SIZES {
        configure(&mut group, n);
        for kind in [Kind::Full, Kind::Lean] {
            let mut raw = RawLoop::new(n, Layout::OwnWires, kind);
            let name = format!("{}/raw-loop", kind.name());
            group.bench_function(BenchmarkId::new(name, n), |b| {
                b.iter(|| black_box(raw.step()));
            });
            for threads in [Threads::Single, Threads::Parallel] {
                let mut app = plugin_app(n, Layout::OwnWires, threads, kind);
                let name = format!("{}/plugin-{}", kind.name(), threads.name());
                group.bench_function(BenchmarkId::new(name, n), |b| {
                    b.iter(|| app.world_mut().run_schedule(FixedUpdate));
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, scale, overhead);
criterion_main!(benches);
