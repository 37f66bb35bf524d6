//! The solves on each lane's unrotated circle, operation for operation as
//! the single-bead step takes them: eq. (3), the RK4 stages, RATTLE,
//! projection and the restores of eq. (9).

use std::convert::Infallible;

use crate::geometry::circle_geometry;
use crate::lane::{Lane, Mask, V2};
use crate::solver::projection::{NEWTON_MAX_ITERATIONS, newton_done, reach};
use crate::solver::restore::{bead_energy_scale, speed_scale};
use crate::solver::rk4::Stages;
use crate::solver::settings::StepSettings;
use crate::solver::solve::{ConstraintForce, constraint_force};
use crate::solver::state::LinearForceLanes;
use crate::solver::wire_normal::{across, along, usable};

/// Eqs. (3)–(4) on each lane's circle: the geometry, the solve and whether
/// its normal is usable.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
#[inline(always)]
pub(super) fn solve_on_circles<T: Lane>(
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
    let regular = g.len.is_nonzero() & usable(nn);
    (solved, g.normal, regular)
}

/// The RK4 stages of the lanes: eq. (4) on each lane's circle, noting
/// which lanes met a singular point.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(super) struct CircleStages<'a, T: Lane> {
    pub(super) centre: V2<T>,
    pub(super) radius: T,
    pub(super) force: &'a LinearForceLanes<T>,
    pub(super) m: T,
    pub(super) settings: &'a StepSettings,
    pub(super) regular: T::Mask,
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

/// A circle's `|p|`, `C` and `∇C` at a point of each lane: what the steps
/// below reuse instead of evaluating the same point again.
#[derive(Clone, Copy)]
pub(super) struct At<T: Lane> {
    pub(super) len: T,
    pub(super) c: T,
    pub(super) normal: V2<T>,
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
pub(super) struct Advanced<T: Lane> {
    pub(super) x: V2<T>,
    pub(super) v: V2<T>,
    /// λ and `λN` as the step reports them.
    pub(super) lambda: T,
    pub(super) constraint_force: V2<T>,
    /// The circle at the new position.
    pub(super) end: At<T>,
    /// `∇C` at the start, where the lanes with a usable one are `regular`.
    pub(super) start_normal: V2<T>,
    /// The lanes the integrator finished.
    pub(super) regular: T::Mask,
}

/// Each lane's unrotated circle, for the steps that solve on it: RATTLE,
/// projection and the energy restore, written as
/// [`rattle`](fn@crate::solver::rattle), [`project`](crate::solver::project)
/// and eq. (11) compute them for one bead (on a fixed wire, with no
/// surface), operation for operation, so each lane returns their bits.
/// Each also returns the lanes where the scalar function would have
/// succeeded; the others mean nothing.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
#[derive(Clone, Copy)]
pub(super) struct OnCircles<T: Lane> {
    pub(super) centre: V2<T>,
    pub(super) radius: T,
}

#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
impl<T: Lane> OnCircles<T> {
    /// The circle at `x`.
    #[inline(always)]
    pub(super) fn at(self, x: V2<T>) -> At<T> {
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
        (nn, at.len.is_nonzero() & usable(nn))
    }

    /// Whether a Newton solve at the point `at` is done at residual `|c|`
    /// after `previous` (`newton_done`, the circle's scale its radius).
    #[inline(always)]
    fn converged(self, c: T, previous: T, at: V2<T>, last: bool) -> T::Mask {
        newton_done(c.abs(), previous, self.radius, reach(at), last)
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
            active = active & usable(slope.abs());
            s = T::select(active, s - g.c / slope, s);
        }
        (s, root, found)
    }

    /// `rattle` on a fixed wire.
    #[inline(always)]
    pub(super) fn rattle(
        self,
        x0: V2<T>,
        v0: V2<T>,
        force: &LinearForceLanes<T>,
        m: T,
        h: T,
    ) -> Advanced<T> {
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
        let (nn, ok) = self.normal_length_squared(at);
        (v - across(at.normal, nn, v - zero), ok)
    }

    /// `project` from `x`, where the circle is `start`: Newton steps along
    /// the local gradient onto `C = 0`, then the velocity's normal
    /// component removed. Returns the circle where it ends.
    #[inline(always)]
    pub(super) fn project(
        self,
        x: V2<T>,
        v: V2<T>,
        start: At<T>,
    ) -> (V2<T>, V2<T>, At<T>, T::Mask) {
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

    /// Eq. (10) (`restore_speed`) after an Euler step of length `h` from
    /// `(x0, v0)`, where `∇C` was `n0` (usable, as the step's `regular`
    /// lanes hold): the projected velocity `vp` (where the circle is `at`)
    /// scaled to the speed of `v0 + h a_t`, `a_t` the applied acceleration
    /// along the wire at `x0`, and its normal component removed again.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn restore_speed(
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
        let kick = along(n0, n0.dot(n0), applied);
        let now = vp - zero;
        let scale = speed_scale(relative, kick, h, now);
        self.tangential(at, zero + now.scale(scale))
    }

    /// Eq. (11) (`restore_energy`): the projected velocity `vp` at `xp`
    /// (where the circle is `at`) scaled so the energy is that of
    /// `(x0, v0)`, and its normal component removed again.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn restore_energy(
        self,
        x0: V2<T>,
        v0: V2<T>,
        xp: V2<T>,
        vp: V2<T>,
        at: At<T>,
        force: &LinearForceLanes<T>,
        m: T,
    ) -> (V2<T>, T::Mask) {
        let scale = bead_energy_scale(force, m, (x0, v0), (xp, vp));
        self.tangential(at, vp.scale(scale))
    }
}
