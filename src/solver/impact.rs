//! Impacts between beads that touch, eq. (18): the impulse of one strike
//! between two beads, each free or held to its wire, and the rule that
//! resolves simultaneous and chained strikes one pair at a time.
//!
//! Two beads of radii `r_a` and `r_b` touch when `|x_b − x_a| = r_a + r_b`.
//! With `n̂` the unit vector from `a`'s centre to `b`'s, the pair closes at
//! `u = n̂·(v_b − v_a) < 0`. A strike is an impulse `p n̂` on `b` and
//! `−p n̂` on `a`; each bead takes of it only what its wire lets it take,
//! the projection `P` onto the directions it may move in ([`Freedom`]):
//!
//! ```text
//! w = n̂·P_a n̂ / m_a + n̂·P_b n̂ / m_b,   p = −(1 + e) u / w,
//! v_a ← v_a − (p / m_a) P_a n̂,          v_b ← v_b + (p / m_b) P_b n̂,
//! ```
//!
//! which leaves the pair separating at `−e u` and, `P` being an orthogonal
//! projection, keeps the kinetic energy at `e = 1` and loses
//! `½ (1 − e²) u² / w` below it.
//!
//! A bead joined to others answers with its whole island: the impulse
//! `W Jᵀ p` projected onto the island's constraints in the kinetic-energy
//! norm, `Δv = P W Jᵀ p` with `P = I − W Jᵀ (J W Jᵀ)⁻¹ J`. A [`Response`]
//! holds that answer per unit impulse for one touching pair (each bead's
//! velocity change), and `w = n̂·(Δv_b − Δv_a)`: [`Freedom`] is the same
//! projection for a bead held by its own rows alone.
//!
//! **Simultaneous and chained strikes** ([`resolve_impacts`]) are resolved
//! as sequential pairwise impacts: while a touching pair closes, the one
//! closing fastest (the first in the list among equals) strikes alone, and
//! the others see its result. A row of touching equal balls at `e = 1` so
//! passes one ball's momentum from pair to pair to the last ball, and
//! Newton's cradle sends out as many balls as came in, which one impulse
//! solved for every touching pair at once does not. Three equal balls, the
//! outer two striking the middle one at once from both sides at speed `v`,
//! end with the outer two leaving at `v` and the middle one at rest: the
//! first pair exchanges, the middle ball carries `v` into the third, and
//! the first ball takes the middle one's rebound.
//!
//! **Friction** (Coulomb, coefficient `μ`): after each strike of impulse
//! `p`, the pair's slip (the part of `v_b − v_a` across the normal) is
//! opposed by an impulse along it of at most `μ p`: `min(μ p, |s| / w_t)`,
//! where `w_t` is the pair's weight along the slip (as `w` along the
//! normal, from its response to an impulse along each tangent), so a
//! strike stops the slip where friction can and never reverses it. Such an
//! impulse never adds energy.
//!
//! A pair whose bounce `e u` would be slower than the speed one step's
//! forces give it along the normal (its rest speed, [`Touch::resting_below`])
//! strikes with `e = 0`: it stays in touch, as a bead landing slowly on a
//! one-sided wire stays on it (eq. 16). A pair at `e = 0` that meets
//! slower than its step's forces move it is not struck at all: its
//! island's step holds it (see [`settle_touches`](crate::solver::settle_touches)).

use bevy::math::DVec2;
use thiserror::Error;

use crate::geometry::Coordinates;

/// Closing speeds at or below this fraction of the fastest bead's speed in
/// the touching pairs count as zero: what rounding leaves of a strike
/// that stopped the pair.
const SLACK: f64 = 1e-12;

/// How many strikes per touching pair [`resolve_impacts`] allows by
/// default before it reports that the strikes did not settle.
pub const MAX_STRIKES_PER_TOUCH: usize = 256;

