//! One run of beads stored side by side, stepped on one thread: the
//! batched step for beads on unrotated circles (or spheres in space), the
//! single-bead step for the rest, the outputs written in the same pass.

use bevy::ecs::change_detection::ContiguousMut;
use bevy::prelude::*;

use super::lone::{LoneStep, OnTrack};
use super::table::{TableWire, WireTable};
use crate::dynamics::{
    BeadDiagnostics, BeadForce, BeadMass, BeadPosition, BeadVelocity, DivergenceReason, OnWire,
    WireContact,
};
use crate::geometry::{Placement, Surface, Track};
use crate::plugin::report::{FoundDivergences, FoundEvents};
use crate::solver::{
    self, BeadState, Contact, LinearForce, RoundLanes, RoundSteps, RowReport, StepOutput,
    StepSettings,
};

/// How many batches of [`solver::LANES`] beads one call of the batched step
/// takes.
const BATCHES: usize = 8;

/// What stepping a run of beads needs, shared by the threads.
pub(super) struct StepContext<'a, V: LoneStep> {
    pub(super) settings: StepSettings,
    /// Gravity in these coordinates.
    pub(super) gravity: V,
    pub(super) wires: &'a WireTable<V>,
    pub(super) found: &'a FoundDivergences,
    pub(super) events: &'a FoundEvents<V>,
    pub(super) time: f64,
}

