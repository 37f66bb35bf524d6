//! Beads on surfaces in space through the solver's one-row step, the
//! same code that steps a bead on a curve in the plane.

use std::f64::consts::TAU;

use crate::common;
use bevy::math::{DVec2, DVec3};
use wirebead::geometry::{
    Circle, Cylinder, FixedTrack, ImplicitCurve, ImplicitSurface, Placed, PlacedSurface, Pose,
    Pose3, Sphere,
};
use wirebead::solver::{
    BeadState, LinearForce, Method, Stabilization, StepSettings, constraint_state_on, step_on,
};

const G: f64 = 9.81;

fn settings(method: Method, dt: f64) -> StepSettings {
    common::params(method, dt).step_settings()
}

/// Steps a bead in the plane on `curve` and one in space on `surface`
/// side by side for `steps` steps, from the same start in the xy-plane at
/// rest or moving in it, under gravity along −y: how far apart they got
/// and how far the one in space left the plane (`|z|` or `|v_z|`).
fn plane_against_space<C: ImplicitCurve + ?Sized, S: ImplicitSurface + ?Sized>(
    curve: &C,
    surface: &S,
    start: BeadState,
    s: &StepSettings,
    steps: usize,
) -> (f64, f64) {
    let mut flat = start;
    let mut round = BeadState {
        position: start.position.extend(0.0),
        velocity: start.velocity.extend(0.0),
    };
    let (plane_force, space_force) = (
        LinearForce::constant(DVec2::new(0.0, -G)),
        LinearForce::constant(DVec3::new(0.0, -G, 0.0)),
    );
    let (mut apart, mut off) = (0.0f64, 0.0f64);
    for k in 0..steps {
        let t = k as f64 * s.dt;
        flat = step_on(&FixedTrack(curve), t, flat, &plane_force, 1.0, s)
            .expect("a step in the plane")
            .state;
        round = step_on(&FixedTrack(surface), t, round, &space_force, 1.0, s)
            .expect("a step in space")
            .state;
        apart = apart.max((round.position.truncate() - flat.position).length());
        off = off.max(round.position.z.abs()).max(round.velocity.z.abs());
    }
    (apart, off)
}

/// A bead inside a sphere of radius `r`, `alpha` from the downward
/// vertical, moving round the vertical axis at the conical pendulum's
/// speed `v² = g r sin²α / cos α`.
pub(crate) fn conical_start(r: f64, alpha: f64) -> (BeadState<DVec3>, f64) {
    let v = (G * r * alpha.sin().powi(2) / alpha.cos()).sqrt();
    let state = BeadState {
        position: DVec3::new(r * alpha.sin(), -r * alpha.cos(), 0.0),
        velocity: DVec3::new(0.0, 0.0, -v),
    };
    (state, v)
}

/// A bead's turns about the vertical axis, from +x through −z (the
/// azimuth about +y growing, unwrapped), and the time each was completed,
/// interpolated within its step.
#[derive(Default)]
struct Turns {
    turned: f64,
    previous: f64,
    passes: Vec<f64>,
}

impl Turns {
    /// Takes in the bead at `position` at the end `t` of a step of `dt`.
    fn note(&mut self, position: DVec3, t: f64, dt: f64) {
        let azimuth = (-position.z).atan2(position.x);
        let mut delta = azimuth - self.previous;
        if delta < -TAU / 2.0 {
            delta += TAU;
        }
        self.previous = azimuth;
        let before = self.turned;
        self.turned += delta;
        let k = (self.passes.len() + 1) as f64;
        if before < TAU * k && self.turned >= TAU * k {
            let fraction = (TAU * k - before) / (self.turned - before);
            self.passes.push(t - dt + fraction * dt);
        }
    }

    /// How many whole turns.
    fn count(&self) -> usize {
        self.passes.len()
    }

    /// The mean time of a turn, from the start.
    fn period(&self) -> f64 {
        self.passes[self.passes.len() - 1] / self.passes.len() as f64
    }
}

