//! [`Bead`] and its columns: position, velocity, mass, the force
//! accumulated for the next step and the parameters a restart returns to;
//! its parameters for the next run and the spring anchor that pulls it.

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use bevy::ecs::lifecycle::HookContext;
use bevy::ecs::query::QueryData;
use bevy::ecs::world::DeferredWorld;

use crate::geometry::{Coordinates, Twist};
use crate::solver::{BeadState, LinearForce};
use crate::validate::{ParamError, finite_vector, positive};

/// The per-bead parameters of the assignment's panel: mass, initial position and
/// initial velocity. On a bead, the state a [`Restart`](crate::Restart)
/// returns it to.
#[derive(Component, Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Reflect)]
#[reflect(Component)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct BeadParams<V: Coordinates = DVec2> {
    /// Mass in kg.
    pub mass: f64,
    /// Where a restart puts the bead.
    pub initial_position: V,
    /// The velocity a restart gives it.
    pub initial_velocity: V,
}

impl<V: Coordinates> Default for BeadParams<V> {
    fn default() -> Self {
        Self {
            mass: 1.0,
            initial_position: V::from_xyz(DVec3::new(0.0, -1.0, 0.0)),
            initial_velocity: V::ZERO,
        }
    }
}

impl<V: Coordinates> BeadParams<V> {
    /// Checks every field; the first problem found is returned.
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("mass", self.mass)?;
        finite_vector("initial position", self.initial_position)?;
        finite_vector("initial velocity", self.initial_velocity).map(drop)
    }

    /// The initial velocity in the world on a wire moving by `twist` at
    /// t = 0: the initial velocity is relative to the wire's own where the
    /// bead starts.
    pub(crate) fn initial_velocity_on(&self, twist: &Twist<V>) -> V {
        self.initial_velocity + twist.velocity_at(self.initial_position)
    }
}

/// A bead: the marker its other components hang on. A bead's state is
/// split into columns of its own, as a rigid body's is in avian:
///
/// | component | what it holds | who writes it |
/// |---|---|---|
/// | [`BeadPosition`] | the position, `f64` world coordinates | the step; a game may teleport |
/// | [`BeadVelocity`] | the velocity | the step; a game may kick |
/// | [`BeadMass`] | the mass, checked positive and finite | a restart; a game through [`BeadMass::new`] |
/// | [`BeadForce`] | the force accumulated for the next step | systems in [`WireBeadSystems::Forces`](crate::WireBeadSystems::Forces), through [`BeadForces`]; the step consumes it |
/// | [`BeadParams`] | mass and initial state a restart returns to | [`Restart`](crate::Restart), from [`NextBeadParams`] |
///
/// The step streams only the first four. [`Bead::new`] spawns all five in
/// one expression; a bare `Bead` gets the others as required components
/// (at rest at the origin, 1 kg) and remembers the state it was spawned in
/// as its [`BeadParams`] unless one is given.
///
/// A position or velocity written directly is checked by the step, which
/// marks the bead [`Diverged`](crate::Diverged) rather than propagate a
/// non-finite value.
///
/// With [`WireBeadPlugin`](crate::WireBeadPlugin)'s defaults a bead also gets
/// a `Transform` (the plugin writes its position there) and
/// [`BeadDiagnostics`](crate::BeadDiagnostics);
/// [`WireBeadPlugin::lean`](crate::WireBeadPlugin::lean) leaves both out for
/// crowds of beads nobody looks at one by one.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Component)]
#[require(BeadPosition, BeadVelocity, BeadMass, BeadForce)]
#[component(on_add = remember_start::<DVec2>)]
pub struct Bead;

/// A bead in space: [`Bead`]'s marker for the columns of three
/// coordinates, `BeadPosition<DVec3>`, `BeadVelocity<DVec3>`,
/// [`BeadMass`] and `BeadForce<DVec3>`, which it requires. Put it on a
/// [`SpaceWire`](crate::SpaceWire) with [`OnWire`](crate::OnWire), join
/// it to others by rods, pins, springs and joints, or leave it free.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Component)]
#[require(BeadPosition<DVec3>, BeadVelocity<DVec3>, BeadMass, BeadForce<DVec3>)]
#[component(on_add = remember_start::<DVec3>)]
pub struct SpaceBead;

