//! Beads joined by rods, pins and springs in the plugin: the systems only
//! move data (the same steps as the pure island solver, bit for bit),
//! free beads fly, and bad links are left out in words.

use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::geometry::{Line, Pose, WireShape};
use wirebead::headless::Headless;
use wirebead::plugin::StepSplit;
use wirebead::prelude::*;
use wirebead::solver::{BeadState, Island, IslandRow, IslandWork, LinearForce, RowKind};
use wirebead::{ConstraintDiagnostics, Islands, ParallelStep, ScenePreset, Stabilization};

use crate::common::{app, bead, params, run_steps, splits};

/// A cart of mass 2 on a horizontal line, a bob of mass 1 on a rod of
/// length 1, 30° out. Returns (cart, bob, rod).
fn cart_and_bob(app: &mut App) -> (Entity, Entity, Entity) {
    let world = app.world_mut();
    let line = world.spawn(Wire::line()).id();
    let cart = world
        .spawn((Bead::at_rest(2.0, DVec2::ZERO).unwrap(), OnWire(line)))
        .id();
    let bob_at = DVec2::new(0.5, -(0.75f64).sqrt());
    let bob = world.spawn(Bead::at_rest(1.0, bob_at).unwrap()).id();
    let rod = world.spawn(Rod::new(cart, bob, 1.0).unwrap()).id();
    (cart, bob, rod)
}

#[test]
fn the_plugin_steps_a_pendulum_on_a_cart_as_the_island_solver_does() {
    let p = params(Method::Rattle, 1.0 / 60.0);
    let mut app = app(p.clone());
    let (cart, bob, rod) = cart_and_bob(&mut app);
    run_steps(&mut app, 120);

    let island = Island::new(
        &[2.0, 1.0],
        vec![
            IslandRow {
                kind: RowKind::Wire {
                    shape: WireShape::Line(Line),
                    pose: Pose::default(),
                },
                beads: vec![0],
            },
            IslandRow {
                kind: RowKind::Rod { length: 1.0 },
                beads: vec![0, 1],
            },
        ],
        vec![],
    )
    .unwrap();
    let mut states = vec![
        BeadState::default(),
        BeadState {
            position: DVec2::new(0.5, -(0.75f64).sqrt()),
            velocity: DVec2::ZERO,
        },
    ];
    let forces = [
        LinearForce::constant(2.0 * p.gravity),
        LinearForce::constant(p.gravity),
    ];
    let mut work = IslandWork::default();
    for _ in 0..120 {
        island
            .step(&mut states, &forces, &p.step_settings(), &mut work)
            .unwrap();
    }
    assert_eq!(bead(&app, cart).state(), states[0]);
    assert_eq!(bead(&app, bob).state(), states[1]);
    let rod = app.world().get::<ConstraintDiagnostics>(rod).unwrap();
    assert!(rod.c.abs() <= 1e-12, "the rod drifted {:e}", rod.c);
    assert!(rod.lambda < 0.0, "a hanging rod pulls: λ = {}", rod.lambda);
    let momentum = 2.0 * bead(&app, cart).velocity.x + bead(&app, bob).velocity.x;
    assert!(momentum.abs() < 1e-12, "horizontal momentum {momentum:e}");
    let islands = app.world().resource::<Islands>();
    let report = islands.of(bob).expect("the bob is in an island");
    assert_eq!((report.beads.len(), report.rows), (2, 2));
    let transform = app.world().get::<Transform>(bob).unwrap();
    assert_eq!(transform.translation.x, states[1].position.x as f32);
}

/// An island's drift is the largest `|C|` of its rows: here the
/// rod's or the cart's wire row, with the assignment's semi-implicit Euler
/// and Baumgarte, which leave a drift to see.
#[test]
fn an_islands_drift_is_its_largest_row_drift() {
    let mut app = app(params(Method::default(), 1.0 / 60.0));
    let (cart, bob, rod) = cart_and_bob(&mut app);
    run_steps(&mut app, 120);
    let rod = app.world().get::<ConstraintDiagnostics>(rod).unwrap().c;
    let wire = app.world().get::<BeadDiagnostics>(cart).unwrap().c;
    let islands = app.world().resource::<Islands>();
    let report = islands.of(bob).expect("the bob is in an island");
    assert_eq!(report.drift, rod.abs().max(wire.abs()));
    assert!(
        report.drift > 1e-6 && report.drift < 0.1,
        "drift {:e}",
        report.drift
    );
}

