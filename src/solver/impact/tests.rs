use bevy::math::{DVec2, DVec3};

use super::*;

// The beads of these tests each held by its own rows alone, free or by a
// freedom: a strike's answer written out by hand for them, as the island
// writes it for beads joined by constraints.

/// The directions a bead's velocity may change in at a strike: any (a free
/// bead), along one line (a bead on a curve), or across one direction (a
/// bead on a surface in space; a bead on a rod from a fixed pin).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Freedom<V = DVec2> {
    kind: FreedomKind,
    axis: V,
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum FreedomKind {
    #[default]
    Free,
    Along,
    Across,
}

impl<V: Coordinates> Freedom<V> {
    /// A free bead: it takes a strike in full.
    fn free() -> Self {
        Self {
            kind: FreedomKind::Free,
            axis: V::ZERO,
        }
    }

    /// A bead that moves along `tangent` only (its length does not matter).
    fn along(tangent: V) -> Result<Self, ImpactError> {
        Ok(Self {
            kind: FreedomKind::Along,
            axis: unit(tangent)?,
        })
    }

    /// A bead that moves in every direction but `normal`'s (its length
    /// does not matter).
    fn across(normal: V) -> Result<Self, ImpactError> {
        Ok(Self {
            kind: FreedomKind::Across,
            axis: unit(normal)?,
        })
    }

    /// The part of `v` the bead can take: `P v`.
    fn project(&self, v: V) -> V {
        match self.kind {
            FreedomKind::Free => v,
            FreedomKind::Along => self.axis * self.axis.dot(v),
            FreedomKind::Across => v - self.axis * self.axis.dot(v),
        }
    }
}

/// A bead as a strike sees it: its inverse mass and its [`Freedom`].
#[derive(Clone, Copy, Debug, PartialEq)]
struct ImpactBead<V = DVec2> {
    /// `1 / m`.
    inverse_mass: f64,
    /// The directions it may move in.
    freedom: Freedom<V>,
}

impl<V: Coordinates> Response<V> {
    /// The answer of two beads each held by its own rows alone (free, or
    /// by its [`Freedom`]): `∓P n̂ / m`.
    fn through(touch: &Touch<V>, beads: &[ImpactBead<V>]) -> Result<Self, ImpactError> {
        let bead = |i: usize| {
            beads.get(i).ok_or(ImpactError::MissingBead {
                bead: i,
                beads: beads.len(),
            })
        };
        let (a, b) = (bead(touch.a)?, bead(touch.b)?);
        let along = |d: V| {
            vec![
                (touch.a, -a.freedom.project(d) * a.inverse_mass),
                (touch.b, b.freedom.project(d) * b.inverse_mass),
            ]
        };
        let tangents = if touch.friction > 0.0 {
            touch.tangents().into_iter().map(along).collect()
        } else {
            Vec::new()
        };
        Ok(Self::new(touch, along(touch.normal)).with_tangents(tangents))
    }
}

/// Free beads in a row along x, `spacing` apart, each of radius
/// `spacing / 2`, so that neighbours touch.
fn row(masses: &[f64], spacing: f64, e: f64) -> (Vec<ImpactBead>, Vec<Touch>) {
    let beads = masses
        .iter()
        .map(|m| ImpactBead {
            inverse_mass: 1.0 / m,
            freedom: Freedom::free(),
        })
        .collect();
    let at = |i: usize| DVec2::new(spacing * i as f64, 0.0);
    let touches = (1..masses.len())
        .map(|i| {
            Touch::between(
                (i - 1, at(i - 1), spacing / 2.0),
                (i, at(i), spacing / 2.0),
                e,
            )
            .expect("apart")
        })
        .collect();
    (beads, touches)
}

fn energy<V: Coordinates>(beads: &[ImpactBead<V>], v: &[V]) -> f64 {
    beads
        .iter()
        .zip(v)
        .map(|(b, v)| 0.5 * v.dot(*v) / b.inverse_mass)
        .sum()
}

fn momentum(beads: &[ImpactBead], v: &[DVec2]) -> DVec2 {
    beads.iter().zip(v).map(|(b, v)| *v / b.inverse_mass).sum()
}

/// The responses of `touches` between beads held by their freedoms.
fn responses<V: Coordinates>(beads: &[ImpactBead<V>], touches: &[Touch<V>]) -> Vec<Response<V>> {
    touches
        .iter()
        .map(|t| Response::through(t, beads).expect("beads named"))
        .collect()
}

