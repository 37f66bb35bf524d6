//! Beads that touch, through the plugin: gliders on an air track, balls
//! too fast for a step, Newton's cradle.

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;
use wirebead::geometry::Coordinates;
use wirebead::headless::{Headless, bead_state, idle, run_steps};
use wirebead::prelude::*;
use wirebead::preset::{GRAIN_RADIUS, Hourglass, Pour};
use wirebead::solver::BeadState;
use wirebead::{
    BeadsStruck, CatchesBeads, Contacts, Integrator, Islands, Restitution, SceneEnergy, SceneFile,
    ScenePreset, SimClock, WireContact, preset::PILE_RADIUS,
};

/// A headless app at `dt` with RATTLE, no gravity along the track.
fn app(dt: f64, e: f64) -> App {
    let params = SimParams {
        timestep: dt,
        method: Method::new(Integrator::Rattle, None).expect("RATTLE"),
        ..SimParams::default()
    };
    let plugin = WireBeadPlugin::new(params).expect("valid params");
    let mut app = Headless::new(plugin).single_threaded().build();
    app.insert_resource(Contacts::new(e).expect("a restitution"));
    app
}

/// A headless app at the default step with RATTLE and no gravity.
fn weightless() -> App {
    let params = SimParams {
        gravity: DVec2::ZERO,
        method: Method::new(Integrator::Rattle, None).expect("RATTLE"),
        ..SimParams::default()
    };
    let plugin = WireBeadPlugin::new(params).expect("valid params");
    Headless::new(plugin).single_threaded().build()
}

/// A glider of mass `m` and radius `r` on `track` at `x` moving at `v`.
fn glider(app: &mut App, track: Entity, m: f64, x: f64, v: f64, r: f64) -> Entity {
    let params = BeadParams {
        mass: m,
        initial_position: DVec2::new(x, 0.0),
        initial_velocity: DVec2::new(v, 0.0),
    };
    app.world_mut()
        .spawn((
            Bead::new(params).expect("a bead"),
            OnWire(track),
            BeadRadius::new(r).expect("a radius"),
        ))
        .id()
}

fn velocity(app: &App, bead: Entity) -> f64 {
    bead_state(app.world(), bead).expect("a bead").velocity.x
}

fn position(app: &App, bead: Entity) -> f64 {
    bead_state(app.world(), bead).expect("a bead").position.x
}

/// Two gliders of masses `ma`, `mb` from 0 and 1 m at `ua`, `ub`, radii
/// 0.1 m, on a level track, run for 1 s at 1/60 s: their final velocities
/// and positions, and when they met.
fn air_track(ma: f64, mb: f64, ua: f64, ub: f64, e: f64) -> ([f64; 2], [f64; 2], App) {
    let mut app = app(1.0 / 60.0, e);
    let track = app.world_mut().spawn(Wire::line()).id();
    let a = glider(&mut app, track, ma, 0.0, ua, 0.1);
    let b = glider(&mut app, track, mb, 1.0, ub, 0.1);
    run_steps(&mut app, 60);
    let v = [velocity(&app, a), velocity(&app, b)];
    let x = [position(&app, a), position(&app, b)];
    (v, x, app)
}

#[test]
fn equal_gliders_exchange_velocities_at_the_instant_they_meet() {
    let (ua, ub) = (2.0, -0.5);
    let (v, x, _) = air_track(1.0, 1.0, ua, ub, 1.0);
    assert!((v[0] - ub).abs() <= 1e-12, "{v:?}");
    assert!((v[1] - ua).abs() <= 1e-12, "{v:?}");
    // They meet when the 0.8 m gap closes at 2.5 m/s: at 0.32 s, within
    // the twentieth step; each then moves on at the other's speed.
    let meet = 0.8 / (ua - ub);
    let xa = ua * meet + ub * (1.0 - meet);
    let xb = 1.0 + ub * meet + ua * (1.0 - meet);
    assert!((x[0] - xa).abs() <= 1e-12, "{} against {xa}", x[0]);
    assert!((x[1] - xb).abs() <= 1e-12, "{} against {xb}", x[1]);
}

#[test]
fn gliders_of_masses_one_and_three_leave_with_the_elastic_velocities() {
    let (m1, m2, u1, u2) = (1.0, 3.0, 2.0, -0.5);
    let (v, _, _) = air_track(m1, m2, u1, u2, 1.0);
    let v1 = ((m1 - m2) * u1 + 2.0 * m2 * u2) / (m1 + m2);
    let v2 = ((m2 - m1) * u2 + 2.0 * m1 * u1) / (m1 + m2);
    assert!((v[0] - v1).abs() <= 1e-12, "{} against {v1}", v[0]);
    assert!((v[1] - v2).abs() <= 1e-12, "{} against {v2}", v[1]);
}

#[test]
fn gliders_at_restitution_zero_move_on_together_losing_half_mu_v_squared() {
    let (m1, m2, u1, u2) = (1.0, 3.0, 2.0, -0.5);
    let (v, x, _) = air_track(m1, m2, u1, u2, 0.0);
    let common = (m1 * u1 + m2 * u2) / (m1 + m2);
    assert!(
        (v[0] - common).abs() <= 1e-12 && (v[1] - common).abs() <= 1e-12,
        "{v:?}"
    );
    let before = 0.5 * m1 * u1 * u1 + 0.5 * m2 * u2 * u2;
    let after = 0.5 * (m1 + m2) * common * common;
    let mu = m1 * m2 / (m1 + m2);
    let lost = 0.5 * mu * (u1 - u2) * (u1 - u2);
    assert!((before - after - lost).abs() <= 1e-12);
    let after_run = 0.5 * m1 * v[0] * v[0] + 0.5 * m2 * v[1] * v[1];
    assert!(
        (before - after_run - lost).abs() <= 1e-12,
        "lost {}",
        before - after_run
    );
    assert!(
        (x[1] - x[0] - 0.2).abs() <= 1e-12,
        "they stay in touch: {x:?}"
    );
}

/// Two gliders of radius 0.1 m on a level track, each `(mass, x, v)`,
/// run `steps` steps of `dt` at restitution `e`: their final velocities
/// and positions, and how many strikes were reported.
fn gliders_counting_strikes(
    dt: f64,
    e: f64,
    gliders: [(f64, f64, f64); 2],
    steps: usize,
) -> ([f64; 2], [f64; 2], usize) {
    let mut app = app(dt, e);
    let track = app.world_mut().spawn(Wire::line()).id();
    let [a, b] = gliders.map(|(m, x, v)| glider(&mut app, track, m, x, v, 0.1));
    let mut strikes = 0;
    for _ in 0..steps {
        run_steps(&mut app, 1);
        let messages = app.world().resource::<Messages<BeadsStruck>>();
        strikes += messages.iter_current_update_messages().count();
    }
    let v = [velocity(&app, a), velocity(&app, b)];
    let x = [position(&app, a), position(&app, b)];
    (v, x, strikes)
}

/// Gliders of masses 1 and 3 closing at 0.26 m/s, slower than one 1/60 s
/// step of gravity moves a glider (9.81/60 m/s each, 0.327 m/s for the
/// pair), from 0.8 m apart: at `e = 0` the step that meets holds their
/// contact (a plastic impact within the step, with no strike to
/// report), and they move on together with the momentum's velocity,
/// having lost `½ μ v_rel²`, to 1e-12, at most `v_rel · dt` from where
/// the impact located at its instant leaves them; at `e = 1` they strike
/// at the instant and part with the elastic velocities to 1e-12.
#[test]
fn gliders_meeting_slowly_at_restitution_zero_move_on_together_without_a_strike() {
    let (m1, m2, u1, u2) = (1.0, 3.0, 0.2, -0.06);
    let dt = 1.0 / 60.0;
    let run = |e: f64| gliders_counting_strikes(dt, e, [(m1, 0.0, u1), (m2, 1.0, u2)], 240);
    let (v, x, strikes) = run(0.0);
    assert_eq!(strikes, 0, "a slow meeting at e = 0 is no strike");
    let common = (m1 * u1 + m2 * u2) / (m1 + m2);
    assert!(
        (v[0] - common).abs() <= 1e-12 && (v[1] - common).abs() <= 1e-12,
        "{v:?}"
    );
    let before = 0.5 * m1 * u1 * u1 + 0.5 * m2 * u2 * u2;
    let after = 0.5 * m1 * v[0] * v[0] + 0.5 * m2 * v[1] * v[1];
    let lost = 0.5 * (m1 * m2 / (m1 + m2)) * (u1 - u2) * (u1 - u2);
    assert!(
        (before - after - lost).abs() <= 1e-12,
        "lost {}",
        before - after
    );
    assert!((x[1] - x[0] - 0.2).abs() <= 1e-12, "in touch: {x:?}");
    // Met at 0.8 / 0.26 s (within the 185th step), then on together.
    let meet = 0.8 / (u1 - u2);
    let xa = u1 * meet + common * (4.0 - meet);
    assert!((x[0] - xa).abs() <= (u1 - u2) * dt, "{} against {xa}", x[0]);
    eprintln!(
        "slow plastic meeting: {:e} m from the located one",
        x[0] - xa
    );
    let (v, _, strikes) = run(1.0);
    assert_eq!(strikes, 1);
    let v1 = ((m1 - m2) * u1 + 2.0 * m2 * u2) / (m1 + m2);
    let v2 = ((m2 - m1) * u2 + 2.0 * m1 * u1) / (m1 + m2);
    assert!(
        (v[0] - v1).abs() <= 1e-12 && (v[1] - v2).abs() <= 1e-12,
        "{v:?} against {v1}, {v2}"
    );
}

