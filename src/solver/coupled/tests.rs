//! Islands against the single-bead solver and against physics: a double
//! pendulum, a pendulum on a cart, a rope, a ring with a redundant row, a
//! spring, and bad input.

use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use bevy::math::DVec2;

use super::*;
use crate::geometry::{Circle, Ellipse, Line, Pose, WireShape};
use crate::solver::test_support::{G, settings};
use crate::solver::{BeadState, LinearForce, Method, Stabilization, StepSettings, step};

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

#[test]
fn one_wire_row_steps_as_the_single_bead_solver() {
    let ellipse = Ellipse { a: 1.5, b: 1.0 };
    let pose = Pose::new(DVec2::new(0.2, -0.1), 0.3);
    let placed = crate::geometry::Placed {
        curve: &ellipse,
        pose,
    };
    let start = BeadState {
        position: pose.to_world(DVec2::new(1.5, 0.0)),
        velocity: DVec2::ZERO,
    };
    let island = Island::new(
        &[2.0],
        vec![wire(0, WireShape::Ellipse(ellipse), pose)],
        vec![],
    )
    .unwrap();
    let force = LinearForce::constant(2.0 * G);
    for method in Method::ALL {
        if matches!(method, Method::ExplicitEuler(_)) {
            continue; // diverges on its own at this step; compared below at a smaller one
        }
        let s = settings(method, 1.0 / 120.0);
        let mut single = start;
        let mut states = vec![start];
        let mut work = IslandWork::default();
        for _ in 0..240 {
            single = step(&placed, single, &force, 2.0, &s).unwrap().state;
            island.step(&mut states, &[force], &s, &mut work).unwrap();
        }
        let gap = (single.position - states[0].position).length()
            + (single.velocity - states[0].velocity).length();
        assert!(
            gap < 1e-9,
            "{method}: the island is {gap:e} from the single bead"
        );
    }
    let s = settings(Method::ExplicitEuler(Stabilization::Baumgarte), 1e-3);
    let (mut single, mut states) = (start, vec![start]);
    let mut work = IslandWork::default();
    for _ in 0..500 {
        single = step(&placed, single, &force, 2.0, &s).unwrap().state;
        island.step(&mut states, &[force], &s, &mut work).unwrap();
    }
    assert!((single.position - states[0].position).length() < 1e-9);
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
    let e0 = island.energy(&states, G);
    let mut worst = (0.0f64, 0.0f64);
    run(
        &island,
        &mut states,
        &forces,
        &settings(method, dt),
        steps,
        |states, work| {
            worst.0 = worst.0.max(max_drift(work, 1.0));
            worst.1 = worst.1.max((island.energy(states, G) - e0).abs());
        },
    );
    worst
}

#[test]
fn double_pendulum_holds_its_rods_and_its_energy() {
    // Chaotic, so only the invariants are tested: the rods to the Newton
    // tolerance (RATTLE, projection) and the energy, whose scale is
    // m g L = 9.81 J. RATTLE's error stays bounded at O(h²); RK4 with
    // projection is fourth order.
    for (method, dt, energy_tolerance) in [
        (Method::Rattle, 1.0 / 240.0, 0.05),
        (Method::Rk4(Stabilization::Projection), 1.0 / 240.0, 0.05),
    ] {
        let worst = double_pendulum_run(method, dt, (10.0 / dt) as usize);
        assert!(worst.0 <= 1e-12, "{method}: |C| reached {:e}", worst.0);
        assert!(
            worst.1 <= energy_tolerance,
            "{method}: energy moved by {:e} J",
            worst.1
        );
    }
}

#[test]
fn baumgarte_keeps_the_double_pendulums_drift_below_none() {
    let drift_after = |stabilization| {
        let (island, mut states, forces) = double_pendulum();
        let mut work = IslandWork::default();
        let s = settings(Method::SemiImplicitEuler(stabilization), 1.0 / 240.0);
        let mut worst = 0.0f64;
        for _ in 0..1200 {
            island.step(&mut states, &forces, &s, &mut work).unwrap();
            worst = worst.max(max_drift(&work, 1.0));
        }
        worst
    };
    let (baumgarte, none) = (
        drift_after(Stabilization::Baumgarte),
        drift_after(Stabilization::None),
    );
    assert!(
        baumgarte < 0.2 * none,
        "drift with Baumgarte {baumgarte:e}, without {none:e}"
    );
}

