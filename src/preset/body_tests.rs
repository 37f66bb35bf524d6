//! Scene files with rigid bodies and path joints: parsed with their
//! defaults, refused in one line naming the item, written back.

use bevy::math::{DVec2, DVec3};

use super::{
    BodyKind, BodyShape, PathRotationPreset, SceneBody, SceneFile, SceneJoin, ScenePreset,
    SpaceScene, plane_inertia, scene_ron,
};

/// The scene of the format's description, to the letter.
const CART: &str = include_str!("../../tests/scenes/cart_on_hoop.scene.ron");

/// The scene with `from` replaced by `to`, read; its error in words.
fn refused(from: &str, to: &str) -> String {
    let text = CART.replace(from, to);
    assert_ne!(text, CART, "{from:?} is not in the scene");
    ScenePreset::from_ron(&text).unwrap_err().to_string()
}

#[test]
fn the_formats_own_scene_reads_with_its_body_and_its_joint() {
    let scene = ScenePreset::from_ron(CART).expect("the scene reads");
    let cart = &scene.bodies[0];
    assert_eq!(cart.kind, BodyKind::Dynamic);
    assert_eq!(cart.mass, Some(2.0));
    assert_eq!(cart.position, DVec2::new(1.0, 0.0));
    assert_eq!(cart.friction, 0.0);
    assert_eq!(scene.wires[0].name, "hoop");
    let paths = scene.paths().expect("the joint resolves");
    assert_eq!(paths.len(), 1);
    assert_eq!((paths[0].body, paths[0].wire), (0, 0));
    assert_eq!(paths[0].rotation, PathRotationPreset::Free);
    assert!(scene.links().expect("no bead links").is_empty());
    // The inertia of a uniform box of 2 kg, 0.4 m by 0.2 m.
    let (mass, inertia) = cart.mass_properties().expect("a dynamic body");
    assert_eq!(mass, 2.0);
    assert!((inertia - 2.0 * (0.16 + 0.04) / 12.0).abs() < 1e-15);
    assert_eq!(inertia, plane_inertia(&cart.shape, 2.0));
}

#[test]
fn a_body_given_only_what_it_must_takes_the_defaults() {
    let scene = ScenePreset::from_ron(
        r#"(name: "least", bodies: [
            (name: "ball", shape: Ball((radius: 0.1)), mass: 1.0, position: (0.0, 2.0)),
            (name: "floor", kind: Static, shape: Box((half_extents: (5.0, 0.1))), position: (0.0, -1.0)),
        ])"#,
    )
    .expect("a scene of bodies alone reads");
    let ball = &scene.bodies[0];
    assert_eq!(ball.kind, BodyKind::Dynamic);
    assert_eq!((ball.angle_degrees, ball.angular_velocity), (0.0, 0.0));
    assert_eq!(
        (ball.velocity, ball.restitution, ball.friction),
        (DVec2::ZERO, 0.0, 0.5)
    );
    assert_eq!(ball.inertia, None);
    assert_eq!(scene.bodies[1].mass_properties(), None);
}

