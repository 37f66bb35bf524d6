//! [`WireBeadSystems::Prepare`](crate::WireBeadSystems::Prepare) and
//! [`WireBeadSystems::Step`](crate::WireBeadSystems::Step): the systems that
//! move beads. They only move data between the ECS and
//! [`solver`](crate::solver).

use std::sync::{Mutex, PoisonError};

use bevy::ecs::change_detection::ContiguousMut;
use bevy::ecs::entity::EntityHashSet;
use bevy::ecs::system::{SystemChangeTick, SystemParam};
use bevy::math::DVec2;
use bevy::prelude::*;

use super::islands::InIsland;
use super::parallel::ParallelStep;
use super::restart::SimClock;
use super::writeback::{LastStep, place};
use crate::dynamics::{
    Bead, BeadDiagnostics, BeadDiverged, ContactChanged, Diverged, DivergenceReason, OnWire,
    PrescribedMotion, SimParams, Wire, WireContact, WirePose, pose_of,
};
use crate::geometry::{
    FixedTrack, MovingTrack, Near, Placed, Pose, PoseHistory, PosePath, Surface, Track, WireShape,
};
use crate::solver::{
    self, BeadState, Contact, ContactEvent, LinearForce, StepOutput, StepSettings,
};

/// Prepares the step: places every wire (reads each changed wire
/// `Transform` once, so the beads do not; writes the `Transform` of a wire
/// on a prescribed motion; takes in the pose of a wire the game moves) and
/// advances the [`SimClock`].
pub(crate) fn prepare_step(
    params: Res<SimParams>,
    mut clock: ResMut<SimClock>,
    mut driven: Query<(&PrescribedMotion, &mut Transform, &mut WirePose)>,
    mut followed: Query<(Ref<Transform>, &mut WirePose), (With<Wire>, Without<PrescribedMotion>)>,
    moved: Query<Entity, (With<Wire>, Without<PrescribedMotion>, Changed<Transform>)>,
    mut moving: Local<EntityHashSet>,
) {
    let (start, h) = (clock.time, params.timestep);
    let end = start + h;
    for (motion, mut transform, mut pose) in &mut driven {
        let placed = prescribed(motion, &pose, &transform);
        pose.set_if_neq(placed);
        if let Ok(path) = placed.get() {
            set_pose(&mut transform, path.pose(end));
        }
    }
    // Only the wires whose `Transform` changed, and the ones that were
    // still moving: the rest stay where they are, unvisited.
    let mut still_moving = EntityHashSet::default();
    let before = moving.iter().copied().filter(|&e| !moved.contains(e));
    for entity in moved.iter().chain(before) {
        let Ok((transform, mut pose)) = followed.get_mut(entity) else {
            continue;
        };
        let Ok(now) = pose_of(&transform) else {
            pose.set_if_neq(WirePose::from_transform(&transform));
            continue;
        };
        let mut history = match pose.get() {
            Ok(PosePath::Fixed(at)) if at == now => continue,
            Ok(PosePath::Fixed(at)) => PoseHistory::at_rest(f64::NEG_INFINITY, at),
            Ok(PosePath::Followed(history)) => history,
            Ok(path @ PosePath::Prescribed { .. }) => PoseHistory::at_rest(start, path.pose(start)),
            Err(_) => PoseHistory::at_rest(start, now),
        };
        history.push(end, h, now);
        let path = if history.is_at_rest() {
            PosePath::Fixed(now)
        } else {
            still_moving.insert(entity);
            PosePath::Followed(history)
        };
        pose.set_if_neq(WirePose::on(path));
    }
    *moving = still_moving;
    clock.steps += 1;
    clock.time = end;
}

/// Places a wire where its `Transform` puts it the moment it is added, so
/// that a game moving it from its first step on moves it from there.
pub(crate) fn wire_added(add: On<Add, Wire>, mut wires: Query<(&Transform, &mut WirePose)>) {
    if let Ok((transform, mut pose)) = wires.get_mut(add.entity) {
        *pose = WirePose::from_transform(transform);
    }
}

/// A wire on `motion` about its resting pose: the one `pose` already
/// holds, else its `Transform`'s (when the motion first applies).
pub(crate) fn prescribed(
    motion: &PrescribedMotion,
    pose: &WirePose,
    transform: &Transform,
) -> WirePose {
    let base = match pose.get() {
        Ok(PosePath::Prescribed { base, .. }) => Ok(base),
        _ => pose_of(transform),
    };
    match base {
        Ok(base) => WirePose::on(PosePath::Prescribed {
            base,
            motion: motion.motion(),
        }),
        Err(_) => WirePose::from_transform(transform),
    }
}