/// RATTLE at 1 ms: the conical pendulum keeps its height to 1e-5 r and
/// goes round in `2π r sin α / v` to 1e-5 (relative).
#[test]
fn a_conical_pendulum_on_a_sphere_keeps_its_height_and_period() {
    let (r, alpha) = (1.5, 0.6);
    let sphere = Sphere { radius: r };
    let track = FixedTrack(&sphere);
    let (mut state, v) = conical_start(r, alpha);
    let force = LinearForce::constant(DVec3::new(0.0, -G, 0.0));
    let s = settings(Method::Rattle, 1e-3);
    let period = TAU * r * alpha.sin() / v;
    let (height, mut worst) = (state.position.y, 0.0f64);
    let mut turns = Turns::default();
    let mut t = 0.0;
    while turns.count() < 3 {
        let out = step_on(&track, t, state, &force, 1.0, &s).expect("a step");
        state = out.state;
        t += s.dt;
        worst = worst.max((state.position.y - height).abs());
        turns.note(state.position, t, s.dt);
        assert!(t < 10.0 * period, "the bead did not go round");
    }
    assert!(worst <= 1e-5 * r, "height moved {worst:e}");
    let measured = turns.period();
    let error = (measured - period).abs() / period;
    assert!(
        error <= 1e-5,
        "period {measured} against {period}: {error:e}"
    );
    let (c, c_dot) = constraint_state_on(&track, t, state);
    assert!(
        c.abs() <= 1e-12 && c_dot.abs() <= 1e-12,
        "C = {c:e}, Ċ = {c_dot:e}"
    );
}

/// From a start that is not a circular orbit, RATTLE keeps the angular
/// momentum about the vertical to rounding (gravity and the sphere's
/// push have no moment about it) and the energy to 1e-5 of m g r.
#[test]
fn a_spherical_pendulum_keeps_its_vertical_angular_momentum_and_energy() {
    let r = 1.0;
    let sphere = Sphere { radius: r };
    let track = FixedTrack(&sphere);
    let mut state = BeadState {
        position: DVec3::new(r * 0.8f64.sin(), -r * 0.8f64.cos(), 0.0),
        velocity: DVec3::new(0.0, 0.0, -1.3),
    };
    let m = 0.7;
    let gravity = DVec3::new(0.0, -G, 0.0);
    let force = LinearForce::constant(m * gravity);
    let s = settings(Method::Rattle, 1e-3);
    let momentum =
        |b: &BeadState<DVec3>| m * (b.position.z * b.velocity.x - b.position.x * b.velocity.z);
    let energy = |b: &BeadState<DVec3>| {
        let (kinetic, potential) = b.energy(m, gravity);
        kinetic + potential
    };
    let (l0, e0) = (momentum(&state), energy(&state));
    let (mut worst_l, mut worst_e) = (0.0f64, 0.0f64);
    for k in 0..5000 {
        state = step_on(&track, k as f64 * s.dt, state, &force, m, &s)
            .expect("a step")
            .state;
        worst_l = worst_l.max((momentum(&state) - l0).abs());
        worst_e = worst_e.max((energy(&state) - e0).abs());
    }
    assert!(worst_l <= 1e-11 * l0.abs(), "L_y moved {worst_l:e} of {l0}");
    assert!(worst_e <= 1e-5 * m * G * r, "energy moved {worst_e:e}");
}

/// A bead on a sphere moving in its xy great circle is a bead on a
/// circle: every stabilized method gives the plane's trajectory, with z and its
/// velocity exactly zero.
#[test]
fn a_sphere_cut_through_its_centre_steps_as_the_circle_does() {
    let sphere = Sphere { radius: 1.2 };
    let circle = Circle { radius: 1.2 };
    let start = BeadState {
        position: DVec2::new(1.2 * 0.9f64.sin(), -1.2 * 0.9f64.cos()),
        velocity: DVec2::new(0.5, 0.2),
    };
    // Every stabilized method (the unstabilized ones drift off the
    // circle at this step in either dimension).
    let stabilized = Method::ALL
        .into_iter()
        .filter(|m| m.stabilization() != Some(Stabilization::None));
    for method in stabilized {
        let s = settings(method, 1.0 / 60.0);
        let (apart, off) = plane_against_space(&circle, &sphere, start, &s, 300);
        assert_eq!(off, 0.0, "{method}: left the plane");
        assert!(
            apart <= 1e-10,
            "{method}: {apart:e} from the plane's trajectory"
        );
    }
}