#[test]
fn pendulum_on_a_cart_conserves_momentum_and_swings_at_the_coupled_frequency() {
    // Cart of mass M on a horizontal line, bob of mass m on a rod of
    // length l: ω² = (g/l)(M + m)/M for small swings.
    let (cart, bob, l) = (2.0, 1.0, 1.0);
    let theta: f64 = 1f64.to_radians();
    let island = Island::new(
        &[cart, bob],
        vec![
            wire(0, WireShape::Line(Line), Pose::default()),
            rod(0, 1, l),
        ],
        vec![],
    )
    .unwrap();
    let mut states = at_rest(&[DVec2::ZERO, DVec2::new(l * theta.sin(), -l * theta.cos())]);
    let forces = weights(&[cart, bob]);
    let dt = 1.0 / 1000.0;
    let mut crossings = Vec::new();
    let mut previous = states[1].position.x - states[0].position.x;
    let mut t = 0.0;
    let mut momentum = 0.0f64;
    let mut drift = 0.0f64;
    run(
        &island,
        &mut states,
        &forces,
        &settings(Method::Rattle, dt),
        8000,
        |states, work| {
            drift = drift.max(max_drift(work, 1.0));
            t += dt;
            let offset = states[1].position.x - states[0].position.x;
            if previous > 0.0 && offset <= 0.0 {
                crossings.push(t - dt * offset / (offset - previous));
            }
            previous = offset;
            let p = cart * states[0].velocity.x + bob * states[1].velocity.x;
            momentum = momentum.max(p.abs());
        },
    );
    let periods = (crossings.len() - 1) as f64;
    let measured = (crossings[crossings.len() - 1] - crossings[0]) / periods;
    let exact = TAU / ((9.81 / l) * (cart + bob) / cart).sqrt();
    assert!(
        (measured / exact - 1.0).abs() < 1e-3,
        "period {measured} against {exact}"
    );
    // Zero to 1e-12 of m sqrt(g l) = 3.13 kg·m/s, and the rod and the rail
    // to rounding.
    assert!(
        momentum < 1e-12 * bob * (9.81 * l).sqrt(),
        "horizontal momentum reached {momentum:e}"
    );
    assert!(drift <= 1e-12, "|C| reached {drift:e}");
}

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
    let e0 = island.energy(&states, G);
    let (mut worst, mut energy, mut halved) = (0.0f64, 0.0f64, 0);
    run(
        &island,
        &mut states,
        &weights(&masses),
        &settings(Method::Rattle, 1.0 / steps_per_second),
        (10.0 * steps_per_second) as usize,
        |states, work| {
            worst = worst.max(max_drift(work, l));
            energy = energy.max((island.energy(states, G) - e0).abs());
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

/// Six beads on a unit circle joined in a closed ring of rods: twelve
/// rows on twelve coordinates with one motion left, so one row is
/// redundant.
fn ring() -> (Island, Vec<BeadState>) {
    let n = 6;
    let circle = WireShape::Circle(Circle { radius: 1.0 });
    let chord = 2.0 * (PI / n as f64).sin();
    let mut rows: Vec<IslandRow> = (0..n)
        .map(|i| wire(i, circle.clone(), Pose::default()))
        .collect();
    rows.extend((0..n).map(|i| rod(i, (i + 1) % n, chord)));
    let island = Island::new(&vec![1.0; n], rows, vec![]).unwrap();
    let states = (0..n)
        .map(|i| {
            let angle = TAU * i as f64 / n as f64;
            let radial = DVec2::from_angle(angle);
            BeadState {
                position: radial,
                velocity: 2.0 * radial.perp(),
            }
        })
        .collect();
    (island, states)
}

#[test]
fn a_ring_with_a_redundant_row_turns_steadily() {
    // Gravity exerts no torque on the symmetric ring, so it turns at a
    // constant rate, here 2 rad/s.
    for method in [Method::Rattle, Method::Rk4(Stabilization::Projection)] {
        let (island, mut states) = ring();
        let forces = weights(&[1.0; 6]);
        let mut worst = (0.0f64, 0.0f64);
        let mut redundant = 0;
        run(
            &island,
            &mut states,
            &forces,
            &settings(method, 1.0 / 60.0),
            600,
            |states, work| {
                redundant = redundant.max(work.redundant());
                worst.0 = worst.0.max(max_drift(work, 1.0));
                for s in states {
                    let rate = s.position.perp_dot(s.velocity) / s.position.length_squared();
                    worst.1 = worst.1.max((rate - 2.0).abs());
                }
            },
        );
        assert!(redundant >= 1, "{method}: no row was found redundant");
        assert!(worst.0 <= 1e-12, "{method}: |C| reached {:e}", worst.0);
        // RK4's phase error on a uniform turn, (ωh)⁵/120 a step, is
        // 3.5e-10 here: 2e-7 over 600 steps.
        assert!(worst.1 <= 2e-7, "{method}: the rate moved by {:e}", worst.1);
    }
}

#[test]
fn the_same_rod_twice_moves_as_one_rod() {
    let pendulum = |rods: usize| {
        let mut rows: Vec<IslandRow> = pin(0, DVec2::ZERO).into();
        rows.extend((0..rods).map(|_| rod(0, 1, 1.0)));
        let island = Island::new(&[1.0, 1.0], rows, vec![]).unwrap();
        let mut states = at_rest(&[DVec2::ZERO, DVec2::new(1.0, 0.0)]);
        let mut lambdas = Vec::new();
        run(
            &island,
            &mut states,
            &weights(&[1.0, 1.0]),
            &settings(Method::Rk4(Stabilization::Baumgarte), 1.0 / 120.0),
            240,
            |_, work| lambdas.push(work.rows()[2..].iter().map(|r| r.lambda).sum::<f64>()),
        );
        (states[1], lambdas)
    };
    let ((one, one_lambda), (two, two_lambda)) = (pendulum(1), pendulum(2));
    assert!(two.is_finite());
    assert!((one.position - two.position).length() < 1e-9);
    for (a, b) in one_lambda.iter().zip(&two_lambda) {
        assert!((a - b).abs() < 1e-9 * a.abs().max(1.0), "λ {a} against {b}");
    }
}

#[test]
fn a_spring_between_beads_on_a_line_oscillates_at_its_frequency() {
    // Relative motion of two masses joined by a spring: ω² = k (1/m₁ + 1/m₂).
    let (m1, m2, k) = (1.0, 2.0, 50.0);
    let line = WireShape::Line(Line);
    let island = Island::new(
        &[m1, m2],
        vec![
            wire(0, line.clone(), Pose::default()),
            wire(1, line, Pose::default()),
        ],
        vec![SpringLink {
            a: 0,
            b: 1,
            rest_length: 1.0,
            stiffness: k,
            damping: 0.0,
        }],
    )
    .unwrap();
    let mut states = at_rest(&[DVec2::ZERO, DVec2::new(1.2, 0.0)]);
    let dt = 1e-3;
    let (mut t, mut previous, mut crossings) = (0.0, 0.2, Vec::new());
    run(
        &island,
        &mut states,
        &weights(&[m1, m2]),
        &settings(Method::Rk4(Stabilization::Projection), dt),
        3000,
        |states, _| {
            t += dt;
            let stretch = states[1].position.x - states[0].position.x - 1.0;
            if previous > 0.0 && stretch <= 0.0 {
                crossings.push(t - dt * stretch / (stretch - previous));
            }
            previous = stretch;
        },
    );
    // The first downward crossing is a quarter period in.
    let omega = (k * (1.0 / m1 + 1.0 / m2)).sqrt();
    assert!((crossings[0] - 0.25 * TAU / omega).abs() < 1e-6);
    assert!((crossings[1] - crossings[0] - TAU / omega).abs() < 1e-6);
}

/// A rod written as a game's own constraint.
struct DistanceConstraint(f64);

impl Constraint for DistanceConstraint {
    fn value(&self, x: &[DVec2]) -> f64 {
        (x[0] - x[1]).length() - self.0
    }
    fn gradient(&self, x: &[DVec2], gradient: &mut [DVec2]) {
        let n = (x[0] - x[1]).normalize();
        gradient[0] = n;
        gradient[1] = -n;
    }
    fn curvature(&self, x: &[DVec2], v: &[DVec2]) -> f64 {
        let d = x[0] - x[1];
        let u = v[0] - v[1];
        let along = u.dot(d) / d.length();
        (u.length_squared() - along * along) / d.length()
    }
}

#[test]
fn a_custom_constraint_steps_as_the_built_in_rod() {
    let run_with = |kind: RowKind| {
        let mut rows: Vec<IslandRow> = pin(0, DVec2::ZERO).into();
        rows.push(IslandRow {
            kind,
            beads: vec![0, 1],
        });
        let island = Island::new(&[1.0, 3.0], rows, vec![]).unwrap();
        let mut states = at_rest(&[DVec2::ZERO, DVec2::new(0.6, -0.8)]);
        run(
            &island,
            &mut states,
            &weights(&[1.0, 3.0]),
            &settings(Method::Rattle, 1.0 / 60.0),
            300,
            |_, _| {},
        );
        states[1]
    };
    let built_in = run_with(RowKind::Rod { length: 1.0 });
    let custom = run_with(RowKind::Custom(Arc::new(DistanceConstraint(1.0))));
    assert!((built_in.position - custom.position).length() < 1e-12);
}

#[test]
fn bad_islands_are_refused_in_words() {
    let refuse = |masses: &[f64], rows: Vec<IslandRow>| {
        Island::new(masses, rows, vec![])
            .err()
            .expect("refused")
            .to_string()
    };
    assert_eq!(
        refuse(&[1.0], vec![rod(0, 0, 1.0)]),
        "constraint 0 (rod) joins bead 0 to itself"
    );
    assert_eq!(
        refuse(&[1.0], vec![rod(0, 3, 1.0)]),
        "constraint 0 (rod) names bead 3, but there are only 1 beads"
    );
    assert_eq!(
        refuse(&[1.0, 1.0], vec![rod(0, 1, 0.0)]),
        "constraint 0 (rod): length must be positive and finite, got 0"
    );
    assert_eq!(
        refuse(&[1.0, -2.0], vec![rod(0, 1, 1.0)]),
        "bead 1 has mass -2; a mass must be positive and finite"
    );
    let spring = SpringLink {
        a: 0,
        b: 1,
        rest_length: f64::NAN,
        stiffness: 1.0,
        damping: 0.0,
    };
    assert_eq!(
        Island::new(&[1.0, 1.0], vec![], vec![spring])
            .err()
            .expect("refused")
            .to_string(),
        "spring 0: rest length must be zero or more and finite, got NaN"
    );
}

#[test]
fn a_rod_of_two_coincident_beads_is_a_singular_point_not_a_nan() {
    let (island, _, forces) = double_pendulum();
    let mut states = at_rest(&[DVec2::ZERO, DVec2::ZERO, DVec2::new(1.0, 0.0)]);
    let before = states.clone();
    for method in Method::ALL {
        let err = island
            .step(
                &mut states,
                &forces,
                &settings(method, 0.01),
                &mut IslandWork::default(),
            )
            .unwrap_err();
        assert!(
            matches!(err, crate::solver::SolveError::Singular { .. }),
            "{method}: {err}"
        );
        assert_eq!(states, before, "{method}: the state changed");
    }
}

#[test]
fn a_long_rope_at_a_sixtieth_is_stepped_in_substeps_that_follow_its_whips() {
    // A rope of 100 rods of 0.1 m released horizontal, RATTLE at 1/60 s
    // for 10 s: its free end whips round faster than whole steps can
    // follow, so steps are split, down to where the last step ended and
    // back up once the whip has passed; no step may fail.
    let (n, l) = (100, 0.1);
    let (island, mut states, masses) = horizontal_rope(n, l);
    let e0 = island.energy(&states, G);
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
            energy = energy.max((island.energy(states, G) - e0).abs());
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
    let e0 = island.energy(&states, G);
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
            energy = energy.max((island.energy(states, G) - e0).abs());
        },
    );
    assert!(fewest >= 4, "a step took only {fewest} substeps");
    assert!(worst <= 1e-12, "max |C|/L = {worst:e}");
    // ½ m v² = 112.5 J; RATTLE's bounded error at 36° a substep.
    assert!(energy <= 0.01 * 112.5, "energy moved by {energy} J");
}

