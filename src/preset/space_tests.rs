//! Scene files in space parsed, refused with their messages in one line
//! naming the item, and told apart from scenes in the plane.

use bevy::math::{DQuat, DVec3};

use super::{SceneFile, ScenePreset, SpaceMotionPreset, SpaceScene};
use crate::geometry::SpaceMotion;

/// The rotating hoop, as a scene file in space writes it.
const HOOP: &str = r#"(
    name: "Bead on a rotating hoop",
    dimension: 3,
    params: (integrator: Rattle, timestep: 0.001, gravity: (0.0, -9.81, 0.0)),
    wires: [(
        shape: Circle((radius: 1.0)),
        position: (0.0, 0.0, 0.0),
        rotation: (axis: (0.0, 1.0, 0.0), angle_degrees: 0.0),
        motion: Spin((angular_velocity: 6.0, axis: (0.0, 1.0, 0.0))),
        beads: [(name: "b", mass: 1.0, initial_position: (0.5, -0.8660254037844386, 0.0))],
    )],
)"#;

fn space(text: &str) -> SpaceScene {
    match SceneFile::from_ron(text).expect("a valid scene") {
        SceneFile::Space(scene) => scene,
        SceneFile::Plane(_) => panic!("read as a scene in the plane"),
    }
}

fn refused(text: &str) -> String {
    SceneFile::from_ron(text).unwrap_err().to_string()
}

#[test]
fn the_rotating_hoop_scene_parses() {
    let scene = space(HOOP);
    assert_eq!(scene.params.0.timestep, 0.001);
    assert_eq!(
        scene.params.0.gravity_in_space(),
        DVec3::new(0.0, -9.81, 0.0)
    );
    let wire = &scene.wires[0];
    assert_eq!(wire.pose().unwrap().rotation, DQuat::IDENTITY);
    assert_eq!(
        wire.motion.motion(),
        SpaceMotion::Spin {
            angular_velocity: 6.0,
            axis: DVec3::Y
        }
    );
    assert_eq!(scene.bead_names(), ["b"]);
    assert_eq!(scene.wires[0].rail, None);
    // A rail: its beads turn with the track.
    let rail = space(&HOOP.replace("beads:", "rail: (up: (0.0, 1.0, 0.0)), beads:"));
    assert_eq!(rail.wires[0].rail, Some(super::RailPreset { up: DVec3::Y }));
    // A bowl that catches, a wire that sends its beads back: written as
    // read, left out where not given.
    assert!(!scene.wires[0].catches && scene.wires[0].sends_back.is_none());
    let back = "sends_back: (to: (1.0, 0.0, 0.0), speed: 0.1, after: 0.5), beads:";
    let bowl = space(
        &HOOP
            .replace("Circle((radius: 1.0))", "Sphere((radius: 1.0))")
            .replace("beads:", &format!("side: Negative, catches: true, {back}")),
    );
    let wire = &bowl.wires[0];
    assert!(wire.catches);
    let sent = wire
        .sends_back
        .expect("sends back")
        .component()
        .expect("valid");
    assert_eq!(
        (sent.to(), sent.speed(), sent.after()),
        (DVec3::X, 0.1, 0.5)
    );
    let written = crate::preset::scene_ron(&SceneFile::Space(bowl.clone())).expect("written");
    assert!(written.contains("catches: true") && written.contains("sends_back: ("));
    let plain = crate::preset::scene_ron(&SceneFile::Space(scene.clone())).expect("written");
    assert!(!plain.contains("sends_back") && !plain.contains("catches"));
    // A spin with no axis turns about z, as in the plane.
    let default_axis = space(&HOOP.replace(", axis: (0.0, 1.0, 0.0)))", "))"));
    assert_eq!(
        default_axis.wires[0].motion,
        SpaceMotionPreset::Spin(super::SpinPreset {
            angular_velocity: 6.0,
            axis: DVec3::Z
        })
    );
    // A scene in the plane is one still, with or without `dimension: 2`.
    let plane = "(name: \"p\", wires: [(shape: Circle((radius: 1.0)), beads: [()])])";
    assert!(matches!(
        SceneFile::from_ron(plane),
        Ok(SceneFile::Plane(_))
    ));
    let two = plane.replace("name: \"p\",", "name: \"p\", dimension: 2,");
    assert!(matches!(SceneFile::from_ron(&two), Ok(SceneFile::Plane(_))));
}

