//! Ghost copies of the scene: stepped beside the run with another method,
//! a ghost is that method's run of the scene, bit for bit; the drag pulls
//! its beads too; a step back brings it back to the run's time.

use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::ghost::{GhostFocus, GhostPlugin, GhostRequest, GhostSpec, Ghosts};
use wirebead::headless::{Headless, idle, run_steps};
use wirebead::plugin::{TimelinePlugin, TimelineSeek};
use wirebead::prelude::*;
use wirebead::preset::ActivePreset;
use wirebead::{LoadPreset, SceneFile, SpringAnchor};

use crate::presets::{asset_app, shipped_dir, wait_for};

/// The assignment's circle (semi-implicit Euler with Baumgarte) running,
/// with a RATTLE ghost.
fn circle_with_ghost() -> (App, Entity) {
    let mut app = asset_app(&shipped_dir());
    app.add_plugins((GhostPlugin, TimelinePlugin));
    app.world_mut()
        .write_message(LoadPreset("assignment_circle.scene.ron".into()));
    wait_for(&mut app, |a| a.running.is_some());
    let bead = app.world().resource::<ActivePreset>().beads[0];
    app.world_mut().resource_mut::<GhostFocus>().0 = Some(bead);
    let params = app.world().resource::<SimParams>().clone();
    assert_ne!(params.method, Method::Rattle);
    let spec = GhostSpec {
        method: Method::Rattle,
        ..GhostSpec::of(&params)
    };
    app.world_mut().write_message(GhostRequest::Add(spec));
    idle(&mut app);
    (app, bead)
}

/// The same scene alone with RATTLE, `steps` steps, a drag anchor on its
/// bead if one is given: the bead's position.
fn rattle_alone(steps: u32, anchor: Option<DVec2>) -> DVec2 {
    let text = std::fs::read_to_string(shipped_dir().join("assignment_circle.scene.ron")).unwrap();
    let SceneFile::Plane(mut scene) = SceneFile::from_ron(&text).unwrap() else {
        panic!("in the plane");
    };
    scene.params.method = Method::Rattle;
    let plugin = WireBeadPlugin::new(scene.params.clone()).unwrap();
    let mut app = Headless::new(plugin).single_threaded().build();
    let beads = scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    idle(&mut app);
    if let Some(at) = anchor {
        app.world_mut()
            .entity_mut(beads[0])
            .insert(SpringAnchor::new(at).unwrap());
    }
    run_steps(&mut app, steps);
    app.world().get::<BeadPosition>(beads[0]).unwrap().0
}

fn ghost_bead(app: &App) -> DVec2 {
    let ghosts = app.world().resource::<Ghosts>();
    assert_eq!(ghosts.list.len(), 1);
    ghosts.list[0].positions()[0].truncate()
}

#[test]
fn a_rattle_ghost_is_rattles_run_of_the_scene_bit_for_bit() {
    let (mut app, bead) = circle_with_ghost();
    run_steps(&mut app, 120);
    assert_eq!(ghost_bead(&app), rattle_alone(120, None));
    let ghosts = app.world().resource::<Ghosts>();
    let samples = &ghosts.list[0].samples;
    assert_eq!(samples.len(), 120);
    let ghost_drift = samples.iter().map(|s| s.c.abs()).fold(0.0, f64::max);
    let own_drift = app.world().get::<BeadDiagnostics>(bead).unwrap().c.abs();
    eprintln!("drift: RATTLE ghost {ghost_drift:e} m, the run {own_drift:e} m");
    assert!(
        ghost_drift < 1e-12,
        "RATTLE's ghost drifts {ghost_drift:e} m"
    );
    assert!(
        own_drift > 1e-4,
        "Euler with Baumgarte drifts {own_drift:e} m"
    );
}

#[test]
fn the_drag_pulls_the_ghosts_bead_too() {
    let (mut app, bead) = circle_with_ghost();
    let at = DVec2::new(-1.0, 0.5);
    app.world_mut()
        .entity_mut(bead)
        .insert(SpringAnchor::new(at).unwrap());
    run_steps(&mut app, 90);
    assert_eq!(ghost_bead(&app), rattle_alone(90, Some(at)));
    assert_ne!(rattle_alone(90, Some(at)), rattle_alone(90, None));
}

#[test]
fn after_a_step_back_the_ghost_is_at_the_runs_time_again() {
    let (mut app, _) = circle_with_ghost();
    run_steps(&mut app, 120);
    app.world_mut().write_message(TimelineSeek::To(60));
    idle(&mut app);
    let ghosts = app.world().resource::<Ghosts>();
    let clock = app.world().resource::<wirebead::SimClock>();
    assert_eq!(clock.steps, 60);
    assert!((ghosts.list[0].time() - clock.time).abs() < 1e-12);
    assert_eq!(ghost_bead(&app), rattle_alone(60, None));
}
