//! A bead leaving a one-sided loop and falling freely, and friction that
//! stops a sliding bead and holds one at rest.

use super::*;
use crate::geometry::{Circle, FixedTrack, Friction, Line, Placed, Pose, Side};
use crate::solver::test_support::{G, settings};
use crate::solver::{Method, Stabilization};

/// A bead inside a one-sided vertical circle of radius 1 (`Negative`:
/// the wire only pushes inwards), leaving the bottom with `v0² = 3gr`,
/// leaves the wire at `cos φ = −1/3`, `4r/3` above the bottom, and
/// then falls freely: its acceleration is `g` to 1e-9.
#[test]
fn a_loop_the_loop_bead_leaves_at_four_thirds_and_falls_freely() {
    let circle = Circle { radius: 1.0 };
    let track = FixedTrack(&circle);
    let surface = Surface {
        side: Side::Negative,
        ..Surface::PLAIN
    };
    let g = G.length();
    for (method, dt, bound) in [
        (Method::Rattle, 1e-3, 1e-3),
        (Method::Rk4(Stabilization::None), 1e-3, 1e-3),
        (Method::Rk4(Stabilization::Projection), 1e-3, 1e-3),
        (
            Method::SemiImplicitEuler(Stabilization::Projection),
            1e-4,
            1e-2,
        ),
    ] {
        let s = settings(method, dt);
        let mut state = BeadState {
            position: DVec2::new(0.0, -1.0),
            velocity: DVec2::new((3.0 * g).sqrt(), 0.0),
        };
        let mut contact = Contact::OnWire;
        let mut left_at = None;
        let mut worst_fall = 0.0f64;
        let mut flying = 0;
        for k in 0..(2.0 / dt) as usize {
            let t = k as f64 * dt;
            let step = step_surface(
                &track,
                t,
                state,
                &LinearForce::constant(G),
                1.0,
                &s,
                &surface,
                contact,
            )
            .unwrap();
            if let Some(ContactEvent::Left { position, .. }) = step.event {
                left_at = Some(position);
            }
            if contact == Contact::InFlight && step.contact == Contact::InFlight {
                let a = (step.output.state.velocity - state.velocity) / dt;
                worst_fall = worst_fall.max((a - G).length() / g);
                flying += 1;
            }
            if contact == Contact::InFlight && step.contact == Contact::OnWire {
                break;
            }
            state = step.output.state;
            contact = step.contact;
        }
        let left = left_at.unwrap_or_else(|| panic!("{method}: never left the wire"));
        let height = left.y + 1.0;
        let error = (height - 4.0 / 3.0).abs();
        eprintln!(
            "{method} at {dt}: left {height:.6} r above the bottom (error {error:e} r), \
             {flying} steps of free fall, acceleration off g by {worst_fall:e}"
        );
        assert!(error < bound, "{method}: left at {height}, not 4/3");
        assert!(flying > 100, "{method}: only {flying} steps of flight");
        assert!(
            worst_fall < 1e-9,
            "{method}: free-fall acceleration off by {worst_fall:e}"
        );
    }
}

/// A horizontal rough line, `μk = 0.3`: a bead sent at `v0 = 3` stops
/// after `v0² / (2 μk g)` and then stays exactly where it stopped.
#[test]
fn friction_stops_a_sliding_bead_at_the_coulomb_distance() {
    let line = Line;
    let track = FixedTrack(&line);
    let surface = Surface {
        friction: Friction::new(0.5, 0.3).unwrap(),
        ..Surface::PLAIN
    };
    let v0 = 3.0;
    let expected = v0 * v0 / (2.0 * 0.3 * G.length());
    for (method, dt, bound) in [
        (Method::Rattle, 1.0 / 60.0, 1e-9),
        (Method::Rk4(Stabilization::None), 1.0 / 60.0, 1e-9),
        (Method::Rk4(Stabilization::Projection), 1.0 / 60.0, 1e-9),
        (
            Method::SemiImplicitEuler(Stabilization::Projection),
            5e-4,
            1e-3,
        ),
        (Method::ExplicitEuler(Stabilization::Baumgarte), 5e-4, 1e-3),
    ] {
        let s = settings(method, dt);
        let mut state = BeadState {
            position: DVec2::ZERO,
            velocity: DVec2::new(v0, 0.0),
        };
        let mut stopped_at = None;
        for k in 0..(3.0 / dt) as usize {
            let step = step_surface(
                &track,
                k as f64 * dt,
                state,
                &LinearForce::constant(G),
                1.0,
                &s,
                &surface,
                Contact::OnWire,
            )
            .unwrap();
            state = step.output.state;
            if state.velocity.x == 0.0 {
                match stopped_at {
                    None => stopped_at = Some(state.position),
                    Some(at) => assert_eq!(state.position, at, "{method}: crept"),
                }
            }
        }
        let at = stopped_at.unwrap_or_else(|| panic!("{method}: never stopped"));
        let error = (at.x - expected).abs() / expected;
        eprintln!(
            "{method} at {dt}: stopped at {:.9} (relative error {error:e})",
            at.x
        );
        assert!(
            error < bound,
            "{method}: stopped at {}, not {expected}",
            at.x
        );
    }
}

/// On a line tilted steeper than `atan μs` a bead from rest slides; on a
/// gentler one it stays exactly at rest.
#[test]
fn static_friction_holds_a_bead_on_a_gentle_slope_and_not_a_steep_one() {
    let surface = Surface {
        friction: Friction::new(0.5, 0.4).unwrap(),
        ..Surface::PLAIN
    };
    let limit = 0.5f64.atan().to_degrees();
    for (degrees, slides) in [(limit - 2.0, false), (limit + 2.0, true)] {
        let line = Line;
        let placed = Placed {
            curve: &line,
            pose: Pose::new(DVec2::ZERO, degrees.to_radians()),
        };
        let track = FixedTrack(&placed);
        for method in Method::ALL {
            let s = settings(method, 1.0 / 60.0);
            let start = BeadState::default();
            let mut state = start;
            for k in 0..120 {
                state = step_surface(
                    &track,
                    k as f64 / 60.0,
                    state,
                    &LinearForce::constant(G),
                    1.0,
                    &s,
                    &surface,
                    Contact::OnWire,
                )
                .unwrap()
                .output
                .state;
            }
            if slides {
                assert!(
                    state.position.length() > 0.1,
                    "{method} at {degrees}°: stuck"
                );
            } else {
                assert_eq!(state, start, "{method} at {degrees}°: moved");
            }
        }
    }
}