/// Writes an in-plane pose into a `Transform` (x, y and the rotation about
/// z; z kept), converted to `f32` at this edge.
pub(crate) fn set_pose(transform: &mut Transform, pose: Pose) {
    let origin = pose.origin.as_vec2();
    if origin.is_finite() && pose.rotation.is_finite() {
        transform.translation.x = origin.x;
        transform.translation.y = origin.y;
        transform.rotation = Quat::from_rotation_z(pose.rotation.to_angle() as f32);
    }
}

/// Divergences found inside a (possibly parallel) loop, reported after it.
#[derive(Default)]
pub(crate) struct FoundDivergences(Mutex<Vec<(Entity, DivergenceReason, f64)>>);

impl FoundDivergences {
    fn push(&self, bead: Entity, reason: DivergenceReason, time: f64) {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push((bead, reason, time));
    }

    fn report(&mut self, divergences: &mut Divergences) {
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

/// Runs `$body` with `$curve` bound to the shape's concrete curve, so the
/// solver is inlined for each built-in shape.
macro_rules! with_curve {
    ($shape:expr, $curve:ident => $body:expr) => {
        match $shape {
            WireShape::Circle($curve) => $body,
            WireShape::Ellipse($curve) => $body,
            WireShape::Line($curve) => $body,
            WireShape::Parabola($curve) => $body,
            WireShape::Sine($curve) => $body,
            WireShape::Cycloid($curve) => $body,
            WireShape::Spline($curve) => $body,
            WireShape::Custom(custom) => {
                let $curve = custom.as_ref();
                $body
            }
        }
    };
}

/// A wire as the step needs it: its shape and, for most wires, where it
/// stays; a moving wire's path and a one-sided, rough or damped wire's
/// surface behind one pointer, so the table stays small for the rest.
pub(crate) struct TableWire {
    shape: WireShape,
    /// Where a plain wire that stays put is (when `track` is none).
    pose: Pose,
    /// The path and surface of the others.
    track: Option<Box<(PosePath, Surface)>>,
}

impl TableWire {
    fn new(shape: WireShape, path: PosePath, surface: Surface) -> Self {
        match path.fixed() {
            Some(pose) if surface.is_plain() => Self {
                shape,
                pose,
                track: None,
            },
            _ => Self {
                shape,
                pose: Pose::IDENTITY,
                track: Some(Box::new((path, surface))),
            },
        }
    }

    /// The path (a fixed one for a wire that stays put).
    fn path(&self) -> PosePath {
        match &self.track {
            Some(track) => track.0,
            None => PosePath::Fixed(self.pose),
        }
    }

    /// The surface.
    fn surface(&self) -> &Surface {
        self.track.as_deref().map_or(&Surface::PLAIN, |t| &t.1)
    }
}

/// A wire for the step, or why beads cannot be stepped on it.
type PlacedWire = Result<TableWire, DivergenceReason>;

/// Every wire's shape and pose, kept by [`step_beads`] from change
/// detection (a copy made when a wire changes, not each step), so a bead
/// finds its wire with one indexed read instead of a query lookup. The
/// plain circles that stay put unrotated (the batched step's wires) are
/// also kept as a small record each, which is all the step reads for a
/// bead on one.
#[derive(Default)]
pub(crate) struct WireTable {
    /// Each wire's place in `wires` plus one, by entity index (0: none).
    slot: Vec<u32>,
    /// The wires, each with its entity.
    wires: Vec<(Entity, PlacedWire)>,
    /// For each wire, its entity and, where it is a plain circle that
    /// stays put unrotated, its centre and radius (else a NaN radius).
    circles: Vec<(Entity, DVec2, f64)>,
}

impl WireTable {
    /// Takes in the wires that changed or were added since the last call,
    /// and drops the ones whose `Wire` or `WirePose` was removed.
    fn refresh<'a>(
        &mut self,
        removed: impl IntoIterator<Item = Entity>,
        changed: impl IntoIterator<Item = (Entity, &'a Wire, &'a WirePose)>,
    ) {
        for entity in removed {
            if let Some(k) = self.place(entity) {
                let _ = self.wires.swap_remove(k);
                self.circles.swap_remove(k);
                self.slot[entity.index_u32() as usize] = 0;
                if let Some(&(moved, _)) = self.wires.get(k) {
                    self.slot[moved.index_u32() as usize] = k as u32 + 1;
                }
            }
        }
        for (entity, wire, pose) in changed {
            let placed = pose
                .get()
                .map(|path| TableWire::new(wire.shape().clone(), path, *wire.surface()))
                .map_err(|e| DivergenceReason::InvalidWire(e.to_string()));
            let circle = match &placed {
                Ok(TableWire {
                    shape: WireShape::Circle(circle),
                    pose,
                    track: None,
                }) if pose.is_unrotated() => (entity, pose.origin, circle.radius),
                _ => (entity, DVec2::ZERO, f64::NAN),
            };
            let index = entity.index_u32() as usize;
            if index >= self.slot.len() {
                self.slot.resize(index + 1, 0);
            }
            match self.slot[index].checked_sub(1) {
                Some(k) => {
                    // This wire, or a despawned one whose index it reuses.
                    self.wires[k as usize] = (entity, placed);
                    self.circles[k as usize] = circle;
                }
                None => {
                    self.wires.push((entity, placed));
                    self.circles.push(circle);
                    self.slot[index] = self.wires.len() as u32;
                }
            }
        }
    }

    /// Where wire `entity` is in the table.
    #[inline(always)]
    fn place(&self, entity: Entity) -> Option<usize> {
        let k = self.slot.get(entity.index_u32() as usize)?.checked_sub(1)? as usize;
        (self.wires[k].0 == entity).then_some(k)
    }

    /// The wire a bead is on.
    fn get(&self, on: &OnWire) -> Result<&TableWire, DivergenceReason> {
        match self.place(on.0) {
            Some(k) => self.wires[k].1.as_ref().map_err(Clone::clone),
            None => Err(DivergenceReason::InvalidWire(format!(
                "entity {} has no Wire",
                on.0
            ))),
        }
    }

    /// The centre and radius of the wire a bead is on, where it is a plain
    /// circle that stays put unrotated.
    #[inline(always)]
    fn circle(&self, on: &OnWire) -> Option<(DVec2, f64)> {
        let k = self.slot.get(on.0.index_u32() as usize)?.checked_sub(1)? as usize;
        let &(entity, centre, radius) = self.circles.get(k)?;
        (entity == on.0 && !radius.is_nan()).then_some((centre, radius))
    }
}

/// How many batches of [`solver::LANES`] beads one call of the batched step
/// takes.
const BATCHES: usize = 8;

/// What stepping a run of beads needs, shared by the threads.
struct StepContext<'a> {
    params: &'a SimParams,
    settings: StepSettings,
    wires: &'a WireTable,
    found: &'a FoundDivergences,
    events: &'a FoundEvents,
    time: f64,
}

