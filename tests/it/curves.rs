//! Beads on curves in space traced from Bevy's `CubicCurve<Vec3>`: two
//! rows of one bead, the offset from the curve's nearest point along two
//! of its normals.

use bevy::math::cubic_splines::{CubicCardinalSpline, CyclicCubicGenerator};
use bevy::math::{DVec2, DVec3, Vec3};
use wirebead::geometry::{SpaceCurve, Spline, SplineKind, SplineSpec};
use wirebead::solver::{BeadState, Island, IslandWork, LinearForce, Method};

use crate::common;
use crate::space::{curve_against_plane, curve_rows};

const G: f64 = 9.81;

/// How far `p` is from `curve`: the length of its two rows' offsets.
fn off(curve: &impl SpaceCurve, p: DVec3) -> f64 {
    let [a, b] = curve.rows(p, f64::NAN);
    a.c.hypot(b.c)
}

/// Steps one bead on `spline` from its point at parameter `s0` moving
/// along it at `speed`, RATTLE at 1 ms for `duration`: the largest
/// distance from the curve, the largest change of the energy per unit
/// mass, and the curve's parameter at each step, tracked from the last.
fn ride(
    spline: &Spline<DVec3>,
    s0: f64,
    speed: f64,
    duration: f64,
    dt: f64,
) -> (f64, f64, Vec<f64>) {
    let s = common::params(Method::Rattle, dt).step_settings();
    let island = Island::new(&[1.0], curve_rows(spline.clone()).to_vec(), vec![])
        .expect("a bead on a spline");
    let mut work = IslandWork::default();
    let start = spline.point(s0);
    let tangent = spline.frame(start, s0).tangent;
    let mut states = [BeadState {
        position: start,
        velocity: tangent * speed,
    }];
    let gravity = [LinearForce::constant(DVec3::new(0.0, -G, 0.0))];
    let energy = |b: &BeadState<DVec3>| 0.5 * b.velocity.length_squared() + G * b.position.y;
    let e0 = energy(&states[0]);
    let (mut worst, mut drift, mut along) = (0.0f64, 0.0f64, vec![s0]);
    for k in 0..(duration / s.dt).round() as usize {
        island
            .step_at(k as f64 * s.dt, &mut states, &gravity, &s, &mut work)
            .expect("a step");
        let p = states[0].position;
        worst = worst.max(off(spline, p));
        drift = drift.max((energy(&states[0]) - e0).abs());
        let last = *along.last().unwrap_or(&s0);
        along.push(spline.parameter(p, last));
    }
    (worst, drift, along)
}

/// RATTLE's energy error on a wire, as on an implicit one: within 2e-4
/// of the kinetic energy `kinetic` at 1 ms, and second order in the step
/// (at 0.5 ms, 3.5 to 4.5 times smaller), with no drift that would not
/// shrink so.
fn second_order(drift: f64, half: f64, kinetic: f64) {
    assert!(drift <= 2e-4 * kinetic, "the energy moved {drift:e}");
    let ratio = drift / half;
    assert!(
        (3.5..=4.5).contains(&ratio),
        "halving the step divided the energy error by {ratio}"
    );
}

/// A closed Catmull–Rom loop in space made by Bevy
/// (`CubicCardinalSpline::new_catmull_rom(..).to_curve_cyclic()`): a bead
/// sent round it at 12 m/s stays on the curve to 1e-9 for 5 s and keeps its
/// energy as on an implicit wire (see `second_order`).
#[test]
fn a_bead_rides_a_closed_catmull_rom_loop_from_bevy() {
    let points = [
        (0.0, 0.0, 0.0),
        (4.0, 1.0, 1.0),
        (6.0, 3.0, 0.0),
        (4.0, 5.0, -1.0),
        (0.0, 4.0, -2.0),
        (-3.0, 2.0, -1.0),
        (-4.0, 0.5, 1.0),
    ]
    .map(|(x, y, z)| Vec3::new(x, y, z));
    let curve = CubicCardinalSpline::new_catmull_rom(points)
        .to_curve_cyclic()
        .expect("a loop");
    let spline = Spline::<DVec3>::from_curve(&curve);
    let (worst, drift, along) = ride(&spline, 0.0, 12.0, 5.0, 1e-3);
    let (_, half, _) = ride(&spline, 0.0, 12.0, 5.0, 5e-4);
    assert!(worst <= 1e-9, "left the loop by {worst:e}");
    second_order(drift, half, 0.5 * 12.0 * 12.0);
    // It went round more than once.
    let laps = along.windows(2).filter(|w| w[1] < w[0] - 3.0).count();
    assert!(laps >= 1, "it did not go round: {:?}", along.last());
}

