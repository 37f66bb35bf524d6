//! Settling touches on beads that coast, whose meetings are known in
//! closed form; the broad phase and which beads are near in `broad`.

use bevy::math::{DVec2, DVec3};

use super::*;

mod broad;
mod obstacle;

/// Free beads coasting at constant velocity (of unit mass unless
/// [`Coasting::of_mass`] says otherwise): exact, so that where they meet
/// is known in closed form.
struct Coasting {
    start: Vec<BeadState>,
    end: Vec<BeadState>,
    steps: usize,
    mass: f64,
}

impl Coasting {
    fn new(states: &[(f64, f64)], dt: f64) -> Self {
        let start: Vec<BeadState> = states
            .iter()
            .map(|&(x, v)| BeadState {
                position: DVec2::new(x, 0.0),
                velocity: DVec2::new(v, 0.0),
            })
            .collect();
        let mut end = start.clone();
        for s in &mut end {
            s.position += s.velocity * dt;
        }
        Self {
            start,
            end,
            steps: 0,
            mass: 1.0,
        }
    }

    /// The same beads, each of `mass`.
    fn of_mass(self, mass: f64) -> Self {
        Self { mass, ..self }
    }
}

impl TouchBody<DVec2> for Coasting {
    fn start(&self) -> &[BeadState] {
        &self.start
    }
    fn end(&self) -> &[BeadState] {
        &self.end
    }
    fn advance(&mut self, _: f64, h: f64, states: &mut [BeadState]) -> Result<(), SolveError> {
        self.steps += 1;
        for s in states {
            s.position += s.velocity * h;
        }
        Ok(())
    }
    fn keep(&mut self) {}
    fn respond(
        &mut self,
        _: f64,
        states: &[BeadState],
        bead: usize,
        impulse: DVec2,
    ) -> Result<Vec<DVec2>, SolveError> {
        Ok(unit_answer(states.len(), bead, impulse / self.mass))
    }
    fn push(&self, _: usize) -> DVec2 {
        DVec2::ZERO
    }
    fn finish(&mut self, states: &[BeadState]) {
        self.end = states.to_vec();
    }
}

/// The answer of free beads of unit mass to `impulse` on bead `bead`.
fn unit_answer(beads: usize, bead: usize, impulse: DVec2) -> Vec<DVec2> {
    let mut answer = vec![DVec2::ZERO; beads];
    answer[bead] = impulse;
    answer
}

fn beads(bodies: usize, radius: f64) -> Vec<TouchBead> {
    (0..bodies)
        .map(|body| TouchBead {
            body,
            bead: 0,
            radius,
            restitution: 1.0,
            friction: 0.0,
        })
        .collect()
}

/// Six beads coasting on a line at random places and speeds, strikes
/// sending them into beads their first boxes never met, in 300 draws:
/// every pair whose boxes from where it started to where the settlement
/// ended it overlap is among the pairs the settlement says are near (the
/// pairs that end in touch are so among them), and no pair is named
/// twice.
#[test]
fn the_settlement_names_every_pair_whose_settled_paths_come_near() {
    let dt = 0.1;
    let r = 0.05;
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut draw = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut grown_beyond = 0;
    for _ in 0..300 {
        let mut places: Vec<f64> = (0..6).map(|_| 2.0 * draw()).collect();
        places.sort_by(f64::total_cmp);
        // Apart by at least a diameter, so that none starts overlapping.
        for k in 1..places.len() {
            places[k] = places[k].max(places[k - 1] + 2.0 * r * 1.01);
        }
        let mut bodies: Vec<Coasting> = places
            .iter()
            .map(|&x| Coasting::new(&[(x, 20.0 * draw() - 10.0)], dt))
            .collect();
        let first: Vec<(DVec3, DVec3)> = bodies
            .iter()
            .map(|b| {
                let (a, e) = (b.start[0].position.xyz(), b.end[0].position.xyz());
                (a.min(e), a.max(e))
            })
            .collect();
        let span = StepSpan { time: 0.0, dt };
        let (mut struck, mut near) = (Vec::new(), Vec::new());
        settle_touches(span, &mut bodies, &beads(6, r), (&mut struck, &mut near)).expect("settles");
        let settled: Vec<(DVec3, DVec3)> = bodies
            .iter()
            .map(|b| {
                let (a, e) = (b.start[0].position.xyz(), b.end[0].position.xyz());
                (a.min(e) - r, a.max(e) + r)
            })
            .collect();
        for (k, (low, high)) in settled.iter().enumerate() {
            grown_beyond += usize::from(low.x < first[k].0.x - r || high.x > first[k].1.x + r);
        }
        for i in 0..6 {
            for j in i + 1..6 {
                let (a, b) = (settled[i], settled[j]);
                if a.0.cmple(b.1).all() && b.0.cmple(a.1).all() {
                    assert!(near.contains(&(i, j)), "({i}, {j}) not named: {near:?}");
                }
            }
        }
        // Strictly increasing: in order, and none named twice.
        assert!(
            near.windows(2).all(|w| w[0] < w[1]),
            "out of order or named twice: {near:?}"
        );
    }
    assert!(
        grown_beyond > 50,
        "{grown_beyond} beads sent past their first boxes"
    );
}