impl SpaceBead {
    /// A bead in space at its initial position with its initial velocity,
    /// if the parameters are valid: every component of it, to spawn in one
    /// expression.
    pub fn new(params: BeadParams<DVec3>) -> Result<SpaceBeadBundle, ParamError> {
        params.validate()?;
        Ok((
            SpaceBead,
            BeadPosition(params.initial_position),
            BeadVelocity(params.initial_velocity),
            BeadMass(params.mass),
            params,
        ))
    }

    /// A bead in space of the given mass at rest at `position`.
    pub fn at_rest(mass: f64, position: DVec3) -> Result<SpaceBeadBundle, ParamError> {
        Self::new(BeadParams {
            mass,
            initial_position: position,
            initial_velocity: DVec3::ZERO,
        })
    }
}

/// Every component of a bead in space, as [`SpaceBead::new`] makes them.
pub type SpaceBeadBundle = (
    SpaceBead,
    BeadPosition<DVec3>,
    BeadVelocity<DVec3>,
    BeadMass,
    BeadParams<DVec3>,
);

impl Bead {
    /// A bead at its initial position with its initial velocity, if the
    /// parameters are valid: every component of the bead, to spawn in one
    /// expression.
    pub fn new(params: BeadParams) -> Result<BeadBundle, ParamError> {
        params.validate()?;
        Ok((
            Bead,
            BeadPosition(params.initial_position),
            BeadVelocity(params.initial_velocity),
            BeadMass(params.mass),
            params,
        ))
    }

    /// A bead of the given mass at rest at `position`.
    pub fn at_rest(mass: f64, position: DVec2) -> Result<BeadBundle, ParamError> {
        Self::new(BeadParams {
            mass,
            initial_position: position,
            initial_velocity: DVec2::ZERO,
        })
    }
}

/// Every component of a bead, as [`Bead::new`] makes them: spawn it, with
/// an [`OnWire`](crate::OnWire) to put the bead on a wire.
pub type BeadBundle = (Bead, BeadPosition, BeadVelocity, BeadMass, BeadParams);

/// A bead spawned without [`BeadParams`] restarts where it was spawned.
fn remember_start<V: Coordinates + Reflect + TypePath>(
    mut world: DeferredWorld,
    context: HookContext,
) {
    let entity = context.entity;
    if world.get::<BeadParams<V>>(entity).is_some() {
        return;
    }
    let start = world.entity(entity);
    let params = BeadParams {
        mass: start.get::<BeadMass>().map_or(1.0, BeadMass::get),
        initial_position: start.get::<BeadPosition<V>>().map_or(V::ZERO, |p| p.0),
        initial_velocity: start.get::<BeadVelocity<V>>().map_or(V::ZERO, |v| v.0),
    };
    world.commands().entity(entity).insert_if_new(params);
}

/// A bead's position in `f64` world coordinates. The step writes it; a game
/// may too (a teleport).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut, Reflect)]
#[reflect(Component)]
pub struct BeadPosition<V: Coordinates = DVec2>(pub V);

/// A bead's velocity. The step writes it; a game may too (a kick).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut, Reflect)]
#[reflect(Component)]
pub struct BeadVelocity<V: Coordinates = DVec2>(pub V);

/// A bead's mass in kg, positive and finite: made only by
/// [`BeadMass::new`], so the step never divides by a bad one. 1 kg by
/// default.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct BeadMass(f64);

impl Default for BeadMass {
    fn default() -> Self {
        Self(1.0)
    }
}

impl BeadMass {
    /// A mass, if it is positive and finite.
    pub fn new(mass: f64) -> Result<Self, ParamError> {
        positive("mass", mass).map(Self)
    }

