//! The analysis tool's library on small settings: CSV schema, the assignment's
//! drift claim in the figures' runs, and PNGs that decode and are not blank.

use std::path::PathBuf;

use wirebead::Stabilization;
use wirebead::prelude::*;
use wirebead_analysis::{self as analysis, FIGURE_SIZE, RunConfig};

mod common;
use common::both_csvs;

fn out_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn read_csv(path: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header = reader
        .headers()
        .unwrap()
        .iter()
        .map(str::to_owned)
        .collect();
    let rows = reader
        .records()
        .map(|r| {
            r.unwrap()
                .iter()
                .map(|v| v.parse::<f64>().unwrap())
                .collect()
        })
        .collect();
    (header, rows)
}

#[test]
fn simulate_writes_one_row_per_step_with_the_schema() {
    let dir = out_dir("simulate");
    let mut config: RunConfig = analysis::assignment_setup(1.0);
    config.params.method = Method::Rattle;
    let out = analysis::simulate(&config).unwrap();
    let path = dir.join("run.csv");
    analysis::write_csv(&path, &out.rows).unwrap();
    let (header, rows) = read_csv(&path);
    assert_eq!(header.join(","), "t,x,y,vx,vy,c,c_dot,lambda,energy");
    assert_eq!(rows.len(), 61, "t = 0 and 60 steps");
    assert_eq!(rows[0][0], 0.0);
    assert_eq!(rows[0][1..5], [0.0, -1.0, 4.0, 0.0]);
    assert!((rows[60][0] - 1.0).abs() < 1e-9);
    // RATTLE keeps the bead on the unit circle.
    assert!(rows.iter().all(|r| (r[1].hypot(r[2]) - 1.0).abs() < 1e-12));
}

#[test]
fn simulate_refuses_bad_input_and_reports_divergence() {
    let mut config = analysis::assignment_setup(1.0);
    config.bead.mass = -1.0;
    assert_eq!(
        analysis::simulate(&config).unwrap_err().to_string(),
        "mass must be positive and finite, got -1"
    );
    let mut config = analysis::assignment_setup(10.0);
    config.params.method = Method::ExplicitEuler(Stabilization::Baumgarte);
    config.params.timestep = 0.05;
    let out = analysis::simulate(&config).unwrap();
    let (t, why) = out.diverged.expect("explicit Euler at 0.05 s blows up");
    assert!(why.contains("drifted"), "{why}");
    assert!(
        (out.rows.last().unwrap().t - t).abs() <= 0.05 + 1e-9,
        "rows stop at the divergence"
    );
    assert!(out.rows.iter().all(|r| r.position.is_finite()));
}