/// Every method holds a bead on a sphere: the drift stays within the
/// method's own bound over 5 s of a swinging spherical pendulum.
#[test]
fn every_method_steps_a_bead_on_a_sphere() {
    let r = 1.0;
    let sphere = Sphere { radius: r };
    let track = FixedTrack(&sphere);
    for (method, bound) in [
        (Method::ExplicitEuler(Stabilization::Baumgarte), 1e-2),
        (Method::SemiImplicitEuler(Stabilization::Baumgarte), 1e-2),
        (Method::SemiImplicitEuler(Stabilization::Projection), 1e-12),
        (Method::Rk4(Stabilization::Baumgarte), 1e-3),
        (Method::Rk4(Stabilization::Projection), 1e-12),
        (Method::Rattle, 1e-12),
    ] {
        let (mut state, _) = conical_start(r, 0.5);
        state.velocity *= 0.6;
        let force = LinearForce::constant(DVec3::new(0.0, -G, 0.0));
        let s = settings(method, 1.0 / 240.0);
        let mut worst = 0.0f64;
        for k in 0..1200 {
            let out = step_on(&track, k as f64 * s.dt, state, &force, 1.0, &s)
                .unwrap_or_else(|e| panic!("{method}: {e}"));
            state = out.state;
            worst = worst.max(out.c.abs());
        }
        assert!(worst <= bound * r, "{method}: |C| reached {worst:e}");
    }
}

/// A cylinder turned to lie along z is, in the xy-plane, a circle: a
/// bead on it that does not move along its axis follows the plane's
/// bead on the circle (to 1e-10 over 5 s), z and its velocity kept
/// within 1e-12 (the turn's rounding: cos 90° is 6e-17, not 0).
#[test]
fn a_cylinder_lying_along_z_steps_as_the_circle_does() {
    let cylinder = Cylinder { radius: 0.8 };
    let turned = PlacedSurface {
        surface: &cylinder,
        pose: Pose3::from_axis_angle(DVec3::new(0.5, -0.25, 0.0), DVec3::X, TAU / 4.0)
            .expect("a pose"),
    };
    let circle = Placed {
        curve: &Circle { radius: 0.8 },
        pose: Pose::new(DVec2::new(0.5, -0.25), 0.0),
    };
    let start = BeadState {
        position: DVec2::new(0.5 + 0.8, -0.25),
        velocity: DVec2::ZERO,
    };
    let s = settings(Method::Rattle, 1e-3);
    let (apart, off) = plane_against_space(&circle, &turned, start, &s, 5000);
    assert!(off <= 1e-12, "left the plane by {off:e}");
    assert!(apart <= 1e-10, "{apart:e} from the plane's trajectory");
}

/// A bead released 2° from the top of a one-sided sphere (it pushes
/// outward only) slides off where the sphere would have to pull:
/// `cos θ = ⅔ cos θ₀` (energy and the normal force), then falls at g.
#[test]
fn a_bead_slides_off_a_one_sided_sphere_where_cos_theta_is_two_thirds() {
    use wirebead::geometry::{Side, Surface};
    use wirebead::solver::{Contact, ContactEvent, step_surface};
    let r = 2.0;
    let sphere = Sphere { radius: r };
    let track = FixedTrack(&sphere);
    let surface = Surface {
        side: Side::Positive,
        ..Surface::PLAIN
    };
    let theta0 = 2f64.to_radians();
    // Tipped toward +x and −z at once, so the slide is off every axis.
    let across = DVec3::new(1.0, 0.0, -1.0).normalize();
    let mut state = BeadState {
        position: r * (theta0.cos() * DVec3::Y + theta0.sin() * across),
        velocity: DVec3::ZERO,
    };
    let gravity = DVec3::new(0.0, -G, 0.0);
    let force = LinearForce::constant(gravity);
    let s = settings(Method::Rattle, 1e-3);
    let mut contact = Contact::OnWire;
    let mut left = None;
    let mut t = 0.0;
    while t < 3.0 {
        let step =
            step_surface(&track, t, state, &force, 1.0, &s, &surface, contact).expect("a step");
        if let Some(ContactEvent::Left { time, position }) = step.event {
            left = Some((time, position));
        }
        let before = state;
        state = step.output.state;
        contact = step.contact;
        t += s.dt;
        if let Some((time, _)) = left
            && time < t - s.dt
        {
            // In flight for the whole step: the velocity gains g dt.
            let gained = state.velocity - before.velocity;
            assert!(
                (gained - gravity * s.dt).length() <= 1e-12,
                "in flight the bead gained {gained} in a step"
            );
        }
        if state.position.y < -r {
            break;
        }
    }
    let (_, at) = left.expect("the bead left the sphere");
    let cos_theta = at.y / at.length();
    let expected = 2.0 / 3.0 * theta0.cos();
    assert!(
        (cos_theta - expected).abs() <= 1e-6,
        "left at cos θ = {cos_theta}, expected {expected}"
    );
    // It left in the plane it slid in.
    assert!((at.x + at.z).abs() <= 1e-12 * r, "left at {at}");
    assert_eq!(contact, Contact::InFlight);
}

