//! The timeline with avian's bodies: a step back puts every moving body
//! where it was recorded (position, turn, velocities and `Transform`, bit
//! for bit), with the beads, and the run goes on from there.

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;
use wirebead::controls::{StepRequests, run_requested_steps};
use wirebead::headless::{Headless, idle, run_steps};
use wirebead::plugin::{Timeline, TimelineSeek};
use wirebead::prelude::*;
use wirebead::preset::table::{BodyState, SceneSpace};
use wirebead::{SceneFile, SimClock};

use crate::presets::shipped_dir;

/// A headless app with avian and the timeline running the shipped scene
/// `avian/<stem>`: its beads and moving bodies in the file's order.
fn scene(stem: &str) -> (App, Vec<Entity>, Vec<Entity>) {
    let path = shipped_dir().join(format!("avian/{stem}.scene.ron"));
    let scene = SceneFile::from_ron(&std::fs::read_to_string(path).unwrap()).unwrap();
    let plugin = WireBeadPlugin::new(scene.params().clone()).unwrap();
    let mut app = Headless::new(plugin)
        .single_threaded()
        .bodies(scene.in_space())
        .timeline()
        .build();
    let (beads, bodies) = scene.spawn_recorded(&mut app.world_mut().commands());
    idle(&mut app);
    (app, beads, bodies)
}

/// The bodies' states (as a scene's run reads them), their `Transform`s,
/// and the beads' positions and velocities.
type Snapshot<V> = (Vec<BodyState<V>>, Vec<Transform>, Vec<(DVec3, DVec3)>);

/// What [`Snapshot`] says, now.
fn snapshot<V: SceneSpace>(app: &App, beads: &[Entity], bodies: &[Entity]) -> Snapshot<V> {
    let world = app.world();
    let states = bodies.iter().map(|&b| V::body(world, b).unwrap()).collect();
    let shown = bodies
        .iter()
        .map(|&b| *world.get::<Transform>(b).unwrap())
        .collect();
    let beads = beads
        .iter()
        .map(|&bead| {
            if V::DIMENSION == 2 {
                let x = world.get::<BeadPosition>(bead).unwrap().0;
                let v = world.get::<BeadVelocity>(bead).unwrap().0;
                (x.extend(0.0), v.extend(0.0))
            } else {
                let x = world.get::<BeadPosition<DVec3>>(bead).unwrap().0;
                (x, world.get::<BeadVelocity<DVec3>>(bead).unwrap().0)
            }
        })
        .collect();
    (states, shown, beads)
}

/// Takes the run to `step` and lets it go on.
fn seek(app: &mut App, step: u64) {
    app.world_mut().write_message(TimelineSeek::To(step));
    idle(app);
    let mut time = app.world_mut().resource_mut::<Time<Virtual>>();
    assert!(time.is_paused(), "a seek pauses the run");
    time.unpause();
}

/// Runs `stem` 40 steps, takes it back to step 25 and runs it on to 40:
/// the state at 25 comes back bit for bit, and the run from there ends
/// where the first did to within `within` (its bodies); where `within` is
/// zero, the timeline finds every step the same as recorded.
fn taken_back<V: SceneSpace>(stem: &str, within: f64) {
    let (mut app, beads, bodies) = scene(stem);
    assert!(!bodies.is_empty(), "{stem}: moving bodies");
    run_steps(&mut app, 25);
    let at25 = snapshot::<V>(&app, &beads, &bodies);
    run_steps(&mut app, 15);
    let (at40, ..) = snapshot::<V>(&app, &beads, &bodies);
    assert_ne!(at25.0, at40, "{stem}: the bodies moved");

    seek(&mut app, 25);
    assert_eq!(app.world().resource::<SimClock>().steps, 25);
    assert_eq!(
        snapshot::<V>(&app, &beads, &bodies),
        at25,
        "{stem}: step 25 again"
    );
    let timeline = app.world().resource::<Timeline>();
    for (&body, state) in bodies.iter().zip(&at25.0) {
        let recorded = timeline.body(25, body).expect("the body is recorded");
        assert_eq!(V::recorded_body(recorded).as_ref(), Some(state), "{stem}");
    }

    run_steps(&mut app, 15);
    let (again, ..) = snapshot::<V>(&app, &beads, &bodies);
    let off = again
        .iter()
        .zip(&at40)
        .map(|(a, b)| {
            let d = a.position - b.position;
            d.dot(d).sqrt()
        })
        .fold(0.0, f64::max);
    let timeline = app.world().resource::<Timeline>();
    println!(
        "{stem}: run on from step 25, the bodies end {off:.2e} m from the first run's; \
         {} steps the same, departed at {:?}",
        timeline.matched(),
        timeline.departed()
    );
    assert!(off <= within, "{stem}: {off:e} m from the first run");
    if within == 0.0 {
        assert_eq!(
            (timeline.matched(), timeline.departed()),
            (15, None),
            "{stem}"
        );
    } else {
        assert!(
            timeline.departed().is_some(),
            "{stem}: avian's contacts start cold"
        );
    }
}

/// Path joints alone (a cart on a hoop beside a falling ball; a cart on a
/// loop in space; a bead on a hoop on a swinging door, riding it as a body
/// of avian): the same run again, bit for bit, each joint taken back with
/// what it held.
#[test]
fn a_step_back_with_path_joints_runs_on_the_same_bit_for_bit() {
    taken_back::<DVec2>("cart_on_hoop", 0.0);
    taken_back::<DVec3>("cart_on_loop_in_space", 0.0);
    taken_back::<DVec3>("door", 0.0);
}

/// Bodies that touch (beads knocking crates about, dominoes, a train of
/// cars on avian's joints pushing crates): each comes back where it was,
/// and the run from there differs from the first by what avian's contacts
/// and joints, which start cold, change over 15 steps (measured 1.4e-5 m,
/// 4.8e-7 m and 6.7e-4 m).
#[test]
fn a_step_back_puts_touching_bodies_back_where_they_were() {
    taken_back::<DVec2>("beads_and_crates", 1e-4);
    taken_back::<DVec2>("dominoes", 1e-5);
    taken_back::<DVec3>("coaster_train", 2e-3);
}

/// A single step taken while paused (N) is one whole step, avian's
/// included: the door, its hoop and its bead end where a tenth step of a
/// run ends, bit for bit.
#[test]
fn a_single_step_while_paused_steps_avian_too() {
    let (mut app, beads, bodies) = scene("door");
    run_steps(&mut app, 10);
    let ten = snapshot::<DVec3>(&app, &beads, &bodies);

    let (mut app, beads, bodies) = scene("door");
    run_steps(&mut app, 9);
    app.world_mut().resource_mut::<Time<Virtual>>().pause();
    app.world_mut().insert_resource(StepRequests(1));
    run_requested_steps(app.world_mut());
    assert_eq!(app.world().resource::<SimClock>().steps, 10);
    assert_eq!(snapshot::<DVec3>(&app, &beads, &bodies), ten);
}