#[test]
fn figures_reproduce_the_assignment_studies() {
    let dir = out_dir("figures");
    analysis::figures(&dir, 3.0).unwrap();
    // α = 0 drifts more than the large α.
    let max_drift = |stem: &str| {
        let (_, rows) = read_csv(&dir.join(format!("{stem}.csv")));
        rows.iter().map(|r| r[5].abs()).fold(0.0, f64::max)
    };
    let (none, large) = (max_drift("alpha_0"), max_drift("alpha_1000"));
    assert!(
        none > 10.0 * large,
        "max |C|: α = 0 {none:e}, α = 1000 {large:e}"
    );
    for study in ["alpha", "beta", "timestep"] {
        for (kind, size) in [
            ("trajectory", FIGURE_SIZE),
            ("drift", (FIGURE_SIZE.0, FIGURE_SIZE.1 / 2)),
            ("energy", (FIGURE_SIZE.0, FIGURE_SIZE.1 / 2)),
        ] {
            let path = dir.join(format!("{study}_{kind}.png"));
            let image = image::open(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .to_rgb8();
            assert_eq!(image.dimensions(), size, "{}", path.display());
            let coloured = image
                .pixels()
                .filter(|p| p.0.iter().any(|&c| c < 200))
                .count();
            let fraction = coloured as f64 / (size.0 * size.1) as f64;
            assert!(
                fraction > 0.01 && fraction < 0.6,
                "{}: {:.1}% drawn",
                path.display(),
                100.0 * fraction
            );
        }
    }
    let summary = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    assert_eq!(
        summary
            .lines()
            .filter(|l| l.starts_with("| alpha")
                || l.starts_with("| beta")
                || l.starts_with("| timestep"))
            .count(),
        9
    );
}

#[test]
fn compare_ranks_rattle_above_euler() {
    let table = analysis::compare(1.0, 9.81, 90.0, 6.0, &[1.0 / 60.0]).unwrap();
    assert_eq!(table.len(), Method::ALL.len());
    let find = |m| table.iter().find(|r| r.method == m).unwrap();
    let rattle = find(Method::Rattle);
    let assignment = find(Method::SemiImplicitEuler(Stabilization::Baumgarte));
    assert!(rattle.max_drift < 1e-12);
    assert!(rattle.period_error.unwrap().abs() < 1e-3);
    assert!(rattle.energy_error * 100.0 < assignment.energy_error);
}

/// The shipped scene file `name`.
fn shipped(name: &str) -> wirebead::ScenePreset {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/scenes")
        .join(name);
    analysis::load_scene(&path).unwrap()
}

#[test]
fn simulate_scene_writes_a_column_set_per_named_bead() {
    let dir = out_dir("simulate_scene");
    let preset = shipped("pendulum_on_cart.scene.ron");
    let run = analysis::simulate_scene(&preset, preset.params.clone(), 1.0).unwrap();
    let path = dir.join("cart.csv");
    analysis::write_scene_csv(&path, &run).unwrap();
    let (header, rows) = read_csv(&path);
    assert_eq!(
        header.join(","),
        "t,cart.x,cart.y,cart.vx,cart.vy,cart.on,bob.x,bob.y,bob.vx,bob.vy,bob.on,energy,max_abs_c"
    );
    assert_eq!(rows.len(), 61, "t = 0 and 60 steps");
    assert_eq!(rows[0][6..8], [0.75f64.sqrt(), -0.5]);
    for row in &rows {
        // RATTLE: the rod and the rail to rounding; no horizontal momentum.
        assert!(row[12] <= 1e-12, "max |C| = {:e}", row[12]);
        assert!((2.0 * row[3] + row[8]).abs() < 1e-12);
        assert!((row[11] - rows[0][11]).abs() < 1e-2, "energy {}", row[11]);
        // The cart is on its rail; the bob is on no wire.
        assert_eq!((row[5], row[10]), (1.0, 0.0));
    }
}

#[test]
fn simulate_scene_names_unnamed_beads_and_stops_at_a_divergence() {
    // Two unnamed free beads at one point, joined by a rod: singular.
    let preset = wirebead::ScenePreset::from_ron(
        "(name: \"bad\", beads: [(), ()], constraints: [Rod((a: \"bead0\", b: \"bead1\", length: 1.0))])",
    )
    .unwrap();
    let run = analysis::simulate_scene(&preset, preset.params.clone(), 1.0).unwrap();
    assert_eq!(run.names, ["bead0", "bead1"]);
    let (t, why) = run
        .diverged
        .expect("a rod between coincident beads is singular");
    assert!(why.contains("singular point"), "{why}");
    assert!(t <= 1.0 / 60.0 + 1e-12);
    assert_eq!(run.rows.len(), 1, "only the t = 0 row precedes it");
}

#[test]
fn compare_scene_holds_rattle_to_rounding_on_the_double_pendulum() {
    let preset = shipped("double_pendulum.scene.ron");
    let table = analysis::compare_scene(&preset, 2.0, &[1.0 / 120.0]).unwrap();
    assert_eq!(table.len(), Method::ALL.len());
    let find = |m| table.iter().find(|r| r.method == m).unwrap();
    let rattle = find(Method::Rattle);
    assert!(rattle.max_abs_c < 1e-12, "{:e}", rattle.max_abs_c);
    let none = find(Method::SemiImplicitEuler(Stabilization::None));
    assert!(none.diverged.is_some() || none.max_abs_c > 1e3 * rattle.max_abs_c);
    let md = analysis::scene_comparison_markdown(&table, &preset, 2.0);
    assert_eq!(md.lines().filter(|l| l.starts_with("| ")).count(), 11);
}

#[test]
fn simulate_scene_starts_from_velocities_that_meet_the_constraints() {
    // A slider-crank whose crank turns while its piston was left at rest:
    // row 0 is the projected state the first step starts from, so the
    // energy of row 1 is row 0's to the step's own error.
    let preset = wirebead::ScenePreset::from_ron(
        r#"(
            name: "Slider-crank",
            params: (integrator: Rattle, timestep: 0.001),
            wires: [
                (shape: Circle((radius: 0.5)), beads: [(name: "crank", mass: 1.0,
                    initial_position: (0.0, 0.5), initial_velocity: (-2.0, 0.0))]),
                (shape: Line(()), beads: [(name: "piston", mass: 2.0,
                    initial_position: (1.4142135623730951, 0.0))]),
            ],
            constraints: [Rod((a: "crank", b: "piston", length: 1.5))],
        )"#,
    )
    .unwrap();
    let run = analysis::simulate_scene(&preset, preset.params.clone(), 0.01).unwrap();
    let (row0, row1) = (&run.rows[0], &run.rows[1]);
    assert!(
        row0.velocities[1].x.abs() > 0.5,
        "the piston starts at rest"
    );
    let given = 0.5 * 1.0 * 4.0 + 1.0 * 9.81 * 0.5;
    assert!(
        row0.energy < given - 0.1,
        "{} J given, {} J in row 0",
        given,
        row0.energy
    );
    assert!(
        (row1.energy - row0.energy).abs() < 1e-6,
        "row 0 {} J, row 1 {} J",
        row0.energy,
        row1.energy
    );
}

