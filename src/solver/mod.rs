//! The constraint solve and the integrators, as pure functions over plain
//! values: nothing here knows about the ECS. One file (or folder, with a
//! table of its own) per piece:
//!
//! | file | what it holds |
//! |---|---|
//! | `method` | [`Integrator`], [`Stabilization`] and the [`Method`] that pairs them |
//! | `settings` | [`StepSettings`]: what is the same for every bead in a step |
//! | `state` | [`BeadState`], [`LinearForce`] |
//! | `solve` | λ of eq. (3) in closed form |
//! | `friction` | friction and damping along a wire, eq. (17) |
//! | `wire_normal` | when the wire's normal is usable, and a vector split along and across the wire |
//! | `euler`, `rk4`, `rattle`, `projection`, `restore` | the integrators and post-stabilization, eqs. (6)–(11) |
//! | `newton` | Newton's method on `C` and its stopping test, for RATTLE and projection |
//! | `step` | [`step`]: a whole step of one bead, with the divergence check |
//! | `contact/` (`wire`, `flight`, `locate`) | [`step_surface`]: one-sided wires, landings and friction, eqs. (16)–(17): on the wire, in flight, where an event falls |
//! | `impact` | `resolve_impacts`: strikes between beads that touch, eq. (18), one pair at a time |
//! | `touch/` (`group`) | `settle_touches`: where within a step beads meet (broad phase, regula falsi), the step cut there |
//! | `lanes/` (`circle`) | the batched step: eight beads on circles at once, bit for bit [`step`](fn@step), many such batches in one call; the solves on each lane's circle (crate-private) |
//! | `path/` (`plane`, `space`, `substep`) | a rigid body's anchor held on a wire, and its orientation turned with it, in the plane and in space: the corrections of an engine's substep (a path joint), and the [`PathMotor`] that drives it |
//! | `coupled/` (`island/`, `normal/`, …) | [`Island`]: beads joined by rods, pins, wires and springs, eqs. (12)–(14) |
//!
//! The equations below are numbered as the code and the tests cite them.
//!
#![doc = include_str!("../../docs/method.md")]

mod contact;
mod coupled;
mod euler;
mod friction;
mod impact;
pub(crate) use impact::Strike;
mod lanes;
mod method;
mod newton;
#[cfg_attr(not(any(feature = "avian2d", feature = "avian3d")), allow(dead_code))]
pub(crate) mod path;
mod projection;
mod rattle;
mod restore;
mod rk4;
mod settings;
mod solve;
mod state;
mod step;
mod touch;
mod wire_normal;

pub use contact::{Contact, ContactEvent, SurfaceStep, free_step, step_surface};
pub use coupled::{
    Constraint, Island, IslandError, IslandMark, IslandRow, IslandWork, RowKind, RowReport,
    SpringLink, islands,
};
pub(crate) use coupled::{pair_gap, pair_speeds};
pub use euler::{explicit_euler, semi_implicit_euler};
pub(crate) use lanes::{LANES, RoundLanes, RoundSteps, step_on_round_batches};
pub use method::{Integrator, Method, Stabilization};
pub use path::PathMotor;
pub use projection::project;
pub use rattle::rattle;
pub use rk4::rk4;
pub use settings::{Gains, StepSettings};
pub use solve::{SolveError, Solved, lambda, solve};
pub use state::{Advance, BeadState, LinearForce};
pub use step::{StepOutput, constraint_state, constraint_state_on, step, step_on};
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
pub(crate) use touch::{BodyPoint, Nearest};
pub(crate) use touch::{
    BodyPush, MeetsObstacles, Obstacle, ObstaclePair, ObstacleStrike, meet_obstacles,
};
pub(crate) use touch::{
    Pressed, StepSpan, StruckPair, TOUCHING, TouchBead, TouchBody, TouchError, may_touch,
    may_touch_near, overlapping, rests_in_touch, settle_touches, swept, wire_response,
};

/// What the solver's unit tests share.
#[cfg(test)]
pub(crate) mod test_support {
    use bevy::math::DVec2;

    use super::{Method, StepSettings};

    /// Earth's gravity, down.
    pub(crate) const G: DVec2 = DVec2::new(0.0, -9.81);

    /// The default gains (α = 100, β = 20) and a divergence bound of one
    /// wire scale, with `method` and step `dt`.
    pub(crate) fn settings(method: Method, dt: f64) -> StepSettings {
        StepSettings {
            dt,
            method,
            alpha: 100.0,
            beta: 20.0,
            drift_bound: 1.0,
        }
    }
}