fn resolve_all<V: Coordinates>(
    beads: &[ImpactBead<V>],
    touches: &[Touch<V>],
    v: &mut [V],
) -> Result<Vec<Strike>, ImpactError> {
    let mut strikes = Vec::new();
    resolve_impacts(touches, &responses(beads, touches), v, &mut strikes)?;
    Ok(strikes)
}

fn resolve(beads: &[ImpactBead], touches: &[Touch], v: &mut [DVec2]) -> Vec<Strike> {
    resolve_all(beads, touches, v).expect("settles")
}

#[test]
fn equal_masses_exchange_velocities_and_masses_one_and_three_part_as_in_one_dimension() {
    let (beads, touches) = row(&[1.0, 1.0], 0.1, 1.0);
    let mut v = [DVec2::new(2.0, 0.0), DVec2::new(-0.5, 0.0)];
    resolve(&beads, &touches, &mut v);
    assert!((v[0] - DVec2::new(-0.5, 0.0)).length() <= 1e-12, "{v:?}");
    assert!((v[1] - DVec2::new(2.0, 0.0)).length() <= 1e-12, "{v:?}");

    let (m1, m2, u1, u2) = (1.0, 3.0, 2.0, -0.5);
    let (beads, touches) = row(&[m1, m2], 0.1, 1.0);
    let mut v = [DVec2::new(u1, 0.0), DVec2::new(u2, 0.0)];
    resolve(&beads, &touches, &mut v);
    let v1 = ((m1 - m2) * u1 + 2.0 * m2 * u2) / (m1 + m2);
    let v2 = ((m2 - m1) * u2 + 2.0 * m1 * u1) / (m1 + m2);
    assert!((v[0].x - v1).abs() <= 1e-12, "{} against {v1}", v[0].x);
    assert!((v[1].x - v2).abs() <= 1e-12, "{} against {v2}", v[1].x);
}

#[test]
fn at_restitution_zero_the_pair_moves_on_together_losing_half_mu_v_squared() {
    let (m1, m2, u1, u2) = (1.0, 3.0, 2.0, -0.5);
    let (beads, touches) = row(&[m1, m2], 0.1, 0.0);
    let mut v = [DVec2::new(u1, 0.0), DVec2::new(u2, 0.0)];
    let before = energy(&beads, &v);
    let strikes = resolve(&beads, &touches, &mut v);
    let common = (m1 * u1 + m2 * u2) / (m1 + m2);
    assert!((v[0].x - common).abs() <= 1e-12 && (v[1].x - common).abs() <= 1e-12);
    let mu = m1 * m2 / (m1 + m2);
    let lost = before - energy(&beads, &v);
    let expected = 0.5 * mu * (u1 - u2) * (u1 - u2);
    assert!(
        (lost - expected).abs() <= 1e-12,
        "{lost} against {expected}"
    );
    assert_eq!(strikes.len(), 1);
    assert!(!strikes[0].bounced);
}

/// Newton's cradle of five equal balls at `e = 1`: `k` balls in at `v`
/// send exactly `k` out at `v`, the rest at rest, momentum and energy
/// kept to 1e-12.
#[test]
fn the_cradle_sends_out_as_many_balls_as_came_in() {
    let v0 = 1.3;
    for k in 1..=4 {
        let (beads, touches) = row(&[1.0; 5], 0.05, 1.0);
        let mut v: Vec<DVec2> = (0..5)
            .map(|i| DVec2::new(if i < k { v0 } else { 0.0 }, 0.0))
            .collect();
        let (p0, e0) = (momentum(&beads, &v), energy(&beads, &v));
        resolve(&beads, &touches, &mut v);
        for (i, v) in v.iter().enumerate() {
            let expected = if i >= 5 - k { v0 } else { 0.0 };
            assert!(
                (v.x - expected).abs() <= 1e-12 * v0 && v.y == 0.0,
                "{k} in: ball {i} leaves at {v}, not {expected}"
            );
        }
        assert!((momentum(&beads, &v) - p0).length() <= 1e-12);
        assert!((energy(&beads, &v) - e0).abs() <= 1e-12);
    }
}