/// Two equal beads that would pass right through each other within one
/// step meet at the instant their gap closes and exchange velocities:
/// their ends are the exact ones to 1e-12.
#[test]
fn a_pair_that_would_pass_through_in_one_step_meets_and_exchanges() {
    let dt = 0.1;
    // Gap 0.4 closing at 12 m/s: they meet at 1/30 s, and would be
    // 0.8 past each other at the step's end.
    let mut bodies = vec![
        Coasting::new(&[(0.0, 6.0)], dt),
        Coasting::new(&[(0.5, -6.0)], dt),
    ];
    let span = StepSpan { time: 2.0, dt };
    let mut struck = Vec::new();
    settle_touches(
        span,
        &mut bodies,
        &beads(2, 0.05),
        (&mut struck, &mut Vec::new()),
    )
    .expect("settles");
    assert_eq!(struck.len(), 1, "{struck:?}");
    let meet = 0.4 / 12.0;
    assert!(
        (struck[0].time - (2.0 + meet)).abs() <= 1e-12,
        "{}",
        struck[0].time
    );
    let (a, b) = (bodies[0].end[0], bodies[1].end[0]);
    let xa = 6.0 * meet - 6.0 * (dt - meet);
    let xb = 0.5 - 6.0 * meet + 6.0 * (dt - meet);
    assert!(
        (a.position.x - xa).abs() <= 1e-12,
        "{} against {xa}",
        a.position.x
    );
    assert!(
        (b.position.x - xb).abs() <= 1e-12,
        "{} against {xb}",
        b.position.x
    );
    assert!((a.velocity.x + 6.0).abs() <= 1e-12 && (b.velocity.x - 6.0).abs() <= 1e-12);
    // Their paths are straight, so the predicted instant is the one: a
    // trial there, which is the step to it, and the step on from it.
    for body in &bodies {
        assert_eq!(body.steps, 2, "advances of one body");
    }
}

/// The cubic through two states is exact for a bead under a constant
/// acceleration: where it predicts a pile's beads meet within a step.
#[test]
fn the_cubic_through_two_states_is_exact_under_constant_acceleration() {
    let (h, g) = (0.25, DVec2::new(0.3, -9.81));
    let start = BeadState {
        position: DVec2::new(1.0, 2.0),
        velocity: DVec2::new(-0.5, 4.0),
    };
    let at = |t: f64| start.position + start.velocity * t + g * (0.5 * t * t);
    let end = BeadState {
        position: at(h),
        velocity: start.velocity + g * h,
    };
    for k in 0..=8 {
        let t = h * k as f64 / 8.0;
        let error = (group::hermite(start, end, h, t) - at(t)).length();
        assert!(error <= 1e-14, "at {t}: {error:e}");
    }
}

/// Five equal balls, four touching at rest and one coming in: exactly
/// one leaves, at the speed that came in, and the rest stay touching
/// at rest.
#[test]
fn one_ball_into_a_touching_row_sends_out_one() {
    let (dt, r, v) = (0.01, 0.05, 3.0);
    let mut bodies = vec![Coasting::new(&[(-0.02, v)], dt)];
    for k in 1..5 {
        bodies.push(Coasting::new(&[(0.1 * k as f64, 0.0)], dt));
    }
    let mut struck = Vec::new();
    let span = StepSpan { time: 0.0, dt };
    settle_touches(
        span,
        &mut bodies,
        &beads(5, r),
        (&mut struck, &mut Vec::new()),
    )
    .expect("settles");
    assert_eq!(struck.len(), 4, "one strike down the row: {struck:?}");
    for (k, body) in bodies.iter().enumerate() {
        let expected = if k == 4 { v } else { 0.0 };
        assert!(
            (body.end[0].velocity.x - expected).abs() <= 1e-12,
            "ball {k}"
        );
    }
    assert!((bodies[0].end[0].position.x - 0.0).abs() <= 1e-12);
}

