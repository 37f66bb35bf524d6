//! The batched step: [`LANES`] beads on unrotated circles at once. It runs
//! the very functions [`step`] runs (eq. 3 in `solve`, the integrators,
//! the circle's geometry), instantiated for eight lanes instead of one, so
//! each lane's result is bit for bit what [`step`] returns.

use std::convert::Infallible;

use super::euler::{explicit_euler_lanes, semi_implicit_euler_lanes};
use super::method::Method;
use super::projection::{
    ENERGY_CORRECTION_LIMIT, NEWTON_ACCEPT, NEWTON_MAX_ITERATIONS, NEWTON_TOLERANCE,
};
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
use crate::lane::{Lane, Mask, V2};
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
pub fn step_on_circles(b: &CircleLanes, settings: &StepSettings, out: &mut CircleSteps) {
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
    let bound = m.splat(settings.drift_bound) * radius;
    regular = regular
        & x.is_finite()
        & v.is_finite()
        & x1.is_finite()
        & v1.is_finite()
        & end.len.is_nonzero()
        & end.c.abs_le(bound);
    let (x1, v1, end) = if settings.method.projects() {
        // Eq. (9), then the speed of eq. (9b) after an Euler step, the
        // energy of eq. (9c) after RK4.
        let (xp, vp, at, projected) = circle.project(x1, v1, end);
        let (vr, restored) = if settings.method.is_euler() {
            circle.restore_speed(x, v, start_normal, vp, at, &force, m, h)
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

/// A circle's `|p|`, `C` and `∇C` at a point of each lane: what the steps
/// below reuse instead of evaluating the same point again.
#[derive(Clone, Copy)]
struct At<T: Lane> {
    len: T,
    c: T,
    normal: V2<T>,
}

impl<T: Lane> At<T> {
    /// `a` in the lanes where `mask` holds, `b` in the others.
    #[inline(always)]
    fn select(mask: T::Mask, a: Self, b: Self) -> Self {
        Self {
            len: T::select(mask, a.len, b.len),
            c: T::select(mask, a.c, b.c),
            normal: V2::select(mask, a.normal, b.normal),
        }
    }
}

/// What a step's integrator hands back on the lanes, before the
/// divergence check and the projection.
#[derive(Clone, Copy)]
struct Advanced<T: Lane> {
    x: V2<T>,
    v: V2<T>,
    /// λ and `λN` as the step reports them.
    lambda: T,
    constraint_force: V2<T>,
    /// The circle at the new position.
    end: At<T>,
    /// `∇C` at the start, where the lanes with a usable one are `regular`.
    start_normal: V2<T>,
    /// The lanes the integrator finished.
    regular: T::Mask,
}

/// Each lane's unrotated circle, for the steps that solve on it: RATTLE,
/// projection and the energy restore, written as [`rattle`](super::rattle),
/// [`project`](super::project) and eq. (9c) compute them for one bead (on
/// a fixed wire, with no surface), operation for operation, so each lane
/// returns their bits. Each also returns the lanes where the scalar
/// function would have succeeded; the others mean nothing.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
#[derive(Clone, Copy)]
struct OnCircles<T: Lane> {
    centre: V2<T>,
    radius: T,
}

#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
impl<T: Lane> OnCircles<T> {
    /// The circle at `x`.
    #[inline(always)]
    fn at(self, x: V2<T>) -> At<T> {
        let g = circle_geometry(x - self.centre, self.radius);
        At {
            len: g.len,
            c: g.c,
            normal: g.normal,
        }
    }

    /// `|N|²` where the normal is usable (the scalar step's
    /// `normal_length_squared`): not at the centre, finite, not vanishing.
    #[inline(always)]
    fn normal_length_squared(self, at: At<T>) -> (T, T::Mask) {
        let nn = at.normal.dot(at.normal);
        (
            nn,
            at.len.is_nonzero() & nn.is_finite() & nn.gt(nn.splat(1e-24)),
        )
    }

    /// Whether a Newton solve at the point `at` is done at residual `|c|`
    /// after `previous`, as `newton_done` says.
    #[inline(always)]
    fn converged(self, c: T, previous: T, at: V2<T>, last: bool) -> T::Mask {
        let r = self.radius;
        let residual = c.abs();
        let reach = at.x.abs().max(at.y.abs());
        let within = residual.abs_le(r.splat(NEWTON_TOLERANCE) * r.max(reach));
        let accepted = residual.abs_le(r.splat(NEWTON_ACCEPT) * r);
        if last {
            within | accepted
        } else {
            within | (accepted & residual.gt(r.splat(0.5) * previous))
        }
    }

    /// The lanes whose scale is the radius itself (`scale().max(MIN_POSITIVE)`).
    #[inline(always)]
    fn sized(self) -> T::Mask {
        self.radius.gt(self.radius.splat(f64::MIN_POSITIVE))
    }

    /// `newton_along`: the root `s` of `C(base + s dir) = 0`, and the
    /// circle at `base + s dir`.
    #[inline(always)]
    fn newton_along(self, base: V2<T>, dir: V2<T>) -> (T, At<T>, T::Mask) {
        let mut s = self.radius.splat(0.0);
        let mut active = self.sized();
        let mut found = active & !active;
        let mut previous = s.splat(f64::INFINITY);
        // Set in each lane where it is done.
        let mut root = At {
            len: s,
            c: s,
            normal: V2::new(s, s),
        };
        for i in 0..=NEWTON_MAX_ITERATIONS {
            // At s = 0 too the point is `base + 0 dir`, as the scalar solve
            // evaluates it (a zero's sign can differ from `base`'s).
            let p = base.plus(s, dir);
            let g = self.at(p);
            let last = i == NEWTON_MAX_ITERATIONS;
            let done = active & self.converged(g.c, previous, p, last);
            previous = g.c.abs();
            root = At::select(done, g, root);
            found = found | done;
            active = active & !done;
            if last || !active.any() {
                break;
            }
            let slope = g.normal.dot(dir);
            active = active & slope.is_finite() & !slope.abs_le(slope.splat(1e-300));
            s = T::select(active, s - g.c / slope, s);
        }
        (s, root, found)
    }

    /// `rattle` on a fixed wire.
    #[inline(always)]
    fn rattle(self, x0: V2<T>, v0: V2<T>, force: &LinearForceLanes<T>, m: T, h: T) -> Advanced<T> {
        let zero = V2::new(m.splat(0.0), m.splat(0.0));
        let g0 = self.at(x0);
        let n0 = g0.normal;
        let (_, mut ok) = self.normal_length_squared(g0);
        let two_m = m.splat(2.0) * m;
        // No friction on the batched wires: the resisting force is zero.
        let free = x0.plus(h, v0).plus(h * h / two_m, force.at(x0) + zero);
        // Newton's last point is `free + s n0`, the new position.
        let (s, g1, found) = self.newton_along(free, n0);
        let x1 = free.plus(s, n0);
        let lambda = two_m * s / (h * h);
        let v_half = (x1 - x0).div(h);
        let n1 = g1.normal;
        let (nn1, usable) = self.normal_length_squared(g1);
        ok = ok & found & usable;
        let w = v_half.plus(h / two_m, force.at(x1) + zero);
        let mu_scaled = -n1.dot(w - zero) / nn1;
        let v1 = w.plus(mu_scaled, n1);
        let mu = two_m * mu_scaled / h;
        let half = m.splat(0.5);
        let constraint_force = (n0.scale(lambda) + n1.scale(mu)).scale(half);
        Advanced {
            x: x1,
            v: v1,
            lambda: half * (lambda + mu),
            constraint_force,
            end: g1,
            start_normal: n0,
            regular: ok,
        }
    }

    /// `v` without its normal component at the point where the circle is
    /// `at` (`tangential`).
    #[inline(always)]
    fn tangential(self, at: At<T>, v: V2<T>) -> (V2<T>, T::Mask) {
        let zero = V2::new(at.c.splat(0.0), at.c.splat(0.0));
        let n = at.normal;
        let (nn, ok) = self.normal_length_squared(at);
        (v - n.scale(n.dot(v - zero) / nn), ok)
    }

    /// `project` from `x`, where the circle is `start`: Newton steps along
    /// the local gradient onto `C = 0`, then the velocity's normal
    /// component removed. Returns the circle where it ends.
    #[inline(always)]
    fn project(self, x: V2<T>, v: V2<T>, start: At<T>) -> (V2<T>, V2<T>, At<T>, T::Mask) {
        let mut x = x;
        let mut active = self.sized();
        let mut found = active & !active;
        let mut end = start;
        let mut previous = start.c.splat(f64::INFINITY);
        for i in 0..=NEWTON_MAX_ITERATIONS {
            let g = if i == 0 { start } else { self.at(x) };
            let last = i == NEWTON_MAX_ITERATIONS;
            let done = active & self.converged(g.c, previous, x, last);
            previous = g.c.abs();
            end = At::select(done, g, end);
            found = found | done;
            active = active & !done;
            if last || !active.any() {
                break;
            }
            let (nn, usable) = self.normal_length_squared(g);
            active = active & usable;
            x = V2::select(active, x - g.normal.scale(g.c / nn), x);
        }
        let (v, ok) = self.tangential(end, v);
        (x, v, end, found & ok)
    }

    /// Eq. (9b) (`restore_speed`) after an Euler step of length `h` from
    /// `(x0, v0)`, where `∇C` was `n0` (usable, as the step's `regular`
    /// lanes hold): the projected velocity `vp` (where the circle is `at`)
    /// scaled to the speed of `v0 + h a_t`, `a_t` the applied acceleration
    /// along the wire at `x0`, and its normal component removed again.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn restore_speed(
        self,
        x0: V2<T>,
        v0: V2<T>,
        n0: V2<T>,
        vp: V2<T>,
        at: At<T>,
        force: &LinearForceLanes<T>,
        m: T,
        h: T,
    ) -> (V2<T>, T::Mask) {
        // A fixed wire: its velocity is zero at both ends of the step.
        let zero = V2::new(m.splat(0.0), m.splat(0.0));
        let relative = v0 - zero;
        let applied = force.at(x0).div(m);
        let kick = applied - n0.scale(n0.dot(applied) / n0.dot(n0));
        let moved = relative.plus(h, kick);
        let target = moved.dot(moved);
        let now = vp - zero;
        // `kinetic_scale`.
        let ratio = target / now.dot(now);
        let scale = T::select(
            ratio.is_finite() & ratio.gt(m.splat(0.0)),
            ratio.sqrt(),
            m.splat(1.0),
        );
        self.tangential(at, zero + now.scale(scale))
    }

    /// Eq. (9c) (`restore_energy`): the projected velocity `vp` at `xp`
    /// (where the circle is `at`) scaled so the energy is that of
    /// `(x0, v0)`, and its normal component removed again.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn restore_energy(
        self,
        x0: V2<T>,
        v0: V2<T>,
        xp: V2<T>,
        vp: V2<T>,
        at: At<T>,
        force: &LinearForceLanes<T>,
        m: T,
    ) -> (V2<T>, T::Mask) {
        let half = m.splat(0.5);
        let potential = |x: V2<T>| {
            let d = x - force.at;
            -force.force.dot(d) + half * force.stiffness * d.dot(d)
        };
        let target = half * m * v0.dot(v0) + potential(x0) - potential(xp);
        let now = half * m * vp.dot(vp);
        let one = m.splat(1.0);
        // `kinetic_scale`, then `energy_scale`'s limit.
        let ratio = target / now;
        let scale = T::select(
            ratio.is_finite() & ratio.gt(m.splat(0.0)),
            ratio.sqrt(),
            one,
        );
        let scale = T::select(
            (scale - one).abs_le(m.splat(ENERGY_CORRECTION_LIMIT)),
            scale,
            one,
        );
        self.tangential(at, vp.scale(scale))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Circle, Placed, Pose};
    use crate::solver::Stabilization;
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
        for method in Method::ALL {
            let batch_settings = StepSettings {
                drift_bound: bound,
                ..settings(method, 1.0 / 60.0)
            };
            let (mut batches, mut singles) = (Vec::new(), Vec::new());
            for k in 0..50 {
                let mut lanes = CircleLanes::default();
                let mut inputs = Vec::new();
                for lane in 0..LANES {
                    let j = (k * LANES + lane) as f64;
                    let radius = 0.5 + (j * 0.37) % 3.0;
                    // Every other batch far from the origin, where rounding
                    // stalls the Newton solves above their tolerance.
                    let far = if k % 2 == 1 { 3.0e4 } else { 0.0 };
                    let centre =
                        DVec2::new((j * 1.3) % 5.0 - 2.5 + far, (j * 0.7) % 4.0 - 2.0 - far);
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
                batches.push(lanes);
                singles.push(outs);
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
            // All the batches in one call: the same, bit for bit.
            let mut many = vec![CircleSteps::default(); batches.len()];
            step_on_circle_batches(&batches, &batch_settings, &mut many);
            let bits = |o: &CircleSteps| {
                [o.x, o.y, o.vx, o.vy, o.lambda, o.fx, o.fy, o.c, o.c_dot]
                    .map(|a| a.map(f64::to_bits))
            };
            for (k, (one, all)) in singles.iter().zip(&many).enumerate() {
                assert_eq!(bits(one), bits(all), "{method} batch {k} in one call");
                assert_eq!(one.done, all.done);
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
    }
}
