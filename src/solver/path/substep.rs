//! A path joint's course through one substep of a physics engine, the
//! same in the plane and in space: what the joint keeps between substeps
//! ([`JointState`]), SHAKE's position step with the wire's end, its motor
//! or friction and its sharp corners ([`Substep::correct`]), and RATTLE's
//! velocity step ([`velocity_on_wire`]). The engine's adapter reads the
//! body, calls these and writes back what they return.

use bevy::math::DVec2;
use bevy::reflect::Reflect;

use super::{
    BodyRow, BodyVelocity, Drive, Held, Impulse, JointBody, JointWire, Projected, Rows, Turn,
    project, project_driven, project_velocity, turns_a_corner,
};
use crate::geometry::Coordinates;
use crate::lane::Vector;

/// What drives a body along its wire.
#[derive(Clone, Copy, Debug, PartialEq, Reflect)]
pub enum PathMotor<V = DVec2> {
    /// The anchor's speed along the wire, relative to the wire, brought
    /// to `speed` (m/s, along the wire's own direction: a line's +x, a
    /// circle or an ellipse counter-clockwise, a graph's growing x, a
    /// spline's, a cycloid's or a curve in space's parameter) by a force
    /// of at most `max_force` (N) along it.
    Velocity {
        /// The speed the motor holds, m/s.
        speed: f64,
        /// The largest force it gives, N.
        max_force: f64,
    },
    /// The anchor drawn along the wire towards `target` (a point of the
    /// wire, in the wire's frame) as by a spring of `frequency` (Hz) and
    /// `damping_ratio` (1: critical), by a force of at most `max_force`
    /// (N). The spring pulls along the wire's tangent at the anchor by the
    /// target's distance along it, so it draws the anchor to a target
    /// nearer than a quarter of the wire's turn (a quarter circle on a
    /// hoop); a farther one is reached by moving it as the anchor goes.
    Position {
        /// The point of the wire the anchor is drawn to, wire's frame.
        target: V,
        /// The spring's frequency, Hz.
        frequency: f64,
        /// Its damping ratio (1: critically damped).
        damping_ratio: f64,
        /// The largest force it gives, N.
        max_force: f64,
    },
}

/// What a joint asks beside holding its body on the wire.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Law<V> {
    /// What drives the body along the wire, if anything.
    pub motor: Option<PathMotor<V>>,
    /// The largest force that holds it against sliding while no motor
    /// drives it, N.
    pub friction: f64,
    /// How far the anchor yields per newton, m/N (0: rigid).
    pub compliance: f64,
}

impl<V> Law<V> {
    /// A joint's law: a compliance that is not a finite positive number
    /// (negative, NaN, infinite) is rigid.
    pub fn new(motor: Option<PathMotor<V>>, friction: f64, compliance: f64) -> Self {
        let compliance = if compliance.is_finite() && compliance > 0.0 {
            compliance
        } else {
            0.0
        };
        Self {
            motor,
            friction,
            compliance,
        }
    }

    /// Whether the joint is rigid: met in velocity as well as in position.
    pub fn rigid(&self) -> bool {
        self.compliance == 0.0
    }
}

/// What a path joint holds from one substep to the next; `T` is how the
/// body turns with the wire, once fixed where the joint began (the
/// plane's angle offset, space's [`Alignment`](super::Alignment)).
#[derive(Clone, Copy, Debug)]
pub(crate) struct JointState<B: JointBody, T> {
    /// The time the step began at, and how far into it the substeps are.
    pub time: (f64, f64),
    /// The body (and the carrier of its wire) where the step began.
    pub start: Held<B>,
    /// The body (and the carrier) where the substep began.
    pub previous: Held<B>,
    /// How the body turns with the wire, once fixed.
    pub turn: Option<T>,
    /// The wire's parameter at the anchor: its branch where it crosses
    /// itself (NaN until the anchor has been on it).
    pub hint: f64,
    /// Why the joint holds nothing, once said.
    pub warned: bool,
    /// The impulse the joint gave over the step so far: through the
    /// centre of mass, about it, and its drive's along the wire.
    pub impulse: (B::V, B::Turn, f64),
    /// The rows held where the last substep ended (its velocity step took
    /// them there): where the next substep begins, with the wire where it
    /// was then.
    pub rows: Option<Rows<B>>,
}

