//! Beads that touch: a bead's [`BeadRadius`] and [`Restitution`], the
//! scene-wide [`Contacts`], the [`BeadsStruck`] message, the wires that
//! catch beads with radii ([`CatchesBeads`]) and those that take their
//! beads back to the start ([`SendsBeadsBack`]).

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::geometry::Coordinates;
use crate::validate::{ParamError, finite_vector, non_negative, positive, restitution};

/// A bead's radius in metres: beads with radii touch when their centres
/// are the sum of their radii apart, and may not come closer. The centre
/// rides the wire; the radius does not move it off. Zero touches nothing.
///
/// A bead with a radius steps in an island (alone, if joined to nothing),
/// whose step is cut where it meets another.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Component)]
pub struct BeadRadius(f64);

impl BeadRadius {
    /// A radius, if it is zero or more and finite.
    pub fn new(radius: f64) -> Result<Self, ParamError> {
        non_negative("radius", radius).map(Self)
    }

    /// The radius in metres.
    pub fn get(&self) -> f64 {
        self.0
    }
}

/// Makes a one-sided wire (see [`Surface`](crate::Surface)) catch every
/// bead with a [`BeadRadius`] that flies onto it, not only the beads on it:
/// a marble run's tracks, each marble free or on a track of its own,
/// falling from one track onto the next. Such a bead lands on the wire
/// from the side it pushes toward (never from behind), by the wire's
/// restitution, runs along it with its centre on it, and leaves it where
/// the wire would have to pull or past an end, as the wire's own beads
/// do. A bead starts on it only where it starts on it.
///
/// Every bead with a radius gets a row on every wire that catches, in its
/// island: the cost of a step grows with their product. A two-sided wire
/// catches nothing.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
#[reflect(Component)]
pub struct CatchesBeads;

/// Sends each bead on the wire back to a point of it, at rest and held on
/// the wire again, once the bead has left the wire (past an end, or where
/// a one-sided wire would have to pull) and settled: slower than `speed`
/// for `after` seconds. A bead waits while another bead with a radius is
/// within reach of the point (the sum of their radii and one radius
/// more), so that none is put on another. A marble run that runs for
/// ever: each marble that comes to rest in the bowl goes back to the top
/// of its rail.
///
/// The point is where the bead is put: on the wire, or the step pulls it
/// there. A bead sent back is a bead moved by the game: its island is
/// built again, its rows start afresh.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct SendsBeadsBack<V: Coordinates + Reflect + TypePath = DVec2> {
    to: V,
    speed: f64,
    after: f64,
}

impl<V: Coordinates + Reflect + TypePath> SendsBeadsBack<V> {
    /// Sends settled beads back to `to`, if it is finite, `speed` positive
    /// and `after` zero or more (both finite).
    pub fn new(to: V, speed: f64, after: f64) -> Result<Self, ParamError> {
        Ok(Self {
            to: finite_vector("point beads are sent back to", to)?,
            speed: positive("speed below which a bead has settled", speed)?,
            after: non_negative("time a bead takes to settle", after)?,
        })
    }

    /// Where a settled bead is put.
    pub fn to(&self) -> V {
        self.to
    }

    /// The speed below which a bead is settling, m/s.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// How long a bead must stay below that speed, s.
    pub fn after(&self) -> f64 {
        self.after
    }
}

/// A bead's own restitution, for the pairs it strikes in: the pair takes
/// the smaller of its two beads' (a bead without one takes
/// [`Contacts::restitution`]). The smaller, because a soft ball is soft
/// against anything.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct Restitution(f64);

impl Restitution {
    /// A restitution, if it is between 0 (they stay together) and 1 (no
    /// energy lost).
    pub fn new(e: f64) -> Result<Self, ParamError> {
        restitution(e).map(Self)
    }

    /// The coefficient.
    pub fn get(&self) -> f64 {
        self.0
    }
}

/// How beads that touch strike, scene-wide: their restitution and
/// Coulomb friction.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Resource)]
pub struct Contacts {
    restitution: f64,
    friction: f64,
}

impl Default for Contacts {
    /// Elastic (`e = 1`) and frictionless.
    fn default() -> Self {
        Self {
            restitution: 1.0,
            friction: 0.0,
        }
    }
}