#[test]
fn a_free_bead_flies_a_parabola() {
    // RK4 is exact for constant acceleration.
    let mut app = app(params(Method::Rk4(Stabilization::Baumgarte), 0.01));
    let v0 = DVec2::new(3.0, 4.0);
    let free = Bead::new(BeadParams {
        mass: 1.5,
        initial_position: DVec2::ZERO,
        initial_velocity: v0,
    })
    .unwrap();
    let free = app.world_mut().spawn(free).id();
    run_steps(&mut app, 50);
    let t = 0.5;
    let g = DVec2::new(0.0, -9.81);
    let expect = v0 * t + 0.5 * g * t * t;
    let got = bead(&app, free).position;
    assert!((got - expect).length() < 1e-12, "{got} against {expect}");
}

#[test]
fn a_rod_to_an_entity_that_is_no_bead_is_left_out() {
    let mut app = app(params(Method::Rattle, 0.01));
    let stranger = app.world_mut().spawn_empty().id();
    let free = app
        .world_mut()
        .spawn(Bead::at_rest(1.0, DVec2::ZERO).unwrap())
        .id();
    app.world_mut()
        .spawn(Rod::new(free, stranger, 1.0).unwrap());
    run_steps(&mut app, 10);
    // The bead falls freely: the rod was left out, nothing panicked.
    let y = bead(&app, free).position.y;
    assert!(y < -0.04 && y.is_finite(), "y = {y}");
    assert!(app.world().get::<Diverged>(free).is_none());
}

#[test]
fn links_refuse_a_bead_joined_to_itself_in_words() {
    let mut app = app(SimParams::default());
    let b = app.world_mut().spawn_empty().id();
    assert_eq!(
        Rod::new(b, b, 1.0).unwrap_err().to_string(),
        "a rod must join two different beads"
    );
    assert_eq!(
        Spring::new(b, b, 1.0, 10.0, 0.0).unwrap_err().to_string(),
        "a spring must join two different beads"
    );
    assert_eq!(
        Rod::new(b, Entity::PLACEHOLDER, -1.0)
            .unwrap_err()
            .to_string(),
        "rod length must be positive and finite, got -1"
    );
    assert_eq!(
        Pin::new(b, DVec2::new(f64::NAN, 0.0))
            .unwrap_err()
            .to_string(),
        "pin point must be finite, got (NaN, 0)"
    );
}

#[test]
fn removing_the_rod_lets_the_bob_fall_freely() {
    let mut app = app(params(Method::Rk4(Stabilization::Baumgarte), 0.01));
    let (_, bob, rod) = cart_and_bob(&mut app);
    run_steps(&mut app, 5);
    app.world_mut().despawn(rod);
    let before = bead(&app, bob);
    run_steps(&mut app, 10);
    // Ten free steps from the state it had: exact for RK4.
    let t = 0.1;
    let expect = before.position + before.velocity * t + 0.5 * DVec2::new(0.0, -9.81) * t * t;
    let got = bead(&app, bob).position;
    assert!((got - expect).length() < 1e-12, "{got} against {expect}");
}

#[test]
fn an_island_that_fails_stops_whole_and_keeps_its_state() {
    let mut app = app(params(Method::Rattle, 0.01));
    let world = app.world_mut();
    let top = world.spawn(Bead::at_rest(1.0, DVec2::ZERO).unwrap()).id();
    let bob = world.spawn(Bead::at_rest(1.0, DVec2::ZERO).unwrap()).id();
    world.spawn(Pin::new(top, DVec2::ZERO).unwrap());
    world.spawn(Rod::new(top, bob, 1.0).unwrap());
    run_steps(&mut app, 3);
    for b in [top, bob] {
        let diverged = app.world().get::<Diverged>(b).expect("diverged");
        assert!(
            diverged.reason.to_string().contains("singular point"),
            "{}",
            diverged.reason
        );
        assert_eq!(bead(&app, b).position, DVec2::ZERO);
        assert!(app.world().get::<Transform>(b).unwrap().is_finite());
    }
}

