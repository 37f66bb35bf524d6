//! The solves on each lane's unrotated circle or sphere: eq. (3), the RK4 stages,
//! RATTLE, projection and the restores of eqs. (10) and (11). Each runs
//! the function the single-bead step runs (in `solve`, `rk4`, `rattle`,
//! `newton`, `restore`), written over [`Lane`], on the circle or sphere as
//! a [`WireAt`].

use std::convert::Infallible;

use crate::geometry::round_geometry;
use crate::lane::{Lane, LaneSpace, Symmetric, Vector};
use crate::solver::newton::{WireAt, newton_onto, tangential};
use crate::solver::rattle::rattle_lanes;
use crate::solver::restore::{bead_energy_scale, speed_scale};
use crate::solver::rk4::Stages;
use crate::solver::settings::StepSettings;
use crate::solver::solve::{ConstraintForce, constraint_force};
use crate::solver::state::LinearForceLanes;
use crate::solver::wire_normal::{along, usable};

/// Eqs. (3)–(4) on each lane's circle or sphere: the geometry, the solve
/// and whether its normal is usable.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
#[inline(always)]
pub(super) fn solve_on_rounds<T: Lane, S: LaneSpace>(
    p: S::Lanes<T>,
    v: S::Lanes<T>,
    centre: S::Lanes<T>,
    radius: T,
    force: &LinearForceLanes<T, S::Lanes<T>>,
    m: T,
    settings: &StepSettings,
) -> (ConstraintForce<T, S::Lanes<T>>, S::Lanes<T>, T::Mask) {
    let g = round_geometry::<S, T>(p - centre, radius);
    let hv = g.hessian.apply(v);
    let solved = constraint_force(g.normal, hv, g.c, v, force.at(p), m, settings.gains());
    // The normal's usability as `WireAt::normal_length_squared` has it,
    // from the `|N|²` the solve computed.
    let regular = g.len.is_nonzero() & usable(solved.nn);
    (solved, g.normal, regular)
}

/// The RK4 stages of the lanes: eq. (4) on each lane's circle or sphere,
/// noting which lanes met a singular point.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(super) struct RoundStages<'a, T: Lane, S: LaneSpace> {
    pub(super) centre: S::Lanes<T>,
    pub(super) radius: T,
    pub(super) force: &'a LinearForceLanes<T, S::Lanes<T>>,
    pub(super) m: T,
    pub(super) settings: &'a StepSettings,
    pub(super) regular: T::Mask,
}