impl StepContext<'_> {
    /// Steps a run of beads stored side by side. Beads on unrotated circles
    /// go through the batched step, [`solver::LANES`] at a time, up to
    /// [`BATCHES`] batches per call; the others, and the lanes it hands
    /// back, one by one.
    fn step_run(&self, mut run: BeadRun) {
        let mut lanes = [solver::CircleLanes::default(); BATCHES];
        let mut outs = [solver::CircleSteps::default(); BATCHES];
        let mut waiting = [0; BATCHES * solver::LANES];
        let mut queued = 0;
        for i in 0..run.beads.len() {
            if let Some((centre, radius)) = self.wires.circle(&run.on_wires[i]) {
                let bead = &run.beads[i];
                lanes[queued / solver::LANES].set(
                    queued % solver::LANES,
                    bead.state(),
                    &bead.step_force(self.params.gravity),
                    bead.mass(),
                    centre,
                    radius,
                );
                waiting[queued] = i;
                queued += 1;
                if queued == waiting.len() {
                    solver::step_on_circle_batches(&lanes, &self.settings, &mut outs);
                    self.finish_batches(&mut run, &outs, &waiting);
                    queued = 0;
                }
                continue;
            }
            self.step_one(&mut run, i);
        }
        // The last, partial batches: full ones batched, the rest one by one.
        let whole = queued / solver::LANES;
        solver::step_on_circle_batches(&lanes[..whole], &self.settings, &mut outs[..whole]);
        let batched = whole * solver::LANES;
        self.finish_batches(&mut run, &outs[..whole], &waiting[..batched]);
        for &j in &waiting[batched..queued] {
            self.step_one(&mut run, j);
        }
    }

    /// Stores the batched steps of the beads `waiting` (in order, one lane
    /// each); a lane the batch did not finish goes through
    /// [`StepContext::step_one`].
    fn finish_batches(&self, run: &mut BeadRun, outs: &[solver::CircleSteps], waiting: &[usize]) {
        for (k, &j) in waiting.iter().enumerate() {
            match outs[k / solver::LANES].lane(k % solver::LANES) {
                Some(out) => self.finish(run.outputs(j), out),
                None => self.step_one(run, j),
            }
        }
    }

    /// Bead `i` of `run` through [`solver::step`]; a failure is recorded.
    fn step_one(&self, run: &mut BeadRun, i: usize) {
        let contact = run.contacts.as_deref_mut().map(|c| &mut c[i]);
        let bead = &run.beads[i];
        let result = match self.wires.get(&run.on_wires[i]) {
            Err(reason) => Err(reason),
            Ok(wire) if !wire.surface().is_plain() || wire.shape.is_traced() => {
                self.step_on_surface(wire, bead, run.entities[i], contact)
            }
            Ok(TableWire {
                shape,
                pose,
                track: None,
            }) => with_curve!(shape, curve => {
                self.step_bead(&FixedTrack(&Placed { curve, pose: *pose }), bead)
            }),
            Ok(wire) => {
                let path = &wire.path();
                with_curve!(&wire.shape, curve => {
                    self.step_bead(&MovingTrack { curve, path }, bead)
                })
            }
        };
        match result {
            Ok(out) => self.finish(run.outputs(i), out),
            Err(reason) => {
                // The bead keeps its state; its `Transform` shows it.
                let outputs = run.outputs(i);
                if let Some(transform) = outputs.transform {
                    place(transform, outputs.bead.position);
                }
                self.found.push(run.entities[i], reason, self.time);
            }
        }
    }

    /// Eq. (3) and the integrator for one bead, the step starting at
    /// `time − dt`.
    fn step_bead<T: Track + ?Sized>(
        &self,
        track: &T,
        bead: &Bead,
    ) -> Result<StepOutput, DivergenceReason> {
        let (state, force, start) = self.start(bead)?;
        solver::step_on(track, start, state, &force, bead.mass(), &self.settings)
            .map_err(DivergenceReason::Solve)
    }

    /// [`solver::step_surface`] for one bead on `track`.
    fn surface_step<T: Track + ?Sized>(
        &self,
        track: &T,
        bead: &Bead,
        surface: &Surface,
        contact: Contact,
    ) -> Result<solver::SurfaceStep, DivergenceReason> {
        let (state, force, start) = self.start(bead)?;
        let (mass, settings) = (bead.mass(), &self.settings);
        solver::step_surface(
            track, start, state, &force, mass, settings, surface, contact,
        )
        .map_err(DivergenceReason::Solve)
    }

    /// A bead's state (checked finite), the force on it and the time the
    /// step starts.
    fn start(&self, bead: &Bead) -> Result<(BeadState, LinearForce, f64), DivergenceReason> {
        let state = bead.state();
        if !state.is_finite() {
            return Err(DivergenceReason::NonFiniteState);
        }
        let force = bead.step_force(self.params.gravity);
        Ok((state, force, self.time - self.settings.dt))
    }

    /// One bead on a wire with a surface (one-sided, rough or damped):
    /// [`solver::step_surface`] from its contact, which it updates; a
    /// change of contact is recorded.
    fn step_on_surface(
        &self,
        wire: &TableWire,
        bead: &Bead,
        entity: Entity,
        contact: Option<&mut WireContact>,
    ) -> Result<StepOutput, DivergenceReason> {
        let from = contact.as_deref().map_or(Contact::OnWire, WireContact::get);
        let hint = contact.as_deref().map_or(f64::NAN, WireContact::along);
        let (shape, path, surface) = (&wire.shape, &wire.path(), wire.surface());
        let curve = &Near {
            curve: shape.curve(),
            hint,
        };
        let stepped = match path.fixed() {
            Some(pose) => {
                self.surface_step(&FixedTrack(&Placed { curve, pose }), bead, surface, from)
            }
            None => self.surface_step(&MovingTrack { curve, path }, bead, surface, from),
        }?;
        if let Some(contact) = contact {
            contact.contact = stepped.contact;
            let local = path.pose(self.time).to_local(stepped.output.state.position);
            contact.along = shape.curve().parameter(local, hint) as f32;
        }
        if let Some(event) = stepped.event {
            self.events.push(entity, event);
        }
        Ok(stepped.output)
    }

    /// Stores a step's result: the new state (which consumes the force),
    /// the diagnostics, the `Transform`'s translation.
    #[inline(always)]
    fn finish(&self, outputs: BeadOutputs, out: StepOutput) {
        let BeadOutputs {
            bead,
            diagnostics,
            transform,
        } = outputs;
        bead.advance_to(out.state);
        if let Some(diagnostics) = diagnostics {
            let (kinetic, potential) = out.state.energy(bead.mass(), self.params.gravity);
            *diagnostics = BeadDiagnostics {
                c: out.c,
                c_dot: out.c_dot,
                lambda: out.lambda,
                constraint_force: out.constraint_force,
                kinetic,
                potential,
            };
        }
        if let Some(transform) = transform {
            place(transform, out.state.position);
        }
    }
}

