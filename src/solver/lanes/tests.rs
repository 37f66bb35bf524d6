//! The batched step against [`step`](crate::solver::step), lane for lane
//! and bit for bit, and the lanes it hands back.

use super::*;
use bevy::math::{DQuat, DVec3};

use crate::geometry::{Circle, FixedTrack, Placed, PlacedSurface, Pose, Pose3, Sphere};
use crate::solver::test_support::{G, settings};
use crate::solver::{Stabilization, step, step_on};

/// A bead of test case `j` about `centre`: its offset from the centre at
/// `radius` (slightly off the circle or sphere), its velocity, and the
/// applied force `f` besides gravity.
struct Case<S> {
    centre: S,
    offset: S,
    velocity: S,
    push: S,
}

/// The batched step on 50 batches of beads, every method, against the
/// single-bead step `single` lane by lane, bit for bit, and in one call
/// against one call per batch. `case(j, far)` places bead `j` (`far`: far
/// from the origin, where rounding stalls the Newton solves above their
/// tolerance).
fn batched_is_bit_identical<S: LaneSpace + crate::geometry::Coordinates>(
    case: impl Fn(f64, f64) -> Case<S>,
    single: impl Fn(f64, S, BeadState<S>, &LinearForce<S>, f64, &StepSettings) -> StepOutput<S>,
    gravity: S,
) {
    // Without AVX2 the batch finishes no lane and every bead takes
    // `step` itself: there is nothing to compare.
    assert!(
        crate::lane::avx2().is_some(),
        "this processor has no AVX2: the batched step is not used here"
    );
    let bound = 0.5;
    for method in Method::ALL {
        let batch_settings = StepSettings {
            drift_bound: bound,
            ..settings(method, 1.0 / 60.0)
        };
        let (mut batches, mut singles) = (Vec::new(), Vec::new());
        for k in 0..50 {
            let mut lanes = RoundLanes::<S>::default();
            let mut inputs = Vec::new();
            for lane in 0..LANES {
                let j = (k * LANES + lane) as f64;
                let radius = 0.5 + (j * 0.37) % 3.0;
                let far = if k % 2 == 1 { 3.0e4 } else { 0.0 };
                let Case {
                    centre,
                    offset,
                    velocity,
                    push,
                } = case(j, far);
                let off = 1.0 + 0.02 * ((j * 0.13).sin());
                let state = BeadState {
                    position: centre + offset.scale(radius * off),
                    velocity,
                };
                let mass = 0.3 + (j * 0.17) % 2.0;
                let force = LinearForce {
                    force: gravity.scale(mass) + push,
                    stiffness: j % 4.0,
                    at: state.position + push.scale(0.01 * (j % 5.0)),
                };
                lanes.set(lane, state, &force, mass, centre, radius);
                inputs.push((state, force, mass, centre, radius));
            }
            // (the same where there is no AVX2).
            let mut outs = RoundSteps::<S>::default();
            step_on_rounds(&lanes, &batch_settings, &mut outs);
            batches.push(lanes);
            singles.push(outs);
            let each = (0..LANES).map(|i| outs.lane(i));
            for (out, (state, force, mass, centre, radius)) in each.zip(&inputs) {
                let expected = single(*radius, *centre, *state, force, *mass, &batch_settings);
                let out = out.expect("an ordinary lane");
                let bits = |o: &StepOutput<S>| {
                    [o.state.position, o.state.velocity, o.constraint_force].map(|v| {
                        v.components()
                            .iter()
                            .map(|x| x.to_bits())
                            .collect::<Vec<_>>()
                    })
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
        let mut many = vec![RoundSteps::<S>::default(); batches.len()];
        step_on_round_batches(&batches, &batch_settings, &mut many);
        for (k, (one, all)) in singles.iter().zip(&many).enumerate() {
            assert_eq!(
                format!("{one:?}"),
                format!("{all:?}"),
                "{method} batch {k} in one call"
            );
        }
    }
}

#[test]
fn batched_step_on_circles_is_bit_identical_to_step() {
    // Beads in all directions, at all speeds, on circles of different
    // sizes and centres, with a spring's stiffness on some.
    batched_is_bit_identical(
        |j, far| Case {
            centre: DVec2::new((j * 1.3) % 5.0 - 2.5 + far, (j * 0.7) % 4.0 - 2.0 - far),
            offset: DVec2::from_angle(j * 0.91),
            velocity: DVec2::new((j * 0.29).sin(), (j * 0.41).cos()) * 4.0,
            push: DVec2::new(j % 3.0, -(j % 2.0)),
        },
        |radius, centre, state, force, mass, settings| {
            let placed = Placed {
                curve: &Circle { radius },
                pose: Pose::new(centre, 0.0),
            };
            step(&placed, state, force, mass, settings).unwrap()
        },
        G,
    );
}

#[test]
fn batched_step_on_spheres_is_bit_identical_to_step_on() {
    // The same in space: beads all over spheres, moving every way.
    batched_is_bit_identical(
        |j, far| {
            let (a, b) = (j * 0.91, j * 0.53);
            Case {
                centre: DVec3::new(
                    (j * 1.3) % 5.0 - 2.5 + far,
                    (j * 0.7) % 4.0 - 2.0 - far,
                    (j * 0.3) % 3.0 - 1.5 + far,
                ),
                offset: DVec3::new(a.cos() * b.sin(), a.sin() * b.sin(), b.cos()),
                velocity: DVec3::new((j * 0.29).sin(), (j * 0.41).cos(), (j * 0.17).sin()) * 4.0,
                push: DVec3::new(j % 3.0, -(j % 2.0), j % 1.5),
            }
        },
        |radius, centre, state, force, mass, settings| {
            let placed = PlacedSurface {
                surface: &Sphere { radius },
                pose: Pose3 {
                    origin: centre,
                    rotation: DQuat::IDENTITY,
                },
            };
            step_on(&FixedTrack(&placed), 0.0, state, force, mass, settings).unwrap()
        },
        DVec3::new(0.0, -9.81, 0.0),
    );
}

#[test]
fn batched_step_hands_back_the_lanes_it_cannot_finish() {
    let centre = DVec2::new(1.0, 2.0);
    let mut lanes = RoundLanes::<DVec2>::default();
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
    let mut outs = RoundSteps::<DVec2>::default();
    step_on_rounds(&lanes, &s, &mut outs);
    // The unused lanes 4 to 7 are all at their circle's centre.
    let mut done = [false; LANES];
    done[0] = true;
    assert_eq!(outs.done, done, "{outs:?}");
    assert!(outs.lane(0).is_some() && outs.lane(1).is_none());
}
