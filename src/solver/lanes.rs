//! The batched step: [`LANES`] beads on unrotated circles at once. It runs
//! the very functions [`step`] runs (eq. 3 in `solve`, the integrators,
//! the circle's geometry), instantiated for eight lanes instead of one, so
//! each lane's result is bit for bit what [`step`] returns.

use std::convert::Infallible;

use super::euler::{explicit_euler_lanes, semi_implicit_euler_lanes};
use super::method::{Method, Stabilization};
use super::rk4::{Stages, rk4_lanes};
use super::settings::StepSettings;
use super::solve::{ConstraintForce, constraint_force};
use super::state::{BeadState, LinearForce, LinearForceLanes};
use super::step::StepOutput;
#[cfg(doc)]
use super::step::step;
use crate::geometry::circle_geometry;
pub use crate::lane::LANES;
#[cfg(target_arch = "x86_64")]
use crate::lane::{F64x8, avx2};
use crate::lane::{Lane, V2};
use bevy::math::DVec2;
#[cfg(target_arch = "x86_64")]
use pulp::x86::V3;

/// [`LANES`] beads on circles, as arrays of their scalars (one entry per
/// bead), the layout the batched step vectorizes over.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CircleLanes {
    /// Position x.
    pub x: [f64; LANES],
    /// Position y.
    pub y: [f64; LANES],
    /// Velocity x.
    pub vx: [f64; LANES],
    /// Velocity y.
    pub vy: [f64; LANES],
    /// The external force's [`LinearForce::force`], x.
    pub fx: [f64; LANES],
    /// The external force's [`LinearForce::force`], y.
    pub fy: [f64; LANES],
    /// The external force's [`LinearForce::stiffness`].
    pub stiffness: [f64; LANES],
    /// The external force's [`LinearForce::at`], x.
    pub at_x: [f64; LANES],
    /// The external force's [`LinearForce::at`], y.
    pub at_y: [f64; LANES],
    /// Mass.
    pub mass: [f64; LANES],
    /// The circle's centre, x.
    pub ox: [f64; LANES],
    /// The circle's centre, y.
    pub oy: [f64; LANES],
    /// The circle's radius.
    pub radius: [f64; LANES],
}

impl CircleLanes {
    /// Puts bead `lane`'s state, force, mass and circle in place.
    #[inline(always)]
    pub fn set(
        &mut self,
        lane: usize,
        state: BeadState,
        force: &LinearForce,
        mass: f64,
        centre: DVec2,
        radius: f64,
    ) {
        (self.x[lane], self.y[lane]) = (state.position.x, state.position.y);
        (self.vx[lane], self.vy[lane]) = (state.velocity.x, state.velocity.y);
        (self.fx[lane], self.fy[lane]) = (force.force.x, force.force.y);
        self.stiffness[lane] = force.stiffness;
        (self.at_x[lane], self.at_y[lane]) = (force.at.x, force.at.y);
        self.mass[lane] = mass;
        (self.ox[lane], self.oy[lane]) = (centre.x, centre.y);
        self.radius[lane] = radius;
    }
}

/// What [`step_on_circles`] returns: each lane's step, as arrays of the
/// fields of a [`StepOutput`] (one entry per bead), and which lanes it
/// finished.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CircleSteps {
    /// New position x.
    pub x: [f64; LANES],
    /// New position y.
    pub y: [f64; LANES],
    /// New velocity x.
    pub vx: [f64; LANES],
    /// New velocity y.
    pub vy: [f64; LANES],
    /// λ.
    pub lambda: [f64; LANES],
    /// The constraint force `λN`, x.
    pub fx: [f64; LANES],
    /// The constraint force `λN`, y.
    pub fy: [f64; LANES],
    /// `C` at the new state.
    pub c: [f64; LANES],
    /// `Ċ` at the new state.
    pub c_dot: [f64; LANES],
    /// Whether the lane finished as [`step`] would (if not, the other
    /// entries of the lane mean nothing).
    pub done: [bool; LANES],
}

