//! Beads sent back to a point of their wire once they have left it and
//! settled ([`SendsBeadsBack`]), before the islands are built for the
//! step.

use bevy::prelude::*;

use super::Islands;
use crate::dynamics::{
    BeadPosition, BeadRadius, BeadSentBack, BeadVelocity, Dimension, SendsBeadsBack, WireBeads,
    WireContact,
};
use crate::geometry::Coordinates;
use crate::plugin::clock::SimClock;
use crate::solver::Contact;

/// What the send-back reads and writes of a bead.
type SentBead<V> = (
    Entity,
    &'static mut BeadPosition<V>,
    &'static mut BeadVelocity<V>,
    &'static mut WireContact,
    Option<&'static BeadRadius>,
);

/// Whether a bead of radius `reach` may be put at `to` among `others`
/// (position and radius): no bead with a radius within the sum of their
/// radii and one radius more. A bead with no radius touches nothing.
fn clear_at<V: Coordinates>(to: V, reach: f64, others: impl Iterator<Item = (V, f64)>) -> bool {
    let mut others = others;
    reach <= 0.0
        || others.all(|(at, r)| r <= 0.0 || (at - to).dot(at - to).sqrt() >= 2.0 * reach + r)
}

/// Sends back each bead of a wire with [`SendsBeadsBack`] that has been
/// off it and slower than its speed for its time, where the point is
/// clear: put there at rest, held on the wire again, its island built
/// anew (its rows start afresh, as for a bead a game moved), and
/// [`BeadSentBack`] sent. Since when
/// each bead has been slow is kept with the [`Islands`], so that the
/// [`Timeline`](crate::plugin::Timeline) takes it back with them; a time
/// ahead of the clock (a restart) starts again.
pub(super) fn send_back<V: Dimension>(
    clock: Res<SimClock>,
    wires: Query<(&SendsBeadsBack<V>, &WireBeads)>,
    mut beads: Query<SentBead<V>, With<V::Bead>>,
    mut islands: ResMut<Islands<V>>,
    mut sent: MessageWriter<BeadSentBack>,
) {
    let now = clock.time;
    let mut ready = Vec::new();
    for (back, on) in &wires {
        for bead in on.iter() {
            let Ok((_, _, velocity, contact, _)) = beads.get(bead) else {
                continue;
            };
            // Not slow where the speed is NaN (a bead that diverged).
            let slow = velocity.0.dot(velocity.0).sqrt() < back.speed();
            if contact.get() != Contact::InFlight || !slow {
                islands.settling.remove(&bead);
                continue;
            }
            let since = islands.settling.entry(bead).or_insert(now);
            if *since > now {
                *since = now;
            }
            if now - *since >= back.after() {
                ready.push((bead, back.to()));
            }
        }
    }
    for (bead, to) in ready {
        let reach = beads
            .get(bead)
            .map_or(0.0, |b| b.4.map_or(0.0, BeadRadius::get));
        let others = beads
            .iter()
            .filter(|b| b.0 != bead)
            .map(|b| (b.1.0, b.4.map_or(0.0, BeadRadius::get)));
        if !clear_at(to, reach, others) {
            continue;
        }
        let Ok((_, mut position, mut velocity, mut contact, _)) = beads.get_mut(bead) else {
            continue;
        };
        position.0 = to;
        velocity.0 = V::ZERO;
        *contact = WireContact::default();
        islands.settling.remove(&bead);
        islands.mark_dirty();
        sent.write(BeadSentBack { bead, time: now });
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec3;

    use super::clear_at;

    /// A point is clear of a bead at more than the two radii and one more,
    /// of a bead with no radius always, and for a bead with none.
    #[test]
    fn a_point_is_clear_two_radii_and_one_more_from_the_nearest() {
        let to = DVec3::ZERO;
        let at = |x: f64| (DVec3::new(x, 0.0, 0.0), 0.01);
        assert!(clear_at(to, 0.01, [at(0.031)].into_iter()));
        assert!(!clear_at(to, 0.01, [at(0.031), at(0.029)].into_iter()));
        assert!(clear_at(to, 0.01, [(DVec3::ZERO, 0.0)].into_iter()));
        assert!(clear_at(to, 0.0, [at(0.0)].into_iter()));
    }
}
