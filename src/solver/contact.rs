//! One-sided wires, landings and friction for one bead, eq. (14): a step
//! that may leave the wire, fly, land (bouncing with a restitution), stop
//! and stick.
//!
//! Each change happens at the instant it happens, not at the end of a step:
//! the step is cut where a bead's `λ` changes sign (it leaves), where its
//! flight crosses the wire (it lands) or where friction brings its sliding
//! to rest (it stops), by regula falsi on the length of a sub-step, and
//! the rest of the step goes on in the new state.

use bevy::math::DVec2;

use super::euler::{explicit_euler_lanes, semi_implicit_euler_lanes};
use super::method::Method;
use super::projection::project_on;
use super::rk4::{Stages, rk4_lanes};
use super::settings::{Gains, StepSettings};
use super::solve::{SolveError, Solved, normal_length_squared, solve_on};
use super::state::{BeadState, LinearForce};
use super::step::{StepOutput, step_on};
use crate::geometry::{Rough, Surface, Track};
use crate::lane::V2;

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
pub enum ContactEvent {
    /// It left its one-sided wire at `time`, where the force holding it
    /// would have had to pull.
    Left {
        /// When.
        time: f64,
        /// Where.
        position: DVec2,
    },
    /// It reached its wire again at `time` with normal speed
    /// `normal_speed` (relative to the wire) and stayed on it, or bounced.
    Landed {
        /// When.
        time: f64,
        /// Where.
        position: DVec2,
        /// The speed across the wire it arrived with.
        normal_speed: f64,
        /// Whether it bounced off (restitution) rather than stayed on.
        bounced: bool,
    },
}

/// The result of one [`step_surface`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceStep {
    /// The new state and what the step applied (λ zero in flight).
    pub output: StepOutput,
    /// On the wire or in flight after the step.
    pub contact: Contact,
    /// The last change of contact during the step, if any.
    pub event: Option<ContactEvent>,
}

/// How many events one step may cut itself at before it takes the rest of
/// the step plainly.
const MAX_EVENTS: u32 = 4;

/// One step of a bead on a wire with a [`Surface`] (see [`step_on`] for
/// the rest), from `contact`. A plain surface takes [`step_on`] itself.
///
/// On the wire, a one-sided wire's bead leaves where eq. (3)'s λ (with
/// α = β = 0) changes to the sign the wire cannot push with; friction and
/// damping enter eq. (14) at every stage (RK4, Euler) or at the step's
/// start (RATTLE); a bead whose sliding friction stops stays at rest while
/// the force along the wire is within static friction. In flight, the
/// bead follows its forces alone by the method's own integrator without
/// the constraint; where it crosses the wire it lands: its normal
/// velocity (relative to the wire) is reversed and scaled by the
/// restitution `e`, the tangential kept; it stays on when `e` is zero or
/// the bounce is slower than one step of its forces would undo.
#[allow(clippy::too_many_arguments)]
pub fn step_surface<T: Track + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState,
    force: &LinearForce,
    mass: f64,
    settings: &StepSettings,
    surface: &Surface,
    contact: Contact,
) -> Result<SurfaceStep, SolveError> {
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
struct Walk<'a, T: Track + ?Sized> {
    track: &'a T,
    force: &'a LinearForce,
    mass: f64,
    settings: &'a StepSettings,
    surface: &'a Surface,
}

