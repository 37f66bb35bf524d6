//! The step's cost per bead: `cargo bench --bench step`.
//!
//! - `scale`: the plugin as a game gets it (Bevy's executor, parallel loops
//!   from `ParallelStep::default()`), N beads each on its own circle or all
//!   on one, N = 1 … 1,000,000. Throughput is bead-steps per second.
//! - `overhead`: at each N, the same math as one fused loop over a `Vec` of
//!   plain structs (the floor), against the plugin single-threaded and
//!   parallel.

use std::hint::black_box;
use std::time::Duration;

use bevy::prelude::*;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

mod support;
use support::{Layout, RawLoop, Threads, plugin_app};

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
        for layout in [Layout::OwnWires, Layout::SharedWire] {
            let mut app = plugin_app(n, layout, Threads::Parallel);
            group.bench_function(BenchmarkId::new(layout.name(), n), |b| {
                b.iter(|| app.world_mut().run_schedule(FixedUpdate));
            });
        }
    }
    group.finish();
}

fn overhead(c: &mut Criterion) {
    let mut group = c.benchmark_group("overhead");
    for n in SIZES {
        configure(&mut group, n);
        let mut raw = RawLoop::new(n, Layout::OwnWires);
        group.bench_function(BenchmarkId::new("raw-loop", n), |b| {
            b.iter(|| black_box(raw.step()));
        });
        for (name, threads) in [
            ("plugin-single", Threads::Single),
            ("plugin-parallel", Threads::Parallel),
        ] {
            let mut app = plugin_app(n, Layout::OwnWires, threads);
            group.bench_function(BenchmarkId::new(name, n), |b| {
                b.iter(|| app.world_mut().run_schedule(FixedUpdate));
            });
        }
    }
    group.finish();
}

criterion_group!(benches, scale, overhead);
criterion_main!(benches);
