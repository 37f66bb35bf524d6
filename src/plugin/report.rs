//! Reports the bead step and the island step share: divergences (the
//! [`Diverged`] marker, the [`BeadDiverged`] message and a warning) and
//! changes of contact (the [`ContactChanged`] message and a line in the
//! log), each found inside a possibly parallel loop and sent after it;
//! and the one line a strike is logged in.

use std::sync::{Mutex, PoisonError};

use bevy::ecs::system::SystemParam;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::dynamics::{BeadDiverged, ContactChanged, Dimension, Diverged, DivergenceReason};
use crate::geometry::Coordinates;
use crate::solver::{ContactEvent, Strike};

/// Divergences found inside a (possibly parallel) loop, reported after it.
#[derive(Default)]
pub(crate) struct FoundDivergences(Mutex<Vec<(Entity, DivergenceReason, f64)>>);

impl FoundDivergences {
    pub(crate) fn push(&self, bead: Entity, reason: DivergenceReason, time: f64) {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push((bead, reason, time));
    }

    pub(crate) fn report(&mut self, divergences: &mut Divergences) {
        let found = self.0.get_mut().unwrap_or_else(PoisonError::into_inner);
        for (bead, reason, time) in found.drain(..) {
            divergences.report(bead, reason, time);
        }
    }
}

/// Marks beads diverged: inserts [`Diverged`], sends [`BeadDiverged`] and
/// logs a warning.
#[derive(SystemParam)]
pub(crate) struct Divergences<'w, 's> {
    commands: Commands<'w, 's>,
    messages: MessageWriter<'w, BeadDiverged>,
}

impl Divergences<'_, '_> {
    /// Reports that `bead` stopped at simulated time `time`.
    pub(crate) fn report(&mut self, bead: Entity, reason: DivergenceReason, time: f64) {
        warn!(
            "wirebead: bead {bead} diverged at t = {time:.4} s: {reason}; press Space (send Restart) to recover"
        );
        self.commands.entity(bead).try_insert(Diverged {
            reason: reason.clone(),
            time,
        });
        self.messages.write(BeadDiverged { bead, reason });
    }
}

/// Sends [`ContactChanged`] and logs the change in one line.
#[derive(SystemParam)]
pub(crate) struct ContactReports<'w, V: Dimension = DVec2> {
    messages: MessageWriter<'w, ContactChanged<V>>,
}

impl<V: Dimension> ContactReports<'_, V> {
    /// Reports that `bead`'s contact changed.
    pub(crate) fn report(&mut self, bead: Entity, event: ContactEvent<V>) {
        info!("wirebead: bead {bead} {}", describe_event(&event));
        self.messages.write(ContactChanged { bead, event });
    }
}

/// A change of contact in words, for the log.
fn describe_event<V: Dimension>(event: &ContactEvent<V>) -> String {
    match *event {
        ContactEvent::Left { time, position } => format!(
            "left a wire at t = {time:.4} s at {}, where it would have had to pull or past its end",
            point(position)
        ),
        ContactEvent::Landed {
            time,
            position,
            normal_speed,
            bounced,
        } => format!(
            "landed on a wire at t = {time:.4} s at {} at {normal_speed:.3} m/s across it and {}",
            point(position),
            if bounced { "bounced off" } else { "stayed on" }
        ),
    }
}

/// A point for the log: `(x, y)` in the plane, `(x, y, z)` in space, to
/// the millimetre.
fn point<V: Dimension>(p: V) -> String {
    let p = p.xyz();
    if V::DIMENSION == 3 {
        format!("({:.3}, {:.3}, {:.3})", p.x, p.y, p.z)
    } else {
        format!("({:.3}, {:.3})", p.x, p.y)
    }
}

/// Changes of contact found inside a (possibly parallel) loop, sent after
/// it.
pub(crate) struct FoundEvents<V: Coordinates = DVec2>(Mutex<Vec<(Entity, ContactEvent<V>)>>);

impl<V: Coordinates> Default for FoundEvents<V> {
    fn default() -> Self {
        Self(Mutex::default())
    }
}

impl<V: Coordinates> FoundEvents<V> {
    pub(crate) fn push(&self, bead: Entity, event: ContactEvent<V>) {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push((bead, event));
    }

    pub(crate) fn take(&mut self) -> Vec<(Entity, ContactEvent<V>)> {
        std::mem::take(self.0.get_mut().unwrap_or_else(PoisonError::into_inner))
    }
}

/// Logs one strike between `who` at `time` in one line: a bounce (`apart`
/// or off) as information, a pair that stays in touch at the debug level
/// (a resting pile strikes every step).
pub(crate) fn log_strike(who: &str, (time, s): (f64, &Strike), apart: &str) {
    let rubbed = if s.friction_impulse > 0.0 {
        format!(" and {:.4} N s of friction", s.friction_impulse)
    } else {
        String::new()
    };
    if s.bounced {
        info!(
            "wirebead: {who} struck at t = {time:.4} s, closing at {:.3} m/s, and bounced {apart} with an impulse of {:.4} N s{rubbed}",
            s.closing_speed, s.impulse
        );
    } else {
        debug!(
            "wirebead: {who} met at t = {time:.4} s, closing at {:.3} m/s, and stayed in touch",
            s.closing_speed
        );
    }
}
