//! `simulate --scene` on scene files with rigid bodies: their columns
//! after the beads', the energy with theirs, and a build without avian
//! refusing them in words.

use std::path::PathBuf;

use wirebead_analysis as analysis;

#[cfg(all(feature = "avian2d", feature = "avian3d"))]
mod common;

/// The scene format's own scene: a box of 2 kg on a unit hoop, released
/// level with the hoop's centre, at 1 ms.
const CART: &str = include_str!("../../tests/scenes/cart_on_hoop.scene.ron");

/// `text` written to a scene file of its own, read as the tool reads one.
fn scene_file(name: &str, text: &str) -> wirebead::SceneFile {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bodies");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.scene.ron"));
    std::fs::write(&path, text).unwrap();
    analysis::load_scene_file(&path).unwrap()
}

/// A run's CSV: its header and rows.
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
fn csv_of<V: wirebead::preset::table::SceneSpace>(
    run: &wirebead::preset::table::SceneRun<V>,
) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut text = Vec::new();
    wirebead::preset::table::write_scene_csv(&mut text, run).unwrap();
    let mut reader = csv::Reader::from_reader(text.as_slice());
    let header = reader
        .headers()
        .unwrap()
        .iter()
        .map(str::to_owned)
        .collect();
    let rows = reader
        .records()
        .map(|r| r.unwrap().iter().map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// A build of the tool without avian refuses a scene with bodies, naming
/// the feature that runs them.
#[cfg(not(feature = "avian2d"))]
#[test]
fn a_scene_with_bodies_is_refused_by_a_build_without_avian() {
    let wirebead::SceneFile::Plane(scene) = scene_file("cart", CART) else {
        panic!("a scene in the plane");
    };
    let said = analysis::simulate_scene(&scene, scene.params.clone(), 0.1)
        .unwrap_err()
        .to_string();
    assert_eq!(
        said,
        "scene \"A cart on a hoop\" has rigid bodies, which this build of the tool cannot run: build it with --features avian2d"
    );
}

/// The box's columns follow the beads' (there are none), in the format's
/// order; it stays on its hoop (1e-5 m, as `max_abs_c` says of its
/// joint) and never turns (1e-5 rad), and
/// the energy, the body's kinetic and gravitational, stays within 1e-2 J
/// (5e-4 of `m g r`) of its start over 2 s: avian's substeps turn the
/// joint's corrections into velocity to first order in the substep.
#[cfg(feature = "avian2d")]
#[test]
fn a_scene_with_a_body_writes_its_columns_and_its_energy() {
    let wirebead::SceneFile::Plane(scene) = scene_file("cart", CART) else {
        panic!("a scene in the plane");
    };
    let run = analysis::simulate_scene(&scene, scene.params.clone(), 2.0).unwrap();
    let (header, rows) = csv_of(&run);
    assert_eq!(
        header.join(","),
        "t,cart.x,cart.y,cart.angle,cart.vx,cart.vy,cart.w,energy,max_abs_c"
    );
    assert_eq!(rows.len(), 2001, "t = 0 and 2,000 steps");
    assert_eq!(rows[0][1..7], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    // At rest level with the hoop's centre: no energy to begin with.
    assert!(rows[0][7].abs() < 1e-12, "{}", rows[0][7]);
    let (mut off, mut turned, mut energy) = (0.0f64, 0.0f64, 0.0f64);
    for row in &rows {
        off = off.max((row[1].hypot(row[2]) - 1.0).abs());
        turned = turned.max(row[3].abs());
        energy = energy.max(row[7].abs());
        // The joint's anchor measured on its wire, as the column says.
        assert!((row[8] - (row[1].hypot(row[2]) - 1.0).abs()).abs() < 1e-12);
    }
    println!("off the hoop {off:.2e} m, turned {turned:.2e} rad, energy within {energy:.2e} J");
    assert!(off <= 1e-5, "{off:e} m off the hoop");
    assert!(turned <= 1e-5, "turned {turned:e} rad");
    assert!(energy <= 1e-2, "the energy moved {energy:e} J");
    // It swings: down through the bottom within the first second.
    assert!(
        rows.iter().any(|r| r[2] < -0.999),
        "never reached the bottom"
    );
}

/// In space: a box on a hoop that rides a static door turned 90° about y
/// (the hoop 0.3 m in front of it), released at the hoop's side: the
/// box's columns with its quaternion and its spin; it swings in the
/// hoop's plane (x stays 2.3 to 1e-5 m), `Fixed` never turns, and its
/// energy stays within 5e-3 J (1e-3 of `m g r`) over 1 s.
#[cfg(feature = "avian3d")]
#[test]
fn a_scene_in_space_with_a_body_writes_its_quaternion_and_spin() {
    let text = r#"(
        name: "A box on a hoop on a door",
        dimension: 3,
        params: (integrator: Rattle, timestep: 0.001, gravity: (0.0, -9.81, 0.0)),
        bodies: [
            (name: "door", kind: Static, shape: Box((half_extents: (0.5, 1.0, 0.05))),
             position: (2.0, 0.0, 0.0), rotation: (axis: (0.0, 1.0, 0.0), angle_degrees: 90.0)),
            (name: "box", shape: Box((half_extents: (0.1, 0.1, 0.1))), mass: 1.0,
             position: (2.3, 0.0, 0.5)),
        ],
        wires: [(name: "hoop", body: "door", position: (0.0, 0.0, 0.3), shape: Circle((radius: 0.5)))],
        constraints: [Path((body: "box", wire: "hoop", rotation: Fixed))],
    )"#;
    let wirebead::SceneFile::Space(scene) = scene_file("door", text) else {
        panic!("a scene in space");
    };
    let run = analysis::simulate_scene(&scene, scene.params.0.clone(), 1.0).unwrap();
    let (header, rows) = csv_of(&run);
    assert_eq!(
        header.join(","),
        "t,box.x,box.y,box.z,box.qx,box.qy,box.qz,box.qw,box.vx,box.vy,box.vz,box.wx,box.wy,box.wz,energy,max_abs_c"
    );
    let (mut across, mut turned, mut energy) = (0.0f64, 0.0f64, 0.0f64);
    for row in &rows {
        across = across.max((row[1] - 2.3).abs());
        turned = turned.max((row[7].abs() - 1.0).abs());
        energy = energy.max((row[14] - rows[0][14]).abs());
        assert!(
            row[15] <= 1e-5,
            "the joint's anchor is {} m off the hoop",
            row[15]
        );
    }
    println!("across the door {across:.2e} m, turned {turned:.2e}, energy within {energy:.2e} J");
    assert!(across <= 1e-5, "left the door's plane by {across:e} m");
    assert!(turned <= 1e-5, "turned: qw off one by {turned:e}");
    assert!(energy <= 5e-3, "the energy moved {energy:e} J");
    assert!(
        rows.iter().any(|r| r[2] < -0.49),
        "never reached the bottom"
    );
}

/// A bead of a scene on a hoop that rides a free body (no gravity, 60 Hz):
/// the bead rides the hoop and pushes its hub, and the CSV's columns turn
/// the pair as the two-body answer says, to 1e-4 m over 5 s; their
/// momentum stays to 1e-5 of itself, the hub never spins (1e-5 rad/s),
/// and `max_abs_c` measures the bead against the hoop where the hub has
/// it (1e-5 m). Neither sleeps: the hub slows to 0.012 m/s near 4.2 s,
/// where avian would put it to sleep alone and lose the pair's momentum.
#[cfg(feature = "avian2d")]
#[test]
fn a_scene_beads_on_a_hoop_on_a_free_body_turn_the_pair_as_two_bodies_do() {
    use bevy::math::DVec3;
    let text = r#"(
        name: "A bead on a hoop on a free hub",
        params: (integrator: Rattle, timestep: 0.016666666666666666, gravity: (0.0, 0.0)),
        bodies: [(name: "hub", shape: Ball((radius: 0.1)), mass: 3.0, inertia: 0.5, position: (0.0, 0.0))],
        wires: [(name: "hoop", body: "hub", shape: Circle((radius: 1.0)), beads: [
            (name: "b", mass: 1.0, initial_position: (1.0, 0.0), initial_velocity: (0.0, 1.5)),
        ])],
    )"#;
    let wirebead::SceneFile::Plane(scene) = scene_file("hub", text) else {
        panic!("a scene in the plane");
    };
    let run = analysis::simulate_scene(&scene, scene.params.clone(), 5.0).unwrap();
    assert!(run.diverged.is_none(), "{:?}", run.diverged);
    let (header, rows) = csv_of(&run);
    assert_eq!(
        header.join(","),
        "t,b.x,b.y,b.vx,b.vy,b.on,hub.x,hub.y,hub.angle,hub.vx,hub.vy,hub.w,energy,max_abs_c"
    );
    assert_eq!(rows.len(), 301, "t = 0 and 300 steps");
    let (mut off, mut drift, mut spin, mut c) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for row in &rows {
        let (bead_at, hub_at) = wirebead::reference::bead_on_a_free_hoop(
            (1.0, 3.0),
            (DVec3::X, DVec3::new(0.0, 1.5, 0.0)),
            (DVec3::ZERO, DVec3::ZERO),
            row[0],
        );
        off = off
            .max((DVec3::new(row[1], row[2], 0.0) - bead_at).length())
            .max((DVec3::new(row[6], row[7], 0.0) - hub_at).length());
        let momentum = (row[3] + 3.0 * row[9]).hypot(row[4] + 3.0 * row[10] - 1.5);
        drift = drift.max(momentum / 1.5);
        spin = spin.max(row[11].abs());
        c = c.max(row[13]);
    }
    println!(
        "off the two-body answer {off:.2e} m, momentum {drift:.2e}, spin {spin:.2e} rad/s, max |C| {c:.2e} m"
    );
    assert!(off <= 1e-4, "{off:e} m off the two-body answer");
    assert!(drift <= 1e-5, "the momentum changed by {drift:e} of itself");
    assert!(spin <= 1e-5, "the hub spins at {spin:e} rad/s");
    assert!(c <= 1e-5, "the bead is {c:e} m off its hoop");
}

