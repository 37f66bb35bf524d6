//! What a scene's rows are measured against: its constraints (a wire,
//! a rod, a pin, a path joint's anchor), its springs, its beads' and its
//! bodies' masses; and a rigid body's state in a row.

use super::{SceneRow, SceneSpace};
use crate::geometry::Placement;
use crate::preset::{BodyKind, SceneBody, SceneLink, ScenePath};

/// Whether a run records a body: a dynamic or kinematic one (a static
/// one never moves).
fn moves<B: SceneBody>(body: &B) -> bool {
    body.kind() != BodyKind::Static
}

/// The index among the recorded bodies of `bodies[index]`, if a run
/// records it.
fn recorded_index<B: SceneBody>(bodies: &[B], index: usize) -> Option<usize> {
    moves(&bodies[index]).then(|| bodies[..index].iter().filter(|b| moves(*b)).count())
}

/// Each body's name, and whether a run records it.
pub(super) fn recorded<B: SceneBody>(bodies: &[B]) -> Vec<(String, bool)> {
    bodies
        .iter()
        .map(|b| (b.name().to_owned(), moves(b)))
        .collect()
}

/// A wire as measured where it rides the body named `body` (none if
/// empty): placed on a static body where the body starts, or riding a
/// recorded body (its index among them), its place then in the body's
/// frame.
pub(super) fn carried_by<V: SceneSpace, B: SceneBody<Pose = V::Pose>>(
    check: V::WireCheck,
    bodies: &[B],
    body: &str,
) -> (V::WireCheck, Option<usize>) {
    let Some(index) = bodies
        .iter()
        .position(|b| !body.is_empty() && b.name() == body)
    else {
        return (check, None);
    };
    match recorded_index(bodies, index) {
        Some(recorded) => (check, Some(recorded)),
        None => (V::carried(&check, &bodies[index].pose()), None),
    }
}

/// One constraint to measure, with beads as indices in the file's order.
#[derive(Clone, Debug)]
enum Check<V: SceneSpace> {
    /// A bead on a wire, the wire riding the recorded body of that index
    /// where it rides one.
    Wire(usize, V::WireCheck, Option<usize>),
    Rod(usize, usize, f64),
    Pin(usize, V),
    /// A path joint: the recorded body of that index, its anchor (in its
    /// frame), and its wire (riding the recorded body of that index where
    /// it rides one).
    Path(usize, V, V::WireCheck, Option<usize>),
}

/// What a scene's rows are measured against: its constraints, springs and
/// masses.
#[derive(Clone, Debug)]
pub struct Measure<V: SceneSpace> {
    checks: Vec<Check<V>>,
    springs: Vec<(usize, usize, f64, f64)>,
    masses: Vec<f64>,
    gravity: V,
    /// Each recorded body's mass and principal moments (none for a
    /// kinematic body given no mass).
    bodies: Vec<Option<(f64, V::Inertia)>>,
}

/// A rigid body's state in a row of a scene's run: its origin, its turn,
/// its velocity and its spin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyState<V: SceneSpace> {
    /// Where its origin is.
    pub position: V,
    /// How it is turned.
    pub turn: V::Turn,
    /// Its velocity.
    pub velocity: V,
    /// Its spin (counter-clockwise in the plane; right-handed in space).
    pub spin: V::Angular,
}

impl<V: SceneSpace> From<(V, V::Turn, V, V::Angular)> for BodyState<V> {
    fn from((position, turn, velocity, spin): (V, V::Turn, V, V::Angular)) -> Self {
        Self {
            position,
            turn,
            velocity,
            spin,
        }
    }
}

/// `|v|`.
fn length<V: SceneSpace>(v: V) -> f64 {
    v.dot(v).sqrt()
}

impl<V: SceneSpace> Measure<V> {
    /// A scene's measure: each wire with its number of beads (the wires'
    /// beads come first in the file's order), the links, every bead's
    /// mass and gravity.
    pub(crate) fn new(
        wires: &[(V::WireCheck, Option<usize>, usize)],
        links: Vec<SceneLink<V>>,
        masses: Vec<f64>,
        gravity: V,
    ) -> Self {
        let mut checks = Vec::new();
        let mut bead = 0;
        for (wire, carrier, count) in wires {
            for _ in 0..*count {
                checks.push(Check::Wire(bead, wire.clone(), *carrier));
                bead += 1;
            }
        }
        let mut springs = Vec::new();
        for link in links {
            match link {
                SceneLink::Rod { a, b, length } => checks.push(Check::Rod(a, b, length)),
                SceneLink::Pin { bead, at } => checks.push(Check::Pin(bead, at)),
                SceneLink::Spring { a, b, spring } => {
                    springs.push((a, b, spring.rest_length, spring.stiffness))
                }
            }
        }
        Self {
            checks,
            springs,
            masses,
            gravity,
            bodies: Vec::new(),
        }
    }