/// A plane spinning at ω about an axis that lies in it flings a bead
/// that starts at rest on it (relative to it), with no gravity, along the
/// plane away from the axis: its distance from the axis is `r₀ cosh ωt`,
/// as on the plane's spinning rod.
#[test]
fn a_bead_on_a_plane_spinning_about_an_axis_in_it_slides_out_as_cosh() {
    use wirebead::geometry::{MovingSurface, Plane, SpaceMotion, SpacePath};
    let (r0, omega) = (0.2, 2.0);
    // The plane y = 0 spins about z, which lies in it.
    let path = SpacePath::Prescribed {
        base: Pose3::IDENTITY,
        motion: SpaceMotion::Spin {
            angular_velocity: omega,
            axis: DVec3::Z,
        },
    };
    let track = MovingSurface {
        surface: &Plane,
        path: &path,
    };
    let start = DVec3::new(r0, 0.0, 0.4);
    let mut state = BeadState {
        position: start,
        // Moving with the plane: ω ẑ × r.
        velocity: DVec3::new(0.0, omega * r0, 0.0),
    };
    let s = settings(Method::Rattle, 1e-3);
    let none = LinearForce::constant(DVec3::ZERO);
    let mut worst = 0.0f64;
    for k in 0..1500 {
        let t = k as f64 * s.dt;
        state = step_on(&track, t, state, &none, 1.0, &s)
            .expect("a step")
            .state;
        let exact = r0 * (omega * (t + s.dt)).cosh();
        let rho = state.position.truncate().length();
        worst = worst.max((rho - exact).abs() / exact);
        // Nothing pushes along the axis.
        assert!((state.position.z - start.z).abs() <= 1e-12);
    }
    assert!(
        worst <= 1e-5,
        "relative error in the distance reached {worst:e}"
    );
}

/// A sphere spinning about its centre moves none of its points off
/// itself: a frictionless bead on it moves as on the sphere at rest, the
/// frame's terms of eq. (15) cancelling, to 1e-9 over 3 s.
#[test]
fn a_sphere_spinning_about_its_centre_does_not_move_a_frictionless_bead() {
    use wirebead::geometry::{MovingSurface, SpaceMotion, SpacePath};
    let sphere = Sphere { radius: 1.0 };
    let path = SpacePath::Prescribed {
        base: Pose3::IDENTITY,
        motion: SpaceMotion::Spin {
            angular_velocity: 3.0,
            axis: DVec3::new(0.3, 1.0, -0.2),
        },
    };
    let spinning = MovingSurface {
        surface: &sphere,
        path: &path,
    };
    let (start, _) = conical_start(1.0, 0.7);
    let (mut still, mut turning) = (start, start);
    let s = settings(Method::Rattle, 1e-3);
    let gravity = LinearForce::constant(DVec3::new(0.0, -G, 0.0));
    let mut worst = 0.0f64;
    for k in 0..3000 {
        let t = k as f64 * s.dt;
        still = step_on(&FixedTrack(&sphere), t, still, &gravity, 1.0, &s)
            .expect("a step on the sphere at rest")
            .state;
        turning = step_on(&spinning, t, turning, &gravity, 1.0, &s)
            .expect("a step on the spinning sphere")
            .state;
        worst = worst.max((still.position - turning.position).length());
    }
    assert!(worst <= 1e-9, "{worst:e} between the two");
}