#[test]
fn rattle_keeps_a_spring_pair_on_a_track_to_second_order_in_energy() {
    // Two beads on a bowl joined by a stretched spring (5.5 J stored):
    // RATTLE's energy error is O(h²), so a step four times smaller cuts it
    // about sixteenfold.
    use crate::geometry::Parabola;
    let energy_error = |dt: f64| {
        let shape = WireShape::Parabola(Parabola { focal_length: 1.0 });
        let pose = Pose::new(DVec2::new(0.0, -1.0), 0.0);
        let spring = SpringLink {
            a: 0,
            b: 1,
            rest_length: 1.5,
            stiffness: 20.0,
            damping: 0.0,
        };
        let island = Island::new(
            &[1.0, 0.5],
            vec![wire(0, shape.clone(), pose), wire(1, shape, pose)],
            vec![spring],
        )
        .unwrap();
        let mut states = at_rest(&[DVec2::new(-1.5, -0.4375), DVec2::new(0.7, -0.8775)]);
        let e0 = island.energy(&states, G);
        let mut worst = 0.0f64;
        run(
            &island,
            &mut states,
            &weights(&[1.0, 0.5]),
            &settings(Method::Rattle, dt),
            (5.0 / dt) as usize,
            |s, _| worst = worst.max((island.energy(s, G) - e0).abs()),
        );
        worst
    };
    let (coarse, fine) = (energy_error(1.0 / 60.0), energy_error(1.0 / 240.0));
    assert!(coarse < 0.05, "energy moved {coarse} J at 1/60 s");
    let order = (coarse / fine).log(4.0);
    assert!((1.8..2.2).contains(&order), "observed order {order}");
}

