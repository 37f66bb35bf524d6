//! Beads that strike avian's bodies, what both dimensions share: before
//! the step, each collider (not a sensor) is read into
//! [`WorldBodies`](crate::plugin::WorldBodies) as a shape moving on with
//! its body's velocity and spin over the step; the island step meets it
//! with the beads that come near (`solver::meet_obstacles`); after the
//! step, the impulses the beads gave are applied to the dynamic bodies at
//! the points struck. Everything is read in `f64` and placed in space
//! (the plane's `z` zero, its turns about `z`).

use bevy::ecs::query::{QueryData, QueryItem, ROQueryItem, ReadOnlyQueryData};
use bevy::math::{DMat3, DQuat, DVec3};
use bevy::prelude::*;

use crate::dynamics::{BeadMass, BeadRadius, Dimension, SimParams};
use crate::geometry::Coordinates;
use crate::plugin::{BodyImpulse, SceneEnergy, WorldBodies, WorldBody};
use crate::solver::{BodyPoint, Nearest, Obstacle};

/// A collider as read: its shape, where it is, its body and its surface.
pub(crate) struct ColliderRead<S> {
    /// Its shape, in its own frame.
    pub shape: S,
    /// Its origin and turn.
    pub origin: DVec3,
    /// Its turn.
    pub turn: DQuat,
    /// Its rigid body (itself where it is one), if any.
    pub body: Option<Entity>,
    /// Its restitution and Coulomb friction.
    pub surface: (f64, f64),
}

/// A rigid body's motion and mass as read, in the world's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BodyRead {
    /// Its centre of mass.
    pub centre: DVec3,
    /// Its velocity and spin.
    pub velocity: DVec3,
    /// Its spin (rad/s, about `z` in the plane).
    pub spin: DVec3,
    /// Its inverse mass and inverse inertia (zero where strikes do not
    /// move it: static and kinematic bodies).
    pub inverse_mass: f64,
    /// Its inverse inertia, in the world's frame.
    pub inverse_inertia: DMat3,
}

impl BodyRead {
    /// A body that does not move.
    const FIXED: Self = Self {
        centre: DVec3::ZERO,
        velocity: DVec3::ZERO,
        spin: DVec3::ZERO,
        inverse_mass: 0.0,
        inverse_inertia: DMat3::ZERO,
    };
}

/// What beads striking bodies need of one avian crate: its colliders and
/// bodies, read in `f64`, and where impulses go.
pub(crate) trait WorldShapes: Send + Sync + 'static {
    /// The beads' coordinates.
    type V: Dimension;
    /// A collider's shape.
    type Shape: Clone + Send + Sync + 'static;
    /// A collider as the query reads it.
    type Collider: ReadOnlyQueryData;
    /// A rigid body as the query reads it.
    type Body: ReadOnlyQueryData;
    /// What takes an impulse at a point.
    type Forces: QueryData;
    /// Avian's gravity.
    type Gravity: Resource;

    /// A collider, none for a sensor.
    fn collider(
        collider: ROQueryItem<'_, '_, Self::Collider>,
        entity: Entity,
    ) -> Option<ColliderRead<Self::Shape>>;
    /// A body's motion and mass.
    fn body(body: ROQueryItem<'_, '_, Self::Body>) -> BodyRead;
    /// The point of `shape`'s surface nearest `local` (in its frame), and
    /// whether `local` is inside it.
    fn project(shape: &Self::Shape, local: DVec3) -> (DVec3, bool);
    /// How far the shape reaches from its origin, at most.
    fn extent(shape: &Self::Shape) -> f64;
    /// Applies `impulse` at the world point `at`.
    fn apply(forces: QueryItem<'_, '_, Self::Forces>, impulse: DVec3, at: DVec3);
    /// Avian's gravity, in space.
    fn gravity(gravity: &Self::Gravity) -> DVec3;
    /// A dynamic body's kinetic and gravitational energy under
    /// `gravity`; zero for a static or kinematic one.
    fn energy(body: ROQueryItem<'_, '_, Self::Body>, gravity: DVec3) -> f64;
}

