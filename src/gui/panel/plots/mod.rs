//! The selected bead's last seconds of drift, energy and λ: recorded each
//! step and plotted with labelled axes; and the last strikes between beads,
//! recorded for the panel's list.

mod axes;
mod draw;

use std::collections::VecDeque;

use bevy::math::DVec3;
use bevy::prelude::*;

pub(super) use axes::panel_plot;
pub use axes::{grid_steps, tick_label};
pub(super) use draw::{plots_section, shown};

use crate::geometry::Coordinates;
use crate::geometry::{ImplicitCurve, Placed};
use crate::gui::drag::SelectedBead;
use crate::plugin::SceneEnergy;
use crate::reference::{AlongWire, along_wire, circle_angle, circle_normal_force};
use crate::{
    BeadDiagnostics, BeadParams, BeadPosition, BeadStruckBody, BeadVelocity, BeadsStruck, Islands,
    OnWire, SimClock, SimParams, Wire, WireShape, pose_of,
};

/// What holds a plotted bead, and so what its drift `C` and λ are.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum HeldBy {
    /// Its wire: `C`, `Ċ` and λ are its wire's.
    #[default]
    Wire,
    /// Rods or pins only, no wire: `C` is the largest drift of its island
    /// ([`IslandReport::drift`](crate::IslandReport::drift)); it has no
    /// λ of its own (the panel lists each rod's).
    Links,
    /// Nothing: a free bead has no `C` or λ.
    Nothing,
}

impl HeldBy {
    /// A bead's hold as its wire says: [`HeldBy::Wire`] on one, else
    /// [`HeldBy::Nothing`] until its island says it is joined to others.
    fn on(wire: Option<&OnWire>) -> Self {
        if wire.is_some() {
            Self::Wire
        } else {
            Self::Nothing
        }
    }
}

/// One plotted sample of the selected bead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlotSample {
    /// Simulated time.
    pub t: f64,
    /// What holds the bead ([`HeldBy`]).
    pub held_by: HeldBy,
    /// Drift `C`: its wire's, or its island's largest.
    pub c: f64,
    /// Its rate `Ċ`.
    pub c_dot: f64,
    /// The bead's own energy, kinetic plus gravitational.
    pub energy: f64,
    /// Whether the bead's own energy is worth a line of its own beside
    /// the scene's: it is joined to no other bead by a rod, pin or
    /// contact, and the scene holds more than it.
    pub own_energy: bool,
    /// The scene's energy ([`SceneEnergy`]): what changes only by
    /// damping, friction, inelastic strikes, drift and a drag.
    pub scene_energy: f64,
    /// λ.
    pub lambda: f64,
    /// Where the bead was (`z` zero in the plane).
    pub position: DVec3,
    /// How fast it moved.
    pub velocity: DVec3,
    /// On a circle in the plane: the angle from its lowest point and its
    /// rate ([`circle_angle`](crate::reference::circle_angle)).
    pub on_circle: Option<(f64, f64)>,
    /// On a wire in the plane: how far along it the bead has come since
    /// the plot began, and how fast ([`along_wire`]).
    pub along: Option<AlongWire>,
    /// The bead's own kinetic energy `½ m |v|²`.
    pub kinetic: f64,
    /// Its own potential energy `−m g·x`.
    pub potential: f64,
    /// On a circle in the plane: the force holding the bead toward the
    /// centre, as simulated and as energy kept from its start says
    /// ([`circle_normal_force`](crate::reference::circle_normal_force)).
    pub normal_force: Option<(f64, f64)>,
}

impl PlotSample {
    /// A sample at time `t` of a bead's diagnostics `d`, at rest at the
    /// origin and on no circle until told where it is.
    fn of<V: Coordinates>(t: f64, d: &BeadDiagnostics<V>) -> Self {
        Self {
            t,
            held_by: HeldBy::Wire,
            c: d.c,
            c_dot: d.c_dot,
            energy: d.energy(),
            own_energy: false,
            scene_energy: d.energy(),
            lambda: d.lambda,
            position: DVec3::ZERO,
            velocity: DVec3::ZERO,
            on_circle: None,
            along: None,
            kinetic: d.kinetic,
            potential: d.potential,
            normal_force: None,
        }
    }
}