#[test]
fn a_bad_body_wire_or_joint_is_refused_naming_it() {
    let cases = [
        (
            r#"wires: [(name: "hoop","#,
            r#"wires: [(name: "hoop", body: "door","#,
            r#"wire 0 ("hoop"): no body is named "door""#,
        ),
        (
            r#"body: "cart", wire"#,
            r#"body: "cat", wire"#,
            r#"constraint 0 (path): no body is named "cat""#,
        ),
        (
            r#"wire: "hoop", anchor"#,
            r#"wire: "loop", anchor"#,
            r#"constraint 0 (path): no wire is named "loop""#,
        ),
        ("mass: 2.0,", "mass: 0.0,", r#"body 0 ("cart"): "#),
        ("mass: 2.0,", "", "a dynamic body needs a mass"),
        (
            "(half_extents: (0.2, 0.1))",
            "(half_extents: (0.2, 0.0))",
            "box half extent y",
        ),
        (
            "position: (1.0, 0.0)",
            "position: (NaN, 0.0)",
            "body position",
        ),
        (
            "rotation: Free",
            "rotation: AroundTangent",
            "that rotation is of space",
        ),
        (
            "position: (1.0, 0.0)",
            "position: (1.5, 0.0)",
            r#"the anchor of body "cart" starts 5.000e-1 m off wire "hoop""#,
        ),
        (
            r#"wires: [(name: "hoop", shape: Circle((radius: 1.0)))]"#,
            r#"wires: [(name: "hoop", shape: Circle((radius: 1.0))), (name: "hoop", shape: Line(()))]"#,
            r#"two wires are named "hoop""#,
        ),
    ];
    for (from, to, says) in cases {
        let said = refused(from, to);
        assert!(said.contains(says), "{said:?} should say {says:?}");
        assert!(!said.contains('\n'), "{said:?} is more than one line");
    }
    let twice = CART.replace("    wires:", "    bodies: [],\n    wires:");
    assert!(
        ScenePreset::from_ron(&twice).is_err(),
        "a field given twice"
    );
    let two = CART.replace(
        ")],\n    wires:",
        "), (name: \"cart\", shape: Ball((radius: 0.1)), mass: 1.0, position: (0.0, 0.0))],\n    wires:",
    );
    let said = ScenePreset::from_ron(&two).unwrap_err().to_string();
    assert_eq!(said, r#"two bodies are named "cart""#);
}

#[test]
fn a_scene_with_bodies_is_written_back_as_it_was_read() {
    let scene = ScenePreset::from_ron(CART).expect("the scene reads");
    let text = scene_ron(&SceneFile::Plane(scene.clone())).expect("written");
    let again = ScenePreset::from_ron(&text).expect("read back");
    assert_eq!(again.bodies, scene.bodies);
    assert_eq!(again.constraints, scene.constraints);
    assert_eq!(again.wires[0].name, "hoop");
}

/// A scene in space: a box on a hoop that rides a turned door, the box's
/// anchor on the hoop where the door has it.
const DOOR: &str = r#"(
    name: "A box on a hoop on a door",
    dimension: 3,
    bodies: [
        (name: "door", kind: Static, shape: Box((half_extents: (0.5, 1.0, 0.05))),
         position: (2.0, 0.0, 0.0), rotation: (axis: (0.0, 1.0, 0.0), angle_degrees: 90.0)),
        (name: "box", shape: Box((half_extents: (0.1, 0.1, 0.1))), mass: 1.0,
         position: (2.0, -0.5, 0.0), inertia: (0.01, 0.02, 0.03)),
    ],
    wires: [(name: "hoop", body: "door", shape: Circle((radius: 0.5)))],
    constraints: [Path((body: "box", wire: "hoop", rotation: AroundBinormal))],
)"#;

#[test]
fn a_scene_in_space_puts_its_anchor_on_a_wire_its_body_carries() {
    let scene = match SceneFile::from_ron(DOOR).expect("the scene reads") {
        SceneFile::Space(scene) => scene,
        SceneFile::Plane(_) => panic!("a scene in space"),
    };
    let paths = scene.paths().expect("the joint resolves");
    assert_eq!((paths[0].body, paths[0].wire), (1, 0));
    assert_eq!(paths[0].anchor, DVec3::ZERO);
    let door = &scene.bodies[0];
    assert!(matches!(door.shape, BodyShape::Box(_)));
    assert_eq!(
        scene.bodies[1].mass_properties().map(|m| m.1),
        Some(DVec3::new(0.01, 0.02, 0.03))
    );
    let said = |from: &str, to: &str| {
        let text = DOOR.replace(from, to);
        assert_ne!(text, DOOR);
        SceneFile::from_ron(&text).unwrap_err().to_string()
    };
    assert!(said("AroundBinormal", "Tangent").contains("Tangent is of the plane"));
    assert!(
        said("(2.0, -0.5, 0.0)", "(2.0, -0.6, 0.0)")
            .contains(r#"the anchor of body "box" starts 1.000e-1 m off wire "hoop""#)
    );
    assert!(said("(0.01, 0.02, 0.03)", "(0.01, -0.02, 0.03)").contains("body inertia y"));
    let text = scene_ron(&SceneFile::Space(scene.clone())).expect("written");
    let again: SpaceScene = match SceneFile::from_ron(&text).expect("read back") {
        SceneFile::Space(scene) => scene,
        SceneFile::Plane(_) => panic!("a scene in space"),
    };
    assert_eq!(again.bodies, scene.bodies);
}

/// The format's scene with a static post and the cart hinged to it at
/// the hoop's centre.
fn hinged(hinge: &str) -> String {
    CART.replace(
        ")],\n    wires:",
        "), (name: \"post\", kind: Static, shape: Ball((radius: 0.05)), position: (0.0, 0.0))],\n    wires:",
    )
    .replace(
        "rotation: Free))]",
        &format!("rotation: Free)), {hinge}]"),
    )
}

#[test]
fn a_hinge_joins_two_named_bodies_and_is_refused_naming_it_when_bad() {
    let text = hinged(r#"Hinge((a: "post", b: "cart", at: (0.0, 0.0)))"#);
    let scene = ScenePreset::from_ron(&text).expect("the hinged scene reads");
    let joins = scene.joins().expect("the hinge resolves");
    assert_eq!(
        joins,
        [SceneJoin::Hinge {
            bodies: [1, 0],
            at: DVec2::ZERO,
            axis: None
        }]
    );
    // Written back as read.
    let again =
        ScenePreset::from_ron(&scene_ron(&SceneFile::Plane(scene.clone())).expect("written"))
            .expect("read back");
    assert_eq!(again.constraints, scene.constraints);
    for (hinge, says) in [
        (
            r#"Hinge((a: "post", b: "cat", at: (0.0, 0.0)))"#,
            r#"constraint 1 (hinge): no body is named "cat""#,
        ),
        (
            r#"Hinge((a: "cart", b: "cart", at: (0.0, 0.0)))"#,
            r#"constraint 1 (hinge): joins body "cart" to itself"#,
        ),
        (
            r#"Hinge((a: "post", b: "cart", at: (0.0, NaN)))"#,
            "constraint 1 (hinge): hinge point",
        ),
        (
            r#"Hinge((a: "post", b: "cart", at: (0.0, 0.0), axis: (0.0, 1.0)))"#,
            "a hinge in the plane turns about z: it takes no axis",
        ),
    ] {
        let said = ScenePreset::from_ron(&hinged(hinge))
            .unwrap_err()
            .to_string();
        assert!(said.contains(says), "{said:?} should say {says:?}");
        assert!(!said.contains('\n'), "{said:?} is more than one line");
    }
    // In space a hinge's axis comes out of unit length, and a zero one
    // is refused.
    let space = |axis: &str| {
        DOOR.replace(
            "rotation: AroundBinormal))]",
            &format!(
                r#"rotation: AroundBinormal)), Hinge((a: "door", b: "box", at: (2.0, 0.0, 0.0), axis: {axis}))]"#
            ),
        )
    };
    let scene = match SceneFile::from_ron(&space("(0.0, 2.0, 0.0)")).expect("reads") {
        SceneFile::Space(scene) => scene,
        SceneFile::Plane(_) => panic!("a scene in space"),
    };
    let SceneJoin::Hinge { axis, .. } = scene.joins().expect("resolves")[0] else {
        panic!("a hinge");
    };
    assert_eq!(axis, Some(DVec3::Y));
    let said = SceneFile::from_ron(&space("(0.0, 0.0, 0.0)"))
        .unwrap_err()
        .to_string();
    assert!(said.contains("a hinge's axis must not be zero"), "{said}");
}

/// A coupling is a rod between a point of each body, as long as they are
/// apart where the bodies start: the cart's left end and the post's
/// centre, 0.8 m apart.
#[test]
fn a_coupling_is_as_long_as_its_ends_are_apart_at_the_start() {
    let text = hinged(r#"Coupling((a: "cart", b: "post", anchor_a: (-0.2, 0.0)))"#);
    let scene = ScenePreset::from_ron(&text).expect("the coupled scene reads");
    let [
        SceneJoin::Coupling {
            bodies,
            anchors,
            length,
        },
    ] = scene.joins().expect("the coupling resolves")[..]
    else {
        panic!("one coupling");
    };
    assert_eq!(bodies, [0, 1]);
    assert_eq!(anchors, [DVec2::new(-0.2, 0.0), DVec2::ZERO]);
    assert!((length - 0.8).abs() < 1e-15, "{length}");
    let said = ScenePreset::from_ron(&hinged(
        r#"Coupling((a: "cart", b: "post", anchor_b: (inf, 0.0)))"#,
    ))
    .unwrap_err()
    .to_string();
    assert!(
        said.contains("constraint 1 (coupling): coupling anchor"),
        "{said}"
    );
}