/// A run of beads stored side by side: their entities, states and wires,
/// and, when they have them, their diagnostics and transforms.
struct BeadRun<'w> {
    entities: &'w [Entity],
    beads: &'w mut [Bead],
    on_wires: &'w [OnWire],
    diagnostics: Option<&'w mut [BeadDiagnostics]>,
    transforms: Option<&'w mut [Transform]>,
    contacts: Option<&'w mut [WireContact]>,
}

/// What one bead's step writes.
struct BeadOutputs<'a> {
    bead: &'a mut Bead,
    diagnostics: Option<&'a mut BeadDiagnostics>,
    transform: Option<&'a mut Transform>,
}

impl BeadRun<'_> {
    #[inline(always)]
    fn outputs(&mut self, i: usize) -> BeadOutputs<'_> {
        BeadOutputs {
            bead: &mut self.beads[i],
            diagnostics: self.diagnostics.as_deref_mut().map(|d| &mut d[i]),
            transform: self.transforms.as_deref_mut().map(|t| &mut t[i]),
        }
    }
}

/// The columns of one table of beads, as the step's query hands them out.
type BeadTable<'w> = (
    &'w [Entity],
    ContiguousMut<'w, Bead>,
    &'w [OnWire],
    Option<ContiguousMut<'w, BeadDiagnostics>>,
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
/// others up. Marks the beads, diagnostics and transforms changed.
fn split_table<'w>(
    (entities, beads, on_wires, diagnostics, transforms, contacts): BeadTable<'w>,
    threads: usize,
) -> Vec<BeadRun<'w>> {
    let runs = if threads > 1 { 4 * threads } else { 1 };
    let n = entities.len().div_ceil(runs).max(1);
    let beads = ContiguousMut::split(beads).0;
    entities
        .chunks(n)
        .zip(beads.chunks_mut(n))
        .zip(on_wires.chunks(n))
        .zip(column_runs(diagnostics, n))
        .zip(column_runs(transforms, n))
        .zip(contact_runs(contacts, n))
        .map(
            |(((((entities, beads), on_wires), diagnostics), transforms), contacts)| BeadRun {
                entities,
                beads,
                on_wires,
                diagnostics,
                transforms,
                contacts,
            },
        )
        .collect()
}

