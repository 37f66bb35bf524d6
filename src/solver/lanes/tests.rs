//! The batched step against [`step`](crate::solver::step), lane for lane
//! and bit for bit, and the lanes it hands back.

use super::*;
use crate::geometry::{Circle, Placed, Pose};
use crate::solver::Stabilization;
use crate::solver::step;
use crate::solver::test_support::{G, settings};

#[test]
fn batched_step_on_circles_is_bit_identical_to_step() {
    // Without AVX2 the batch finishes no lane and every bead takes
    // `step` itself: there is nothing to compare.
    assert!(
        crate::lane::avx2().is_some(),
        "this processor has no AVX2: the batched step is not used here"
    );
    // Beads in all directions, at all speeds, on circles of different
    // sizes and centres, with a spring's stiffness on some.
    let bound = 0.5;
    for method in Method::ALL {
        let batch_settings = StepSettings {
            drift_bound: bound,
            ..settings(method, 1.0 / 60.0)
        };
        let (mut batches, mut singles) = (Vec::new(), Vec::new());
        for k in 0..50 {
            let mut lanes = CircleLanes::default();
            let mut inputs = Vec::new();
            for lane in 0..LANES {
                let j = (k * LANES + lane) as f64;
                let radius = 0.5 + (j * 0.37) % 3.0;
                // Every other batch far from the origin, where rounding
                // stalls the Newton solves above their tolerance.
                let far = if k % 2 == 1 { 3.0e4 } else { 0.0 };
                let centre = DVec2::new((j * 1.3) % 5.0 - 2.5 + far, (j * 0.7) % 4.0 - 2.0 - far);
                let angle = j * 0.91;
                let off = 1.0 + 0.02 * ((j * 0.13).sin());
                let state = BeadState {
                    position: centre + radius * off * DVec2::from_angle(angle),
                    velocity: DVec2::new((j * 0.29).sin(), (j * 0.41).cos()) * 4.0,
                };
                let mass = 0.3 + (j * 0.17) % 2.0;
                let force = LinearForce {
                    force: mass * G + DVec2::new(j % 3.0, -(j % 2.0)),
                    stiffness: j % 4.0,
                    at: state.position + DVec2::new(0.01, -0.02) * (j % 5.0),
                };
                lanes.set(lane, state, &force, mass, centre, radius);
                inputs.push((state, force, mass, centre, radius));
            }
            // (the same where there is no AVX2).
            let mut outs = CircleSteps::default();
            step_on_circles(&lanes, &batch_settings, &mut outs);
            batches.push(lanes);
            singles.push(outs);
            let each = (0..LANES).map(|i| outs.lane(i));
            for (out, (state, force, mass, centre, radius)) in each.zip(&inputs) {
                let (state, force, mass, centre, radius) =
                    (*state, *force, *mass, *centre, *radius);
                let placed = Placed {
                    curve: &Circle { radius },
                    pose: Pose::new(centre, 0.0),
                };
                let expected = step(&placed, state, &force, mass, &batch_settings).unwrap();
                let out = out.expect("an ordinary lane");
                let bits = |o: &StepOutput| {
                    [o.state.position, o.state.velocity, o.constraint_force]
                        .map(|v| v.to_array().map(f64::to_bits))
                };
                assert_eq!(bits(&out), bits(&expected), "{method} lane {k}");
                for (a, b) in [
                    (out.lambda, expected.lambda),
                    (out.c, expected.c),
                    (out.c_dot, expected.c_dot),
                ] {
                    assert_eq!(a.to_bits(), b.to_bits());
                }
            }
        }
        // All the batches in one call: the same, bit for bit.
        let mut many = vec![CircleSteps::default(); batches.len()];
        step_on_circle_batches(&batches, &batch_settings, &mut many);
        let bits = |o: &CircleSteps| {
            [o.x, o.y, o.vx, o.vy, o.lambda, o.fx, o.fy, o.c, o.c_dot].map(|a| a.map(f64::to_bits))
        };
        for (k, (one, all)) in singles.iter().zip(&many).enumerate() {
            assert_eq!(bits(one), bits(all), "{method} batch {k} in one call");
            assert_eq!(one.done, all.done);
        }
    }
}

#[test]
fn batched_step_hands_back_the_lanes_it_cannot_finish() {
    let centre = DVec2::new(1.0, 2.0);
    let mut lanes = CircleLanes::default();
    let at = |angle: f64| centre + DVec2::from_angle(angle);
    let states = [
        (at(0.3), DVec2::new(1.0, 0.0)),      // ordinary
        (centre, DVec2::ZERO),                // the singular centre
        (at(1.0), DVec2::new(f64::NAN, 0.0)), // not finite
        (at(2.0), DVec2::new(1e6, 0.0)),      // flung past the bound
    ];
    for (lane, (position, velocity)) in states.into_iter().enumerate() {
        let state = BeadState { position, velocity };
        lanes.set(lane, state, &LinearForce::constant(G), 1.0, centre, 1.0);
    }
    let s = settings(Method::SemiImplicitEuler(Stabilization::Baumgarte), 0.01);
    let mut outs = CircleSteps::default();
    step_on_circles(&lanes, &s, &mut outs);
    // The unused lanes 4 to 7 are all at their circle's centre.
    let mut done = [false; LANES];
    done[0] = true;
    assert_eq!(outs.done, done, "{outs:?}");
    assert!(outs.lane(0).is_some() && outs.lane(1).is_none());
}
