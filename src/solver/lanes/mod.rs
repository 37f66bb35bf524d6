//! The batched step: [`LANES`] beads on unrotated circles at once. It runs
//! the very functions [`step`] runs (eq. 3 in `solve`, the integrators,
//! the circle's geometry), instantiated for eight lanes instead of one, so
//! each lane's result is bit for bit what [`step`] returns.
//!
//! | file | what it holds |
//! |---|---|
//! | `mod` | the lanes' layout ([`CircleLanes`], [`CircleSteps`]), the entry points and the step's outline on the lanes |
//! | `circle` | the solves on each lane's circle: eq. (3), the RK4 stages, RATTLE, projection and the restores of eqs. (10) and (11) |

#[cfg(target_arch = "x86_64")]
use self::circle::{Advanced, CircleStages, OnCircles, solve_on_circles};
#[cfg(target_arch = "x86_64")]
use super::euler::{explicit_euler_lanes, semi_implicit_euler_lanes};
#[cfg(target_arch = "x86_64")]
use super::method::Method;
#[cfg(target_arch = "x86_64")]
use super::newton::WireAt;
#[cfg(target_arch = "x86_64")]
use super::rk4::rk4_lanes;
use super::settings::StepSettings;
#[cfg(target_arch = "x86_64")]
use super::state::LinearForceLanes;
use super::state::{BeadState, LinearForce};
use super::step::StepOutput;
#[cfg(target_arch = "x86_64")]
use super::step::drift_check;
#[cfg(doc)]
use super::step::step;
pub use crate::lane::LANES;
#[cfg(target_arch = "x86_64")]
use crate::lane::{F64x8, Lane, V2, Vector, avx2};
use bevy::math::DVec2;
#[cfg(target_arch = "x86_64")]
use pulp::x86::V3;

mod circle;
#[cfg(test)]
mod tests;

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
        self.done[i].then(|| self.lane_unchecked(i))
    }

    /// Lane `i`'s entries as a [`StepOutput`], whether or not the lane
    /// finished (check [`done`](Self::done) first).
    #[inline(always)]
    pub fn lane_unchecked(&self, i: usize) -> StepOutput {
        StepOutput {
            state: BeadState {
                position: DVec2::new(self.x[i], self.y[i]),
                velocity: DVec2::new(self.vx[i], self.vy[i]),
            },
            lambda: self.lambda[i],
            constraint_force: DVec2::new(self.fx[i], self.fy[i]),
            c: self.c[i],
            c_dot: self.c_dot[i],
        }
    }
}

/// A step of eq. (3) for [`LANES`] beads on unrotated
/// [`Circle`](crate::geometry::Circle)s at once, by any [`Method`] (RATTLE,
/// RK4 and the Euler methods, with projection, Baumgarte stabilization or
/// none), bit for bit what [`step`] returns for each.
///
/// The lanes run as AVX2 vectors (pulp's `V3`, chosen at run time on
/// x86-64; elsewhere every lane goes through [`step`]): the
/// square roots and divisions of eight beads run side by side instead of
/// one after another. A lane the batch cannot finish (a non-finite state,
/// the circle's centre, a step past the drift bound) comes back not
/// [`done`](CircleSteps::done): take that bead through [`step`], which
/// reports why. A processor without AVX2 finishes no lane. Each lane has
/// its own mass; its drift bound is
/// `settings.drift_bound` times its radius, as [`step`] takes it.
///
/// The result goes into `out` (reused from call to call, so that nothing
/// large is copied or cleared per call). Many batches go faster through
/// [`step_on_circle_batches`].
#[inline]
#[cfg(test)]
pub(super) fn step_on_circles(b: &CircleLanes, settings: &StepSettings, out: &mut CircleSteps) {
    step_on_circle_batches(std::slice::from_ref(b), settings, std::slice::from_mut(out));
}

/// [`step_on_circles`] for several batches in one call: `outs[i]` gets
/// `batches[i]`'s step (a batch with no `outs` entry is not stepped; an
/// `outs` entry with no batch is left as it was). One call enters the
/// AVX2 code once for all of them, and reads each batch's lanes well
/// after they were written one by one (loading a vector just after
/// writing its lanes one at a time stalls the processor).
#[inline]
pub fn step_on_circle_batches(
    batches: &[CircleLanes],
    settings: &StepSettings,
    outs: &mut [CircleSteps],
) {
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (batches, settings);
        for out in outs.iter_mut() {
            out.done = [false; LANES];
        }
    }
    #[cfg(target_arch = "x86_64")]
    match avx2() {
        Some(simd) => simd.vectorize(StepLanes {
            simd,
            batches,
            settings,
            outs,
        }),
        _ => {
            for out in outs.iter_mut() {
                out.done = [false; LANES];
            }
        }
    }
}

/// [`step_lanes`] as pulp runs it: inside a function compiled with AVX2,
/// into which every call down to the vector instructions is inlined (a
/// closure is not always inlined, and outside that function each vector
/// instruction would be a call).
#[cfg(target_arch = "x86_64")]
struct StepLanes<'a> {
    simd: V3,
    batches: &'a [CircleLanes],
    settings: &'a StepSettings,
    outs: &'a mut [CircleSteps],
}

#[cfg(target_arch = "x86_64")]
impl pulp::NullaryFnOnce for StepLanes<'_> {
    type Output = ();
    #[inline(always)]
    fn call(self) {
        for (b, out) in self.batches.iter().zip(self.outs) {
            step_lanes(self.simd, b, self.settings, out);
        }
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
    let circle = OnCircles { centre, radius };
    let advanced = if settings.method == Method::Rattle {
        circle.rattle(x, v, &force, m, h)
    } else {
        let (first, normal, mut regular) =
            solve_on_circles(x, v, centre, radius, &force, m, settings);
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
            // RATTLE took the other branch.
            Method::SemiImplicitEuler(_) | Method::Rattle => semi_implicit_euler_lanes(x, v, a, h),
        };
        Advanced {
            x: x1,
            v: v1,
            lambda: first.lambda,
            constraint_force: normal.scale(first.lambda),
            end: circle.at(x1),
            start_normal: normal,
            regular,
        }
    };
    let Advanced {
        x: x1,
        v: v1,
        lambda,
        constraint_force,
        end,
        start_normal,
        mut regular,
    } = advanced;
    let (_, within) = drift_check(settings, end.c, radius);
    regular = regular
        & x.is_finite()
        & v.is_finite()
        & x1.is_finite()
        & v1.is_finite()
        & end.len.is_nonzero()
        & within;
    let (x1, v1, end) = if settings.method.projects() {
        // Eq. (9), then the speed of eq. (10) after an Euler step, the
        // energy of eq. (11) after RK4.
        let (xp, vp, at, projected) = circle.project(x1, v1, end);
        let (vr, restored) = if settings.method.is_euler() {
            circle.restore_speed(x, v, start_normal, xp, vp, at, &force, m, h)
        } else {
            circle.restore_energy(x, v, xp, vp, at, &force, m)
        };
        regular = regular & projected & restored;
        (xp, vr, at)
    } else {
        (x1, v1, end)
    };
    *out = CircleSteps {
        x: x1.x.store(),
        y: x1.y.store(),
        vx: v1.x.store(),
        vy: v1.y.store(),
        lambda: lambda.store(),
        fx: constraint_force.x.store(),
        fy: constraint_force.y.store(),
        c: end.c.store(),
        c_dot: end.normal.dot(v1).store(),
        done: regular.store(),
    };
}