/// Steps every bead that has not diverged: solve, integrate, check, update
/// diagnostics (see [`WireBeadSystems::Step`](crate::WireBeadSystems::Step)).
/// Walks the beads table by table as slices, split over the compute task
/// pool from [`ParallelStep::threshold`] beads up.
pub(crate) fn step_beads(
    params: Res<SimParams>,
    clock: Res<SimClock>,
    parallel: Res<ParallelStep>,
    mut wires: Local<WireTable>,
    changed: Query<(Entity, &Wire, &WirePose), Or<(Changed<Wire>, Changed<WirePose>)>>,
    mut removed_wires: RemovedComponents<Wire>,
    mut removed_poses: RemovedComponents<WirePose>,
    mut beads: Query<
        (
            Entity,
            &mut Bead,
            &OnWire,
            Option<&mut BeadDiagnostics>,
            Option<&mut Transform>,
            Option<&mut WireContact>,
        ),
        (Without<Diverged>, Without<InIsland>),
    >,
    mut found: Local<FoundDivergences>,
    mut events: Local<FoundEvents>,
    mut changes: MessageWriter<ContactChanged>,
    mut stepped: ResMut<LastStep>,
    ticks: SystemChangeTick,
    mut divergences: Divergences,
) {
    let removed = removed_wires.read().chain(removed_poses.read());
    wires.refresh(removed, changed);
    let ctx = StepContext {
        params: &params,
        settings: params.step_settings(),
        wires: &wires,
        found: &found,
        events: &events,
        time: clock.time,
    };
    let count = beads.iter().size_hint().1.unwrap_or(usize::MAX);
    let pool = parallel.pool(count);
    let threads = pool.map_or(1, |(_, threads)| threads);
    let Ok(tables) = beads.contiguous_iter_mut() else {
        error!("wirebead: the bead query is not table-dense; no bead was stepped");
        return;
    };
    let split = |table| split_table(table, threads);
    match pool {
        Some((pool, _)) => {
            pool.scope(|scope| {
                for run in tables.flat_map(split) {
                    let ctx = &ctx;
                    scope.spawn(async move { ctx.step_run(run) });
                }
            });
        }
        None => {
            for run in tables.flat_map(split) {
                ctx.step_run(run);
            }
        }
    };
    found.report(&mut divergences);
    for (bead, event) in events.take() {
        if let Ok((.., Some(mut contact))) = beads.get_mut(bead) {
            contact.set_changed();
        }
        info!("wirebead: bead {bead} {}", describe_event(&event));
        changes.write(ContactChanged { bead, event });
    }
    stepped.0 = ticks.this_run();
}

