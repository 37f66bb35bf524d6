//! Post-stabilization on an island, eq. (13): positions back onto the
//! constraints, velocities onto `J v = 0`, and the energy or speed kept.
//! Where a lone bead removes one normal component, an island solves
//! `J W Jᵀ` for all its rows at once; the speed and energy are restored by
//! the lone bead's scale factors, with targets summed over the island.

use crate::geometry::WireSpace;

use super::{Island, IslandWork};
use crate::solver::restore::{energy_scale, kinetic_scale};
use crate::solver::solve::SolveError;
use crate::solver::state::{BeadState, LinearForce};

impl<V: WireSpace> Island<V> {
    /// `Σ ½ m |v|²` of the beads' `velocities`.
    fn kinetic(&self, velocities: impl IntoIterator<Item = V>) -> f64 {
        velocities
            .into_iter()
            .zip(&self.inverse_mass)
            .map(|(v, w)| 0.5 * v.dot(v) / w)
            .sum()
    }

    /// Projects the beads' velocities onto the island's two-sided
    /// constraints at `time`: `v ← v − W Jᵀ (J W Jᵀ)⁻¹ (J v − bias)`, the
    /// velocities nearest the given ones in the kinetic-energy norm that
    /// meet `Ċ = 0` on every rod, pin, joint and two-sided wire (a moving
    /// wire's own velocity kept). One-sided wires and friction's stick
    /// rows are left to the step, which lets a bead leave or land. The
    /// positions are not moved. Returns the kinetic energy before and
    /// after; a state that meets its constraints is returned as it was,
    /// to rounding.
    ///
    /// For the first state of a run: initial velocities that break a
    /// constraint (a crank that turns while its piston is at rest) would
    /// otherwise be projected by the first step, so that the state the
    /// run starts from is not the one simulated.
    pub fn project_velocities(
        &self,
        time: f64,
        states: &mut [BeadState<V>],
        work: &mut IslandWork<V>,
    ) -> Result<(f64, f64), SolveError> {
        let kinetic = |states: &[BeadState<V>]| self.kinetic(states.iter().map(|s| s.velocity));
        let before = kinetic(states);
        if states.len() != self.beads() {
            return Ok((before, before));
        }
        let fresh = work.inactive.len() != self.rows();
        if fresh {
            self.start_rows(time, states, work);
        }
        let held = work.inactive.clone();
        for (r, inactive) in work.inactive.iter_mut().enumerate() {
            *inactive |= self.sides[r].0 != 0.0;
        }
        work.time = time;
        work.load(states);
        self.evaluate_at_new(work);
        let projected = self.project_velocity(work);
        work.inactive = held;
        if fresh {
            // The first step starts its rows from the projected state.
            work.inactive.clear();
        }
        projected?;
        for (state, v) in states.iter_mut().zip(&work.v) {
            state.velocity = *v;
        }
        Ok((before, kinetic(states)))
    }

