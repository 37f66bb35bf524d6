//! Wire places in space (`WirePlace::in_space`): a turn read from an `f32`
//! rotation is taken as the exact rotation nearest it, and a place that
//! places nothing leaves the wire at its `Transform`.

use bevy::math::{DQuat, DVec3};
use bevy::prelude::*;
use wirebead::geometry::{Circle, OnPlane, Pose3};
use wirebead::headless::{Headless, run_for, space_bead_state};
use wirebead::prelude::*;
use wirebead::{SpaceBead, SpaceWire, WirePlace};

/// A headless app stepping with RATTLE at 1 ms.
fn app() -> App {
    let params = SimParams {
        timestep: 1e-3,
        method: Method::Rattle,
        ..default()
    };
    Headless::new(WireBeadPlugin::new(params).expect("valid parameters"))
        .single_threaded()
        .build()
}

/// A hoop of radius 1 at `place` (its `Transform` `shown`) with a bead of
/// 1 kg let go at rest at `start`: the wire and the bead.
fn hoop_with_bead(
    app: &mut App,
    (place, shown): (Pose3, Transform),
    start: DVec3,
) -> (Entity, Entity) {
    let wire = app
        .world_mut()
        .spawn((
            SpaceWire::curve(OnPlane(Circle { radius: 1.0 })),
            WirePlace::in_space(place),
            shown,
        ))
        .id();
    let bead = SpaceBead::new(BeadParams {
        mass: 1.0,
        initial_position: start,
        initial_velocity: DVec3::ZERO,
    })
    .expect("a valid bead");
    let bead = app.world_mut().spawn((bead, OnWire(wire))).id();
    (wire, bead)
}

/// A place whose turn was read from an `f32` rotation (a quaternion whose
/// length is one only to some 1e-7) is taken, made exactly the rotation
/// it is nearest: a hoop so turned 60° about x keeps its bead in the plane
/// of that rotation to 1e-12 m over 1 s. Refused as no rotation, the hoop
/// would be placed by its `f32` `Transform`, whose plane is off by some
/// 1e-8.
#[test]
fn a_turn_read_from_an_f32_rotation_places_its_wire_exactly() {
    let read = Quat::from_axis_angle(Vec3::X, 60f32.to_radians()).as_dquat() * (1.0 + 3e-7);
    assert!((read.length() - 1.0).abs() > 1e-7, "{read:?}");
    let turn = read.normalize();
    let normal = turn * DVec3::Z;
    let start = turn * DVec3::new(0.6, -0.8, 0.0);
    let mut app = app();
    let place = Pose3 {
        origin: DVec3::ZERO,
        rotation: read,
    };
    let (_, bead) = hoop_with_bead(&mut app, (place, Transform::default()), start);
    let (mut out_of_plane, mut moved) = (0.0f64, 0.0f64);
    for _ in 0..1000 {
        app.update();
        let at = space_bead_state(app.world(), bead)
            .expect("a bead")
            .position;
        out_of_plane = out_of_plane.max(at.dot(normal).abs());
        moved = moved.max((at - start).length());
    }
    assert!(moved > 0.3, "the bead swung only {moved} m");
    assert!(
        out_of_plane <= 1e-12,
        "the bead left the rotation's plane by {out_of_plane:e} m"
    );
}

/// A place in space that is not finite, or whose turn is no rotation (a
/// zero quaternion, or one of length 2), is not taken, at spawn or when
/// the game writes it: the hoop stays where its `Transform` (at
/// (0.5, 0, 0), unturned) puts it, its bead on that hoop to 1e-9 m, with
/// no NaN anywhere.
#[test]
fn a_place_in_space_that_places_nothing_leaves_the_wire_at_its_transform() {
    let nan = Pose3 {
        origin: DVec3::new(f64::NAN, 0.0, 0.0),
        rotation: DQuat::IDENTITY,
    };
    let no_turn = Pose3 {
        origin: DVec3::ZERO,
        rotation: DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0),
    };
    let stretched = Pose3 {
        origin: DVec3::ZERO,
        rotation: DQuat::from_xyzw(0.0, 0.0, 0.0, 2.0),
    };
    let centre = DVec3::new(0.5, 0.0, 0.0);
    let transform = Transform::from_xyz(0.5, 0.0, 0.0);
    for bad in [nan, no_turn, stretched] {
        let mut app = app();
        let start = centre + DVec3::new(0.6, -0.8, 0.0);
        let (wire, bead) = hoop_with_bead(&mut app, (bad, transform), start);
        run_for(&mut app, 0.5);
        // Written again by the game.
        app.world_mut().get_mut::<WirePlace<DVec3>>(wire).unwrap().0 = bad;
        run_for(&mut app, 0.5);
        let at = space_bead_state(app.world(), bead)
            .expect("a bead")
            .position;
        let off = ((at - centre).length() - 1.0).abs();
        assert!(off <= 1e-9, "{bad:?}: the bead is {off:e} m off the hoop");
        assert!(
            at.z.abs() <= 1e-9,
            "{bad:?}: the bead left the hoop's plane"
        );
        assert!(app.world().get::<Diverged>(bead).is_none(), "{bad:?}");
        assert_eq!(
            *app.world().get::<Transform>(wire).unwrap(),
            transform,
            "{bad:?}"
        );
    }
}