impl CircleSteps {
    /// Lane `i`'s step, bit for bit what [`step`] returns, or `None` if the
    /// bead must go through [`step`].
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Option<StepOutput> {
        self.done[i].then(|| StepOutput {
            state: BeadState {
                position: DVec2::new(self.x[i], self.y[i]),
                velocity: DVec2::new(self.vx[i], self.vy[i]),
            },
            lambda: self.lambda[i],
            constraint_force: DVec2::new(self.fx[i], self.fy[i]),
            c: self.c[i],
            c_dot: self.c_dot[i],
        })
    }
}

/// Whether [`step_on_circles`] takes steps of this method: explicit or
/// semi-implicit Euler or RK4, with Baumgarte stabilization or none.
pub fn is_batched(method: Method) -> bool {
    !matches!(
        method.stabilization(),
        None | Some(Stabilization::Projection)
    )
}

/// A step of eq. (3) for [`LANES`] beads on unrotated
/// [`Circle`](crate::geometry::Circle)s at once, for the methods
/// [`is_batched`] accepts, bit for bit what [`step`] returns for each.
///
/// The lanes run as AVX2 vectors (pulp's `V3`, chosen at run time on
/// x86-64; elsewhere every lane goes through [`step`]): the
/// square roots and divisions of eight beads run side by side instead of
/// one after another. A lane the batch cannot finish (a non-finite state,
/// the circle's centre, a step past the drift bound) comes back not
/// [`done`](CircleSteps::done): take that bead through [`step`], which
/// reports why. A method [`is_batched`] refuses, or a processor without
/// AVX2, finishes no lane. Each lane has its own mass; its drift bound is
/// `settings.drift_bound` times its radius, as [`step`] takes it.
///
/// The result goes into `out` (reused from call to call, so that nothing
/// large is copied or cleared per call).
#[inline]
pub fn step_on_circles(b: &CircleLanes, settings: &StepSettings, out: &mut CircleSteps) {
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (b, settings);
        out.done = [false; LANES];
    }
    #[cfg(target_arch = "x86_64")]
    match avx2() {
        Some(simd) if is_batched(settings.method) => simd.vectorize(StepLanes {
            simd,
            b,
            settings,
            out,
        }),
        _ => out.done = [false; LANES],
    }
}

/// [`step_lanes`] as pulp runs it: inside a function compiled with AVX2,
/// into which every call down to the vector instructions is inlined (a
/// closure is not always inlined, and outside that function each vector
/// instruction would be a call).
#[cfg(target_arch = "x86_64")]
struct StepLanes<'a> {
    simd: V3,
    b: &'a CircleLanes,
    settings: &'a StepSettings,
    out: &'a mut CircleSteps,
}

#[cfg(target_arch = "x86_64")]
impl pulp::NullaryFnOnce for StepLanes<'_> {
    type Output = ();
    #[inline(always)]
    fn call(self) {
        step_lanes(self.simd, self.b, self.settings, self.out);
    }
}

/// Eqs. (3)–(4) on each lane's circle: the geometry, the solve and whether
/// its normal is usable.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
#[inline(always)]
fn solve_on_circles<T: Lane>(
    p: V2<T>,
    v: V2<T>,
    centre: V2<T>,
    radius: T,
    force: &LinearForceLanes<T>,
    m: T,
    settings: &StepSettings,
) -> (ConstraintForce<T>, V2<T>, T::Mask) {
    let g = circle_geometry(p - centre, radius);
    let hv = g.hessian.apply(v);
    let solved = constraint_force(g.normal, hv, g.c, v, force.at(p), m, settings.gains());
    let nn = solved.nn;
    let regular = g.len.is_nonzero() & nn.is_finite() & nn.gt(nn.splat(1e-24));
    (solved, g.normal, regular)
}

