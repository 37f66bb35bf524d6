//! # wirebead
//!
//! Beads on wires for [Bevy](https://bevy.org): Witkin-style constrained
//! dynamics in `f64`. A bead is kept on its wire `C(x) = 0` by a constraint
//! force `λ∇C`, with λ chosen so that the drift obeys `C̈ = -αC - βĊ`
//! (Baumgarte), or by post-stabilization projection, or by RATTLE, which holds
//! the constraint to solver tolerance and keeps the energy error bounded.
//!
//! ## Add the plugin
//!
//! ```
//! use bevy::math::DVec2;
//! use bevy::prelude::*;
//! use wirebead::prelude::*;
//!
//! fn setup(mut commands: Commands) -> Result {
//!     let wire = commands.spawn(Wire::circle(1.0)?).id();
//!     commands.spawn((Bead::at_rest(1.0, DVec2::new(1.0, 0.0))?, OnWire(wire)));
//!     Ok(())
//! }
//!
//! App::new()
//!     .add_plugins((MinimalPlugins, WireBeadPlugin::default()))
//!     .add_systems(Startup, setup)
//!     .update();
//! ```
//!
//! ## What is in the box
//!
//! | item | what it is |
//! |---|---|
//! | [`WireBeadPlugin`] | the simulation: components, parameters, the step in `FixedUpdate` |
//! | [`WireBeadSystems`] | the step's chained sets: `Prepare → Forces → Step → Writeback` |
//! | [`Wire`], [`Bead`], [`OnWire`] | a wire placed by its `Transform`; a bead on it |
//! | [`SimParams`], [`PendingParams`], [`PendingBead`] | applied and edited parameters; [`Restart`] applies the edits |
//! | `gui::WireBeadGuiPlugin` | the windowed scene (feature `gui`): picking drag, egui panel, plots |
//! | [`KeyboardControlsPlugin`] | Space restarts, P pauses, N steps once: headless-testable |
//! | [`DragTarget`] | the user's drag: a spring `k (target - x)` while present |
//! | [`BeadDiagnostics`], [`Diverged`], [`BeadDiverged`] | `C`, `Ċ`, λ and energy each step; divergence reports |
//! | [`SimClock`], [`ParallelStep`] | steps and seconds since the last restart; when the step splits over threads |
//! | [`ScenePresetPlugin`], [`ScenePreset`] | scenes as RON assets (`*.scene.ron`), hot-reloaded |
//! | [`solver`], [`wire`], [`reference`](mod@reference) | the pure math: eq. 1.9, the integrators, the shapes, the exact pendulum period |
//!
//! ## Feature flags
//!
//! | feature | default | what it adds |
//! |---|---|---|
//! | `gui` | yes | the windowed scene: rendering, picking, the egui panel and plots |
//!
//! With `default-features = false` the crate needs only Bevy's headless core.
#![warn(missing_docs)]

#[cfg(feature = "analysis")]
pub mod analysis;
pub mod components;
pub mod controls;
#[cfg(feature = "gui")]
pub mod gui;
pub mod params;
pub mod plugin;
pub mod preset;
pub mod reference;
pub mod solver;
pub mod systems;
pub mod wire;

pub use components::{
    Bead, BeadDiagnostics, Diverged, DivergenceReason, DragTarget, OnWire, Wire, WireBeads,
    WirePose,
};
pub use controls::KeyboardControlsPlugin;
pub use params::{
    BeadParams, Integrator, ParamError, PendingBead, PendingParams, SimParams, Stabilization,
};
pub use plugin::{BeadDiverged, ParallelStep, Restart, SimClock, WireBeadPlugin, WireBeadSystems};
pub use preset::{ActivePreset, LoadPreset, ScenePreset, ScenePresetPlugin};
pub use wire::{ImplicitCurve, WireShape};

/// The types most apps need: `use wirebead::prelude::*;`.
pub mod prelude {
    pub use crate::{
        Bead, BeadDiagnostics, BeadDiverged, BeadParams, Diverged, DragTarget, ImplicitCurve,
        Integrator, KeyboardControlsPlugin, LoadPreset, OnWire, ParallelStep, PendingBead,
        PendingParams, Restart, ScenePreset, ScenePresetPlugin, SimClock, SimParams, Stabilization,
        Wire, WireBeadPlugin, WireBeadSystems, WireBeads, WireShape,
    };
}

/// The README's code blocks, compiled and run as doc tests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