/// The last seconds of the selected bead's diagnostics.
#[derive(Resource, Clone, Debug)]
pub struct PlotHistory {
    /// Seconds kept.
    pub seconds: f64,
    /// The samples, oldest first.
    pub samples: VecDeque<PlotSample>,
    /// Where the bead rides a circle in the plane: the size of gravity and
    /// the circle's radius (for the pendulum's separatrix).
    pub circle: Option<(f64, f64)>,
    bead: Option<Entity>,
}

impl PlotHistory {
    /// The bead plotted.
    pub fn bead(&self) -> Option<Entity> {
        self.bead
    }
}

impl Default for PlotHistory {
    fn default() -> Self {
        Self {
            seconds: 10.0,
            samples: VecDeque::new(),
            circle: None,
            bead: None,
        }
    }
}

/// What [`record_history`] reads of a bead in the plane: its state, its
/// diagnostics and its wire.
type PlaneBead = (
    &'static BeadPosition,
    &'static BeadVelocity,
    &'static BeadDiagnostics,
    &'static BeadParams,
    Option<&'static OnWire>,
);

/// What [`record_history`] reads of a bead in space.
type SpaceBeadRead = (
    &'static BeadPosition<DVec3>,
    &'static BeadVelocity<DVec3>,
    &'static BeadDiagnostics<DVec3>,
    Option<&'static OnWire>,
);

/// Appends the selected bead's diagnostics (in the plane or in space) to
/// the plot history, with the scene's energy ([`SceneEnergy`]): an
/// island's own jumps as contacts join and part its beads, and a rod does
/// work on each of its beads, not on the two together, so the bead's own
/// is kept only for a bead joined to nothing.
#[allow(clippy::too_many_arguments)]
pub fn record_history(
    selected: Res<SelectedBead>,
    clock: Res<SimClock>,
    params: Res<SimParams>,
    beads: Query<PlaneBead>,
    space_beads: Query<SpaceBeadRead>,
    wires: Query<(&Wire, &Transform)>,
    islands: Res<Islands>,
    space_islands: Res<Islands<DVec3>>,
    scene_energy: Option<Res<SceneEnergy>>,
    mut history: ResMut<PlotHistory>,
) {
    let Some(entity) = selected.0 else { return };
    let g = params.gravity;
    let plane = beads.get(entity).ok().map(|(x, v, d, start, on)| {
        // Its wire's shape and pose, looked up once.
        let wire = on.and_then(|on| {
            let (wire, transform) = wires.get(on.0).ok()?;
            Some((wire.shape(), pose_of(transform).ok()?))
        });
        // On a circle: its centre and radius.
        let circle = wire.and_then(|(shape, pose)| match shape {
            WireShape::Circle(c) => Some((pose.origin, c.radius)),
            _ => None,
        });
        let on_circle = circle.and_then(|(centre, _)| circle_angle(centre, g, x.0, v.0));
        let normal_force = circle
            .zip(on_circle)
            .and_then(|((centre, radius), (theta, _))| {
                let from = circle_angle(centre, g, start.initial_position, start.initial_velocity)?;
                let inward = (centre - x.0).try_normalize()?;
                let expected = circle_normal_force(start.mass, g.length(), radius, from, theta);
                Some((d.constraint_force.dot(inward), expected))
            });
        // The wire's normal where the bead is, for how far along it is.
        let normal = wire.map(|(shape, pose)| {
            let curve = shape.curve();
            Placed { curve, pose }.gradient(x.0)
        });
        let sample = PlotSample {
            held_by: HeldBy::on(on),
            position: x.0.extend(0.0),
            velocity: v.0.extend(0.0),
            on_circle,
            normal_force,
            ..PlotSample::of(clock.time, d)
        };
        (sample, circle.map(|c| c.1), normal)
    });
    let space = || {
        let (x, v, d, on) = space_beads.get(entity).ok()?;
        let sample = PlotSample {
            held_by: HeldBy::on(on),
            position: x.0,
            velocity: v.0,
            ..PlotSample::of(clock.time, d)
        };
        Some((sample, None, None))
    };
    let Some((mut sample, radius, normal)) = plane.or_else(space) else {
        return;
    };
    history.circle = radius.map(|r| (g.length(), r));
    let t = clock.time;
    if history.bead != Some(entity) {
        history.samples.clear();
        history.bead = Some(entity);
    }
    // Back at an earlier time (a restart, a step back): the plots go on
    // from there.
    while history.samples.back().is_some_and(|s| s.t >= t) {
        history.samples.pop_back();
    }
    if let Some(normal) = normal {
        let previous = history.samples.back().and_then(|s| s.along);
        let (x, v) = (sample.position.truncate(), sample.velocity.truncate());
        sample.along = along_wire(previous.as_ref(), x, v, normal);
    }
    let joined = islands
        .of(entity)
        .or_else(|| space_islands.of(entity))
        .filter(|island| island.rows > 0);
    if let Some(island) = joined {
        // A bead held by rods or pins alone: its island's drift.
        if sample.held_by == HeldBy::Nothing {
            sample.held_by = HeldBy::Links;
            sample.c = island.drift;
        }
    }
    // Measured at this time: a sample taken before the first step of a
    // restarted run has the bead's own.
    if let Some(scene) = scene_energy.filter(|e| e.time == t) {
        sample.scene_energy = scene.total;
        let apart = (scene.total - sample.energy).abs() > 1e-12 * scene.total.abs().max(1.0);
        sample.own_energy = joined.is_none() && apart;
    }
    history.samples.push_back(sample);
    let horizon = t - history.seconds;
    while history.samples.front().is_some_and(|s| s.t < horizon) {
        history.samples.pop_front();
    }
}

