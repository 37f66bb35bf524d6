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

/// `v / |v|`, if `v` is finite and not zero.
fn unit<V: Coordinates>(v: V) -> Result<V, ImpactError> {
    let length = v.dot(v).sqrt();
    if length.is_finite() && length > 0.0 {
        Ok(v / length)
    } else {
        Err(ImpactError::NoDirection)
    }
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

    /// The unit vector from `a`'s centre to `b`'s.
    pub fn normal(&self) -> V {
        self.normal
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

    /// The answer to a unit impulse on `touch` along its normal, and
    /// along each of its tangents where it rubs (friction above zero),
    /// each from `answer` (the changes for an impulse along a direction).
    pub(crate) fn answered<E>(
        touch: &Touch<V>,
        mut answer: impl FnMut(V) -> Result<Vec<(usize, V)>, E>,
    ) -> Result<Self, E> {
        let response = Self::new(touch, answer(touch.normal)?);
        if touch.friction > 0.0 {
            let tangents = touch.tangents().into_iter().map(&mut answer);
            Ok(response.with_tangents(tangents.collect::<Result<_, _>>()?))
        } else {
            Ok(response)
        }
    }

    /// With the answers to a unit impulse along each of the pair's
    /// [`Touch::tangents`] (`−t̂` on `a`, `+t̂` on `b`), as `changes` are
    /// to one along the normal: what friction needs.
    pub fn with_tangents(self, tangents: Vec<Vec<(usize, V)>>) -> Self {
        Self { tangents, ..self }
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
mod tests;
