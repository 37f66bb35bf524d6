//! The ECS nouns: [`Wire`], [`Bead`], the [`OnWire`] relationship, the drag
//! target, diagnostics and the divergence marker.

use std::fmt;
use std::sync::Arc;

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::params::{BeadParams, ParamError};
use crate::solver::{BeadState, SolveError};
use crate::wire::{Circle, Ellipse, ImplicitCurve, Line, Parabola, Pose, Sine, WireShape};

/// A wire: a shape placed in the plane by the entity's `Transform`
/// (translation x, y and rotation about z; the wire should be a top-level
/// entity, since the plugin reads `Transform`, not `GlobalTransform`).
///
/// Built only through validating constructors, so a wire in the world always
/// has valid dimensions.
#[derive(Component, Clone, Debug)]
#[require(Transform, WirePose)]
pub struct Wire {
    shape: WireShape,
}

impl Wire {
    /// A wire of any shape, if its dimensions are valid.
    pub fn new(shape: WireShape) -> Result<Self, ParamError> {
        shape.validate()?;
        Ok(Self { shape })
    }

    /// A circle of the given radius about the entity's origin.
    pub fn circle(radius: f64) -> Result<Self, ParamError> {
        Self::new(WireShape::Circle(Circle { radius }))
    }

    /// An ellipse with semi-axes `a` (local x) and `b` (local y).
    pub fn ellipse(a: f64, b: f64) -> Result<Self, ParamError> {
        Self::new(WireShape::Ellipse(Ellipse { a, b }))
    }

    /// The infinite line along the entity's local x axis.
    pub fn line() -> Self {
        Self {
            shape: WireShape::Line(Line),
        }
    }

    /// The parabola `y = x²/(4f)`.
    pub fn parabola(focal_length: f64) -> Result<Self, ParamError> {
        Self::new(WireShape::Parabola(Parabola { focal_length }))
    }

    /// The sine track `y = A sin(2πx/λ)`.
    pub fn sine(amplitude: f64, wavelength: f64) -> Result<Self, ParamError> {
        Self::new(WireShape::Sine(Sine {
            amplitude,
            wavelength,
        }))
    }

    /// A wire along a curve of the game's own.
    pub fn custom(curve: impl ImplicitCurve + Send + Sync + 'static) -> Self {
        Self {
            shape: WireShape::Custom(Arc::new(curve)),
        }
    }

    /// The shape.
    pub fn shape(&self) -> &WireShape {
        &self.shape
    }
}

/// Where a wire sits for the current step: its `Transform` read once, in
/// [`WireBeadSystems::Prepare`](crate::WireBeadSystems::Prepare), so the
/// beads on it do not each convert it. Kept by the plugin.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct WirePose(Option<Pose>);

impl Default for WirePose {
    fn default() -> Self {
        Self(Some(Pose::IDENTITY))
    }
}

impl WirePose {
    /// The pose of `transform`, or none if it is not finite.
    pub fn from_transform(transform: &Transform) -> Self {
        Self(Pose::from_transform(transform).ok())
    }

    /// The pose, or the error that the wire's transform is not finite.
    pub fn get(&self) -> Result<Pose, ParamError> {
        self.0.ok_or(ParamError::NotFinite {
            name: "wire transform",
            value: f64::NAN,
        })
    }
}

/// An edited shape for a wire, applied (and removed) by the next
/// [`Restart`](crate::Restart). Built only from a valid shape.
#[derive(Component, Clone, Debug)]
pub struct PendingWire(Wire);

impl PendingWire {
    /// A pending edit, if `shape` is valid.
    pub fn new(shape: WireShape) -> Result<Self, ParamError> {
        Wire::new(shape).map(Self)
    }

    /// The edited shape.
    pub fn shape(&self) -> &WireShape {
        self.0.shape()
    }

    /// The wire it will become.
    pub fn wire(&self) -> &Wire {
        &self.0
    }
}

/// Puts a bead on a wire. Several beads may share one wire; despawning the
/// wire despawns its beads.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
#[relationship(relationship_target = WireBeads)]
pub struct OnWire(pub Entity);

/// The beads on a wire, kept by Bevy from their [`OnWire`].
#[derive(Component, Debug, Default)]
#[relationship_target(relationship = OnWire, linked_spawn)]
pub struct WireBeads(Vec<Entity>);

/// A bead: its applied parameters, its `f64` state, the external force
/// accumulated for the next step and the last constraint multiplier.
///
/// The position and velocity may be written directly (a game teleporting a
/// bead); the step checks them and marks the bead [`Diverged`] rather than
/// propagate a non-finite value.
///
/// With [`WireBeadPlugin`](crate::WireBeadPlugin)'s defaults a bead also gets
/// a `Transform` (the plugin writes its position there) and
/// [`BeadDiagnostics`]; [`WireBeadPlugin::lean`](crate::WireBeadPlugin::lean)
/// leaves both out for crowds of beads nobody looks at one by one.
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct Bead {
    params: BeadParams,
    /// Position in world coordinates.
    pub position: DVec2,
    /// Velocity.
    pub velocity: DVec2,
    /// The external force accumulated for the next step, gravity not
    /// included (the step adds `m g` itself). The step consumes it: it is
    /// zero again after every step.
    pub force: DVec2,
    /// The stiffness of that force (the sum of the spring constants in it):
    /// multi-stage integrators evaluate `force - force_stiffness (x - position)`.
    /// Consumed with `force`.
    pub force_stiffness: f64,
    /// λ of the last step (for RATTLE the mean of its position and velocity
    /// multipliers).
    pub lambda: f64,
}