/// Gliders of masses 1 and 3 closing at 2.5 m/s, 20 times faster than
/// the slow meetings above, whose gap closes 1/32 of a step after a
/// step's start (half of the 1/16 of a step within which a meeting at
/// `e = 0` counts as near its start, README.md): that step holds
/// their contact, with no strike to report, and they end where the
/// impact located at its instant leaves them, at the momentum's velocity
/// and having lost `½ μ v_rel²`, all to 1e-12 (on a line the two are the
/// same). Met half a step in, the same pair is struck at its instant.
#[test]
fn gliders_meeting_near_a_steps_start_at_restitution_zero_are_held_by_that_step() {
    let (m1, m2, u1, u2) = (1.0, 3.0, 2.0, -0.5);
    let dt = 1.0 / 60.0;
    let run = |steps_to_meet: f64| {
        let start = 0.2 + (u1 - u2) * steps_to_meet * dt;
        gliders_counting_strikes(dt, 0.0, [(m1, 0.0, u1), (m2, start, u2)], 30)
    };
    let common = (m1 * u1 + m2 * u2) / (m1 + m2);
    let lost = 0.5 * (m1 * m2 / (m1 + m2)) * (u1 - u2) * (u1 - u2);
    let before = 0.5 * m1 * u1 * u1 + 0.5 * m2 * u2 * u2;
    for (steps_to_meet, struck) in [(10.0 + 1.0 / 32.0, 0), (10.5, 1)] {
        let (v, x, strikes) = run(steps_to_meet);
        assert_eq!(strikes, struck, "meeting {steps_to_meet} steps in");
        assert!(
            (v[0] - common).abs() <= 1e-12 && (v[1] - common).abs() <= 1e-12,
            "{v:?}"
        );
        let after = 0.5 * m1 * v[0] * v[0] + 0.5 * m2 * v[1] * v[1];
        assert!(
            (before - after - lost).abs() <= 1e-12,
            "lost {}",
            before - after
        );
        let meet = steps_to_meet * dt;
        let xa = u1 * meet + common * (30.0 * dt - meet);
        assert!((x[0] - xa).abs() <= 1e-12, "{} against {xa}", x[0]);
        assert!((x[1] - x[0] - 0.2).abs() <= 1e-12, "in touch: {x:?}");
    }
}

/// A pair closing at 600 m/s covers ten metres a step: it still meets at
/// the instant the gap closes, and neither passes the other.
#[test]
fn gliders_too_fast_for_a_step_still_meet_and_never_pass() {
    let (v, x, _) = air_track(1.0, 1.0, 300.0, -300.0, 1.0);
    assert!(
        (v[0] + 300.0).abs() <= 1e-9 && (v[1] - 300.0).abs() <= 1e-9,
        "{v:?}"
    );
    let meet = 0.8 / 600.0;
    let xa = 300.0 * meet - 300.0 * (1.0 - meet);
    assert!((x[0] - xa).abs() <= 1e-9, "{} against {xa}", x[0]);
    assert!(x[0] < x[1]);
}

/// A bead's own restitution: the pair takes the smaller.
#[test]
fn a_pair_strikes_with_the_smaller_restitution_of_its_two_beads() {
    let mut app = app(1.0 / 60.0, 1.0);
    let track = app.world_mut().spawn(Wire::line()).id();
    let a = glider(&mut app, track, 1.0, 0.0, 1.0, 0.1);
    let b = glider(&mut app, track, 1.0, 0.5, 0.0, 0.1);
    app.world_mut()
        .entity_mut(b)
        .insert(Restitution::new(0.5).expect("a restitution"));
    run_steps(&mut app, 60);
    // Equal masses at e = ½: the pair opens at half the 1 m/s it closed at.
    let (va, vb) = (velocity(&app, a), velocity(&app, b));
    assert!(
        (va - 0.25).abs() <= 1e-12 && (vb - 0.75).abs() <= 1e-12,
        "{va}, {vb}"
    );
}

/// Newton's cradle: five balls of radius 5 cm hanging touching from pins
/// 10 cm apart on rods of 1 m, RATTLE at 1/600 s. Returns the app, the
/// balls, and the first `k` released from 30°.
fn cradle(k: usize) -> (App, Vec<Entity>) {
    let mut app = app(1.0 / 600.0, 1.0);
    let (length, radius, angle) = (1.0, 0.05, 30f64.to_radians());
    let mut balls = Vec::new();
    for i in 0..5 {
        let top = DVec2::new(2.0 * radius * i as f64, length);
        let at = if i < k {
            top + DVec2::new(-angle.sin(), -angle.cos()) * length
        } else {
            top - DVec2::Y * length
        };
        let pivot = app
            .world_mut()
            .spawn(Bead::at_rest(1.0, top).expect("a pivot"))
            .id();
        app.world_mut().spawn(Pin::new(pivot, top).expect("a pin"));
        let ball = app
            .world_mut()
            .spawn((
                Bead::at_rest(1.0, at).expect("a ball"),
                BeadRadius::new(radius).expect("a radius"),
            ))
            .id();
        app.world_mut()
            .spawn(Rod::new(pivot, ball, length).expect("a rod"));
        balls.push(ball);
    }
    (app, balls)
}

/// The shipped Newton's cradle for 5 s (3,000 steps): the scene's energy
/// ([`SceneEnergy`], which the panel plots) stays within 1e-4 J of where
/// it started, while the island of the first ball gains and loses the
/// balls it strikes, so that the island's own energy (which the panel
/// plotted for a bead joined to others) jumps by joules.
#[test]
fn the_cradles_scene_energy_is_kept_while_its_islands_gain_and_lose_balls() {
    let (mut app, beads, _) = shipped("newtons_cradle.scene.ron");
    app.init_resource::<SceneEnergy>();
    let first_ball = beads[5];
    run_steps(&mut app, 1);
    let e0 = app.world().resource::<SceneEnergy>().total;
    let island = |app: &App| {
        let islands = app.world().resource::<Islands>();
        islands.of(first_ball).expect("the ball's island").energy
    };
    let (mut low, mut high) = (island(&app), island(&app));
    let mut worst = 0.0f64;
    for _ in 1..3000 {
        run_steps(&mut app, 1);
        let scene = app.world().resource::<SceneEnergy>();
        let time = app.world().resource::<SimClock>().time;
        assert_eq!(scene.time, time, "measured after each step");
        worst = worst.max((scene.total - e0).abs());
        let e = island(&app);
        (low, high) = (low.min(e), high.max(e));
    }
    eprintln!(
        "cradle: scene energy kept to {worst:e} J; the first ball's island from {low} to {high} J"
    );
    assert!(worst <= 1e-4, "the scene's energy changed by {worst:e} J");
    assert!(
        high - low >= 1.0,
        "the first ball's island kept its energy ({low} to {high} J): no merging to tell apart"
    );
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
}

/// `k` balls released from 30° send out `k`: the ones struck last rise
/// to the release height within 1e-3 of it (measured: 2.2e-6 of it), the
/// rest move less than 1e-6 of the impact speed through the first half
/// swing (measured: 1e-18 of it); the energy through the strikes' step
/// is kept to 1e-9 J (measured: 3.3e-10 J).
#[test]
fn the_cradle_sends_out_as_many_balls_as_came_in() {
    let g = 9.81;
    let rise = 1.0 - 30f64.to_radians().cos();
    let impact_speed = (2.0 * g * rise).sqrt();
    for k in 1..=2 {
        let (mut app, balls) = cradle(k);
        let state = |app: &App, i: usize| bead_state(app.world(), balls[i]).expect("a ball");
        // Until the first strike: a quarter swing, about 0.5 s.
        let energy = |app: &App| -> f64 {
            let islands = app.world().resource::<Islands>();
            islands.iter().map(|r| r.energy).sum()
        };
        let mut steps = 0;
        let mut before = 0.0;
        // (Resting, a ball moves by rounding only.)
        while state(&app, 4).velocity.length() < 1e-6 * impact_speed {
            before = energy(&app);
            run_steps(&mut app, 1);
            steps += 1;
            assert!(steps < 600, "{k} in: no strike within a second");
        }
        // Through the step of the strikes, the energy is kept to 1e-9 J
        // (the swinging balls carry 1.3 J per ball) ...
        let change = energy(&app) - before;
        assert!(
            change.abs() <= 1e-9,
            "{k} in: the energy changed by {change} J"
        );
        // ... and each strike passes on one ball's momentum: along the
        // row, the impulses are all m v, to 1e-9 of it.
        let messages = app.world().resource::<Messages<BeadsStruck>>();
        let struck: Vec<BeadsStruck> = messages.get_cursor().read(messages).copied().collect();
        let passed = struck[0].impulse;
        assert!(struck.len() >= 4, "{struck:?}");
        for s in &struck {
            assert!(
                s.bounced && (s.impulse - passed).abs() <= 1e-9 * passed,
                "{struck:?}"
            );
        }
        let mut highest = [f64::MIN; 5];
        let mut fastest = [0f64; 5];
        // The first half swing out: 1 s.
        for _ in 0..600 {
            run_steps(&mut app, 1);
            for i in 0..5 {
                let s = state(&app, i);
                highest[i] = highest[i].max(s.position.y);
                fastest[i] = fastest[i].max(s.velocity.length());
            }
        }
        for i in 0..5 {
            if i >= 5 - k {
                let risen = highest[i];
                assert!(
                    (risen - rise).abs() <= 1e-3 * rise,
                    "{k} in: ball {i} rises to {risen}, not {rise}"
                );
            } else {
                assert!(
                    fastest[i] <= 1e-6 * impact_speed,
                    "{k} in: ball {i} moves at {} after the strike",
                    fastest[i]
                );
            }
        }
    }
}