#[test]
fn euler_with_projection_adds_no_energy_to_an_island() {
    // The double pendulum at 1/240 s for 10 s: semi-implicit Euler with
    // projection keeps the energy within 5 % of m g L = 9.81 J (0.15 J
    // measured; 17 J without eq. (9b)).
    let worst = double_pendulum_run(
        Method::SemiImplicitEuler(Stabilization::Projection),
        1.0 / 240.0,
        2400,
    );
    assert!(worst.0 <= 1e-12, "|C| reached {:e}", worst.0);
    assert!(worst.1 < 0.05 * 9.81, "energy moved {} J", worst.1);
}

#[test]
fn double_pendulum_energy_stays_bounded_over_1000_seconds_with_rattle() {
    // Chaotic, so the energy error is compared between the first and the
    // last tenth of the run: bounded means no larger at the end (within a
    // factor 2 for the spread of a chaotic path), and the rods hold to
    // rounding throughout.
    let (island, mut states, forces) = double_pendulum();
    let e0 = island.energy(&states, G);
    let steps = 60_000;
    let (mut first, mut last, mut drift) = (0.0f64, 0.0f64, 0.0f64);
    let mut i = 0;
    run(
        &island,
        &mut states,
        &forces,
        &settings(Method::Rattle, 1.0 / 60.0),
        steps,
        |states, work| {
            let error = (island.energy(states, G) - e0).abs();
            if i < steps / 10 {
                first = first.max(error);
            } else if i >= steps - steps / 10 {
                last = last.max(error);
            }
            drift = drift.max(max_drift(work, 1.0));
            i += 1;
        },
    );
    assert!(drift <= 1e-12, "|C| reached {drift:e}");
    assert!(
        last <= 2.0 * first,
        "energy error grew from {first:e} J to {last:e} J"
    );
    assert!(first < 0.05 * 9.81, "energy error {first:e} J");
}