/// A scene file in space, `SceneFile` dispatching on its dimension.
fn shipped_in_space(name: &str) -> wirebead::SpaceScene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/scenes")
        .join(name);
    match analysis::load_scene_file(&path).unwrap() {
        wirebead::SceneFile::Space(scene) => scene,
        wirebead::SceneFile::Plane(_) => panic!("{name} is a scene in the plane"),
    }
}

/// `simulate --scene` on a scene in space: `t`, then seven columns a bead
/// (`x,y,z,vx,vy,vz,on`), then `energy,max_abs_c`, a row per step from
/// t = 0; the rotating hoop's bead is held on its hoop to 1e-12.
#[test]
fn simulate_scene_in_space_writes_three_components_a_vector() {
    let dir = out_dir("simulate_scene_in_space");
    let scene = shipped_in_space("rotating_hoop.scene.ron");
    let run = analysis::simulate_scene(&scene, scene.params.0.clone(), 0.5).unwrap();
    let path = dir.join("hoop.csv");
    analysis::write_scene_csv(&path, &run).unwrap();
    let (header, rows) = read_csv(&path);
    assert_eq!(
        header.join(","),
        "t,b.x,b.y,b.z,b.vx,b.vy,b.vz,b.on,energy,max_abs_c"
    );
    assert_eq!(rows.len(), 501, "t = 0 and 500 steps");
    assert_eq!(rows[0][1..4], [0.5, -0.8660254037844386, 0.0]);
    // At relative rest on a hoop turning at 6 rad/s about y: (0, 0, −3).
    assert!((rows[0][6] + 3.0).abs() < 1e-12, "vz = {}", rows[0][6]);
    for row in &rows {
        assert!(row[9] <= 1e-12, "max |C| = {:e}", row[9]);
        assert_eq!(row[7], 1.0);
    }
}

