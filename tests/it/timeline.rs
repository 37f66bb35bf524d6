//! The timeline: a run taken back to a recorded step runs on the same, bit
//! for bit, on every shipped scene (islands, touching beads, moving wires,
//! space); an edit drops the recorded future; the history stays in bounds.

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;
use wirebead::headless::{Headless, idle, run_steps};
use wirebead::plugin::{Timeline, TimelinePlugin, TimelineSeek};
use wirebead::prelude::*;
use wirebead::{Integrator, KeyboardControlsPlugin, Restart, SceneFile, SimClock};

use crate::common::{self, circle_bead};
use crate::controls::press;
use crate::presets::shipped_dir;

/// Every bead's position and velocity, as bits, by entity.
type Bits = Vec<(Entity, [u64; 6])>;

fn bits(app: &mut App) -> Bits {
    let world = app.world_mut();
    let mut out: Bits = Vec::new();
    let mut plane = world.query::<(Entity, &BeadPosition, &BeadVelocity)>();
    for (e, x, v) in plane.iter(world) {
        out.push((e, pack(x.0.extend(0.0), v.0.extend(0.0))));
    }
    let mut space = world.query::<(Entity, &BeadPosition<DVec3>, &BeadVelocity<DVec3>)>();
    for (e, x, v) in space.iter(world) {
        out.push((e, pack(x.0, v.0)));
    }
    out.sort_unstable_by_key(|(e, _)| *e);
    out
}

fn pack(x: DVec3, v: DVec3) -> [u64; 6] {
    [x.x, x.y, x.z, v.x, v.y, v.z].map(f64::to_bits)
}

/// A headless app with the timeline, running the scene file `name`.
fn scene(name: &str) -> App {
    let text = std::fs::read_to_string(shipped_dir().join(name)).unwrap();
    let scene = SceneFile::from_ron(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
    let plugin = WireBeadPlugin::new(scene.params().clone()).unwrap();
    let mut app = Headless::new(plugin).single_threaded().build();
    app.add_plugins(TimelinePlugin);
    scene.spawn(&mut app.world_mut().commands());
    idle(&mut app);
    app
}

fn seek(app: &mut App, to: TimelineSeek) {
    app.world_mut().write_message(to);
    idle(app);
    let mut time = app.world_mut().resource_mut::<Time<Virtual>>();
    assert!(time.is_paused(), "a seek pauses the run");
    time.unpause();
}

fn history(app: &App) -> &Timeline {
    app.world().resource::<Timeline>()
}

fn scene_files() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(shipped_dir())
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".scene.ron"))
        .collect();
    names.sort();
    names
}

#[test]
fn every_shipped_scene_runs_on_from_a_step_back_bit_for_bit() {
    const STEPS: usize = 48;
    const BACK_TO: usize = 16;
    let names = scene_files();
    assert!(names.len() >= 27, "{names:?}");
    let mut moved = 0;
    for name in &names {
        let mut app = scene(name);
        let mut run = vec![bits(&mut app)];
        for _ in 0..STEPS {
            run_steps(&mut app, 1);
            run.push(bits(&mut app));
        }
        assert!(!run[STEPS].is_empty(), "{name}: no bead");
        moved += usize::from(run[STEPS] != run[0]);
        assert_eq!(history(&app).len(), STEPS, "{name}");

        seek(&mut app, TimelineSeek::To(BACK_TO as u64));
        assert_eq!(app.world().resource::<SimClock>().steps, BACK_TO as u64);
        assert_eq!(bits(&mut app), run[BACK_TO], "{name}: the step went back");
        for (k, recorded) in run.iter().enumerate().skip(BACK_TO + 1) {
            run_steps(&mut app, 1);
            assert_eq!(
                bits(&mut app),
                *recorded,
                "{name}: step {k} run again differs"
            );
        }
        let timeline = history(&app);
        assert_eq!(timeline.departed(), None, "{name}");
        assert_eq!(timeline.matched(), (STEPS - BACK_TO) as u64, "{name}");
        assert_eq!(timeline.at(), None, "{name}: back at the newest step");

        seek(&mut app, TimelineSeek::Back);
        assert_eq!(bits(&mut app), run[STEPS - 1], "{name}: one step back");
        seek(&mut app, TimelineSeek::Back);
        assert_eq!(bits(&mut app), run[STEPS - 2], "{name}: two steps back");
        run_steps(&mut app, 2);
        assert_eq!(bits(&mut app), run[STEPS], "{name}: and forward again");
    }
    // The bowl's bead and the resting bead start at rest.
    assert!(
        moved >= names.len() - 2,
        "{moved} of {} scenes moved",
        names.len()
    );
}

/// A bead on a circle, let go level with its centre, with RATTLE and the
/// timeline.
fn circle() -> (App, Entity) {
    let params = SimParams {
        method: Method::new(Integrator::Rattle, None).unwrap(),
        ..SimParams::default()
    };
    let mut app = common::app(params);
    app.add_plugins(TimelinePlugin);
    let bead = circle_bead(&mut app, 1.0, DVec2::new(1.0, 0.0), DVec2::ZERO);
    idle(&mut app);
    (app, bead)
}