/// A pair that starts touching and closing strikes at once; pairs that
/// are apart and never meet, or touch without closing, cost no step.
#[test]
fn a_closing_pair_in_touch_strikes_at_once_and_pairs_that_never_meet_are_left() {
    let dt = 0.01;
    let mut bodies = vec![
        Coasting::new(&[(0.0, 1.0)], dt),
        Coasting::new(&[(0.1, 0.0)], dt),
    ];
    let mut struck = Vec::new();
    let span = StepSpan { time: 0.0, dt };
    settle_touches(
        span,
        &mut bodies,
        &beads(2, 0.05),
        (&mut struck, &mut Vec::new()),
    )
    .expect("settles");
    assert_eq!(struck.len(), 1);
    assert_eq!(struck[0].time, 0.0);
    assert!((bodies[1].end[0].position.x - (0.1 + dt)).abs() <= 1e-15);

    let mut apart = vec![
        Coasting::new(&[(0.0, 0.0)], dt),
        Coasting::new(&[(0.1, 1.0)], dt),
        Coasting::new(&[(5.0, 1.0)], dt),
    ];
    struck.clear();
    settle_touches(
        span,
        &mut apart,
        &beads(3, 0.05),
        (&mut struck, &mut Vec::new()),
    )
    .expect("settles");
    assert!(struck.is_empty());
    assert!(apart.iter().all(|b| b.steps == 0), "no pair needed a step");
}

/// Two beads of unit mass in one body that time-steps its contacts at
/// `e = 0`, joined by a contact row set aside: the first at rest at the
/// origin, the second turning about it on a circle of `radius` by `angle`
/// over the step of `dt`.
struct Turning {
    start: Vec<BeadState>,
    end: Vec<BeadState>,
    steps: usize,
    radius: f64,
    angle: f64,
    dt: f64,
}

impl Turning {
    /// The second bead `s` of the way through the step.
    fn at(&self, s: f64) -> BeadState {
        let (sin, cos) = (self.angle * s).sin_cos();
        BeadState {
            position: DVec2::new(cos, sin) * self.radius,
            velocity: DVec2::new(-sin, cos) * self.radius * self.angle / self.dt,
        }
    }

    /// The pair, the second bead also closing on the first at `closing`
    /// where the step begins.
    fn new(radius: f64, angle: f64, dt: f64, closing: f64) -> Self {
        let mut turning = Self {
            start: Vec::new(),
            end: Vec::new(),
            steps: 0,
            radius,
            angle,
            dt,
        };
        let mut second = turning.at(0.0);
        second.velocity -= second.position.normalize() * closing;
        turning.start = vec![BeadState::default(), second];
        turning.end = vec![BeadState::default(), turning.at(1.0)];
        turning
    }
}

impl TouchBody<DVec2> for Turning {
    fn start(&self) -> &[BeadState] {
        &self.start
    }
    fn end(&self) -> &[BeadState] {
        &self.end
    }
    fn advance(&mut self, time: f64, h: f64, states: &mut [BeadState]) -> Result<(), SolveError> {
        self.steps += 1;
        states[1] = self.at((time + h) / self.dt);
        Ok(())
    }
    fn keep(&mut self) {}
    fn respond(
        &mut self,
        _: f64,
        states: &[BeadState],
        bead: usize,
        impulse: DVec2,
    ) -> Result<Vec<DVec2>, SolveError> {
        Ok(unit_answer(states.len(), bead, impulse))
    }
    fn push(&self, _: usize) -> DVec2 {
        DVec2::ZERO
    }
    fn finish(&mut self, states: &[BeadState]) {
        self.end = states.to_vec();
    }
    fn contact(&self, _: usize, _: usize) -> Option<bool> {
        Some(false)
    }
    fn time_steps(&self) -> bool {
        true
    }
}

