//! One-sided rows and friction on an island: a cart that lands, bounces,
//! flies off a hump, and stops and sticks on a rough line.

use bevy::math::DVec2;

use super::*;
use crate::geometry::{Circle, Line};
use crate::solver::Stabilization;

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
pub(super) fn rough_cart(degrees: f64, friction: crate::geometry::Friction) -> Island {
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
    island
        .set_rough(0, friction, 0.0, Some(3))
        .expect("row 0 is a wire's, row 3 an axis of its bead");
    island
        .set_rough(1, friction, 0.0, Some(4))
        .expect("row 1 is a wire's, row 4 an axis of its bead");
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

/// One bead of 1 kg on a one-sided floor (the line `y = 0`, pushing up)
/// of restitution `restitution`, its row set aside till it lands.
fn floor(restitution: f64) -> Island {
    let mut island = Island::new(
        &[1.0],
        vec![wire(0, WireShape::Line(Line), Pose::IDENTITY)],
        vec![],
    )
    .unwrap();
    island.set_side(0, crate::geometry::Side::Positive, restitution);
    island
}

/// When the first landing among `events` happened.
fn landed_at(mut events: impl Iterator<Item = crate::solver::ContactEvent>) -> Option<f64> {
    use crate::solver::ContactEvent;
    events.find_map(|e| match e {
        ContactEvent::Landed { time, .. } => Some(time),
        ContactEvent::Left { .. } => None,
    })
}

/// A bead thrown onto a one-sided floor lands where a lone bead does: an
/// island of its one row locates the landing within the step as
/// [`step_surface`](crate::solver::step_surface) does, and goes on from
/// there the same way.
#[test]
fn an_island_lands_within_the_step_where_a_lone_bead_does() {
    use crate::geometry::{FixedTrack, Side, Surface};
    use crate::solver::{Contact, step_surface};
    let line = Line;
    let track = FixedTrack(&line);
    let start = BeadState {
        position: DVec2::new(0.0, 1.0),
        velocity: DVec2::new(0.7, 0.3),
    };
    let force = LinearForce::constant(G);
    for method in [
        Method::SemiImplicitEuler(Stabilization::Baumgarte),
        Method::Rk4(Stabilization::Projection),
        Method::Rattle,
    ] {
        for restitution in [0.0, 0.5] {
            let surface = Surface {
                side: Side::Positive,
                restitution,
                ..Surface::PLAIN
            };
            let island = floor(restitution);
            let s = settings(method, 1.0 / 60.0);
            let (mut lone, mut contact) = (start, Contact::InFlight);
            let mut states = vec![start];
            let mut work = IslandWork::default();
            let (mut lone_landed, mut island_landed) = (None, None);
            for k in 0..90 {
                let t = k as f64 / 60.0;
                let step =
                    step_surface(&track, t, lone, &force, 1.0, &s, &surface, contact).unwrap();
                (lone, contact) = (step.output.state, step.contact);
                lone_landed = lone_landed.or(landed_at(step.event.into_iter()));
                island
                    .step_at(t, &mut states, &[force], &s, &mut work)
                    .unwrap();
                island_landed = island_landed.or(landed_at(work.events().iter().map(|e| e.2)));
            }
            let (lone_t, island_t) = (lone_landed.unwrap(), island_landed.unwrap());
            // Thrown up at 0.3 m/s from 1 m: it lands after 0.483 s, in
            // the middle of a step; RK4 and RATTLE fly exactly under a
            // constant force, semi-implicit Euler to O(dt).
            let exact = (0.3 + (0.09f64 + 2.0 * 9.81).sqrt()) / 9.81;
            let tolerance = if method.is_euler() { 1.0 / 60.0 } else { 1e-9 };
            assert!(
                (lone_t - exact).abs() < tolerance && (lone_t * 60.0).fract() > 0.05,
                "{method}: the lone bead landed at {lone_t}, not {exact}"
            );
            assert!(
                (island_t - lone_t).abs() < 1e-12,
                "{method}, e = {restitution}: the island landed at {island_t}, the lone bead at {lone_t}"
            );
            let gap = (lone.position - states[0].position).length()
                + (lone.velocity - states[0].velocity).length();
            assert!(
                gap < 1e-9,
                "{method}, e = {restitution}: the island is {gap:e} from the lone bead"
            );
        }
    }
}

/// A bead at rest 0.4 g dt² above a one-sided floor, RATTLE at 1/60 s:
/// free fall crosses the floor within the step, at `dt √0.8`. At
/// restitution 0 it reaches the floor no faster than the step's weight
/// moves it, so it lands at the step's end, on the floor to 1e-12 m and at
/// rest across it to 1e-12 m/s, its speed along the floor kept to 1e-12;
/// at restitution ½ the landing is located at its instant to 1e-9 s.
#[test]
fn a_bead_that_reaches_its_floor_slowly_lands_at_the_step_end() {
    let dt = 1.0 / 60.0;
    let gap = 0.4 * 9.81 * dt * dt;
    for restitution in [0.0, 0.5] {
        let island = floor(restitution);
        let mut states = vec![BeadState {
            position: DVec2::new(0.0, gap),
            velocity: DVec2::new(0.5, 0.0),
        }];
        let mut work = IslandWork::default();
        island
            .step_at(
                0.0,
                &mut states,
                &weights(&[1.0]),
                &settings(Method::Rattle, dt),
                &mut work,
            )
            .unwrap();
        let landed = landed_at(work.events().iter().map(|e| e.2));
        let landed = landed.expect("the bead lands within its first step");
        if restitution == 0.0 {
            assert_eq!(landed, dt, "a slow landing is taken at the step's end");
            let BeadState { position, velocity } = states[0];
            assert!(position.y.abs() < 1e-12, "{} m off the floor", position.y);
            assert!(
                velocity.y.abs() < 1e-12,
                "{} m/s across the floor",
                velocity.y
            );
            assert!(
                (velocity.x - 0.5).abs() < 1e-12,
                "{} m/s along it",
                velocity.x
            );
        } else {
            let instant = dt * 0.8f64.sqrt();
            assert!(
                (landed - instant).abs() < 1e-9,
                "e = ½: landed at {landed} s, not {instant} s"
            );
        }
    }
}

/// A contact row between a pinned bead and a 2 kg bead resting on it:
/// set aside at the start; held (from a mark), the pair presses with the
/// weight, `λ = m g` to 1e-12 of it, and the bead stays put; pushed up
/// instead, RATTLE's velocity solve lets the row go (its multiplier
/// would pull) and the bead leaves: moving up after the step, risen after
/// the next.
#[test]
fn a_contact_row_holds_a_pressing_pair_and_lets_a_pulling_one_go() {
    let (r, m, g) = (0.1, 2.0, 9.81);
    let [px, py] = pin(0, DVec2::ZERO);
    let mut island = Island::new(&[1.0, m], vec![px, py, rod(0, 1, 2.0 * r)], vec![]).unwrap();
    island.set_contact(2);
    assert!(island.is_contact(2) && !island.is_contact(0));
    let start = at_rest(&[DVec2::ZERO, DVec2::new(0.0, 2.0 * r)]);
    let s = settings(Method::Rattle, 1.0 / 240.0);
    for (weight, held) in [(-g, true), (g, false)] {
        let forces = vec![
            LinearForce::constant(DVec2::ZERO),
            LinearForce::constant(DVec2::new(0.0, m * weight)),
        ];
        let mut states = start.clone();
        let mut work = IslandWork::default();
        island.begin(0.0, &states, &mut work);
        assert!(!work.holds(2), "a contact starts set aside");
        let mut mark = work.mark();
        assert_eq!(mark.hold(2, true), Some(false));
        work.rewind(&mark);
        island
            .step_at(0.0, &mut states, &forces, &s, &mut work)
            .unwrap();
        assert_eq!(work.holds(2), held);
        let rise = states[1].position.y - 2.0 * r;
        if held {
            let lambda = work.rows()[2].lambda;
            assert!((lambda - m * g).abs() <= 1e-12 * m * g, "λ = {lambda}");
            assert!(rise.abs() <= 1e-15 && states[1].velocity.length() <= 1e-12);
        } else {
            assert!(states[1].velocity.y > 0.0, "v = {}", states[1].velocity);
            island
                .step_at(s.dt, &mut states, &forces, &s, &mut work)
                .unwrap();
            let rise = states[1].position.y - 2.0 * r;
            assert!(rise > 0.0 && !work.holds(2), "rise {rise}");
        }
    }
}

/// A bead of mass `m` and a pinned 1 kg bead, both of radius `r`, the
/// first resting on the second under gravity `g` (their contact row 2):
/// the island, the states and the forces.
fn resting_on_a_pin(r: f64, m: f64, g: f64) -> (Island, Vec<BeadState>, Vec<LinearForce>) {
    let [px, py] = pin(0, DVec2::ZERO);
    let mut island = Island::new(&[1.0, m], vec![px, py, rod(0, 1, 2.0 * r)], vec![]).unwrap();
    island.set_contact(2);
    let states = at_rest(&[DVec2::ZERO, DVec2::new(0.0, 2.0 * r)]);
    let forces = vec![
        LinearForce::constant(DVec2::ZERO),
        LinearForce::constant(DVec2::new(0.0, -m * g)),
    ];
    (island, states, forces)
}

/// A 2 kg bead resting on a pinned one, its contact row set aside: RATTLE's
/// own step finds the pair touching at its start and pressed into each
/// other at its end, holds the row and takes the step again, so the bead
/// stays put (to rounding) pressing with its weight to 1e-12 of it.
#[test]
fn rattle_holds_a_touching_pair_its_step_would_press_together() {
    let (r, m, g) = (0.1, 2.0, 9.81);
    let (island, mut states, forces) = resting_on_a_pin(r, m, g);
    let s = settings(Method::Rattle, 1.0 / 240.0);
    let mut work = IslandWork::default();
    island.begin(0.0, &states, &mut work);
    assert!(!work.holds(2), "a contact starts set aside");
    for k in 0..240 {
        island
            .step_at(k as f64 / 240.0, &mut states, &forces, &s, &mut work)
            .unwrap();
        assert!(work.holds(2), "step {k}: the pressed pair is held");
        let sink = 2.0 * r - states[1].position.y;
        assert!(sink.abs() <= 1e-14 * r, "step {k}: sunk by {sink:e}");
        let lambda = work.rows()[2].lambda;
        assert!((lambda - m * g).abs() <= 1e-12 * m * g, "λ = {lambda}");
    }
}

/// The island of a 2 kg bead resting on a pinned one, rebuilt after a
/// step (a fresh work told each row's state by `carry_row`): it starts
/// with the pair pressed, its force the weight to 1e-12 before it steps
/// (where a fresh island starts its contacts set aside, and its force
/// unknown), and steps as the island it replaces, the states and forces
/// the same to rounding; a row of an island built and not stepped passes
/// on what it was told.
#[test]
fn an_island_rebuilt_starts_its_contacts_as_the_last_one_left_them() {
    let (r, m, g) = (0.1, 2.0, 9.81);
    let (island, mut states, forces) = resting_on_a_pin(r, m, g);
    let s = settings(Method::Rattle, 1.0 / 240.0);
    let mut work = IslandWork::default();
    island
        .step_at(0.0, &mut states, &forces, &s, &mut work)
        .unwrap();
    assert!(work.holds(2));
    let mut rebuilt = IslandWork::default();
    for row in 0..island.rows() {
        rebuilt.carry_row(row, &work, row);
    }
    island.begin(s.dt, &states, &mut rebuilt);
    assert!(rebuilt.holds(2), "the pressed pair starts held");
    let carried = rebuilt.rows()[2].lambda;
    assert!((carried - m * g).abs() <= 1e-12 * m * g, "λ = {carried}");
    // Told, not stepped: passed on as told.
    let mut again = IslandWork::default();
    again.carry_row(2, &rebuilt, 2);
    assert_eq!(again.carried(2), Some(true));
    let mut continued = states.clone();
    island
        .step_at(s.dt, &mut continued, &forces, &s, &mut work)
        .unwrap();
    island
        .step_at(s.dt, &mut states, &forces, &s, &mut rebuilt)
        .unwrap();
    for (a, b) in continued.iter().zip(&states) {
        assert!((a.position - b.position).length() <= 1e-15);
        assert!((a.velocity - b.velocity).length() <= 1e-12);
    }
    let (a, b) = (work.rows()[2].lambda, rebuilt.rows()[2].lambda);
    assert!((a - b).abs() <= 1e-12 * m * g, "λ {a} and {b}");
}

/// Two free 1 kg beads pressed together (their contact row held) answer a
/// unit impulse on one along the line between them as one 2 kg body: each
/// moves at ½ m/s to 1e-15; set aside, the struck bead alone takes 1 m/s.
#[test]
fn a_strike_on_a_held_pair_moves_it_as_one() {
    let mut island = Island::new(&[1.0, 1.0], vec![rod(0, 1, 0.2)], vec![]).unwrap();
    island.set_contact(0);
    let states = at_rest(&[DVec2::ZERO, DVec2::new(0.2, 0.0)]);
    for (held, expect) in [(true, [0.5, 0.5]), (false, [1.0, 0.0])] {
        let mut work = IslandWork::default();
        island.begin(0.0, &states, &mut work);
        let mut mark = work.mark();
        mark.hold(0, held);
        work.rewind(&mark);
        let answer = island
            .respond(0.0, &states, 0, DVec2::new(1.0, 0.0), &mut work)
            .unwrap();
        for (k, v) in answer.iter().enumerate() {
            assert!(
                (v.x - expect[k]).abs() <= 1e-15 && v.y.abs() <= 1e-15,
                "held {held}: bead {k} at {v}"
            );
        }
        assert_eq!(work.holds(0), held, "the answer leaves the row as it was");
    }
}

/// Two free 1 kg beads in touch, the first closing on the second at
/// 1 m/s, their contact row held: pressed, they move on together at
/// ½ m/s to 1e-15, the row pushing with ½ N s, having lost ¼ J (`½ μ u²`,
/// μ = ½ kg); pulling apart instead, the row is let go and nothing moves.
#[test]
fn pressing_a_closing_held_pair_strikes_it_inelastically() {
    let mut island = Island::new(&[1.0, 1.0], vec![rod(0, 1, 0.2)], vec![]).unwrap();
    island.set_contact(0);
    for (u, expect, push) in [(1.0, [0.5, 0.5], 0.5), (-1.0, [-1.0, 0.0], 0.0)] {
        let mut states = at_rest(&[DVec2::ZERO, DVec2::new(0.2, 0.0)]);
        states[0].velocity = DVec2::new(u, 0.0);
        let mut work = IslandWork::default();
        island.begin(0.0, &states, &mut work);
        let mut mark = work.mark();
        mark.hold(0, true);
        work.rewind(&mark);
        let (velocities, impulses) = island.press(0.0, &states, &mut work).unwrap();
        for (k, v) in velocities.iter().enumerate() {
            assert!(
                (v.x - expect[k]).abs() <= 1e-15 && v.y.abs() <= 1e-15,
                "u = {u}: bead {k} at {v}"
            );
        }
        assert!(
            (impulses[0] - push).abs() <= 1e-15,
            "impulse {}",
            impulses[0]
        );
        assert!(work.holds(0), "the press leaves the row held");
    }
}