/// Circular orbits on the other surfaces, each held by its own Hessian in
/// eq. (3), RATTLE at 1 ms for 2 s:
/// - inside a cone (apex down, half angle a), at radius ρ the wall holds a
///   bead going round at `v² = g ρ cot a` at its height;
/// - on a torus with no gravity, the outer equator is a circle the bead
///   keeps, at its speed;
/// - on a vertical cylinder a bead thrown round falls as `−½ g t²` and
///   keeps its angular speed.
#[test]
fn beads_keep_their_orbits_on_a_cone_a_torus_and_a_cylinder() {
    use wirebead::geometry::{Cone, Cylinder, Torus};
    let s = settings(Method::Rattle, 1e-3);
    let run = |track: &dyn Fn(f64, BeadState<DVec3>) -> BeadState<DVec3>,
               mut state: BeadState<DVec3>,
               check: &dyn Fn(f64, BeadState<DVec3>) -> f64| {
        let mut worst = 0.0f64;
        for k in 0..2000 {
            let t = k as f64 * s.dt;
            state = track(t, state);
            worst = worst.max(check(t + s.dt, state));
        }
        worst
    };
    let gravity = LinearForce::constant(DVec3::new(0.0, -G, 0.0));
    let none = LinearForce::constant(DVec3::ZERO);

    let (a, rho) = (0.5f64, 0.8);
    let cone = Cone { half_angle: a };
    let v = (G * rho / a.tan()).sqrt();
    let height = rho / a.tan();
    let on_cone = |t: f64, b: BeadState<DVec3>| {
        step_on(&FixedTrack(&cone), t, b, &gravity, 1.0, &s)
            .expect("a step on the cone")
            .state
    };
    let start = BeadState {
        position: DVec3::new(rho, height, 0.0),
        velocity: DVec3::new(0.0, 0.0, v),
    };
    let drift = run(&on_cone, start, &|_, b| (b.position.y - height).abs());
    assert!(drift <= 2e-5 * rho, "the cone's orbit moved {drift:e}");

    let torus = Torus {
        major_radius: 1.5,
        minor_radius: 0.4,
    };
    let (outer, u) = (1.9, 2.5);
    let on_torus = |t: f64, b: BeadState<DVec3>| {
        step_on(&FixedTrack(&torus), t, b, &none, 1.0, &s)
            .expect("a step on the torus")
            .state
    };
    let start = BeadState {
        position: DVec3::new(outer, 0.0, 0.0),
        velocity: DVec3::new(0.0, 0.0, u),
    };
    let off = run(&on_torus, start, &|_, b| {
        let ring = (b.position.x.hypot(b.position.z) - outer).abs();
        ring.max(b.position.y.abs())
            .max((b.velocity.length() - u).abs())
    });
    assert!(off <= 1e-9, "left the torus's outer equator by {off:e}");

    let cylinder = Cylinder { radius: 0.6 };
    let spin = 2.0;
    let on_cylinder = |t: f64, b: BeadState<DVec3>| {
        step_on(&FixedTrack(&cylinder), t, b, &gravity, 1.0, &s)
            .expect("a step on the cylinder")
            .state
    };
    let start = BeadState {
        position: DVec3::new(0.6, 0.0, 0.0),
        velocity: DVec3::new(0.0, 0.0, 0.6 * spin),
    };
    let fall = run(&on_cylinder, start, &|t, b| {
        let y = -0.5 * G * t * t;
        let angular = (b.position.x * b.velocity.z - b.position.z * b.velocity.x) / 0.36;
        (b.position.y - y).abs().max((angular - spin).abs())
    });
    assert!(fall <= 1e-9, "the fall or the turn was off by {fall:e}");
}

/// The conical pendulum again, as an island: a bob on a rod from a bead
/// pinned in space by three axis rows, RATTLE at 1 ms. It keeps its
/// height to 1e-5 L and goes round in `2π L sin α / v` to 1e-5.
#[test]
fn a_conical_pendulum_on_a_rod_from_a_pin_keeps_its_height_and_period() {
    use wirebead::solver::{Island, IslandRow, IslandWork, RowKind};
    let (length, alpha) = (1.2, 0.5);
    let axis = |axis: DVec3| IslandRow {
        kind: RowKind::Axis { axis, offset: 0.0 },
        beads: vec![0],
    };
    let rows = vec![
        axis(DVec3::X),
        axis(DVec3::Y),
        axis(DVec3::Z),
        IslandRow {
            kind: RowKind::Rod { length },
            beads: vec![0, 1],
        },
    ];
    let island = Island::new(&[1.0, 0.5], rows, vec![]).expect("an island");
    let mut work = IslandWork::default();
    let (bob, v) = conical_start(length, alpha);
    let mut states = [BeadState::default(), bob];
    let gravity = DVec3::new(0.0, -G, 0.0);
    let forces = [
        LinearForce::constant(gravity),
        LinearForce::constant(gravity * 0.5),
    ];
    let s = settings(Method::Rattle, 1e-3);
    let period = TAU * length * alpha.sin() / v;
    let height = bob.position.y;
    let (mut worst, mut t) = (0.0f64, 0.0);
    let mut turns = Turns::default();
    while turns.count() < 2 {
        island
            .step_at(t, &mut states, &forces, &s, &mut work)
            .expect("a step");
        t += s.dt;
        worst = worst.max((states[1].position.y - height).abs());
        turns.note(states[1].position, t, s.dt);
        assert!(t < 10.0 * period, "the bob did not go round");
    }
    assert!(worst <= 1e-5 * length, "height moved {worst:e}");
    let error = (turns.period() - period).abs() / period;
    assert!(error <= 1e-5, "period off by {error:e}");
    assert!(states[0].position.length() <= 1e-12, "the pin moved");
}

