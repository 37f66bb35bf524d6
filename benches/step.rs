//! The step's cost per bead: `cargo bench --bench step`.
//!
//! - `scale`: the plugin as a game gets it (Bevy's executor, parallel loops
//!   from `ParallelStep::default()`), N beads each on its own circle or all
//!   on one, N = 1 … 1,000,000, full beads (the default) and lean ones
//!   (`WireBeadPlugin::lean`). Throughput is bead-steps per second.
//! - `overhead`: at each N and for each kind of bead, the same physics
//!   written out by hand as one plain loop over arrays (the floor,
//!   `support::RawLoop`, which uses none of the plugin's or the solver's
//!   code and is checked to move the beads as the plugin does), against the
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

/// Steps the floor and the plugin side by side from the same start and
/// checks they move the beads alike (rounding aside): the floor is the
/// same physics, written apart.
fn floor_agrees_with_the_plugin(kind: Kind) {
    let (n, steps) = (1_000, 120);
    let mut raw = RawLoop::new(n, Layout::OwnWires, kind);
    let mut app = plugin_app(n, Layout::OwnWires, Threads::Single, kind);
    for _ in 0..steps {
        assert_eq!(raw.step(), 0, "the floor diverged");
        app.world_mut().run_schedule(FixedUpdate);
    }
    let world = app.world_mut();
    let plugin: Vec<_> = world
        .query_filtered::<&wirebead::BeadPosition, With<wirebead::Bead>>()
        .iter(world)
        .map(|p| p.0)
        .collect();
    let worst = raw
        .positions()
        .zip(&plugin)
        .map(|(a, b)| (a - *b).length())
        .fold(0.0, f64::max);
    eprintln!(
        "overhead/{}: the floor and the plugin {worst:.1e} m apart after {steps} steps",
        kind.name()
    );
    assert!(
        plugin.len() == n && worst <= 1e-9,
        "the floor is not the plugin's physics"
    );
}

fn overhead(c: &mut Criterion) {
    let mut group = c.benchmark_group("overhead");
    floor_agrees_with_the_plugin(Kind::Full);
    floor_agrees_with_the_plugin(Kind::Lean);
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