impl<V: LoneStep> StepContext<'_, V> {
    /// Steps a run of beads stored side by side. Beads on unrotated circles
    /// or spheres go through the batched step, [`solver::LANES`] at a time, up to
    /// [`BATCHES`] batches per call; the others, and the lanes it hands
    /// back, one by one.
    pub(super) fn step_run(&self, run: BeadRun<V>) {
        // Compiled for AVX2 where the processor has it, so that filling
        // and storing the batches inlines with the batched step.
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = crate::lane::avx2() {
            struct Run<'c, 'w, V: LoneStep>(&'c StepContext<'c, V>, BeadRun<'w, V>);
            impl<V: LoneStep> pulp::NullaryFnOnce for Run<'_, '_, V> {
                type Output = ();
                #[inline(always)]
                fn call(self) {
                    self.0.step_run_here(self.1);
                }
            }
            return simd.vectorize(Run(self, run));
        }
        self.step_run_here(run);
    }

    /// [`StepContext::step_run`] in whatever code it is compiled into.
    #[inline(always)]
    fn step_run_here(&self, mut run: BeadRun<V>) {
        let mut lanes = [RoundLanes::<V>::default(); BATCHES];
        let mut outs = [RoundSteps::<V>::default(); BATCHES];
        let mut waiting = [0; BATCHES * solver::LANES];
        let mut queued = 0;
        let mut i = 0;
        while i < run.entities.len() {
            if queued == waiting.len() {
                solver::step_on_round_batches(&lanes, &self.settings, &mut outs);
                self.finish_batches(&mut run, &outs, &waiting);
                queued = 0;
            }
            // A block of beads side by side, each on a plain circle or sphere: into
            // one batch column by column.
            if queued % solver::LANES == 0
                && self.fill_block(&run, i, &mut lanes[queued / solver::LANES])
            {
                for (lane, wait) in waiting[queued..][..solver::LANES].iter_mut().enumerate() {
                    *wait = i + lane;
                }
                queued += solver::LANES;
                i += solver::LANES;
                continue;
            }
            match self.wires.circle(&run.on_wires[i]) {
                Some((centre, radius)) => {
                    let bead = run.bead(i);
                    lanes[queued / solver::LANES].set(
                        queued % solver::LANES,
                        bead.state,
                        &bead.force(self.gravity),
                        bead.mass,
                        centre,
                        radius,
                    );
                    waiting[queued] = i;
                    queued += 1;
                }
                None => self.step_one(&mut run, i),
            }
            i += 1;
        }
        // The last batches: full ones batched, the rest one by one.
        let whole = queued / solver::LANES;
        solver::step_on_round_batches(&lanes[..whole], &self.settings, &mut outs[..whole]);
        let batched = whole * solver::LANES;
        self.finish_batches(&mut run, &outs[..whole], &waiting[..batched]);
        for &j in &waiting[batched..queued] {
            self.step_one(&mut run, j);
        }
    }

    /// Stores the batched steps of the beads `waiting` (in order, one lane
    /// each); a lane the batch did not finish goes through
    /// [`StepContext::step_one`].
    #[inline(always)]
    fn finish_batches(&self, run: &mut BeadRun<V>, outs: &[RoundSteps<V>], waiting: &[usize]) {
        for (out, waiting) in outs.iter().zip(waiting.chunks_exact(solver::LANES)) {
            let first = waiting[0];
            if out.done == [true; solver::LANES]
                && waiting[solver::LANES - 1] == first + solver::LANES - 1
            {
                self.finish_block(run, out, first);
                continue;
            }
            for (lane, &j) in waiting.iter().enumerate() {
                match out.lane(lane) {
                    Some(out) => self.finish(run.outputs(j), out),
                    None => self.step_one(run, j),
                }
            }
        }
    }

    /// Puts the [`solver::LANES`] beads from `first` on into `lanes`, column
    /// by column, if each is on a plain circle or sphere; else leaves
    /// `lanes` as it was and returns false.
    #[inline(always)]
    fn fill_block(&self, run: &BeadRun<V>, first: usize, lanes: &mut RoundLanes<V>) -> bool {
        const N: usize = solver::LANES;
        let Some(on_wires) = run.on_wires.get(first..first + N) else {
            return false;
        };
        let mut circles = [(V::ZERO, 0.0); N];
        for (circle, on) in circles.iter_mut().zip(on_wires) {
            match self.wires.circle(on) {
                Some(found) => *circle = found,
                None => return false,
            }
        }
        let gravity = self.gravity;
        let positions = &run.positions[first..first + N];
        let velocities = &run.velocities[first..first + N];
        let masses = &run.masses[first..first + N];
        let forces = &run.forces[first..first + N];
        for (j, (centre, radius)) in circles.into_iter().enumerate() {
            let (p, m) = (positions[j].0, masses[j].get());
            let state = BeadState {
                position: p,
                velocity: velocities[j].0,
            };
            lanes.set(
                j,
                state,
                &forces[j].linear(m, gravity, p),
                m,
                centre,
                radius,
            );
        }
        true
    }

    /// Stores a finished batch whose beads lie side by side from `first`
    /// on, column by column.
    #[inline(always)]
    fn finish_block(&self, run: &mut BeadRun<V>, out: &RoundSteps<V>, first: usize) {
        const N: usize = solver::LANES;
        let range = first..first + N;
        for (j, p) in run.positions[range.clone()].iter_mut().enumerate() {
            p.0 = V::get(&out.x, j);
        }
        for (j, v) in run.velocities[range.clone()].iter_mut().enumerate() {
            v.0 = V::get(&out.v, j);
        }
        for force in &mut run.forces[range.clone()] {
            force.clear();
        }
        if let Some(diagnostics) = run.diagnostics.as_deref_mut() {
            let masses = &run.masses[range.clone()];
            for (j, d) in diagnostics[range.clone()].iter_mut().enumerate() {
                let out = out.lane_unchecked(j);
                *d = self.diagnose(&out, masses[j].get());
            }
        }
        if let Some(transforms) = run.transforms.as_deref_mut() {
            for (j, t) in transforms[range].iter_mut().enumerate() {
                V::place(t, V::get(&out.x, j));
            }
        }
    }

    /// Bead `i` of `run` through [`solver::step_on`]; a failure is
    /// recorded.
    fn step_one(&self, run: &mut BeadRun<V>, i: usize) {
        let bead = run.bead(i);
        let contact = run.contacts.as_deref_mut().map(|c| &mut c[i]);
        let plain = PlainStep {
            ctx: self,
            bead: &bead,
        };
        let result = match self.wires.get(&run.on_wires[i]) {
            Err(reason) => Err(reason),
            Ok(wire) if !wire.surface().is_plain() || V::traced(&wire.shape) => {
                self.step_on_surface(wire, &bead, run.entities[i], contact)
            }
            Ok(TableWire {
                shape,
                pose,
                track: None,
            }) => V::fixed(shape, *pose, plain),
            Ok(wire) => V::moving(&wire.shape, &wire.path(), plain),
        };
        match result {
            Ok(out) => self.finish(run.outputs(i), out),
            Err(reason) => {
                // The bead keeps its state; its `Transform` shows it.
                if let Some(transform) = run.outputs(i).transform {
                    V::place(transform, bead.state.position);
                }
                self.found.push(run.entities[i], reason, self.time);
            }
        }
    }

    /// Eq. (3) and the integrator for one bead, the step starting at
    /// `time − dt`.
    fn step_bead<T: Track<V> + ?Sized>(
        &self,
        track: &T,
        bead: &BeadInputs<V>,
    ) -> Result<StepOutput<V>, DivergenceReason> {
        let (state, force, start) = self.start(bead)?;
        solver::step_on(track, start, state, &force, bead.mass, &self.settings)
            .map_err(DivergenceReason::Solve)
    }

    /// [`solver::step_surface`] for one bead on `track`.
    fn surface_step<T: Track<V> + ?Sized>(
        &self,
        track: &T,
        bead: &BeadInputs<V>,
        surface: &Surface,
        contact: Contact,
    ) -> Result<solver::SurfaceStep<V>, DivergenceReason> {
        let (state, force, start) = self.start(bead)?;
        let (mass, settings) = (bead.mass, &self.settings);
        solver::step_surface(
            track, start, state, &force, mass, settings, surface, contact,
        )
        .map_err(DivergenceReason::Solve)
    }

    /// A bead's state (checked finite), the force on it and the time the
    /// step starts.
    #[allow(clippy::type_complexity)]
    fn start(
        &self,
        bead: &BeadInputs<V>,
    ) -> Result<(BeadState<V>, LinearForce<V>, f64), DivergenceReason> {
        if !bead.state.is_finite() {
            return Err(DivergenceReason::NonFiniteState);
        }
        let force = bead.force(self.gravity);
        Ok((bead.state, force, self.time - self.settings.dt))
    }

    /// One bead on a wire with a surface (one-sided, rough or damped):
    /// [`solver::step_surface`] from its contact, which it updates; a
    /// change of contact is recorded.
    fn step_on_surface(
        &self,
        wire: &TableWire<V>,
        bead: &BeadInputs<V>,
        entity: Entity,
        contact: Option<&mut WireContact>,
    ) -> Result<StepOutput<V>, DivergenceReason> {
        let from = contact.as_deref().map_or(Contact::OnWire, WireContact::get);
        let hint = contact.as_deref().map_or(f64::NAN, WireContact::along);
        let (shape, path, surface) = (&wire.shape, &wire.path(), wire.surface());
        let on = SurfaceStep {
            ctx: self,
            bead,
            surface,
            contact: from,
        };
        let stepped = V::near(shape, path, hint, on)?;
        if let Some(contact) = contact {
            contact.contact = stepped.contact;
            let (pose, _) = path.at(self.time);
            let local = pose.to_local(stepped.output.state.position);
            contact.along = V::parameter(shape, local, hint) as f32;
        }
        if let Some(event) = stepped.event {
            self.events.push(entity, event);
        }
        Ok(stepped.output)
    }

    /// Stores a step's result: the new state (which consumes the force),
    /// the diagnostics, the `Transform`'s translation.
    #[inline(always)]
    fn finish(&self, outputs: BeadOutputs<V>, out: StepOutput<V>) {
        let BeadOutputs {
            position,
            velocity,
            force,
            mass,
            diagnostics,
            transform,
        } = outputs;
        (position.0, velocity.0) = (out.state.position, out.state.velocity);
        force.clear();
        if let Some(diagnostics) = diagnostics {
            *diagnostics = self.diagnose(&out, mass);
        }
        if let Some(transform) = transform {
            V::place(transform, out.state.position);
        }
    }
}