#[test]
fn three_balls_struck_at_once_from_both_sides_send_the_outer_two_away() {
    let v0 = 2.0;
    let (beads, touches) = row(&[1.0; 3], 0.05, 1.0);
    let mut v = vec![DVec2::new(v0, 0.0), DVec2::ZERO, DVec2::new(-v0, 0.0)];
    let strikes = resolve(&beads, &touches, &mut v);
    assert!((v[0].x + v0).abs() <= 1e-12, "{v:?}");
    assert!(v[1].x.abs() <= 1e-12, "{v:?}");
    assert!((v[2].x - v0).abs() <= 1e-12, "{v:?}");
    assert_eq!(strikes.len(), 3, "{strikes:?}");
}

/// Beads held to lines at angles to the line between them, in the
/// plane and in space: at `e = 1` the pair separates at the speed it
/// closed with and the energy is kept, at `e = ½` it separates at half
/// that speed; each bead's velocity stays along its line.
#[test]
fn beads_held_to_their_wires_strike_with_the_speed_along_the_normal_they_can_take() {
    for (k, e) in [(0, 1.0), (1, 0.5), (2, 1.0), (3, 0.0)] {
        let angle = 0.3 + 0.4 * k as f64;
        let ta = DVec3::new(angle.cos(), angle.sin(), 0.2 * k as f64);
        let tb = DVec3::new(-0.2, 1.0, angle);
        let beads = [
            ImpactBead {
                inverse_mass: 1.0 / 1.5,
                freedom: Freedom::along(ta).expect("a tangent"),
            },
            ImpactBead {
                inverse_mass: 1.0 / 0.7,
                freedom: Freedom::across(tb).expect("a normal"),
            },
        ];
        let xa = DVec3::ZERO;
        let xb = DVec3::new(0.3, 0.1, -0.05);
        let r = xb.length() / 2.0;
        let touch = Touch::between((0, xa, r), (1, xb, r), e).expect("apart");
        let mut v = [
            beads[0].freedom.project(DVec3::new(2.0, 1.0, 0.5)),
            beads[1].freedom.project(DVec3::new(-1.0, 0.3, 0.2)),
        ];
        let u = touch.normal_speed(&v);
        assert!(u < 0.0, "the pair must close");
        let before = energy(&beads, &v);
        resolve_all(&beads, &[touch], &mut v).expect("settles");
        assert!((touch.normal_speed(&v) + e * u).abs() <= 1e-12, "e = {e}");
        assert!((beads[0].freedom.project(v[0]) - v[0]).length() <= 1e-12);
        assert!((beads[1].freedom.project(v[1]) - v[1]).length() <= 1e-12);
        if e == 1.0 {
            assert!((energy(&beads, &v) - before).abs() <= 1e-12 * before);
        } else {
            assert!(energy(&beads, &v) < before);
        }
    }
}

/// Equal free balls in space, one at rest: at `e = 1` they leave at
/// right angles, the struck one along the line of centres.
#[test]
fn an_oblique_strike_of_equal_balls_sends_them_off_at_right_angles() {
    let beads = [ImpactBead {
        inverse_mass: 1.0,
        freedom: Freedom::<DVec3>::free(),
    }; 2];
    let xb = DVec3::new(0.08, 0.05, 0.03);
    let touch =
        Touch::between((0, DVec3::ZERO, 0.05), (1, xb, xb.length() - 0.05), 1.0).expect("apart");
    let mut v = [DVec3::new(3.0, 0.0, 0.0), DVec3::ZERO];
    resolve_all(&beads, &[touch], &mut v).expect("settles");
    assert!(v[0].dot(v[1]).abs() <= 1e-12, "{v:?}");
    assert!(v[1].normalize().cross(touch.normal()).length() <= 1e-12);
    assert!((v[0] + v[1] - DVec3::new(3.0, 0.0, 0.0)).length() <= 1e-12);
}

#[test]
fn a_slow_pair_stays_in_touch_and_a_pair_that_opens_is_left_alone() {
    let (beads, touches) = row(&[1.0, 1.0], 0.1, 1.0);
    let slow = [touches[0].resting_below(0.05)];
    let mut v = [DVec2::new(0.01, 0.0), DVec2::ZERO];
    let strikes = resolve(&beads, &slow, &mut v);
    assert_eq!(v[0], v[1], "they move on together at the same speed");
    assert!(!strikes[0].bounced);

    let mut v = [DVec2::new(-1.0, 0.0), DVec2::new(1.0, 0.0)];
    let strikes = resolve(&beads, &touches, &mut v);
    assert_eq!(v, [DVec2::new(-1.0, 0.0), DVec2::new(1.0, 0.0)]);
    assert!(strikes.is_empty());
}

