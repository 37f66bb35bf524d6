//! Ropes released horizontal: the rods and the energy held, and steps
//! halved into substeps where the free end whips round.

use bevy::math::DVec2;

use super::*;

/// A rope of `n` rods of length `l` from a pin at the origin, beads of
/// 1 kg at rest along +x: the island, the states, the masses.
fn horizontal_rope(n: usize, l: f64) -> (Island, Vec<BeadState>, Vec<f64>) {
    let masses = vec![1.0; n + 1];
    let mut rows: Vec<IslandRow> = pin(0, DVec2::ZERO).into();
    rows.extend((0..n).map(|i| rod(i, i + 1, l)));
    let island = Island::new(&masses, rows, vec![]).unwrap();
    let states = at_rest(
        &(0..=n)
            .map(|i| DVec2::new(l * i as f64, 0.0))
            .collect::<Vec<_>>(),
    );
    (island, states, masses)
}

#[test]
fn a_horizontal_rope_keeps_every_rod_and_its_energy() {
    // 20 rods of 0.1 m from a pin, released horizontal, RATTLE for 10 s:
    // the free end whips round, where the chord iteration turns to exact
    // Newton steps. The whip's tension spikes make the taut rope's
    // transverse modes (ω² ≈ 2T/(mL)) stiff: at 1/60 s and 1/240 s the
    // energy error reaches a large part of the energy released, so this
    // runs at 1/960 s.
    let (n, l, steps_per_second) = (20, 0.1, 960.0);
    let (island, mut states, masses) = horizontal_rope(n, l);
    let e0 = island.energy(&states, G).expect("a state per bead");
    let (mut worst, mut energy, mut halved) = (0.0f64, 0.0f64, 0);
    run(
        &island,
        &mut states,
        &weights(&masses),
        &settings(Method::Rattle, 1.0 / steps_per_second),
        (10.0 * steps_per_second) as usize,
        |states, work| {
            worst = worst.max(max_drift(work, l));
            energy = energy.max((island.energy(states, G).expect("a state per bead") - e0).abs());
            halved += usize::from(work.substeps() > 1);
        },
    );
    assert!(worst <= 1e-12, "max |C|/L = {worst:e}");
    // The rope's fall releases m g L n(n+1)/2 = 206 J; at this step
    // RATTLE's energy error stays under 1 % of it (0.6 J measured; 0.11 J
    // at a step four times smaller), and no step needs halving.
    assert!(energy <= 0.01 * 206.0, "energy moved by {energy} J");
    assert_eq!(halved, 0, "{halved} steps were halved");
}

#[test]
fn a_long_rope_at_a_sixtieth_is_stepped_in_substeps_that_follow_its_whips() {
    // A rope of 100 rods of 0.1 m released horizontal, RATTLE at 1/60 s
    // for 10 s: its free end whips round faster than whole steps can
    // follow, so steps are split, down to where the last step ended and
    // back up once the whip has passed; no step may fail.
    let (n, l) = (100, 0.1);
    let (island, mut states, masses) = horizontal_rope(n, l);
    let e0 = island.energy(&states, G).expect("a state per bead");
    let (mut worst, mut energy) = (0.0f64, 0.0f64);
    let mut substeps = Vec::new();
    run(
        &island,
        &mut states,
        &weights(&masses),
        &settings(Method::Rattle, 1.0 / 60.0),
        600,
        |states, work| {
            worst = worst.max(max_drift(work, l));
            energy = energy.max((island.energy(states, G).expect("a state per bead") - e0).abs());
            substeps.push(work.substeps());
        },
    );
    assert!(worst <= 1e-12, "max |C|/L = {worst:e}");
    let most = substeps.iter().copied().max().unwrap_or(0);
    let total: u32 = substeps.iter().sum();
    assert!(most >= 8, "the whips took at most {most} substeps");
    // Back to coarser steps after the finest: the level comes back up.
    let finest = substeps.iter().position(|&s| s == most).unwrap_or(0);
    let after = substeps[finest..].iter().copied().min().unwrap_or(most);
    assert!(
        after <= most / 4,
        "after {most} substeps, never fewer than {after}"
    );
    // 5.9 substeps a step measured: starting where the last step ended
    // keeps the count near what the whips need.
    assert!(total <= 10 * 600, "{total} substeps in 600 steps");
    // The fall releases m g L n(n+1)/2 = 5050 J; RATTLE's error at these
    // steps stays under 10 % of it (215 J measured).
    assert!(energy <= 0.1 * 5050.0, "energy moved by {energy} J");
}

#[test]
fn a_step_with_no_rattle_solution_is_halved() {
    // A bead on a rod of 0.1 m whirling at 15 m/s: in 1/60 s it would
    // travel 0.25 m, more than the rod can reach along its old direction,
    // so RATTLE's position solve has no root; quarter steps (0.0625 m,
    // 36° of turn) do.
    let (l, speed) = (0.1, 15.0);
    let rows: Vec<IslandRow> = pin(0, DVec2::ZERO)
        .into_iter()
        .chain([rod(0, 1, l)])
        .collect();
    let island = Island::new(&[1.0, 1.0], rows, vec![]).unwrap();
    let mut states = vec![
        BeadState::default(),
        BeadState {
            position: DVec2::new(0.0, -l),
            velocity: DVec2::new(speed, 0.0),
        },
    ];
    let e0 = island.energy(&states, G).expect("a state per bead");
    let (mut fewest, mut worst, mut energy) = (u32::MAX, 0.0f64, 0.0f64);
    run(
        &island,
        &mut states,
        &weights(&[1.0, 1.0]),
        &settings(Method::Rattle, 1.0 / 60.0),
        120,
        |states, work| {
            fewest = fewest.min(work.substeps());
            worst = worst.max(max_drift(work, l));
            energy = energy.max((island.energy(states, G).expect("a state per bead") - e0).abs());
        },
    );
    assert!(fewest >= 4, "a step took only {fewest} substeps");
    assert!(worst <= 1e-12, "max |C|/L = {worst:e}");
    // ½ m v² = 112.5 J; RATTLE's bounded error at 36° a substep.
    assert!(energy <= 0.01 * 112.5, "energy moved by {energy} J");
}