/// In a body that time-steps its contacts, a joined pair that turns 50°
/// about each other within a step, 1% of its reach apart throughout, is
/// the body's step's: its straight paths from start to end cut the
/// corner to 0.92 of its reach, and it closes at 1 m/s where the step
/// begins, yet it is not looked into (no trial step, no strike).
#[test]
fn a_time_stepping_body_keeps_a_pair_that_turns_about_itself_within_a_step() {
    let (dt, r) = (1.0 / 60.0, 0.02);
    let mut beads = vec![
        TouchBead {
            body: 0,
            bead: 0,
            radius: r,
            restitution: 0.0,
            friction: 0.0,
        };
        2
    ];
    beads[1].bead = 1;
    let span = StepSpan { time: 0.0, dt };
    // Closing at 1 m/s where the step begins: not a meeting its step
    // takes by being slow.
    let mut turning = vec![Turning::new(2.0 * r * 1.01, 50f64.to_radians(), dt, 1.0)];
    let mut struck = Vec::new();
    settle_touches(span, &mut turning, &beads, (&mut struck, &mut Vec::new())).expect("settles");
    assert!(struck.is_empty(), "{struck:?}");
    assert_eq!(turning[0].steps, 0, "trial steps of the body");
}

#[test]
fn a_bead_naming_a_missing_body_is_refused_in_words() {
    let mut bodies = vec![Coasting::new(&[(0.0, 0.0)], 0.01)];
    let err = settle_touches(
        StepSpan {
            time: 0.0,
            dt: 0.01,
        },
        &mut bodies,
        &beads(2, 0.1),
        (&mut Vec::new(), &mut Vec::new()),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "touching bead 1 names a body or a bead that is not there"
    );
}

/// Four beads of radius 0.1 on a line, each a body, in two groups the
/// broad phase finds apart: W at rest with X drifting towards it, settled
/// first; then Z, of 10 kg, strikes Y halfway through the step and sends
/// it back into X, after X's group was settled. Y's group is settled
/// again with X's from the step's start: no pair ends overlapping, Y and
/// X strike, and momentum and energy are kept to 1e-12.
#[test]
fn a_strike_that_sends_a_bead_into_a_group_settled_before_settles_both_again() {
    let dt = 1.0;
    let masses = [1.0, 1.0, 1.0, 10.0];
    let starts = [(0.015, 0.0), (0.25, -0.04), (0.5, 0.0), (0.8, -0.2)];
    let mut bodies: Vec<Coasting> = starts
        .iter()
        .zip(masses)
        .map(|(&start, m)| Coasting::new(&[start], dt).of_mass(m))
        .collect();
    let beads = beads(4, 0.1);
    let sums = |states: &[(f64, f64)]| {
        let momentum: f64 = states.iter().zip(masses).map(|((_, v), m)| m * v).sum();
        let energy: f64 = states
            .iter()
            .zip(masses)
            .map(|((_, v), m)| 0.5 * m * v * v)
            .sum();
        (momentum, energy)
    };
    // Apart, the broad phase sees two groups: W and X, then Y and Z.
    let boxes: Vec<(DVec3, DVec3)> = bodies
        .iter()
        .zip(&beads)
        .map(|(b, t)| swept(t, b.start[0].position, b.end[0].position))
        .collect();
    assert_eq!(overlapping(&boxes), vec![(0, 1), (2, 3)]);
    let mut struck = Vec::new();
    let span = StepSpan { time: 0.0, dt };
    settle_touches(span, &mut bodies, &beads, (&mut struck, &mut Vec::new())).expect("settles");
    let ends: Vec<(f64, f64)> = bodies
        .iter()
        .map(|b| (b.end[0].position.x, b.end[0].velocity.x))
        .collect();
    for i in 0..4 {
        for j in i + 1..4 {
            let gap = (ends[j].0 - ends[i].0).abs() - 0.2;
            assert!(
                gap >= -1e-12,
                "beads {i} and {j} end {gap:e} apart: {ends:?}"
            );
        }
    }
    let ((p0, e0), (p1, e1)) = (sums(&starts), sums(&ends));
    assert!((p1 - p0).abs() <= 1e-12, "momentum {p0} to {p1}");
    assert!((e1 - e0).abs() <= 1e-12, "energy {e0} to {e1}");
    assert!(
        struck
            .iter()
            .any(|s| (s.a.min(s.b), s.a.max(s.b)) == (1, 2)),
        "{struck:?}"
    );
}