/// A collider as beads meet it over one step: its shape moving on with
/// its body's velocity and spin.
struct Moving<A: WorldShapes> {
    shape: A::Shape,
    origin: DVec3,
    turn: DQuat,
    body: BodyRead,
    /// The strikes within the step: each one's part of the step, and the
    /// velocity and spin it added.
    kicks: Vec<(f64, DVec3, DVec3)>,
    extent: f64,
    dt: f64,
    surface: (f64, f64),
}

impl<A: WorldShapes> Moving<A> {
    /// How far it has moved and turned (as a rotation vector), a part `s`
    /// of the step in, and its velocity and spin there.
    fn motion(&self, s: f64) -> (DVec3, DVec3, DVec3, DVec3) {
        let dt = self.dt;
        let (mut moved, mut turned) = (self.body.velocity * (s * dt), self.body.spin * (s * dt));
        let (mut velocity, mut spin) = (self.body.velocity, self.body.spin);
        for &(from, dv, dw) in self.kicks.iter().filter(|k| k.0 < s) {
            moved += dv * ((s - from) * dt);
            turned += dw * ((s - from) * dt);
            velocity += dv;
            spin += dw;
        }
        (moved, turned, velocity, spin)
    }

    /// Where its centre of mass is, a part `s` of the step in, and how it
    /// has turned.
    fn placed(&self, s: f64) -> (DVec3, DQuat) {
        let (moved, turned, _, _) = self.motion(s);
        (self.body.centre + moved, DQuat::from_scaled_axis(turned))
    }
}

impl<A: WorldShapes> Obstacle<A::V> for Moving<A> {
    fn nearest(&self, s: f64, at: A::V) -> Option<Nearest<A::V>> {
        let (centre, turned) = self.placed(s);
        let origin = centre + turned * (self.origin - self.body.centre);
        let turn = turned * self.turn;
        let at = at.xyz();
        let local = turn.inverse() * (at - origin);
        let (point, inside) = A::project(&self.shape, local);
        let point = origin + turn * point;
        let d = at - point;
        let distance = d.length();
        if !(distance > 0.0 && distance.is_finite()) {
            return None;
        }
        let sign = if inside { -1.0 } else { 1.0 };
        Some(Nearest {
            point: A::V::from_xyz(point),
            normal: A::V::from_xyz(d * (sign / distance)),
            distance: sign * distance,
        })
    }

    fn point(&self, s: f64, at: A::V) -> BodyPoint {
        let (centre, _) = self.placed(s);
        let (_, _, velocity, spin) = self.motion(s);
        let r = at.xyz() - centre;
        let body = &self.body;
        let cross =
            |v: DVec3| DMat3::from_cols(v.cross(DVec3::X), v.cross(DVec3::Y), v.cross(DVec3::Z));
        // K J = J/M + (I⁻¹ (r × J)) × r.
        let skew = cross(r);
        BodyPoint {
            velocity: velocity + spin.cross(r),
            response: DMat3::from_diagonal(DVec3::splat(body.inverse_mass))
                - skew * body.inverse_inertia * skew,
        }
    }

    fn reach(&self) -> f64 {
        let arm = (self.origin - self.body.centre).length() + self.extent;
        (self.body.velocity.length() + self.body.spin.length() * arm) * self.dt
    }

    fn surface(&self) -> (f64, f64) {
        self.surface
    }

    fn struck(&mut self, s: f64, at: A::V, impulse: A::V) {
        let (centre, _) = self.placed(s);
        let j = impulse.xyz();
        let dv = j * self.body.inverse_mass;
        let dw = self.body.inverse_inertia * (at.xyz() - centre).cross(j);
        if dv.is_finite() && dw.is_finite() {
            self.kicks.push((s, dv, dw));
        }
    }
}

