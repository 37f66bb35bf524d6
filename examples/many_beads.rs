//! N beads stepped through the plugin, for profiling and for the memory
//! figure in BENCHMARKS.md:
//!
//! ```text
//! cargo run --release --example many_beads -- --beads 1000000 --steps 20
//! cargo run --release --example many_beads -- --memory --kind lean
//! ```
//!
//! Prints the time per bead-step and the process's peak resident memory;
//! `--memory` runs itself with no beads and with N and prints the bytes per
//! bead (peak RSS difference divided by N).

use std::process::{Command, ExitCode};
use std::time::Instant;

use bevy::prelude::*;
use clap::Parser;

#[path = "../benches/support/mod.rs"]
mod support;
use support::{Kind, Layout, Threads, plugin_app};
use wirebead::prelude::*;

#[derive(Parser, Debug)]
#[command(about = "Step N beads through the plugin and report time and memory")]
struct Args {
    /// How many beads.
    #[arg(long, default_value_t = 1_000_000)]
    beads: usize,
    /// How many steps.
    #[arg(long, default_value_t = 20)]
    steps: usize,
    /// Each bead on its own circle, or all on one.
    #[arg(long, value_enum, default_value_t = Layout::SharedWire)]
    layout: Layout,
    /// Single-threaded or parallel loops.
    #[arg(long, value_enum, default_value_t = Threads::Parallel)]
    threads: Threads,
    /// Full beads (with Transform and diagnostics) or lean ones.
    #[arg(long, value_enum, default_value_t = Kind::Full)]
    kind: Kind,
    /// Measure bytes per bead: run with 0 and with N beads and compare peak RSS.
    #[arg(long)]
    memory: bool,
}

/// Peak resident set size of this process, in bytes (Linux).
fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

fn child_peak(args: &Args, beads: usize) -> Result<u64, String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let out = Command::new(exe)
        .args([
            "--beads",
            &beads.to_string(),
            "--steps",
            &args.steps.to_string(),
        ])
        .args(["--layout", args.layout.name()])
        .args(["--threads", args.threads.name()])
        .args(["--kind", args.kind.name()])
        .output()
        .map_err(|e| e.to_string())?;
    let text = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(format!("run with {beads} beads failed: {text}"));
    }
    text.lines()
        .find_map(|l| l.strip_prefix("peak_rss_bytes="))
        .and_then(|v| v.trim().parse().ok())
        .ok_or_else(|| format!("no peak_rss_bytes in the output of the run with {beads} beads"))
}

fn main() -> ExitCode {
    let args = Args::parse();
    if args.memory {
        return match (child_peak(&args, 0), child_peak(&args, args.beads)) {
            (Ok(empty), Ok(full)) => {
                let per_bead = (full.saturating_sub(empty)) as f64 / args.beads.max(1) as f64;
                println!(
                    "layout={} kind={} beads={} empty_app_peak_rss={empty} peak_rss={full} bytes_per_bead={per_bead:.1}",
                    args.layout.name(),
                    args.kind.name(),
                    args.beads
                );
                ExitCode::SUCCESS
            }
            (Err(e), _) | (_, Err(e)) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        };
    }
    let mut app = plugin_app(args.beads, args.layout, args.threads, args.kind);
    let start = Instant::now();
    for _ in 0..args.steps {
        app.world_mut().run_schedule(FixedUpdate);
    }
    let seconds = start.elapsed().as_secs_f64();
    let bead_steps = (args.beads * args.steps).max(1) as f64;
    println!(
        "beads={} steps={} ns_per_bead_step={:.2} bead_steps_per_second={:.3e}",
        args.beads,
        args.steps,
        seconds * 1e9 / bead_steps,
        bead_steps / seconds
    );
    println!(
        "component_bytes: BeadPosition={} BeadVelocity={} BeadMass={} BeadForce={} BeadParams={} BeadDiagnostics={} OnWire={} Transform={} GlobalTransform={}",
        size_of::<BeadPosition>(),
        size_of::<BeadVelocity>(),
        size_of::<BeadMass>(),
        size_of::<wirebead::BeadForce>(),
        size_of::<BeadParams>(),
        size_of::<BeadDiagnostics>(),
        size_of::<OnWire>(),
        size_of::<Transform>(),
        size_of::<GlobalTransform>()
    );
    match peak_rss() {
        Some(bytes) => println!("peak_rss_bytes={bytes}"),
        None => println!("peak_rss_bytes=unknown (needs /proc/self/status)"),
    }
    ExitCode::SUCCESS
}