/// A figure eight in space that passes through its own crossing point
/// twice per lap: a bead sent round it at 6 m/s keeps to its branch at
/// every crossing (its parameter moves on by less than 0.1 a step, never
/// jumping to the other branch), on the curve to 1e-9 and with its energy
/// kept as on an implicit wire over 6 s.
#[test]
fn a_bead_keeps_its_branch_where_a_track_crosses_itself() {
    let n = 16;
    let points: Vec<DVec3> = (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            DVec3::new(
                2.0 * t.sin(),
                (2.0 * t).sin(),
                0.5 * (1.0 - (2.0 * t).cos()),
            )
        })
        .collect();
    // t = 0 and t = π both pass through the origin.
    assert_eq!(points[0], DVec3::ZERO);
    assert!(points[n / 2].length() < 1e-15);
    let spline = Spline::new(SplineSpec {
        kind: SplineKind::CatmullRom,
        points,
        closed: true,
    })
    .expect("a figure eight");
    let (worst, drift, along) = ride(&spline, 0.0, 6.0, 6.0, 1e-3);
    let (_, half, _) = ride(&spline, 0.0, 6.0, 6.0, 5e-4);
    assert!(worst <= 1e-9, "left the track by {worst:e}");
    second_order(drift, half, 0.5 * 6.0 * 6.0);
    let period = n as f64;
    let mut crossings = 0;
    for w in along.windows(2) {
        let step = (w[1] - w[0] + period / 2.0).rem_euclid(period) - period / 2.0;
        assert!(
            step.abs() < 0.1,
            "the parameter jumped from {} to {}",
            w[0],
            w[1]
        );
        let near = |s: f64| s.min(period - s).min((s - period / 2.0).abs());
        if near(w[1]) < 1e-2 && near(w[0]) >= 1e-2 {
            crossings += 1;
        }
    }
    assert!(crossings >= 4, "passed the crossing only {crossings} times");
}

/// An open Catmull–Rom valley in the xy-plane, made in space with `z = 0`,
/// steps as the same spline in the plane: RATTLE over 3 s at 1 ms, the
/// trajectories within 1e-10 and `z` and its velocity exactly 0.
#[test]
fn a_planar_spline_in_space_steps_as_in_the_plane() {
    let flat: Vec<DVec2> = [
        (-3.0, 2.0),
        (-1.5, 0.3),
        (0.0, -0.5),
        (1.0, 0.0),
        (3.0, 1.5),
    ]
    .map(|(x, y)| DVec2::new(x, y))
    .to_vec();
    let plane = Spline::new(SplineSpec {
        kind: SplineKind::CatmullRom,
        points: flat.clone(),
        closed: false,
    })
    .expect("a valley");
    let space = Spline::<DVec3>::new(SplineSpec {
        kind: SplineKind::CatmullRom,
        points: flat.iter().map(|p| p.extend(0.0)).collect(),
        closed: false,
    })
    .expect("a valley in space");
    let worst = curve_against_plane(&plane, space, plane.point(0.5), 3000);
    assert!(worst <= 1e-10, "{worst:e} from the plane's trajectory");
}

/// A bead that slides down an open spline in space leaves it at its end,
/// as on an open curve in the plane: the instant it passes the end is
/// found within the step, the island reports it once (for the curve's two
/// rows), and the bead flies on from there. On a straight track (three
/// points in a line) RATTLE slides and flies exactly under gravity, so
/// the bead leaves where the track ends at `√(2 g sinθ L)` along it and
/// then follows the parabola from there: to 1e-9 m over half a second.
#[test]
fn a_bead_leaves_an_open_spline_in_space_at_its_end() {
    let (top, end) = (DVec3::new(0.0, 1.0, 0.0), DVec3::new(1.6, 0.0, 1.2));
    let spline = Spline::<DVec3>::new(SplineSpec {
        kind: SplineKind::CatmullRom,
        points: vec![top, (top + end) / 2.0, end],
        closed: false,
    })
    .expect("a straight track");
    assert!(spline.has_ends(), "an open spline ends");
    let s = common::params(Method::Rattle, 1.0 / 240.0).step_settings();
    let island = Island::new(&[1.0], curve_rows(spline.clone()).to_vec(), vec![])
        .expect("a bead on a spline");
    let mut work = IslandWork::default();
    let mut states = [BeadState {
        position: top,
        velocity: DVec3::ZERO,
    }];
    let g = DVec3::new(0.0, -G, 0.0);
    let gravity = [LinearForce::constant(g)];
    let length = (end - top).length();
    let tangent = (end - top) / length;
    let along = g.dot(tangent);
    let leaves = (2.0 * length / along).sqrt();
    let leaving = tangent * along * leaves;
    let mut left = Vec::new();
    let steps = ((leaves + 0.5) / s.dt).round() as usize;
    for k in 0..steps {
        island
            .step_at(k as f64 * s.dt, &mut states, &gravity, &s, &mut work)
            .expect("a step");
        left.extend(work.events().iter().map(|&(_, _, event)| event));
    }
    let [wirebead::solver::ContactEvent::Left { time, position }] = left[..] else {
        panic!("the bead left once: {left:?}");
    };
    assert!(
        (time - leaves).abs() <= 1e-9,
        "left at {time}, not {leaves}"
    );
    assert!(
        (position - end).length() <= 1e-9,
        "left at {position}, not {end}"
    );
    let t = steps as f64 * s.dt - leaves;
    let flown = end + leaving * t + 0.5 * g * t * t;
    let off = (states[0].position - flown).length();
    assert!(
        off <= 1e-9,
        "{off:e} m from the parabola from the track's end"
    );
    let fast = (states[0].velocity - (leaving + g * t)).length();
    assert!(fast <= 1e-9, "{fast:e} m/s from the parabola's velocity");
}