/// Reads every collider that is not a sensor into `world`, with the box
/// it sweeps over the coming step, its body moving on as it moves now:
/// what the island step meets the beads with.
pub(crate) fn gather_world_bodies<A: WorldShapes>(
    colliders: Query<(Entity, A::Collider)>,
    bodies: Query<A::Body>,
    params: Res<SimParams>,
    mut world: ResMut<WorldBodies<A::V>>,
) {
    let dt = params.step_settings().dt;
    world.bodies.clear();
    world.impulses.clear();
    for (entity, collider) in &colliders {
        let Some(read) = A::collider(collider, entity) else {
            continue;
        };
        let body = read
            .body
            .and_then(|b| bodies.get(b).ok())
            .map_or(BodyRead::FIXED, A::body);
        let extent = A::extent(&read.shape);
        let moving = Moving::<A> {
            shape: read.shape,
            origin: read.origin,
            turn: read.turn,
            body,
            kicks: Vec::new(),
            extent,
            dt,
            surface: read.surface,
        };
        let reach = moving.reach();
        let (from, to) = (read.origin, read.origin + body.velocity * dt);
        let grown = extent + reach;
        let bounds = (from.min(to) - grown, from.max(to) + grown);
        if !(bounds.0.is_finite() && bounds.1.is_finite()) {
            continue;
        }
        world.bodies.push(WorldBody {
            entity,
            moved: read.body.filter(|_| body.inverse_mass > 0.0),
            bounds,
            obstacle: Box::new(moving),
        });
    }
}

/// Applies to each dynamic body the impulses its colliders took from
/// beads this step, at the points struck.
pub(crate) fn apply_world_impulses<A: WorldShapes>(
    mut world: ResMut<WorldBodies<A::V>>,
    mut forces: Query<A::Forces>,
) {
    for BodyImpulse {
        body,
        point,
        impulse,
    } in world.impulses.drain(..)
    {
        if let Ok(item) = forces.get_mut(body) {
            A::apply(item, impulse.xyz(), point.xyz());
        }
    }
}

/// Adds to the [`SceneEnergy`] the kinetic and gravitational energy of
/// each dynamic body of avian (under avian's `Gravity`; our beads that
/// ride bodies, counted already, left out), after avian's step: the
/// scene's energy counts the bodies beads strike, ride and push.
pub(crate) fn add_body_energy<A: WorldShapes>(
    mut energy: ResMut<SceneEnergy>,
    gravity: Res<A::Gravity>,
    bodies: Query<A::Body, Without<BeadMass>>,
) {
    let g = A::gravity(&gravity);
    energy.total += bodies.iter().map(|b| A::energy(b, g)).sum::<f64>();
}

/// Whether any bead has a radius (only those meet bodies).
pub(crate) fn any_bead_radius(beads: Query<(), With<BeadRadius>>) -> bool {
    !beads.is_empty()
}

