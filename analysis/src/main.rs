//! `wirebead-analysis`: the assignment's figures and every method against the
//! exact pendulum, headless, through the same plugin.
//!
//! ```sh
//! cargo run --release -p wirebead-analysis -- simulate --alpha 0 --out run.csv
//! cargo run --release -p wirebead-analysis -- simulate --scene assets/scenes/rope.scene.ron --out rope.csv
//! cargo run --release -p wirebead-analysis -- figures --out-dir docs/figures
//! cargo run --release -p wirebead-analysis -- compare --out-dir docs/compare
//! cargo run --release -p wirebead-analysis -- compare --scene assets/scenes/double_pendulum.scene.ron --out-dir docs/compare
//! cargo run --release -p wirebead-analysis -- bifurcation --out-dir docs/bifurcation
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

use bevy::math::DVec2;
use clap::{Args, Parser, Subcommand};
use wirebead::prelude::*;
use wirebead::{Integrator, SceneFile, Stabilization, WireKind};
use wirebead_analysis::{self as analysis, RunConfig, Scene};

/// Headless runs, the assignment's figures, and the method comparison.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run one simulation and write a CSV (`t,x,y,vx,vy,c,c_dot,lambda,energy`);
    /// with `--scene`, any scene file (`t`, then
    /// `<bead>.x,<bead>.y,<bead>.vx,<bead>.vy,<bead>.on` for each bead, `on` 1
    /// while held on its wire, then
    /// `<body>.x,<body>.y,<body>.angle,<body>.vx,<body>.vy,<body>.w` for each
    /// dynamic or kinematic body, then `energy,max_abs_c`; in space
    /// `<bead>.x,<bead>.y,<bead>.z,<bead>.vx,<bead>.vy,<bead>.vz,<bead>.on`
    /// and `<body>.x,…,<body>.qx,<body>.qy,<body>.qz,<body>.qw,<body>.vx,…,<body>.wz`).
    /// A scene with bodies needs the tool built with `--features avian`.
    Simulate(SimulateArgs),
    /// Reproduce the assignment's three studies: trajectory, drift and energy PNGs,
    /// the CSV behind each, and summary.md.
    Figures {
        /// Where to write everything.
        #[arg(long)]
        out_dir: PathBuf,
        /// Simulated seconds per run.
        #[arg(long, default_value_t = 10.0)]
        duration: f64,
    },
    /// Every integrator × stabilization on the pendulum against the exact
    /// period: a markdown table and a log–log error-versus-dt plot. With
    /// `--scene`, every method on any scene file: constraint error, energy
    /// error and cost per step, as `<scene>.md`.
    Compare {
        /// Where to write everything.
        #[arg(long)]
        out_dir: PathBuf,
        /// A scene file to compare the methods on instead of the pendulum.
        #[arg(long, conflicts_with_all = ["theta0", "radius", "gravity"])]
        scene: Option<PathBuf>,
        /// Release angle from the bottom, degrees.
        #[arg(long, default_value_t = 135.0)]
        theta0: f64,
        /// Circle radius.
        #[arg(long, default_value_t = 1.0)]
        radius: f64,
        /// Gravity magnitude.
        #[arg(long, default_value_t = 9.81)]
        gravity: f64,
        /// Simulated seconds per run.
        #[arg(long, default_value_t = 10.0)]
        duration: f64,
        /// Timesteps, comma-separated; fractions like 1/60 are accepted.
        #[arg(long, value_delimiter = ',', value_parser = parse_seconds,
              default_value = "1/30,1/60,1/120,1/240")]
        dt: Vec<f64>,
    },
    /// The rotating hoop's bifurcation: sweep the hoop's spin ω, run a bead
    /// from just off the bottom with light damping, and plot the angle it
    /// settles at against the theory (θ* = 0 below √(g/r), cos θ* =
    /// g/(ω² r) above), as `bifurcation.png` with `bifurcation.csv`.
    Bifurcation {
        /// Where to write everything.
        #[arg(long)]
        out_dir: PathBuf,
        /// Hoop radius (m).
        #[arg(long, default_value_t = 1.0)]
        radius: f64,
        /// Gravity magnitude (m/s²).
        #[arg(long, default_value_t = 9.81)]
        gravity: f64,
        /// The fastest spin (rad/s); the sweep runs from it / count up.
        #[arg(long, default_value_t = 8.0)]
        omega_max: f64,
        /// How many spins.
        #[arg(long, default_value_t = 32)]
        count: u32,
        /// Damping along the hoop (N·s/m on a bead of 1 kg).
        #[arg(long, default_value_t = 1.0)]
        damping: f64,
        /// Simulated seconds per spin.
        #[arg(long, default_value_t = 30.0)]
        duration: f64,
    },
}