/// A shipped scene, spawned into a headless app with its parameters and
/// contacts.
fn shipped(name: &str) -> (App, Vec<Entity>, ScenePreset) {
    let text = std::fs::read_to_string(crate::presets::shipped_dir().join(name)).expect(name);
    spawned(&text)
}

/// A scene's text, spawned into a headless app with its parameters and
/// contacts: the app, the beads in the file's order and the scene.
fn spawned(text: &str) -> (App, Vec<Entity>, ScenePreset) {
    let preset = ScenePreset::from_ron(text).unwrap_or_else(|e| panic!("{e}"));
    let (app, beads) = spawned_from(&preset);
    (app, beads, preset)
}

/// [`spawned`] for a scene already made.
fn spawned_from(preset: &ScenePreset) -> (App, Vec<Entity>) {
    spawned_from_file(&SceneFile::Plane(preset.clone()))
}

/// A single-threaded headless app with `scene` spawned, in the plane or
/// in space, and its beads.
fn spawned_from_file(scene: &SceneFile) -> (App, Vec<Entity>) {
    let plugin = WireBeadPlugin::new(scene.params().clone()).expect("valid params");
    let mut app = Headless::new(plugin).single_threaded().build();
    let beads = scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    (app, beads)
}

/// The worst overlap of any two beads with radii, as a share of the
/// smaller radius (negative while every pair is apart).
fn worst_overlap(app: &mut App) -> f64 {
    worst_overlap_of::<DVec2>(app)
}

/// [`worst_overlap`] of the beads in the plane (`V = DVec2`) or in space
/// (`DVec3`).
fn worst_overlap_of<V: Coordinates>(app: &mut App) -> f64 {
    let world = app.world_mut();
    let mut query = world.query::<(&BeadPosition<V>, &BeadRadius)>();
    let beads: Vec<(V, f64)> = query.iter(world).map(|(p, r)| (p.0, r.get())).collect();
    let mut worst = f64::MIN;
    for (i, &(a, ra)) in beads.iter().enumerate() {
        for &(b, rb) in &beads[i + 1..] {
            if ra > 0.0 && rb > 0.0 {
                let d = b - a;
                worst = worst.max((ra + rb - d.dot(d).sqrt()) / ra.min(rb));
            }
        }
    }
    worst
}

/// Every preset with beads that touch, ten seconds: no two beads ever
/// overlap by more than 1e-9 of a radius, and no bead stops.
#[test]
fn no_preset_lets_beads_overlap() {
    for name in [
        "newtons_cradle.scene.ron",
        "air_track.scene.ron",
        "air_track_sticky.scene.ron",
        "abacus.scene.ron",
        "train.scene.ron",
    ] {
        let (mut app, _, preset) = shipped(name);
        let steps = (10.0 / preset.params.timestep).round() as u32;
        let mut worst = f64::MIN;
        for _ in 0..steps {
            run_steps(&mut app, 1);
            worst = worst.max(worst_overlap(&mut app));
        }
        assert!(
            worst <= 1e-9,
            "{name}: beads overlap by {worst:e} of a radius"
        );
        let world = app.world_mut();
        assert_eq!(world.query::<&Diverged>().iter(world).count(), 0, "{name}");
    }
}

/// The air track presets end as their files say: elastic, 1 kg back at
/// 1.75 m/s and 3 kg on at 0.75 m/s; sticky, both at 0.125 m/s having
/// lost 2.34375 J (to 1e-12).
#[test]
fn the_air_track_presets_end_as_their_files_say() {
    for (name, light, heavy) in [
        ("air_track.scene.ron", -1.75, 0.75),
        ("air_track_sticky.scene.ron", 0.125, 0.125),
    ] {
        let (mut app, beads, _) = shipped(name);
        run_steps(&mut app, 120);
        let (a, b) = (velocity(&app, beads[0]), velocity(&app, beads[1]));
        assert!(
            (a - light).abs() <= 1e-12 && (b - heavy).abs() <= 1e-12,
            "{name}: {a}, {b}"
        );
        let energy = 0.5 * a * a + 1.5 * b * b;
        let expected = if light == heavy {
            2.375 - 2.34375
        } else {
            2.375
        };
        assert!((energy - expected).abs() <= 1e-12, "{name}: {energy} J");
    }
}

/// A scene's bad radius, restitution, friction, starting overlap or wire
/// that catches beads but pushes both ways: refused in one line naming it.
#[test]
fn bad_radii_restitutions_frictions_overlaps_and_catching_wires_are_refused_in_one_line() {
    let scene = |bead_a: &str, contacts: &str| {
        format!(
            "(name: \"t\", {contacts} wires: [(shape: Line(()), beads: [{bead_a}, (name: \"b\", radius: 0.1, initial_position: (1.0, 0.0))])])"
        )
    };
    let refused = |text: String| ScenePreset::from_ron(&text).unwrap_err().to_string();
    assert_eq!(
        refused(scene(
            "(name: \"a\", radius: -0.1, initial_position: (0.0, 0.0))",
            ""
        )),
        "wire 0, bead 0: radius must be zero or more and finite, got -0.1"
    );
    assert_eq!(
        refused(scene(
            "(name: \"a\", radius: NaN, initial_position: (0.0, 0.0))",
            ""
        )),
        "wire 0, bead 0: radius must be zero or more and finite, got NaN"
    );
    assert_eq!(
        refused(scene(
            "(name: \"a\", radius: 0.1, initial_position: (0.0, 0.0))",
            "contacts: (restitution: 1.5),"
        )),
        "contacts: restitution must be between 0 and 1, got 1.5"
    );
    assert_eq!(
        refused(scene(
            "(name: \"a\", radius: 0.1, initial_position: (0.0, 0.0))",
            "contacts: (restitution: -0.5),"
        )),
        "contacts: restitution must be between 0 and 1, got -0.5"
    );
    assert_eq!(
        refused(scene(
            "(name: \"a\", radius: 0.95, initial_position: (0.0, 0.0))",
            ""
        )),
        "beads \"a\" and \"b\" overlap by 5.000e-2 m where they start; beads with radii may touch but not overlap"
    );
    // Touching is not overlapping.
    let touching = scene(
        "(name: \"a\", radius: 0.9, initial_position: (0.0, 0.0))",
        "",
    );
    assert!(ScenePreset::from_ron(&touching).is_ok());
    assert_eq!(
        refused(scene(
            "(name: \"a\", radius: 0.1, initial_position: (0.0, 0.0))",
            "contacts: (friction: -0.2),"
        )),
        "contacts: friction must be zero or more and finite, got -0.2"
    );
    // A wire that catches beads pushes one way only.
    assert_eq!(
        refused("(name: \"t\", wires: [(shape: Line(()), catches: true)])".to_string()),
        "wire 0: a wire that catches beads must be one-sided (side: Positive or Negative)"
    );
}

/// An abacus of 20 lines of 10 beads each, beads pushed to and fro at
/// different speeds; with the island step split over threads or not.
fn abacus(parallel: wirebead::ParallelStep) -> (App, Vec<Entity>) {
    let params = SimParams {
        method: Method::new(Integrator::Rattle, None).expect("RATTLE"),
        ..SimParams::default()
    };
    let plugin = WireBeadPlugin::new(params).expect("valid params");
    let mut app = Headless::new(plugin).parallel(parallel).build();
    let mut beads = Vec::new();
    for line in 0..20 {
        let y = 0.3 * line as f64;
        let track = app
            .world_mut()
            .spawn((Wire::line(), Transform::from_xyz(0.0, y as f32, 0.0)))
            .id();
        for k in 0..10 {
            let speed = ((line * 7 + k * 3) % 11) as f64 - 5.0;
            let params = BeadParams {
                mass: 1.0 + (k % 3) as f64,
                initial_position: DVec2::new(0.25 * k as f64, y),
                initial_velocity: DVec2::new(speed, 0.0),
            };
            beads.push(
                app.world_mut()
                    .spawn((
                        Bead::new(params).expect("a bead"),
                        OnWire(track),
                        BeadRadius::new(0.1).expect("a radius"),
                    ))
                    .id(),
            );
        }
    }
    (app, beads)
}

