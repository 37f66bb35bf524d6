//! # wirebead
//!
//! Beads on wires for [Bevy](https://bevy.org): Witkin-style constrained
//! dynamics in `f64`. A bead is kept on its wire `C(x) = 0` by a constraint
//! force `λ∇C`, with λ chosen so that the drift obeys `C̈ = -αC - βĊ`
//! (Baumgarte), or by post-stabilization projection, or by RATTLE, which holds
//! the constraint to solver tolerance and keeps the energy error bounded.
//! The equations, numbered as the code cites them, are in [`solver`].
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
//! | [`WireBeadPlugin`] | the simulation, a group of small plugins (see [`plugin`]): components, parameters, the step in `FixedUpdate` |
//! | [`WireBeadSystems`] | the sets: `Restart` in `PreUpdate`; `Prepare → Forces → Step → Writeback` in `FixedUpdate` |
//! | [`Wire`], [`Bead`], [`OnWire`] | a wire placed by its `Transform`; a bead on it (or free, on none) |
//! | [`BeadPosition`], [`BeadVelocity`], [`BeadMass`], [`BeadForce`], [`BeadParams`] | a bead's columns: its state, mass, the force for the next step (added through [`BeadForces`]) and the state a restart returns to |
//! | [`Surface`], [`WireContact`], [`ContactChanged`] | one-sided wires a bead leaves and lands on, restitution, friction; each bead's contact and the message when it changes |
//! | [`PrescribedMotion`] | a wire that moves ([`WireMotion`]: oscillates or spins), its motion exact in the constraint force; a wire the game moves is followed |
//! | [`Rod`], [`Pin`], [`Joint`], [`Spring`] | links between beads, each on an entity of its own; [`Constraint`] for a game's own joint |
//! | [`SpaceBead`], [`SpaceWire`], [`Dimension`] | beads in space on surfaces and curves (`BeadPosition<DVec3>`, …), stepped in islands; each system is written once over the [`Dimension`] |
//! | [`Islands`], [`ConstraintDiagnostics`] | the beads links join, solved together (`J W Jᵀ λ = …`); each link's `C`, `Ċ`, λ |
//! | [`SimParams`], [`NextParams`], [`NextBeadParams`], [`NextWireShape`] | applied and edited parameters; [`Restart`] applies the edits |
//! | [`Method`] | an [`Integrator`] with its [`Stabilization`] (RATTLE takes none) |
//! | [`KeyboardControlsPlugin`] | Space restarts, P pauses, N steps once: headless-testable |
//! | [`SpringAnchor`] | a point a spring `k (anchor - x)` pulls a bead toward (the assignment's mouse drag) |
//! | [`GrabPoint`] | the point of an avian body a [`SpringAnchor`] on it pulls (the scene's drag of a body) |
//! | [`BeadDiagnostics`], [`Diverged`], [`BeadDiverged`] | `C`, `Ċ`, λ and energy each step; divergence reports |
//! | [`SimClock`], [`ParallelStep`] | steps and seconds since the last restart; when the step splits over threads |
//! | [`SceneEnergy`] | the whole scene's energy after each step, for a plot that jumps only where energy is taken or given |
//! | [`ScenePresetPlugin`], [`ScenePreset`] | scenes as RON assets (`*.scene.ron`), hot-reloaded |
//! | `debug_render::WireBeadDebugPlugin` | gizmo drawing of wires, beads, links and forces (feature `debug-render`) |
//! | `gui::WireBeadGuiPlugin` | the windowed scene (feature `gui`): picking drag, egui panel, plots |
//!
//! ## The modules, bottom up
//!
//! Each module uses only the ones above it in this list.
//!
//! | module | what it holds |
//! |---|---|
//! | [`geometry`] | [`ImplicitCurve`] (`C`, `∇C`, the Hessian), one file per shape, [`Pose`](geometry::Pose) |
//! | [`reference`](mod@reference) | reference answers for tests (not the simulation): the pendulum's period |
//! | [`solver`] | the pure math: eq. (3), the integrators, RATTLE, projection, the batched lanes |
//! | `dynamics` | the components and resources above (re-exported here) |
//! | [`plugin`] | the plugin group and its plugins, the sets, the systems |
//! | [`controls`], [`preset`] | keyboard controls; scene files |
//! | [`headless`] | the test harness (not the simulation) the tests, benches and tools build on |
//! | `debug_render` | gizmo drawing of the simulation (feature `debug-render`) |
//! | `gui` | the windowed scene |
//!
//! ## Feature flags
//!
//! | feature | default | what it adds |
//! |---|---|---|
//! | `parallel` | yes | Bevy's `multi_threaded`: the step splits over the compute pool |
//! | `debug-render` | no | `debug_render::WireBeadDebugPlugin`: wires, beads, links and forces drawn with gizmos |
//! | `gui` | no | the windowed scene the examples run: rendering, picking, the egui panel and plots |
//!
//! The default build is headless: Bevy's core and nothing that opens a
//! window; with `default-features = false` the step also runs on one
//! thread.
#![warn(missing_docs)]

