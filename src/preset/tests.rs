//! Scene files parsed, refused with their messages, and read back.

use super::{PresetError, ScenePreset};
use crate::dynamics::{BeadParams, SimParams};

const GOOD: &str = r#"(
        name: "two",
        params: (alpha: 50.0, integrator: Rattle),
        wires: [
            (shape: Circle((radius: 2.0)), position: (1.0, 0.5), angle_degrees: 30.0,
             beads: [(mass: 1.0, initial_position: (3.0, 0.5))]),
            (shape: Sine((amplitude: 0.3, wavelength: 2.0)), beads: [()]),
        ],
    )"#;

#[test]
fn a_preset_parses_with_defaults_filled_in() {
    let preset = ScenePreset::from_ron(GOOD).unwrap();
    assert_eq!(preset.params.alpha, 50.0);
    assert_eq!(preset.params.method, crate::solver::Method::Rattle);
    assert_eq!(preset.params.beta, SimParams::default().beta);
    assert_eq!(preset.wires[1].beads[0].params(), BeadParams::default());
    assert_eq!(preset.wires[0].angle_degrees, 30.0);
}

#[test]
fn malformed_files_say_where_and_what() {
    let err = ScenePreset::from_ron("(name: \"x\", wires: [ (shape: Circle((radius: 1.0)) ]")
        .unwrap_err();
    let text = err.to_string();
    assert!(
        text.starts_with("malformed scene file at line 1, column "),
        "{text}"
    );
    let err = ScenePreset::from_ron(&GOOD.replace("radius: 2.0", "radius: 0.0")).unwrap_err();
    assert_eq!(
        err.to_string(),
        "wire 0: radius must be positive and finite, got 0"
    );
    let err = ScenePreset::from_ron(&GOOD.replace("mass: 1.0", "mass: -1.0")).unwrap_err();
    assert_eq!(
        err.to_string(),
        "wire 0, bead 0: mass must be positive and finite, got -1"
    );
    let err = ScenePreset::from_ron(&GOOD.replace("alpha: 50.0", "timestep: -0.1")).unwrap_err();
    assert_eq!(
        err.to_string(),
        "invalid params: timestep must be positive and finite, got -0.1"
    );
}

/// The format as the module doc gives it, with a spring and a pin.
const CART: &str = r#"(
        name: "Pendulum on a cart",
        params: (integrator: Rattle),
        wires: [(shape: Line(()), beads: [(name: "cart", mass: 2.0, initial_position: (0.0, 0.0))])],
        beads: [(name: "bob", mass: 1.0, initial_position: (0.0, -1.0)), (initial_position: (1.0, -1.0))],
        constraints: [Rod((a: "cart", b: "bob", length: 1.0)), Pin((bead: "bead2", at: (1.0, -1.0)))],
        springs: [(a: "bob", b: "bead2", rest_length: 1.0, stiffness: 50.0, damping: 0.1)],
    )"#;

#[test]
fn an_unknown_field_is_refused_in_one_line_naming_it_and_its_item() {
    let refuse = |from: &str, to: &str| {
        let text = GOOD.replace(from, to);
        assert_ne!(text, GOOD, "{from} is not in the file");
        ScenePreset::from_ron(&text).unwrap_err().to_string()
    };
    let err = refuse(
        "angle_degrees: 30.0,",
        "angle_degrees: 30.0, restitutoin: 0.5,",
    );
    assert!(
        err.starts_with("unknown field `restitutoin` in wires[0] at line 5, column "),
        "{err}"
    );
    assert!(
        err.contains("known fields: name, body, shape, position,"),
        "{err}"
    );
    assert!(!err.contains('\n'), "{err}");
    let err = refuse("mass: 1.0", "mas: 1.0");
    assert!(
        err.starts_with("unknown field `mas` in wires[0].beads[0] at line 6"),
        "{err}"
    );
    let err = refuse("alpha: 50.0", "alhpa: 50.0");
    assert!(
        err.starts_with("unknown field `alhpa` in params at line 3"),
        "{err}"
    );
    let err = refuse("name: \"two\",", "name: \"two\", wire: [],");
    assert!(
        err.starts_with("unknown field `wire` in the scene at line 2"),
        "{err}"
    );
    let err = refuse("radius: 2.0", "radius: 2.0, centre: (0.0, 0.0)");
    assert!(
        err.starts_with("unknown field `centre` in wires[0].shape"),
        "{err}"
    );
}

#[test]
fn a_coupled_scene_names_its_beads_and_links() {
    let preset = ScenePreset::from_ron(CART).unwrap();
    assert_eq!(preset.bead_names(), ["cart", "bob", "bead2"]);
    assert_eq!(preset.all_beads().count(), 3);
    assert_eq!(preset.constraints.len(), 2);
    assert_eq!(preset.springs[0].damping, 0.1);
    // Today's files, with no names, free beads or links, still load.
    assert!(ScenePreset::from_ron(GOOD).unwrap().constraints.is_empty());
}

