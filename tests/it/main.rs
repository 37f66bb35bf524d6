//! The integration tests, one module per behaviour, linked into one test
//! binary. Each runs the plugin headless through `wirebead::headless`;
//! `window` checks the files `.ci/run` makes in a real window and is ignored
//! by a plain `cargo test`.

#[cfg(feature = "avian2d")]
mod avian;
#[cfg(feature = "avian3d")]
mod avian3d;
#[cfg(feature = "avian3d")]
mod avian3d_strikes;
#[cfg(feature = "avian2d")]
mod avian_strikes;
#[cfg(all(feature = "avian2d", feature = "avian3d"))]
mod avian_timeline;
mod bad_input;
mod baumgarte;
mod common;
mod controls;
mod curves;
#[cfg(feature = "debug-render")]
mod debug_render;
mod fuzz;
mod ghost;
mod islands;
mod layers;
mod layout;
mod marble_run;
mod parallel;
mod pendulum;
mod places;
mod precision;
mod presets;
mod readme;
mod restart;
mod scenes;
mod space;
mod space_plugin;
mod timeline;
mod touch;
mod tracks;
#[cfg(feature = "gui")]
mod window;