/// The same circle scene run in the plane and in space (the circle in the
/// xy-plane, gravity along −y): the trajectories agree to 1e-10 over 3 s
/// and `z` and its velocity stay exactly 0. (The wire sits where `f32`,
/// the `Transform`'s precision, puts it exactly, so the bead starts on it
/// in both.)
#[test]
fn a_planar_scene_run_in_space_gives_the_planes_trajectory() {
    let plane = wirebead::ScenePreset::from_ron(
        r#"(name: "circle", params: (integrator: Rattle, timestep: 0.001),
            wires: [(shape: Circle((radius: 0.8)), position: (0.25, -0.5),
                beads: [(initial_position: (1.05, -0.5), initial_velocity: (0.0, 1.5))])])"#,
    )
    .unwrap();
    let space = match wirebead::SceneFile::from_ron(
        r#"(name: "circle", dimension: 3,
            params: (integrator: Rattle, timestep: 0.001, gravity: (0.0, -9.81, 0.0)),
            wires: [(shape: Circle((radius: 0.8)), position: (0.25, -0.5, 0.0),
                beads: [(initial_position: (1.05, -0.5, 0.0), initial_velocity: (0.0, 1.5, 0.0))])])"#,
    )
    .unwrap()
    {
        wirebead::SceneFile::Space(scene) => scene,
        wirebead::SceneFile::Plane(_) => panic!("read in the plane"),
    };
    let flat = analysis::simulate_scene(&plane, plane.params.clone(), 3.0).unwrap();
    let round = analysis::simulate_scene(&space, space.params.0.clone(), 3.0).unwrap();
    assert_eq!(flat.rows.len(), round.rows.len());
    let mut worst = 0.0f64;
    for (a, b) in flat.rows.iter().zip(&round.rows) {
        let (p, v) = (b.positions[0], b.velocities[0]);
        assert_eq!((p.z, v.z), (0.0, 0.0));
        worst = worst
            .max((p.truncate() - a.positions[0]).length())
            .max((v.truncate() - a.velocities[0]).length());
    }
    assert!(worst <= 1e-10, "{worst:e} apart");
}

/// The rotating hoop's bifurcation (r = 1 m, damping 1 N·s/m, RATTLE at
/// 2 ms, 15 s a spin): below `√(g/r)` = 3.13 rad/s the bead settles at the
/// bottom, above it at `acos(g/(ω² r))`, each within 1e-4 rad; the CSV and
/// the plot are written.
#[test]
fn bifurcation_settles_where_the_theory_says() {
    let dir = out_dir("bifurcation");
    let sweep = analysis::HoopSweep {
        omegas: vec![2.0, 5.0, 7.0],
        duration: 15.0,
        ..analysis::HoopSweep::default()
    };
    let points = sweep.run().unwrap();
    for p in &points {
        let expected = analysis::hoop_equilibrium(p.omega, 9.81, 1.0);
        assert!(
            (p.settled - expected).abs() <= 1e-4,
            "at {} rad/s it settled at {} rad, against {expected}",
            p.omega,
            p.settled
        );
    }
    assert!(points[0].theory == 0.0 && points[1].theory > 1.0);
    let written = analysis::bifurcation(
        &dir,
        &analysis::HoopSweep {
            omegas: vec![2.0, 5.0],
            duration: 2.0,
            ..analysis::HoopSweep::default()
        },
    )
    .unwrap();
    let (header, rows) = read_csv(&written[0]);
    assert_eq!(header.join(","), "omega,settled_deg,theory_deg,swing_deg");
    assert_eq!(rows.len(), 2);
    let png = image::open(&written[1]).unwrap();
    assert!(png.width() > 800);
}

/// Every scene in space that ships (`assets/scenes`, `dimension: 3`) runs
/// 1 s through the plugin with RATTLE holding each bead on its wire, rod or
/// pin to 1e-12 and, where nothing does work on the beads or takes it (no
/// wire driven or sending beads back, no beads that meet below `e = 1`),
/// the energy to 1e-3 of its start.
#[test]
fn every_shipped_scene_in_space_runs() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes");
    let mut seen = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let Ok(wirebead::SceneFile::Space(scene)) = analysis::load_scene_file(&path) else {
            continue;
        };
        let run = analysis::simulate_scene(&scene, scene.params.0.clone(), 1.0).unwrap();
        assert!(run.diverged.is_none(), "{}: {:?}", scene.name, run.diverged);
        let e0 = run.rows[0].energy;
        let driven = scene.wires.iter().any(|w| {
            w.motion != wirebead::preset::SpaceMotionPreset::Fixed || w.sends_back.is_some()
        });
        let meet = scene.all_beads().any(|b| b.radius > 0.0) && scene.contacts.restitution < 1.0;
        let driven = driven || meet;
        for row in &run.rows {
            assert!(
                row.max_abs_c <= 1e-12,
                "{}: |C| = {:e}",
                scene.name,
                row.max_abs_c
            );
            assert!(
                driven || (row.energy - e0).abs() <= 1e-3 * e0.abs().max(1.0),
                "{}: energy {} from {e0}",
                scene.name,
                row.energy
            );
        }
        seen.push(scene.name);
    }
    assert!(seen.len() >= 6, "only {seen:?}");
}