impl Contacts {
    /// Strikes with restitution `e` (between 0 and 1), frictionless.
    pub fn new(restitution: f64) -> Result<Self, ParamError> {
        self::restitution(restitution).map(|restitution| Self {
            restitution,
            friction: 0.0,
        })
    }

    /// With Coulomb friction `μ` (zero or more and finite) between beads
    /// that strike: each strike of impulse `p` opposes the pair's slip
    /// across the line between their centres with an impulse of at most
    /// `μ p`, as much as stops it where that is less (see
    /// `rub`), pairs struck together at `e = 0` as
    /// well as pairs struck one by one. Pairs pressed together rub between
    /// strikes as a bead on a rough wire does: `μ |λ|` against their slip,
    /// and in the plane held still where they stop slipping while `μ |λ|`
    /// can hold them (see
    /// [`Island::set_contact_friction`](crate::solver::Island::set_contact_friction)).
    pub fn with_friction(self, friction: f64) -> Result<Self, ParamError> {
        non_negative("friction", friction).map(|friction| Self { friction, ..self })
    }

    /// The restitution of a pair whose beads have none of their own.
    pub fn restitution(&self) -> f64 {
        self.restitution
    }

    /// The Coulomb friction between beads.
    pub fn friction(&self) -> f64 {
        self.friction
    }
}

/// Sent when a wire with [`SendsBeadsBack`] sends one of its beads back:
/// the bead jumped there between two steps (a trail drawn through the
/// jump would cross the scene).
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct BeadSentBack {
    /// The bead.
    pub bead: Entity,
    /// The time it was sent back at (before the next step), s.
    pub time: f64,
}

/// Sent when a bead strikes a body of the physics world (a collider of
/// avian's; also logged, one line).
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct BeadStruckBody {
    /// The bead.
    pub bead: Entity,
    /// The collider it struck.
    pub body: Entity,
    /// When, in simulated seconds.
    pub time: f64,
    /// The impulse along the body's normal there (N s).
    pub impulse: f64,
    /// How fast they closed (m/s).
    pub closing_speed: f64,
    /// Whether the bead bounced off, or stayed in touch (`e = 0`, or too
    /// slow to bounce: resting on the body).
    pub bounced: bool,
    /// The friction impulse against their slip (N s).
    pub friction_impulse: f64,
}

/// Sent when two beads strike (also logged, one line).
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct BeadsStruck {
    /// One bead.
    pub a: Entity,
    /// The other.
    pub b: Entity,
    /// When, in simulated seconds.
    pub time: f64,
    /// The impulse along the line from `a`'s centre to `b`'s (N s).
    pub impulse: f64,
    /// How fast they closed (m/s).
    pub closing_speed: f64,
    /// Whether they bounced apart, or stayed in touch (`e = 0`, or too
    /// slow to bounce).
    pub bounced: bool,
    /// The friction impulse against their slip (N s; zero without
    /// [`Contacts::with_friction`]).
    pub friction_impulse: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_radii_and_restitutions_are_refused_in_words() {
        assert_eq!(
            BeadRadius::new(-0.1).unwrap_err().to_string(),
            "radius must be zero or more and finite, got -0.1"
        );
        assert!(BeadRadius::new(f64::NAN).is_err());
        assert_eq!(BeadRadius::new(0.25).map(|r| r.get()), Ok(0.25));
        assert_eq!(
            Contacts::new(1.5).unwrap_err().to_string(),
            "restitution must be between 0 and 1, got 1.5"
        );
        assert!(Restitution::new(f64::NAN).is_err());
        assert!(Contacts::new(-0.1).is_err());
        assert_eq!(Restitution::new(0.0).map(|e| e.get()), Ok(0.0));
        assert_eq!(
            Contacts::default()
                .with_friction(-0.2)
                .unwrap_err()
                .to_string(),
            "friction must be zero or more and finite, got -0.2"
        );
        assert!(Contacts::default().with_friction(f64::INFINITY).is_err());
        assert_eq!(
            Contacts::default().with_friction(0.4).map(|c| c.friction()),
            Ok(0.4)
        );
    }
}