    /// The mass in kg.
    #[inline(always)]
    pub fn get(&self) -> f64 {
        self.0
    }
}

/// The external force accumulated on a bead for the next step, gravity not
/// included (the step adds `m g` itself), and its stiffness: the sum of the
/// spring constants in it. Add to it through [`BeadForces`] from a system
/// in [`WireBeadSystems::Forces`](crate::WireBeadSystems::Forces); the step
/// consumes it, so both are zero again after every step.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Component)]
pub struct BeadForce<V: Coordinates = DVec2> {
    force: V,
    stiffness: f64,
}

impl<V: Coordinates> BeadForce<V> {
    /// The force added so far, and its stiffness.
    pub fn get(&self) -> (V, f64) {
        (self.force, self.stiffness)
    }

    /// The force of the next step on a bead of mass `mass` at `at`, eq. (5):
    /// gravity plus the accumulated force, linearized at the bead's
    /// position.
    #[inline(always)]
    pub(crate) fn linear(&self, mass: f64, gravity: V, at: V) -> LinearForce<V> {
        LinearForce {
            force: self.force + gravity * mass,
            stiffness: self.stiffness,
            at,
        }
    }

    /// Empties the accumulator (the step has used it), writing only where
    /// a force was added.
    #[inline(always)]
    pub(crate) fn clear(&mut self) {
        if *self != Self::default() {
            *self = Self::default();
        }
    }
}

/// The query a game adds forces through, in
/// [`WireBeadSystems::Forces`](crate::WireBeadSystems::Forces):
/// `Query<BeadForces>`, then [`add_force`](BeadForcesItem::add_force) or
/// [`add_spring`](BeadForcesItem::add_spring) on each item.
#[derive(QueryData)]
#[query_data(mutable)]
pub struct BeadForces<V: Coordinates + Reflect + TypePath = DVec2> {
    /// Where the bead is (a spring pulls from here).
    pub position: &'static BeadPosition<V>,
    /// The accumulator.
    pub force: &'static mut BeadForce<V>,
}

impl<V: Coordinates + Reflect + TypePath> BeadForcesItem<'_, '_, V> {
    /// Adds a constant force for the next step.
    pub fn add_force(&mut self, force: V) {
        self.force.force += force;
    }

    /// Adds a spring `k (anchor - x)` for the next step.
    pub fn add_spring(&mut self, k: f64, anchor: V) {
        let pull = (anchor - self.position.0) * k;
        self.force.force += pull;
        self.force.stiffness += k;
    }

    /// The force added for the next step so far, and its stiffness.
    pub fn accumulated(&self) -> (V, f64) {
        self.force.get()
    }
}

/// What the step and a restart read and write of a bead: its state, mass
/// and force.
#[derive(QueryData)]
#[query_data(mutable)]
pub(crate) struct BeadMotion<V: Coordinates + Reflect + TypePath = DVec2> {
    pub(crate) position: &'static mut BeadPosition<V>,
    pub(crate) velocity: &'static mut BeadVelocity<V>,
    pub(crate) mass: &'static mut BeadMass,
    pub(crate) force: &'static mut BeadForce<V>,
}

/// A bead's position and velocity as the solver takes them.
#[inline(always)]
fn state_of<V: Coordinates>(
    position: &BeadPosition<V>,
    velocity: &BeadVelocity<V>,
) -> BeadState<V> {
    BeadState {
        position: position.0,
        velocity: velocity.0,
    }
}

impl<V: Coordinates + Reflect + TypePath> BeadMotionItem<'_, '_, V> {
    /// Position and velocity.
    pub(crate) fn state(&self) -> BeadState<V> {
        state_of(&self.position, &self.velocity)
    }

    /// The mass.
    pub(crate) fn mass(&self) -> f64 {
        self.mass.get()
    }

    /// Stores a step's new state and clears the consumed force (touching
    /// the force only where one was added).
    #[inline]
    pub(crate) fn advance_to(&mut self, state: BeadState<V>) {
        self.position.0 = state.position;
        self.velocity.0 = state.velocity;
        // Marked changed only where a force was added.
        self.force.set_if_neq(BeadForce::default());
    }