/// The part of the window the panel's plots and phase plot show in, in
/// physical pixels (left, top, right, bottom): what a PNG of the plots
/// holds. None while they are folded away or scrolled out of view.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct PlotsShown(pub Option<[f32; 4]>);

/// How many of the last strikes the panel lists.
const STRIKES_SHOWN: usize = 6;

/// One strike as the panel lists it: between two beads, or a bead and a
/// body of the physics world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShownStrike {
    /// The bead, or the first bead.
    pub a: Entity,
    /// The other bead, or the body.
    pub b: Entity,
    /// When, s.
    pub time: f64,
    /// How fast they closed, m/s.
    pub closing_speed: f64,
    /// The impulse along the normal, N s.
    pub impulse: f64,
    /// The friction impulse, N s.
    pub friction_impulse: f64,
    /// Whether they bounced apart.
    pub bounced: bool,
}

impl From<BeadsStruck> for ShownStrike {
    fn from(s: BeadsStruck) -> Self {
        Self {
            a: s.a,
            b: s.b,
            time: s.time,
            closing_speed: s.closing_speed,
            impulse: s.impulse,
            friction_impulse: s.friction_impulse,
            bounced: s.bounced,
        }
    }
}

impl From<BeadStruckBody> for ShownStrike {
    fn from(s: BeadStruckBody) -> Self {
        Self {
            a: s.bead,
            b: s.body,
            time: s.time,
            closing_speed: s.closing_speed,
            impulse: s.impulse,
            friction_impulse: s.friction_impulse,
            bounced: s.bounced,
        }
    }
}

/// The last strikes between beads, and of beads on bodies, newest first,
/// for the panel.
#[derive(Resource, Default)]
pub struct RecentStrikes(pub(super) VecDeque<ShownStrike>);

/// A strike that leaves its pair in touch closing slower than this (m/s)
/// is a resting pair's, not listed: a pile trades such strikes every step.
const RESTING_CLOSING: f64 = 1e-3;

/// Keeps the last six strikes, between beads and of beads on bodies
/// (leaving out resting pairs' closing slower than 1 mm/s); forgets them
/// when the run starts again (the clock went back).
pub fn record_strikes(
    (mut struck, mut on_bodies): (MessageReader<BeadsStruck>, MessageReader<BeadStruckBody>),
    clock: Res<SimClock>,
    mut recent: ResMut<RecentStrikes>,
) {
    if recent.0.front().is_some_and(|s| s.time > clock.time) {
        recent.0.clear();
    }
    let strikes = struck
        .read()
        .map(|&s| ShownStrike::from(s))
        .chain(on_bodies.read().map(|&s| ShownStrike::from(s)));
    for strike in strikes {
        if strike.bounced || strike.closing_speed >= RESTING_CLOSING {
            recent.0.push_front(strike);
        }
    }
    recent.0.truncate(STRIKES_SHOWN);
}
