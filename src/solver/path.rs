//! A rigid body held on a wire by a point of its own (a path joint), in
//! the plane: the position corrections of extended position-based
//! dynamics (XPBD) that a physics engine's substep applies, as pure
//! functions of the body's state (docs/method.md, "Rigid bodies on
//! wires"). The body's centre of mass `c` and angle `θ` are its
//! coordinates; its anchor `a = c + R(θ) r` (`r` the anchor's offset from
//! the centre of mass in the body's frame) is held on the curve, and where
//! the body turns with the wire, `θ` is held at the wire's direction at
//! the anchor plus the offset it had when the joint began.

use bevy::math::DVec2;

use crate::geometry::ImplicitCurve;

/// A rigid body in the plane as a correction sees it: where its centre of
/// mass is, where its anchor is, and how hard each is to move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PlaneBody {
    /// The centre of mass, world frame.
    pub centre: DVec2,
    /// The anchor, world frame.
    pub anchor: DVec2,
    /// `1 / m` along each axis (0 along an axis the body does not move
    /// along, as an engine's locked axes).
    pub inverse_mass: DVec2,
    /// `1 / I` about the centre of mass (0 for a body that does not turn).
    pub inverse_inertia: f64,
}

/// One row of a body's constraint: its value and its gradient with
/// respect to the centre of mass and the angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BodyRow {
    /// `C`.
    pub value: f64,
    /// `∂C/∂c`.
    pub along_centre: DVec2,
    /// `∂C/∂θ`.
    pub along_angle: f64,
}

/// What one XPBD correction does: the change of the row's multiplier
/// (an impulse times the substep, `λ = J h`), of the centre of mass and of
/// the angle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Correction {
    /// `Δλ`.
    pub lambda: f64,
    /// `Δc`.
    pub centre: DVec2,
    /// `Δθ`.
    pub angle: f64,
}

/// `v` turned a quarter counter-clockwise.
fn perp(v: DVec2) -> DVec2 {
    DVec2::new(-v.y, v.x)
}

/// The anchor's distance from the curve to first order, `C(a) / |∇C(a)|`,
/// as a row of the body: its gradient is the curve's unit normal at the
/// anchor along the centre, and that normal's moment about the centre
/// along the angle. `None`
/// where the curve's gradient vanishes (a singular point) or is not
/// finite.
pub(crate) fn on_curve(curve: &impl ImplicitCurve, body: &PlaneBody) -> Option<BodyRow> {
    let geometry = curve.geometry(body.anchor);
    let length = geometry.normal.length();
    if !(length > 0.0 && length.is_finite() && geometry.c.is_finite()) {
        return None;
    }
    let normal = geometry.normal / length;
    Some(BodyRow {
        value: geometry.c / length,
        along_centre: normal,
        along_angle: normal.dot(perp(body.anchor - body.centre)),
    })
}

/// The angle of the curve's tangent at the anchor, `ψ = atan2(t)` with the
/// tangent `t = ∇C⊥ / |∇C|`, and its gradient with respect to the anchor,
/// `∇ψ = H t / |∇C|` (`H` the Hessian of `C`). `None` at a singular point.
fn tangent_angle(curve: &impl ImplicitCurve, anchor: DVec2) -> Option<(f64, DVec2)> {
    let geometry = curve.geometry(anchor);
    let length = geometry.normal.length();
    if !(length > 0.0 && length.is_finite()) {
        return None;
    }
    let tangent = perp(geometry.normal) / length;
    // The tangent turns as the normal does: dψ = N⊥ · dN / |N|² with
    // dN = H dx, so ∇ψ = H N⊥ / |N|² = H t / |N|.
    let gradient = geometry.hessian * tangent / length;
    Some((tangent.y.atan2(tangent.x), gradient))
}

/// The body's angle less the curve's tangent angle at the anchor and
/// `offset`, wrapped into `(−π, π]`, as a row of the body. `None` at a
/// singular point.
pub(crate) fn turned_with_curve(
    curve: &impl ImplicitCurve,
    body: &PlaneBody,
    angle: f64,
    offset: f64,
) -> Option<BodyRow> {
    let (psi, gradient) = tangent_angle(curve, body.anchor)?;
    let value = wrap(angle - psi - offset);
    // ψ depends on the anchor, which moves with the centre and turns about
    // it: ∂a/∂c = I, ∂a/∂θ = (a − c)⊥.
    Some(BodyRow {
        value,
        along_centre: -gradient,
        along_angle: 1.0 - gradient.dot(perp(body.anchor - body.centre)),
    })
}

/// The tangent angle at the anchor that a body turned with the curve keeps
/// its own angle from: `angle − ψ`, wrapped. `None` at a singular point.
pub(crate) fn turn_offset(curve: &impl ImplicitCurve, body: &PlaneBody, angle: f64) -> Option<f64> {
    let (psi, _) = tangent_angle(curve, body.anchor)?;
    Some(wrap(angle - psi))
}

/// `angle` wrapped into `(−π, π]`.
fn wrap(angle: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let wrapped = angle.rem_euclid(TAU);
    if wrapped > PI { wrapped - TAU } else { wrapped }
}