/// A bead's step on a plain wire, run on its concrete track.
struct PlainStep<'c, 'b, V: LoneStep> {
    ctx: &'c StepContext<'c, V>,
    bead: &'b BeadInputs<V>,
}

impl<V: LoneStep> OnTrack<V, Result<StepOutput<V>, DivergenceReason>> for PlainStep<'_, '_, V> {
    #[inline(always)]
    fn run<T: Track<V> + ?Sized>(self, track: &T) -> Result<StepOutput<V>, DivergenceReason> {
        self.ctx.step_bead(track, self.bead)
    }
}

/// A bead's step on a wire with a surface, from its contact.
struct SurfaceStep<'c, 'b, V: LoneStep> {
    ctx: &'c StepContext<'c, V>,
    bead: &'b BeadInputs<V>,
    surface: &'b Surface,
    contact: Contact,
}

impl<V: LoneStep> OnTrack<V, Result<solver::SurfaceStep<V>, DivergenceReason>>
    for SurfaceStep<'_, '_, V>
{
    fn run<T: Track<V> + ?Sized>(
        self,
        track: &T,
    ) -> Result<solver::SurfaceStep<V>, DivergenceReason> {
        self.ctx
            .surface_step(track, self.bead, self.surface, self.contact)
    }
}

impl<V: LoneStep> StepContext<'_, V> {
    /// The diagnostics of a bead of mass `mass` after step `out`.
    #[inline(always)]
    fn diagnose(&self, out: &StepOutput<V>, mass: f64) -> BeadDiagnostics<V> {
        let row = RowReport {
            c: out.c,
            c_dot: out.c_dot,
            lambda: out.lambda,
        };
        BeadDiagnostics::of(out.state, mass, self.gravity, row, out.constraint_force)
    }
}

