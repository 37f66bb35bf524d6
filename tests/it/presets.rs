//! Scene presets: the shipped files are valid, a preset loads as an asset and
//! replaces the scene, and a malformed file leaves the running scene as it was.

use std::path::PathBuf;
use std::time::Duration;

use bevy::prelude::*;
use wirebead::SceneLink;
use wirebead::headless::{Headless, idle, run_steps};
use wirebead::prelude::*;
use wirebead::preset::{ActivePreset, FromPreset};
use wirebead::{ConstraintDiagnostics, LoadPreset, SceneEnergy, ScenePreset};

use crate::common::{BeadNow, bead};

pub(crate) const SHIPPED: &[&str] = &[
    "assignment_circle.scene.ron",
    "pendulum.scene.ron",
    "ellipse.scene.ron",
    "sine_track.scene.ron",
    "multi_bead.scene.ron",
    "resting.scene.ron",
    "pendulum_on_cart.scene.ron",
    "double_pendulum.scene.ron",
    "rope.scene.ron",
    "ring.scene.ron",
    "spring_pair.scene.ron",
    "kapitza.scene.ron",
    "spinning_rod.scene.ron",
    "tautochrone.scene.ron",
    "roller_coaster.scene.ron",
    "newtons_cradle.scene.ron",
    "air_track.scene.ron",
    "air_track_sticky.scene.ron",
    "abacus.scene.ron",
    "train.scene.ron",
    "marble_run.scene.ron",
];

/// The shipped presets that join beads.
const COUPLED: &[&str] = &[
    "pendulum_on_cart.scene.ron",
    "double_pendulum.scene.ron",
    "rope.scene.ron",
    "ring.scene.ron",
    "spring_pair.scene.ron",
    "newtons_cradle.scene.ron",
    "abacus.scene.ron",
];

/// The shipped presets, found at run time: a test binary reused from another
/// checkout must read this checkout's files.
pub(crate) fn shipped_dir() -> PathBuf {
    std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .unwrap_or_default()
        .join("assets/scenes")
}