#[test]
fn an_edit_after_a_step_back_drops_the_recorded_future() {
    let (mut app, bead) = circle();
    run_steps(&mut app, 100);
    let recorded = history(&app).bead(60, bead).expect("step 60 recorded");
    seek(&mut app, TimelineSeek::To(50));
    let (x50, v50) = history(&app).bead(50, bead).unwrap();
    assert_eq!(app.world().get::<BeadPosition>(bead).unwrap().0, x50);
    assert_eq!(app.world().get::<BeadVelocity>(bead).unwrap().0, v50);
    // The edit: a push.
    app.world_mut().get_mut::<BeadVelocity>(bead).unwrap().0 *= 1.5;
    run_steps(&mut app, 10);
    let timeline = history(&app);
    assert_eq!(timeline.departed(), Some(51));
    assert_eq!(timeline.matched(), 0);
    assert_eq!(
        timeline.len(),
        60,
        "steps 51 to 100 were dropped for 51 to 60"
    );
    let (x60, _) = timeline.bead(60, bead).unwrap();
    assert!(
        (x60 - recorded.0).length() > 1e-3,
        "the pushed run went elsewhere"
    );
    assert_eq!(timeline.bead(61, bead), None);
}

#[test]
fn the_history_keeps_its_seconds_and_a_restart_starts_it_anew() {
    let (mut app, bead) = circle();
    app.world_mut().resource_mut::<Timeline>().seconds = 0.1;
    run_steps(&mut app, 100);
    let dt = app.world().resource::<SimParams>().timestep;
    let timeline = history(&app);
    let (first, last) = timeline.span().unwrap();
    assert_eq!(last.steps, 100);
    assert_eq!(timeline.len() as f64, (0.1 / dt).ceil());
    assert_eq!(first.steps, 100 - timeline.len() as u64);
    assert!(timeline.bytes() > 0);
    // Asked for a step before the oldest kept, the run goes to the oldest.
    seek(&mut app, TimelineSeek::To(0));
    assert_eq!(app.world().resource::<SimClock>().steps, first.steps);
    let (x, _) = timeline_bead(&app, first.steps, bead);
    assert_eq!(app.world().get::<BeadPosition>(bead).unwrap().0, x);

    app.world_mut().write_message(Restart);
    run_steps(&mut app, 3);
    let timeline = history(&app);
    assert_eq!(
        timeline.span().map(|(a, b)| (a.steps, b.steps)),
        Some((0, 3))
    );
}

fn timeline_bead(app: &App, step: u64, bead: Entity) -> (DVec2, DVec2) {
    history(app).bead(step, bead).unwrap()
}

#[test]
fn b_steps_back_and_n_runs_forward_the_same() {
    let (mut app, bead) = circle();
    app.add_plugins(KeyboardControlsPlugin);
    run_steps(&mut app, 40);
    // The first press comes in a frame that steps (to 41): it goes back
    // from there, after the step.
    for _ in 0..5 {
        press(&mut app, KeyCode::KeyB, 1);
    }
    assert!(app.world().resource::<Time<Virtual>>().is_paused());
    assert_eq!(app.world().resource::<SimClock>().steps, 36);
    let (x36, v36) = history(&app).bead(36, bead).unwrap();
    assert_eq!(app.world().get::<BeadPosition>(bead).unwrap().0, x36);
    assert_eq!(app.world().get::<BeadVelocity>(bead).unwrap().0, v36);
    for _ in 0..3 {
        press(&mut app, KeyCode::KeyN, 1);
    }
    assert_eq!(app.world().resource::<SimClock>().steps, 39);
    let (x39, v39) = history(&app).bead(39, bead).unwrap();
    let now = (
        app.world().get::<BeadPosition>(bead).unwrap().0,
        app.world().get::<BeadVelocity>(bead).unwrap().0,
    );
    assert_eq!(now, (x39, v39));
    assert_eq!(history(&app).matched(), 3);
    assert_eq!(history(&app).at().map(|c| c.steps), Some(39));
}

/// A wire moved through its [`WirePlace`](wirebead::WirePlace) (at
/// x = 1000, by 1e-6 m a step, less than the `f32` step of its
/// `Transform` there) is taken back with its place: back to step 30 the
/// place is step 30's to the bit, and the run written on from there as
/// before is the recorded one, bit for bit.
#[test]
fn a_wire_moved_by_its_place_runs_on_from_a_step_back_bit_for_bit() {
    use wirebead::WirePlace;
    use wirebead::geometry::Pose;
    let place = |step: u64| Pose::new(DVec2::new(1000.0 + 1e-6 * step as f64, 0.0), 0.0);
    let params = SimParams {
        timestep: 1.0 / 240.0,
        method: Method::new(Integrator::Rattle, None).unwrap(),
        ..SimParams::default()
    };
    let mut app = common::app(params);
    app.add_plugins(TimelinePlugin);
    let wire = app
        .world_mut()
        .spawn((Wire::circle(1.0).unwrap(), WirePlace::new(place(0))))
        .id();
    common::bead_at_rest_on(&mut app, wire, place(0).origin);
    // The place for the end of the coming step, as a game writes it.
    let step = |app: &mut App| {
        let next = app.world().resource::<SimClock>().steps + 1;
        app.world_mut().get_mut::<WirePlace>(wire).unwrap().0 = place(next);
        run_steps(app, 1);
    };
    let mut run = vec![bits(&mut app)];
    for _ in 0..60 {
        step(&mut app);
        run.push(bits(&mut app));
    }
    assert_ne!(run[60], run[0], "the bead rode the moving wire");
    seek(&mut app, TimelineSeek::To(30));
    assert_eq!(app.world().get::<WirePlace>(wire).unwrap().0, place(30));
    assert_eq!(bits(&mut app), run[30], "the step went back");
    for (k, recorded) in run.iter().enumerate().skip(31) {
        step(&mut app);
        assert_eq!(bits(&mut app), *recorded, "step {k} run again differs");
    }
}
