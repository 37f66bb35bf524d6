//! The analysis tool's library: headless runs through the plugin, their
//! CSV, the assignment's three studies as figures, and every method against the
//! exact pendulum. The binary `wirebead-analysis` is its command line.

use std::error::Error;

mod bifurcation;
mod comparison;
mod plot;
mod run;
mod scene;
mod studies;

pub use bifurcation::{HoopPoint, HoopSweep, bifurcation, hoop_equilibrium};
pub use comparison::{Comparison, compare, comparison_markdown, pendulum_config};
pub use plot::{FIGURE_SIZE, plot_convergence, plot_series, plot_trajectories};
pub use run::{CSV_HEADER, Row, RunConfig, RunOutput, Summary, simulate, summarize, write_csv};
pub use scene::{
    Measure, Scene, SceneComparison, SceneRow, SceneRun, SceneSpace, compare_scene, load_scene,
    load_scene_file, scene_comparison_markdown, simulate_scene, write_scene_csv,
};
pub use studies::{Study, StudyRun, assignment_setup, assignment_studies, figures};

/// Errors of the analysis: a message naming what failed.
pub type AnalysisResult<T> = Result<T, Box<dyn Error>>;