/// A shipped scene with bodies (`assets/scenes/avian/`), by its stem.
#[cfg(all(feature = "avian2d", feature = "avian3d"))]
fn shipped(stem: &str) -> wirebead::SceneFile {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/scenes/avian")
        .join(format!("{stem}.scene.ron"));
    analysis::load_scene_file(&path).unwrap()
}

/// The column `name` of a run's CSV (`header`, `rows`).
#[cfg(all(feature = "avian2d", feature = "avian3d"))]
fn column(header: &[String], rows: &[Vec<f64>], name: &str) -> Vec<f64> {
    let i = header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    rows.iter().map(|r| r[i]).collect()
}

/// A run of a shipped scene for `seconds`: its CSV, which never
/// diverged and held every path joint, and bead on a carried wire, on its
/// wire to 1e-5 m.
#[cfg(all(feature = "avian2d", feature = "avian3d"))]
fn shipped_run(stem: &str, seconds: f64) -> (Vec<String>, Vec<Vec<f64>>) {
    let (header, rows) = match shipped(stem) {
        wirebead::SceneFile::Plane(scene) => {
            let run = analysis::simulate_scene(&scene, scene.params.clone(), seconds).unwrap();
            assert!(run.diverged.is_none(), "{stem}: {:?}", run.diverged);
            csv_of(&run)
        }
        wirebead::SceneFile::Space(scene) => {
            let run = analysis::simulate_scene(&scene, scene.params.0.clone(), seconds).unwrap();
            assert!(run.diverged.is_none(), "{stem}: {:?}", run.diverged);
            csv_of(&run)
        }
    };
    let c = column(&header, &rows, "max_abs_c")
        .into_iter()
        .fold(0.0, f64::max);
    println!("{stem}: |C| at most {c:.2e} m over {seconds} s");
    assert!(c <= 1e-5, "{stem}: |C| reached {c:e} m");
    (header, rows)
}