/// Why impacts could not be resolved, in words.
#[derive(Clone, Copy, Debug, Error, PartialEq)]
pub enum ImpactError {
    /// Two beads' centres are at one point (or not finite): the line
    /// between them has no direction.
    #[error(
        "beads {a} and {b} have their centres at one point, so the line between them has no direction"
    )]
    Coincident {
        /// The first bead.
        a: usize,
        /// The second bead.
        b: usize,
    },
    /// A direction a bead is held to is zero or not finite.
    #[error("a bead's wire direction must be a finite vector that is not zero")]
    NoDirection,
    /// The pairs kept striking each other past the allowed count.
    #[error("the impacts did not settle after {strikes} strikes between touching beads")]
    DidNotSettle {
        /// How many strikes were made.
        strikes: usize,
    },
    /// An index names no bead.
    #[error("a touching pair names bead {bead}, and there are {beads} beads")]
    MissingBead {
        /// The index.
        bead: usize,
        /// How many beads there are.
        beads: usize,
    },
}

/// The directions a bead's velocity may change in at a strike: any (a free
/// bead), along one line (a bead on a curve), or across one direction (a
/// bead on a surface in space; a bead on a rod from a fixed pin).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Freedom<V = DVec2> {
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
    pub fn free() -> Self {
        Self {
            kind: FreedomKind::Free,
            axis: V::ZERO,
        }
    }

    /// A bead that moves along `tangent` only (its length does not matter).
    pub fn along(tangent: V) -> Result<Self, ImpactError> {
        Ok(Self {
            kind: FreedomKind::Along,
            axis: unit(tangent)?,
        })
    }

    /// A bead that moves in every direction but `normal`'s (its length
    /// does not matter).
    pub fn across(normal: V) -> Result<Self, ImpactError> {
        Ok(Self {
            kind: FreedomKind::Across,
            axis: unit(normal)?,
        })
    }

    /// The part of `v` the bead can take: `P v`.
    pub fn project(&self, v: V) -> V {
        match self.kind {
            FreedomKind::Free => v,
            FreedomKind::Along => self.axis * self.axis.dot(v),
            FreedomKind::Across => v - self.axis * self.axis.dot(v),
        }
    }
}

/// `v / |v|`, if `v` is finite and not zero.
fn unit<V: Coordinates>(v: V) -> Result<V, ImpactError> {
    let length = v.dot(v).sqrt();
    if length.is_finite() && length > 0.0 {
        Ok(v / length)
    } else {
        Err(ImpactError::NoDirection)
    }
}

/// A bead as a strike sees it: its inverse mass and its [`Freedom`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpactBead<V = DVec2> {
    /// `1 / m`.
    pub inverse_mass: f64,
    /// The directions it may move in.
    pub freedom: Freedom<V>,
}

/// Two beads that touch (or overlap): their indices, the unit vector from
/// `a`'s centre to `b`'s, the gap between their surfaces and the
/// restitution of a strike between them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Touch<V = DVec2> {
    a: usize,
    b: usize,
    normal: V,
    gap: f64,
    restitution: f64,
    rest_speed: f64,
    friction: f64,
}

impl<V: Coordinates> Touch<V> {
    /// Beads `a` at `xa` of radius `ra` and `b` at `xb` of radius `rb`,
    /// striking with `restitution`: their normal and gap
    /// `|x_b − x_a| − (r_a + r_b)`. Refused if the centres coincide.
    pub fn between(
        (a, xa, ra): (usize, V, f64),
        (b, xb, rb): (usize, V, f64),
        restitution: f64,
    ) -> Result<Self, ImpactError> {
        let d = xb - xa;
        let distance = d.dot(d).sqrt();
        let normal = unit(d).map_err(|_| ImpactError::Coincident { a, b })?;
        Ok(Self {
            a,
            b,
            normal,
            gap: distance - (ra + rb),
            restitution,
            rest_speed: 0.0,
            friction: 0.0,
        })
    }