/// Two beads on a sphere joined by a rod, as an island of two surface
/// rows and a rod row: RATTLE keeps both on the sphere and the rod's
/// length to 1e-12 and the energy to 1e-5 of m g r over 3 s.
#[test]
fn a_rod_between_two_beads_on_a_sphere_holds_as_an_island() {
    use wirebead::geometry::SpaceRow;
    use wirebead::solver::{Island, IslandRow, IslandWork, RowKind};
    let r = 1.0;
    let wire = || RowKind::Wire {
        shape: SpaceRow::surface(Sphere { radius: r }),
        pose: Pose3::IDENTITY,
    };
    let a = DVec3::new(0.6, -0.8, 0.0);
    let b = DVec3::new(0.0, -0.8, 0.6);
    let length = (a - b).length();
    let rows = vec![
        IslandRow {
            kind: wire(),
            beads: vec![0],
        },
        IslandRow {
            kind: wire(),
            beads: vec![1],
        },
        IslandRow {
            kind: RowKind::Rod { length },
            beads: vec![0, 1],
        },
    ];
    let masses = [1.0, 2.0];
    let island = Island::new(&masses, rows, vec![]).expect("an island");
    let mut work = IslandWork::default();
    let mut states = [
        BeadState {
            position: a,
            velocity: DVec3::new(0.0, 0.0, 1.0),
        },
        BeadState {
            position: b,
            velocity: DVec3::new(-1.0, 0.0, 0.0),
        },
    ];
    let gravity = DVec3::new(0.0, -G, 0.0);
    let forces = masses.map(|m| LinearForce::constant(gravity * m));
    let energy = |states: &[BeadState<DVec3>]| {
        states
            .iter()
            .zip(masses)
            .map(|(s, m)| {
                let (kinetic, potential) = s.energy(m, gravity);
                kinetic + potential
            })
            .sum::<f64>()
    };
    let e0 = energy(&states);
    let s = settings(Method::Rattle, 1e-3);
    let (mut off, mut drift) = (0.0f64, 0.0f64);
    for k in 0..3000 {
        island
            .step_at(k as f64 * s.dt, &mut states, &forces, &s, &mut work)
            .expect("a step");
        for state in &states {
            off = off.max((state.position.length() - r).abs());
        }
        off = off.max(((states[0].position - states[1].position).length() - length).abs());
        drift = drift.max((energy(&states) - e0).abs());
    }
    assert!(off <= 1e-12, "off the sphere or the rod by {off:e}");
    assert!(drift <= 1e-5 * 3.0 * G * r, "energy moved {drift:e}");
}

/// The two rows of bead 0 of an island on `curve`, in its own frame.
pub(crate) fn curve_rows(
    curve: impl wirebead::geometry::SpaceCurve + Send + Sync + 'static,
) -> [wirebead::solver::IslandRow<DVec3>; 2] {
    wirebead::geometry::SpaceRow::curve(curve).map(|shape| wirebead::solver::IslandRow {
        kind: wirebead::solver::RowKind::Wire {
            shape,
            pose: Pose3::IDENTITY,
        },
        beads: vec![0],
    })
}

/// A hoop of radius `r` in its local xy-plane, its centre at the origin,
/// spinning about the vertical y-axis at `omega`: the island of one bead
/// held by the hoop's plane and its circle drawn out of it.
fn hoop(
    r: f64,
    omega: f64,
) -> (
    wirebead::solver::Island<DVec3>,
    wirebead::geometry::SpacePath,
) {
    use wirebead::geometry::{OnPlane, SpaceMotion, SpacePath};
    use wirebead::solver::Island;
    let rows = curve_rows(OnPlane(Circle { radius: r })).to_vec();
    let mut island = Island::new(&[1.0], rows, vec![]).expect("a hoop");
    let path = SpacePath::Prescribed {
        base: Pose3::IDENTITY,
        motion: SpaceMotion::Spin {
            angular_velocity: omega,
            axis: DVec3::Y,
        },
    };
    island.move_wire(0, None, path);
    island.move_wire(1, None, path);
    (island, path)
}

