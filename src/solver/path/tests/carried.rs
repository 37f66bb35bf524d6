//! A joint on a wire that rides a body: the carrier's rows, its push and
//! the pair's momentum.

use super::*;

/// A body on an ellipse that rides a carrier: `carrier` turned by
/// `angle` about its centre of mass `centre`, its origin 0.1 m from it.
fn carrier_at(centre: DVec2, angle: f64) -> PlaneBody {
    PlaneBody {
        centre,
        angle,
        arm: DVec2::new(-0.1, 0.05),
        inverse_mass: DVec2::splat(0.25),
        inverse_inertia: 0.5,
    }
}

/// The held body whose anchor (off its centre, the body turned) is at
/// the local point `local` of `wire` as `carrier` carries it.
fn held_on(
    wire: &PlaneWire<'_, impl ImplicitCurve>,
    carrier: &PlaneBody,
    local: DVec2,
) -> Held<PlaneBody> {
    let anchor = wire.carried_by(Some(carrier)).curve.pose.to_world(local);
    let (arm, angle) = (DVec2::new(0.25, -0.4), 0.7);
    Held {
        body: body(anchor - DVec2::from_angle(angle).rotate(arm), angle, arm),
        carrier: Some(*carrier),
    }
}

/// On a wire that rides a body, each row is a function of where the held
/// body is against the carrier alone: its gradient along the carrier's
/// coordinates, the held body's carried across, agrees with central
/// differences of its value to 1e-7, on an ellipse placed on the carrier
/// and turned, the held body turned with it.
#[test]
fn a_carried_row_has_the_gradients_of_its_values_along_the_carrier() {
    let curve = Ellipse { a: 2.0, b: 1.0 };
    let wire = PlaneWire {
        curve: Placed {
            curve: &curve,
            pose: Pose::new(DVec2::new(0.3, -0.2), 0.4),
        },
        turned: Some(0.3),
        travel: 1.0,
    };
    let (centre, angle) = (DVec2::new(0.5, 0.7), 0.9);
    let at = held_on(
        &wire,
        &carrier_at(centre, angle),
        DVec2::new(2.0 * 1.1f64.cos(), 1.1f64.sin()),
    );
    let rows = wire.held_at(&at).expect("rows");
    assert_eq!(rows.len(), 2);
    let offset = centre - at.body.centre;
    let value = |i: usize, centre: DVec2, angle: f64| {
        let moved = Held {
            carrier: Some(carrier_at(centre, angle)),
            ..at
        };
        wire.held_at(&moved).expect("rows").rows[i].value
    };
    for (i, row) in rows.iter().enumerate() {
        let carried = row.carried(offset);
        assert_plane_gradient(&carried, |dc, da| value(i, centre + dc, angle + da));
    }
}

