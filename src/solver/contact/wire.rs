//! A part of a step on the wire: sliding, leaving where λ takes the sign
//! the wire cannot push with or past an end, and stopping and sticking
//! where friction holds the bead.

use super::{Contact, MAX_EVENTS, SurfaceStep, Walk};
use crate::geometry::{Coordinates, Track};
use crate::solver::friction;
use crate::solver::settings::Gains;
use crate::solver::solve::{SolveError, Solved, in_frame, solve_on};
use crate::solver::state::BeadState;
use crate::solver::step::StepOutput;
use crate::solver::wire_normal::along;

impl<V: Coordinates, T: Track<V> + ?Sized> Walk<'_, T, V> {
    /// A part of length `h` on the wire from `state` at `t`.
    pub(super) fn on_wire(
        &self,
        t: f64,
        h: f64,
        state: BeadState<V>,
        events: u32,
    ) -> Result<SurfaceStep<V>, SolveError> {
        let side = self.surface.side.sign();
        let cut = events < MAX_EVENTS;
        let ends = self.track.has_ends();
        // How far on the wire the bead is: negative past an end; λ's sign
        // the wire can push with.
        let on_the_curve = |t: f64, x: BeadState<V>| -self.track.past_end(t, x.position);
        let pushing = |t: f64, x: BeadState<V>| Ok::<f64, SolveError>(side * self.lambda(t, x)?);
        if cut && ends && on_the_curve(t, state) < 0.0 {
            return self.leave(t, h, state, events);
        }
        let start = if side != 0.0 { pushing(t, state)? } else { 0.0 };
        if cut && side != 0.0 && start < 0.0 {
            return self.leave(t, h, state, events);
        }
        let friction = self.surface.friction.is_some();
        let (_, sliding, _) = self.split(t, state)?;
        if friction
            && sliding == V::ZERO
            && let Some(solved) = self.sticks(t, state)?
        {
            return self.held(t, h, state, solved);
        }
        let out = self.slide(t, h, state, sliding)?;
        let end = t + h;
        if cut && ends && on_the_curve(end, out.state) < 0.0 {
            // It passed an end within the step: it leaves there.
            let at = self.cut(t, h, state, sliding, on_the_curve(t, state), |tau, x| {
                Ok(on_the_curve(t + tau, x))
            })?;
            return self.leave(at.0, t + h - at.0, at.1, events);
        }
        if cut && side != 0.0 && pushing(end, out.state)? < 0.0 {
            // The wire would have to pull within the step: it leaves there.
            let at = self.cut(t, h, state, sliding, start, |tau, x| pushing(t + tau, x))?;
            return self.leave(at.0, t + h - at.0, at.1, events);
        }
        if cut && friction && sliding.dot(self.split(end, out.state)?.1) < 0.0 {
            // Friction stopped the bead within the step: it stops there.
            let (when, at) = self.cut(t, h, state, sliding, sliding.dot(sliding), |tau, x| {
                Ok(self.split(t + tau, x)?.1.dot(sliding))
            })?;
            let (wire, _, across) = self.split(when, at)?;
            let stopped = BeadState {
                velocity: wire + across,
                ..at
            };
            return self.on_wire(when, t + h - when, stopped, events + 1);
        }
        Ok(SurfaceStep {
            output: out,
            contact: Contact::OnWire,
            event: None,
        })
    }

    /// The constraint force on a bead at rest on the wire if it stays so
    /// (the force along the wire within static friction); none if it
    /// slides.
    fn sticks(&self, t: f64, state: BeadState<V>) -> Result<Option<Solved<V>>, SolveError> {
        let solved = solve_on(self.track, t, state, self.force, self.mass, Gains::NONE)?;
        let f = self.force.at(state.position);
        let applied = in_frame(self.track, t, state, f, self.mass).applied;
        let normal = self.track.geometry(t, state.position).normal;
        let nn = normal.dot(normal);
        let pull = along(normal, nn, applied);
        let press = friction::press(solved.lambda, nn);
        let strength = pull.dot(pull).sqrt();
        Ok(friction::holds(&self.surface.friction, strength, press).then_some(solved))
    }

    /// A part of length `h` in which static friction holds the bead still
    /// on the wire (carried with it if it moves).
    fn held(
        &self,
        t: f64,
        h: f64,
        state: BeadState<V>,
        solved: Solved<V>,
    ) -> Result<SurfaceStep<V>, SolveError> {
        let position = self.track.carry(state.position, t, t + h);
        let velocity = self.track.twist(t + h).velocity_at(position);
        let end = BeadState { position, velocity };
        let g = self.track.geometry(t + h, position);
        Ok(SurfaceStep {
            output: StepOutput {
                state: end,
                lambda: solved.lambda,
                constraint_force: solved.constraint_force,
                c: g.c,
                c_dot: 0.0,
            },
            contact: Contact::OnWire,
            event: None,
        })
    }
}