    /// Applies `params`' mass and initial state, the force cleared.
    pub(crate) fn reset(&mut self, params: &BeadParams<V>) {
        self.mass.set_if_neq(BeadMass(params.mass));
        self.advance_to(state_of(
            &BeadPosition(params.initial_position),
            &BeadVelocity(params.initial_velocity),
        ));
    }
}

impl<V: Coordinates + Reflect + TypePath> BeadMotionReadOnlyItem<'_, '_, V> {
    /// Position and velocity.
    pub(crate) fn state(&self) -> BeadState<V> {
        state_of(self.position, self.velocity)
    }

    /// The mass.
    pub(crate) fn mass(&self) -> f64 {
        self.mass.get()
    }
}

/// Edited [`BeadParams`] for one bead, applied (and removed) by the next
/// [`Restart`](crate::Restart). Construct it with [`NextBeadParams::new`] so that
/// an invalid edit never gets into the world. `NextBeadParams` edits a bead
/// in the plane, `NextBeadParams<DVec3>` one in space.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct NextBeadParams<V: Coordinates + Reflect + TypePath = DVec2>(BeadParams<V>);

impl NextBeadParams {
    /// A pending edit of a bead in the plane, if `params` is valid.
    pub fn new(params: BeadParams) -> Result<Self, ParamError> {
        Self::validated(params)
    }
}

impl NextBeadParams<DVec3> {
    /// A pending edit of a bead in space, if `params` is valid.
    pub fn in_space(params: BeadParams<DVec3>) -> Result<Self, ParamError> {
        Self::validated(params)
    }
}

impl<V: Coordinates + Reflect + TypePath> NextBeadParams<V> {
    /// A pending edit, if `params` is valid.
    pub(crate) fn validated(params: BeadParams<V>) -> Result<Self, ParamError> {
        params.validate()?;
        Ok(Self(params))
    }

    /// The edited parameters.
    pub fn get(&self) -> &BeadParams<V> {
        &self.0
    }

    /// Edits in place; kept only if the result is valid.
    pub fn update(&mut self, edit: impl FnOnce(&mut BeadParams<V>)) -> Result<(), ParamError> {
        super::params::edit_validated(&mut self.0, edit, BeadParams::validate)
    }
}

/// A point a spring pulls the bead toward while present: the force
/// `k (anchor - x)`, k being
/// [`SimParams::drag_stiffness`](crate::SimParams::drag_stiffness). The
/// assignment's mouse drag is one (the scene inserts it on grab, moves it
/// with the cursor, removes it on release); a game may pull a bead anywhere
/// with one. `SpringAnchor` pulls a bead in the plane,
/// `SpringAnchor<DVec3>` one in space.
///
/// On an avian rigid body (features `avian2d`, `avian3d`, with the
/// `PathJointPlugin` of its dimension) the same spring pulls the body's
/// [`GrabPoint`] (its origin without one), as a force at that point: the
/// scene's mouse drag of a body.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct SpringAnchor<V: Coordinates + Reflect + TypePath = DVec2>(V);

/// The point of a rigid body, in the body's frame, that its
/// [`SpringAnchor`] pulls: where the mouse took hold of it.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Component)]
pub struct GrabPoint<V: Coordinates + Reflect + TypePath = DVec2>(V);

impl<V: Coordinates + Reflect + TypePath> GrabPoint<V> {
    /// The point `local` of the body (its frame), if it is finite.
    pub fn new(local: V) -> Result<Self, ParamError> {
        finite_vector("grab point", local).map(Self)
    }

    /// The point, in the body's frame.
    pub fn get(&self) -> V {
        self.0
    }
}

impl<V: Coordinates + Reflect + TypePath> SpringAnchor<V> {
    /// An anchor at `point`, if it is finite.
    pub fn new(point: V) -> Result<Self, ParamError> {
        finite_vector("spring anchor", point).map(Self)
    }