#[test]
fn double_pendulum_keeps_its_energy_to_1e_6_with_rk4_and_projection() {
    // 100 s at 1/240 s: within 1e-6 of m g l = 9.81 J. RK4 alone drifts by
    // 6.7e-6 of it here; eq. (9c) keeps the energy of the conservative
    // island at the start's.
    let (_, worst) =
        double_pendulum_run(Method::Rk4(Stabilization::Projection), 1.0 / 240.0, 24_000);
    assert!(worst < 1e-6 * 9.81, "energy moved {worst:e} J");
}

#[test]
fn a_hanging_chain_at_rest_pulls_with_the_weight_below_each_rod() {
    // Eleven beads of masses 1.0, 1.1, … hanging from a pin on rods of
    // 0.5 m: rod k carries the weight of the beads below it, T = −λ, to
    // 1e-9 of it, whatever the method.
    let n = 10;
    let masses: Vec<f64> = (0..=n).map(|j| 1.0 + 0.1 * j as f64).collect();
    let mut rows: Vec<IslandRow> = pin(0, DVec2::ZERO).into();
    rows.extend((0..n).map(|k| rod(k, k + 1, 0.5)));
    let island = Island::new(&masses, rows, vec![]).unwrap();
    for method in Method::ALL {
        let mut states = at_rest(
            &(0..=n)
                .map(|j| DVec2::new(0.0, -0.5 * j as f64))
                .collect::<Vec<_>>(),
        );
        let mut work = IslandWork::default();
        island
            .step(
                &mut states,
                &weights(&masses),
                &settings(method, 0.01),
                &mut work,
            )
            .unwrap();
        for k in 0..n {
            let below: f64 = masses[k + 1..].iter().sum::<f64>() * 9.81;
            let tension = -work.rows()[2 + k].lambda;
            assert!(
                (tension - below).abs() <= 1e-9 * below,
                "{method}: rod {k} pulls {tension} N, the weight below is {below} N"
            );
        }
    }
}