/// The shipped scenes with bodies do what their files say, each holding
/// its joints to 1e-5 m: the marbles topple all nine dominoes (each
/// turned past 60° toward +x in 6 s); the coaster train runs its loop
/// keeping its energy to 3 % until it strikes the crates, and knocks each
/// crate more than 1 m from where it stood; gravity swings the door more
/// than 120° about its leaning hinge with the bead on its hoop; the carts
/// on the hoop and on the loop run on; the first of two beads on a rail
/// knocks the stack of crates over, pushing the bottom one to the wall at
/// the run's end, where no bead passes the wall or a crate, or the other
/// bead.
#[cfg(all(feature = "avian2d", feature = "avian3d"))]
#[test]
fn the_shipped_scenes_with_bodies_do_what_they_say() {
    let (header, rows) = shipped_run("dominoes", 6.0);
    for i in 1..=9 {
        let angle = *column(&header, &rows, &format!("domino {i}.angle"))
            .last()
            .unwrap();
        assert!(
            angle < -60f64.to_radians(),
            "domino {i} stands at {angle} rad"
        );
    }

    let (header, rows) = shipped_run("coaster_train", 4.0);
    let energy = column(&header, &rows, "energy");
    let t = column(&header, &rows, "t");
    let before = t.iter().position(|&t| t >= 2.0).unwrap();
    let kept = energy[..before]
        .iter()
        .map(|e| (e - energy[0]).abs() / energy[0])
        .fold(0.0, f64::max);
    println!("coaster train: energy kept to {kept:.2e} before the crates");
    assert!(
        kept <= 0.03,
        "the train's energy changed by {kept} before the crates"
    );
    for i in 1..=5 {
        let [x, y, z] = ["x", "y", "z"].map(|a| column(&header, &rows, &format!("crate {i}.{a}")));
        let moved = ((x[x.len() - 1] - x[0]).powi(2)
            + (y[y.len() - 1] - y[0]).powi(2)
            + (z[z.len() - 1] - z[0]).powi(2))
        .sqrt();
        assert!(moved > 1.0, "crate {i} moved only {moved} m");
    }

    let (header, rows) = shipped_run("door", 4.0);
    let [qx, qy, qz, qw] =
        ["qx", "qy", "qz", "qw"].map(|a| column(&header, &rows, &format!("door.{a}")));
    let swing = (0..qw.len())
        .map(|i| 2.0 * (qx[i].hypot(qy[i]).hypot(qz[i])).atan2(qw[i].abs()))
        .fold(0.0, f64::max);
    println!("door: swung {:.1}°", swing.to_degrees());
    assert!(
        swing > 120f64.to_radians(),
        "the door swung only {swing} rad"
    );

    let (header, rows) = shipped_run("beads_and_crates", 4.0);
    let last = |name: &str| *column(&header, &rows, name).last().unwrap();
    let pushed = last("crate 1.x") - 1.0;
    let fallen = 0.75 - last("crate 3.y");
    println!("beads and crates: crate 1 pushed {pushed:.3} m, crate 3 fell {fallen:.3} m");
    assert!(pushed > 4.0, "crate 1 was pushed only {pushed} m");
    assert!(fallen > 0.5, "crate 3 fell only {fallen} m");
    // Each bead ends before the wall's face, and the second against the
    // first crate at most, never in either.
    for bead in ["bead 1", "bead 2"] {
        let x = column(&header, &rows, &format!("{bead}.x"));
        let farthest = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!(farthest <= 5.4 + 1e-6, "{bead} reached {farthest} m");
    }
    assert!(last("bead 2.x") <= last("crate 1.x") - 0.25 + 1e-6);
    let (one, two) = (
        column(&header, &rows, "bead 1.x"),
        column(&header, &rows, "bead 2.x"),
    );
    let closest = one
        .iter()
        .zip(&two)
        .map(|(a, b)| (b - a).abs())
        .fold(f64::INFINITY, f64::min);
    assert!(closest >= 0.2 - 1e-6, "the beads came {closest} m apart");

    shipped_run("cart_on_hoop", 2.0);
    shipped_run("cart_on_loop_in_space", 2.0);
}

/// The window's export of a run with bodies (E, from the timeline) writes
/// the rows `simulate --scene` writes of the same run, the bodies' columns
/// and their energy included: the cart on its hoop, the beads knocking the
/// crates about, and the cart on its loop in space, over a second.
#[cfg(all(feature = "avian2d", feature = "avian3d"))]
#[test]
fn the_recorded_run_with_bodies_exports_the_rows_simulate_writes() {
    for stem in ["cart_on_hoop", "beads_and_crates", "cart_on_loop_in_space"] {
        let file = shipped(stem);
        let (simulated, exported) = match &file {
            wirebead::SceneFile::Plane(scene) => common::both_csvs(scene, &file, 60),
            wirebead::SceneFile::Space(scene) => common::both_csvs(scene, &file, 60),
        };
        let header = simulated.lines().next().unwrap();
        assert!(
            header.contains(".angle") || header.contains(".qw"),
            "{stem}: {header}"
        );
        assert_eq!(
            simulated.lines().count(),
            62,
            "{stem}: the header and 61 rows"
        );
        assert_eq!(exported, simulated, "{stem}");
    }
}