#[test]
fn bad_pairs_are_refused_in_words() {
    let err = Touch::between((3, DVec2::ONE, 0.1), (4, DVec2::ONE, 0.1), 1.0).unwrap_err();
    assert_eq!(
        err.to_string(),
        "beads 3 and 4 have their centres at one point, so the line between them has no direction"
    );
    assert_eq!(Freedom::along(DVec2::ZERO), Err(ImpactError::NoDirection));
    let (beads, touches) = row(&[1.0, 1.0], 0.1, 1.0);
    let err = Response::through(&touches[0], &beads[..1]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "a touching pair names bead 1, and there are 1 beads"
    );
    let answers = responses(&beads, &touches);
    let mut v = [DVec2::X];
    let err = resolve_impacts(&touches, &answers, &mut v, &mut Vec::new()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "a touching pair names bead 1, and there are 1 beads"
    );
}

/// A ball caught between two walls of infinite mass (beads that cannot
/// move along the line) at `e = 1` would strike forever: the count is
/// bounded and the failure reported.
#[test]
fn strikes_that_never_settle_are_reported() {
    let fixed = ImpactBead {
        inverse_mass: 0.0,
        freedom: Freedom::free(),
    };
    let ball = ImpactBead {
        inverse_mass: 1.0,
        freedom: Freedom::free(),
    };
    let beads = [fixed, ball, fixed];
    let at = |x: f64| DVec2::new(x, 0.0);
    let touches = [
        Touch::between((0, at(0.0), 0.05), (1, at(0.1), 0.05), 1.0).expect("apart"),
        Touch::between((1, at(0.1), 0.05), (2, at(0.2), 0.05), 1.0).expect("apart"),
    ];
    let mut v = [DVec2::ZERO, at(1.0), DVec2::ZERO];
    let err = resolve_all(&beads, &touches, &mut v).unwrap_err();
    assert_eq!(
        err,
        ImpactError::DidNotSettle {
            strikes: 2 * MAX_STRIKES_PER_TOUCH
        }
    );
}

/// Ball `a` (1 kg) at 1 m/s along x strikes ball `b` (1 kg, at rest)
/// whose centre is 60° off its path, at `e = 1`: the normal impulse
/// `cos 60°` and a slip of `sin 60°` across the normal. With `μ = 0.2`
/// the pair slides (friction `μ p = 0.1` N s, less than the `0.433`
/// that would stop the slip) and loses `f s − f² w_t / 2` of energy;
/// with `μ = 1` the slip stops. Both to 1e-15.
#[test]
fn friction_opposes_the_slip_by_mu_p_or_stops_it() {
    let theta = 60f64.to_radians();
    let n = DVec2::new(theta.cos(), theta.sin());
    let t = DVec2::new(-n.y, n.x);
    let beads = [ImpactBead {
        inverse_mass: 1.0,
        freedom: Freedom::free(),
    }; 2];
    for (mu, slides) in [(0.2, true), (1.0, false)] {
        let touch = Touch::between((0, DVec2::ZERO, 0.5), (1, n, 0.5), 1.0)
            .expect("apart")
            .with_friction(mu);
        assert_eq!(touch.tangents().len(), 1);
        let response = Response::through(&touch, &beads).expect("two beads");
        let mut v = [DVec2::X, DVec2::ZERO];
        let mut strikes = Vec::new();
        resolve_impacts(&[touch], &[response], &mut v, &mut strikes).expect("settles");
        let (p, slip) = (theta.cos(), theta.sin());
        let f = if slides { mu * p } else { slip / 2.0 };
        assert!((strikes[0].impulse - p).abs() <= 1e-15);
        assert!((strikes[0].friction_impulse - f).abs() <= 1e-15);
        let sign = t.dot(-DVec2::X).signum();
        let expected_a = DVec2::X - n * p + t * (f * sign);
        let expected_b = n * p - t * (f * sign);
        assert!((v[0] - expected_a).length() <= 1e-15, "{:?}", v[0]);
        assert!((v[1] - expected_b).length() <= 1e-15, "{:?}", v[1]);
        let lost = 0.5 - energy(&beads, &v);
        assert!((lost - (f * slip - f * f)).abs() <= 1e-15, "lost {lost}");
        if !slides {
            assert!(t.dot(v[1] - v[0]).abs() <= 1e-15);
        }
    }
}

