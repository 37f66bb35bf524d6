//! Demonstrates the interactive scene: the assignment's application in a window.
//!
//! Drag the bead with the mouse (a spring `k (cursor - bead)` pulls it),
//! edit every parameter in the panel and press Space to apply them, watch the
//! drift, energy and λ plots. P pauses, N steps once while paused, B steps
//! back; E writes the run as CSV and S the scene with its edits.
//!
//! ```sh
//! cargo run --release --example bead_on_wire
//! cargo run --release --example bead_on_wire -- --preset scenes/multi_bead.scene.ron
//! # automation: 300 frames, a screenshot and its report, then exit 0
//! cargo run --example bead_on_wire -- --frames 300 --screenshot /tmp/shot.png
//! ```

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::window::WindowResolution;
use clap::Parser;
use wirebead::LoadPreset;
use wirebead::controls::Presentation;
use wirebead::gui::{AutomationPlugin, WireBeadGuiPlugin};
use wirebead::prelude::*;
use wirebead::preset::ExportDir;

/// The interactive bead-on-a-wire scene.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Args {
    /// Scene preset to start with (an asset path under `assets/`).
    #[arg(long, default_value = "scenes/assignment_circle.scene.ron")]
    preset: String,
    /// Exit after this many frames (status 0, or non-zero if anything failed).
    #[arg(long)]
    frames: Option<u32>,
    /// Save a PNG screenshot here near the end of the run (needs --frames),
    /// with a report of what is where beside it (`.ron`).
    #[arg(long, requires = "frames")]
    screenshot: Option<PathBuf>,
    /// Write a report of where the beads are once the scene runs.
    #[arg(long)]
    ready: Option<PathBuf>,
    /// Write a final report on exit.
    #[arg(long)]
    report: Option<PathBuf>,
    /// End the run 20 frames after this file appears, as if its frames
    /// were done (needs --frames, which stays the longest it runs).
    #[arg(long, requires = "frames")]
    finish_when: Option<PathBuf>,
    /// Window width in pixels.
    #[arg(long, default_value_t = 1280)]
    width: u32,
    /// Window height in pixels.
    #[arg(long, default_value_t = 800)]
    height: u32,
    /// Start in presentation mode (F5 turns it on and off): larger text,
    /// the plots beside the scene.
    #[arg(long)]
    present: bool,
    /// Where E (export CSV) and S (save scene) write.
    #[arg(long, default_value = "exports")]
    export_dir: PathBuf,
}

fn main() -> AppExit {
    let args = Args::parse();
    let preset = args.preset.clone();
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(WindowPlugin {
                primary_window: Some(Window {
                    title: "wirebead: a bead on a wire".into(),
                    resolution: WindowResolution::new(args.width, args.height),
                    ..default()
                }),
                ..default()
            })
            .set(AssetPlugin {
                watch_for_changes_override: Some(true),
                ..default()
            }),
    )
    .add_plugins((WireBeadPlugin::default(), WireBeadGuiPlugin))
    .insert_resource(ExportDir(args.export_dir))
    .insert_resource(Presentation(args.present))
    .add_plugins(AutomationPlugin {
        frames: args.frames,
        screenshot: args.screenshot,
        ready: args.ready,
        report: args.report,
        finish_when: args.finish_when,
    })
    .add_systems(Startup, move |mut loads: MessageWriter<LoadPreset>| {
        loads.write(LoadPreset(preset.clone()));
    });
    add_rigid_bodies(&mut app);
    app.run()
}

/// Avian's physics of each dimension the build has (features `avian2d`,
/// `avian3d`), for scenes with rigid bodies; a build with neither runs
/// such scenes with their bodies left out, and says so.
fn add_rigid_bodies(_app: &mut App) {
    #[cfg(feature = "avian2d")]
    _app.add_plugins((
        avian2d::prelude::PhysicsPlugins::default(),
        wirebead::avian::PathJointPlugin,
    ));
    #[cfg(feature = "avian3d")]
    {
        use bevy::app::PluginGroup as _;
        let physics = avian3d::prelude::PhysicsPlugins::default().build();
        // Each avian's interpolation adds the one plugin an app takes once
        // (`bevy_transform_interpolation`'s): avian2d's has added it.
        #[cfg(feature = "avian2d")]
        let physics = physics.disable::<avian3d::prelude::PhysicsInterpolationPlugin>();
        _app.add_plugins((physics, wirebead::avian3d::PathJointPlugin));
    }
}