/// The RK4 stages of the lanes: eq. (4) on each lane's circle, noting
/// which lanes met a singular point.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
struct CircleStages<'a, T: Lane> {
    centre: V2<T>,
    radius: T,
    force: &'a LinearForceLanes<T>,
    m: T,
    settings: &'a StepSettings,
    regular: T::Mask,
}

impl<T: Lane> Stages<T> for CircleStages<'_, T> {
    type Error = Infallible;
    #[inline(always)]
    fn acceleration(&mut self, x: V2<T>, v: V2<T>, _at: f64) -> Result<V2<T>, Infallible> {
        let (solved, _, ok) = solve_on_circles(
            x,
            v,
            self.centre,
            self.radius,
            self.force,
            self.m,
            self.settings,
        );
        self.regular = self.regular & ok;
        Ok(solved.acceleration)
    }
}

/// [`step_on_circles`] on the AVX2 lanes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn step_lanes(simd: V3, b: &CircleLanes, settings: &StepSettings, out: &mut CircleSteps) {
    let load = |a: &[f64; LANES]| F64x8::load(simd, a);
    let x = V2::new(load(&b.x), load(&b.y));
    let v = V2::new(load(&b.vx), load(&b.vy));
    let centre = V2::new(load(&b.ox), load(&b.oy));
    let (radius, m) = (load(&b.radius), load(&b.mass));
    let force = LinearForceLanes {
        force: V2::new(load(&b.fx), load(&b.fy)),
        stiffness: load(&b.stiffness),
        at: V2::new(load(&b.at_x), load(&b.at_y)),
    };
    let h = m.splat(settings.dt);
    let (first, normal, mut regular) = solve_on_circles(x, v, centre, radius, &force, m, settings);
    let a = first.acceleration;
    let (x1, v1) = match settings.method {
        Method::ExplicitEuler(_) => explicit_euler_lanes(x, v, a, h),
        Method::Rk4(_) => {
            let mut stages = CircleStages {
                centre,
                radius,
                force: &force,
                m,
                settings,
                regular,
            };
            let Ok(stepped) = rk4_lanes(x, v, a, h, &mut stages);
            regular = stages.regular;
            stepped
        }
        // `is_batched` leaves semi-implicit Euler here.
        Method::SemiImplicitEuler(_) | Method::Rattle => semi_implicit_euler_lanes(x, v, a, h),
    };
    let constraint_force = normal.scale(first.lambda);
    let end = circle_geometry(x1 - centre, radius);
    let bound = m.splat(settings.drift_bound) * radius;
    let done = x.is_finite()
        & v.is_finite()
        & x1.is_finite()
        & v1.is_finite()
        & regular
        & end.len.is_nonzero()
        & end.c.abs_le(bound);
    *out = CircleSteps {
        x: x1.x.store(),
        y: x1.y.store(),
        vx: v1.x.store(),
        vy: v1.y.store(),
        lambda: first.lambda.store(),
        fx: constraint_force.x.store(),
        fy: constraint_force.y.store(),
        c: end.c.store(),
        c_dot: end.normal.dot(v1).store(),
        done: done.store(),
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Circle, Placed, Pose};
    use crate::solver::step;
    use crate::solver::test_support::{G, settings};

    #[test]
    fn batched_step_on_circles_is_bit_identical_to_step() {
        // Without AVX2 the batch finishes no lane and every bead takes
        // `step` itself: there is nothing to compare.
        assert!(
            crate::lane::avx2().is_some(),
            "this processor has no AVX2: the batched step is not used here"
        );
        // Beads in all directions, at all speeds, on circles of different
        // sizes and centres, with a spring's stiffness on some.
        let bound = 0.5;
        for method in Method::ALL.into_iter().filter(|m| is_batched(*m)) {
            let batch_settings = StepSettings {
                drift_bound: bound,
                ..settings(method, 1.0 / 60.0)
            };
            for k in 0..50 {
                let mut lanes = CircleLanes::default();
                let mut inputs = Vec::new();
                for lane in 0..LANES {
                    let j = (k * LANES + lane) as f64;
                    let radius = 0.5 + (j * 0.37) % 3.0;
                    let centre = DVec2::new((j * 1.3) % 5.0 - 2.5, (j * 0.7) % 4.0 - 2.0);
                    let angle = j * 0.91;
                    let off = 1.0 + 0.02 * ((j * 0.13).sin());
                    let state = BeadState {
                        position: centre + radius * off * DVec2::from_angle(angle),
                        velocity: DVec2::new((j * 0.29).sin(), (j * 0.41).cos()) * 4.0,
                    };
                    let mass = 0.3 + (j * 0.17) % 2.0;
                    let force = LinearForce {
                        force: mass * G + DVec2::new(j % 3.0, -(j % 2.0)),
                        stiffness: j % 4.0,
                        at: state.position + DVec2::new(0.01, -0.02) * (j % 5.0),
                    };
                    lanes.set(lane, state, &force, mass, centre, radius);
                    inputs.push((state, force, mass, centre, radius));
                }
                // (the same where there is no AVX2).
                let mut outs = CircleSteps::default();
                step_on_circles(&lanes, &batch_settings, &mut outs);
                let each = (0..LANES).map(|i| outs.lane(i));
                for (out, (state, force, mass, centre, radius)) in each.zip(&inputs) {
                    let (state, force, mass, centre, radius) =
                        (*state, *force, *mass, *centre, *radius);
                    let placed = Placed {
                        curve: &Circle { radius },
                        pose: Pose::new(centre, 0.0),
                    };
                    let expected = step(&placed, state, &force, mass, &batch_settings).unwrap();
                    let out = out.expect("an ordinary lane");
                    let bits = |o: &StepOutput| {
                        [o.state.position, o.state.velocity, o.constraint_force]
                            .map(|v| v.to_array().map(f64::to_bits))
                    };
                    assert_eq!(bits(&out), bits(&expected), "{method} lane {k}");
                    for (a, b) in [
                        (out.lambda, expected.lambda),
                        (out.c, expected.c),
                        (out.c_dot, expected.c_dot),
                    ] {
                        assert_eq!(a.to_bits(), b.to_bits());
                    }
                }
            }
        }
    }

    #[test]
    fn batched_step_hands_back_the_lanes_it_cannot_finish() {
        let centre = DVec2::new(1.0, 2.0);
        let mut lanes = CircleLanes::default();
        let at = |angle: f64| centre + DVec2::from_angle(angle);
        let states = [
            (at(0.3), DVec2::new(1.0, 0.0)),      // ordinary
            (centre, DVec2::ZERO),                // the singular centre
            (at(1.0), DVec2::new(f64::NAN, 0.0)), // not finite
            (at(2.0), DVec2::new(1e6, 0.0)),      // flung past the bound
        ];
        for (lane, (position, velocity)) in states.into_iter().enumerate() {
            let state = BeadState { position, velocity };
            lanes.set(lane, state, &LinearForce::constant(G), 1.0, centre, 1.0);
        }
        let s = settings(Method::SemiImplicitEuler(Stabilization::Baumgarte), 0.01);
        let mut outs = CircleSteps::default();
        step_on_circles(&lanes, &s, &mut outs);
        // The unused lanes 4 to 7 are all at their circle's centre.
        let mut done = [false; LANES];
        done[0] = true;
        assert_eq!(outs.done, done, "{outs:?}");
        assert!(outs.lane(0).is_some() && outs.lane(1).is_none());
        // What `is_batched` refuses, the batch finishes no lane of.
        for method in [
            Method::Rattle,
            Method::Rk4(Stabilization::Projection),
            Method::SemiImplicitEuler(Stabilization::Projection),
        ] {
            assert!(!is_batched(method));
            let refused = StepSettings { method, ..s };
            outs.done = [true; LANES];
            step_on_circles(&lanes, &refused, &mut outs);
            assert_eq!(outs.done, [false; LANES]);
        }
    }
}
