//! Scene presets: RON files that set the wires, the beads, the links
//! between beads and the parameters, loaded as Bevy assets
//! (`*.scene.ron`).
//!
//! ```ron
//! (
//!     name: "Pendulum on a cart",
//!     params: (integrator: Rattle),
//!     wires: [(shape: Line(()), beads: [(name: "cart", mass: 2.0, initial_position: (0.0, 0.0))])],
//!     beads: [(name: "bob", mass: 1.0, initial_position: (0.0, -1.0))],
//!     constraints: [Rod((a: "cart", b: "bob", length: 1.0))],
//!     springs: [],
//! )
//! ```
//!
//! `beads` outside `wires` are free (on no wire). Links name beads by
//! their `name`; a bead without one is `bead0`, `bead1`, … by its place in
//! the file (the wires' beads in order, then the free ones). A pin is
//! `Pin((bead: "top", at: (0.0, 2.0)))`, a spring
//! `(a: "p", b: "q", rest_length: 1.0, stiffness: 50.0, damping: 0.1)`.
//! `beads`, `constraints` and `springs` may be left out.
//!
//! [`ScenePresetPlugin`] loads the file named by [`ActivePreset`], applies it
//! when it loads and again whenever the file changes (with Bevy's
//! `file_watcher`), and on a malformed file keeps the running scene and
//! records the error in [`ActivePreset::error`].

mod error;
mod format;
mod plugin;
mod spawn;
#[cfg(test)]
mod tests;

pub use error::PresetError;
pub use format::{
    BeadPreset, ConstraintPreset, PinPreset, RodPreset, SceneLink, ScenePreset, SpringPreset,
    WirePreset,
};
pub use plugin::{
    ActivePreset, LoadPreset, ScenePresetLoader, ScenePresetPlugin, apply_loaded_preset,
    load_requested_preset, report_preset_errors,
};
pub use spawn::FromPreset;
