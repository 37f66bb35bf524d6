//! The rows a dense island's step holds, found before its exact solves:
//! projected Gauss–Seidel on the linear complementarity problem of its
//! one-sided rows (../shared/PHYSICS.md, "Many contacts at once"),
//! warm-started from the last step's multipliers. The exact solves
//! (RATTLE's position solve, the velocity projection) then hold those
//! rows, and their checks (a held row that pulls, one let go that
//! overlaps or closes) have little left to correct: a jammed pile at rest
//! settles its held set in one or two passes instead of one pass per row
//! that changes.

use super::{Island, IslandWork};
use crate::geometry::WireSpace;

/// The most sweeps of [`Island::gauss_seidel`].
const SWEEPS: usize = 60;

/// A sweep that changes no multiplier by more than this fraction of the
/// largest ends the iteration.
const SETTLED: f64 = 1e-6;

impl<V: WireSpace> Island<V> {
    /// Projected Gauss–Seidel on rows `candidate`: multipliers `mu` with
    /// `g = g0 + J W Jᵀ μ` (`J` the rows' `gradient`), each one-sided row
    /// (of `side(r)` ±1) pushing only (`side·μ ≥ 0`), violated nowhere
    /// (`side·g ≥ 0`) and pushing only where it is met (`μ·g = 0`),
    /// two-sided rows (`side(r) = 0`) met (`g = 0`). Rows not candidates
    /// keep `μ = 0`. `mu` comes in as the warm start; `moved` is scratch
    /// for `W Jᵀ μ`, bead by bead.
    pub(super) fn gauss_seidel(
        &self,
        (gradient, g0): (&[V], &[f64]),
        candidate: &[bool],
        side: impl Fn(usize) -> f64,
        mu: &mut [f64],
        moved: &mut Vec<V>,
    ) {
        let rows = self.rows();
        // Each row's diagonal of J W Jᵀ; a row that moves nothing is left out.
        let diagonal: Vec<f64> = (0..rows)
            .map(|r| self.normal.diagonal_value(r, &self.inverse_mass, gradient))
            .collect();
        let live = |r: usize| candidate[r] && diagonal[r] > 0.0 && diagonal[r].is_finite();
        moved.clear();
        moved.resize(self.beads(), V::ZERO);
        for (r, m) in mu.iter_mut().enumerate() {
            let side = side(r);
            if !live(r) || (side != 0.0 && side * *m < 0.0) {
                *m = 0.0;
            }
            if *m != 0.0 {
                self.move_along(gradient, r, *m, moved);
            }
        }
        for _ in 0..SWEEPS {
            let (mut change, mut largest) = (0.0f64, 0.0f64);
            for r in 0..rows {
                if !live(r) {
                    continue;
                }
                let g = g0[r] + self.along(r, gradient, moved);
                let side = side(r);
                let mut next = mu[r] - g / diagonal[r];
                if side != 0.0 && side * next < 0.0 {
                    next = 0.0;
                }
                let step = next - mu[r];
                if step != 0.0 {
                    self.move_along(gradient, r, step, moved);
                    mu[r] = next;
                }
                change = change.max((step * diagonal[r]).abs());
                largest = largest.max((next * diagonal[r]).abs());
            }
            if change <= SETTLED * largest {
                break;
            }
        }
    }

    /// Which contact rows a dense island's velocity projection holds,
    /// from Gauss–Seidel on the velocity problem (`g = J v − bias +
    /// J W Jᵀ ν`, the contacts pushing only) over the rows held: a contact
    /// whose multiplier is zero is set aside in `work.inactive`, its
    /// gradient and bias zeroed in `work`. The projection's pivoting
    /// starts from there.
    pub(super) fn predict_pushing(&self, work: &mut IslandWork<V>) {
        let rows = self.rows();
        let candidate: Vec<bool> = work.inactive.iter().map(|&i| !i).collect();
        let g0: Vec<f64> = (0..rows)
            .map(|r| self.rate(r, &work.gradient, &work.v, &work.bias))
            .collect();
        let mut nu = vec![0.0; rows];
        let mut moved = std::mem::take(&mut work.moved);
        let contact = |r: usize| if self.contacts[r] { 1.0 } else { 0.0 };
        self.gauss_seidel(
            (&work.gradient, &g0),
            &candidate,
            contact,
            &mut nu,
            &mut moved,
        );
        work.moved = moved;
        for r in 0..rows {
            if candidate[r] && self.contacts[r] && nu[r] <= 0.0 {
                work.inactive[r] = true;
                work.gradient[self.row_start[r]..self.row_start[r + 1]].fill(V::ZERO);
                work.bias[r] = 0.0;
            }
        }
    }