fn vector() -> impl proptest::strategy::Strategy<Value = DVec3> {
    use proptest::prelude::*;
    (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

fn freedom() -> impl proptest::strategy::Strategy<Value = Freedom<DVec3>> {
    use proptest::prelude::*;
    (0..3usize, vector()).prop_map(|(kind, axis)| match kind {
        0 => Freedom::free(),
        1 => Freedom::along(axis).unwrap_or_default(),
        _ => Freedom::across(axis).unwrap_or_default(),
    })
}

proptest::proptest! {
    /// Any two beads, free or held, of any masses, struck at any
    /// restitution: the pair opens at `−e u` (where either can move
    /// along the normal), no bead leaves its freedom, the energy never
    /// grows, and struck at `e = 1` it is kept.
    #[test]
    fn a_strike_opens_the_pair_at_minus_e_u_and_never_adds_energy(
        (ma, mb) in (0.05..20.0f64, 0.05..20.0f64),
        (fa, fb) in (freedom(), freedom()),
        (xb, va, vb) in (vector(), vector(), vector()),
        e in 0.0..=1.0f64,
    ) {
        let beads = [
            ImpactBead { inverse_mass: 1.0 / ma, freedom: fa },
            ImpactBead { inverse_mass: 1.0 / mb, freedom: fb },
        ];
        proptest::prop_assume!(xb.length() > 1e-3);
        let touch = Touch::between((0, DVec3::ZERO, 0.0), (1, xb, xb.length()), e)
            .expect("apart");
        let mut v = [fa.project(va), fb.project(vb)];
        let (u, before) = (touch.normal_speed(&v), energy(&beads, &v));
        let response = Response::through(&touch, &beads).expect("two beads");
        let impulse = strike(&touch, e, &response, &mut v);
        let after = energy(&beads, &v);
        let scale = 1e-12 * (1.0 + va.length() + vb.length());
        if impulse != 0.0 {
            proptest::prop_assert!((touch.normal_speed(&v) + e * u).abs() <= scale);
        }
        proptest::prop_assert!((fa.project(v[0]) - v[0]).length() <= scale);
        proptest::prop_assert!((fb.project(v[1]) - v[1]).length() <= scale);
        proptest::prop_assert!(after <= before * (1.0 + 1e-12) + 1e-300);
        let mut elastic = [fa.project(va), fb.project(vb)];
        strike(&touch, 1.0, &response, &mut elastic);
        let kept = energy(&beads, &elastic);
        proptest::prop_assert!((kept - before).abs() <= 1e-12 * before.max(1e-300));
    }

    /// Any two closing beads, free or held, struck at any restitution
    /// with any friction: the friction impulse is at most `μ p`, no bead
    /// leaves its freedom, and the energy never grows.
    #[test]
    fn friction_never_adds_energy_or_exceeds_mu_p(
        (ma, mb) in (0.05..20.0f64, 0.05..20.0f64),
        (fa, fb) in (freedom(), freedom()),
        (xb, va, vb) in (vector(), vector(), vector()),
        (e, mu) in (0.0..=1.0f64, 0.0..3.0f64),
    ) {
        let beads = [
            ImpactBead { inverse_mass: 1.0 / ma, freedom: fa },
            ImpactBead { inverse_mass: 1.0 / mb, freedom: fb },
        ];
        proptest::prop_assume!(xb.length() > 1e-3);
        let touch = Touch::between((0, DVec3::ZERO, 0.0), (1, xb, xb.length()), e)
            .expect("apart")
            .with_friction(mu);
        let mut v = [fa.project(va), fb.project(vb)];
        // A pair strikes only while it closes.
        proptest::prop_assume!(touch.normal_speed(&v) < 0.0);
        let before = energy(&beads, &v);
        let response = Response::through(&touch, &beads).expect("two beads");
        let p = strike(&touch, e, &response, &mut v);
        let f = rub(&touch, mu * p, &response, &mut v);
        let scale = 1e-12 * (1.0 + va.length() + vb.length());
        proptest::prop_assert!(f >= 0.0 && f <= mu * p * (1.0 + 1e-15));
        proptest::prop_assert!((fa.project(v[0]) - v[0]).length() <= scale);
        proptest::prop_assert!((fb.project(v[1]) - v[1]).length() <= scale);
        proptest::prop_assert!(energy(&beads, &v) <= before * (1.0 + 1e-12) + 1e-300);
    }
}
