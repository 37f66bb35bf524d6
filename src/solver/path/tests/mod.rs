use super::*;
use crate::geometry::{
    Circle, Ellipse, Helix, ImplicitCurve, Line, Placed, Pose, Pose3, SpaceShape, Spline,
    SplineKind, SplineSpec,
};
use bevy::math::{DMat3, DQuat, DVec2, DVec3};

fn body(centre: DVec2, angle: f64, arm: DVec2) -> PlaneBody {
    PlaneBody {
        centre,
        angle,
        arm,
        inverse_mass: DVec2::splat(0.5),
        inverse_inertia: 2.0,
    }
}

fn rows_of(list: &[BodyRow<PlaneBody>]) -> Rows<PlaneBody> {
    let mut rows = Rows::default();
    for row in list {
        rows.push(*row);
    }
    rows
}

/// Rows whose gradients are those of their values where the anchor is on
/// the curve (the distance row is first order off it): central
/// differences of `C` over the centre (the anchor moving with it) and over
/// the angle (the anchor turning about the centre) agree with the
/// gradients to 1e-7, on an ellipse.
#[test]
fn rows_have_the_gradients_of_their_values() {
    let curve = Ellipse { a: 2.0, b: 1.0 };
    let (arm, angle) = (DVec2::new(0.25, -0.4), 0.7);
    let on = DVec2::new(2.0 * 1.1f64.cos(), 1.1f64.sin());
    let at = |centre: DVec2, angle: f64| body(centre, angle, arm);
    let centre = on - DVec2::from_angle(angle).rotate(arm);
    let rows: [&dyn Fn(&PlaneBody) -> BodyRow<PlaneBody>; 2] =
        [&|b| on_curve(&curve, b).expect("a row"), &|b| {
            turned_with_curve(&curve, b, 0.3).expect("a row")
        }];
    for row in rows {
        let exact = row(&at(centre, angle));
        assert_plane_gradient(&exact, |dc, da| row(&at(centre + dc, angle + da)).value);
    }
}

/// Asserts that central differences of `value` (a row's value with the
/// body's centre moved by `dc` and its angle by `da`) agree with `row`'s
/// gradient to 1e-7, along each axis and the angle.
fn assert_plane_gradient(row: &BodyRow<PlaneBody>, value: impl Fn(DVec2, f64) -> f64) {
    let e = 1e-6;
    for axis in [DVec2::X, DVec2::Y] {
        let numeric = (value(e * axis, 0.0) - value(-e * axis, 0.0)) / (2.0 * e);
        let exact = row.along_centre.dot(axis);
        assert!(
            (numeric - exact).abs() <= 1e-7,
            "∂C/∂c along {axis}: {numeric} against {exact}"
        );
    }
    let numeric = (value(DVec2::ZERO, e) - value(DVec2::ZERO, -e)) / (2.0 * e);
    assert!(
        (numeric - row.along_angle).abs() <= 1e-7,
        "∂C/∂θ: {numeric} against {}",
        row.along_angle
    );
}

/// SHAKE's step: a body off a unit circle, its anchor off its centre, is
/// put back on it to 1e-14 m, moved only along the row's gradient where
/// the substep began (its centre along the start normal over its mass,
/// its angle by that normal's moment over its inertia, one multiplier for
/// both).
#[test]
fn a_projection_puts_the_anchor_on_the_curve_along_the_start_gradient() {
    let curve = Circle { radius: 1.0 };
    let arm = DVec2::new(0.2, 0.1);
    let start = body(DVec2::new(0.0, -1.0) - arm, 0.0, arm);
    let start_rows = rows_of(&[on_curve(&curve, &start).expect("a row")]);
    let predicted = PlaneBody {
        centre: start.centre + DVec2::new(0.05, -0.03),
        angle: 0.02,
        ..start
    };
    let projected = project(&start_rows, Held::alone(predicted), 0.0, 1e-15, |b| {
        Some(rows_of(&[on_curve(&curve, &b.body)?]))
    })
    .expect("a projection");
    assert!(projected.converged);
    let projected_body = projected.body.body;
    let off = (projected_body.anchor().length() - 1.0).abs();
    assert!(off <= 1e-14, "the anchor is {off:e} m off the circle");
    let g = start_rows.iter().next().expect("a row");
    let moved = projected_body.centre - predicted.centre;
    let expected = g.along_centre * start.inverse_mass * projected.lambda[0];
    assert!(
        (moved - expected).length() <= 1e-15,
        "{moved} against {expected}"
    );
    let turned = projected_body.angle - predicted.angle;
    let expected = g.along_angle * start.inverse_inertia * projected.lambda[0];
    assert!((turned - expected).abs() <= 1e-15);
}