#[derive(Args, Debug)]
struct SimulateArgs {
    /// A scene file (`*.scene.ron`) to run instead of one bead on one wire;
    /// its own parameters apply unless --dt, --integrator, --stabilization,
    /// --alpha or --beta say otherwise.
    #[arg(long, conflicts_with_all = ["wire", "radius", "mass", "gravity", "x0", "y0", "vx0", "vy0", "k"])]
    scene: Option<PathBuf>,
    /// Wire shape.
    #[arg(long, default_value = "circle", value_parser = parse_wire)]
    wire: WireKind,
    /// Wire size (a circle's radius).
    #[arg(long, default_value_t = 1.0)]
    radius: f64,
    /// Bead mass.
    #[arg(long, default_value_t = 1.0)]
    mass: f64,
    /// Gravity's y component.
    #[arg(long, default_value_t = -9.81, allow_negative_numbers = true)]
    gravity: f64,
    /// Timestep in seconds (fractions like 1/60 are accepted); default 1/60,
    /// or the scene's.
    #[arg(long, value_parser = parse_seconds)]
    dt: Option<f64>,
    /// Simulated seconds.
    #[arg(long, default_value_t = 10.0)]
    duration: f64,
    /// Initial x (default: the bottom of the wire).
    #[arg(long, allow_negative_numbers = true)]
    x0: Option<f64>,
    /// Initial y (default: the bottom of the wire).
    #[arg(long, allow_negative_numbers = true)]
    y0: Option<f64>,
    /// Initial velocity x.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    vx0: f64,
    /// Initial velocity y.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    vy0: f64,
    /// Baumgarte α (default: the plugin's).
    #[arg(long, allow_negative_numbers = true)]
    alpha: Option<f64>,
    /// Baumgarte β (default: the plugin's).
    #[arg(long, allow_negative_numbers = true)]
    beta: Option<f64>,
    /// Drag spring constant k (default: the plugin's; no drag runs headless).
    #[arg(long, allow_negative_numbers = true)]
    k: Option<f64>,
    /// explicit-euler, semi-implicit-euler (the default), rk4 or rattle; or
    /// the scene's.
    #[arg(long)]
    integrator: Option<Integrator>,
    /// baumgarte (the default), projection or none; rattle takes none.
    #[arg(long)]
    stabilization: Option<Stabilization>,
    /// The CSV to write.
    #[arg(long)]
    out: PathBuf,
}

fn parse_seconds(s: &str) -> Result<f64, String> {
    let value = match s.split_once('/') {
        Some((n, d)) => {
            let n: f64 = n.trim().parse().map_err(|e| format!("{s:?}: {e}"))?;
            let d: f64 = d.trim().parse().map_err(|e| format!("{s:?}: {e}"))?;
            n / d
        }
        None => s.trim().parse().map_err(|e| format!("{s:?}: {e}"))?,
    };
    Ok(value)
}

fn parse_wire(s: &str) -> Result<WireKind, String> {
    s.parse().map_err(|e: wirebead::ParamError| e.to_string())
}

/// Exit code 3, with a line saying why, where the run diverged.
fn exit_code(diverged: Option<(f64, String)>) -> ExitCode {
    match diverged {
        Some((t, why)) => {
            eprintln!("error: the run diverged at t = {t:.4} s: {why}");
            ExitCode::from(3)
        }
        None => ExitCode::SUCCESS,
    }
}

fn simulate_scene(
    args: SimulateArgs,
    path: &std::path::Path,
) -> Result<ExitCode, Box<dyn std::error::Error>> {
    match analysis::load_scene_file(path)? {
        SceneFile::Plane(scene) => simulate_scene_in(args, &scene),
        SceneFile::Space(scene) => simulate_scene_in(args, &scene),
    }
}

fn simulate_scene_in<S: Scene>(
    args: SimulateArgs,
    preset: &S,
) -> Result<ExitCode, Box<dyn std::error::Error>> {
    let own = preset.params().clone();
    let method = match (args.integrator, args.stabilization) {
        (None, None) => own.method,
        (integrator, stabilization) => Method::new(
            integrator.unwrap_or(own.method.integrator()),
            stabilization
                .or(own.method.stabilization())
                .filter(|_| integrator != Some(Integrator::Rattle) || args.stabilization.is_some()),
        )?,
    };
    let params = SimParams {
        timestep: args.dt.unwrap_or(own.timestep),
        alpha: args.alpha.unwrap_or(own.alpha),
        beta: args.beta.unwrap_or(own.beta),
        method,
        ..own
    };
    params.validate()?;
    let run = analysis::simulate_scene(preset, params, args.duration)?;
    analysis::write_scene_csv(&args.out, &run)?;
    eprintln!("wrote {} rows to {}", run.rows.len(), args.out.display());
    Ok(exit_code(run.diverged))
}

