//! Islands against the single-bead solver and against physics, by what they
//! test: the methods, the rows, the substeps of a rope, and contact.

use bevy::math::DVec2;

use super::*;
use crate::geometry::{Pose, WireShape};
use crate::solver::test_support::{G, settings};
use crate::solver::{BeadState, LinearForce, Method, StepSettings};

mod contact;
mod methods;
mod ropes;
mod rows;

fn rod(a: usize, b: usize, length: f64) -> IslandRow {
    IslandRow {
        kind: RowKind::Rod { length },
        beads: vec![a, b],
    }
}

fn wire(bead: usize, shape: WireShape, pose: Pose) -> IslandRow {
    IslandRow {
        kind: RowKind::Wire { shape, pose },
        beads: vec![bead],
    }
}

/// The two rows that hold `bead` at `at`.
fn pin(bead: usize, at: DVec2) -> [IslandRow; 2] {
    [DVec2::X, DVec2::Y].map(|axis| IslandRow {
        kind: RowKind::Axis {
            axis,
            offset: axis.dot(at),
        },
        beads: vec![bead],
    })
}

fn at_rest(positions: &[DVec2]) -> Vec<BeadState> {
    positions
        .iter()
        .map(|&position| BeadState {
            position,
            velocity: DVec2::ZERO,
        })
        .collect()
}

fn weights(masses: &[f64]) -> Vec<LinearForce> {
    masses
        .iter()
        .map(|m| LinearForce::constant(*m * G))
        .collect()
}

/// Runs `steps` steps, calling `each` after every one.
fn run(
    island: &Island,
    states: &mut [BeadState],
    forces: &[LinearForce],
    s: &StepSettings,
    steps: usize,
    mut each: impl FnMut(&[BeadState], &IslandWork),
) {
    let mut work = IslandWork::default();
    for i in 0..steps {
        island
            .step(states, forces, s, &mut work)
            .unwrap_or_else(|e| panic!("{}: step {i}: {e}", s.method));
        each(states, &work);
    }
}

fn max_drift(work: &IslandWork, scale: f64) -> f64 {
    work.rows()
        .iter()
        .map(|r| r.c.abs() / scale)
        .fold(0.0, f64::max)
}

/// A pivot pinned at the origin, two rods of length 1, released
/// horizontal: the double pendulum.
fn double_pendulum() -> (Island, Vec<BeadState>, Vec<LinearForce>) {
    let masses = [1.0, 1.0, 1.0];
    let mut rows: Vec<IslandRow> = pin(0, DVec2::ZERO).into();
    rows.push(rod(0, 1, 1.0));
    rows.push(rod(1, 2, 1.0));
    let island = Island::new(&masses, rows, vec![]).unwrap();
    let states = at_rest(&[DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(2.0, 0.0)]);
    (island, states, weights(&masses))
}

/// The double pendulum run `steps` steps under `method` at `dt`: the
/// largest `|C|` and the largest energy change (J) over the run.
fn double_pendulum_run(method: Method, dt: f64, steps: usize) -> (f64, f64) {
    let (island, mut states, forces) = double_pendulum();
    let e0 = island.energy(&states, G).expect("a state per bead");
    let mut worst = (0.0f64, 0.0f64);
    run(
        &island,
        &mut states,
        &forces,
        &settings(method, dt),
        steps,
        |states, work| {
            worst.0 = worst.0.max(max_drift(work, 1.0));
            worst.1 = worst
                .1
                .max((island.energy(states, G).expect("a state per bead") - e0).abs());
        },
    );
    worst
}
