//! Tracks that move: prescribed motions and wires a game moves, through
//! the plugin (docs/method.md, "Moving wires"; the Kapitza pendulum).

use std::f64::consts::TAU;

use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::geometry::Pose;
use wirebead::prelude::*;
use wirebead::{ContactChanged, Side, SimClock, Stabilization, Surface, WireContact};
use wirebead::{Oscillate, PrescribedMotion, ScenePreset, WireMotion, WirePlace};

use crate::common::{Recording, app, bead_at_rest_on, run_for, spawn_bead, spawn_wire};

fn preset(file: &str) -> ScenePreset {
    let path = format!("{}/assets/scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    ScenePreset::from_ron(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Runs `preset` for `seconds` and returns the recorded samples of its
/// first bead as `(t, position)`.
fn run_scene(preset: &ScenePreset, seconds: f64) -> Vec<(f64, DVec2)> {
    let mut app = app(preset.params.clone());
    let beads = preset.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    run_for(&mut app, seconds);
    assert!(
        app.world().get::<Diverged>(beads[0]).is_none(),
        "{} diverged",
        preset.name
    );
    app.world()
        .resource::<Recording>()
        .of(beads[0])
        .iter()
        .map(|s| (s.t, s.position))
        .collect()
}

/// The largest angle from the top of the Kapitza circle over `seconds`,
/// shaken at `frequency`, in degrees.
fn kapitza_worst_angle(frequency: f64, seconds: f64) -> f64 {
    let mut scene = preset("kapitza.scene.ron");
    let WireMotion::Oscillate(shake) = scene.wires[0].motion else {
        panic!("the Kapitza scene shakes its wire");
    };
    let shake = Oscillate { frequency, ..shake };
    scene.wires[0].motion = WireMotion::Oscillate(shake);
    let samples = run_scene(&scene, seconds);
    samples
        .iter()
        .map(|&(t, x)| {
            let centre = shake.amplitude * (TAU * frequency * t).sin();
            let r = x - centre;
            r.x.atan2(r.y).abs().to_degrees()
        })
        .fold(0.0, f64::max)
}

/// A circle of radius 1 shaken vertically by 0.1 at 20 Hz keeps a bead
/// released 10° from the top within 30° of it for 20 s
/// (a²ω² = 158 > 2gl = 19.6); shaken at 3 Hz (a²ω² = 3.6) the bead falls.
#[test]
fn the_kapitza_pendulum_stands_when_shaken_fast_and_falls_when_slow() {
    let fast = kapitza_worst_angle(20.0, 20.0);
    assert!(
        fast < 30.0,
        "at 20 Hz the bead reached {fast:.1}° from the top"
    );
    let slow = kapitza_worst_angle(3.0, 5.0);
    assert!(
        slow > 90.0,
        "at 3 Hz the bead only reached {slow:.1}° from the top"
    );
    eprintln!("Kapitza: 20 Hz worst {fast:.2}°, 3 Hz worst {slow:.1}°");
}

/// A bead from rest on a rod spinning at ω, with no gravity, slides out as
/// `r₀ cosh ωt` (the spinning-rod scene: r₀ = 0.2, ω = 1, RATTLE at 2 ms).
#[test]
fn a_bead_on_the_spinning_rod_scene_slides_out_as_cosh() {
    let samples = run_scene(&preset("spinning_rod.scene.ron"), 3.0);
    let worst = samples
        .iter()
        .map(|&(t, x)| {
            let exact = 0.2 * t.cosh();
            (x.length() - exact).abs() / exact
        })
        .fold(0.0, f64::max);
    assert!(worst < 1e-5, "relative error in r reached {worst:e}");
    eprintln!("spinning rod: worst relative error in r over 3 s {worst:e}");
}

/// The motion both runs of the comparison give the wire: its origin at
/// `A sin(2π f t)`.
const SHAKE: Oscillate = Oscillate {
    amplitude: DVec2::new(0.3, 0.2),
    frequency: 1.0,
};

/// Where the shaken wire is at the end of the coming step.
fn shaken_origin(clock: &SimClock, params: &SimParams) -> DVec2 {
    let t = clock.time + params.timestep;
    SHAKE.amplitude * (TAU * SHAKE.frequency * t).sin()
}

/// Writes the shaken wire's `Transform` for the end of the coming step, as
/// a game moving a platform would.
fn shake_wire(
    clock: Res<SimClock>,
    params: Res<SimParams>,
    mut wires: Query<&mut Transform, With<Wire>>,
) {
    let origin = shaken_origin(&clock, &params).as_vec2();
    for mut transform in &mut wires {
        transform.translation = origin.extend(0.0);
    }
}

/// Writes the shaken wire's [`WirePlace`] for the end of the coming step,
/// in `f64`, as a game moving a platform exactly would.
fn shake_place(
    clock: Res<SimClock>,
    params: Res<SimParams>,
    mut wires: Query<&mut WirePlace, With<Wire>>,
) {
    let origin = shaken_origin(&clock, &params);
    for mut place in &mut wires {
        place.0 = Pose::new(origin, 0.0);
    }
}

/// How the shaken wire moves.
#[derive(Clone, Copy, PartialEq)]
enum Shaken {
    /// By a [`PrescribedMotion`].
    Prescribed,
    /// By the game writing its `Transform`.
    ByTransform,
    /// By the game writing its [`WirePlace`].
    ByPlace,
}

/// A pendulum on a circle shaken by `SHAKE` for 2 s at `dt`, the wire
/// moved as `shaken` says; the bead's last position.
fn shaken_pendulum(dt: f64, shaken: Shaken) -> DVec2 {
    let mut app = app(SimParams {
        timestep: dt,
        method: Method::Rattle,
        ..default()
    });
    let wire = app
        .world_mut()
        .spawn((Wire::circle(1.0).unwrap(), Transform::default()))
        .id();
    match shaken {
        Shaken::ByTransform => {
            app.add_systems(FixedUpdate, shake_wire.before(WireBeadSystems::Prepare));
        }
        Shaken::ByPlace => {
            app.world_mut()
                .entity_mut(wire)
                .insert(WirePlace::new(Pose::IDENTITY));
            app.add_systems(FixedUpdate, shake_place.before(WireBeadSystems::Prepare));
        }
        Shaken::Prescribed => {
            let motion = PrescribedMotion::new(WireMotion::Oscillate(SHAKE)).unwrap();
            app.world_mut().entity_mut(wire).insert(motion);
        }
    }
    let start = DVec2::new(60f64.to_radians().sin(), -60f64.to_radians().cos());
    // At rest relative to the wire, which starts at speed 2π f A.
    let velocity = SHAKE.amplitude * TAU * SHAKE.frequency;
    let bead = Bead::new(BeadParams {
        mass: 1.0,
        initial_position: start,
        initial_velocity: velocity,
    })
    .unwrap();
    let bead = app.world_mut().spawn((bead, OnWire(wire))).id();
    run_for(&mut app, 2.0);
    assert!(app.world().get::<Diverged>(bead).is_none());
    if shaken == Shaken::ByPlace {
        // The `Transform` shows the place, in `f32`.
        let place = app.world().get::<WirePlace>(wire).unwrap().0.origin;
        let shown = app.world().get::<Transform>(wire).unwrap().translation;
        assert_eq!(shown.truncate(), place.as_vec2());
    }
    app.world().get::<BeadPosition>(bead).unwrap().0
}

/// A game writing a wire's `Transform` each step gives the trajectory of
/// the same prescribed motion, to second order in the timestep (the
/// pose history's quadratic, see `WireBeadSystems::Prepare`); one writing
/// its [`WirePlace`] in `f64` gives it to 1e-10 (3e-8 through the `f32`
/// `Transform` at 1/100 s).
#[test]
fn a_wire_the_game_moves_gives_the_prescribed_motions_trajectory() {
    let gap = |dt: f64, moved| {
        (shaken_pendulum(dt, moved) - shaken_pendulum(dt, Shaken::Prescribed)).length()
    };
    let (coarse, fine) = (
        gap(1.0 / 100.0, Shaken::ByTransform),
        gap(1.0 / 200.0, Shaken::ByTransform),
    );
    let order = (coarse / fine).log2();
    assert!(
        coarse < 1e-2,
        "the trajectories part by {coarse:e} at 1/100 s"
    );
    assert!(order > 1.8, "observed order {order:.2}");
    for dt in [1.0 / 100.0, 1.0 / 200.0] {
        let placed = gap(dt, Shaken::ByPlace);
        assert!(
            placed <= 1e-10,
            "moved by its place, the trajectory parts by {placed:e} at {dt} s"
        );
    }
}

/// A wire far from the origin, at rest for 20 steps, then moved through
/// its [`WirePlace`] by less than the `f32` step of its coordinates each
/// step (1e-6 m a step at x = 1000, where `f32` steps by 6.1e-5), is
/// followed from its first move: its bead stays on the exact moving
/// circle to 1e-9.
#[test]
fn a_wire_moved_by_its_place_less_than_f32_resolves_is_followed() {
    let centre = |step: u32| DVec2::new(1000.0 + 1e-6 * f64::from(step.saturating_sub(20)), 0.0);
    let mut app = app(SimParams {
        timestep: 1.0 / 240.0,
        method: Method::Rattle,
        ..default()
    });
    let wire = app
        .world_mut()
        .spawn((
            Wire::circle(1.0).unwrap(),
            WirePlace::new(Pose::new(centre(0), 0.0)),
        ))
        .id();
    let bead = bead_at_rest_on(&mut app, wire, centre(0));
    let mut off = 0.0f64;
    for step in 1..=260 {
        // The place for the end of the coming step, as a game writes it.
        app.world_mut().get_mut::<WirePlace>(wire).unwrap().0 = Pose::new(centre(step), 0.0);
        app.update();
        let at = app.world().get::<BeadPosition>(bead).unwrap().0;
        off = off.max(((at - centre(step)).length() - 1.0).abs());
    }
    assert!(
        off <= 1e-9,
        "the bead strayed {off:e} m from the moving circle"
    );
}

/// A scene's wire is at its [`WirePlace`]; a game that writes its
/// `Transform` instead moves it there, the place following the
/// `Transform`, and its bead rides it where it now is.
#[test]
fn a_placed_wire_moved_by_its_transform_is_followed_and_its_place_follows() {
    let scene = preset("pendulum.scene.ron");
    let mut app = app(scene.params.clone());
    let bead = scene.spawn(&mut app.world_mut().commands())[0];
    app.world_mut().flush();
    let wire = app.world().get::<OnWire>(bead).unwrap().0;
    let place = app.world().get::<WirePlace>(wire).copied().unwrap();
    run_for(&mut app, 0.1);
    let moved_to = Vec3::new(0.25, -0.5, 0.0);
    app.world_mut()
        .get_mut::<Transform>(wire)
        .unwrap()
        .translation = moved_to;
    run_for(&mut app, 0.5);
    let now = app.world().get::<WirePlace>(wire).unwrap().0;
    assert_ne!(now, place.0);
    assert_eq!(now.origin, moved_to.truncate().as_dvec2());
    let shown = app.world().get::<Transform>(wire).unwrap().translation;
    assert_eq!(shown, moved_to, "the Transform stays where the game put it");
    // The bead is on the circle where it now is.
    let at = app.world().get::<BeadPosition>(bead).unwrap().0;
    let radius = 1.0;
    let off = ((at - now.origin).length() - radius).abs();
    assert!(off <= 1e-9, "the bead is {off:e} m off the moved wire");
}

/// Every contact change, as the plugin sends them.
#[derive(Resource, Default)]
struct Changes(Vec<ContactChanged>);

fn collect_changes(mut messages: MessageReader<ContactChanged>, mut changes: ResMut<Changes>) {
    changes.0.extend(messages.read().copied());
}

/// Through the plugin: a bead inside a one-sided loop, leaving the bottom
/// with `v0² = 3gr`, leaves at `4r/3` (a `ContactChanged` message and its
/// `WireContact`), flies, and lands on the loop again.
#[test]
fn a_bead_leaves_a_one_sided_loop_and_lands_on_it_again() {
    let mut app = app(SimParams {
        timestep: 1e-3,
        method: Method::Rattle,
        ..default()
    });
    app.init_resource::<Changes>()
        .add_systems(FixedUpdate, collect_changes.after(WireBeadSystems::Step));
    let surface = Surface {
        side: Side::Negative,
        ..Surface::PLAIN
    };
    let wire = Wire::circle(1.0).unwrap().with_surface(surface).unwrap();
    let wire = app.world_mut().spawn(wire).id();
    let g = 9.81f64;
    let bead = Bead::new(BeadParams {
        mass: 1.0,
        initial_position: DVec2::new(0.0, -1.0),
        initial_velocity: DVec2::new((3.0 * g).sqrt(), 0.0),
    })
    .unwrap();
    let bead = app.world_mut().spawn((bead, OnWire(wire))).id();
    let mut in_flight = false;
    for _ in 0..2000 {
        crate::common::run_steps(&mut app, 1);
        in_flight |= !app.world().get::<WireContact>(bead).unwrap().is_on();
    }
    assert!(in_flight, "the WireContact never showed the flight");
    let changes = &app.world().resource::<Changes>().0;
    let [left, landed, ..] = changes.as_slice() else {
        panic!("expected a departure and a landing, got {changes:?}");
    };
    let wirebead::solver::ContactEvent::Left { position, .. } = left.event else {
        panic!("first {left:?}");
    };
    let height = position.y + 1.0;
    assert!(
        (height - 4.0 / 3.0).abs() < 1e-3,
        "left {height} r above the bottom"
    );
    assert!(matches!(
        landed.event,
        wirebead::solver::ContactEvent::Landed { bounced: false, .. }
    ));
    assert!(app.world().get::<Diverged>(bead).is_none());
    eprintln!("plugin loop-the-loop: left {height:.6} r above the bottom, then {landed:?}");
}

/// The tautochrone scene: three beads released from rest at heights 1.5,
/// 1 and 0.5 on a cycloid of generating radius 1 each reach the bottom
/// after `π sqrt(r/g)`, within 1e-4 of it, with every accurate method.
#[test]
fn tautochrone_beads_reach_the_bottom_together() {
    let scene = preset("tautochrone.scene.ron");
    let expected = std::f64::consts::PI * (1.0 / 9.81f64).sqrt();
    for method in [
        Method::Rattle,
        Method::Rk4(Stabilization::None),
        Method::Rk4(Stabilization::Projection),
    ] {
        let mut scene = scene.clone();
        scene.params.method = method;
        let mut app = app(scene.params.clone());
        let beads = scene.spawn(&mut app.world_mut().commands());
        app.world_mut().flush();
        run_for(&mut app, 1.2);
        let recording = app.world().resource::<Recording>();
        for &bead in &beads {
            let samples = recording.of(bead);
            // The first time x reaches 0, interpolated within the step.
            let arrival = samples
                .windows(2)
                .find(|w| w[0].position.x < 0.0 && w[1].position.x >= 0.0)
                .map(|w| {
                    let (a, b) = (w[0].position.x, w[1].position.x);
                    w[0].t + (w[1].t - w[0].t) * (-a / (b - a))
                })
                .expect("reaches the bottom");
            let error = (arrival - expected).abs() / expected;
            eprintln!("{method}: arrived at {arrival:.6} s (relative error {error:e})");
            assert!(
                error < 1e-4,
                "{method}: arrived at {arrival}, not {expected}"
            );
        }
    }
}

/// `y = x²` on `[-2, 2]` as a Bevy Hermite curve: points every 0.25 with
/// the tangents of `u ↦ (x + u/4, (x + u/4)²)`, so its `f32` coefficients
/// are exact and the spline is the parabola itself.
fn parabola_spline() -> wirebead::geometry::Spline {
    use bevy::math::cubic_splines::{CubicGenerator, CubicHermite};
    let xs: Vec<f32> = (-8..=8).map(|i| i as f32 * 0.25).collect();
    let points = xs.iter().map(|&x| Vec2::new(x, x * x));
    let tangents = xs.iter().map(|&x| Vec2::new(0.25, 0.5 * x));
    let curve = CubicHermite::new(points, tangents).to_curve().unwrap();
    wirebead::geometry::Spline::from_curve(&curve)
}

/// A bead on a spline wire made from a Bevy `CubicCurve` stays on it to
/// 1e-9, and moves as on the implicit wire of the same shape: on the
/// parabola `y = x²`, RATTLE's trajectories on the two agree to 1e-9 and
/// both keep the energy to the same bound.
#[test]
fn a_bead_on_a_bevy_spline_moves_as_on_the_implicit_wire_of_its_shape() {
    use wirebead::geometry::{ImplicitCurve, Parabola};
    use wirebead::solver::{BeadState, LinearForce, StepSettings, step};
    let spline = parabola_spline();
    let parabola = Parabola { focal_length: 0.25 };
    let settings = StepSettings {
        dt: 1.0 / 240.0,
        method: Method::Rattle,
        alpha: 0.0,
        beta: 0.0,
        drift_bound: 1.0,
    };
    let gravity = LinearForce::constant(DVec2::new(0.0, -9.81));
    let start = BeadState {
        position: DVec2::new(-1.5, 2.25),
        velocity: DVec2::ZERO,
    };
    let energy = |s: &BeadState| 0.5 * s.velocity.length_squared() + 9.81 * s.position.y;
    let (mut on_spline, mut on_parabola) = (start, start);
    let (mut apart, mut off, mut drift_spline, mut drift_parabola) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..2400 {
        on_spline = step(&spline, on_spline, &gravity, 1.0, &settings)
            .unwrap()
            .state;
        on_parabola = step(&parabola, on_parabola, &gravity, 1.0, &settings)
            .unwrap()
            .state;
        apart = apart.max((on_spline.position - on_parabola.position).length());
        let x = on_spline.position;
        off = off.max((x.y - x.x * x.x).abs()).max(spline.value(x).abs());
        drift_spline = drift_spline.max((energy(&on_spline) - energy(&start)).abs());
        drift_parabola = drift_parabola.max((energy(&on_parabola) - energy(&start)).abs());
    }
    eprintln!(
        "spline parabola: {apart:e} apart over 10 s, {off:e} off the curve, energy error {drift_spline:e} (implicit {drift_parabola:e})"
    );
    assert!(off < 1e-9, "the bead left the spline by {off:e}");
    assert!(apart < 1e-9, "the trajectories part by {apart:e}");
    assert!(
        (drift_spline - drift_parabola).abs() <= 1e-9 + 0.01 * drift_parabola,
        "energy errors {drift_spline:e} on the spline, {drift_parabola:e} on the parabola"
    );
}

/// A bead sliding off the open end of a spline leaves the wire there (a
/// `ContactChanged` at the end point) and falls freely.
#[test]
fn a_bead_sliding_off_an_open_spline_falls_freely_from_its_end() {
    let mut app = app(SimParams {
        timestep: 1.0 / 240.0,
        method: Method::Rattle,
        ..default()
    });
    app.init_resource::<Changes>()
        .add_systems(FixedUpdate, collect_changes.after(WireBeadSystems::Step));
    let spline = parabola_spline();
    let end = DVec2::new(2.0, 4.0);
    let wire = Wire::new(wirebead::WireShape::Spline(spline)).unwrap();
    let wire = app.world_mut().spawn(wire).id();
    let bead = Bead::new(BeadParams {
        mass: 1.0,
        initial_position: DVec2::new(-1.0, 1.0),
        initial_velocity: DVec2::new(6.0, -12.0),
    })
    .unwrap();
    let bead = app.world_mut().spawn((bead, OnWire(wire))).id();
    crate::common::run_steps(&mut app, 240);
    let changes = &app.world().resource::<Changes>().0;
    let Some(wirebead::solver::ContactEvent::Left { position, .. }) =
        changes.first().map(|c| c.event)
    else {
        panic!("expected a departure, got {changes:?}");
    };
    assert!(
        (position - end).length() < 1e-9,
        "left at {position:?}, not the end {end:?}"
    );
    assert!(!app.world().get::<WireContact>(bead).unwrap().is_on());
    let samples = app.world().resource::<Recording>().of(bead);
    let last = &samples[samples.len() - 3..];
    let a = (last[2].velocity - last[1].velocity) / (last[2].t - last[1].t);
    assert!(
        (a - DVec2::new(0.0, -9.81)).length() < 1e-9,
        "acceleration {a:?}"
    );
}

/// A bead rides a Catmull–Rom loop that crosses itself: through the
/// crossing it keeps to its branch (its parameter only grows), goes round
/// the loop and leaves on the far side, on the curve to 1e-9 throughout.
#[test]
fn a_bead_rides_a_self_crossing_spline_loop_on_its_branch() {
    use wirebead::geometry::{Spline, SplineKind, SplineSpec};
    let points = [
        (-4.0, 0.0),
        (-2.0, 0.0),
        (0.0, 0.0),
        (1.2, 1.1),
        (0.0, 2.2),
        (-1.2, 1.1),
        (0.0, 0.0),
        (2.0, 0.0),
        (4.0, 0.0),
    ];
    let spline = Spline::new(SplineSpec {
        kind: SplineKind::CatmullRom,
        points: points.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
        closed: false,
    })
    .unwrap();
    let segments = (points.len() - 3) as f64;
    let start = spline.point(0.1);
    let ahead = (spline.point(0.1001) - start).normalize();
    let mut app = app(SimParams {
        timestep: 1.0 / 240.0,
        method: Method::Rattle,
        gravity: DVec2::ZERO,
        ..default()
    });
    let wire = Wire::new(wirebead::WireShape::Spline(spline)).unwrap();
    let wire = app.world_mut().spawn(wire).id();
    let bead = Bead::new(BeadParams {
        mass: 1.0,
        initial_position: start,
        initial_velocity: 3.0 * ahead,
    })
    .unwrap();
    let bead = app.world_mut().spawn((bead, OnWire(wire))).id();
    let (mut last, mut top, mut worst) = (0.0f64, f64::MIN, 0.0f64);
    for _ in 0..2000 {
        crate::common::run_steps(&mut app, 1);
        let along = app.world().get::<WireContact>(bead).unwrap().along();
        let y = app.world().get::<BeadPosition>(bead).unwrap().0.y;
        let c = crate::common::diagnostics(&app, bead).c.abs();
        if along >= segments - 0.05 {
            break;
        }
        assert!(along >= last - 1e-6, "went back from {last} to {along}");
        (last, top, worst) = (along, top.max(y), worst.max(c));
    }
    eprintln!(
        "self-crossing loop: reached parameter {last:.3} of {segments}, top {top:.3}, |C| {worst:e}"
    );
    assert!(last > segments - 0.2, "stopped at parameter {last}");
    assert!(top > 2.0, "never went round the loop (highest {top})");
    assert!(worst < 1e-9, "|C| reached {worst:e}");
}

/// A cart of two beads joined by a rod on the roller coaster's one-sided
/// track: solved as an island, it goes round the self-crossing loop, flies
/// off the hill (both wheels leave) and lands again, the rod held to 1e-9
/// and each wheel on the track to 1e-9 while it is held.
#[test]
fn a_two_bead_cart_rides_the_roller_coaster_and_flies_off_its_hill() {
    use wirebead::geometry::WireShape;
    use wirebead::preset::{BeadPreset, ConstraintPreset, RodPreset};
    let mut scene = preset("roller_coaster.scene.ron");
    let WireShape::Spline(track) = scene.wires[0].shape.clone() else {
        panic!("the roller coaster runs on a spline");
    };
    let (back, front) = (track.point(0.0), track.point(0.25));
    let length = (front - back).length();
    scene.wires[0].beads = vec![
        BeadPreset {
            name: "back".into(),
            mass: 1.0,
            initial_position: back,
            ..default()
        },
        BeadPreset {
            name: "front".into(),
            mass: 1.0,
            initial_position: front,
            ..default()
        },
    ];
    scene.constraints = vec![ConstraintPreset::Rod(RodPreset {
        a: "back".into(),
        b: "front".into(),
        length,
    })];
    let mut app = app(scene.params.clone());
    app.init_resource::<Changes>()
        .add_systems(FixedUpdate, collect_changes.after(WireBeadSystems::Step));
    let beads = scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    let (mut stretch, mut off, mut top) = (0.0f64, 0.0f64, f64::MIN);
    for _ in 0..4000 {
        crate::common::run_steps(&mut app, 1);
        let at = |b: Entity| app.world().get::<BeadPosition>(b).unwrap().0;
        stretch = stretch.max(((at(beads[0]) - at(beads[1])).length() - length).abs());
        for &b in &beads {
            assert!(app.world().get::<Diverged>(b).is_none());
            if app.world().get::<WireContact>(b).unwrap().is_on() {
                off = off.max(crate::common::diagnostics(&app, b).c.abs());
            }
            if at(b).x.abs() < 2.0 {
                top = top.max(at(b).y);
            }
        }
    }
    let changes = &app.world().resource::<Changes>().0;
    let left = changes
        .iter()
        .filter(|c| matches!(c.event, wirebead::solver::ContactEvent::Left { .. }))
        .count();
    let landed = changes.len() - left;
    eprintln!(
        "two-bead cart: {left} departures, {landed} landings, rod {stretch:e}, track {off:e}, loop top {top:.2}"
    );
    assert!(left >= 2 && landed >= 2, "{changes:?}");
    assert!(stretch < 1e-9, "the rod stretched by {stretch:e}");
    assert!(off < 1e-9, "a held wheel was {off:e} off the track");
    assert!(
        top > 3.5,
        "the cart never went round the loop (highest {top})"
    );
}

/// A scene's rough wire through the plugin: a lone bead and a two-bead
/// cart (an island), each sent at 3 m/s along a line with
/// `friction: (static: 0.5, kinetic: 0.3)`, stop after `v0² / (2 μk g)`.
#[test]
fn a_scene_with_a_rough_wire_stops_lone_beads_and_carts_at_the_coulomb_distance() {
    let scene = ScenePreset::from_ron(
        "(name: \"rough\", params: (integrator: Rattle, timestep: 0.004),
          wires: [
            (shape: Line(()), friction: (static: 0.5, kinetic: 0.3),
             beads: [(name: \"lone\", mass: 1.0, initial_velocity: (3.0, 0.0))]),
            (shape: Line(()), position: (0.0, -5.0), friction: (static: 0.5, kinetic: 0.3),
             beads: [(name: \"front\", mass: 1.0, initial_position: (0.5, -5.0), initial_velocity: (3.0, 0.0)),
                     (name: \"back\", mass: 2.0, initial_position: (0.0, -5.0), initial_velocity: (3.0, 0.0))]),
          ],
          constraints: [Rod((a: \"front\", b: \"back\", length: 0.5))])",
    )
    .unwrap();
    let mut app = app(scene.params.clone());
    let beads = scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    run_for(&mut app, 3.0);
    let expected = 9.0 / (2.0 * 0.3 * 9.81);
    for (bead, start) in [(beads[0], 0.0), (beads[2], 0.0)] {
        let b = crate::common::bead(&app, bead);
        let error = ((b.position.x - start) - expected).abs() / expected;
        eprintln!(
            "rough scene: stopped after {:.6} m (relative error {error:.2e})",
            b.position.x
        );
        assert!(
            error < 1e-3,
            "stopped after {}, not {expected}",
            b.position.x
        );
        assert!(b.velocity.length() < 1e-9);
    }
}

/// A wire the game moves in one step and then leaves is taken to have
/// moved at constant speed during that step and to be at rest from the
/// next on: its bead stays on it where it now is.
#[test]
fn a_wire_moved_once_then_left_holds_its_bead_where_it_now_is() {
    let mut app = app(SimParams {
        method: Method::Rattle,
        ..default()
    });
    let wire = spawn_wire(&mut app, Wire::circle(1.0).unwrap(), Transform::default());
    let bead = spawn_bead(
        &mut app,
        wire,
        BeadParams {
            mass: 1.0,
            initial_position: DVec2::new(0.6, -0.8),
            initial_velocity: DVec2::ZERO,
        },
    );
    let steps = |app: &mut App, n: usize| {
        for _ in 0..n {
            app.world_mut().run_schedule(FixedUpdate);
        }
    };
    steps(&mut app, 10);
    // Five centimetres to the right in one step (3 m/s at 1/60 s).
    let mut transform = app.world_mut().get_mut::<Transform>(wire).unwrap();
    transform.translation.x = 0.05;
    steps(&mut app, 120);
    let p = app.world().get::<BeadPosition>(bead).unwrap().0;
    let off = ((p - DVec2::new(f64::from(0.05f32), 0.0)).length() - 1.0).abs();
    eprintln!("moved once, then left: the bead is {off:.1e} m off the wire after 2 s");
    assert!(
        off < 1e-12,
        "the bead is {off:e} m off the wire where it now is"
    );
}

/// Static friction on a wire across rebuilds: a two-bead cart (an island)
/// laid at rest on a line tilted 10° with `friction: (static: 0.5,
/// kinetic: 0.3)` (tan 10° = 0.18, so static friction holds it), the
/// islands built again ten times in its 2 s (a bead spawned far away
/// each time): the cart stays where it was laid to 1e-9 m, each rebuilt
/// island starting the wheels' stick rows held at the lines they held on.
#[test]
fn a_cart_held_by_static_friction_stays_held_when_its_island_is_built_again() {
    let (c, s) = (10f64.to_radians().cos(), 10f64.to_radians().sin());
    let scene = ScenePreset::from_ron(&format!(
        "(name: \"tilted\", params: (integrator: Rattle, timestep: 0.004),
          wires: [
            (shape: Line(()), angle_degrees: 10.0, friction: (static: 0.5, kinetic: 0.3),
             beads: [(name: \"front\", mass: 1.0, initial_position: ({}, {})),
                     (name: \"back\", mass: 2.0, initial_position: (0.0, 0.0))]),
          ],
          constraints: [Rod((a: \"front\", b: \"back\", length: 0.5))])",
        0.5 * c,
        0.5 * s
    ))
    .unwrap();
    let mut app = app(scene.params.clone());
    let beads = scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    for rebuild in 0..=10 {
        if rebuild > 0 {
            crate::common::build_islands_again(&mut app, rebuild);
        }
        run_for(&mut app, 2.0 / 11.0);
    }
    let back = crate::common::bead(&app, beads[1]);
    let moved = back.position.length();
    eprintln!("a cart held on a tilted rough line through 10 rebuilds moved {moved:.1e} m");
    assert!(moved <= 1e-9, "the cart slid {moved:e} m");
}