/// A compliant row is met as `C + α̃ λ = 0`: it yields in proportion to
/// its multiplier, to 1e-15.
#[test]
fn a_compliant_projection_yields_by_its_multiplier() {
    let curve = Line;
    let start = body(DVec2::ZERO, 0.0, DVec2::ZERO);
    let start_rows = rows_of(&[on_curve(&curve, &start).expect("a row")]);
    let predicted = body(DVec2::new(0.3, -0.1), 0.0, DVec2::ZERO);
    let compliance = 2.0;
    let projected = project(
        &start_rows,
        Held::alone(predicted),
        compliance,
        1e-15,
        |b| Some(rows_of(&[on_curve(&curve, &b.body)?])),
    )
    .expect("a projection");
    let c = projected.body.body.centre.y;
    assert!((c + compliance * projected.lambda[0]).abs() <= 1e-15);
    // w = 1/2, so C = −0.1 + λ/2 = −2λ: λ = 0.04, C = −0.08.
    assert!((c + 0.08).abs() <= 1e-15, "the row holds at {c}");
}

/// RATTLE's velocity step leaves a body on a circle moving along it: the
/// row's rate is the wire's (here still) to 1e-15, and the kinetic energy
/// only falls (the part taken is the part along the normal).
#[test]
fn a_velocity_projection_takes_off_the_normal_part() {
    let curve = Circle { radius: 1.0 };
    let arm = DVec2::new(0.1, 0.0);
    let b = body(DVec2::new(0.0, -1.0) - arm, 0.0, arm);
    let rows = rows_of(&[on_curve(&curve, &b).expect("a row")]);
    let v = PlaneVelocity {
        linear: DVec2::new(1.0, 0.4),
        spin: -0.7,
    };
    let energy = |v: PlaneVelocity| {
        0.5 * (v.linear.length_squared() / 0.5 + v.spin * v.spin / b.inverse_inertia)
    };
    let (after, _) = project_velocity(
        &rows,
        &Held::alone(b),
        Held::alone(v),
        PlaneVelocity::default(),
    )
    .expect("a projection");
    let after = after.body;
    let rate = rows.iter().next().expect("a row").rate(after);
    assert!(
        rate.abs() <= 1e-15,
        "the anchor leaves the circle at {rate:e} m/s"
    );
    assert!(energy(after) < energy(v));
}

/// A drive with room to spare moves the anchor along the wire by its
/// shift, the held row kept; a bounded one gives exactly its bound: a
/// body of mass 2 held at its centre on a line, predicted 0.1 m along and
/// 0.05 m off it, is moved 0.3 m along by an unbounded drive asking for
/// that, and `bound / m` beyond its prediction by a bounded one.
#[test]
fn a_drive_moves_by_its_shift_or_gives_its_bound() {
    let curve = Line;
    let previous = body(DVec2::ZERO, 0.0, DVec2::ZERO);
    let start = rows_of(&[on_curve(&curve, &previous).expect("a row")]);
    let along = along_curve(&curve, &previous, -1.0).expect("a row");
    assert_eq!(along.along_centre, DVec2::X, "a line's own direction is +x");
    let predicted = body(DVec2::new(0.1, 0.05), 0.0, DVec2::ZERO);
    let drive = |bound: f64| Drive {
        direction: along.along_centre,
        from: previous.anchor(),
        shift: 0.3,
        bound,
        carrier: None,
    };
    let rows_at = |b: &Held<PlaneBody>| Some(rows_of(&[on_curve(&curve, &b.body)?]));
    let (free, multiplier) = project_driven(
        &start,
        &Held::alone(previous),
        &drive(1.0),
        Held::alone(predicted),
        0.0,
        1e-15,
        rows_at,
    )
    .expect("a projection");
    assert!((free.body.body.centre - DVec2::new(0.3, 0.0)).length() <= 1e-15);
    // The body moved 0.2 m along at 1/m = 1/2: λ = 0.4.
    assert!(
        (multiplier - 0.4).abs() <= 1e-15,
        "a multiplier of {multiplier}"
    );
    let (bounded, multiplier) = project_driven(
        &start,
        &Held::alone(previous),
        &drive(0.1),
        Held::alone(predicted),
        0.0,
        1e-15,
        rows_at,
    )
    .expect("a projection");
    assert_eq!(multiplier, 0.1);
    assert!((bounded.body.body.centre - DVec2::new(0.15, 0.0)).length() <= 1e-15);
}