#[test]
fn a_restart_returns_an_island_to_its_start() {
    let mut app = app(params(Method::Rattle, 1.0 / 60.0));
    let (cart, bob, _) = cart_and_bob(&mut app);
    run_steps(&mut app, 30);
    let first = (bead(&app, cart).state(), bead(&app, bob).state());
    app.world_mut().write_message(Restart);
    run_steps(&mut app, 0);
    assert_eq!(bead(&app, bob).position, DVec2::new(0.5, -(0.75f64).sqrt()));
    run_steps(&mut app, 30);
    assert_eq!((bead(&app, cart).state(), bead(&app, bob).state()), first);
}

/// A headless app on one thread, or on every core with every loop split
/// from one bead up.
fn one_or_all_cores(plugin: WireBeadPlugin, parallel: bool) -> App {
    let headless = Headless::new(plugin);
    if parallel {
        headless.parallel(ParallelStep { threshold: 1 }).build()
    } else {
        headless.single_threaded().build()
    }
}

#[test]
fn a_coupled_scene_runs_bit_identically_sequential_and_parallel() {
    // The rope preset and the ring (a redundant row), each run twice on
    // one thread and once on every core with the bead loops split from one
    // bead up: the same bits every time.
    for name in ["rope.scene.ron", "ring.scene.ron", "spring_pair.scene.ron"] {
        let path = crate::presets::shipped_dir().join(name);
        let preset = ScenePreset::from_ron(&std::fs::read_to_string(path).unwrap()).unwrap();
        let run = |parallel: bool| {
            let plugin = WireBeadPlugin::new(preset.params.clone()).unwrap();
            let mut app = one_or_all_cores(plugin, parallel);
            let beads = preset.spawn(&mut app.world_mut().commands());
            app.world_mut().flush();
            run_steps(&mut app, 120);
            beads
                .iter()
                .map(|&b| bead(&app, b).state())
                .collect::<Vec<_>>()
        };
        let first = run(false);
        assert_eq!(first, run(false), "{name}: two sequential runs differ");
        assert_eq!(first, run(true), "{name}: the parallel run differs");
    }
}