/// Asserts that the shipped scene file `name` is the scene `made`: read
/// back, it writes the same scene file, to the digit.
pub(crate) fn assert_shipped_is(name: &str, made: wirebead::SceneFile) {
    let text =
        std::fs::read_to_string(shipped_dir().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let shipped = wirebead::SceneFile::from_ron(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
    let written = |scene| wirebead::preset::scene_ron(&scene).expect("written");
    assert_eq!(written(shipped), written(made), "{name}");
}

#[test]
fn shipped_presets_are_valid_and_put_beads_on_their_wires() {
    let dir = shipped_dir();
    let mut beads = 0;
    for name in SHIPPED {
        let text = std::fs::read_to_string(dir.join(name)).unwrap();
        let preset = ScenePreset::from_ron(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        for wire in &preset.wires {
            let pose =
                wirebead::geometry::Pose::new(wire.position, wire.angle_degrees.to_radians());
            let placed = wirebead::geometry::Placed {
                curve: wire.shape.curve(),
                pose,
            };
            for bead in &wire.beads {
                use wirebead::ImplicitCurve;
                let c = placed.value(bead.initial_position);
                assert!(c.abs() < 1e-9, "{name}: a bead starts {c:e} off its wire");
                beads += 1;
            }
        }
        let at: Vec<_> = preset.all_beads().map(|b| b.initial_position).collect();
        for link in preset.links().unwrap() {
            let c = match link {
                SceneLink::Rod { a, b, length } => (at[a] - at[b]).length() - length,
                SceneLink::Pin { bead, at: p } => (at[bead] - p).length(),
                SceneLink::Spring { .. } => 0.0,
            };
            assert!(c.abs() < 1e-9, "{name}: {link:?} starts {c:e} off");
        }
    }
    assert!(beads >= 7);
}

#[test]
fn coupled_presets_run_ten_seconds_on_their_constraints() {
    for name in COUPLED {
        let text = std::fs::read_to_string(shipped_dir().join(name)).unwrap();
        let preset = ScenePreset::from_ron(&text).unwrap();
        let plugin = WireBeadPlugin::new(preset.params.clone()).unwrap();
        let mut app = Headless::new(plugin).single_threaded().build();
        app.init_resource::<SceneEnergy>();
        preset.spawn(&mut app.world_mut().commands());
        app.world_mut().flush();
        run_steps(&mut app, 1);
        let energy = |app: &App| app.world().resource::<SceneEnergy>().total;
        let e0 = energy(&app);
        let mut worst = 0.0f64;
        let mut drift = 0.0f64;
        for _ in 0..599 {
            run_steps(&mut app, 1);
            let world = app.world_mut();
            let mut links = world.query::<(&ConstraintDiagnostics, Option<&Rod>)>();
            for (d, rod) in links.iter(world) {
                worst = worst.max(d.c.abs() / rod.map_or(1.0, Rod::length));
            }
            let mut wires = world.query_filtered::<&BeadDiagnostics, With<OnWire>>();
            for d in wires.iter(world) {
                worst = worst.max(d.c.abs());
            }
            let mut diverged = world.query::<&Diverged>();
            assert!(
                diverged.iter(world).next().is_none(),
                "{name}: a bead diverged"
            );
            drift = drift.max((energy(&app) - e0).abs());
        }
        assert!(worst <= 1e-9, "{name}: |C| reached {worst:e}");
        // RATTLE's energy error stays bounded: under 2 % of the weight of
        // the scene times its size (2 m). The spring pair's spring is
        // damped, so its energy falls.
        let weight: f64 = preset.all_beads().map(|b| b.mass * 9.81).sum();
        if !name.starts_with("spring") {
            assert!(
                drift <= 0.02 * weight * 2.0,
                "{name}: energy moved {drift} J"
            );
        }
    }
}

/// A headless app with assets read from `dir`.
pub(crate) fn asset_app(dir: &std::path::Path) -> App {
    let mut app = Headless::new(WireBeadPlugin::default()).assets(dir).build();
    idle(&mut app);
    app
}

/// Updates (with no fixed step) until `done` or 10 s pass.
pub(crate) fn wait_for(app: &mut App, done: impl Fn(&ActivePreset) -> bool) {
    for _ in 0..1000 {
        idle(app);
        if done(app.world().resource::<ActivePreset>()) {
            return;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    panic!("timed out: {:?}", app.world().resource::<ActivePreset>());
}

fn beads(app: &mut App) -> Vec<(Entity, BeadNow)> {
    let mut query = app
        .world_mut()
        .query_filtered::<Entity, (With<Bead>, With<FromPreset>)>();
    let entities: Vec<Entity> = query.iter(app.world()).collect();
    let mut beads: Vec<(Entity, BeadNow)> =
        entities.into_iter().map(|e| (e, bead(app, e))).collect();
    beads.sort_by_key(|(e, _)| *e);
    beads
}

#[test]
fn malformed_preset_reports_its_error_and_the_scene_runs_on() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("presets_malformed");
    std::fs::create_dir_all(&dir).unwrap();
    let shipped = shipped_dir().join("multi_bead.scene.ron");
    std::fs::copy(shipped, dir.join("good.scene.ron")).unwrap();
    std::fs::write(
        dir.join("bad.scene.ron"),
        "(name: \"bad\", wires: [ (shape: Circle((radius: -1.0)), beads: [()]) ])",
    )
    .unwrap();
    std::fs::write(dir.join("broken.scene.ron"), "(name: \"broken\", wires: [").unwrap();
    std::fs::write(
        dir.join("badlink.scene.ron"),
        "(name: \"badlink\", beads: [(name: \"a\")], constraints: [Rod((a: \"a\", b: \"zz\", length: 1.0))])",
    )
    .unwrap();

    let mut app = asset_app(&dir);
    app.world_mut()
        .write_message(LoadPreset("good.scene.ron".into()));
    wait_for(&mut app, |a| a.running.is_some());
    assert_eq!(
        app.world().resource::<ActivePreset>().running.as_deref(),
        Some("Many beads")
    );
    assert_eq!(app.world().resource::<SimParams>().method, Method::Rattle);
    run_steps(&mut app, 30);
    let before = beads(&mut app);
    assert_eq!(before.len(), 4);
    let params = app.world().resource::<SimParams>().clone();

    for (file, expected) in [
        (
            "bad.scene.ron",
            "wire 0: radius must be positive and finite, got -1",
        ),
        (
            "broken.scene.ron",
            "malformed scene file at line 1, column ",
        ),
        (
            "badlink.scene.ron",
            "constraint 0 (rod): no bead is named \"zz\"",
        ),
    ] {
        app.world_mut().write_message(LoadPreset(file.into()));
        wait_for(&mut app, |a| a.error.is_some());
        let error = app
            .world()
            .resource::<ActivePreset>()
            .error
            .clone()
            .unwrap();
        assert!(error.contains(file) && error.contains(expected), "{error}");
        // The scene is the one that was running, untouched.
        assert_eq!(beads(&mut app), before);
        assert_eq!(app.world().resource::<SimParams>(), &params);
        assert_eq!(
            app.world().resource::<ActivePreset>().running.as_deref(),
            Some("Many beads")
        );
        app.world_mut().resource_mut::<ActivePreset>().error = None;
    }
    // And it still steps.
    run_steps(&mut app, 10);
    let after = beads(&mut app);
    assert_eq!(after.len(), 4);
    assert_ne!(after, before);
}

#[test]
fn the_run_exports_as_csv_and_the_scene_saves_with_its_edits() {
    use wirebead::controls::ExportRequests;
    use wirebead::plugin::TimelinePlugin;
    use wirebead::preset::{ExportDir, ExportPlugin, LastExport};
    use wirebead::{NextBeadParams, NextParams, NextWireShape, SceneFile, Wire, WireShape};

    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("presets_export");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(
        shipped_dir().join("pendulum_on_cart.scene.ron"),
        dir.join("cart.scene.ron"),
    )
    .unwrap();
    let mut app = asset_app(&dir);
    app.add_plugins((TimelinePlugin, ExportPlugin))
        .insert_resource(ExportDir(dir.join("out")));
    app.world_mut()
        .write_message(LoadPreset("cart.scene.ron".into()));
    wait_for(&mut app, |a| a.running.is_some());
    run_steps(&mut app, 30);

    // Edits, pending: the bob heavier, a smaller step, the rail a circle.
    let order = app.world().resource::<ActivePreset>().beads.clone();
    assert_eq!(order.len(), 2, "the cart, then the bob");
    let mut bob = *app.world().get::<BeadParams>(order[1]).unwrap();
    bob.mass = 3.5;
    let edit = NextBeadParams::new(bob).unwrap();
    app.world_mut().entity_mut(order[1]).insert(edit);
    let rail = app.world().get::<OnWire>(order[0]).unwrap().0;
    let circle = Wire::circle(2.5).unwrap();
    app.world_mut()
        .entity_mut(rail)
        .insert(NextWireShape::new(circle.shape().clone()).unwrap());
    app.world_mut()
        .resource_mut::<NextParams>()
        .update(|p| p.timestep = 1.0 / 240.0)
        .unwrap();

    let mut requests = app.world_mut().resource_mut::<ExportRequests>();
    requests.csv += 1;
    requests.scene += 1;
    idle(&mut app);
    let last = app.world().resource::<LastExport>().0.clone();
    let message = last.expect("an export").expect("written");
    assert!(!message.contains('\n'), "{message}");
    assert!(message.contains("cart.csv (31 rows)"), "{message}");

    let csv = std::fs::read_to_string(dir.join("out/cart.csv")).unwrap();
    assert_eq!(csv.lines().count(), 32, "the header and t = 0 to step 30");
    assert!(csv.starts_with("t,cart.x,cart.y,cart.vx,cart.vy,cart.on,bob.x"));

    let text = std::fs::read_to_string(dir.join("out/cart.scene.ron")).unwrap();
    let SceneFile::Plane(saved) = SceneFile::from_ron(&text).expect("the saved scene loads") else {
        panic!("a scene in the plane");
    };
    assert_eq!(saved.params.timestep, 1.0 / 240.0);
    assert_eq!(saved.all_beads().nth(1).unwrap().mass, 3.5);
    assert_eq!(
        saved.all_beads().next().unwrap().mass,
        2.0,
        "the cart as it was"
    );
    assert!(matches!(&saved.wires[0].shape, WireShape::Circle(c) if c.radius == 2.5));
    assert_eq!(saved.constraints.len(), 1, "the rod kept");
}