impl<B: JointBody, T> JointState<B, T> {
    /// A joint that has not begun, its body at `body`.
    pub fn new(body: B) -> Self {
        Self {
            time: (0.0, 0.0),
            start: Held::alone(body),
            previous: Held::alone(body),
            turn: None,
            hint: f64::NAN,
            warned: false,
            impulse: (B::V::ZERO, B::Turn::default(), 0.0),
            rows: None,
        }
    }

    /// The step begins with the body (and the carrier) at `body`, at time
    /// `time`.
    pub fn begin(&mut self, body: Held<B>, time: f64) {
        self.start = body;
        self.previous = body;
        self.time = (time, 0.0);
        self.impulse = (B::V::ZERO, B::Turn::default(), 0.0);
        self.rows = None;
    }

    /// Adds a substep's impulse: `(p, τ)` and the drive's.
    pub fn add_impulse(&mut self, (p, tau): (B::V, B::Turn), driven: f64) {
        self.impulse.0 += p;
        self.impulse.1 = self.impulse.1 + tau;
        self.impulse.2 += driven;
    }

    /// The mean force, torque and drive force over the step so far; `None`
    /// before a substep or where one is not finite.
    pub fn mean_forces(&self) -> Option<(B::V, B::Turn, f64)> {
        let dt = self.time.1;
        let (p, tau, driven) = self.impulse;
        let mean = (p / dt, tau * (1.0 / dt), driven / dt);
        (dt > 0.0 && mean.0.is_finite() && mean.1.finite() && mean.2.is_finite()).then_some(mean)
    }
}

/// One substep of a joint: the wire where the substep begins and where
/// it ends (in its carrier's frame, where it rides one), the body (and the
/// carrier) where it began and where the engine moved it, its velocity
/// and the wire's where it began.
pub(crate) struct Substep<'w, B: JointBody, W> {
    /// The wire where the substep begins.
    pub before: &'w W,
    /// The wire where it ends.
    pub after: &'w W,
    /// The body (and the carrier) where it began.
    pub previous: Held<B>,
    /// The body (and the carrier) as the engine moved it, freely.
    pub predicted: Held<B>,
    /// The body's velocity.
    pub v: BodyVelocity<B>,
    /// The velocity the body would have riding rigidly with the wire,
    /// where the substep began (with its carrier, where it rides one).
    pub frame: BodyVelocity<B>,
    /// The substep, s.
    pub h: f64,
    /// The rows held at `previous` on `before`, where known.
    pub start: Option<Rows<B>>,
}