impl<T: Lane, S: LaneSpace> Stages<T, S::Lanes<T>> for RoundStages<'_, T, S> {
    type Error = Infallible;
    #[inline(always)]
    fn acceleration(
        &mut self,
        x: S::Lanes<T>,
        v: S::Lanes<T>,
        _at: f64,
    ) -> Result<S::Lanes<T>, Infallible> {
        let (solved, _, ok) = solve_on_rounds::<T, S>(
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

/// A circle's or sphere's `|p|`, `C` and `∇C` at a point of each lane:
/// what the steps below reuse instead of evaluating the same point again.
#[derive(Clone, Copy)]
pub(super) struct At<T: Lane, V> {
    pub(super) len: T,
    pub(super) c: T,
    pub(super) normal: V,
}

impl<T: Lane, V: Vector<T>> At<T, V> {
    /// `a` in the lanes where `mask` holds, `b` in the others.
    #[inline(always)]
    fn select(mask: T::Mask, a: Self, b: Self) -> Self {
        Self {
            len: T::select(mask, a.len, b.len),
            c: T::select(mask, a.c, b.c),
            normal: V::select(mask, a.normal, b.normal),
        }
    }
}

/// What a step's integrator hands back on the lanes, before the
/// divergence check and the projection.
#[derive(Clone, Copy)]
pub(super) struct Advanced<T: Lane, V> {
    pub(super) x: V,
    pub(super) v: V,
    /// λ and `λN` as the step reports them.
    pub(super) lambda: T,
    pub(super) constraint_force: V,
    /// The circle or sphere at the new position.
    pub(super) end: At<T, V>,
    /// `∇C` at the start, where the lanes with a usable one are `regular`.
    pub(super) start_normal: V,
    /// The lanes the integrator finished.
    pub(super) regular: T::Mask,
}

/// Each lane's unrotated circle or sphere, for the steps that solve on it: RATTLE,
/// projection and the restores, by the functions that
/// [`rattle`](fn@crate::solver::rattle), [`project`](crate::solver::project)
/// and the restores run for one bead (on a fixed wire, with no surface),
/// so each lane returns their bits. Each also returns the lanes where the
/// scalar function would have succeeded; the others mean nothing.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(super) struct OnRounds<T: Lane, S: LaneSpace> {
    pub(super) centre: S::Lanes<T>,
    pub(super) radius: T,
}

impl<T: Lane, S: LaneSpace> Clone for OnRounds<T, S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T: Lane, S: LaneSpace> Copy for OnRounds<T, S> {}

impl<T: Lane, S: LaneSpace> WireAt<T> for OnRounds<T, S> {
    type V = S::Lanes<T>;
    type At = At<T, S::Lanes<T>>;
    /// The circle or sphere at `p`.
    #[inline(always)]
    fn at(&self, p: Self::V) -> Self::At {
        let g = round_geometry::<S, T>(p - self.centre, self.radius);
        At {
            len: g.len,
            c: g.c,
            normal: g.normal,
        }
    }
    #[inline(always)]
    fn c(at: &Self::At) -> T {
        at.c
    }
    #[inline(always)]
    fn normal(at: &Self::At) -> Self::V {
        at.normal
    }
    /// `|N|²` where the normal is usable (the scalar step's
    /// `normal_length_squared`): not at the centre, finite, not vanishing.
    #[inline(always)]
    fn normal_length_squared(at: &Self::At) -> (T, T::Mask) {
        let nn = at.normal.dot(at.normal);
        (nn, at.len.is_nonzero() & usable(nn))
    }
    #[inline(always)]
    fn select(mask: T::Mask, a: Self::At, b: Self::At) -> Self::At {
        At::select(mask, a, b)
    }
    /// A fixed wire's: zero.
    #[inline(always)]
    fn velocity(&self, _: Self::V) -> Self::V {
        S::splat(self.radius.splat(0.0))
    }
}

#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
impl<T: Lane, S: LaneSpace> OnRounds<T, S> {
    /// The lanes whose scale is the radius itself (`scale().max(MIN_POSITIVE)`).
    #[inline(always)]
    fn sized(self) -> T::Mask {
        self.radius.gt(self.radius.splat(f64::MIN_POSITIVE))
    }

    /// `rattle` on a fixed wire.
    #[inline(always)]
    pub(super) fn rattle(
        self,
        x0: S::Lanes<T>,
        v0: S::Lanes<T>,
        force: &LinearForceLanes<T, S::Lanes<T>>,
        m: T,
        h: T,
    ) -> Advanced<T, S::Lanes<T>> {
        let g0 = self.at(x0);
        let (_, ok) = Self::normal_length_squared(&g0);
        // No friction on the batched wires: the resisting force is zero.
        let zero = self.velocity(x0);
        let step = rattle_lanes(
            &self,
            (x0, v0),
            g0.normal,
            force,
            zero,
            m,
            h,
            self.radius,
            self.sized(),
        );
        Advanced {
            x: step.x,
            v: step.v,
            lambda: step.lambda,
            constraint_force: step.constraint_force,
            end: step.root.at,
            start_normal: g0.normal,
            regular: ok & step.root.found & step.end_usable,
        }
    }

    /// `project` from `x`, where the circle is `start`: Newton steps along
    /// the local gradient onto `C = 0`, then the velocity's normal
    /// component removed. Returns the circle where it ends.
    #[inline(always)]
    pub(super) fn project(
        self,
        x: S::Lanes<T>,
        v: S::Lanes<T>,
        start: At<T, S::Lanes<T>>,
    ) -> (S::Lanes<T>, S::Lanes<T>, At<T, S::Lanes<T>>, T::Mask) {
        let onto = newton_onto(&self, x, start, self.radius, self.sized());
        let (v, ok) = tangential(&self, &onto.at, onto.root, v);
        (onto.root, v, onto.at, onto.found & ok)
    }

    /// Eq. (10) (as `restore` takes it) after an Euler step of length `h` from
    /// `(x0, v0)`, where `∇C` was `n0` (usable, as the step's `regular`
    /// lanes hold): the projected velocity `vp` at `xp` (where the circle
    /// is `at`) scaled to the speed of `v0 + h a_t`, `a_t` the applied
    /// acceleration along the wire at `x0`, and its normal component
    /// removed again.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn restore_speed(
        self,
        x0: S::Lanes<T>,
        v0: S::Lanes<T>,
        n0: S::Lanes<T>,
        xp: S::Lanes<T>,
        vp: S::Lanes<T>,
        at: At<T, S::Lanes<T>>,
        force: &LinearForceLanes<T, S::Lanes<T>>,
        m: T,
        h: T,
    ) -> (S::Lanes<T>, T::Mask) {
        let (w0, w1) = (self.velocity(x0), self.velocity(xp));
        let relative = v0 - w0;
        let applied = force.at(x0).div(m);
        let kick = along(n0, n0.dot(n0), applied);
        let now = vp - w1;
        let scale = speed_scale(relative, kick, h, now);
        tangential(&self, &at, xp, w1 + now.scale(scale))
    }

    /// Eq. (11) (as `restore` takes it): the projected velocity `vp` at `xp`
    /// (where the circle is `at`) scaled so the energy is that of
    /// `(x0, v0)`, and its normal component removed again.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn restore_energy(
        self,
        x0: S::Lanes<T>,
        v0: S::Lanes<T>,
        xp: S::Lanes<T>,
        vp: S::Lanes<T>,
        at: At<T, S::Lanes<T>>,
        force: &LinearForceLanes<T, S::Lanes<T>>,
        m: T,
    ) -> (S::Lanes<T>, T::Mask) {
        let scale = bead_energy_scale(force, m, (x0, v0), (xp, vp));
        tangential(&self, &at, xp, vp.scale(scale))
    }
}
