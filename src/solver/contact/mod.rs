//! One-sided wires, landings and friction for one bead, eqs. (16)–(17): a step
//! that may leave the wire, fly, land (bouncing with a restitution), stop
//! and stick.
//!
//! Each change happens at the instant it happens, not at the end of a step:
//! the step is cut where a bead's `λ` changes sign (it leaves), where its
//! flight crosses the wire (it lands) or where friction brings its sliding
//! to rest (it stops), by regula falsi on the length of a sub-step, and
//! the rest of the step goes on in the new state.
//!
//! | file | what it holds |
//! |---|---|
//! | `mod` | [`Contact`], [`ContactEvent`], [`SurfaceStep`], [`step_surface`], and what every part of a cut step shares |
//! | `wire` | a part on the wire: sliding, leaving where λ changes sign or past an end, stopping and sticking by friction |
//! | `flight` | a part in flight, landing (or bouncing) where it crosses the wire, and [`free_step`] |
//! | `locate` | where within a part an event falls: regula falsi on the part's length |

use bevy::math::DVec2;

use super::settings::{Gains, StepSettings};
use super::solve::{SolveError, normal_length_squared, solve_on};
use super::state::{BeadState, LinearForce};
use super::step::{StepOutput, step_on};
use super::wire_normal::across;
use crate::geometry::{Coordinates, Rough, Surface, Track};

mod flight;
mod locate;
#[cfg(test)]
mod tests;
mod wire;

pub use flight::free_step;
pub(crate) use locate::{bracket_root, locate, locate_between};

/// Whether a bead is on its wire or flying off it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Contact {
    /// Held on its wire.
    #[default]
    OnWire,
    /// Left a one-sided wire and flying under its forces alone.
    InFlight,
}

/// A change of a bead's contact during a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactEvent<V = DVec2> {
    /// It left its one-sided wire at `time`, where the force holding it
    /// would have had to pull.
    Left {
        /// When.
        time: f64,
        /// Where.
        position: V,
    },
    /// It reached its wire again at `time` with normal speed
    /// `normal_speed` (relative to the wire) and stayed on it, or bounced.
    Landed {
        /// When.
        time: f64,
        /// Where.
        position: V,
        /// The speed across the wire it arrived with.
        normal_speed: f64,
        /// Whether it bounced off (restitution) rather than stayed on.
        bounced: bool,
    },
}

/// The result of one [`step_surface`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceStep<V = DVec2> {
    /// The new state and what the step applied (λ zero in flight).
    pub output: StepOutput<V>,
    /// On the wire or in flight after the step.
    pub contact: Contact,
    /// The last change of contact during the step, if any.
    pub event: Option<ContactEvent<V>>,
}

/// How many events one step may cut itself at before it takes the rest of
/// the step plainly.
const MAX_EVENTS: u32 = 4;

/// The bounce rule of eq. (16), for a lone bead and an island alike: a
/// bead that lands at `normal_speed` across its wire bounces off with
/// restitution `e` only where one step `dt` of the applied `force`'s push
/// along the wire's `normal` (on a bead of inverse mass `inverse_mass`)
/// would not undo the bounce; a slower one lands and stays on.
pub(crate) fn bounces<V: Coordinates>(
    e: f64,
    normal_speed: f64,
    normal: V,
    force: V,
    inverse_mass: f64,
    dt: f64,
) -> bool {
    let length = normal.dot(normal).sqrt();
    let push = (normal.dot(force) * inverse_mass).abs() / length.max(f64::MIN_POSITIVE);
    e > 0.0 && e * normal_speed > push * dt
}

/// One step of a bead on a wire with a [`Surface`] (see [`step_on`] for
/// the rest), from `contact`. A plain surface takes [`step_on`] itself.
///
/// On the wire, a one-sided wire's bead leaves where eq. (3)'s λ (with
/// α = β = 0) changes to the sign the wire cannot push with; friction and
/// damping enter eq. (17) at every stage (RK4, Euler) or at the step's
/// start (RATTLE); a bead whose sliding friction stops stays at rest while
/// the force along the wire is within static friction. In flight, the
/// bead follows its forces alone by the method's own integrator without
/// the constraint; where it crosses the wire it lands: its normal
/// velocity (relative to the wire) is reversed and scaled by the
/// restitution `e`, the tangential kept; it stays on when `e` is zero or
/// the bounce is slower than one step of its forces would undo.
#[allow(clippy::too_many_arguments)]
pub fn step_surface<V: Coordinates, T: Track<V> + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState<V>,
    force: &LinearForce<V>,
    mass: f64,
    settings: &StepSettings,
    surface: &Surface,
    contact: Contact,
) -> Result<SurfaceStep<V>, SolveError> {
    if surface.is_plain() && !track.has_ends() {
        return Ok(SurfaceStep {
            output: step_on(track, t, state, force, mass, settings)?,
            contact: Contact::OnWire,
            event: None,
        });
    }
    let walk = Walk {
        track,
        force,
        mass,
        settings,
        surface,
    };
    match contact {
        Contact::OnWire => walk.on_wire(t, settings.dt, state, 0),
        Contact::InFlight => walk.in_flight(t, settings.dt, state, 0),
    }
}

/// What every part of a cut step shares.
struct Walk<'a, T: ?Sized, V> {
    track: &'a T,
    force: &'a LinearForce<V>,
    mass: f64,
    settings: &'a StepSettings,
    surface: &'a Surface,
}

impl<V: Coordinates, T: Track<V> + ?Sized> Walk<'_, T, V> {
    /// The settings for a part of length `h`.
    fn part(&self, h: f64) -> StepSettings {
        StepSettings {
            dt: h,
            ..*self.settings
        }
    }

    /// A plain step of length `h` from `state` at `t`, resisted by the
    /// surface for a bead that slides along `sliding` at its start.
    fn slide(
        &self,
        t: f64,
        h: f64,
        state: BeadState<V>,
        sliding: V,
    ) -> Result<StepOutput<V>, SolveError> {
        let rough = Rough {
            track: self.track,
            surface: self.surface,
            sliding,
        };
        step_on(&rough, t, state, self.force, self.mass, &self.part(h))
    }

    /// λ of eq. (3) with no stabilization: the force the wire must apply.
    fn lambda(&self, t: f64, state: BeadState<V>) -> Result<f64, SolveError> {
        Ok(solve_on(self.track, t, state, self.force, self.mass, Gains::NONE)?.lambda)
    }

    /// The velocity relative to the wire, split into its component along
    /// the wire and its component across, at time `t`.
    fn split(&self, t: f64, state: BeadState<V>) -> Result<(V, V, V), SolveError> {
        let normal = self.track.geometry(t, state.position).normal;
        let nn = normal_length_squared(normal, state.position)?;
        let wire = self.track.twist(t).velocity_at(state.position);
        let relative = state.velocity - wire;
        let across = across(normal, nn, relative);
        Ok((wire, relative - across, across))
    }
}