impl<B: JointBody, W: JointWire<B>> Substep<'_, B, W> {
    /// SHAKE's step: the body put back on its rows along their gradients
    /// where the substep began, to rounding, past an end of an open wire
    /// stopped there as by a buffer, driven by its motor or held by its
    /// friction; past a sharp corner put back onto the new segment. The
    /// projection and the drive's multiplier; `None` where the wire is
    /// singular at the body.
    pub fn correct(&self, law: &Law<B::V>) -> Option<(Projected<B>, f64)> {
        let (before, after) = (self.before, self.after);
        let predicted = &self.predicted;
        let end = after
            .on(predicted.carrier.as_ref(), |wire| {
                wire.past_end(&predicted.body)
            })
            .is_some_and(|row| row.value > 0.0);
        let with_end = |wire: &W, at: &Held<B>| {
            wire.on(at.carrier.as_ref(), |wire| {
                let mut rows = wire.held(&at.body)?;
                if end {
                    rows.push(wire.past_end(&at.body)?);
                }
                rows.ride(at);
                Some(rows)
            })
        };
        let start = match self.start {
            Some(rows) if !end => rows,
            _ => with_end(before, &self.previous)?,
        };
        let tolerance = 1e-12 * after.scale().max(1.0);
        let compliance = law.compliance / (self.h * self.h);
        let rows_at = |at: &Held<B>| with_end(after, at);
        // At an end the buffer holds the anchor, whatever drives it.
        let drive = if end { None } else { self.drive(law) };
        let put_back = |start: &Rows<B>, from: &Held<B>| match drive {
            Some(drive) => project_driven(
                start,
                from,
                &drive,
                self.predicted,
                compliance,
                tolerance,
                rows_at,
            ),
            None => {
                project(start, self.predicted, compliance, tolerance, rows_at).map(|p| (p, 0.0))
            }
        };
        let projected = put_back(&start, &self.previous)?;
        // Past a sharp corner the gradients where the substep began point
        // off the wire's new direction: put the body back along those
        // where it is instead, onto the nearest point of the new segment.
        if let Some(there) = projected.0.rows
            && turns_a_corner((&self.previous, &start), (&projected.0.body, &there))
            && let Some(here) = rows_at(&self.predicted)
            && let Some(nearest) = put_back(&here, &self.predicted)
        {
            return Some(nearest);
        }
        Some(projected)
    }

    /// The joint's motor, or its friction while no motor drives it, as a
    /// displacement along the wire and a bound; `None` for a joint that
    /// neither drives nor holds.
    fn drive(&self, law: &Law<B::V>) -> Option<Drive<B>> {
        // A joint that neither drives nor holds costs no evaluation of
        // the wire.
        if law.motor.is_none() && law.friction <= 0.0 {
            return None;
        }
        self.before.on(self.previous.carrier.as_ref(), |before| {
            let previous = &self.previous.body;
            let along = before.along(previous)?;
            let relative = along.rate(self.v) - along.rate(self.frame);
            let (speed, max_force) = match law.motor {
                Some(PathMotor::Velocity { speed, max_force }) => (speed, max_force),
                Some(PathMotor::Position {
                    target,
                    frequency,
                    damping_ratio,
                    max_force,
                }) => {
                    // The spring–damper's implicit step, as avian's motors take it.
                    let error = along
                        .along_centre
                        .dot(before.to_world(target) - previous.anchor());
                    let omega = std::f64::consts::TAU * frequency;
                    let damping = 2.0 * damping_ratio * omega;
                    let h = self.h;
                    let change = (omega * omega * error - damping * relative) * h
                        / (1.0 + damping * h + omega * omega * h * h);
                    (relative + change, max_force)
                }
                None => (0.0, law.friction),
            };
            // Along a wire the game moves the anchor goes with the wire too; on
            // a wire that rides a body the drive moves with the carrier.
            let carried = self.previous.carrier;
            let riding = if carried.is_some() {
                0.0
            } else {
                along.rate(self.frame)
            };
            let (speed, max_force) = (speed + riding, max_force.max(0.0));
            (speed.is_finite() && !max_force.is_nan()).then(|| Drive {
                direction: along.along_centre,
                from: previous.anchor(),
                shift: speed * self.h,
                bound: max_force * self.h * self.h,
                carrier: carried,
            })
        })
    }
}

/// What RATTLE's velocity step left: the velocities of the body (and
/// the carrier), the generalized impulses that gave them, and the rows
/// held where the body is (for the next substep to begin from).
pub(crate) type OnWire<B> = (Held<BodyVelocity<B>>, Held<Impulse<B>>, Option<Rows<B>>);

/// RATTLE's velocity step: the velocity a joint leaves its body (and the
/// carrier of its wire) with, on its rows where the substep ends (a
/// compliant joint, met in position only, keeps its velocity), stopped
/// at an end of an open wire it would pass; the generalized impulses that
/// did it; and the rows it held. `frame` is the velocity riding rigidly
/// with a wire the game moves (zero for one that rides a carrier). `None`
/// where the rows are singular.
pub(crate) fn velocity_on_wire<B: JointBody>(
    rigid: bool,
    wire: &impl JointWire<B>,
    bodies: &Held<B>,
    v: Held<BodyVelocity<B>>,
    frame: BodyVelocity<B>,
) -> Option<OnWire<B>> {
    let held = if rigid {
        Some(wire.held_at(bodies)?)
    } else {
        None
    };
    let body = &bodies.body;
    let mut rows = held.unwrap_or_default();
    rows.ride(bodies);
    let end = wire.on(bodies.carrier.as_ref(), |wire| {
        wire.past_end(body)
            .filter(|end| end.value > -1e-9 * wire.scale())
    });
    if let Some(end) = end
        && end.rate_of(rows.carrier, &v) > end.rate(frame)
    {
        rows.push(BodyRow { value: 0.0, ..end });
    }
    let (v, impulse) = project_velocity(&rows, bodies, v, frame)?;
    Some((v, impulse, held))
}