/// A run of beads stored side by side: their entities, the columns of
/// their state, mass, force and wire, and, when they have them, their
/// diagnostics, transforms and contacts.
pub(super) struct BeadRun<'w, V: LoneStep> {
    entities: &'w [Entity],
    positions: &'w mut [BeadPosition<V>],
    velocities: &'w mut [BeadVelocity<V>],
    masses: &'w [BeadMass],
    forces: &'w mut [BeadForce<V>],
    on_wires: &'w [OnWire],
    diagnostics: Option<&'w mut [BeadDiagnostics<V>]>,
    transforms: Option<&'w mut [Transform]>,
    contacts: Option<&'w mut [WireContact]>,
}

/// What one bead's step reads.
struct BeadInputs<V: LoneStep> {
    state: BeadState<V>,
    mass: f64,
    force: BeadForce<V>,
}

impl<V: LoneStep> BeadInputs<V> {
    /// The force of the step, eq. (5).
    #[inline(always)]
    fn force(&self, gravity: V) -> LinearForce<V> {
        self.force.linear(self.mass, gravity, self.state.position)
    }
}

/// What one bead's step writes.
struct BeadOutputs<'a, V: LoneStep> {
    position: &'a mut BeadPosition<V>,
    velocity: &'a mut BeadVelocity<V>,
    force: &'a mut BeadForce<V>,
    mass: f64,
    diagnostics: Option<&'a mut BeadDiagnostics<V>>,
    transform: Option<&'a mut Transform>,
}