/// Strikes settle the same, bit for bit, whether the islands step on one
/// thread or many; no two beads of the abacus ever overlap by more than
/// 1e-9 of a radius.
#[test]
fn strikes_are_bit_identical_sequential_and_parallel() {
    let (mut one, beads_one) = abacus(wirebead::ParallelStep::OFF);
    let (mut many, beads_many) = abacus(wirebead::ParallelStep { threshold: 0 });
    let mut worst = f64::MIN;
    for _ in 0..300 {
        run_steps(&mut one, 1);
        worst = worst.max(worst_overlap(&mut one));
    }
    run_steps(&mut many, 300);
    assert!(worst <= 1e-9, "beads overlap by {worst:e} of a radius");
    let mut moved = 0;
    for (&a, &b) in beads_one.iter().zip(&beads_many) {
        let (sa, sb) = (
            bead_state(one.world(), a).expect("a bead"),
            bead_state(many.world(), b).expect("a bead"),
        );
        for (va, vb) in [(sa.position, sb.position), (sa.velocity, sb.velocity)] {
            assert_eq!(
                va.to_array().map(f64::to_bits),
                vb.to_array().map(f64::to_bits)
            );
        }
        moved += usize::from(sa.velocity.x != 0.0);
    }
    assert!(moved > 150, "{moved} beads moving");
    let world = one.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
}

/// Two equal free balls in space with no gravity, one struck off centre:
/// they leave at right angles, momentum and energy kept to 1e-12.
#[test]
fn free_balls_in_space_struck_off_centre_leave_at_right_angles() {
    use bevy::math::DVec3;
    use wirebead::SpaceBead;
    use wirebead::headless::space_bead_state;
    let mut app = weightless();
    let u = DVec3::new(3.0, 0.0, 0.0);
    let mut spawn = |at: DVec3, v: DVec3| {
        let params = BeadParams {
            mass: 1.0,
            initial_position: at,
            initial_velocity: v,
        };
        app.world_mut()
            .spawn((
                SpaceBead::new(params).expect("a bead"),
                BeadRadius::new(0.1).expect("a radius"),
            ))
            .id()
    };
    let a = spawn(DVec3::ZERO, u);
    let b = spawn(DVec3::new(1.0, 0.08, 0.06), DVec3::ZERO);
    run_steps(&mut app, 60);
    let (sa, sb) = (
        space_bead_state(app.world(), a).expect("a bead"),
        space_bead_state(app.world(), b).expect("a bead"),
    );
    let (va, vb) = (sa.velocity, sb.velocity);
    assert!(vb.length() > 1.0, "the struck ball moves: {vb}");
    assert!(va.dot(vb).abs() <= 1e-12, "{va} · {vb}");
    assert!((va + vb - u).length() <= 1e-12, "momentum: {}", va + vb);
    let energy = 0.5 * (va.length_squared() + vb.length_squared());
    assert!((energy - 4.5).abs() <= 1e-12, "{energy} J");
    assert!((sb.position - sa.position).length() > 0.2);
}

/// Three free balls of 1, 2 and 3 kg dropped in a column onto a pinned
/// one, 5 cm between each (restitution 0): each lands on the one below and
/// stays, held by its contact row. For two seconds no pair overlaps by
/// more than 1e-9 of a radius; at rest, each pair presses with the weight
/// above it (λ = 6 g, 3 g and g, to 1e-9 of it) and the balls sit
/// 2r apart to 1e-9 of a radius.
#[test]
fn a_column_of_balls_dropped_on_a_pinned_one_rests_pressed_by_the_weight_above() {
    let dt = 1.0 / 240.0;
    let params = SimParams {
        timestep: dt,
        method: Method::new(Integrator::Rattle, None).expect("RATTLE"),
        ..SimParams::default()
    };
    let g = params.gravity.length();
    let plugin = WireBeadPlugin::new(params).expect("valid params");
    let mut app = Headless::new(plugin).single_threaded().build();
    app.insert_resource(Contacts::new(0.0).expect("a restitution"));
    let r = 0.1;
    let mut spawn = |mass: f64, y: f64| {
        app.world_mut()
            .spawn((
                Bead::at_rest(mass, DVec2::new(0.0, y)).expect("a ball"),
                BeadRadius::new(r).expect("a radius"),
            ))
            .id()
    };
    let base = spawn(1.0, 0.0);
    let column = [
        spawn(3.0, 2.0 * r + 0.05),
        spawn(2.0, 4.0 * r + 0.10),
        spawn(1.0, 6.0 * r + 0.15),
    ];
    app.world_mut()
        .spawn(Pin::new(base, DVec2::ZERO).expect("a pin"));
    let mut worst = f64::MIN;
    for _ in 0..480 {
        run_steps(&mut app, 1);
        worst = worst.max(worst_overlap(&mut app));
    }
    assert!(worst <= 1e-9, "balls overlap by {worst:e} of a radius");
    for (k, &ball) in column.iter().enumerate() {
        let state = bead_state(app.world(), ball).expect("a ball");
        let height = 2.0 * r * (k + 1) as f64;
        assert!(
            (state.position.y - height).abs() <= 1e-9 * r && state.position.x == 0.0,
            "ball {k} rests at {} instead of {height}",
            state.position
        );
        assert!(
            state.velocity.length() <= 1e-9,
            "ball {k} moves at {}",
            state.velocity
        );
    }
    let islands = app.world().resource::<Islands>();
    let pressed: Vec<_> = islands.iter().flat_map(|i| i.pressed.clone()).collect();
    assert_eq!(pressed.len(), 3, "{pressed:?}");
    let below = [base, column[0], column[1]];
    for (k, pair) in pressed.iter().enumerate() {
        let lower = below.iter().position(|&b| b == pair.a || b == pair.b);
        let weight: f64 = [3.0, 2.0, 1.0][lower.unwrap_or(k)..].iter().sum::<f64>() * g;
        assert!(
            (pair.force - weight).abs() <= 1e-9 * weight,
            "pair {k} presses with {} N instead of {weight} N",
            pair.force
        );
    }
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
}

/// The train preset: the 2 kg engine at 1.5 m/s couples the five 1 kg
/// carts within 1.25 s (restitution 0). Coupled, the six run on pressed
/// together, at one speed to 2e-4 of it (measured 7e-5), their kinetic
/// energy that of 7 kg sharing 3 kg m/s to 1e-3 (the strikes on the bend
/// are not quite along the track; measured 2e-4) and kept to 1e-6 of it
/// for eight seconds (measured 3e-7); as the track bends away the pairs
/// part one by one (no couplers), none pressed at the end.
#[test]
fn the_train_couples_runs_on_pressed_together_and_parts_where_the_track_pulls() {
    let (mut app, beads, _) = shipped("train.scene.ron");
    let energy = |app: &App| -> f64 {
        let islands = app.world().resource::<Islands>();
        islands.iter().map(|r| r.energy).sum()
    };
    let pressed = |app: &App| -> usize {
        let islands = app.world().resource::<Islands>();
        islands.iter().map(|r| r.pressed.len()).sum()
    };
    let mut last_strike = 0;
    let mut coupled = None;
    let mut worst_change = 0.0f64;
    for step in 1..=2400 {
        run_steps(&mut app, 1);
        let messages = app.world().resource::<Messages<BeadsStruck>>();
        if messages.iter_current_update_messages().count() > 0 {
            last_strike = step;
        }
        if step == 400 {
            assert_eq!(pressed(&app), 5, "the coupled train presses at every pair");
            let speeds: Vec<f64> = beads
                .iter()
                .map(|&b| {
                    bead_state(app.world(), b)
                        .expect("a cart")
                        .velocity
                        .length()
                })
                .collect();
            let (low, high) = speeds
                .iter()
                .fold((f64::MAX, 0.0f64), |(l, h), &s| (l.min(s), h.max(s)));
            assert!(high - low <= 2e-4 * high, "speeds {speeds:?}");
            let e = energy(&app);
            let shared = 3.0f64 * 3.0 / (2.0 * 7.0);
            assert!(
                (e - shared).abs() <= 1e-3 * shared,
                "energy {e} J, not {shared} J"
            );
            coupled = Some(e);
        }
        if let Some(e0) = coupled {
            worst_change = worst_change.max((energy(&app) - e0).abs() / e0);
        }
    }
    assert!(last_strike <= 300, "still striking at step {last_strike}");
    assert!(
        worst_change <= 1e-6,
        "the coupled train's energy changed by {worst_change:e} of it"
    );
    assert_eq!(
        pressed(&app),
        0,
        "the carts part where the track bends away"
    );
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
}