    /// The pair rubs with Coulomb friction `μ` (zero or more; none by
    /// default) at each strike: see the module's documentation. A
    /// negative or NaN `μ` rubs with none.
    pub fn with_friction(self, friction: f64) -> Self {
        Self {
            friction: if friction > 0.0 { friction } else { 0.0 },
            ..self
        }
    }

    /// Its Coulomb friction `μ`.
    pub fn friction(&self) -> f64 {
        self.friction
    }

    /// Unit vectors across the normal, each at right angles to the others:
    /// one in the plane, two in space. A pair's slip is along them.
    pub fn tangents(&self) -> Vec<V> {
        let dimension = V::ZERO.components().len();
        let mut basis: Vec<V> = Vec::with_capacity(dimension - 1);
        for k in 0..dimension {
            if basis.len() + 1 == dimension {
                break;
            }
            let mut axis = V::ZERO;
            *axis.components_mut()[k] = 1.0;
            let mut t = axis - self.normal * self.normal.dot(axis);
            for &b in &basis {
                t = t - b * b.dot(t);
            }
            let length = t.dot(t).sqrt();
            // An axis nearly along the normal or the others: the next one.
            if length > 0.5 {
                basis.push(t * length.recip());
            }
        }
        basis
    }

    /// The pair stays in touch (strikes with `e = 0`) where its bounce
    /// `e u` would be no faster than `speed`: what one step of the forces
    /// pressing it together gives (eq. 16's rule). Zero by default.
    pub fn resting_below(self, speed: f64) -> Self {
        Self {
            rest_speed: speed,
            ..self
        }
    }

    /// The two beads.
    pub fn beads(&self) -> (usize, usize) {
        (self.a, self.b)
    }

    /// The unit vector from `a`'s centre to `b`'s.
    pub fn normal(&self) -> V {
        self.normal
    }

    /// The gap between the surfaces: negative where they overlap.
    pub fn gap(&self) -> f64 {
        self.gap
    }

    /// The rate the gap opens at, `n̂·(v_b − v_a)`: negative while the
    /// pair closes.
    pub fn normal_speed(&self, velocities: &[V]) -> f64 {
        self.normal.dot(velocities[self.b] - velocities[self.a])
    }

    /// The restitution it strikes with when closing at `closing_speed`:
    /// its own, or zero where the bounce would not outrun its rest speed.
    fn restitution_at(&self, closing_speed: f64) -> f64 {
        if self.restitution * closing_speed > self.rest_speed {
            self.restitution
        } else {
            0.0
        }
    }
}

/// How the beads' velocities answer a unit impulse on one touching pair
/// (`−n̂` on `a`, `+n̂` on `b`): each bead's velocity change, and the
/// pair's weight `w = n̂·(Δv_b − Δv_a)`, the inverse of its effective mass
/// along the normal.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Response<V = DVec2> {
    changes: Vec<(usize, V)>,
    weight: f64,
    /// The same per unit impulse along each of [`Touch::tangents`] (none
    /// for a pair without friction).
    tangents: Vec<Vec<(usize, V)>>,
}

impl<V: Coordinates> Response<V> {
    /// The answer `changes` (bead, velocity change per unit impulse; a
    /// bead may be listed more than once, its changes add) to a unit
    /// impulse on `touch`.
    pub fn new(touch: &Touch<V>, changes: Vec<(usize, V)>) -> Self {
        let weight = weight_along(touch, touch.normal, &changes);
        Self {
            changes,
            weight,
            tangents: Vec::new(),
        }
    }

    /// With the answers to a unit impulse along each of the pair's
    /// [`Touch::tangents`] (`−t̂` on `a`, `+t̂` on `b`), as `changes` are
    /// to one along the normal: what friction needs.
    pub fn with_tangents(self, tangents: Vec<Vec<(usize, V)>>) -> Self {
        Self { tangents, ..self }
    }