impl<V: LoneStep> BeadRun<'_, V> {
    #[inline(always)]
    fn bead(&self, i: usize) -> BeadInputs<V> {
        BeadInputs {
            state: BeadState {
                position: self.positions[i].0,
                velocity: self.velocities[i].0,
            },
            mass: self.masses[i].get(),
            force: self.forces[i],
        }
    }

    #[inline(always)]
    fn outputs(&mut self, i: usize) -> BeadOutputs<'_, V> {
        BeadOutputs {
            position: &mut self.positions[i],
            velocity: &mut self.velocities[i],
            force: &mut self.forces[i],
            mass: self.masses[i].get(),
            diagnostics: self.diagnostics.as_deref_mut().map(|d| &mut d[i]),
            transform: self.transforms.as_deref_mut().map(|t| &mut t[i]),
        }
    }
}

/// The columns of one table of beads, as the step's query hands them out.
pub(super) type BeadTable<'w, V> = (
    &'w [Entity],
    ContiguousMut<'w, BeadPosition<V>>,
    ContiguousMut<'w, BeadVelocity<V>>,
    &'w [BeadMass],
    ContiguousMut<'w, BeadForce<V>>,
    &'w [OnWire],
    Option<ContiguousMut<'w, BeadDiagnostics<V>>>,
    Option<ContiguousMut<'w, Transform>>,
    Option<ContiguousMut<'w, WireContact>>,
);

/// An optional column cut into runs of `n`; `None` for every run if absent
/// (marked changed if present).
fn column_runs<'w, T>(
    column: Option<ContiguousMut<'w, T>>,
    n: usize,
) -> impl Iterator<Item = Option<&'w mut [T]>> {
    column
        .into_iter()
        .flat_map(move |c| ContiguousMut::split(c).0.chunks_mut(n).map(Some))
        .chain(std::iter::repeat_with(|| None))
}

/// The contact column cut into runs of `n`, not marked changed: a step
/// marks the few beads whose contact changed itself.
fn contact_runs<'w>(
    column: Option<ContiguousMut<'w, WireContact>>,
    n: usize,
) -> impl Iterator<Item = Option<&'w mut [WireContact]>> {
    column
        .into_iter()
        .flat_map(move |c| {
            ContiguousMut::bypass_change_detection_split(c)
                .0
                .chunks_mut(n)
                .map(Some)
        })
        .chain(std::iter::repeat_with(|| None))
}

/// Cuts one table's beads into runs: one for a single thread, else about a
/// quarter of each thread's share, so a slow thread does not hold the
/// others up. Marks the positions, velocities, diagnostics and transforms
/// changed; not the forces, which the step only empties.
pub(super) fn split_table<'w, V: LoneStep>(
    (entities, positions, velocities, masses, forces, on_wires, diagnostics, transforms, contacts): BeadTable<'w, V>,
    threads: usize,
) -> Vec<BeadRun<'w, V>> {
    let runs = if threads > 1 { 4 * threads } else { 1 };
    let n = entities.len().div_ceil(runs).max(1);
    let mut positions = ContiguousMut::split(positions).0.chunks_mut(n);
    let mut velocities = ContiguousMut::split(velocities).0.chunks_mut(n);
    let mut masses = masses.chunks(n);
    let mut forces = ContiguousMut::bypass_change_detection_split(forces)
        .0
        .chunks_mut(n);
    entities
        .chunks(n)
        .zip(on_wires.chunks(n))
        .zip(column_runs(diagnostics, n))
        .zip(column_runs(transforms, n))
        .zip(contact_runs(contacts, n))
        .filter_map(
            |((((entities, on_wires), diagnostics), transforms), contacts)| {
                Some(BeadRun {
                    entities,
                    positions: positions.next()?,
                    velocities: velocities.next()?,
                    masses: masses.next()?,
                    forces: forces.next()?,
                    on_wires,
                    diagnostics,
                    transforms,
                    contacts,
                })
            },
        )
        .collect()
}