#[test]
fn each_method_converges_at_its_order_on_the_pendulum_on_a_cart() {
    // The bob's position after 1 s from 30°, against RK4 at 1/3840 s:
    // halving dt divides the error by about 2^order.
    let island = Island::new(
        &[2.0, 1.0],
        vec![
            wire(0, WireShape::Line(Line), Pose::default()),
            rod(0, 1, 1.0),
        ],
        vec![],
    )
    .unwrap();
    let theta: f64 = 30f64.to_radians();
    let start = at_rest(&[DVec2::ZERO, DVec2::new(theta.sin(), -theta.cos())]);
    let forces = weights(&[2.0, 1.0]);
    let end = |method, dt: f64| {
        let mut states = start.clone();
        run(
            &island,
            &mut states,
            &forces,
            &settings(method, dt),
            (1.0 / dt).round() as usize,
            |_, _| {},
        );
        states[1].position
    };
    let reference = end(Method::Rk4(Stabilization::None), 1.0 / 3840.0);
    for (method, dt, order) in [
        (
            Method::ExplicitEuler(Stabilization::Baumgarte),
            1.0 / 960.0,
            1.0,
        ),
        (
            Method::SemiImplicitEuler(Stabilization::Baumgarte),
            1.0 / 960.0,
            1.0,
        ),
        (
            Method::SemiImplicitEuler(Stabilization::Projection),
            1.0 / 960.0,
            1.0,
        ),
        (Method::Rattle, 1.0 / 120.0, 2.0),
        (Method::Rk4(Stabilization::None), 1.0 / 60.0, 4.0),
        (Method::Rk4(Stabilization::Projection), 1.0 / 60.0, 4.0),
    ] {
        let coarse = (end(method, dt) - reference).length();
        let fine = (end(method, dt / 2.0) - reference).length();
        let observed = (coarse / fine).log2();
        assert!(
            (observed - order).abs() <= 0.35,
            "{method}: observed order {observed:.2}, expected {order}"
        );
    }
}

/// Two beads on a line spinning at ω about a point of it (no gravity),
/// joined by a rod along the line: the rod's pull cancels in the centre
/// of mass, which slides out as `r₀ cosh ωt` like a single bead (eq. 13
/// on an island). Every method follows it at its order; the methods that
/// hold the constraints hold all three rows.
#[test]
fn a_rod_on_a_spinning_line_slides_out_as_cosh_at_each_methods_order() {
    use crate::geometry::{PosePath, Spin, WireMotion};
    let omega = 2.0;
    let path = PosePath::Prescribed {
        base: Pose::IDENTITY,
        motion: WireMotion::Spin(Spin {
            angular_velocity: omega,
        }),
    };
    let masses = [1.0, 3.0];
    let start = [DVec2::new(0.8, 0.0), DVec2::new(0.4, 0.0)];
    let centre0 = (start[0] * masses[0] + start[1] * masses[1]).x / 4.0;
    let end = 1.5;
    let exact = centre0 * (omega * end).cosh();
    let line = WireShape::Line(Line);
    let run_to_end = |method: Method, dt: f64| {
        let mut island = Island::new(
            &masses,
            vec![
                wire(0, line.clone(), Pose::IDENTITY),
                wire(1, line.clone(), Pose::IDENTITY),
                rod(0, 1, 0.4),
            ],
            vec![],
        )
        .unwrap();
        island.move_wire(0, None, path);
        island.move_wire(1, None, path);
        let twist = path.at(0.0).1;
        let mut states: Vec<BeadState> = start
            .iter()
            .map(|&position| BeadState {
                position,
                velocity: twist.velocity_at(position),
            })
            .collect();
        let forces = vec![LinearForce::default(); 2];
        let s = settings(method, dt);
        let mut work = IslandWork::default();
        let mut worst = 0.0f64;
        let steps = (end / dt).round() as usize;
        for k in 0..steps {
            island
                .step_at(k as f64 * dt, &mut states, &forces, &s, &mut work)
                .unwrap_or_else(|e| panic!("{method}: step {k}: {e}"));
            worst = worst.max(max_drift(&work, 0.4));
        }
        let centre = (states[0].position * masses[0] + states[1].position * masses[1]) / 4.0;
        ((centre.length() - exact).abs() / exact, worst)
    };
    for (method, order, held) in [
        (
            Method::SemiImplicitEuler(Stabilization::Baumgarte),
            1.0,
            0.2,
        ),
        (
            Method::SemiImplicitEuler(Stabilization::Projection),
            1.0,
            1e-12,
        ),
        (Method::Rk4(Stabilization::None), 4.0, 1e-5),
        (Method::Rk4(Stabilization::Projection), 4.0, 1e-12),
        (Method::Rattle, 2.0, 1e-12),
    ] {
        let (e1, c1) = run_to_end(method, 1.0 / 200.0);
        let (e2, _) = run_to_end(method, 1.0 / 400.0);
        let observed = (e1 / e2).log2();
        eprintln!("{method}: error at 1/200 s {e1:e}, order {observed:.3}, |C|/L {c1:e}");
        assert!(
            (observed - order).abs() < 0.3,
            "{method}: relative errors {e1:e}, {e2:e}, order {observed}"
        );
        assert!(c1 <= held, "{method}: |C|/L reached {c1:e}");
    }
}

