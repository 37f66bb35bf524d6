//! The assignment's three studies (α, β, the timestep): their runs, and
//! their CSVs, figures and summary written to a folder.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use bevy::math::DVec2;
use wirebead::geometry::Circle;
use wirebead::{BeadParams, SimParams, WireShape};

use crate::AnalysisResult;
use crate::plot::{plot_series, plot_trajectories};
use crate::run::{Row, RunConfig, progress, simulate, summarize, write_csv};

/// One run of a study.
#[derive(Clone, Debug)]
pub struct StudyRun {
    /// A short label (`"α = 100"`).
    pub label: String,
    /// The file stem of its CSV (`"alpha_100"`).
    pub stem: String,
    /// The configuration.
    pub config: RunConfig,
}

/// One of the assignment's studies: runs that differ in one parameter.
#[derive(Clone, Debug)]
pub struct Study {
    /// The file stem of its figures (`"alpha"`).
    pub name: String,
    /// The figure title.
    pub title: String,
    /// The runs.
    pub runs: Vec<StudyRun>,
}

/// The assignment's setup: a vertical unit circle, the bead starting at the bottom
/// with a sideways push, semi-implicit Euler with Baumgarte.
pub fn assignment_setup(duration: f64) -> RunConfig {
    RunConfig {
        wire: WireShape::Circle(Circle { radius: 1.0 }),
        params: SimParams::default(),
        bead: BeadParams {
            mass: 1.0,
            initial_position: DVec2::new(0.0, -1.0),
            initial_velocity: DVec2::new(4.0, 0.0),
        },
        duration,
    }
}

/// The assignment's three studies (its Figures 1.1–1.3): α with β fixed, β with α
/// fixed, and the timestep up to the assignment's unstable 0.05 s.
pub fn assignment_studies(duration: f64) -> Vec<Study> {
    let base = assignment_setup(duration);
    let with = |label: String, stem: String, edit: &dyn Fn(&mut SimParams)| {
        let mut config = base.clone();
        edit(&mut config.params);
        StudyRun {
            label,
            stem,
            config,
        }
    };
    vec![
        Study {
            name: "alpha".into(),
            title: "Figure 1.1: spring constant α (β = 10)".into(),
            runs: [0.0, 100.0, 1000.0]
                .map(|a| {
                    with(format!("α = {a}"), format!("alpha_{a}"), &|p| {
                        p.alpha = a;
                        p.beta = 10.0;
                    })
                })
                .into(),
        },
        Study {
            name: "beta".into(),
            title: "Figure 1.2: damping constant β (α = 100)".into(),
            runs: [(2.0, "small"), (20.0, "matched"), (100.0, "too large")]
                .map(|(b, what)| {
                    with(format!("β = {b} ({what})"), format!("beta_{b}"), &|p| {
                        p.alpha = 100.0;
                        p.beta = b;
                    })
                })
                .into(),
        },
        Study {
            name: "timestep".into(),
            title: "Figure 1.3: timestep (α = 100, β = 20)".into(),
            runs: [1.0 / 120.0, 1.0 / 60.0, 0.05]
                .map(|dt| {
                    with(format!("dt = {dt:.4} s"), format!("dt_{dt:.4}"), &|p| {
                        p.timestep = dt
                    })
                })
                .into(),
        },
    ]
}

/// Runs the assignment's studies and writes, into `out_dir`, a CSV per run, a
/// trajectory, drift and energy PNG per study, and `summary.md`. Files are
/// written as each run finishes, so a failure leaves the earlier results.
pub fn figures(out_dir: &Path, duration: f64) -> AnalysisResult<Vec<PathBuf>> {
    std::fs::create_dir_all(out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let studies = assignment_studies(duration);
    let total = studies.iter().map(|s| s.runs.len()).sum::<usize>() as u64;
    let bar = progress(total, "figures");
    let mut written = Vec::new();
    let mut summary = String::from(
        "# The assignment's studies\n\nA vertical unit circle, the bead starting at the bottom at 4 m/s, semi-implicit Euler with Baumgarte, |g| = 9.81.\n\n| study | run | max abs(C)/r | final energy error (m·g·r) | diverged |\n|---|---|---|---|---|\n",
    );
    for study in &studies {
        let mut outputs = Vec::new();
        for run in &study.runs {
            bar.set_message(format!("{}: {}", study.name, run.label));
            let out = simulate(&run.config).map_err(|e| format!("run {} failed: {e}", run.stem))?;
            let csv_path = out_dir.join(format!("{}.csv", run.stem));
            write_csv(&csv_path, &out.rows)?;
            written.push(csv_path);
            let s = summarize(
                &out.rows,
                1.0,
                run.config.bead.mass,
                run.config.params.gravity.y,
            );
            let diverged = out.diverged.as_ref().map_or("no".to_owned(), |(t, why)| {
                format!("at t = {t:.2} s: {why}")
            });
            let _ = writeln!(
                summary,
                "| {} | {} | {:.3e} | {:+.3e} | {} |",
                study.name, run.label, s.max_drift, s.final_energy_error, diverged
            );
            outputs.push((run.label.clone(), out));
            bar.inc(1);
        }
        let paths: Vec<(String, &[Row])> = outputs
            .iter()
            .map(|(l, o)| (l.clone(), o.rows.as_slice()))
            .collect();
        let png = out_dir.join(format!("{}_trajectory.png", study.name));
        plot_trajectories(&png, &study.title, &study.runs[0].config.wire, &paths)?;
        written.push(png);
        let drift: Vec<(String, Vec<(f64, f64)>)> = outputs
            .iter()
            .map(|(l, o)| (l.clone(), o.rows.iter().map(|r| (r.t, r.c.abs())).collect()))
            .collect();
        let png = out_dir.join(format!("{}_drift.png", study.name));
        plot_series(
            &png,
            &format!("{}: drift", study.title),
            "|C| (m)",
            &drift,
            true,
        )?;
        written.push(png);
        let energy: Vec<(String, Vec<(f64, f64)>)> = outputs
            .iter()
            .map(|(l, o)| (l.clone(), o.rows.iter().map(|r| (r.t, r.energy)).collect()))
            .collect();
        let png = out_dir.join(format!("{}_energy.png", study.name));
        plot_series(
            &png,
            &format!("{}: energy", study.title),
            "E (J)",
            &energy,
            false,
        )?;
        written.push(png);
        std::fs::write(out_dir.join("summary.md"), &summary)?;
    }
    bar.finish_and_clear();
    written.push(out_dir.join("summary.md"));
    Ok(written)
}