impl Bead {
    /// A bead at its initial position with its initial velocity, if the
    /// parameters are valid.
    pub fn new(params: BeadParams) -> Result<Self, ParamError> {
        params.validate()?;
        Ok(Self::initial(params))
    }

    fn initial(params: BeadParams) -> Self {
        Self {
            params,
            position: params.initial_position,
            velocity: params.initial_velocity,
            force: DVec2::ZERO,
            force_stiffness: 0.0,
            lambda: 0.0,
        }
    }

    /// A bead of the given mass at rest at `position`.
    pub fn at_rest(mass: f64, position: DVec2) -> Result<Self, ParamError> {
        Self::new(BeadParams {
            mass,
            initial_position: position,
            initial_velocity: DVec2::ZERO,
        })
    }

    /// The applied parameters (what a restart returns to).
    pub fn params(&self) -> &BeadParams {
        &self.params
    }

    /// The mass.
    pub fn mass(&self) -> f64 {
        self.params.mass
    }

    /// Position and velocity.
    pub fn state(&self) -> BeadState {
        BeadState {
            position: self.position,
            velocity: self.velocity,
        }
    }

    /// Adds a constant force for the next step (call it from a system in
    /// [`WireBeadSystems::Forces`](crate::WireBeadSystems::Forces)).
    pub fn add_force(&mut self, force: DVec2) {
        self.force += force;
    }

    /// Adds a spring `k (anchor - x)` for the next step.
    pub fn add_spring(&mut self, k: f64, anchor: DVec2) {
        self.force += k * (anchor - self.position);
        self.force_stiffness += k;
    }

    /// Applies `params` and returns the bead to its initial state.
    pub(crate) fn reset(&mut self, params: BeadParams) {
        *self = Self::initial(params);
    }
}

/// Where the user is dragging the bead: while present, the drag spring
/// `k (target - x)` pulls the bead (k is
/// [`SimParams::drag_stiffness`](crate::SimParams::drag_stiffness)). Insert it
/// on grab, update it on move, remove it on release.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct DragTarget(DVec2);

impl DragTarget {
    /// A drag target at `target`, if it is finite.
    pub fn new(target: DVec2) -> Result<Self, ParamError> {
        crate::params::check_vector("drag target", target)?;
        Ok(Self(target))
    }

    /// Where the spring pulls toward.
    pub fn get(&self) -> DVec2 {
        self.0
    }
}

/// Per-bead diagnostics, updated after every step (on beads that have
/// them: see [`WireBeadPlugin::lean`](crate::WireBeadPlugin::lean)).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Component)]
pub struct BeadDiagnostics {
    /// The constraint value `C` (the drift off the wire).
    pub c: f64,
    /// Its rate `Ċ`.
    pub c_dot: f64,
    /// The constraint multiplier λ.
    pub lambda: f64,
    /// The constraint force `λN` of the last step (for RATTLE the mean of
    /// its two multipliers' forces).
    pub constraint_force: DVec2,
    /// `½ m |v|²`.
    pub kinetic: f64,
    /// `-m g·x`.
    pub potential: f64,
    /// Steps taken since the last restart.
    pub steps: u64,
    /// Simulated time since the last restart.
    pub time: f64,
}

impl BeadDiagnostics {
    /// Kinetic plus potential energy.
    pub fn energy(&self) -> f64 {
        self.kinetic + self.potential
    }
}

/// Why a bead stopped.
#[derive(Clone, Debug, PartialEq)]
pub enum DivergenceReason {
    /// The step failed: a singular point, a Newton solve that did not
    /// converge, a non-finite result, or drift past the configured bound.
    Solve(SolveError),
    /// The state was already non-finite before the step (written from
    /// outside).
    NonFiniteState,
    /// The bead's wire entity has no [`Wire`] or its `Transform` is not
    /// finite.
    InvalidWire(String),
}

impl fmt::Display for DivergenceReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Solve(e) => e.fmt(f),
            Self::NonFiniteState => f.write_str("its position or velocity is not finite"),
            Self::InvalidWire(why) => write!(f, "its wire is invalid: {why}"),
        }
    }
}

/// Marks a bead that diverged: it no longer moves until a restart.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct Diverged {
    /// Why.
    pub reason: DivergenceReason,
    /// The simulated time ([`SimClock`](crate::SimClock)) at the end of the
    /// step that found it.
    pub time: f64,
}