fn simulate(args: SimulateArgs) -> Result<ExitCode, Box<dyn std::error::Error>> {
    if let Some(path) = args.scene.clone() {
        return simulate_scene(args, &path);
    }
    let defaults = SimParams::default();
    let shape = args.wire.shape(args.radius);
    let bottom = shape.bottom();
    let config = RunConfig {
        wire: shape,
        params: SimParams {
            timestep: args.dt.unwrap_or(defaults.timestep),
            gravity: DVec2::new(0.0, args.gravity),
            alpha: args.alpha.unwrap_or(defaults.alpha),
            beta: args.beta.unwrap_or(defaults.beta),
            drag_stiffness: args.k.unwrap_or(defaults.drag_stiffness),
            method: Method::new(args.integrator.unwrap_or_default(), args.stabilization)?,
            ..defaults
        },
        bead: BeadParams {
            mass: args.mass,
            initial_position: DVec2::new(args.x0.unwrap_or(bottom.x), args.y0.unwrap_or(bottom.y)),
            initial_velocity: DVec2::new(args.vx0, args.vy0),
        },
        duration: args.duration,
    };
    let out = analysis::simulate(&config)?;
    analysis::write_csv(&args.out, &out.rows)?;
    eprintln!("wrote {} rows to {}", out.rows.len(), args.out.display());
    Ok(exit_code(out.diverged))
}

fn run(cli: Cli) -> Result<ExitCode, Box<dyn std::error::Error>> {
    match cli.command {
        Command::Simulate(args) => simulate(args),
        Command::Figures { out_dir, duration } => {
            let written = analysis::figures(&out_dir, duration)?;
            eprintln!("wrote {} files to {}", written.len(), out_dir.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Compare {
            out_dir,
            scene: Some(path),
            duration,
            dt,
            ..
        } => {
            std::fs::create_dir_all(&out_dir)?;
            let md = match analysis::load_scene_file(&path)? {
                SceneFile::Plane(scene) => compare_scene_in(&scene, duration, &dt)?,
                SceneFile::Space(scene) => compare_scene_in(&scene, duration, &dt)?,
            };
            let stem = path
                .file_name()
                .and_then(|n| n.to_str())
                .map_or("scene", |n| n.trim_end_matches(".scene.ron"));
            std::fs::write(out_dir.join(format!("{stem}.md")), &md)?;
            print!("{md}");
            Ok(ExitCode::SUCCESS)
        }
        Command::Bifurcation {
            out_dir,
            radius,
            gravity,
            omega_max,
            count,
            damping,
            duration,
        } => {
            if count == 0 || !(omega_max.is_finite() && omega_max > 0.0) {
                return Err(
                    "bifurcation: --count must be at least 1 and --omega-max positive".into(),
                );
            }
            let sweep = analysis::HoopSweep {
                radius,
                gravity,
                omegas: (1..=count)
                    .map(|i| omega_max * f64::from(i) / f64::from(count))
                    .collect(),
                damping,
                duration,
                ..analysis::HoopSweep::default()
            };
            let written = analysis::bifurcation(&out_dir, &sweep)?;
            eprintln!("wrote {} files to {}", written.len(), out_dir.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Compare {
            out_dir,
            scene: None,
            theta0,
            radius,
            gravity,
            duration,
            dt,
        } => {
            std::fs::create_dir_all(&out_dir)?;
            let table = analysis::compare(radius, gravity, theta0, duration, &dt)?;
            let md = analysis::comparison_markdown(&table, radius, gravity, theta0, duration);
            std::fs::write(out_dir.join("compare.md"), &md)?;
            analysis::plot_convergence(&out_dir.join("convergence.png"), &table)?;
            print!("{md}");
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// Every method on a scene, as markdown.
fn compare_scene_in<S: Scene>(
    preset: &S,
    duration: f64,
    dt: &[f64],
) -> Result<String, Box<dyn std::error::Error>> {
    let table = analysis::compare_scene(preset, duration, dt)?;
    Ok(analysis::scene_comparison_markdown(
        &table, preset, duration,
    ))
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