#[test]
fn bad_links_are_refused_naming_the_item() {
    let refuse = |from: &str, to: &str| {
        ScenePreset::from_ron(&CART.replace(from, to))
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        refuse("b: \"bob\", length", "b: \"bobby\", length"),
        "constraint 0 (rod): no bead is named \"bobby\""
    );
    assert_eq!(
        refuse("b: \"bob\", length", "b: \"cart\", length"),
        "constraint 0 (rod): a rod must join two different beads"
    );
    assert_eq!(
        refuse("length: 1.0", "length: 0.0"),
        "constraint 0 (rod): rod length must be positive and finite, got 0"
    );
    assert_eq!(
        refuse("at: (1.0, -1.0)", "at: (NaN, -1.0)"),
        "constraint 1 (pin): pin point must be finite, got (NaN, -1)"
    );
    assert_eq!(
        refuse("(name: \"bob\"", "(name: \"cart\""),
        "two beads are named \"cart\""
    );
    assert_eq!(
        refuse("stiffness: 50.0", "stiffness: -50.0"),
        "spring 0: spring stiffness must be zero or more and finite, got -50"
    );
    assert_eq!(
        refuse(
            "mass: 1.0, initial_position: (0.0, -1.0)",
            "mass: 0.0, initial_position: (0.0, -1.0)"
        ),
        "bead \"bob\": mass must be positive and finite, got 0"
    );
}

#[test]
fn a_broken_file_and_bad_tracks_in_a_file_are_refused_in_words() {
    assert_eq!(
        ScenePreset::from_ron("(name: \"broken\", wires: [")
            .unwrap_err()
            .to_string(),
        "malformed scene file at line 1, column 25 in wires[0]: Expected opening `(` for struct `WirePreset`"
    );
    let scene = |wire: &str| {
        ScenePreset::from_ron(&format!("(name: \"t\", wires: [({wire}, beads: [()])])"))
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        scene("shape: Line(()), friction: (static: -1.0, kinetic: 0.0)"),
        "wire 0: static friction must be zero or more and finite, got -1"
    );
    assert_eq!(
        scene("shape: Line(()), motion: Spin((angular_velocity: inf))"),
        "wire 0: angular velocity must be finite, got inf"
    );
    let spline = scene("shape: Spline((points: [(0.0, 0.0)]))");
    assert!(
        spline.contains("a cardinal spline needs two points at least"),
        "{spline}"
    );
}

/// A pile has as many beads as it is asked for, each of
/// [`PILE_RADIUS`](super::PILE_RADIUS), inside the bowl by more than a
/// radius and no two touching (23 to a row are 2.04 radii apart at the
/// least, the jitter taken off 2.17); none to a row is taken as one.
#[test]
fn a_pile_too_large_for_its_bowl_is_refused_saying_how_many_fit() {
    let err = ScenePreset::pile(1000, 23).unwrap_err();
    let PresetError::PileTooLarge { row, most, .. } = err else {
        panic!("refused for another reason: {err}");
    };
    // Rows 2.3 radii apart from y = −0.8: the edge beads of row 36
    // (y = 0.856) are past 0.98 m from the centre.
    assert_eq!((row, most), (36, 36 * 23));
    assert_eq!(
        err.to_string(),
        "a pile of 1000 beads in rows of 23 does not fit in its bowl: row 36 would start outside it; at most 828 fit in rows of 23"
    );
    let fits = ScenePreset::pile(most, 23).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(fits.all_beads().count(), most);
}

#[test]
fn a_pile_has_its_beads_apart_inside_the_bowl() {
    let r = super::PILE_RADIUS;
    for (n, per_row) in [(46, 23), (500, 23), (3, 0)] {
        let pile = ScenePreset::pile(n, per_row).unwrap_or_else(|e| panic!("{e}"));
        let beads: Vec<_> = pile.all_beads().collect();
        assert_eq!(beads.len(), n);
        for (i, a) in beads.iter().enumerate() {
            assert_eq!(a.radius, r);
            let from_centre = a.initial_position.length();
            assert!(from_centre < 1.0 - r, "{} at {from_centre} m", a.name);
            for b in &beads[i + 1..] {
                let apart = (a.initial_position - b.initial_position).length();
                assert!(apart > 2.0 * r, "{} and {}: {apart} m", a.name, b.name);
            }
        }
    }
}

/// Every bead of a pour, in the plane or in space, as `(x, y, z)` with
/// its radius.
fn poured(scene: &super::SceneFile) -> Vec<(bevy::math::DVec3, f64)> {
    match scene {
        super::SceneFile::Plane(scene) => scene
            .all_beads()
            .map(|b| (b.initial_position.extend(0.0), b.radius))
            .collect(),
        super::SceneFile::Space(scene) => scene
            .wires
            .iter()
            .flat_map(|w| &w.beads)
            .map(|b| (b.initial_position, b.radius))
            .collect(),
    }
}