/// A cart of two beads joined by a rod, dropped from 1 m onto a one-sided
/// floor (`Positive`: it only pushes up), both beads on it: with
/// restitution 0 it lands and stays, exactly on the floor and at rest,
/// held by λ ≥ 0; with restitution ½ it bounces to a quarter of the drop.
#[test]
fn a_two_bead_cart_lands_on_a_one_sided_floor_and_stays_or_bounces() {
    use crate::geometry::Side;
    let floor = WireShape::Line(Line);
    let drop = 1.0;
    for restitution in [0.0, 0.5] {
        let mut island = Island::new(
            &[1.0, 1.0],
            vec![
                wire(0, floor.clone(), Pose::IDENTITY),
                wire(1, floor.clone(), Pose::IDENTITY),
                rod(0, 1, 1.0),
            ],
            vec![],
        )
        .unwrap();
        island.set_side(0, Side::Positive, restitution);
        island.set_side(1, Side::Positive, restitution);
        let mut states = at_rest(&[DVec2::new(0.0, drop), DVec2::new(1.0, drop)]);
        let forces = weights(&[1.0, 1.0]);
        let s = settings(Method::Rattle, 1.0 / 240.0);
        let mut work = IslandWork::default();
        let (mut landings, mut top_after, mut landed) = (Vec::new(), 0.0f64, false);
        for k in 0..480 {
            let t = k as f64 / 240.0;
            island
                .step_at(t, &mut states, &forces, &s, &mut work)
                .unwrap();
            for &(_, _, event) in work.events() {
                if let crate::solver::ContactEvent::Landed { normal_speed, .. } = event {
                    landings.push(normal_speed);
                    landed = true;
                }
            }
            if landed {
                top_after = top_after.max(states[0].position.y);
            }
            if landed && restitution == 0.0 {
                for (r, report) in work.rows().iter().enumerate().take(2) {
                    assert!(work.holds(r), "row {r} let go at step {k}");
                    assert!(
                        report.lambda >= 0.0,
                        "the floor pulled: λ = {}",
                        report.lambda
                    );
                }
            }
        }
        let impact = (2.0 * 9.81 * drop).sqrt();
        if restitution == 0.0 {
            assert_eq!(landings.len(), 2, "{landings:?}");
        } else {
            // Each bounce lands at half the speed of the one before.
            assert!(landings.len() >= 4, "{landings:?}");
            for speed in &landings[2..4] {
                let expected = restitution * impact;
                assert!(
                    (speed - expected).abs() < 2.0 * 9.81 / 240.0,
                    "landed again at {speed}, not {expected}"
                );
            }
        }
        for speed in &landings[..2] {
            assert!(
                (speed - impact).abs() < 9.81 / 240.0,
                "landed at {speed}, not {impact}"
            );
        }
        if restitution == 0.0 {
            for state in &states {
                assert!(state.position.y.abs() < 1e-12, "{state:?}");
                assert!(state.velocity.length() < 1e-12, "{state:?}");
            }
        } else {
            let expected = restitution * restitution * drop;
            let error = (top_after - expected).abs() / expected;
            eprintln!(
                "bounce: up to {top_after:.4} m, expected {expected} (relative error {error:.2e})"
            );
            assert!(error < 0.05, "bounced to {top_after}, not {expected}");
        }
    }
}

/// A two-bead cart going over the top of a one-sided hump (`Positive`
/// outside a circle of radius 2) faster than `sqrt(g r)` leaves it at once:
/// both rows are set aside, and the cart flies as a rigid body, its centre
/// of mass falling at `g` to 1e-9 while the rod holds.
#[test]
fn a_two_bead_cart_too_fast_for_a_one_sided_hump_flies_off_it() {
    use crate::geometry::Side;
    let hump = WireShape::Circle(Circle { radius: 2.0 });
    let mut island = Island::new(
        &[1.0, 1.0],
        vec![
            wire(0, hump.clone(), Pose::IDENTITY),
            wire(1, hump.clone(), Pose::IDENTITY),
            rod(0, 1, 4.0 * 5f64.to_radians().sin()),
        ],
        vec![],
    )
    .unwrap();
    island.set_side(0, Side::Positive, 0.0);
    island.set_side(1, Side::Positive, 0.0);
    let speed = 5.0; // v² / r = 12.5 > g
    let mut states: Vec<BeadState> = [-5f64, 5.0]
        .map(|deg| {
            let a = deg.to_radians();
            BeadState {
                position: 2.0 * DVec2::new(a.sin(), a.cos()),
                velocity: speed * DVec2::new(a.cos(), -a.sin()),
            }
        })
        .to_vec();
    let forces = weights(&[1.0, 1.0]);
    let h = 1.0 / 240.0;
    let s = settings(Method::Rattle, h);
    let mut work = IslandWork::default();
    island
        .step_at(0.0, &mut states, &forces, &s, &mut work)
        .unwrap();
    let left = work
        .events()
        .iter()
        .filter(|e| matches!(e.2, crate::solver::ContactEvent::Left { .. }))
        .count();
    assert_eq!(left, 2, "{:?}", work.events());
    let centre = |s: &[BeadState]| 0.5 * (s[0].velocity + s[1].velocity);
    let mut worst = 0.0f64;
    for k in 1..60 {
        let before = centre(&states);
        island
            .step_at(k as f64 * h, &mut states, &forces, &s, &mut work)
            .unwrap();
        assert!(!work.holds(0) && !work.holds(1));
        worst = worst.max(((centre(&states) - before) / h - G).length());
        let stretch =
            (states[0].position - states[1].position).length() - 4.0 * 5f64.to_radians().sin();
        assert!(stretch.abs() < 1e-12, "the rod stretched by {stretch:e}");
    }
    assert!(
        worst < 1e-9,
        "the centre of mass fell at g off by {worst:e}"
    );
}