/// [`WorldShapes`] for one avian crate, whose components have the same
/// names in both: `$avian` the crate, `$shapes` the type to implement it
/// on, `$v` the beads' coordinates; `$up` reads one of the crate's
/// vectors into space in `f64`, `$down` writes one back, `$turn` reads a
/// `Rotation` as a quaternion, `$spin` an angular velocity as a vector
/// and `$inverse_inertia` a body's inverse inertia in the world's frame
/// from its `ComputedAngularInertia` and `Rotation`, and `$spin_energy`
/// the energy `½ ω·I ω` of a spin (in space) from the same. Invoked in
/// each avian adapter.
macro_rules! world_shapes {
    (
        $avian:ident, $shapes:ident, $v:ty,
        up: $up:expr, down: $down:expr, turn: $turn:expr, spin: $spin:expr,
        inverse_inertia: $inverse_inertia:expr, spin_energy: $spin_energy:expr
    ) => {
        impl $crate::carrier::WorldShapes for $shapes {
            type V = $v;
            type Shape = $avian::prelude::Collider;
            type Collider = (
                &'static $avian::prelude::Collider,
                &'static $avian::prelude::Position,
                &'static $avian::prelude::Rotation,
                Option<&'static $avian::prelude::ColliderOf>,
                Option<&'static $avian::prelude::Restitution>,
                Option<&'static $avian::prelude::Friction>,
                bevy::prelude::Has<$avian::prelude::Sensor>,
            );
            type Body = (
                &'static $avian::prelude::RigidBody,
                &'static $avian::prelude::LinearVelocity,
                &'static $avian::prelude::AngularVelocity,
                &'static $avian::prelude::ComputedMass,
                &'static $avian::prelude::ComputedAngularInertia,
                &'static $avian::prelude::ComputedCenterOfMass,
                &'static $avian::prelude::Position,
                &'static $avian::prelude::Rotation,
            );
            type Forces = $avian::prelude::Forces;
            type Gravity = $avian::prelude::Gravity;

            fn collider(
                (shape, position, rotation, of, restitution, friction, sensor): bevy::ecs::query::ROQueryItem<'_, '_, Self::Collider>,
                _entity: bevy::prelude::Entity,
            ) -> Option<$crate::carrier::ColliderRead<Self::Shape>> {
                if sensor {
                    return None;
                }
                let restitution = restitution.copied().unwrap_or_default().coefficient;
                let friction = friction.copied().unwrap_or_default().dynamic_coefficient;
                Some($crate::carrier::ColliderRead {
                    shape: shape.clone(),
                    origin: $up(position.0),
                    turn: $turn(rotation),
                    body: of.map(|of| of.body),
                    surface: (f64::from(restitution), f64::from(friction)),
                })
            }

            fn body(
                (kind, linear, spin, mass, inertia, centre, position, rotation): bevy::ecs::query::ROQueryItem<'_, '_, Self::Body>,
            ) -> $crate::carrier::BodyRead {
                let turn = $turn(rotation);
                let moved = kind.is_dynamic();
                $crate::carrier::BodyRead {
                    centre: $up(position.0) + turn * $up(centre.0),
                    velocity: $up(linear.0),
                    spin: $spin(spin.0),
                    inverse_mass: if moved { f64::from(mass.inverse()) } else { 0.0 },
                    inverse_inertia: if moved {
                        $inverse_inertia(inertia, rotation)
                    } else {
                        bevy::math::DMat3::ZERO
                    },
                }
            }

            fn project(shape: &Self::Shape, local: bevy::math::DVec3) -> (bevy::math::DVec3, bool) {
                use $avian::prelude::*;
                let (point, inside) =
                    shape.project_point(Position::default(), Rotation::default(), $down(local), false);
                ($up(point), inside)
            }

            fn extent(shape: &Self::Shape) -> f64 {
                use $avian::prelude::*;
                let aabb = shape.aabb(Default::default(), Rotation::default());
                $up(aabb.min).abs().max($up(aabb.max).abs()).length()
            }

            fn apply(
                mut forces: bevy::ecs::query::QueryItem<'_, '_, Self::Forces>,
                impulse: bevy::math::DVec3,
                at: bevy::math::DVec3,
            ) {
                use $avian::prelude::WriteRigidBodyForces as _;
                forces.apply_linear_impulse_at_point($down(impulse), $down(at));
            }

            fn gravity(gravity: &$avian::prelude::Gravity) -> bevy::math::DVec3 {
                $up(gravity.0)
            }

            fn energy(
                (kind, linear, spin, mass, inertia, centre, position, rotation): bevy::ecs::query::ROQueryItem<'_, '_, Self::Body>,
                gravity: bevy::math::DVec3,
            ) -> f64 {
                if !kind.is_dynamic() {
                    return 0.0;
                }
                let m = f64::from(mass.value());
                let c = $up(position.0) + $turn(rotation) * $up(centre.0);
                let v = $up(linear.0);
                0.5 * m * v.length_squared() - m * gravity.dot(c)
                    + $spin_energy(inertia, rotation, $spin(spin.0))
            }
        }
    };
}

pub(crate) use world_shapes;