/// A pour of 1,000 beads in a bowl of 1 m, in the plane and in space,
/// and one of 5,000 in the plane in a bowl of 3 m: as many beads as
/// asked, each of [`PILE_RADIUS`](super::PILE_RADIUS), inside the bowl
/// by more than a radius, none touching (2.3 radii apart on the grid,
/// the jitter of up to 1.5 mm taken off), the lowest first, and the
/// scene of the dimension asked for.
#[test]
fn a_pour_has_its_beads_apart_inside_the_bowl_lowest_first() {
    let r = super::PILE_RADIUS;
    for (beads, space, bowl) in [(1000, false, 1.0), (1000, true, 1.0), (5000, false, 3.0)] {
        let pour = super::Pour {
            beads,
            space,
            bowl,
            ..super::Pour::default()
        };
        let scene = pour.scene().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(scene.in_space(), space);
        let at = poured(&scene);
        assert_eq!(at.len(), beads);
        for (i, &(a, radius)) in at.iter().enumerate() {
            assert_eq!(radius, r);
            assert!(a.length() < bowl - r, "bead {i} at {} m", a.length());
            if i > 0 {
                assert!(a.y >= at[i - 1].0.y, "bead {i} below bead {}", i - 1);
            }
            for (j, &(b, _)) in at.iter().enumerate().skip(i + 1) {
                let apart = (a - b).length();
                assert!(apart > 2.0 * r, "beads {i} and {j}: {apart} m");
            }
        }
    }
}

/// A pour of more beads than its bowl holds is refused saying how many
/// fit, and so is a bowl with no room or no radius (zero, negative,
/// NaN); a bowl of a kilometre takes its ten beads at once, and one of
/// 1e300 m is refused in words where rounding stacks them;
/// a timestep that is not positive is refused as any scene file's.
#[test]
fn a_pour_too_large_or_malformed_is_refused_in_words() {
    let pour = super::Pour {
        beads: 5000,
        ..super::Pour::default()
    };
    let err = pour.scene().unwrap_err();
    let PresetError::PourTooLarge { most, .. } = err else {
        panic!("refused for another reason: {err}");
    };
    assert!((1000..5000).contains(&most), "{most}");
    assert_eq!(
        err.to_string(),
        format!(
            "a pour of 5000 beads does not fit in a bowl of radius 1 m: at most {most} beads start inside it"
        )
    );
    let fits = super::Pour {
        beads: most,
        ..pour
    };
    assert_eq!(
        poured(&fits.scene().unwrap_or_else(|e| panic!("{e}"))).len(),
        most
    );
    // A bowl of any size is filled from its bottom in the time its
    // beads take: a kilometre's ten beads start on its grid; a bowl of
    // 1e300 m places its beads so far from its centre that rounding puts
    // them on one another, which the scene's check refuses in words.
    let far = |bowl: f64| {
        super::Pour {
            beads: 10,
            bowl,
            space: true,
            ..super::Pour::default()
        }
        .scene()
    };
    assert_eq!(
        poured(&far(1e3).unwrap_or_else(|e| panic!("{e}"))).len(),
        10
    );
    let err = far(1e300).unwrap_err().to_string();
    assert!(err.contains("overlap"), "{err}");
    for bowl in [0.0, -1.0, f64::NAN, 0.02] {
        let err = super::Pour {
            bowl,
            ..super::Pour::default()
        }
        .scene()
        .unwrap_err();
        assert!(
            matches!(err, PresetError::PourTooLarge { most: 0, .. }),
            "bowl {bowl}: {err}"
        );
    }
    let err = super::Pour {
        timestep: 0.0,
        ..super::Pour::default()
    }
    .scene()
    .unwrap_err();
    assert!(err.to_string().contains("timestep"), "{err}");
}

