//! A part of a step in flight: leaving the wire, flying under the forces
//! alone ([`free_step`]), and landing or bouncing where the flight crosses
//! the wire.

use bevy::math::DVec2;

use super::locate::locate;
use super::{Contact, ContactEvent, MAX_EVENTS, SurfaceStep, Walk, bounces};
use crate::geometry::Track;
use crate::lane::V2;
use crate::solver::euler::{explicit_euler_lanes, semi_implicit_euler_lanes};
use crate::solver::method::Method;
use crate::solver::projection::project_on;
use crate::solver::rk4::{Stages, rk4_lanes};
use crate::solver::solve::SolveError;
use crate::solver::state::{BeadState, LinearForce};
use crate::solver::step::StepOutput;

impl<T: Track + ?Sized> Walk<'_, T> {
    /// The bead leaves its wire at `t` from `state` (an end, or where the
    /// wire would have to pull), flying on for `h`.
    pub(super) fn leave(
        &self,
        t: f64,
        h: f64,
        state: BeadState,
        events: u32,
    ) -> Result<SurfaceStep, SolveError> {
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
        state: BeadState,
        events: u32,
    ) -> Result<SurfaceStep, SolveError> {
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
                    constraint_force: DVec2::ZERO,
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
        let normal_speed = across.length();
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
                velocity: wire + along - e * across,
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
pub fn free_step(
    method: Method,
    state: BeadState,
    force: &LinearForce,
    mass: f64,
    h: f64,
) -> BeadState {
    let (x, v) = (V2::from(state.position), V2::from(state.velocity));
    let accel = |p: DVec2| force.at(p) / mass;
    let a = V2::from(accel(state.position));
    let (x1, v1) = match method {
        Method::ExplicitEuler(_) => explicit_euler_lanes(x, v, a, h),
        Method::SemiImplicitEuler(_) => semi_implicit_euler_lanes(x, v, a, h),
        Method::Rk4(_) => {
            let Ok(end) = rk4_lanes(x, v, a, h, &mut Free { force, mass });
            end
        }
        Method::Rattle => {
            let half = state.velocity + 0.5 * h * accel(state.position);
            let position = state.position + h * half;
            let velocity = half + 0.5 * h * accel(position);
            return BeadState { position, velocity };
        }
    };
    BeadState {
        position: x1.into(),
        velocity: v1.into(),
    }
}

/// RK4's stages for a free bead.
struct Free<'a> {
    force: &'a LinearForce,
    mass: f64,
}

impl Stages<f64> for Free<'_> {
    type Error = std::convert::Infallible;
    fn acceleration(&mut self, x: V2<f64>, _v: V2<f64>, _at: f64) -> Result<V2<f64>, Self::Error> {
        Ok((self.force.at(x.into()) / self.mass).into())
    }
}