/// Beads of 2 cm and 1 kg at `e = 0` poured into a one-sided bowl of
/// radius 1 m with RATTLE at 240 Hz, in rows of 23 (a debug build pours
/// one row of sixteen; a release build two rows of 23, which `.ci/run`
/// runs): they land, slide in, strike each other and come to lie pressed
/// together, every bead pressed by a neighbour, never overlapping by more
/// than 1e-9 of a radius (measured 8e-11 for two rows);
/// in the last second nothing strikes and the pile, rocking in the
/// frictionless bowl, keeps its energy to 1e-9 of it (measured 1.5e-12
/// for two rows).
#[test]
fn a_pile_poured_into_a_bowl_lies_pressed_together_without_overlap() {
    let (n, cols, steps) = if cfg!(debug_assertions) {
        (16, 16, 480)
    } else {
        (46, 23, 720)
    };
    let preset = ScenePreset::pile(n, cols).unwrap_or_else(|e| panic!("{e}"));
    let (mut app, spawned) = spawned_from(&preset);
    let energy = |app: &App| -> f64 {
        let islands = app.world().resource::<Islands>();
        islands.iter().map(|i| i.energy).sum()
    };
    let mut worst = f64::MIN;
    let mut last_second = None;
    let mut worst_change = 0.0f64;
    for step in 1..=steps {
        run_steps(&mut app, 1);
        worst = worst.max(worst_overlap(&mut app));
        if step == steps - 240 {
            last_second = Some(energy(&app));
        }
        if let Some(e0) = last_second {
            worst_change = worst_change.max((energy(&app) - e0).abs() / e0.abs());
            let messages = app.world().resource::<Messages<BeadsStruck>>();
            assert_eq!(
                messages.iter_current_update_messages().count(),
                0,
                "step {step}: still striking"
            );
        }
    }
    let islands = app.world().resource::<Islands>();
    let pressed: Vec<Entity> = islands
        .iter()
        .flat_map(|i| i.pressed.iter().flat_map(|p| [p.a, p.b]))
        .collect();
    let loose = spawned.iter().filter(|b| !pressed.contains(b)).count();
    assert_eq!(loose, 0, "beads not pressed by a neighbour");
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
    assert!(worst <= 1e-9, "beads overlap by {worst:e} of a radius");
    assert!(
        worst_change <= 1e-9,
        "the resting pile's energy changed by {worst_change:e} of it"
    );
    eprintln!("{n} beads: overlap {worst:e}, energy change {worst_change:e}");
}

/// What [`pour_watched`] saw: the worst overlap of any step (a share of
/// a radius), the most the scene's energy rose in one step while the
/// beads poured, the most it rose above the lowest it had been, and its
/// value after each step.
struct Poured {
    worst: f64,
    rise: f64,
    above: f64,
    energies: Vec<f64>,
}

/// Runs a pour of `spawned` beads (in the plane `V = DVec2` or in space
/// `DVec3`) for `steps` steps, asserting at each that no two beads overlap
/// by more than 1e-9 of a radius; the energy's rises are measured over the
/// first `pouring` steps. Asserts that no bead stopped and, where
/// `landing` is given, that every bead (of [`PILE_RADIUS`]) came down onto
/// its bowl of radius 1 m or onto another bead within the first `landing`
/// steps.
fn pour_watched<V: Coordinates>(
    app: &mut App,
    spawned: &[Entity],
    (pouring, landing, steps): (usize, Option<usize>, usize),
) -> Poured {
    let r = PILE_RADIUS;
    let length = |v: V| v.dot(v).sqrt();
    let mut landed = vec![false; spawned.len()];
    let (mut worst, mut rise, mut above, mut lowest) = (f64::MIN, 0.0f64, 0.0f64, f64::INFINITY);
    let mut energies: Vec<f64> = Vec::with_capacity(steps);
    for step in 1..=steps {
        run_steps(app, 1);
        let overlap = worst_overlap_of::<V>(app);
        assert!(
            overlap <= 1e-9,
            "step {step}: beads overlap by {overlap:e} of a radius"
        );
        worst = worst.max(overlap);
        let e = app.world().resource::<SceneEnergy>().total;
        if let (Some(&before), true) = (energies.last(), step <= pouring) {
            rise = rise.max(e - before);
        }
        energies.push(e);
        lowest = lowest.min(e);
        above = above.max(e - lowest);
        if landing.is_none_or(|landing| step > landing) {
            continue;
        }
        let world = app.world_mut();
        let at: Vec<V> = spawned
            .iter()
            .map(|&b| world.get::<BeadPosition<V>>(b).expect("a bead").0)
            .collect();
        for (k, &x) in at.iter().enumerate() {
            let on_bowl = (length(x) - 1.0).abs() <= 1e-6 * r;
            landed[k] |= on_bowl
                || at
                    .iter()
                    .enumerate()
                    .any(|(j, &y)| j != k && length(y - x) <= 2.0 * r * (1.0 + 1e-6));
        }
    }
    let world = app.world_mut();
    let stopped: Vec<String> = world
        .query::<&Diverged>()
        .iter(world)
        .map(|d| format!("at {} s: {}", d.time, d.reason))
        .collect();
    assert!(
        stopped.is_empty(),
        "{} beads stopped, the first {:?}",
        stopped.len(),
        stopped.first()
    );
    if landing.is_some() {
        let aloft = landed.iter().filter(|&&l| !l).count();
        assert_eq!(aloft, 0, "beads that never came down");
    }
    Poured {
        worst,
        rise,
        above,
        energies,
    }
}

/// Five hundred beads of 2 cm and 1 kg at `e = 0` poured in rows of 23
/// into a one-sided bowl of radius 1 m ([`ScenePreset::pile`]), RATTLE at
/// 240 Hz for 3 s, one dense island whose step solves its contacts as
/// one complementarity problem: in 0.45 s every bead comes down onto the
/// bowl or onto the beads below, at no step do two overlap by more than
/// 1e-9 of a radius (measured 3.4e-10), and while they pour (0.45 s) the
/// scene's energy ([`SceneEnergy`]) never rises from one step to the next
/// by more than 1e-9 of the pile's weight times a radius: the landings
/// and meetings at `e = 0` take energy, nothing gives it. Later, as the
/// pile jams and its beads roll over one another, the energy never rises
/// above the lowest it has been by more than 1e-7 of the weight times
/// the bowl's radius (measured 1.2e-5 J of 4,905 J: RATTLE's own
/// oscillation, and what a contact held from within a step does to
/// first order). By 2.5 s the pile has settled: frictionless in a round
/// bowl, it rocks as one body, and its energy changes by no more than
/// 1e-7 of the weight times the radius over its last half second
/// (measured 6e-6 J; some 1e-2 J is lost in each step while it pours). Seconds in release,
/// minutes in a debug build; `.ci/run` runs it in release.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes in a debug build: run with --release"
)]
fn a_pile_of_500_beads_poured_into_a_bowl_never_overlaps_nor_gains_energy() {
    let preset = ScenePreset::pile(500, 23).unwrap_or_else(|e| panic!("{e}"));
    let (mut app, spawned) = spawned_from(&preset);
    app.init_resource::<SceneEnergy>();
    let r = PILE_RADIUS;
    let weight = 500.0 * 9.81;
    let (pouring, settled, steps) = (108, 600, 720);
    let Poured {
        worst,
        rise,
        above,
        energies,
    } = pour_watched::<DVec2>(&mut app, &spawned, (pouring, Some(pouring), steps));
    let settled_range = energies[settled - 1..]
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &e| {
            (lo.min(e), hi.max(e))
        });
    let swing = settled_range.1 - settled_range.0;
    eprintln!(
        "500 beads poured: overlap {worst:e}, energy rose by at most {rise:e} J in a step \
         while pouring, {above:e} J above its lowest, {swing:e} J over the last half second"
    );
    assert!(
        rise <= 1e-9 * weight * r,
        "the scene's energy rose by {rise:e} J in one step while pouring"
    );
    assert!(
        above <= 1e-7 * weight,
        "the scene's energy rose {above:e} J above the lowest it had been"
    );
    assert!(
        swing <= 1e-7 * weight,
        "the settled pile's energy changed by {swing:e} J over its last half second"
    );
}

/// Three hundred marbles of 2 cm and 1 kg at `e = 0` poured into a
/// one-sided sphere of radius 1 m ([`Pour`]), RATTLE at 60 Hz for 2 s,
/// one dense island in space: at no step do two overlap by more than
/// 1e-9 of a radius, no marble stops, every marble comes down onto the
/// sphere or onto another within the first second, and the scene's
/// energy never rises from one step to the next by more than 1e-9 of the
/// pile's weight times a radius while they pour (the first 0.5 s; measured
/// 0), nor ever above the lowest it has been by more than 1e-5 of the
/// weight times the sphere's radius (measured 5.6e-3 J of 2,943 J, some
/// 2e-6: frictionless, the pile rocks in its sphere as one body, and
/// RATTLE's energy swings by `(hω)²` of that motion's, sixteen times what
/// it swings at the 240 Hz of the plane's pour). Seconds in release;
/// `.ci/run` runs it in release.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "a minute in a debug build: run with --release"
)]
fn a_pile_of_marbles_poured_into_a_sphere_never_overlaps_nor_gains_energy() {
    let n = 300;
    let scene = Pour {
        beads: n,
        space: true,
        ..Pour::default()
    }
    .scene()
    .unwrap_or_else(|e| panic!("{e}"));
    let (mut app, spawned) = spawned_from_file(&scene);
    app.init_resource::<SceneEnergy>();
    let r = PILE_RADIUS;
    let weight = n as f64 * 9.81;
    let Poured {
        worst, rise, above, ..
    } = pour_watched::<DVec3>(&mut app, &spawned, (30, Some(60), 120));
    eprintln!(
        "{n} marbles poured: overlap {worst:e}, energy rose by at most {rise:e} J in a step \
         while pouring, {above:e} J above its lowest"
    );
    assert!(
        rise <= 1e-9 * weight * r,
        "the scene's energy rose by {rise:e} J in one step while pouring"
    );
    assert!(
        above <= 1e-5 * weight,
        "the scene's energy rose {above:e} J above the lowest it had been"
    );
}

