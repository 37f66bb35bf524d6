//! Two beads in touch, pair by pair: when they touch, part, close, meet
//! slowly or near a step's start, and end a step in touch. What an
//! island's step and the touch settlement ask of a pair, each written
//! once.

use crate::geometry::Coordinates;
use crate::solver::state::BeadState;

/// Two beads whose gap is at most this fraction of their radii touch.
pub(crate) const TOUCHING: f64 = 1e-10;

/// A contact row's beads part where their gap opens faster than this
/// fraction of their reach (the two radii) plus their speeds, per second:
/// slower is rounding, and the row holds on (see [`Island::set_contact`](super::Island::set_contact)).
pub(crate) const OPENING: f64 = 1e-9;

/// Whether a pair in touch whose gap opens at `rate`, of `reach` (the two
/// radii) and `speeds` (the sum of its beads' speeds), parts (see
/// [`OPENING`]).
pub(crate) fn parts(rate: f64, reach: f64, speeds: f64) -> bool {
    rate > OPENING * (reach + speeds)
}

/// How fast the gap between beads `a` and `b` opens (negative: closes),
/// along the line between their centres, and the sum of their speeds.
pub(crate) fn opening_rate<V: Coordinates>(a: &BeadState<V>, b: &BeadState<V>) -> (f64, f64) {
    let d = b.position - a.position;
    let rate = d.dot(b.velocity - a.velocity) / d.dot(d).sqrt();
    (rate, pair_speeds(a, b))
}

/// The sum of beads `a` and `b`'s speeds.
pub(crate) fn pair_speeds<V: Coordinates>(a: &BeadState<V>, b: &BeadState<V>) -> f64 {
    a.velocity.dot(a.velocity).sqrt() + b.velocity.dot(b.velocity).sqrt()
}

/// The gap between beads at `a` and `b` whose radii sum to `reach`: how
/// far apart their surfaces are (negative where they overlap).
pub(crate) fn pair_gap<V: Coordinates>(a: V, b: V, reach: f64) -> f64 {
    let d = b - a;
    d.dot(d).sqrt() - reach
}

/// A pair in touch closes (and strikes at once) where it closes faster
/// than this fraction of its two beads' speeds: slower is rounding.
const CLOSING: f64 = 1e-9;

/// Whether a pair in touch whose gap opens at `rate`, of `reach` and
/// `speeds` as in [`parts`], closes: faster than [`CLOSING`] of its
/// speeds, and by more than what counts as touching ([`TOUCHING`] of its
/// reach) within a step of `dt`. A pair that closes is the touch
/// settlement's to strike; one that does not and presses is held.
pub(crate) fn closes(rate: f64, reach: f64, speeds: f64, dt: f64) -> bool {
    -rate > CLOSING * speeds && -rate * dt > TOUCHING * reach
}

/// How many times a wire's residual a held contact row's may be where a
/// Newton solve stalls and takes it: 4e-10 of the two radii instead of
/// [`NEWTON_ACCEPT`](crate::solver::newton::NEWTON_ACCEPT)'s 1e-10. Beads
/// jammed among others can hold more contact rows than they can meet
/// exactly at once, and there exact Newton steps stall a little above
/// 1e-10 of the radii however short the step.
pub(crate) const CONTACT_SLACK: f64 = 4.0;

/// Whether a contact row's beads `gap` apart, of `reach` (the two radii),
/// end a step in touch: within what a Newton solve takes of a held
/// contact row ([`CONTACT_SLACK`] times
/// [`NEWTON_ACCEPT`](crate::solver::newton::NEWTON_ACCEPT) of the reach).
pub(crate) fn ends_in_touch(gap: f64, reach: f64) -> bool {
    gap.abs() <= CONTACT_SLACK * crate::solver::newton::NEWTON_ACCEPT * reach
}

/// Whether a pair of restitution `restitution` whose gap closes at
/// `closing` (m/s) meets slowly: at `e = 0`, no faster than `moved`, the
/// speed one whole step's forces give its two beads (each `|f| / m`
/// times the step, summed). Such a meeting is the island's step to hold,
/// not the touch settlement's to strike at its instant (see
/// [`Island::step_at`](super::Island::step_at)).
pub(crate) fn meets_slowly(restitution: f64, closing: f64, moved: f64) -> bool {
    restitution == 0.0 && closing <= moved
}

/// The part of a step within which a pair at `e = 0` that meets is
/// taken by the step rather than struck at its instant: 1/16. Such a
/// pair, `gap` apart and closing at `v`, meets within `gap / v ≤ dt / 16`
/// of the step's start; its body's step holds its contact row where the
/// pair would end overlapping (see [`Island::step_at`](super::Island::step_at)).
pub(crate) const NEAR_MEETING: f64 = 1.0 / 16.0;

/// Whether a pair of restitution `restitution`, `gap` apart and closing
/// at `closing` (m/s), meets near the start of a step of `dt` (or of a
/// part of it, `dt` still the whole step's): at `e = 0`, within
/// [`NEAR_MEETING`] of `dt`. Its body's step holds
/// its row (a plastic impact over the step: for two free beads on a line
/// exactly the one at its instant, elsewhere apart from it by the
/// constraint force over the `gap / v` before it), so a pile whose beads
/// pass their momentum on across gaps of a hair does not cut its step at
/// each (inelastic collapse).
pub(crate) fn meets_near(restitution: f64, gap: f64, closing: f64, dt: f64) -> bool {
    restitution == 0.0 && closing > 0.0 && gap <= NEAR_MEETING * closing * dt
}

/// The speed a step of `dt` gives two beads under `pushes` (each bead's
/// acceleration from its forces, `f / m`): `(|p_a| + |p_b|) dt`, the
/// `moved` of [`meets_slowly`].
pub(crate) fn step_speed<V: Coordinates>(pushes: [V; 2], dt: f64) -> f64 {
    pushes.iter().map(|p| p.dot(*p).sqrt()).sum::<f64>() * dt
}