    /// Which rows a dense island's RATTLE step holds, from Gauss–Seidel
    /// ([`Island::gauss_seidel`]) on the position problem linearized at
    /// the step's start: `g0` the rows' `C` where the beads drift to
    /// without them (`work.x`), the gradients the start's. The candidates
    /// are the rows held and the one-sided rows the step may hold
    /// (`work.touching`); each one-sided candidate is held where its
    /// multiplier pushes and set aside where it is zero. The warm start
    /// is the last step's multiplier (`λ h²/2`, the position multiplier
    /// of a step of `h`). Returns with `work.lambda` holding the
    /// multipliers, zero for rows set aside: the position solve's start.
    pub(super) fn predict_holds(&self, h: f64, time: f64, work: &mut IslandWork<V>) {
        let rows = self.rows();
        let candidate: Vec<bool> = (0..rows)
            .map(|r| {
                !work.inactive[r] || (self.sides[r].0 != 0.0 && work.touching.get(r) == Some(&true))
            })
            .collect();
        let held = std::mem::replace(&mut work.inactive, candidate.iter().map(|&c| !c).collect());
        self.evaluate_at_start(work, time);
        self.evaluate_positions(work);
        let g0 = work.c.clone();
        let warm = work.reports.len() == rows;
        let mut mu: Vec<f64> = (0..rows)
            .map(|r| {
                if warm && candidate[r] {
                    0.5 * h * h * work.reports[r].lambda
                } else {
                    0.0
                }
            })
            .collect();
        let mut moved = std::mem::take(&mut work.moved);
        self.gauss_seidel(
            (&work.first_gradient, &g0),
            &candidate,
            |r| self.sides[r].0,
            &mut mu,
            &mut moved,
        );
        work.moved = moved;
        for r in 0..rows {
            let side = self.sides[r].0;
            work.inactive[r] = if side == 0.0 || !candidate[r] {
                held[r]
            } else {
                side * mu[r] <= 0.0
            };
            if work.inactive[r] {
                mu[r] = 0.0;
            }
        }
        work.lambda = mu;
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;

    use super::super::{Island, IslandRow, IslandWork};
    use crate::solver::coupled::constraint::RowKind;
    use crate::solver::state::BeadState;

    /// A pinned bead with two beads stacked on it and a third hung under
    /// it by a rod, a fourth touching that one from below, all dropped by
    /// `δ` (the pinned one not): the stack is pushed back up onto its
    /// contacts, each carrying the weight above it (`μ` of `(m₁ + m₂) δ`
    /// and `m₂ δ`, to 1e-3), the rod pulls its bead back up (a two-sided
    /// row may), and the bottom contact, whose gap opens, pushes nothing
    /// at all. Every bead ends within 1e-3 of `δ` of where its rows hold
    /// it (measured 4e-4): the sweeps predict which rows push, and the
    /// exact solves that follow meet them.
    #[test]
    fn gauss_seidel_pushes_where_rows_are_met_and_only_there() {
        let (r, delta) = (0.1, 1e-3);
        let masses = [1.0, 2.0, 3.0, 4.0, 5.0];
        let pin = |axis: DVec2| IslandRow {
            kind: RowKind::Axis { axis, offset: 0.0 },
            beads: vec![0],
        };
        let rod = |a: usize, b: usize| IslandRow {
            kind: RowKind::Rod { length: 2.0 * r },
            beads: vec![a, b],
        };
        let rows = vec![
            pin(DVec2::X),
            pin(DVec2::Y),
            rod(0, 1),
            rod(1, 2),
            rod(0, 3),
            rod(3, 4),
        ];
        let mut island = Island::new(&masses, rows, vec![]).expect("a valid island");
        for contact in [2, 3, 5] {
            island.set_contact(contact);
        }
        let heights = [0.0, 2.0 * r, 4.0 * r, -2.0 * r, -4.0 * r];
        let states: Vec<BeadState> = heights
            .iter()
            .map(|&y| BeadState {
                position: DVec2::new(0.0, y),
                velocity: DVec2::ZERO,
            })
            .collect();
        let mut work = IslandWork::default();
        island.begin(0.0, &states, &mut work);
        work.load(&states);
        work.x0.clone_from(&work.x);
        work.v0.clone_from(&work.v);
        work.inactive = vec![false; island.rows()];
        island.evaluate_at_start(&mut work, 0.0);
        for x in &mut work.x[1..] {
            x.y -= delta;
        }
        island.evaluate_positions(&mut work);
        let g0 = work.c.clone();
        let candidate = vec![true; island.rows()];
        let mut mu = vec![0.0; island.rows()];
        let mut moved = Vec::new();
        island.gauss_seidel(
            (&work.first_gradient, &g0),
            &candidate,
            |r| island.sides[r].0,
            &mut mu,
            &mut moved,
        );
        for (i, (&y, m)) in heights.iter().zip(&moved).enumerate() {
            let end = work.x[i].y + m.y;
            let expected = if i == 4 { y - delta } else { y };
            assert!(
                (end - expected).abs() <= 1e-3 * delta,
                "bead {i} ends at {end}, not {expected}"
            );
        }
        // The contacts' gradients are unit vectors along the line of centres.
        let carried = [(2, masses[1] + masses[2]), (3, masses[2])];
        for (row, mass) in carried {
            let expected = mass * delta;
            assert!(
                (mu[row] - expected).abs() <= 1e-3 * expected,
                "contact {row} pushes with {}, not {expected}",
                mu[row]
            );
        }
        assert!(
            (mu[4].abs() - masses[3] * delta).abs() <= 1e-3 * masses[3] * delta,
            "the rod holds its bead with {}",
            mu[4]
        );
        assert_eq!(mu[5], 0.0, "the opening contact pushes nothing");
    }
}