#[test]
fn many_islands_split_over_threads_step_as_on_one() {
    // 64 pendulums on carts, each its own island, released at different
    // angles: stepped with the islands split over every core, the same bits
    // as on one thread, and each cart still on its rail.
    let run = |parallel: bool| {
        let plugin = WireBeadPlugin::new(params(Method::Rattle, 1.0 / 60.0)).unwrap();
        let mut app = one_or_all_cores(plugin, parallel);
        let world = app.world_mut();
        let mut carts = Vec::new();
        for i in 0..64 {
            let y = -3.0 * f64::from(i);
            let angle = 0.1 + 0.04 * f64::from(i);
            let rail = world
                .spawn((Wire::line(), Transform::from_xyz(0.0, y as f32, 0.0)))
                .id();
            let cart = world
                .spawn((
                    Bead::at_rest(2.0, DVec2::new(0.0, y)).unwrap(),
                    OnWire(rail),
                ))
                .id();
            let swing = DVec2::new(angle.sin(), -angle.cos());
            let bob = world
                .spawn(Bead::at_rest(1.0, DVec2::new(0.0, y) + swing).unwrap())
                .id();
            world.spawn(Rod::new(cart, bob, 1.0).unwrap());
            carts.push((cart, bob, y));
        }
        run_steps(&mut app, 120);
        let islands = app.world().resource::<Islands>().iter().count();
        assert_eq!(islands, 64, "{islands} islands");
        // The parallel run split the islands over more than one thread,
        // in more than one chunk; the sequential one did not.
        let split = *app.world().resource::<StepSplit>();
        if !parallel {
            assert_eq!(
                (split.island_threads, split.island_chunks),
                (0, 1),
                "{split:?}"
            );
        } else if splits() {
            assert!(
                split.island_threads > 1 && split.island_chunks > 1,
                "{split:?}"
            );
        }
        carts
            .iter()
            .map(|&(cart, bob, y)| {
                let (c, b) = (bead(&app, cart), bead(&app, bob));
                assert!((c.position.y - y).abs() <= 1e-12, "a cart left its rail");
                assert!(((b.position - c.position).length() - 1.0).abs() <= 1e-12);
                (c.state(), b.state())
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(run(false), run(true));
}

#[test]
fn a_pin_on_an_entity_holds_its_bead_where_the_entity_is() {
    let mut app = app(params(Method::Rattle, 0.01));
    let world = app.world_mut();
    let anchor = world.spawn(Transform::from_xyz(1.0, 2.0, 0.0)).id();
    let held = world
        .spawn(Bead::at_rest(1.0, DVec2::new(1.5, 2.0)).unwrap())
        .id();
    world.spawn(Pin::on(held, anchor, DVec2::new(0.5, 0.0)).unwrap());
    run_steps(&mut app, 10);
    assert!((bead(&app, held).position - DVec2::new(1.5, 2.0)).length() <= 1e-12);
    // The anchor moves and turns a quarter turn: the bead is held at the
    // offset in the anchor's new frame from the next step on.
    *app.world_mut().get_mut::<Transform>(anchor).unwrap() = Transform::from_xyz(3.0, 2.0, 0.0)
        .with_rotation(Quat::from_rotation_z(std::f32::consts::FRAC_PI_2));
    run_steps(&mut app, 1);
    let at = bead(&app, held).position;
    assert!((at - DVec2::new(3.0, 2.5)).length() <= 1e-6, "bead at {at}");
    assert_eq!(
        Pin::on(held, held, DVec2::ZERO).unwrap_err().to_string(),
        "a pin cannot be anchored to its own bead"
    );
}

/// A slider-crank: the crank pin on a circle of radius 0.5, the piston on
/// a line, a rod of 1.5 between them; the crank pin starts at the top
/// moving at 2 m/s and the piston at rest, which the rod does not allow.
/// Returns the app, the crank pin and the piston.
fn slider_crank() -> (App, Entity, Entity) {
    let mut app = app(params(Method::Rattle, 1e-3));
    let world = app.world_mut();
    let circle = world.spawn(Wire::circle(0.5).unwrap()).id();
    let line = world.spawn(Wire::line()).id();
    let crank = BeadParams {
        mass: 1.0,
        initial_position: DVec2::new(0.0, 0.5),
        initial_velocity: DVec2::new(-2.0, 0.0),
    };
    let crank = world
        .spawn((Bead::new(crank).unwrap(), OnWire(circle)))
        .id();
    let piston = Bead::at_rest(2.0, DVec2::new(2f64.sqrt(), 0.0)).unwrap();
    let piston = world.spawn((piston, OnWire(line))).id();
    world.spawn(Rod::new(crank, piston, 1.5).unwrap());
    (app, crank, piston)
}

/// Kinetic and gravitational energy of `beads`.
fn energy(app: &App, beads: &[Entity]) -> f64 {
    let g = app.world().resource::<SimParams>().gravity;
    beads
        .iter()
        .map(|&e| {
            let b = bead(app, e);
            let (kinetic, potential) = b.state().energy(b.mass, g);
            kinetic + potential
        })
        .sum()
}

/// Asserts that the crank pin and the piston move as the rod and their
/// wires allow.
fn assert_velocities_meet_the_constraints(app: &App, crank: Entity, piston: Entity) {
    let (c, p) = (bead(app, crank), bead(app, piston));
    let along_rod = (c.position - p.position).dot(c.velocity - p.velocity);
    assert!(
        along_rod.abs() < 1e-12,
        "the rod stretches at {along_rod:e}"
    );
    assert!(
        c.velocity.dot(c.position).abs() < 1e-12,
        "the crank leaves its circle"
    );
    assert!(p.velocity.y.abs() < 1e-12, "the piston leaves its line");
    assert!(
        p.velocity.x.abs() > 0.5,
        "the piston does not move: {}",
        p.velocity
    );
}

#[test]
fn initial_velocities_that_break_a_constraint_are_projected_at_spawn_and_restart() {
    let (mut app, crank, piston) = slider_crank();
    let given = energy(&app, &[crank, piston]);
    // Spawned: the state before any step already meets the constraints,
    // and it is the state the first step starts from.
    run_steps(&mut app, 0);
    assert_velocities_meet_the_constraints(&app, crank, piston);
    let start = energy(&app, &[crank, piston]);
    assert!(start < given - 0.1, "{given} J given, {start} J projected");
    run_steps(&mut app, 1);
    let after = energy(&app, &[crank, piston]);
    assert!(
        (after - start).abs() < 1e-6,
        "{start} J, then {after} J a step later"
    );
    // A restart returns to the initial state and projects it the same way.
    run_steps(&mut app, 200);
    app.world_mut().write_message(Restart);
    run_steps(&mut app, 0);
    assert_velocities_meet_the_constraints(&app, crank, piston);
    assert_eq!(energy(&app, &[crank, piston]), start);
}