#[cfg(feature = "avian2d")]
pub mod avian;
#[cfg(feature = "avian3d")]
pub mod avian3d;
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
mod carrier;
pub mod controls;
#[cfg(feature = "debug-render")]
pub mod debug_render;
mod dynamics;
pub mod geometry;
pub mod ghost;
#[cfg(feature = "gui")]
pub mod gui;
pub mod headless;
mod lane;
pub mod plugin;
pub mod preset;
pub mod reference;
pub mod solver;
mod validate;

pub use controls::KeyboardControlsPlugin;
pub use dynamics::{
    Bead, BeadBundle, BeadDiagnostics, BeadDiverged, BeadForce, BeadForces, BeadForcesItem,
    BeadMass, BeadParams, BeadPosition, BeadRadius, BeadSentBack, BeadStruckBody, BeadVelocity,
    BeadsStruck, CatchesBeads, ConstraintDiagnostics, ContactChanged, Contacts, Dimension,
    Diverged, DivergenceReason, GrabPoint, Joint, MAX_TIMESTEP, MIN_TIMESTEP, NextBeadParams,
    NextParams, NextWireShape, OnWire, Pin, PrescribedMotion, RailOrientation, Restitution, Rod,
    SendsBeadsBack, SimParams, SpaceBead, SpaceBeadBundle, SpaceParams, SpaceWire, Spring,
    SpringAnchor, Wire, WireBeads, WireContact, WirePlace, WireRows, pose_of,
};
pub use geometry::{
    Friction, ImplicitCurve, Oscillate, Side, Spin, Surface, WireKind, WireMotion, WireShape,
};
pub use plugin::{
    IslandReport, Islands, ParallelStep, PressedPair, Restart, SceneEnergy, SimClock,
    WireBeadPlugin, WireBeadSystems,
};
pub use preset::{
    ActivePreset, LoadPreset, SceneFile, SceneLink, ScenePreset, ScenePresetPlugin, SpaceScene,
};
pub use solver::{Constraint, Integrator, Method, Stabilization};
pub use validate::ParamError;

/// The old name of [`SpringAnchor`].
#[deprecated(note = "renamed to `SpringAnchor`: a point a spring pulls the bead toward")]
pub type DragTarget = SpringAnchor;
/// The old name of [`NextParams`].
#[deprecated(note = "renamed to `NextParams`: the parameters the next restart applies")]
pub type PendingParams = NextParams;
/// The old name of [`NextBeadParams`].
#[deprecated(note = "renamed to `NextBeadParams`: a bead's parameters for the next restart")]
pub type PendingBead = NextBeadParams;
/// The old name of [`NextWireShape`].
#[deprecated(note = "renamed to `NextWireShape`: a wire's shape for the next restart")]
pub type PendingWire = NextWireShape;

/// The twenty nouns a game uses: `use wirebead::prelude::*;`. Everything
/// else is at the crate root (`wirebead::PrescribedMotion`,
/// `wirebead::Contacts`, `wirebead::BeadsStruck`, `wirebead::Islands`, …).
pub mod prelude {
    pub use crate::{
        Bead, BeadDiagnostics, BeadForces, BeadMass, BeadParams, BeadPosition, BeadRadius,
        BeadVelocity, Diverged, Method, OnWire, Pin, Restart, Rod, SimParams, Spring, Wire,
        WireBeadPlugin, WireBeadSystems, WireShape,
    };
}

/// The README's code blocks, compiled and run as doc tests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