/// Two hundred beads of 2 cm and 1 kg at `e = 0` poured into a one-sided
/// bowl of radius 1 m ([`Pour`]), RATTLE at 60 Hz for 0.5 s, one dense
/// island: its step holds each pair that meets within it, pressed to the
/// overlap its rows' compliance leaves, and the touch settlement takes
/// that as the step's meeting (none is located and struck at an instant
/// afterwards): no `BeadsStruck` is sent, no two beads overlap by more
/// than 1e-9 of a radius, none stops.
#[test]
#[cfg_attr(debug_assertions, ignore = "slow in a debug build: run with --release")]
fn a_pile_poured_at_60_hz_takes_every_meeting_in_its_dense_step() {
    let scene = Pour {
        beads: 200,
        ..Pour::default()
    }
    .scene()
    .unwrap_or_else(|e| panic!("{e}"));
    let (mut app, _) = spawned_from_file(&scene);
    let mut struck = 0;
    let mut worst = f64::MIN;
    for _ in 0..30 {
        run_steps(&mut app, 1);
        let messages = app.world().resource::<Messages<BeadsStruck>>();
        struck += messages.iter_current_update_messages().count();
        worst = worst.max(worst_overlap(&mut app));
    }
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
    assert_eq!(struck, 0, "meetings located and struck");
    assert!(worst <= 1e-9, "beads overlap by {worst:e} of a radius");
}

/// The shipped `hourglass.scene.ron` is the hourglass preset of 300
/// grains ([`Hourglass`]): read back, it writes the same scene file, to
/// the digit.
#[test]
fn the_shipped_hourglass_is_the_preset_of_300_grains() {
    let made = Hourglass {
        beads: 300,
        ..Hourglass::default()
    }
    .scene()
    .unwrap_or_else(|e| panic!("{e}"));
    crate::presets::assert_shipped_is("hourglass.scene.ron", SceneFile::Plane(made));
}

/// Two hundred grains of 1 cm and 10 g at `e = 0` in an hourglass
/// ([`Hourglass`]: a closed one-sided spline, the neck some four grains
/// wide), RATTLE at 240 Hz for 1.5 s, one dense island as they run
/// through the neck and pile below it: every grain is through the neck
/// by 1.5 s (all 200 are by 1.2 s), at no step do two overlap by more
/// than 1e-9 of a radius (measured 6.1e-10), none stops, and while they
/// run (the first second) the scene's energy never rises from one step
/// to the next by more than 1e-9 of the grains' weight times a radius
/// (measured 0: the grains fall freely, meet and land at `e = 0`,
/// nothing gives energy). Piled below, it never rises above the lowest
/// it has been by more than 1e-7 of the weight times a metre (measured
/// 2.8e-7 J: RATTLE's own oscillation of grains pressed
/// together). Seconds in release; `.ci/run` runs it in release.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "a minute in a debug build: run with --release"
)]
fn an_hourglass_of_200_grains_runs_through_its_neck_without_overlap() {
    let n = 200;
    let preset = Hourglass {
        beads: n,
        ..Hourglass::default()
    }
    .scene()
    .unwrap_or_else(|e| panic!("{e}"));
    let (mut app, spawned) = spawned_from(&preset);
    app.init_resource::<SceneEnergy>();
    let r = GRAIN_RADIUS;
    let weight = n as f64 * 0.01 * 9.81;
    let Poured {
        worst, rise, above, ..
    } = pour_watched::<DVec2>(&mut app, &spawned, (240, None, 360));
    let world = app.world_mut();
    let above_neck: Vec<f64> = spawned
        .iter()
        .map(|&g| world.get::<BeadPosition>(g).expect("a grain").0.y)
        .filter(|&y| y > -r)
        .collect();
    eprintln!(
        "hourglass of {n}: overlap {worst:e}, energy rose by at most {rise:e} J in a step \
         while running, {above:e} J above its lowest"
    );
    assert!(
        above_neck.is_empty(),
        "{} grains not through the neck",
        above_neck.len()
    );
    assert!(
        rise <= 1e-9 * weight * r,
        "the scene's energy rose by {rise:e} J in one step while the grains ran"
    );
    assert!(
        above <= 1e-7 * weight,
        "the scene's energy rose {above:e} J above the lowest it had been"
    );
}

/// A straight ramp that ends in mid-air (an open Catmull–Rom spline,
/// one-sided, through `(-1, 0.2)`, `(-0.5, 0.1)`, `(0, 0)` and
/// `(0.5, -0.1)`), with one bead at `(-0.5, 0.1)` sliding down it at
/// `(2, -0.4)` m/s, of radius `radius` if one is given: the scene run for
/// 1 s of RATTLE at 1/240 s, the bead's state and whether it is on its
/// wire.
fn off_the_ramp(radius: Option<f64>) -> (BeadState, bool) {
    let bead =
        "name: \"bead\", mass: 1.0, initial_position: (-0.5, 0.1), initial_velocity: (2.0, -0.4)";
    let bead = match radius {
        Some(r) => format!("({bead}, radius: {r})"),
        None => format!("({bead})"),
    };
    let text = format!(
        "(name: \"ramp\", params: (timestep: {}, integrator: Rattle), \
         wires: [(shape: Spline((points: [(-1.0, 0.2), (-0.5, 0.1), (0.0, 0.0), (0.5, -0.1)])), \
         side: Positive, beads: [{bead}])])",
        1.0 / 240.0
    );
    let (mut app, spawned, _) = spawned(&text);
    run_steps(&mut app, 240);
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
    let on = app
        .world()
        .get::<WireContact>(spawned[0])
        .expect("a contact")
        .is_on();
    (bead_state(app.world(), spawned[0]).expect("a bead"), on)
}

/// A bead with a radius (stepped in an island) leaves an open track at
/// its end, where the instant it passes it is found within the step, as
/// a bead with none does (the lone bead's step): after 1 s, 0.6 s of it
/// in flight, the two are flying and at the same place to 1e-12 m
/// (measured 4e-14).
#[test]
fn a_bead_with_a_radius_leaves_a_track_at_its_end_as_a_lone_bead_does() {
    let (lone, lone_on) = off_the_ramp(None);
    let (front, front_on) = off_the_ramp(Some(0.05));
    assert!(!lone_on && !front_on, "the beads are still on the ramp");
    assert!(
        lone.position.x > 1.0 && lone.position.y < -0.5,
        "the lone bead did not fly off the end: {:?}",
        lone.position
    );
    let apart = (front.position - lone.position).length();
    assert!(
        apart <= 1e-12,
        "{apart:e} m between the bead with a radius and the lone bead"
    );
    let speeds = (front.velocity - lone.velocity).length();
    assert!(speeds <= 1e-11, "{speeds:e} m/s between their velocities");
    eprintln!("off the ramp's end: {apart:e} m, {speeds:e} m/s apart");
}

/// The marble run: every marble runs down the top track or drops onto
/// it, and falls from track to track into the cup. After 10 s every
/// marble lies in the cup (between its rims, below them); each has left
/// a track past its end and landed on another at least three times; no
/// two ever overlap by more than 1e-9 of a radius (measured 4e-14).
#[test]
fn the_marble_run_takes_every_marble_from_track_to_track_into_the_cup() {
    let (mut app, beads, preset) = shipped("marble_run.scene.ron");
    let steps = (10.0 / preset.params.timestep).round() as u32;
    let mut worst = f64::MIN;
    let (mut landed, mut left) = (vec![0; beads.len()], vec![0; beads.len()]);
    for _ in 0..steps {
        run_steps(&mut app, 1);
        worst = worst.max(worst_overlap(&mut app));
        let changes = app.world().resource::<Messages<wirebead::ContactChanged>>();
        for change in changes.iter_current_update_messages() {
            let Some(k) = beads.iter().position(|&b| b == change.bead) else {
                continue;
            };
            match change.event {
                wirebead::solver::ContactEvent::Landed { .. } => landed[k] += 1,
                wirebead::solver::ContactEvent::Left { .. } => left[k] += 1,
            }
        }
    }
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
    for (k, &bead) in beads.iter().enumerate() {
        let x = bead_state(app.world(), bead).expect("a bead").position;
        assert!(
            (0.4..=2.2).contains(&x.x) && x.y <= -1.5,
            "marble {} is not in the cup: {x:?}",
            k + 1
        );
        assert!(
            landed[k] >= 3 && left[k] >= 3,
            "marble {} landed {} and left {} times",
            k + 1,
            landed[k],
            left[k]
        );
    }
    assert!(worst <= 1e-9, "marbles overlap by {worst:e} of a radius");
    eprintln!("marble run: overlap {worst:e}, landings {landed:?}, leavings {left:?}");
}

