//! The batched step: [`LANES`] beads on unrotated circles in the plane, or
//! on spheres in space, at once. It runs
//! the very functions [`step`] runs (eq. 3 in `solve`, the integrators,
//! the circle's geometry), instantiated for eight lanes instead of one, so
//! each lane's result is bit for bit what [`step`] returns.
//!
//! | file | what it holds |
//! |---|---|
//! | `mod` | the lanes' layout ([`RoundLanes`], [`RoundSteps`]), the entry points and the step's outline on the lanes |
//! | `circle` | the solves on each lane's circle or sphere: eq. (3), the RK4 stages, RATTLE, projection and the restores of eqs. (10) and (11) |

#[cfg(target_arch = "x86_64")]
use self::circle::{Advanced, OnRounds, RoundStages, solve_on_rounds};
#[cfg(target_arch = "x86_64")]
use super::euler::Euler;
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
use crate::lane::LaneSpace;
#[cfg(target_arch = "x86_64")]
use crate::lane::{F64x8, Lane, Vector, avx2};
use bevy::math::DVec2;
#[cfg(target_arch = "x86_64")]
use pulp::x86::V3;

mod circle;
#[cfg(test)]
mod tests;

/// [`LANES`] beads on circles in the plane (`S = DVec2`) or on spheres in
/// space (`S = DVec3`), as columns of their scalars (one entry per bead,
/// one column per component), the layout the batched step vectorizes over.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct RoundLanes<S: LaneSpace = DVec2> {
    /// Position.
    pub x: S::Columns,
    /// Velocity.
    pub v: S::Columns,
    /// The external force's [`LinearForce::force`].
    pub f: S::Columns,
    /// The external force's [`LinearForce::stiffness`].
    pub stiffness: [f64; LANES],
    /// The external force's [`LinearForce::at`].
    pub at: S::Columns,
    /// Mass.
    pub mass: [f64; LANES],
    /// The circle's or sphere's centre.
    pub centre: S::Columns,
    /// Its radius.
    pub radius: [f64; LANES],
}

impl<S: LaneSpace> RoundLanes<S> {
    /// Puts bead `lane`'s state, force, mass and circle or sphere in
    /// place.
    #[inline(always)]
    pub fn set(
        &mut self,
        lane: usize,
        state: BeadState<S>,
        force: &LinearForce<S>,
        mass: f64,
        centre: S,
        radius: f64,
    ) {
        S::set(&mut self.x, lane, state.position);
        S::set(&mut self.v, lane, state.velocity);
        S::set(&mut self.f, lane, force.force);
        self.stiffness[lane] = force.stiffness;
        S::set(&mut self.at, lane, force.at);
        self.mass[lane] = mass;
        S::set(&mut self.centre, lane, centre);
        self.radius[lane] = radius;
    }
}

/// What [`step_on_rounds`] returns: each lane's step, as columns of the
/// fields of a [`StepOutput`] (one entry per bead), and which lanes it
/// finished.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct RoundSteps<S: LaneSpace = DVec2> {
    /// New position.
    pub x: S::Columns,
    /// New velocity.
    pub v: S::Columns,
    /// λ.
    pub lambda: [f64; LANES],
    /// The constraint force `λN`.
    pub constraint_force: S::Columns,
    /// `C` at the new state.
    pub c: [f64; LANES],
    /// `Ċ` at the new state.
    pub c_dot: [f64; LANES],
    /// Whether the lane finished as [`step`] would (if not, the other
    /// entries of the lane mean nothing).
    pub done: [bool; LANES],
}

impl<S: LaneSpace> RoundSteps<S> {
    /// Lane `i`'s step, bit for bit what [`step`] returns, or `None` if the
    /// bead must go through [`step`].
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Option<StepOutput<S>> {
        self.done[i].then(|| self.lane_unchecked(i))
    }

    /// Lane `i`'s entries as a [`StepOutput`], whether or not the lane
    /// finished (check [`done`](Self::done) first).
    #[inline(always)]
    pub fn lane_unchecked(&self, i: usize) -> StepOutput<S> {
        StepOutput {
            state: BeadState {
                position: S::get(&self.x, i),
                velocity: S::get(&self.v, i),
            },
            lambda: self.lambda[i],
            constraint_force: S::get(&self.constraint_force, i),
            c: self.c[i],
            c_dot: self.c_dot[i],
        }
    }
}