/// A bead on the hoop at angle `theta` from its bottom at time `t`, at
/// rest relative to the hoop (plus `rate`, dθ/dt along it).
fn on_hoop(
    path: &wirebead::geometry::SpacePath,
    r: f64,
    theta: f64,
    rate: f64,
    t: f64,
) -> BeadState<DVec3> {
    let (pose, twist) = path.at(t);
    let local = DVec3::new(r * theta.sin(), -r * theta.cos(), 0.0);
    let along = DVec3::new(r * theta.cos(), r * theta.sin(), 0.0) * rate;
    let position = pose.to_world(local);
    BeadState {
        position,
        velocity: twist.velocity_at(position) + pose.rotate(along),
    }
}

/// The angle from the hoop's bottom of a bead at `position` at time `t`.
fn hoop_angle(path: &wirebead::geometry::SpacePath, position: DVec3, t: f64) -> f64 {
    let local = path.at(t).0.to_local(position);
    local.x.atan2(-local.y)
}

/// The rotating hoop (RATTLE): above `ω² = g/r` a bead released at
/// relative rest at `cos θ* = g/(ω² r)` stays there to 1e-6 rad over
/// 10 s (at 0.5 ms; the rest at 1 ms); released 0.01 rad off it, it oscillates about θ* at
/// `Ω = ω sin θ*` (within 1e-3); below, the bottom is stable with
/// `Ω² = g/r − ω²`. The Jacobi integral `½|v_rel|² − ½ω²ρ² + g y` (per
/// unit mass) holds to 1e-6 of g r.
#[test]
fn the_rotating_hoop_bifurcates_at_omega_squared_g_over_r() {
    use wirebead::solver::IslandWork;
    let r = 1.0;
    let gravity = [LinearForce::constant(DVec3::new(0.0, -G, 0.0))];
    // Steps the hoop for `duration` at `dt` from θ0 at relative rest; the
    // angles and the Jacobi integral's largest change.
    let run = |omega: f64, theta0: f64, duration: f64, dt: f64| {
        let s = settings(Method::Rattle, dt);
        let (island, path) = hoop(r, omega);
        let mut work = IslandWork::default();
        let mut states = [on_hoop(&path, r, theta0, 0.0, 0.0)];
        let jacobi = |b: &BeadState<DVec3>, t: f64| {
            let relative = b.velocity - path.at(t).1.velocity_at(b.position);
            let rho2 = b.position.x * b.position.x + b.position.z * b.position.z;
            0.5 * relative.dot(relative) - 0.5 * omega * omega * rho2 + G * b.position.y
        };
        let j0 = jacobi(&states[0], 0.0);
        let (mut angles, mut worst) = (Vec::new(), 0.0f64);
        let steps = (duration / s.dt).round() as usize;
        for k in 0..steps {
            let t = k as f64 * s.dt;
            island
                .step_at(t, &mut states, &gravity, &s, &mut work)
                .expect("a step");
            let t1 = t + s.dt;
            angles.push((t1, hoop_angle(&path, states[0].position, t1)));
            worst = worst.max((jacobi(&states[0], t1) - j0).abs());
        }
        (angles, worst)
    };
    let period = |angles: &[(f64, f64)], about: f64| {
        let shifted: Vec<(f64, f64)> = angles.iter().map(|&(t, a)| (t, a - about)).collect();
        wirebead::reference::period_from_crossings(&shifted).expect("oscillations")
    };

    let omega = 6.0;
    let star = (G / (omega * omega * r)).acos();
    // RATTLE's own equilibrium is θ* to O(h²): at 0.5 ms, within 1e-6.
    let (angles, jacobi) = run(omega, star, 10.0, 5e-4);
    let held = angles
        .iter()
        .map(|&(_, a)| (a - star).abs())
        .fold(0.0, f64::max);
    assert!(held <= 1e-6, "θ* = {star} wandered by {held:e}");
    assert!(
        jacobi <= 1e-6 * G * r,
        "the Jacobi integral moved {jacobi:e}"
    );

    let (angles, _) = run(omega, star + 0.01, 5.0, 1e-3);
    let expected = TAU / (omega * star.sin());
    let measured = period(&angles, star);
    assert!(
        (measured - expected).abs() / expected <= 1e-3,
        "about θ* the period was {measured}, against {expected}"
    );

    let omega = 2.0;
    let (angles, jacobi) = run(omega, 0.01, 5.0, 1e-3);
    let expected = TAU / (G / r - omega * omega).sqrt();
    let measured = period(&angles, 0.0);
    assert!(
        (measured - expected).abs() / expected <= 1e-3,
        "about the bottom the period was {measured}, against {expected}"
    );
    assert!(
        jacobi <= 1e-6 * G * r,
        "the Jacobi integral moved {jacobi:e}"
    );
}

