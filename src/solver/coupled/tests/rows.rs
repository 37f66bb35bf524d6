//! What an island's rows may be: redundant, the same rod twice, a game's
//! own constraint, a singular point, and rows refused at building.

use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use bevy::math::DVec2;

use super::*;
use crate::geometry::Circle;
use crate::solver::Stabilization;

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
        Island::<DVec2>::new(&[1.0, 1.0], vec![], vec![spring])
            .err()
            .expect("refused")
            .to_string(),
        "spring 0: rest length must be zero or more and finite, got NaN"
    );
}

#[test]
fn a_spring_or_an_island_given_too_few_beads_says_so_and_a_right_slice_is_answered() {
    let spring = SpringLink {
        a: 0,
        b: 2,
        rest_length: 1.0,
        stiffness: 10.0,
        damping: 0.0,
    };
    let x = [DVec2::ZERO, DVec2::X, DVec2::new(2.0, 0.0)];
    let v = [DVec2::ZERO; 3];
    assert_eq!(
        spring.force(&x[..2], &v).unwrap_err().to_string(),
        "the spring from bead 0 to bead 2 (positions) names bead 2, but there are only 2 beads"
    );
    assert_eq!(
        spring.force(&x, &v[..1]).unwrap_err().to_string(),
        "the spring from bead 0 to bead 2 (velocities) names bead 2, but there are only 1 beads"
    );
    assert!(spring.energy(&x[..1]).is_err());
    // Stretched by 1 m at 10 N/m: 10 N pulling bead 0 toward bead 2, 5 J.
    let pull = spring.force(&x, &v).expect("both ends given");
    assert!((pull - DVec2::new(10.0, 0.0)).length() <= 1e-12, "{pull}");
    let stored = spring.energy(&x).expect("both ends given");
    assert!((stored - 5.0).abs() <= 1e-12, "{stored}");

    let (island, states, _) = double_pendulum();
    assert_eq!(
        island.energy(&states[..1], G).unwrap_err().to_string(),
        "the beads' states: 1 given, but the island has 3 beads"
    );
    let energy = island.energy(&states, G).expect("a state per bead");
    assert!(energy.is_finite());
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
fn friction_on_a_row_that_is_no_wire_or_held_by_another_beads_row_is_refused_in_words() {
    let friction = crate::geometry::Friction {
        static_coefficient: 0.5,
        kinetic_coefficient: 0.4,
    };
    // Rows: the two beads' wires (0, 1), their rod (2), their stick axes
    // (3, 4).
    let mut island = super::contact::rough_cart(0.0, friction);
    assert_eq!(
        island
            .set_rough(2, friction, 0.0, None)
            .unwrap_err()
            .to_string(),
        "the rough row 2 is not a wire's row (the island has 5 rows)"
    );
    assert_eq!(
        island
            .set_rough(9, friction, 0.0, None)
            .unwrap_err()
            .to_string(),
        "the rough row 9 is not a wire's row (the island has 5 rows)"
    );
    assert_eq!(
        island
            .set_rough(0, friction, 0.0, Some(4))
            .unwrap_err()
            .to_string(),
        "the stick row 4 is not an axis row of the rough row's bead (the island has 5 rows)"
    );
    assert!(island.set_rough(0, friction, 0.0, Some(3)).is_ok());
}
