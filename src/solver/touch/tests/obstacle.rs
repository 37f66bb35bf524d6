//! Beads meeting obstacles: a slab of floor, still or moving, that free
//! beads under gravity fall on, whose meetings are known in closed form.

use bevy::math::{DMat3, DVec2, DVec3};

use super::super::obstacle::{BodyPoint, Nearest, Obstacle, ObstaclePair, meet_obstacles};
use super::*;

/// Free beads of one mass falling under a constant acceleration: each
/// step exact, so where they meet a floor is known in closed form.
struct Falling {
    start: Vec<BeadState>,
    end: Vec<BeadState>,
    mass: f64,
    gravity: DVec2,
}

impl Falling {
    fn new(states: &[BeadState], mass: f64, gravity: DVec2) -> Self {
        Self {
            start: states.to_vec(),
            end: states.to_vec(),
            mass,
            gravity,
        }
    }

    /// Steps by `dt` as if nothing were there.
    fn step(&mut self, dt: f64) {
        self.start.clone_from(&self.end);
        let mut states = self.start.clone();
        self.advance(0.0, dt, &mut states).unwrap();
        self.end = states;
    }
}

impl TouchBody<DVec2> for Falling {
    fn start(&self) -> &[BeadState] {
        &self.start
    }
    fn end(&self) -> &[BeadState] {
        &self.end
    }
    fn advance(&mut self, _: f64, h: f64, states: &mut [BeadState]) -> Result<(), SolveError> {
        for s in states {
            s.position += s.velocity * h + 0.5 * self.gravity * h * h;
            s.velocity += self.gravity * h;
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
        self.gravity
    }
    fn finish(&mut self, states: &[BeadState]) {
        self.end = states.to_vec();
    }
}

/// A slab `lo ≤ y ≤ hi`, as wide as the world, moving up at `rise` over
/// steps of `dt`; free of mass `mass` (none: moved by nothing), or fixed.
struct Slab {
    lo: f64,
    hi: f64,
    rise: f64,
    dt: f64,
    mass: Option<f64>,
    restitution: f64,
}

impl Slab {
    fn floor(restitution: f64) -> Self {
        Self {
            lo: -1.0,
            hi: 0.0,
            rise: 0.0,
            dt: 0.0,
            mass: None,
            restitution,
        }
    }
}

impl Obstacle<DVec2> for Slab {
    fn nearest(&self, s: f64, at: DVec2) -> Option<Nearest<DVec2>> {
        let lift = self.rise * s * self.dt;
        let (lo, hi) = (self.lo + lift, self.hi + lift);
        let (y, distance, normal) = if at.y - hi >= lo - at.y {
            (hi, at.y - hi, DVec2::Y)
        } else {
            (lo, lo - at.y, -DVec2::Y)
        };
        Some(Nearest {
            point: DVec2::new(at.x, y),
            normal,
            distance,
        })
    }
    fn point(&self, _: f64, _: DVec2) -> BodyPoint {
        BodyPoint {
            velocity: DVec3::Y * self.rise,
            response: self
                .mass
                .map_or(DMat3::ZERO, |m| DMat3::from_diagonal(DVec3::splat(1.0 / m))),
        }
    }
    fn reach(&self) -> f64 {
        self.rise.abs() * self.dt
    }
    fn surface(&self) -> (f64, f64) {
        (self.restitution, 0.0)
    }
    fn struck(&mut self, _: f64, _: DVec2, _: DVec2) {}
}

fn bead(restitution: f64, radius: f64) -> ObstaclePair {
    ObstaclePair {
        bead: 0,
        radius,
        restitution,
        friction: 0.0,
        obstacle: 0,
    }
}

fn at(x: f64, y: f64, vx: f64, vy: f64) -> BeadState {
    BeadState {
        position: DVec2::new(x, y),
        velocity: DVec2::new(vx, vy),
    }
}

/// A bead dropped from 1 m (its lowest point) onto a floor, both of
/// restitution 0.5 (the strike takes their mean), rises to `e² h`: to
/// 1e-9, its instant of impact found within the step.
#[test]
fn a_bead_dropped_on_a_floor_rises_to_e_squared_h() {
    let (g, dt, r, h) = (9.81, 1.0 / 240.0, 0.02, 1.0);
    let mut falling = Falling::new(&[at(0.0, h + r, 0.0, 0.0)], 1.0, DVec2::new(0.0, -g));
    let mut floor = Slab::floor(0.5);
    let pairs = [bead(0.5, r)];
    let mut struck = Vec::new();
    let mut time = 0.0;
    let (mut top, mut hit) = (0.0_f64, false);
    for _ in 0..240 {
        falling.step(dt);
        let span = StepSpan { time, dt };
        meet_obstacles(
            span,
            &mut falling,
            (&pairs, &mut [&mut floor]),
            true,
            (&mut struck, &mut Vec::new()),
        )
        .unwrap();
        time += dt;
        let s = falling.end[0];
        assert!(
            s.position.y >= r - 1e-12,
            "in the floor at {}",
            s.position.y
        );
        if hit && struck.len() == 1 && s.velocity.y < 0.0 && s.velocity.y + g * dt >= 0.0 {
            // The apex lies within this step: from its start, exactly.
            let v0 = falling.start[0].velocity.y;
            top = top.max(falling.start[0].position.y + v0 * v0 / (2.0 * g) - r);
        }
        hit |= !struck.is_empty();
    }
    // It strikes again, from e² h, at e times the speed.
    assert_eq!(struck.len(), 2, "two strikes: {struck:?}");
    let strike = struck[0];
    let closing = (2.0 * g * h).sqrt();
    assert!((strike.strike.closing_speed - closing).abs() < 1e-9 * closing);
    assert!((strike.time - (2.0 * h / g).sqrt()).abs() < 1e-9);
    assert!(
        (strike.impulse.y + 1.5 * closing).abs() < 1e-9,
        "{strike:?}"
    );
    assert!((struck[1].strike.closing_speed - 0.5 * closing).abs() < 1e-9 * closing);
    assert!((top - 0.25 * h).abs() < 1e-9, "rose to {top}");
}

/// A bead at 2 km/s meets a slab 1 mm thick within one step of 10 ms (20
/// m): it bounces off its near face (e = 1), ending as far before it as
/// it would have gone past, never through.
#[test]
fn a_bead_as_fast_as_a_bullet_does_not_pass_through_a_thin_slab() {
    let (dt, r) = (0.01, 0.01);
    let mut falling = Falling::new(&[at(0.0, 5.0, 0.0, -2000.0)], 1.0, DVec2::ZERO);
    let mut slab = Slab {
        lo: -0.001,
        hi: 0.0,
        ..Slab::floor(1.0)
    };
    let mut struck = Vec::new();
    falling.step(dt);
    assert!(falling.end[0].position.y < -10.0, "passed it untouched");
    let span = StepSpan { time: 0.0, dt };
    meet_obstacles(
        span,
        &mut falling,
        (&[bead(1.0, r)], &mut [&mut slab]),
        true,
        (&mut struck, &mut Vec::new()),
    )
    .unwrap();
    let s = falling.end[0];
    // 5 m − r to the face, 20 m in all: 15 m + r back up.
    assert!((s.position.y - (r + 15.0 + r)).abs() < 1e-9, "{s:?}");
    assert!((s.velocity.y - 2000.0).abs() < 1e-9);
    assert_eq!(struck.len(), 1);
}

/// A bead striking a free body of its own mass head on at `e = 1` stops,
/// the body taking all its momentum: the impulse on the body is `m u`.
#[test]
fn a_bead_gives_a_free_body_of_its_mass_all_its_momentum() {
    let (dt, r, u) = (0.01, 0.05, 3.0);
    let mut falling = Falling::new(&[at(0.0, 0.06, 0.0, -u)], 2.0, DVec2::ZERO);
    let mut body = Slab {
        mass: Some(2.0),
        ..Slab::floor(1.0)
    };
    let mut struck = Vec::new();
    falling.step(dt);
    let span = StepSpan { time: 0.0, dt };
    meet_obstacles(
        span,
        &mut falling,
        (&[bead(1.0, r)], &mut [&mut body]),
        true,
        (&mut struck, &mut Vec::new()),
    )
    .unwrap();
    assert!(falling.end[0].velocity.length() < 1e-12);
    assert_eq!(struck.len(), 1);
    assert!((struck[0].impulse - DVec2::new(0.0, -2.0 * u)).length() < 1e-12);
}

/// A bead resting on a floor stays on it, step after step, at no
/// overlap and no speed; on a platform rising at 0.5 m/s it rides it up.
#[test]
fn a_bead_rests_on_a_floor_and_rides_a_rising_platform() {
    let (g, dt, r) = (9.81, 1.0 / 60.0, 0.02);
    for rise in [0.0, 0.5] {
        let mut falling = Falling::new(&[at(0.0, r, 0.0, rise)], 1.0, DVec2::new(0.0, -g));
        let mut struck = Vec::new();
        let mut top = 0.0;
        for k in 0..120 {
            falling.step(dt);
            let span = StepSpan {
                time: k as f64 * dt,
                dt,
            };
            let mut floor = Slab {
                lo: top - 1.0,
                hi: top,
                rise,
                dt,
                ..Slab::floor(0.5)
            };
            meet_obstacles(
                span,
                &mut falling,
                (&[bead(0.5, r)], &mut [&mut floor]),
                true,
                (&mut struck, &mut Vec::new()),
            )
            .unwrap();
            top += rise * dt;
            let s = falling.end[0];
            assert!(
                (s.position.y - (top + r)).abs() < 1e-12,
                "{rise}: {s:?} over {top}"
            );
            assert!((s.velocity.y - rise).abs() < 1e-12, "{rise}: {s:?}");
        }
        assert!(struck.iter().all(|s| !s.strike.bounced));
    }
}