impl<T: Track + ?Sized> Walk<'_, T> {
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
        state: BeadState,
        sliding: DVec2,
    ) -> Result<StepOutput, SolveError> {
        let rough = Rough {
            track: self.track,
            surface: self.surface,
            sliding,
        };
        step_on(&rough, t, state, self.force, self.mass, &self.part(h))
    }

    /// λ of eq. (3) with no stabilization: the force the wire must apply.
    fn lambda(&self, t: f64, state: BeadState) -> Result<f64, SolveError> {
        Ok(solve_on(self.track, t, state, self.force, self.mass, Gains::NONE)?.lambda)
    }

    /// The velocity relative to the wire, split into its component along
    /// the wire and its component across, at time `t`.
    fn split(&self, t: f64, state: BeadState) -> Result<(DVec2, DVec2, DVec2), SolveError> {
        let normal = self.track.geometry(t, state.position).normal;
        let nn = normal_length_squared(normal, state.position)?;
        let wire = self.track.twist(t).velocity_at(state.position);
        let relative = state.velocity - wire;
        let across = normal * (normal.dot(relative) / nn);
        Ok((wire, relative - across, across))
    }

    /// A part of length `h` on the wire from `state` at `t`.
    fn on_wire(
        &self,
        t: f64,
        h: f64,
        state: BeadState,
        events: u32,
    ) -> Result<SurfaceStep, SolveError> {
        let side = self.surface.side.sign();
        let cut = events < MAX_EVENTS;
        let ends = self.track.has_ends();
        // How far on the wire the bead is: negative past an end; λ's sign
        // the wire can push with.
        let on_the_curve = |t: f64, x: BeadState| -self.track.past_end(t, x.position);
        let pushing = |t: f64, x: BeadState| Ok::<f64, SolveError>(side * self.lambda(t, x)?);
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
            && sliding == DVec2::ZERO
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
            let (when, at) =
                self.cut(t, h, state, sliding, sliding.length_squared(), |tau, x| {
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

    /// Where within a part of length `h` from `state` at `t` (sliding
    /// along `sliding`) the measure `g` (`g0` at the start, positive; not
    /// positive at the end) reaches zero: the time and the state there.
    fn cut(
        &self,
        t: f64,
        h: f64,
        state: BeadState,
        sliding: DVec2,
        g0: f64,
        g: impl Fn(f64, BeadState) -> Result<f64, SolveError>,
    ) -> Result<(f64, BeadState), SolveError> {
        let tau = self.locate(h, g0, |tau| {
            g(tau, self.slide(t, tau, state, sliding)?.state)
        })?;
        Ok((t + tau, self.slide(t, tau, state, sliding)?.state))
    }

    /// The bead leaves its wire at `t` from `state` (an end, or where the
    /// wire would have to pull), flying on for `h`.
    fn leave(
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

    /// The constraint force on a bead at rest on the wire if it stays so
    /// (the force along the wire within static friction); none if it
    /// slides.
    fn sticks(&self, t: f64, state: BeadState) -> Result<Option<Solved>, SolveError> {
        let solved = solve_on(self.track, t, state, self.force, self.mass, Gains::NONE)?;
        let twist = self.track.twist(t);
        let relative = state.velocity - twist.velocity_at(state.position);
        let frame = twist.acceleration_at(state.position, relative);
        let normal = self.track.geometry(t, state.position).normal;
        let nn = normal.length_squared();
        let applied = self.force.at(state.position) - self.mass * frame;
        let pull = applied - normal * (normal.dot(applied) / nn);
        let press = solved.lambda.abs() * nn.sqrt();
        Ok((pull.length() <= self.surface.friction.static_coefficient * press).then_some(solved))
    }

    /// A part of length `h` in which static friction holds the bead still
    /// on the wire (carried with it if it moves).
    fn held(
        &self,
        t: f64,
        h: f64,
        state: BeadState,
        solved: Solved,
    ) -> Result<SurfaceStep, SolveError> {
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

    /// A part of length `h` in flight from `state` at `t`.
    fn in_flight(
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
        let tau = self.locate(h, before, |tau| {
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
        let push = (normal.dot(self.force.at(touching.position)) / self.mass).abs()
            / normal.length().max(f64::MIN_POSITIVE);
        let bounced = e > 0.0 && e * normal_speed > push * self.settings.dt;
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

    /// The sub-step length in `(0, h]` where `g` (`g0` at 0, positive;
    /// not positive at `h`) reaches zero: regula falsi with the Illinois
    /// modification, to a relative width of 1e-13 of `h`.
    fn locate(
        &self,
        h: f64,
        g0: f64,
        mut g: impl FnMut(f64) -> Result<f64, SolveError>,
    ) -> Result<f64, SolveError> {
        let (mut a, mut b) = (0.0, h);
        let (mut ga, mut gb) = (g0, g(h)?);
        if ga.is_nan() || ga <= 0.0 {
            return Ok(0.0);
        }
        let mut last = 0;
        for _ in 0..100 {
            if b - a <= 1e-13 * h || gb == 0.0 {
                break;
            }
            let mut m = b - gb * (b - a) / (gb - ga);
            if !(m > a && m < b) {
                m = 0.5 * (a + b);
            }
            let gm = g(m)?;
            if gm > 0.0 {
                a = m;
                ga = gm;
                if last == 1 {
                    gb *= 0.5;
                }
                last = 1;
            } else {
                b = m;
                gb = gm;
                if last == -1 {
                    ga *= 0.5;
                }
                last = -1;
            }
        }
        Ok(b)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Circle, FixedTrack, Friction, Line, Placed, Pose, Side};
    use crate::solver::Stabilization;
    use crate::solver::test_support::{G, settings};

    /// A bead inside a one-sided vertical circle of radius 1 (`Negative`:
    /// the wire only pushes inwards), leaving the bottom with `v0² = 3gr`,
    /// leaves the wire at `cos φ = −1/3`, `4r/3` above the bottom, and
    /// then falls freely: its acceleration is `g` to 1e-9.
    #[test]
    fn a_loop_the_loop_bead_leaves_at_four_thirds_and_falls_freely() {
        let circle = Circle { radius: 1.0 };
        let track = FixedTrack(&circle);
        let surface = Surface {
            side: Side::Negative,
            ..Surface::PLAIN
        };
        let g = G.length();
        for (method, dt, bound) in [
            (Method::Rattle, 1e-3, 1e-3),
            (Method::Rk4(Stabilization::None), 1e-3, 1e-3),
            (Method::Rk4(Stabilization::Projection), 1e-3, 1e-3),
            (
                Method::SemiImplicitEuler(Stabilization::Projection),
                1e-4,
                1e-2,
            ),
        ] {
            let s = settings(method, dt);
            let mut state = BeadState {
                position: DVec2::new(0.0, -1.0),
                velocity: DVec2::new((3.0 * g).sqrt(), 0.0),
            };
            let mut contact = Contact::OnWire;
            let mut left_at = None;
            let mut worst_fall = 0.0f64;
            let mut flying = 0;
            for k in 0..(2.0 / dt) as usize {
                let t = k as f64 * dt;
                let step = step_surface(
                    &track,
                    t,
                    state,
                    &LinearForce::constant(G),
                    1.0,
                    &s,
                    &surface,
                    contact,
                )
                .unwrap();
                if let Some(ContactEvent::Left { position, .. }) = step.event {
                    left_at = Some(position);
                }
                if contact == Contact::InFlight && step.contact == Contact::InFlight {
                    let a = (step.output.state.velocity - state.velocity) / dt;
                    worst_fall = worst_fall.max((a - G).length() / g);
                    flying += 1;
                }
                if contact == Contact::InFlight && step.contact == Contact::OnWire {
                    break;
                }
                state = step.output.state;
                contact = step.contact;
            }
            let left = left_at.unwrap_or_else(|| panic!("{method}: never left the wire"));
            let height = left.y + 1.0;
            let error = (height - 4.0 / 3.0).abs();
            eprintln!(
                "{method} at {dt}: left {height:.6} r above the bottom (error {error:e} r), \
                 {flying} steps of free fall, acceleration off g by {worst_fall:e}"
            );
            assert!(error < bound, "{method}: left at {height}, not 4/3");
            assert!(flying > 100, "{method}: only {flying} steps of flight");
            assert!(
                worst_fall < 1e-9,
                "{method}: free-fall acceleration off by {worst_fall:e}"
            );
        }
    }

    /// A horizontal rough line, `μk = 0.3`: a bead sent at `v0 = 3` stops
    /// after `v0² / (2 μk g)` and then stays exactly where it stopped.
    #[test]
    fn friction_stops_a_sliding_bead_at_the_coulomb_distance() {
        let line = Line;
        let track = FixedTrack(&line);
        let surface = Surface {
            friction: Friction::new(0.5, 0.3).unwrap(),
            ..Surface::PLAIN
        };
        let v0 = 3.0;
        let expected = v0 * v0 / (2.0 * 0.3 * G.length());
        for (method, dt, bound) in [
            (Method::Rattle, 1.0 / 60.0, 1e-9),
            (Method::Rk4(Stabilization::None), 1.0 / 60.0, 1e-9),
            (Method::Rk4(Stabilization::Projection), 1.0 / 60.0, 1e-9),
            (
                Method::SemiImplicitEuler(Stabilization::Projection),
                5e-4,
                1e-3,
            ),
            (Method::ExplicitEuler(Stabilization::Baumgarte), 5e-4, 1e-3),
        ] {
            let s = settings(method, dt);
            let mut state = BeadState {
                position: DVec2::ZERO,
                velocity: DVec2::new(v0, 0.0),
            };
            let mut stopped_at = None;
            for k in 0..(3.0 / dt) as usize {
                let step = step_surface(
                    &track,
                    k as f64 * dt,
                    state,
                    &LinearForce::constant(G),
                    1.0,
                    &s,
                    &surface,
                    Contact::OnWire,
                )
                .unwrap();
                state = step.output.state;
                if state.velocity.x == 0.0 {
                    match stopped_at {
                        None => stopped_at = Some(state.position),
                        Some(at) => assert_eq!(state.position, at, "{method}: crept"),
                    }
                }
            }
            let at = stopped_at.unwrap_or_else(|| panic!("{method}: never stopped"));
            let error = (at.x - expected).abs() / expected;
            eprintln!(
                "{method} at {dt}: stopped at {:.9} (relative error {error:e})",
                at.x
            );
            assert!(
                error < bound,
                "{method}: stopped at {}, not {expected}",
                at.x
            );
        }
    }

    /// On a line tilted steeper than `atan μs` a bead from rest slides; on a
    /// gentler one it stays exactly at rest.
    #[test]
    fn static_friction_holds_a_bead_on_a_gentle_slope_and_not_a_steep_one() {
        let surface = Surface {
            friction: Friction::new(0.5, 0.4).unwrap(),
            ..Surface::PLAIN
        };
        let limit = 0.5f64.atan().to_degrees();
        for (degrees, slides) in [(limit - 2.0, false), (limit + 2.0, true)] {
            let line = Line;
            let placed = Placed {
                curve: &line,
                pose: Pose::new(DVec2::ZERO, degrees.to_radians()),
            };
            let track = FixedTrack(&placed);
            for method in Method::ALL {
                let s = settings(method, 1.0 / 60.0);
                let start = BeadState::default();
                let mut state = start;
                for k in 0..120 {
                    state = step_surface(
                        &track,
                        k as f64 / 60.0,
                        state,
                        &LinearForce::constant(G),
                        1.0,
                        &s,
                        &surface,
                        Contact::OnWire,
                    )
                    .unwrap()
                    .output
                    .state;
                }
                if slides {
                    assert!(
                        state.position.length() > 0.1,
                        "{method} at {degrees}°: stuck"
                    );
                } else {
                    assert_eq!(state, start, "{method} at {degrees}°: moved");
                }
            }
        }
    }
}