/// Two free balls of 1 kg and radius 0.1 m with no gravity, `contacts:
/// (restitution: 1.0, friction: 0.2)`: one at 2 m/s along x strikes the
/// other, at rest 0.1 m off its path, so they meet with their line of
/// centres 30° off it. The strike's normal impulse is `2 cos 30°` N s and
/// the slip across it 1 m/s: friction gives `μ p = 0.346` N s against it
/// (less than the 0.5 N s that would stop it), and both balls leave with
/// the velocities of that impulse to 1e-12, the message saying so.
#[test]
fn balls_struck_off_centre_with_friction_leave_with_the_coulomb_impulse() {
    let text = format!(
        "(name: \"rub\", params: (timestep: {}, integrator: Rattle, gravity: (0.0, 0.0)), \
         contacts: (restitution: 1.0, friction: 0.2), \
         beads: [(name: \"a\", mass: 1.0, radius: 0.1, initial_position: (-1.0, 0.0), initial_velocity: (2.0, 0.0)), \
                 (name: \"b\", mass: 1.0, radius: 0.1, initial_position: (0.0, 0.1))])",
        1.0 / 60.0
    );
    let (mut app, beads, _) = spawned(&text);
    let mut rubbed = Vec::new();
    for _ in 0..60 {
        run_steps(&mut app, 1);
        let messages = app.world().resource::<Messages<BeadsStruck>>();
        rubbed.extend(
            messages
                .iter_current_update_messages()
                .map(|m| m.friction_impulse),
        );
    }
    let n = DVec2::new(3f64.sqrt() / 2.0, 0.5);
    let t = DVec2::new(-n.y, n.x);
    let (p, f) = (3f64.sqrt(), 0.2 * 3f64.sqrt());
    let a = DVec2::new(2.0, 0.0) - n * p + t * f;
    let b = n * p - t * f;
    let va = bead_state(app.world(), beads[0]).expect("a").velocity;
    let vb = bead_state(app.world(), beads[1]).expect("b").velocity;
    assert!((va - a).length() <= 1e-12, "a leaves at {va:?}, not {a:?}");
    assert!((vb - b).length() <= 1e-12, "b leaves at {vb:?}, not {b:?}");
    assert_eq!(rubbed.len(), 1, "one strike: {rubbed:?}");
    assert!(
        (rubbed[0] - f).abs() <= 1e-12,
        "friction impulse {}",
        rubbed[0]
    );
    eprintln!(
        "off-centre strike with friction: {:e} and {:e} m/s off",
        (va - a).length(),
        (vb - b).length()
    );
}

/// A marble that left its own track and runs on a lower one under it stays
/// off its own track when the islands are rebuilt, twice over with no
/// step between (the second rebuild finds an island that never stepped):
/// after the rebuilds it moves on by no more than its speed allows, where
/// held on both tracks it would stop, reported diverged.
#[test]
fn a_marble_under_its_own_track_stays_off_it_through_rebuilds() {
    let (mut app, beads, _) = shipped("marble_run.scene.ron");
    // Run until one of the top track's own marbles is on the track below,
    // under the top one.
    let under = |app: &App| {
        beads[..4].iter().copied().find(|&b| {
            let x = bead_state(app.world(), b).expect("a marble").position;
            (-1.3..-0.1).contains(&x.x) && x.y < 0.5
        })
    };
    let mut marble = None;
    for _ in 0..2400 {
        run_steps(&mut app, 1);
        marble = under(&app);
        if marble.is_some() {
            break;
        }
    }
    let marble = marble.expect("a marble under its own track");
    let before = bead_state(app.world(), marble).expect("a marble");
    let track = app.world().get::<OnWire>(marble).expect("on a track").0;
    for _ in 0..2 {
        app.world_mut().entity_mut(track).insert(CatchesBeads);
        idle(&mut app);
    }
    run_steps(&mut app, 1);
    let after = bead_state(app.world(), marble).expect("a marble");
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
    let moved = (after.position - before.position).length();
    let reach = 2.0 * before.velocity.length() / 240.0 + 1e-6;
    assert!(
        moved <= reach,
        "the marble jumped {moved} m in one step (at most {reach} m)"
    );
}

/// A bead of 10 cm and 1 kg laid at rest on top of another, pinned, at
/// `degrees` from the top, the pair at `e = 0` with Coulomb friction
/// `mu`, stepped `steps` times with RATTLE at 1/240 s: the angle of the
/// top bead from the top (rad), its angular speed about the bottom bead
/// (rad/s), and whether the two still press.
fn resting_on_a_bead(degrees: f64, mu: f64, steps: u32) -> (f64, f64, bool) {
    resting_on_a_bead_rebuilt(degrees, mu, steps, 0)
}

/// [`resting_on_a_bead`], the islands built again `rebuilds` times
/// through its steps (a bead spawned far away each time).
fn resting_on_a_bead_rebuilt(degrees: f64, mu: f64, steps: u32, rebuilds: u32) -> (f64, f64, bool) {
    let (x, y) = (
        0.2 * degrees.to_radians().sin(),
        0.2 * degrees.to_radians().cos(),
    );
    let text = format!(
        "(name: \"stacked\", params: (timestep: {}, integrator: Rattle), \
         contacts: (restitution: 0.0, friction: {mu}), \
         beads: [(name: \"base\", mass: 1.0, radius: 0.1, initial_position: (0.0, 0.0)), \
                 (name: \"top\", mass: 1.0, radius: 0.1, initial_position: ({x}, {y}))], \
         constraints: [Pin((bead: \"base\", at: (0.0, 0.0)))])",
        1.0 / 240.0
    );
    let (mut app, spawned, _) = spawned(&text);
    let parts = rebuilds + 1;
    for part in 0..parts {
        if part > 0 {
            crate::common::build_islands_again(&mut app, part);
        }
        run_steps(&mut app, steps / parts);
    }
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
    let base = bead_state(app.world(), spawned[0]).expect("the base");
    let top = bead_state(app.world(), spawned[1]).expect("the top");
    let d = top.position - base.position;
    let angle = d.x.atan2(d.y);
    let speed = d.perp_dot(top.velocity - base.velocity) / d.length_squared();
    let islands = app.world().resource::<Islands>();
    let pressing = islands.iter().map(|i| i.pressed.len()).sum::<usize>() == 1;
    (angle, -speed, pressing)
}

/// Static friction between beads: a bead at rest on a pinned bead 20°
/// from its top, with `μ = 0.5 > tan 20° = 0.36`, stays where it was
/// laid for 2 s, pressed (its angle within 1e-9 rad); without friction it
/// slides off.
#[test]
fn a_bead_at_rest_on_another_is_held_by_static_friction() {
    let (angle, speed, pressing) = resting_on_a_bead(20.0, 0.5, 480);
    let moved = (angle - 20f64.to_radians()).abs();
    assert!(moved <= 1e-9, "moved by {moved:e} rad, at {speed:e} rad/s");
    assert!(pressing, "the pair no longer presses");
    let (angle, ..) = resting_on_a_bead(20.0, 0.0, 48);
    assert!(
        angle > 21f64.to_radians(),
        "without friction it did not slide: {angle}"
    );
}

/// Static friction across rebuilds: the bead of
/// [`a_bead_at_rest_on_another_is_held_by_static_friction`], the islands
/// built again ten times in its 2 s (a bead spawned far away each time),
/// stays where it was laid to 1e-9 rad: each rebuilt island starts the
/// pair's stick row held at the line it held on.
#[test]
fn a_bead_held_by_static_friction_stays_held_when_its_island_is_built_again() {
    let (angle, speed, pressing) = resting_on_a_bead_rebuilt(20.0, 0.5, 480, 10);
    let moved = (angle - 20f64.to_radians()).abs();
    assert!(moved <= 1e-9, "moved by {moved:e} rad, at {speed:e} rad/s");
    assert!(pressing, "the pair no longer presses");
}

/// The bead of [`resting_on_a_bead`] in space (the pair in the plane
/// `z = 0`, gravity along `−y`), 30° from the top at `μ = 0.2`: it has
/// no stick row, and slides as the pair in the plane does, its angle and
/// angular speed after 0.2 s within 1e-9 of the plane's (measured the
/// same to the bit).
#[test]
fn a_bead_sliding_on_another_in_space_rubs_as_in_the_plane() {
    use bevy::math::DVec3;
    use wirebead::SpaceBead;
    use wirebead::headless::space_bead_state;
    let params = SimParams {
        timestep: 1.0 / 240.0,
        method: Method::new(Integrator::Rattle, None).expect("RATTLE"),
        ..SimParams::default()
    };
    let plugin = WireBeadPlugin::new(params).expect("valid params");
    let mut app = Headless::new(plugin).single_threaded().build();
    let contacts = Contacts::new(0.0).and_then(|c| c.with_friction(0.2));
    app.insert_resource(contacts.expect("contacts"));
    let theta = 30f64.to_radians();
    let mut spawn = |at: DVec3| {
        let params = BeadParams {
            mass: 1.0,
            initial_position: at,
            initial_velocity: DVec3::ZERO,
        };
        app.world_mut()
            .spawn((
                SpaceBead::new(params).expect("a bead"),
                BeadRadius::new(0.1).expect("a radius"),
            ))
            .id()
    };
    let base = spawn(DVec3::ZERO);
    let top = spawn(DVec3::new(0.2 * theta.sin(), 0.2 * theta.cos(), 0.0));
    app.world_mut()
        .spawn(Pin::new(base, DVec3::ZERO).expect("a pin"));
    run_steps(&mut app, 48);
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
    let (a, b) = (
        space_bead_state(app.world(), base).expect("the base"),
        space_bead_state(app.world(), top).expect("the top"),
    );
    let d = b.position - a.position;
    let angle = d.x.atan2(d.y);
    let speed = -(d.x * (b.velocity.y - a.velocity.y) - d.y * (b.velocity.x - a.velocity.x))
        / d.length_squared();
    let (plane_angle, plane_speed, _) = resting_on_a_bead(30.0, 0.2, 48);
    assert!(
        (angle - plane_angle).abs() <= 1e-9,
        "angle {angle} against {plane_angle} in the plane"
    );
    assert!(
        (speed - plane_speed).abs() <= 1e-9,
        "angular speed {speed} against {plane_speed} in the plane"
    );
    assert!(d.z.abs() <= 1e-12, "left the plane: {}", d.z);
    eprintln!(
        "in space against the plane: angle {:e} rad, angular speed {:e} rad/s",
        angle - plane_angle,
        speed - plane_speed
    );
}