#[test]
fn bad_scenes_in_space_are_refused_in_one_line_naming_the_item() {
    let cases = [
        (
            HOOP.replace(
                "initial_position: (0.5, -0.8660254037844386, 0.0)",
                "initial_position: (0.5, -0.8)",
            ),
            "wires[0].beads[0].initial_position",
        ),
        (
            HOOP.replace(
                "rotation: (axis: (0.0, 1.0, 0.0)",
                "rotation: (axis: (0.0, 0.0, 0.0)",
            ),
            "wire 0: a rotation axis must not be zero",
        ),
        (
            HOOP.replace("6.0, axis: (0.0, 1.0, 0.0)", "6.0, axis: (0.0, 0.0, 0.0)"),
            "wire 0: ",
        ),
        (
            HOOP.replace("Circle((radius: 1.0))", "Sphere((radius: 0.0))"),
            "wire 0: radius must be positive and finite, got 0",
        ),
        (
            HOOP.replace("Circle((radius: 1.0))", "Helix((radius: 1.0, pitch: -0.5))"),
            "wire 0: helix pitch must be positive and finite, got -0.5",
        ),
        (
            HOOP.replace("Circle((radius: 1.0))", "Cone((half_angle_degrees: 90.0))"),
            "wire 0: cone half angle (degrees)",
        ),
        (
            HOOP.replace("gravity: (0.0, -9.81, 0.0)", "gravity: (0.0, NaN, 0.0)"),
            "gravity must be finite, got (0, NaN, 0)",
        ),
        (
            HOOP.replace("beads:", "rail: (up: (0.0, 0.0, 0.0)), beads:"),
            "wire 0: a rail's up must not be zero",
        ),
        (
            HOOP.replace("Circle((radius: 1.0))", "Sphere((radius: 1.0))")
                .replace("beads:", "rail: (up: (0.0, 1.0, 0.0)), beads:"),
            "wire 0: a rail is a curve: a surface has no track to turn with",
        ),
        (
            HOOP.replace("beads:", "catches: true, beads:"),
            "wire 0: a wire that catches beads must be one-sided",
        ),
        (
            HOOP.replace(
                "beads:",
                "sends_back: (to: (1.0, 0.0, 0.0), speed: 0.0, after: 0.5), beads:",
            ),
            "wire 0: speed below which a bead has settled must be positive and finite, got 0",
        ),
        (
            HOOP.replace(
                "beads:",
                "sends_back: (to: (1.0, NaN, 0.0), speed: 0.1, after: 0.5), beads:",
            ),
            "wire 0: point beads are sent back to must be finite",
        ),
        (
            HOOP.replace(
                "beads:",
                "sends_back: (to: (1.0, 0.0, 0.0), speed: 0.1, after: -1.0), beads:",
            ),
            "wire 0: time a bead takes to settle",
        ),
        (
            HOOP.replace("mass: 1.0", "mass: NaN"),
            "wire 0, bead 0: mass must be positive and finite, got NaN",
        ),
        (
            HOOP.replace("dimension: 3", "dimension: 4"),
            "dimension must be 2 or 3, got 4",
        ),
    ];
    for (text, expected) in cases {
        let message = refused(&text);
        assert!(message.contains(expected), "{message:?} lacks {expected:?}");
        assert!(!message.contains('\n'), "{message:?} is not one line");
    }
    // A scene in space read as one in the plane is refused in words.
    assert_eq!(
        ScenePreset::from_ron(HOOP).unwrap_err().to_string(),
        "the scene is in space (dimension: 3); this takes scenes in the plane"
    );
}