    /// The answer of two beads each held by its own rows alone (free, or
    /// by its [`Freedom`]): `∓P n̂ / m`.
    pub fn through(touch: &Touch<V>, beads: &[ImpactBead<V>]) -> Result<Self, ImpactError> {
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

    /// `w = n̂·(Δv_b − Δv_a)` per unit impulse: zero where neither bead
    /// can move along the normal.
    pub fn weight(&self) -> f64 {
        self.weight
    }
}

/// A pair's weight along `d`: `d·(Δv_b − Δv_a)` for the velocity
/// changes `changes` (bead, change; a bead listed more than once takes
/// their sum) that a unit impulse along `d` makes, the inverse of the
/// pair's effective mass along it.
fn weight_along<V: Coordinates>(touch: &Touch<V>, d: V, changes: &[(usize, V)]) -> f64 {
    let of = |bead: usize| {
        changes
            .iter()
            .filter(|(i, _)| *i == bead)
            .fold(V::ZERO, |sum, (_, dv)| sum + *dv)
    };
    d.dot(of(touch.b) - of(touch.a))
}

/// One strike that [`resolve_impacts`] made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strike {
    /// The index of the touching pair in the list given.
    pub touch: usize,
    /// The impulse `p` (N s) along the pair's normal.
    pub impulse: f64,
    /// How fast the pair closed before it (m/s, positive).
    pub closing_speed: f64,
    /// Whether it bounced (struck with its restitution) or stayed in
    /// touch (closed slower than the rest speed, struck with `e = 0`).
    pub bounced: bool,
    /// The friction impulse (N s) against the pair's slip, at most `μ`
    /// times [`Strike::impulse`]; zero without friction.
    pub friction_impulse: f64,
}

/// Strikes `touch` with restitution `e`: the impulse of eq. (18),
/// `p = −(1 + e) u / w`, applied to the `velocities` through the pair's
/// `response`. Returns the impulse, zero where neither bead can move
/// along the normal.
pub fn strike<V: Coordinates>(
    touch: &Touch<V>,
    e: f64,
    response: &Response<V>,
    velocities: &mut [V],
) -> f64 {
    let w = response.weight;
    // A NaN weight, like zero, strikes nothing.
    if w.is_nan() || w <= 0.0 {
        return 0.0;
    }
    let p = -(1.0 + e) * touch.normal_speed(velocities) / w;
    for &(i, dv) in &response.changes {
        velocities[i] += dv * p;
    }
    p
}

/// Opposes the slip of `touch` (the part of `v_b − v_a` across its
/// normal) with an impulse along it of at most `limit` (`μ` times the
/// strike's impulse), through the answers to impulses along the pair's
/// tangents in `response`: as much as stops the slip, where that is less.
/// Returns the impulse, zero where the pair does not slip, has no
/// tangents' answers, cannot be moved along its slip, or names a bead
/// that `velocities` does not have.
pub fn rub<V: Coordinates>(
    touch: &Touch<V>,
    limit: f64,
    response: &Response<V>,
    velocities: &mut [V],
) -> f64 {
    if limit.is_nan() || limit <= 0.0 || response.tangents.is_empty() {
        return 0.0;
    }
    let count = velocities.len();
    let named = response.tangents.iter().flatten().map(|(i, _)| *i);
    if touch.a >= count || touch.b >= count || named.into_iter().any(|i| i >= count) {
        return 0.0;
    }
    let tangents = touch.tangents();
    if response.tangents.len() != tangents.len() {
        return 0.0;
    }
    let relative = velocities[touch.b] - velocities[touch.a];
    let along: Vec<f64> = tangents.iter().map(|t| t.dot(relative)).collect();
    let slip = along.iter().map(|s| s * s).sum::<f64>().sqrt();
    if slip.is_nan() || slip <= 0.0 {
        return 0.0;
    }
    // The answer to a unit impulse along the slip, from the tangents'.
    let mut changes = Vec::new();
    for (k, answers) in response.tangents.iter().enumerate() {
        let share = along[k] / slip;
        changes.extend(answers.iter().map(|&(i, dv)| (i, dv * share)));
    }
    let direction = tangents
        .iter()
        .zip(&along)
        .fold(V::ZERO, |sum, (&t, &s)| sum + t * (s / slip));
    let weight = weight_along(touch, direction, &changes);
    if weight.is_nan() || weight <= 0.0 {
        return 0.0;
    }
    let impulse = limit.min(slip / weight);
    for &(i, dv) in &changes {
        velocities[i] -= dv * impulse;
    }
    impulse
}