    /// The measure with a scene's bodies: each recorded body's mass and
    /// principal moments, and each path joint of a recorded body (its
    /// anchor on its wire, `wires` as [`Measure::new`] took them).
    pub(super) fn with_scene_bodies<B: SceneBody<Inertia = V::Inertia>>(
        mut self,
        wires: &[(V::WireCheck, Option<usize>, usize)],
        paths: &[ScenePath<V>],
        bodies: &[B],
    ) -> Self {
        self.bodies = bodies
            .iter()
            .filter(|b| moves(*b))
            .map(SceneBody::mass_properties)
            .collect();
        for path in paths {
            let body = recorded_index(bodies, path.body);
            if let (Some(body), Some((wire, carrier, _))) = (body, wires.get(path.wire)) {
                let check = Check::Path(body, path.anchor, wire.clone(), *carrier);
                self.checks.push(check);
            }
        }
        self
    }

    /// Kinetic plus gravitational energy of the bodies at `states`.
    pub fn body_energy(&self, states: &[BodyState<V>]) -> f64 {
        self.bodies
            .iter()
            .zip(states)
            .filter_map(|(mass, state)| {
                let (m, inertia) = (*mass)?;
                let (x, v) = (state.position, state.velocity);
                Some(
                    0.5 * m * v.dot(v) - m * self.gravity.dot(x)
                        + V::spin_energy(inertia, state.turn, state.spin),
                )
            })
            .sum()
    }

    /// The largest `|C|` at time `t` of every constraint, wires included
    /// (a bead in flight off its wire left out; a wire that rides a body
    /// where `bodies` has it).
    pub fn max_abs_c(&self, t: f64, x: &[V], on: &[bool], bodies: &[BodyState<V>]) -> f64 {
        self.checks
            .iter()
            .map(|check| match check {
                Check::Wire(b, ..) if !on[*b] => 0.0,
                Check::Wire(b, wire, Some(carrier)) => match bodies.get(*carrier) {
                    Some(body) => V::drift(&V::carried(wire, &V::body_pose(body)), t, x[*b]),
                    None => 0.0,
                },
                Check::Wire(b, wire, None) => V::drift(wire, t, x[*b]),
                Check::Path(body, anchor, wire, carrier) => {
                    let Some(held) = bodies.get(*body) else {
                        return 0.0;
                    };
                    let at = V::body_pose(held).to_world(*anchor);
                    match carrier.map(|c| bodies.get(c)) {
                        Some(Some(on)) => V::drift(&V::carried(wire, &V::body_pose(on)), t, at),
                        Some(None) => 0.0,
                        None => V::drift(wire, t, at),
                    }
                }
                Check::Rod(a, b, rod) => (length(x[*a] - x[*b]) - rod).abs(),
                Check::Pin(b, at) => length(x[*b] - *at),
            })
            .fold(0.0, f64::max)
    }

    /// Kinetic plus gravitational energy of every bead.
    pub fn energy(&self, x: &[V], v: &[V]) -> f64 {
        self.masses
            .iter()
            .zip(x.iter().zip(v))
            .map(|(m, (x, v))| 0.5 * m * v.dot(*v) - m * self.gravity.dot(*x))
            .sum()
    }

    /// The row of the scene's state at time `t`: every bead's position
    /// and velocity in the file's order, whether each is held on its wire,
    /// and each recorded body's state.
    pub fn row(
        &self,
        t: f64,
        (positions, velocities, on): (Vec<V>, Vec<V>, Vec<bool>),
        bodies: Vec<BodyState<V>>,
    ) -> SceneRow<V> {
        SceneRow {
            t,
            energy: self.energy(&positions, &velocities) + self.body_energy(&bodies),
            spring_energy: self.spring_energy(&positions),
            max_abs_c: self.max_abs_c(t, &positions, &on, &bodies),
            positions,
            velocities,
            on,
            bodies,
        }
    }

    /// The energy stored in the springs.
    pub fn spring_energy(&self, x: &[V]) -> f64 {
        self.springs
            .iter()
            .map(|&(a, b, rest, k)| {
                let stretch = length(x[a] - x[b]) - rest;
                0.5 * k * stretch * stretch
            })
            .sum()
    }
}