/// A step of eq. (3) for [`LANES`] beads on unrotated
/// [`Circle`](crate::geometry::Circle)s in the plane or on
/// [`Sphere`](crate::geometry::Sphere)s in space at once, by any [`Method`] (RATTLE,
/// RK4 and the Euler methods, with projection, Baumgarte stabilization or
/// none), bit for bit what [`step`] returns for each.
///
/// The lanes run as AVX2 vectors (pulp's `V3`, chosen at run time on
/// x86-64; elsewhere every lane goes through [`step`]): the
/// square roots and divisions of eight beads run side by side instead of
/// one after another. A lane the batch cannot finish (a non-finite state,
/// the circle's centre, a step past the drift bound) comes back not
/// [`done`](RoundSteps::done): take that bead through [`step`], which
/// reports why. A processor without AVX2 finishes no lane. Each lane has
/// its own mass; its drift bound is
/// `settings.drift_bound` times its radius, as [`step`] takes it.
///
/// The result goes into `out` (reused from call to call, so that nothing
/// large is copied or cleared per call). Many batches go faster through
/// [`step_on_round_batches`].
#[inline]
#[cfg(test)]
pub(super) fn step_on_rounds<S: LaneSpace>(
    b: &RoundLanes<S>,
    settings: &StepSettings,
    out: &mut RoundSteps<S>,
) {
    step_on_round_batches(std::slice::from_ref(b), settings, std::slice::from_mut(out));
}

/// [`step_on_rounds`] for several batches in one call: `outs[i]` gets
/// `batches[i]`'s step (a batch with no `outs` entry is not stepped; an
/// `outs` entry with no batch is left as it was). One call enters the
/// AVX2 code once for all of them, and reads each batch's lanes well
/// after they were written one by one (loading a vector just after
/// writing its lanes one at a time stalls the processor).
#[inline]
pub(crate) fn step_on_round_batches<S: LaneSpace>(
    batches: &[RoundLanes<S>],
    settings: &StepSettings,
    outs: &mut [RoundSteps<S>],
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
struct StepLanes<'a, S: LaneSpace> {
    simd: V3,
    batches: &'a [RoundLanes<S>],
    settings: &'a StepSettings,
    outs: &'a mut [RoundSteps<S>],
}

#[cfg(target_arch = "x86_64")]
impl<S: LaneSpace> pulp::NullaryFnOnce for StepLanes<'_, S> {
    type Output = ();
    #[inline(always)]
    fn call(self) {
        for (b, out) in self.batches.iter().zip(self.outs) {
            step_lanes(self.simd, b, self.settings, out);
        }
    }
}

/// [`step_on_rounds`] on the AVX2 lanes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn step_lanes<S: LaneSpace>(
    simd: V3,
    b: &RoundLanes<S>,
    settings: &StepSettings,
    out: &mut RoundSteps<S>,
) {
    let load = |a: &[f64; LANES]| F64x8::load(simd, a);
    let x = S::load(simd, &b.x);
    let v = S::load(simd, &b.v);
    let centre = S::load(simd, &b.centre);
    let (radius, m) = (load(&b.radius), load(&b.mass));
    let force = LinearForceLanes {
        force: S::load(simd, &b.f),
        stiffness: load(&b.stiffness),
        at: S::load(simd, &b.at),
    };
    let h = m.splat(settings.dt);
    let circle = OnRounds::<F64x8, S> { centre, radius };
    let advanced = if settings.method == Method::Rattle {
        circle.rattle(x, v, &force, m, h)
    } else {
        let (first, normal, mut regular) =
            solve_on_rounds::<F64x8, S>(x, v, centre, radius, &force, m, settings);
        let a = first.acceleration;
        let (x1, v1) = match Euler::of(settings.method) {
            Some(euler) => euler.lanes(x, v, a, h),
            // RK4 (RATTLE took the other branch).
            None => {
                let mut stages = RoundStages::<F64x8, S> {
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
    *out = RoundSteps {
        x: S::store(x1),
        v: S::store(v1),
        lambda: lambda.store(),
        constraint_force: S::store(constraint_force),
        c: end.c.store(),
        c_dot: end.normal.dot(v1).store(),
        done: regular.store(),
    };
}