/// Past the end of an open curve the end row is positive and points out:
/// on a straight open spline from the origin to (2, 0), a point beyond
/// its right end is past it by its distance along the end's tangent, to
/// 1e-12, with the row pointing along +x; one before its left end, along
/// −x; one between the ends is not past either.
#[test]
fn past_an_end_the_row_points_out() {
    let spec = SplineSpec {
        kind: SplineKind::CatmullRom,
        points: vec![DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(2.0, 0.0)],
        closed: false,
    };
    let curve = Spline::new(spec).expect("a spline");
    let at = |x: f64| body(DVec2::new(x, 0.1), 0.0, DVec2::ZERO);
    let right = past_end(&curve, &at(2.5)).expect("a row");
    assert!(
        (right.value - 0.5).abs() <= 1e-12,
        "past by {}",
        right.value
    );
    assert!((right.along_centre - DVec2::X).length() <= 1e-12);
    let left = past_end(&curve, &at(-0.25)).expect("a row");
    assert!((left.value - 0.25).abs() <= 1e-12, "past by {}", left.value);
    assert!((left.along_centre + DVec2::X).length() <= 1e-12);
    assert!(past_end(&curve, &at(1.5)).expect("a row").value < 0.0);
    assert!(past_end(&Circle { radius: 1.0 }, &at(1.5)).is_none());
}

/// Nothing moves a body at a singular point of its curve: no row.
#[test]
fn a_singular_point_gives_no_row() {
    let curve = Circle { radius: 1.0 };
    let centred = body(DVec2::ZERO, 0.0, DVec2::ZERO);
    assert!(on_curve(&curve, &centred).is_none());
    assert!(turned_with_curve(&curve, &centred, 0.0).is_none());
    assert!(along_curve(&curve, &centred, 1.0).is_none());
}

/// A body in space of mass 2 and inertia diag(0.5, 1, 2) turned by
/// `rotation`, centred at `centre`, its anchor at `arm`.
fn space_body(centre: DVec3, rotation: DQuat, arm: DVec3) -> SpaceBody {
    let inertia = DMat3::from_diagonal(DVec3::new(0.5, 1.0, 2.0));
    let world = DMat3::from_quat(rotation);
    SpaceBody {
        centre,
        rotation,
        arm,
        inverse_mass: DVec3::splat(0.5),
        inverse_inertia: world * inertia.inverse() * world.transpose(),
    }
}

/// No rotation held, and each of the modes.
const EVERY_TURN: [Option<SpaceTurn>; 6] = [
    None,
    Some(SpaceTurn::AroundTangent),
    Some(SpaceTurn::AroundNormal),
    Some(SpaceTurn::AroundBinormal),
    Some(SpaceTurn::ToPath),
    Some(SpaceTurn::Fixed),
];

/// A helix of radius 1.5 m and pitch 2 m, and a pose turning it off every
/// axis.
fn helix_on_a_slant() -> (SpaceShape, Pose3) {
    let helix = SpaceShape::curve(Helix {
        radius: 1.5,
        pitch: 2.0,
    });
    let pose = Pose3::from_axis_angle(DVec3::new(0.1, -0.2, 0.3), DVec3::new(1.0, 2.0, 0.5), 0.7)
        .expect("a pose");
    (helix, pose)
}

/// The point of [`helix_on_a_slant`]'s helix at 0.9 rad, placed by `pose`.
fn on_the_helix(pose: &Pose3) -> DVec3 {
    let theta: f64 = 0.9;
    pose.to_world(DVec3::new(
        1.5 * theta.cos(),
        2.0 * theta / std::f64::consts::TAU,
        1.5 * theta.sin(),
    ))
}

/// `shape` at `pose` (on `carrier`, if any) holding `start` turned as
/// `turn` says, its alignment 0.2 rad about y from the frame where it is,
/// so the rows are not zero.
fn turned_off_its_frame<'a>(
    shape: &'a SpaceShape,
    pose: Pose3,
    turn: Option<SpaceTurn>,
    start: &SpaceBody,
    carrier: Option<&SpaceBody>,
) -> SpaceWireAt<'a> {
    let wire = SpaceWireAt {
        shape,
        pose,
        hint: f64::NAN,
        alignment: None,
    };
    let frame = |turn| {
        wire.carried_by(carrier)
            .frame(start, turn)
            .expect("a frame")
    };
    SpaceWireAt {
        alignment: turn.map(|turn| Alignment {
            turn,
            axes: (start.rotation.inverse() * frame(turn) * DQuat::from_rotation_y(0.2))
                .normalize(),
        }),
        ..wire
    }
}