/// A cart of two beads joined by a rod, both on a rough line tilted by
/// `degrees`, the rough rows with their stick rows.
fn rough_cart(degrees: f64, friction: crate::geometry::Friction) -> Island {
    let line = WireShape::Line(Line);
    let pose = Pose::new(DVec2::ZERO, degrees.to_radians());
    let stick = |bead| IslandRow {
        kind: RowKind::Axis {
            axis: DVec2::X,
            offset: 0.0,
        },
        beads: vec![bead],
    };
    let mut island = Island::new(
        &[1.0, 2.0],
        vec![
            wire(0, line.clone(), pose),
            wire(1, line.clone(), pose),
            rod(0, 1, 0.5),
            stick(0),
            stick(1),
        ],
        vec![],
    )
    .unwrap();
    island.set_rough(0, friction, 0.0, Some(3));
    island.set_rough(1, friction, 0.0, Some(4));
    island
}

/// Friction in an island: a two-bead cart sent at 3 m/s along a rough
/// horizontal line (μk = 0.3) stops after `v0² / (2 μk g)` and stays; from
/// rest on a slope gentler than `atan μs` it stays exactly where it is,
/// on a steeper one it slides.
#[test]
fn a_two_bead_cart_on_a_rough_line_stops_at_the_coulomb_distance_and_sticks() {
    use crate::geometry::Friction;
    let friction = Friction::new(0.5, 0.3).unwrap();
    let forces = weights(&[1.0, 2.0]);
    let h = 1.0 / 240.0;
    for method in [Method::Rattle, Method::Rk4(Stabilization::Projection)] {
        let s = settings(method, h);
        let island = rough_cart(0.0, friction);
        let v0 = 3.0;
        let mut states: Vec<BeadState> = [0.5, 0.0]
            .map(|x| BeadState {
                position: DVec2::new(x, 0.0),
                velocity: DVec2::new(v0, 0.0),
            })
            .to_vec();
        let mut work = IslandWork::default();
        for k in 0..720 {
            island
                .step_at(k as f64 * h, &mut states, &forces, &s, &mut work)
                .unwrap();
        }
        let expected = v0 * v0 / (2.0 * 0.3 * 9.81);
        let travelled = states[1].position.x;
        let error = (travelled - expected).abs() / expected;
        eprintln!("{method}: the cart stopped after {travelled:.6} m (relative error {error:.2e})");
        assert!(
            error < 1e-3,
            "{method}: stopped after {travelled}, not {expected}"
        );
        assert!(
            states.iter().all(|s| s.velocity.length() < 1e-9),
            "{states:?}"
        );
    }
    let limit = 0.5f64.atan().to_degrees();
    for (degrees, slides) in [(limit - 2.0, false), (limit + 2.0, true)] {
        let island = rough_cart(degrees, friction);
        let a = degrees.to_radians();
        let start: Vec<BeadState> = [0.5, 0.0]
            .map(|d| BeadState {
                position: d * DVec2::new(a.cos(), a.sin()),
                velocity: DVec2::ZERO,
            })
            .to_vec();
        let mut states = start.clone();
        let mut work = IslandWork::default();
        let s = settings(Method::Rattle, h);
        for k in 0..240 {
            island
                .step_at(k as f64 * h, &mut states, &forces, &s, &mut work)
                .unwrap();
        }
        let moved = (states[1].position - start[1].position).length();
        if slides {
            assert!(moved > 0.1, "at {degrees:.1}° the cart stuck");
        } else {
            assert!(moved < 1e-12, "at {degrees:.1}° the cart crept {moved:e}");
        }
    }
}