/// One XPBD correction of `row` (Macklin et al. 2016, eq. 18): with the
/// generalized inverse mass `w = ∂C/∂c · W ∂C/∂c + (∂C/∂θ)² / I` (`W` the
/// inverse mass along each axis) and `α̃ = compliance / h²`,
/// `Δλ = (−C − α̃ λ) / (w + α̃)`, and the body moves by `Δc = W ∂C/∂c Δλ`,
/// `Δθ = ∂C/∂θ Δλ / I`. Nothing moves where `w`
/// and `α̃` vanish (a body that cannot move) or the row is not finite.
pub(crate) fn correct(
    row: &BodyRow,
    body: &PlaneBody,
    lambda: f64,
    compliance: f64,
    h: f64,
) -> Correction {
    let w = (row.along_centre * row.along_centre).dot(body.inverse_mass)
        + row.along_angle * row.along_angle * body.inverse_inertia;
    let tilde = compliance / (h * h);
    let delta = (-row.value - tilde * lambda) / (w + tilde);
    if w + tilde <= 0.0 || !delta.is_finite() {
        return Correction::default();
    }
    Correction {
        lambda: delta,
        centre: row.along_centre * body.inverse_mass * delta,
        angle: row.along_angle * delta * body.inverse_inertia,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Circle, Ellipse};
    use bevy::math::DVec2;

    fn body(centre: DVec2, anchor: DVec2) -> PlaneBody {
        PlaneBody {
            centre,
            anchor,
            inverse_mass: DVec2::splat(0.5),
            inverse_inertia: 2.0,
        }
    }

    /// Rows whose gradients are those of their values where the anchor is
    /// on the curve (the distance row is first order off it): central
    /// differences of `C` over the centre (the anchor moving with it) and
    /// over the angle (the anchor turning about the centre) agree with the
    /// gradients to 1e-7, on an ellipse.
    #[test]
    fn rows_have_the_gradients_of_their_values() {
        let curve = Ellipse { a: 2.0, b: 1.0 };
        let (offset, angle) = (DVec2::new(0.25, -0.4), 0.7);
        let on = DVec2::new(2.0 * 1.1f64.cos(), 1.1f64.sin());
        let centre = on - DVec2::from_angle(angle).rotate(offset);
        let at = |centre: DVec2, angle: f64| {
            body(centre, centre + DVec2::from_angle(angle).rotate(offset))
        };
        let rows: [&dyn Fn(&PlaneBody, f64) -> BodyRow; 2] =
            [&|b, _| on_curve(&curve, b).expect("a row"), &|b, angle| {
                turned_with_curve(&curve, b, angle, 0.3).expect("a row")
            }];
        let e = 1e-6;
        for row in rows {
            let exact = row(&at(centre, angle), angle);
            for axis in [DVec2::X, DVec2::Y] {
                let plus = row(&at(centre + e * axis, angle), angle).value;
                let minus = row(&at(centre - e * axis, angle), angle).value;
                let numeric = (plus - minus) / (2.0 * e);
                assert!(
                    (numeric - exact.along_centre.dot(axis)).abs() <= 1e-7,
                    "∂C/∂c along {axis}: {numeric} against {}",
                    exact.along_centre.dot(axis)
                );
            }
            let plus = row(&at(centre, angle + e), angle + e).value;
            let minus = row(&at(centre, angle - e), angle - e).value;
            let numeric = (plus - minus) / (2.0 * e);
            assert!(
                (numeric - exact.along_angle).abs() <= 1e-7,
                "∂C/∂θ: {numeric} against {}",
                exact.along_angle
            );
        }
    }

    /// A body whose anchor is its centre, off a unit circle by 0.1 along
    /// the radius, with no compliance: one correction puts the anchor on the
    /// circle (to first order exactly: the row is the distance) and leaves
    /// the body's angle alone, since the pull passes through its centre.
    #[test]
    fn a_stiff_correction_puts_a_centred_anchor_on_the_curve() {
        let curve = Circle { radius: 1.0 };
        let start = DVec2::new(0.0, -1.1);
        let b = body(start, start);
        let row = on_curve(&curve, &b).expect("a row");
        let moved = correct(&row, &b, 0.0, 0.0, 1.0 / 360.0);
        let end = start + moved.centre;
        assert!(
            (end.length() - 1.0).abs() <= 1e-12,
            "the anchor ends at {end}"
        );
        assert_eq!(moved.angle, 0.0, "a pull through the centre turns nothing");
    }

    /// A correction keeps momentum's balance: the impulse `Δλ ∂C/∂c`
    /// moves the centre by it over the mass, and the angle by its moment
    /// about the centre over the inertia.
    #[test]
    fn a_correction_moves_the_centre_and_turns_the_body_by_one_impulse() {
        let curve = Circle { radius: 1.0 };
        let (centre, anchor) = (DVec2::new(0.1, -1.3), DVec2::new(0.3, -1.15));
        let b = body(centre, anchor);
        let row = on_curve(&curve, &b).expect("a row");
        let moved = correct(&row, &b, 0.0, 1e-6, 1.0 / 60.0);
        let impulse = row.along_centre * moved.lambda;
        assert!((moved.centre - impulse * b.inverse_mass).length() <= 1e-15);
        let moment = perp(anchor - centre).dot(impulse);
        assert!((moved.angle - moment * b.inverse_inertia).abs() <= 1e-15);
    }

    /// Nothing moves a body with no mass to move, nor one at a singular
    /// point of its curve.
    #[test]
    fn a_body_that_cannot_move_or_a_singular_point_moves_nothing() {
        let curve = Circle { radius: 1.0 };
        let fixed = PlaneBody {
            inverse_mass: DVec2::ZERO,
            inverse_inertia: 0.0,
            ..body(DVec2::new(0.0, -1.2), DVec2::new(0.0, -1.2))
        };
        let row = on_curve(&curve, &fixed).expect("a row");
        assert_eq!(correct(&row, &fixed, 0.0, 0.0, 0.01), Correction::default());
        let centred = body(DVec2::ZERO, DVec2::ZERO);
        assert!(turned_with_curve(&curve, &centred, 0.0, 0.0).is_none());
    }
}