/// The rows in space have the gradients of their values where the anchor
/// is on the curve: central differences over the centre (the anchor
/// moving with it) and over a turn of the body about each world axis
/// (applied on the left) agree with every row's gradient to 1e-6, on a
/// helix, for the rows on the curve and those of every rotation mode
/// (whose gradients carry the frame's turn along the curve).
#[test]
fn space_rows_have_the_gradients_of_their_values() {
    let (helix, pose) = helix_on_a_slant();
    let arm = DVec3::new(0.2, -0.3, 0.1);
    let rotation = DQuat::from_euler(bevy::math::EulerRot::XYZ, 0.3, -0.5, 1.1);
    let at = |centre: DVec3, rotation: DQuat| space_body(centre, rotation, arm);
    let centre = on_the_helix(&pose) - rotation * arm;
    let start = at(centre, rotation);
    for turn in EVERY_TURN {
        let wire = turned_off_its_frame(&helix, pose, turn, &start, None);
        let rows = wire.held(&start).expect("rows");
        let value = |b: &SpaceBody, i: usize| wire.held(b).expect("rows").rows[i].value;
        for (i, row) in rows.iter().enumerate() {
            assert_space_gradient(row, &format!("{turn:?}, row {i}"), |dc, turn| {
                value(
                    &at(centre + dc, DQuat::from_scaled_axis(turn) * rotation),
                    i,
                )
            });
        }
    }
}

/// Asserts that central differences of `value` (a row's value with the
/// body's centre moved by `dc` and the body turned by the world rotation
/// vector `turn`, on the left) agree with `row`'s gradient to 1e-6, along
/// and about each axis; `what` names the row.
fn assert_space_gradient(
    row: &BodyRow<SpaceBody>,
    what: &str,
    value: impl Fn(DVec3, DVec3) -> f64,
) {
    let e = 1e-6;
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        let numeric = (value(e * axis, DVec3::ZERO) - value(-e * axis, DVec3::ZERO)) / (2.0 * e);
        let exact = row.along_centre.dot(axis);
        assert!(
            (numeric - exact).abs() <= 1e-6,
            "{what}: ∂C/∂c along {axis}: {numeric} against {exact}"
        );
        let numeric = (value(DVec3::ZERO, e * axis) - value(DVec3::ZERO, -e * axis)) / (2.0 * e);
        let exact = row.along_angle.dot(axis);
        assert!(
            (numeric - exact).abs() <= 1e-6,
            "{what}: ∂C/∂θ about {axis}: {numeric} against {exact}"
        );
    }
}

/// SHAKE's step in space: a body on a helix, turned with its frame, moved
/// off its rows and turned by a substep, is put back on all five to
/// 1e-12, along the rows' gradients where it began.
#[test]
fn a_projection_in_space_meets_every_row() {
    let helix = SpaceShape::curve(Helix {
        radius: 2.0,
        pitch: 3.0,
    });
    let arm = DVec3::new(0.0, -0.2, 0.0);
    let anchor = DVec3::new(2.0, 0.0, 0.0);
    let mut wire = SpaceWireAt {
        shape: &helix,
        pose: Pose3::default(),
        hint: f64::NAN,
        alignment: None,
    };
    let probe = space_body(anchor, DQuat::IDENTITY, DVec3::ZERO);
    let frame = wire.frame(&probe, SpaceTurn::ToPath).expect("a frame");
    let start = space_body(anchor - frame * arm, frame, arm);
    wire.alignment = Some(Alignment {
        turn: SpaceTurn::ToPath,
        axes: DQuat::IDENTITY,
    });
    let rows = wire.held(&start).expect("rows");
    assert_eq!(rows.len(), 5);
    assert!(rows.iter().all(|r| r.value.abs() <= 1e-12));
    let predicted = start.displaced(DVec3::new(0.02, 0.05, -0.03), DVec3::new(0.01, -0.02, 0.03));
    let projected = project(&rows, Held::alone(predicted), 0.0, 1e-12, |b| {
        wire.held(&b.body)
    })
    .expect("a projection");
    assert!(projected.converged);
    let moved_body = projected.body.body;
    let after = wire.held(&moved_body).expect("rows");
    let worst = after.iter().fold(0.0f64, |m, r| m.max(r.value.abs()));
    assert!(worst <= 1e-12, "a row is {worst:e} off");
    // Moved along the start gradients: Δc = M⁻¹ Gᵀ λ.
    let (p, _) = rows.impulse(&projected.lambda).body;
    let moved = moved_body.centre - predicted.centre;
    assert!(
        (moved - 0.5 * p).length() <= 1e-14,
        "{moved} against {}",
        0.5 * p
    );
}

mod carried;