    /// Where the spring pulls toward.
    pub fn get(&self) -> V {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spring_anchor_off_the_map_is_refused_in_words() {
        assert_eq!(
            SpringAnchor::new(DVec2::new(f64::NAN, 0.0))
                .unwrap_err()
                .to_string(),
            "spring anchor must be finite, got (NaN, 0)"
        );
    }

    #[test]
    fn a_mass_that_is_not_positive_and_finite_is_refused_in_words() {
        for (mass, words) in [
            (0.0, "mass must be positive and finite, got 0"),
            (-2.0, "mass must be positive and finite, got -2"),
            (f64::NAN, "mass must be positive and finite, got NaN"),
            (f64::INFINITY, "mass must be positive and finite, got inf"),
        ] {
            assert_eq!(BeadMass::new(mass).unwrap_err().to_string(), words);
        }
        assert_eq!(BeadMass::new(2.5).unwrap().get(), 2.5);
    }

    #[test]
    fn a_bead_spawns_in_one_expression_with_every_column() {
        let params = BeadParams {
            mass: 2.0,
            initial_position: DVec2::new(0.5, -1.0),
            initial_velocity: DVec2::new(0.0, 3.0),
        };
        let mut world = World::new();
        let bead = world.spawn(Bead::new(params).unwrap()).id();
        world.flush();
        let bead = world.entity(bead);
        assert_eq!(bead.get::<BeadPosition>().unwrap().0, DVec2::new(0.5, -1.0));
        assert_eq!(bead.get::<BeadVelocity>().unwrap().0, DVec2::new(0.0, 3.0));
        assert_eq!(bead.get::<BeadMass>().unwrap().get(), 2.0);
        assert_eq!(bead.get::<BeadForce>().unwrap().get(), (DVec2::ZERO, 0.0));
        assert_eq!(bead.get::<BeadParams>(), Some(&params));
    }

    #[test]
    fn a_bare_bead_remembers_the_state_it_was_spawned_in() {
        let mut world = World::new();
        let (p, v) = (DVec2::new(1.0, 2.0), DVec2::new(-3.0, 0.25));
        let bead = world
            .spawn((
                Bead,
                BeadPosition(p),
                BeadVelocity(v),
                BeadMass::new(4.0).unwrap(),
            ))
            .id();
        let plain = world.spawn(Bead).id();
        world.flush();
        let expected = BeadParams {
            mass: 4.0,
            initial_position: p,
            initial_velocity: v,
        };
        assert_eq!(world.get::<BeadParams>(bead), Some(&expected));
        let plain = world.entity(plain);
        assert_eq!(plain.get::<BeadMass>().unwrap().get(), 1.0);
        assert_eq!(plain.get::<BeadPosition>().unwrap().0, DVec2::ZERO);
        assert_eq!(
            plain.get::<BeadParams>().unwrap().initial_position,
            DVec2::ZERO
        );
    }

    #[test]
    fn forces_accumulate_and_a_spring_pulls_from_where_the_bead_is() {
        let mut world = World::new();
        let at = DVec2::new(1.0, -1.0);
        let bead = world.spawn(Bead::at_rest(1.0, at).unwrap()).id();
        let mut query = world.query::<BeadForces>();
        let mut forces = query.get_mut(&mut world, bead).unwrap();
        forces.add_force(DVec2::new(0.5, 0.0));
        forces.add_spring(20.0, DVec2::new(2.0, 1.0));
        forces.add_spring(5.0, at);
        let (force, stiffness) = forces.accumulated();
        assert_eq!(force, DVec2::new(0.5 + 20.0, 40.0));
        assert_eq!(stiffness, 25.0);
        // The force of the step adds the weight and is linear about `at`.
        let step = world
            .get::<BeadForce>(bead)
            .unwrap()
            .linear(2.0, DVec2::new(0.0, -10.0), at);
        assert_eq!(step.force, DVec2::new(20.5, 20.0));
        assert_eq!((step.stiffness, step.at), (25.0, at));
    }
}
