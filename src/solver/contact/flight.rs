//! A part of a step in flight: leaving the wire, flying under the forces
//! alone ([`free_step`]), and landing or bouncing where the flight crosses
//! the wire.

use super::locate::locate;
use super::{Contact, ContactEvent, MAX_EVENTS, SurfaceStep, Walk, bounces};
use crate::geometry::{Coordinates, Track};
use crate::solver::euler::Euler;
use crate::solver::method::Method;
use crate::solver::projection::project_on;
use crate::solver::rk4::{Stages, rk4_lanes};
use crate::solver::solve::SolveError;
use crate::solver::state::{BeadState, LinearForce};
use crate::solver::step::StepOutput;

impl<V: Coordinates, T: Track<V> + ?Sized> Walk<'_, T, V> {
    /// The bead leaves its wire at `t` from `state` (an end, or where the
    /// wire would have to pull), flying on for `h`.
    pub(super) fn leave(
        &self,
        t: f64,
        h: f64,
        state: BeadState<V>,
        events: u32,
    ) -> Result<SurfaceStep<V>, SolveError> {
        let mut flown = self.in_flight(t, h, state, events + 1)?;
        flown.event = flown.event.or(Some(ContactEvent::Left {
            time: t,
            position: state.position,
        }));
        Ok(flown)
    }

    /// A part of length `h` in flight from `state` at `t`.
    pub(super) fn in_flight(
        &self,
        t: f64,
        h: f64,
        state: BeadState<V>,
        events: u32,
    ) -> Result<SurfaceStep<V>, SolveError> {
        let side = self.surface.side.sign();
        let flown = free_step(self.settings.method, state, self.force, self.mass, h);
        if !flown.is_finite() {
            return Err(SolveError::NonFinite);
        }
        let c = self.track.geometry(t + h, flown.position).c;
        if side == 0.0
            || side * c > 0.0
            || events >= MAX_EVENTS
            || self.track.past_end(t + h, flown.position) > 0.0
        {
            let (_, _, across) = self.split(t + h, flown)?;
            let normal = self.track.geometry(t + h, flown.position).normal;
            return Ok(SurfaceStep {
                output: StepOutput {
                    state: flown,
                    lambda: 0.0,
                    constraint_force: V::ZERO,
                    c,
                    c_dot: normal.dot(across),
                },
                contact: Contact::InFlight,
                event: None,
            });
        }
        // It crosses the wire within the part: land where it does.
        let before = side * self.track.geometry(t, state.position).c;
        let tau = locate(h, before, |tau| {
            let part = free_step(self.settings.method, state, self.force, self.mass, tau);
            Ok(side * self.track.geometry(t + tau, part.position).c)
        })?;
        let arrived = free_step(self.settings.method, state, self.force, self.mass, tau);
        let touching = BeadState {
            position: project_on(self.track, t + tau, arrived)?.position,
            velocity: arrived.velocity,
        };
        let (wire, along, across) = self.split(t + tau, touching)?;
        let normal_speed = across.dot(across).sqrt();
        let e = self.surface.restitution;
        // A bounce one step of the forces would undo is a landing.
        let normal = self.track.geometry(t + tau, touching.position).normal;
        let force = self.force.at(touching.position);
        let bounced = bounces(
            e,
            normal_speed,
            normal,
            force,
            self.mass.recip(),
            self.settings.dt,
        );
        let event = ContactEvent::Landed {
            time: t + tau,
            position: touching.position,
            normal_speed,
            bounced,
        };
        let mut rest = if bounced {
            let off = BeadState {
                velocity: wire + along - across * e,
                ..touching
            };
            self.in_flight(t + tau, h - tau, off, events + 1)?
        } else {
            let on = BeadState {
                velocity: wire + along,
                ..touching
            };
            self.on_wire(t + tau, h - tau, on, events + 1)?
        };
        rest.event = rest.event.or(Some(event));
        Ok(rest)
    }
}

/// One step of length `h` of a bead under `force` alone, by the method's
/// own integrator: the Euler steps of eq. (6), RK4, or RATTLE's velocity
/// Verlet (both exact under a constant force).
pub fn free_step<V: Coordinates>(
    method: Method,
    state: BeadState<V>,
    force: &LinearForce<V>,
    mass: f64,
    h: f64,
) -> BeadState<V> {
    let (x, v) = (state.position, state.velocity);
    let accel = |p: V| force.at(p) / mass;
    let a = accel(state.position);
    let (x1, v1) = match (method, Euler::of(method)) {
        (_, Some(euler)) => euler.lanes(x, v, a, h),
        (Method::Rk4(_), _) => {
            let Ok(end) = rk4_lanes(x, v, a, h, &mut Free { force, mass });
            end
        }
        // RATTLE's velocity Verlet.
        _ => {
            let half = state.velocity + accel(state.position) * (0.5 * h);
            let position = state.position + half * h;
            let velocity = half + accel(position) * (0.5 * h);
            return BeadState { position, velocity };
        }
    };
    BeadState {
        position: x1,
        velocity: v1,
    }
}

/// RK4's stages for a free bead.
struct Free<'a, V> {
    force: &'a LinearForce<V>,
    mass: f64,
}

impl<V: Coordinates> Stages<f64, V> for Free<'_, V> {
    type Error = std::convert::Infallible;
    fn acceleration(&mut self, x: V, _v: V, _at: f64) -> Result<V, Self::Error> {
        Ok(self.force.at(x) / self.mass)
    }
}