/// SHAKE's and RATTLE's steps on a wire that rides a free body put the
/// held body and the carrier back together: the row met to 1e-14, the
/// anchor's velocity along the wire's normal the carrier's there to
/// 1e-15, and the pair's momentum, and its angular momentum about the
/// origin, what the free substep left (the joint's impulse on the
/// carrier is the body's reversed, about the same points), to 1e-15.
#[test]
fn a_carried_wire_takes_the_joints_push_and_keeps_the_pairs_momentum() {
    let curve = Circle { radius: 1.0 };
    let wire = PlaneWire {
        curve: Placed {
            curve: &curve,
            pose: Pose::new(DVec2::new(0.1, 0.0), 0.2),
        },
        turned: None,
        travel: 1.0,
    };
    let start = held_on(
        &wire,
        &carrier_at(DVec2::new(0.1, 0.2), 0.3),
        DVec2::new(0.6, -0.8),
    );
    let carrier = start.carrier.expect("a carrier");
    let rows = wire.held_at(&start).expect("rows");
    let predicted = Held {
        body: start.body.displaced(DVec2::new(0.05, -0.03), 0.02),
        carrier: Some(carrier.displaced(DVec2::new(-0.01, 0.02), -0.01)),
    };
    let projected =
        project(&rows, predicted, 0.0, 1e-14, |h| wire.held_at(h)).expect("a projection");
    assert!(projected.converged);
    let after = wire.held_at(&projected.body).expect("rows");
    assert!(after.iter().all(|r| r.value.abs() <= 1e-14));
    let (p, tau) = projected.impulse.body;
    let (q, sigma) = projected.impulse.carrier.expect("the carrier's impulse");
    assert!((p + q).length() <= 1e-15, "momentum changed by {}", p + q);
    let about_origin = tau + start.body.centre.perp_dot(p) + sigma + carrier.centre.perp_dot(q);
    assert!(
        about_origin.abs() <= 1e-15,
        "angular momentum changed by {about_origin:e}"
    );
    // Each body moved by its own part: Δc = M⁻¹ p.
    let carried = projected.body.carrier.expect("a carrier");
    let moved = carried.centre - predicted.carrier.expect("a carrier").centre;
    assert!((moved - 0.25 * q).length() <= 1e-15);

    let v = Held {
        body: PlaneVelocity {
            linear: DVec2::new(1.0, 0.4),
            spin: -0.7,
        },
        carrier: Some(PlaneVelocity {
            linear: DVec2::new(-0.3, 0.2),
            spin: 0.5,
        }),
    };
    let (kept, impulse) = project_velocity(&after, &projected.body, v, PlaneVelocity::default())
        .expect("a projection");
    let rate = after.rates(&kept)[0];
    assert!(
        rate.abs() <= 1e-15,
        "the anchor leaves the wire at {rate:e} m/s"
    );
    let momentum =
        |v: &Held<PlaneVelocity>| 2.0 * v.body.linear + 4.0 * v.carrier.expect("a carrier").linear;
    assert!((momentum(&kept) - momentum(&v)).length() <= 1e-15);
    let (p, _) = impulse.body;
    let (q, _) = impulse.carrier.expect("the carrier's impulse");
    assert!((p + q).length() <= 1e-15);
}

/// On a wire in space that rides a body, every row (on the curve, and of
/// each rotation mode) has along the carrier's coordinates the held
/// body's gradient carried across: central differences over the
/// carrier's centre and over a turn of it about each world axis (applied
/// on the left) agree to 1e-6, on a helix placed on a turned carrier.
#[test]
fn carried_space_rows_have_the_gradients_of_their_values_along_the_carrier() {
    let (helix, pose) = helix_on_a_slant();
    let carrier_at = |centre: DVec3, rotation: DQuat| SpaceBody {
        arm: DVec3::new(-0.1, 0.2, 0.05),
        inverse_mass: DVec3::splat(0.25),
        ..space_body(centre, rotation, DVec3::ZERO)
    };
    let (centre, turned) = (
        DVec3::new(0.3, 0.1, -0.2),
        DQuat::from_euler(bevy::math::EulerRot::XYZ, -0.2, 0.4, 0.3),
    );
    let carrier = carrier_at(centre, turned);
    let placed = Pose3 {
        origin: carrier.anchor(),
        rotation: carrier.rotation,
    }
    .compose(&pose);
    let on = on_the_helix(&placed);
    let arm = DVec3::new(0.2, -0.3, 0.1);
    let rotation = DQuat::from_euler(bevy::math::EulerRot::XYZ, 0.3, -0.5, 1.1);
    let start = space_body(on - rotation * arm, rotation, arm);
    for turn in EVERY_TURN {
        let wire = turned_off_its_frame(&helix, pose, turn, &start, Some(&carrier));
        let at = |carrier: SpaceBody| Held {
            body: start,
            carrier: Some(carrier),
        };
        let rows = wire.held_at(&at(carrier)).expect("rows");
        let value = |c: SpaceBody, i: usize| wire.held_at(&at(c)).expect("rows").rows[i].value;
        let offset = carrier.centre - start.centre;
        for (i, row) in rows.iter().enumerate() {
            let what = format!("{turn:?}, row {i} along the carrier");
            assert_space_gradient(&row.carried(offset), &what, |dc, turn| {
                value(
                    carrier_at(centre + dc, DQuat::from_scaled_axis(turn) * turned),
                    i,
                )
            });
        }
    }
}