/// A circle in space (two rows of one bead: its plane, and the circle
/// drawn out of it), steps as the plane's bead on the circle: RATTLE
/// over 5 s at 1 ms, the trajectories within 1e-10, z and its velocity
/// exactly 0.
#[test]
fn a_circle_in_space_steps_as_the_circle_in_the_plane() {
    use wirebead::geometry::OnPlane;
    let r = 0.9;
    let start = DVec2::new(r * 1.2f64.sin(), -r * 1.2f64.cos());
    let circle = Circle { radius: r };
    let worst = curve_against_plane(&circle, OnPlane(circle), start, 5000);
    assert!(worst <= 1e-10, "{worst:e} from the plane's trajectory");
}

/// Steps a bead from rest at `start` on `curve` in the plane and one on
/// `in_space`, the same curve in the xy-plane in space (its two rows on
/// one bead), side by side with RATTLE at 1 ms for `steps` steps: how far
/// apart they got. The one in space keeps `z` and its velocity exactly 0.
pub(crate) fn curve_against_plane<C: ImplicitCurve>(
    curve: &C,
    in_space: impl wirebead::geometry::SpaceCurve + Send + Sync + 'static,
    start: DVec2,
    steps: usize,
) -> f64 {
    use wirebead::solver::{Island, IslandWork};
    let island = Island::new(&[1.0], curve_rows(in_space).to_vec(), vec![]).expect("an island");
    let mut work = IslandWork::default();
    let mut flat = BeadState {
        position: start,
        velocity: DVec2::ZERO,
    };
    let mut round = [BeadState {
        position: start.extend(0.0),
        velocity: DVec3::ZERO,
    }];
    let s = settings(Method::Rattle, 1e-3);
    let plane_force = LinearForce::constant(DVec2::new(0.0, -G));
    let space_force = [LinearForce::constant(DVec3::new(0.0, -G, 0.0))];
    let mut worst = 0.0f64;
    for k in 0..steps {
        let t = k as f64 * s.dt;
        flat = step_on(&FixedTrack(curve), t, flat, &plane_force, 1.0, &s)
            .expect("a step in the plane")
            .state;
        island
            .step_at(t, &mut round, &space_force, &s, &mut work)
            .expect("a step in space");
        worst = worst.max((round[0].position.truncate() - flat.position).length());
        assert_eq!((round[0].position.z, round[0].velocity.z), (0.0, 0.0));
    }
    worst
}

/// A bead from rest on a helix (its two rows: a cylinder's and a
/// helicoid's), RATTLE at 1 ms for 3 s: it slides down as on an incline of
/// slope φ, `y(t) = −½ g sin²φ t²` with `tan φ = p/(2πr)`, within 1e-5
/// relative, and stays on both surfaces to 1e-12.
#[test]
fn a_bead_slides_down_a_helix_as_down_an_incline() {
    use wirebead::geometry::{Helicoid, Helix};
    use wirebead::solver::{Island, IslandWork};
    let (r, pitch) = (1.0, 1.0);
    let rows = curve_rows(Helix { radius: r, pitch }).to_vec();
    let island = Island::new(&[1.0], rows, vec![]).expect("a helix");
    let mut work = IslandWork::default();
    let mut states = [BeadState {
        position: DVec3::new(r, 0.0, 0.0),
        velocity: DVec3::ZERO,
    }];
    let gravity = [LinearForce::constant(DVec3::new(0.0, -G, 0.0))];
    let s = settings(Method::Rattle, 1e-3);
    let slope = (pitch / (TAU * r)).atan();
    let (mut worst, mut off) = (0.0f64, 0.0f64);
    for k in 0..3000 {
        island
            .step_at(k as f64 * s.dt, &mut states, &gravity, &s, &mut work)
            .expect("a step");
        let t = (k + 1) as f64 * s.dt;
        let p = states[0].position;
        let exact = -0.5 * G * slope.sin().powi(2) * t * t;
        worst = worst.max((p.y - exact).abs() / exact.abs());
        let cylinder = (p.x.hypot(p.z) - r).abs();
        let sheet = Helicoid { pitch }.geometry(p).c.abs();
        off = off.max(cylinder).max(sheet);
    }
    assert!(worst <= 1e-5, "the descent was off by {worst:e}");
    assert!(off <= 1e-12, "left the helix by {off:e}");
}