    /// How the beads' velocities answer an `impulse` on bead `bead` at
    /// `states` and `time`: `Δv = P W f`, the impulse's kick projected in
    /// the kinetic-energy norm onto the rows that hold now (rods, pins,
    /// joints, friction holding a bead still, the wires the beads are
    /// on, not a one-sided wire a bead has left, and the contacts held
    /// between beads pressed together, but not one the impulse would pull
    /// apart: it is let go and the kick projected again). A moving wire's own
    /// velocity does not enter: the answer is linear in the impulse, one
    /// velocity change per bead (eq. 18 for a bead joined to others).
    pub(crate) fn respond<'w>(
        &self,
        time: f64,
        states: &[BeadState<V>],
        bead: usize,
        impulse: V,
        work: &'w mut IslandWork<V>,
    ) -> Result<&'w [V], SolveError> {
        if states.len() != self.beads() || bead >= self.beads() {
            return Err(SolveError::WrongLength {
                beads: self.beads(),
                states: states.len(),
                forces: usize::from(bead < self.beads()),
            });
        }
        self.project_held(time, states, work, |island, work| {
            work.bias.fill(0.0);
            work.v.fill(V::ZERO);
            work.v[bead] = impulse * island.inverse_mass[bead];
        })?;
        Ok(&work.v)
    }

    /// The beads' velocities at `states` and `time` projected onto the
    /// rows that hold now, the contacts held between beads included (one
    /// that would pull is let go, as in [`Island::respond`]): the
    /// velocities nearest the given ones in the kinetic-energy norm that
    /// meet `Ċ = 0` on those rows (a moving wire's own velocity kept).
    /// Where held contacts close, this is an inelastic strike of all of
    /// them at once (Moreau's), each row's impulse (N s, pushing positive)
    /// the second slice; a row not held has none. The rows held are left
    /// as they were.
    pub(crate) fn press<'w>(
        &self,
        time: f64,
        states: &[BeadState<V>],
        work: &'w mut IslandWork<V>,
    ) -> Result<(&'w [V], &'w [f64]), SolveError> {
        if states.len() != self.beads() {
            return Err(SolveError::WrongLength {
                beads: self.beads(),
                states: states.len(),
                forces: self.beads(),
            });
        }
        self.project_held(time, states, work, |_, _| {})?;
        Ok((&work.v, &work.rhs))
    }

    /// The rows evaluated at `states` and `time`, `set` given the work to
    /// put the velocities to project (and their bias) in place, and the
    /// velocities projected onto the rows held, a contact that would pull
    /// let go ([`Island::project_velocity_pushing`]); a row let go there
    /// has no multiplier, and the rows held are left as they were.
    fn project_held(
        &self,
        time: f64,
        states: &[BeadState<V>],
        work: &mut IslandWork<V>,
        set: impl FnOnce(&Self, &mut IslandWork<V>),
    ) -> Result<(), SolveError> {
        self.begin(time, states, work);
        let held = work.inactive.clone();
        work.time = time;
        work.load(states);
        self.evaluate_at_new(work);
        set(self, work);
        let projected = self.project_velocity_pushing(work);
        for (multiplier, &inactive) in work.rhs.iter_mut().zip(&work.inactive) {
            if inactive {
                *multiplier = 0.0;
            }
        }
        work.inactive = held;
        projected
    }

    /// Removes the velocity's component off the constraints:
    /// `v ← v − W Jᵀ (J W Jᵀ)⁻¹ J v` at `work.x` (rows evaluated there).
    /// Returns with the multipliers (of `−J v`) in `work.rhs`.
    pub(super) fn project_velocity(&self, work: &mut IslandWork<V>) -> Result<(), SolveError> {
        if self.rows() == 0 {
            return Ok(());
        }
        self.factor(work, false)?;
        work.rhs.clear();
        for r in 0..self.rows() {
            work.rhs
                .push(-self.rate(r, &work.gradient, &work.v, &work.bias));
        }
        self.normal.solve(&mut work.factored, &mut work.rhs);
        self.push(&work.gradient, &work.rhs, &mut work.v);
        Ok(())
    }

    /// Post-stabilization, eq. (13): Newton steps along the current
    /// gradients bring every `C` to zero and the velocity is projected onto
    /// `J v = 0`; then the velocities are scaled by one factor for the
    /// island (which keeps `J v = 0`). After an Euler step of length `h`
    /// the factor gives the kinetic energy of `v₀ + h P₀ W Q`: the start
    /// velocity plus the step's kick with its part off the constraints at
    /// the start removed (`P₀` the mass-weighted projection onto
    /// `J₀ v = 0`), eq. (10). After RK4 it keeps the energy of a
    /// conservative island (no spring damping) what it was, eq. (11).
    pub(super) fn project(
        &self,
        forces: &[LinearForce<V>],
        restore: Restore,
        work: &mut IslandWork<V>,
    ) -> Result<(), SolveError> {
        self.newton_holding(work)?;
        self.evaluate_at_new(work);
        self.project_velocity_pushing(work)?;
        let kinetic = |v: &[V]| self.kinetic(v.iter().copied());
        let now = kinetic(&work.v);
        let h = match restore {
            Restore::Nothing => return Ok(()),
            Restore::Speed(h) => h,
            Restore::Energy => {
                if self.springs.iter().any(|s| s.damping != 0.0) {
                    return Ok(());
                }
                let potential = |x: &[V]| -> f64 {
                    let applied: f64 = forces.iter().zip(x).map(|(f, x)| f.potential(*x)).sum();
                    applied
                        + self
                            .springs
                            .iter()
                            .map(|s| s.stored(x[s.a], x[s.b]))
                            .sum::<f64>()
                };
                let target = kinetic(&work.v0) + potential(&work.x0) - potential(&work.x);
                let scale = energy_scale(target, now);
                for v in &mut work.v {
                    *v *= scale;
                }
                return Ok(());
            }
        };
        // The applied kick W Q at the start, its part off J₀ removed.
        self.evaluate_at_start(work, work.time - h);
        self.applied(forces, &work.x0, &work.v0, &mut work.force);
        for (f, w) in work.force.iter_mut().zip(&self.inverse_mass) {
            *f *= *w;
        }
        if self.rows() > 0 {
            self.factor(work, true)?;
            work.rhs.clear();
            for r in 0..self.rows() {
                work.rhs
                    .push(-self.along(r, &work.first_gradient, &work.force));
            }
            self.normal.solve(&mut work.factored, &mut work.rhs);
            self.push(&work.first_gradient, &work.rhs, &mut work.force);
        }
        let target: f64 = work
            .v0
            .iter()
            .zip(&work.force)
            .zip(&self.inverse_mass)
            .map(|((v, a), w)| {
                let kicked = *v + *a * h;
                0.5 * kicked.dot(kicked) / w
            })
            .sum();
        let scale = kinetic_scale(target, now);
        for v in &mut work.v {
            *v *= scale;
        }
        // The gradients where the step ended, for the report.
        self.evaluate_at_new(work);
        Ok(())
    }
}

/// How a projection ends (see [`Island::project`]).
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Restore {
    /// As projected: an island on a moving wire, which does work on it.
    Nothing,
    /// The pre-kick speed after an Euler step of this length, eq. (10).
    Speed(f64),
    /// The energy of the step's start after RK4, eq. (11).
    Energy,
}