/// Newton's cradle through `simulate --scene`: one ball out, the other
/// four still, in the CSV's own columns.
#[test]
fn simulate_scene_runs_newtons_cradle_and_one_ball_comes_out() {
    let dir = out_dir("simulate_cradle");
    let preset = shipped("newtons_cradle.scene.ron");
    let run = analysis::simulate_scene(&preset, preset.params.clone(), 0.8).unwrap();
    assert!(run.diverged.is_none(), "{:?}", run.diverged);
    let path = dir.join("cradle.csv");
    analysis::write_scene_csv(&path, &run).unwrap();
    let (header, rows) = read_csv(&path);
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let last = rows.last().unwrap();
    // The strike comes about half a second in; by 0.8 s the last ball
    // swings out and the rest hang still.
    assert!(
        last[column("ball 5.vx")] > 0.5,
        "{}",
        last[column("ball 5.vx")]
    );
    for ball in 1..=4 {
        let (vx, vy) = (
            last[column(&format!("ball {ball}.vx"))],
            last[column(&format!("ball {ball}.vy"))],
        );
        assert!(vx.hypot(vy) < 1e-9, "ball {ball} moves at ({vx}, {vy})");
    }
}

/// A ball wedged between two pinned ones at restitution 1 would strike
/// forever within one instant: the run stops there and says why in one
/// line (the tool exits 3 with the rows up to it).
#[test]
fn simulate_scene_stops_where_strikes_never_settle() {
    let preset = wirebead::ScenePreset::from_ron(
        r#"(name: "wedged",
            beads: [
                (name: "left", radius: 0.1, initial_position: (0.0, 0.0)),
                (name: "ball", radius: 0.1, initial_position: (0.2, 0.0), initial_velocity: (1.0, 0.0)),
                (name: "right", radius: 0.1, initial_position: (0.4, 0.0)),
            ],
            constraints: [Pin((bead: "left", at: (0.0, 0.0))), Pin((bead: "right", at: (0.4, 0.0)))])"#,
    )
    .unwrap();
    let run = analysis::simulate_scene(&preset, preset.params.clone(), 1.0).unwrap();
    let (t, why) = run.diverged.expect("the strikes never settle");
    assert_eq!(
        why,
        "its strikes did not settle: the impacts did not settle after 512 strikes between touching beads"
    );
    assert!(t <= 1.0 / 60.0 + 1e-12);
    assert_eq!(run.rows.len(), 1, "only the t = 0 row precedes it");
    assert!(!why.contains('\n'));
}

#[test]
fn the_recorded_run_exports_the_rows_simulate_writes() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes");
    for name in [
        "rope",
        "newtons_cradle",
        "marble_run",
        "rotating_hoop",
        "rope_in_space",
    ] {
        let file = analysis::load_scene_file(&dir.join(format!("{name}.scene.ron"))).unwrap();
        let (simulated, exported) = match &file {
            wirebead::SceneFile::Plane(scene) => both_csvs(scene, &file, 120),
            wirebead::SceneFile::Space(scene) => both_csvs(scene, &file, 120),
        };
        assert_eq!(
            simulated.lines().count(),
            122,
            "{name}: the header and 121 rows"
        );
        assert_eq!(exported, simulated, "{name}");
    }
}