/// Kinetic friction between beads: a bead let go at rest on a pinned bead
/// 30° from its top, with `μ = 0.2 < tan 30°`, slides down it as a bead
/// on the outside of a rough circle of radius `R` = 0.2 m does,
/// `θ̈ = (g / R)(sin θ − μ cos θ) + μ θ̇²` while it presses (integrated
/// by RK4 at 1e-5 s): after 0.2 s, its angle within 2e-3 rad (measured
/// 8.0e-4) and its angular speed within 1 % (measured 0.35 %) of the
/// reference, friction being held at its value at each step's start;
/// without friction it slides further.
#[test]
fn a_bead_sliding_on_another_is_slowed_by_kinetic_friction() {
    let (g, r, mu) = (9.81, 0.2, 0.2);
    let accel =
        |theta: f64, omega: f64| (g / r) * (theta.sin() - mu * theta.cos()) + mu * omega * omega;
    let (mut theta, mut omega) = (30f64.to_radians(), 0.0);
    let h = 1e-5;
    for _ in 0..20_000 {
        let (k1x, k1v) = (omega, accel(theta, omega));
        let (k2x, k2v) = (
            omega + 0.5 * h * k1v,
            accel(theta + 0.5 * h * k1x, omega + 0.5 * h * k1v),
        );
        let (k3x, k3v) = (
            omega + 0.5 * h * k2v,
            accel(theta + 0.5 * h * k2x, omega + 0.5 * h * k2v),
        );
        let (k4x, k4v) = (omega + h * k3v, accel(theta + h * k3x, omega + h * k3v));
        theta += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        omega += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    let (angle, speed, pressing) = resting_on_a_bead(30.0, mu, 48);
    assert!(pressing, "the pair no longer presses");
    assert!(
        (angle - theta).abs() <= 2e-3,
        "angle {angle} against {theta}"
    );
    assert!(
        (speed - omega).abs() <= 1e-2 * omega.abs(),
        "angular speed {speed} against {omega}"
    );
    let (free, ..) = resting_on_a_bead(30.0, 0.0, 48);
    assert!(
        free > angle + 0.01,
        "friction did not slow it: {free} against {angle}"
    );
}

/// The abacus of the touch bench: 1,000 beads of radius 0.1 m on 100
/// rings of radius 1 m, ten to a ring, each set going round at its own
/// speed (up to 5 m/s), no gravity, elastic, RATTLE at 60 Hz. Each bead
/// rides its ring alone, so no island is built, and its meetings are
/// settled by re-stepping the beads they concern (a strike that sends a
/// bead back into a neighbour settled before it settles both again).
/// Over 5 s, with some seventy strikes a step, no two beads overlap
/// by more than 1e-9 of a radius and each ring keeps its energy to 1e-9
/// of it.
#[test]
fn an_abacus_of_beads_riding_alone_keeps_each_rings_energy_and_never_overlaps() {
    let mut app = weightless();
    let mut rings = Vec::new();
    for ring in 0..100 {
        let centre = DVec2::new(3.0 * (ring % 10) as f64, 3.0 * (ring / 10) as f64);
        let world = app.world_mut();
        let wire = world
            .spawn((
                Wire::circle(1.0).expect("a ring"),
                Transform::from_xyz(centre.x as f32, centre.y as f32, 0.0),
            ))
            .id();
        rings.push(wire);
        for k in 0..10 {
            let angle = std::f64::consts::TAU * k as f64 / 10.0;
            let along = DVec2::new(-angle.sin(), angle.cos());
            let speed = ((ring * 7 + k * 3) % 11) as f64 - 5.0;
            let params = BeadParams {
                mass: 1.0 + (k % 3) as f64,
                initial_position: centre + DVec2::from_angle(angle),
                initial_velocity: along * speed,
            };
            world.spawn((
                Bead::new(params).expect("a bead"),
                OnWire(wire),
                BeadRadius::new(0.1).expect("a radius"),
            ));
        }
    }
    let energies = |app: &mut App| -> Vec<f64> {
        let world = app.world_mut();
        let mut query = world.query::<(&BeadVelocity, &BeadMass, &OnWire)>();
        let mut energy = vec![0.0; rings.len()];
        for (v, m, on) in query.iter(world) {
            let ring = rings.iter().position(|&w| w == on.0).expect("a ring");
            energy[ring] += 0.5 * m.get() * v.0.length_squared();
        }
        energy
    };
    run_steps(&mut app, 1);
    let start = energies(&mut app);
    let (mut overlap, mut drift, mut strikes) = (f64::MIN, 0.0f64, 0);
    for _ in 0..300 {
        run_steps(&mut app, 1);
        let messages = app.world().resource::<Messages<BeadsStruck>>();
        strikes += messages.iter_current_update_messages().count();
        overlap = overlap.max(worst_overlap(&mut app));
        for (now, was) in energies(&mut app).iter().zip(&start) {
            drift = drift.max((now - was).abs() / was);
        }
        assert_eq!(app.world().resource::<Islands>().iter().count(), 0);
    }
    eprintln!(
        "abacus: {strikes} strikes, overlap {overlap:e} of a radius, energy kept to {drift:e}"
    );
    assert!(strikes >= 300 * 50, "only {strikes} strikes");
    assert!(overlap <= 1e-9, "beads overlap by {overlap:e} of a radius");
    assert!(drift <= 1e-9, "a ring's energy moved by {drift:e} of it");
    let world = app.world_mut();
    assert_eq!(world.query::<&Diverged>().iter(world).count(), 0);
}

/// Islands merge and split without building the rest again: a pile of
/// 30 beads poured into a bowl at 60 Hz ([`Pour`]) for 1 s, beside two
/// beads far off that close on each other and meet at `e = 0` after
/// 0.78 s (their pair joins an island of its own, and the islands are
/// regrouped for it at a step where the pile's are not): the pile's
/// island is kept whole, counting its steps on as in the same pour run
/// alone ([`IslandReport::steps`](wirebead::IslandReport)), and every
/// bead of the pile is, after every step, where it is in that run, to
/// the bit.
#[test]
fn a_pile_steps_on_unchanged_while_a_pair_far_off_meets_and_joins() {
    let scene = Pour {
        beads: 30,
        ..Pour::default()
    }
    .scene()
    .unwrap_or_else(|e| panic!("{e}"));
    let (mut alone, pile) = spawned_from_file(&scene);
    let (mut beside, same) = spawned_from_file(&scene);
    let mut pair = Vec::new();
    for (x, v) in [(5.0, 1.0), (6.6, -1.0)] {
        let params = BeadParams {
            mass: 1.0,
            initial_position: DVec2::new(x, 0.0),
            initial_velocity: DVec2::new(v, 0.0),
        };
        let bead = (
            Bead::new(params).expect("a bead"),
            BeadRadius::new(PILE_RADIUS).expect("a radius"),
        );
        pair.push(beside.world_mut().spawn(bead).id());
    }
    let (mut pressed, mut kept, mut apart) = (0, 0, 0);
    for step in 1..=60 {
        run_steps(&mut alone, 1);
        run_steps(&mut beside, 1);
        for (&a, &b) in pile.iter().zip(&same) {
            let (a, b) = (bead_state(alone.world(), a), bead_state(beside.world(), b));
            assert_eq!(a, b, "step {step}: a bead of the pile went elsewhere");
        }
        let islands = beside.world().resource::<Islands>();
        let joined = islands
            .of(pair[0])
            .is_some_and(|i| i.beads.contains(&pair[1]));
        pressed += usize::from(joined);
        let lived = |app: &App, bead| app.world().resource::<Islands>().of(bead).map(|i| i.steps);
        let (then, now) = (lived(&alone, pile[0]), lived(&beside, same[0]));
        kept += usize::from(then.is_some() && then == now);
        // The pair's island built anew where the pile's was not.
        apart += usize::from(joined && lived(&beside, pair[0]) == Some(1) && then > Some(1));
        assert!(
            now >= then,
            "step {step}: the pile's island was built again after {now:?} steps, alone after {then:?}"
        );
    }
    assert!(pressed > 0, "the pair far off never met");
    assert!(
        apart > 0,
        "the pair joined only where the pile was built again"
    );
    assert_eq!(kept, 60, "the pile's island was built again for the pair");
    let (a, b) = (
        bead_state(beside.world(), pair[0]).expect("a bead"),
        bead_state(beside.world(), pair[1]).expect("a bead"),
    );
    let gap = (b.position - a.position).length() - 2.0 * PILE_RADIUS;
    assert!(
        gap.abs() <= 1e-9 * PILE_RADIUS && (b.velocity - a.velocity).length() <= 1e-9,
        "the pair far off did not meet at e = 0: gap {gap:e} m"
    );
}
