//! Beads with a radius that ride a plain wire alone ([`LoneTouch`]): each
//! steps by itself, as a bead without a radius does, and is a body of one
//! bead in the touch settlement, so that beads apart cost a bead's step
//! each and a meeting re-steps only the beads it concerns. A pair that
//! comes to rest in touch is joined by a contact row, in an island, when
//! the islands are next built (see `touch::near`).

use bevy::prelude::*;

use crate::dynamics::{BeadDiagnostics, Dimension, DivergenceReason};
use crate::geometry::{Track, WirePath};
use crate::plugin::step::{LoneStep, OnTrack};
use crate::solver::{
    self, BeadState, LinearForce, RowReport, SolveError, StepOutput, StepSettings, TouchBody,
};

/// A bead with a radius on a plain wire, joined to nothing: what its step
/// and the touch settlement keep of it.
#[derive(Clone)]
pub(super) struct LoneTouch<V: Dimension> {
    pub(super) entity: Entity,
    pub(super) wire: Entity,
    /// The wire's path this step.
    pub(super) path: WirePath<V>,
    pub(super) mass: f64,
    /// Its radius, restitution and friction against another bead,
    /// gathered each step.
    pub(super) radius: f64,
    pub(super) restitution: f64,
    pub(super) friction: f64,
    pub(super) force: LinearForce<V>,
    /// Where its step started, and where it ends as taken so far.
    pub(super) start: BeadState<V>,
    pub(super) state: BeadState<V>,
    /// The last step's report: `C`, `Ċ`, λ and the constraint force.
    pub(super) output: Option<StepOutput<V>>,
    /// Whether it stepped this step, and how.
    pub(super) outcome: Option<Result<(), DivergenceReason>>,
    /// Its kinetic and gravitational energy after the last step.
    pub(super) energy: f64,
}

impl<V: Dimension> LoneTouch<V> {
    /// Bead `entity` of `mass` at `state` on `wire`, before its first
    /// step.
    pub(super) fn new(entity: Entity, wire: Entity, mass: f64, state: BeadState<V>) -> Self {
        Self {
            entity,
            wire,
            path: WirePath::Fixed(V::Pose::default()),
            mass,
            radius: 0.0,
            restitution: 1.0,
            friction: 0.0,
            force: LinearForce::default(),
            start: state,
            state,
            output: None,
            outcome: None,
            energy: 0.0,
        }
    }
}

impl<V: LoneStep> LoneTouch<V> {
    /// Steps from `state` at `time` by `settings.dt` on its wire, of
    /// `shape`.
    fn step_from(
        &self,
        shape: &V::Lone,
        time: f64,
        state: BeadState<V>,
        settings: &StepSettings,
    ) -> Result<StepOutput<V>, SolveError> {
        let part = Part {
            time,
            state,
            force: &self.force,
            mass: self.mass,
            settings,
        };
        V::on_path(shape, &self.path, part)
    }

    /// Its whole step on its wire, of `shape`, from where it is, starting
    /// at `time`: kept as its start and end, its outcome set.
    pub(super) fn step(&mut self, shape: &V::Lone, time: f64, settings: &StepSettings) {
        self.start = self.state;
        if !self.state.is_finite() {
            self.outcome = Some(Err(DivergenceReason::NonFiniteState));
            return;
        }
        let stepped = self.step_from(shape, time, self.state, settings);
        self.outcome = Some(match stepped {
            Ok(output) => {
                self.state = output.state;
                self.output = Some(output);
                Ok(())
            }
            Err(e) => Err(DivergenceReason::Solve(e)),
        });
    }
}

impl<V: Dimension> LoneTouch<V> {
    /// Its diagnostics where its step ended, under `gravity`.
    pub(super) fn diagnostics(&self, gravity: V) -> BeadDiagnostics<V> {
        let output = self.output.unwrap_or(StepOutput {
            state: self.state,
            lambda: 0.0,
            constraint_force: V::ZERO,
            c: 0.0,
            c_dot: 0.0,
        });
        let row = RowReport {
            c: output.c,
            c_dot: output.c_dot,
            lambda: output.lambda,
        };
        BeadDiagnostics::of(self.state, self.mass, gravity, row, output.constraint_force)
    }
}

/// A part of a bead's step, run on its wire's concrete track.
struct Part<'a, V: LoneStep> {
    time: f64,
    state: BeadState<V>,
    force: &'a LinearForce<V>,
    mass: f64,
    settings: &'a StepSettings,
}

impl<V: LoneStep> OnTrack<V, Result<StepOutput<V>, SolveError>> for Part<'_, V> {
    #[inline(always)]
    fn run<T: Track<V> + ?Sized>(self, track: &T) -> Result<StepOutput<V>, SolveError> {
        solver::step_on(
            track,
            self.time,
            self.state,
            self.force,
            self.mass,
            self.settings,
        )
    }
}

/// The wire's normal `∇C` at a point and time, run on its concrete track.
struct NormalAt<V> {
    time: f64,
    at: V,
}

impl<V: LoneStep> OnTrack<V, V> for NormalAt<V> {
    fn run<T: Track<V> + ?Sized>(self, track: &T) -> V {
        track.geometry(self.time, self.at).normal
    }
}

/// One lone bead as the touch settlement steps it, on its wire of
/// `shape`.
pub(super) struct LoneBody<'a, V: LoneStep> {
    pub(super) lone: &'a mut LoneTouch<V>,
    pub(super) shape: &'a V::Lone,
    pub(super) settings: StepSettings,
}

impl<V: LoneStep> TouchBody<V> for LoneBody<'_, V> {
    fn start(&self) -> &[BeadState<V>] {
        std::slice::from_ref(&self.lone.start)
    }

    fn end(&self) -> &[BeadState<V>] {
        std::slice::from_ref(&self.lone.state)
    }

    fn advance(
        &mut self,
        time: f64,
        h: f64,
        states: &mut [BeadState<V>],
    ) -> Result<(), SolveError> {
        let Some(state) = states.first_mut() else {
            return Ok(());
        };
        let settings = self.settings.part(h);
        let output = self.lone.step_from(self.shape, time, *state, &settings)?;
        *state = output.state;
        self.lone.output = Some(output);
        Ok(())
    }

    fn keep(&mut self) {}

    fn respond(
        &mut self,
        time: f64,
        states: &[BeadState<V>],
        _bead: usize,
        impulse: V,
    ) -> Result<Vec<V>, SolveError> {
        let Some(state) = states.first() else {
            return Ok(Vec::new());
        };
        let at = state.position;
        let normal = V::on_path(self.shape, &self.lone.path, NormalAt { time, at });
        let change = solver::wire_response(at, normal, self.lone.mass, impulse)?;
        Ok(vec![change])
    }

    fn push(&self, _bead: usize) -> V {
        self.lone.force.at(self.lone.state.position) / self.lone.mass
    }

    fn finish(&mut self, states: &[BeadState<V>]) {
        if let Some(&state) = states.first() {
            self.lone.state = state;
        }
    }
}
