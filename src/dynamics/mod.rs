//! The ECS nouns a game spawns and reads: [`Wire`] and [`OnWire`], [`Bead`]
//! and its edits, the links between beads ([`Rod`], [`Pin`], [`Spring`],
//! [`Joint`]), the parameters, the diagnostics. Plain data with
//! validating constructors; the step that moves them is in
//! [`plugin`](crate::plugin), the math it calls in [`solver`](crate::solver).

mod bead;
mod diagnostics;
mod dimension;
mod links;
mod params;
mod rail;
mod touch;
mod wire;

pub use bead::{
    Bead, BeadBundle, BeadForce, BeadForces, BeadForcesItem, BeadMass, BeadParams, BeadPosition,
    BeadVelocity, GrabPoint, NextBeadParams, SpaceBead, SpaceBeadBundle, SpringAnchor,
};
pub(crate) use bead::{BeadMotion, BeadMotionItem};
pub use diagnostics::{BeadDiagnostics, BeadDiverged, Diverged, DivergenceReason};
pub use dimension::{Dimension, WireRows};
pub(crate) use dimension::{placement, put_in_place, wire_pose};
pub use links::{ConstraintDiagnostics, Joint, Pin, Rod, Spring};
pub use params::{MAX_TIMESTEP, MIN_TIMESTEP, NextParams, SimParams, SpaceParams};
pub use rail::RailOrientation;
pub use touch::{
    BeadRadius, BeadSentBack, BeadStruckBody, BeadsStruck, CatchesBeads, Contacts, Restitution,
    SendsBeadsBack,
};
#[cfg(any(feature = "avian2d", feature = "avian3d"))]
pub use wire::WireOnBody;
pub(crate) use wire::{Boarded, RidingBody, WirePose};
pub use wire::{
    ContactChanged, NextWireShape, OnWire, PrescribedMotion, SpaceWire, Wire, WireBeads,
    WireContact, WirePlace, pose_of,
};