/// A change of contact in words, for the log.
pub(crate) fn describe_event(event: &ContactEvent) -> String {
    match *event {
        ContactEvent::Left { time, position } => format!(
            "left its wire at t = {time:.4} s at ({:.3}, {:.3}), where the wire would have had to pull",
            position.x, position.y
        ),
        ContactEvent::Landed {
            time,
            position,
            normal_speed,
            bounced,
        } => format!(
            "landed on its wire at t = {time:.4} s at ({:.3}, {:.3}) at {normal_speed:.3} m/s across it and {}",
            position.x,
            position.y,
            if bounced { "bounced off" } else { "stayed on" }
        ),
    }
}

/// Changes of contact found inside a (possibly parallel) loop, sent after
/// it.
#[derive(Default)]
pub(crate) struct FoundEvents(Mutex<Vec<(Entity, ContactEvent)>>);

impl FoundEvents {
    fn push(&self, bead: Entity, event: ContactEvent) {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push((bead, event));
    }

    fn take(&mut self) -> Vec<(Entity, ContactEvent)> {
        std::mem::take(self.0.get_mut().unwrap_or_else(PoisonError::into_inner))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plain circle at `x` on the x axis.
    fn placed(x: f32) -> (Wire, WirePose) {
        let pose = WirePose::from_transform(&Transform::from_xyz(x, 0.0, 0.0));
        (Wire::circle(1.0 + f64::from(x)).unwrap(), pose)
    }

    #[test]
    fn the_wire_table_finds_each_wire_after_a_removal_and_not_the_removed_one() {
        let mut world = World::new();
        let wires: Vec<Entity> = (0..4).map(|_| world.spawn_empty().id()).collect();
        let data: Vec<_> = (0..4).map(|i| placed(i as f32)).collect();
        let mut table = WireTable::default();
        table.refresh([], wires.iter().zip(&data).map(|(&e, (w, p))| (e, w, p)));
        // Wire 1 goes: the last one takes its place in the table.
        table.refresh([wires[1]], []);
        // A later entity with wire 1's index.
        let reused = Entity::from_index_and_generation(
            wires[1].index(),
            wires[1].generation().after_versions(1),
        );
        for (i, &wire) in wires.iter().enumerate() {
            let found = table.circle(&OnWire(wire));
            if i == 1 {
                assert_eq!(found, None);
                assert!(table.get(&OnWire(wire)).is_err());
            } else {
                let (centre, radius) = found.expect("a wire in the table");
                assert_eq!(
                    (centre, radius),
                    (DVec2::new(i as f64, 0.0), 1.0 + i as f64)
                );
                assert!(table.get(&OnWire(wire)).is_ok());
            }
        }
        // The entity that reuses the index is not the removed wire.
        assert!(table.circle(&OnWire(reused)).is_none());
        let (w, p) = placed(7.0);
        table.refresh([], [(reused, &w, &p)]);
        assert_eq!(
            table.circle(&OnWire(reused)),
            Some((DVec2::new(7.0, 0.0), 8.0))
        );
        assert!(table.circle(&OnWire(wires[1])).is_none());
    }
}
