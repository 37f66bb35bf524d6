//! A wire of your own shape: implement `ImplicitCurve` (C, ∇C and the
//! Hessian) and put a bead on it. Here a rounded square, the superellipse
//! `x⁴ + y⁴ = a⁴`, tilted by its entity's `Transform`.
//!
//! ```text
//! cargo run --release --example custom_wire
//! ```

use std::path::PathBuf;

use bevy::math::{DMat2, DVec2};
use bevy::prelude::*;
use clap::Parser;
use wirebead::ImplicitCurve;
use wirebead::gui::{AutomationPlugin, WireBeadGuiPlugin};
use wirebead::prelude::*;

/// `C = (x⁴ + y⁴ - a⁴) / (4a³)`: scaled so `|∇C| = 1` where the curve
/// crosses the axes, so α and β mean what they mean on a circle.
struct RoundedSquare {
    a: f64,
}

impl ImplicitCurve for RoundedSquare {
    fn value(&self, p: DVec2) -> f64 {
        (p.x.powi(4) + p.y.powi(4) - self.a.powi(4)) / (4.0 * self.a.powi(3))
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        DVec2::new(p.x.powi(3), p.y.powi(3)) / self.a.powi(3)
    }
    fn hessian(&self, p: DVec2) -> DMat2 {
        DMat2::from_diagonal(DVec2::new(3.0 * p.x * p.x, 3.0 * p.y * p.y) / self.a.powi(3))
    }
    fn scale(&self) -> f64 {
        self.a
    }
}

#[derive(Parser, Debug)]
#[command(about = "A bead on a wire of a custom shape")]
struct Args {
    /// Run this many frames, then exit.
    #[arg(long)]
    frames: Option<u32>,
    /// Save a screenshot here before exiting.
    #[arg(long, requires = "frames")]
    screenshot: Option<PathBuf>,
}

fn main() -> AppExit {
    let args = Args::parse();
    let params = SimParams {
        method: Method::Rattle,
        ..SimParams::default()
    };
    App::new()
        .add_plugins(DefaultPlugins)
        .add_plugins((
            WireBeadPlugin::new(params).expect("valid parameters"),
            WireBeadGuiPlugin,
        ))
        .add_plugins(AutomationPlugin {
            frames: args.frames,
            screenshot: args.screenshot,
            ..default()
        })
        .add_systems(Startup, spawn)
        .run()
}

fn spawn(mut commands: Commands) {
    let a = 1.5;
    let wire = commands
        .spawn((
            Wire::custom(RoundedSquare { a }),
            Transform::from_rotation(Quat::from_rotation_z(0.3)),
        ))
        .id();
    // Start on the wire's local x axis (rotated with it), moving along it.
    let (sin, cos) = 0.3f64.sin_cos();
    let start = DVec2::new(a * cos, a * sin);
    let bead = Bead::new(BeadParams {
        mass: 1.0,
        initial_position: start,
        initial_velocity: DVec2::new(-sin, cos) * 3.0,
    })
    .expect("valid bead");
    commands.spawn((bead, OnWire(wire)));
}