/// Resolves the strikes among touching beads by sequential pairwise
/// impacts (see the module's documentation): while a pair in `touches`
/// closes, the fastest closing one strikes through its response (the
/// same index in `responses`), with its restitution where its bounce
/// outruns its rest speed, with `e = 0` otherwise, and rubs with its
/// friction ([`rub`]). Each strike is appended to `strikes`.
///
/// Stops with [`ImpactError::DidNotSettle`] after
/// [`MAX_STRIKES_PER_TOUCH`] strikes per pair, the velocities as the last
/// strike left them.
pub fn resolve_impacts<V: Coordinates>(
    touches: &[Touch<V>],
    responses: &[Response<V>],
    velocities: &mut [V],
    strikes: &mut Vec<Strike>,
) -> Result<(), ImpactError> {
    let count = velocities.len();
    let named = || {
        touches
            .iter()
            .flat_map(|t| [t.a, t.b])
            .chain(responses.iter().flat_map(|r| {
                r.changes
                    .iter()
                    .chain(r.tangents.iter().flatten())
                    .map(|(i, _)| *i)
            }))
    };
    if let Some(bead) = named().find(|&i| i >= count) {
        return Err(ImpactError::MissingBead { bead, beads: count });
    }
    let fastest = named()
        .map(|i| velocities[i].dot(velocities[i]).sqrt())
        .fold(0.0, f64::max);
    let slack = SLACK * fastest;
    let pairs = touches.len().min(responses.len());
    let limit = MAX_STRIKES_PER_TOUCH * pairs;
    // The pair closing fastest, the first listed among equals.
    let closing = |velocities: &[V]| {
        touches[..pairs]
            .iter()
            .enumerate()
            .map(|(i, t)| (i, -t.normal_speed(velocities)))
            .filter(|&(_, speed)| speed > slack)
            .fold(None, |best: Option<(usize, f64)>, (i, speed)| match best {
                Some((_, s)) if s >= speed => best,
                _ => Some((i, speed)),
            })
    };
    for _ in 0..limit {
        let Some((i, closing_speed)) = closing(velocities) else {
            return Ok(());
        };
        let touch = &touches[i];
        let e = touch.restitution_at(closing_speed);
        let impulse = strike(touch, e, &responses[i], velocities);
        if impulse == 0.0 {
            // Neither bead can move along the line between them: what
            // closes them there is not theirs to stop.
            return Ok(());
        }
        let friction_impulse = rub(touch, touch.friction * impulse, &responses[i], velocities);
        strikes.push(Strike {
            touch: i,
            impulse,
            closing_speed,
            bounced: e > 0.0,
            friction_impulse,
        });
    }
    match closing(velocities) {
        None => Ok(()),
        Some(_) => Err(ImpactError::DidNotSettle { strikes: limit }),
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::{DVec2, DVec3};

    use super::*;

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
    fn responses<V: Coordinates>(
        beads: &[ImpactBead<V>],
        touches: &[Touch<V>],
    ) -> Vec<Response<V>> {
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
        let touch = Touch::between((0, DVec3::ZERO, 0.05), (1, xb, xb.length() - 0.05), 1.0)
            .expect("apart");
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
}