/// The hourglass of 2,000 grains, and ones of 1 and 300: as many grains
/// as asked, each of [`GRAIN_RADIUS`](super::GRAIN_RADIUS), in the upper
/// bulb (above the neck) and inside the glass by more than a radius and
/// a half, none touching, the lowest first; the glass a closed one-sided
/// wire, the same on both sides of the middle and of the neck, whose
/// neck lets the grains' centres through 3.5 radii either side of the
/// middle.
#[test]
fn an_hourglass_has_its_grains_apart_in_the_upper_bulb_lowest_first() {
    use crate::geometry::{ImplicitCurve, WireShape};
    use bevy::math::DVec2;
    let r = super::GRAIN_RADIUS;
    for beads in [2000, 300, 1] {
        let scene = super::Hourglass {
            beads,
            ..super::Hourglass::default()
        }
        .scene()
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(scene.wires.len(), 1);
        let wire = &scene.wires[0];
        let WireShape::Spline(glass) = &wire.shape else {
            panic!("the glass is a {:?}", wire.shape);
        };
        assert!(glass.spec().closed && !glass.has_ends());
        for p in [
            DVec2::new(0.2, 0.3),
            DVec2::new(0.05, 0.9),
            DVec2::new(0.01, 0.02),
        ] {
            let mirrored = [DVec2::new(-p.x, p.y), DVec2::new(p.x, -p.y), -p];
            for q in mirrored {
                assert!(
                    (glass.value(q) - glass.value(p)).abs() <= 1e-9,
                    "{p} and {q}"
                );
            }
        }
        assert!((glass.value(DVec2::ZERO) - 3.5 * r).abs() <= 0.05 * r);
        let grains: Vec<_> = scene.all_beads().collect();
        assert_eq!(grains.len(), beads);
        for (i, a) in grains.iter().enumerate() {
            let at = a.initial_position;
            assert_eq!(a.radius, r);
            assert!(at.y > 2.0 * r, "{} at {at}", a.name);
            assert!(glass.value(at) > 1.5 * r, "{} at {at}", a.name);
            if i > 0 {
                assert!(at.y >= grains[i - 1].initial_position.y, "{} lower", a.name);
            }
            for b in &grains[i + 1..] {
                let apart = (at - b.initial_position).length();
                assert!(apart > 2.0 * r, "{} and {}: {apart} m", a.name, b.name);
            }
        }
    }
}

/// An hourglass of more grains than it is made for is refused in words,
/// and a timestep that is not positive as any scene file's.
#[test]
fn an_hourglass_too_large_or_malformed_is_refused_in_words() {
    let most = super::Hourglass::MOST;
    let err = super::Hourglass {
        beads: most + 1,
        ..super::Hourglass::default()
    }
    .scene()
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "an hourglass of {} grains is more than the {most} it is made for",
            most + 1
        )
    );
    let err = super::Hourglass {
        timestep: -1.0,
        ..super::Hourglass::default()
    }
    .scene()
    .unwrap_err();
    assert!(err.to_string().contains("timestep"), "{err}");
}

/// A marble run: its marbles apart, the first twelve on the rail at its
/// spiral's points (the spline passes through them) and the rest off it inside the
/// bowl below the rail's end; the bowl catches, the rail sends marbles
/// back to its top.
#[test]
fn a_marble_run_has_its_marbles_apart_on_the_rail_and_in_the_bowl() {
    use bevy::math::DVec3;

    use crate::geometry::SpaceCurve;
    let scene = super::MarbleRun::default().scene().expect("a marble run");
    let [bowl, rail] = &scene.wires[..] else {
        panic!("a bowl and a rail: {} wires", scene.wires.len());
    };
    assert!(bowl.catches && bowl.sends_back.is_none());
    let points = super::MarbleRun::rail();
    let back = rail.sends_back.expect("the rail sends back");
    assert_eq!(back.to, points[0]);
    let super::SpaceShapePreset::Spline(curve) = &rail.shape else {
        panic!("the rail is a spline");
    };
    assert!(curve.has_ends());
    let at: Vec<DVec3> = rail.beads.iter().map(|b| b.initial_position).collect();
    assert_eq!(at.len(), 200);
    let r = super::PILE_RADIUS;
    let off = |p: DVec3| {
        let [a, b] = curve.rows(p, f64::NAN);
        a.c.hypot(b.c)
    };
    for (k, &p) in at.iter().enumerate() {
        // The spiral's points but its last, then the bowl.
        if k < points.len() - 3 {
            assert_eq!(p, points[k]);
            assert!(off(p) <= 1e-12, "marble {k} is {} off the rail", off(p));
        } else {
            assert!(off(p) > 2.0 * r, "marble {k} starts on the rail");
            assert!(
                p.length() < super::MARBLE_BOWL - r,
                "marble {k} outside the bowl"
            );
            assert!(
                p.y < points[points.len() - 1].y - 2.0 * r,
                "marble {k} above the rail's end"
            );
        }
        for (j, &q) in at[..k].iter().enumerate() {
            assert!((p - q).length() > 2.0 * r, "marbles {j} and {k} overlap");
        }
    }
    let err = super::MarbleRun {
        marbles: super::MarbleRun::MOST + 1,
        ..super::MarbleRun::default()
    }
    .scene()
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "a marble run of 1001 marbles is more than the 1000 its bowl is made for"
    );
    let none = super::MarbleRun {
        timestep: 0.0,
        ..super::MarbleRun::default()
    }
    .scene()
    .unwrap_err();
    assert!(none.to_string().contains("timestep"), "{none}");
}
