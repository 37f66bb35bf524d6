//! Many beads for the benchmarks, the memory measurement and the profile:
//! pendulums on circles of radius 1, through the plugin or as plain structs.

#![allow(dead_code)]

use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::geometry::{Circle, Placed, Pose};
use wirebead::headless::Headless;
use wirebead::prelude::*;
use wirebead::solver::{self, BeadState, LinearForce, StepSettings};

/// How the beads are put on wires.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Layout {
    /// Each bead on a circle of its own, the circles on a grid.
    OwnWires,
    /// Every bead on one circle.
    SharedWire,
}

impl Layout {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::OwnWires => "own-wires",
            Self::SharedWire => "shared-wire",
        }
    }
}

/// How the plugin runs its loops.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Threads {
    /// One thread: single-threaded executor, [`ParallelStep::OFF`].
    Single,
    /// Bevy's default executor and [`ParallelStep::default`].
    Parallel,
}

impl Threads {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Single => "single",
            Self::Parallel => "parallel",
        }
    }
}

/// What a bead carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Kind {
    /// The default bead: `Transform` and `BeadDiagnostics` included.
    Full,
    /// [`WireBeadPlugin::lean`]: the bead's state and its wire only.
    Lean,
}

impl Kind {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Full => "full",
            Self::Lean => "lean",
        }
    }
}

/// The starting angle from the bottom of bead `i`: spread over ±120° so the
/// beads are at different phases.
pub fn start_angle(i: usize) -> f64 {
    let spread = (i % 241) as f64 / 240.0;
    (spread * 2.0 - 1.0) * 120f64.to_radians()
}

/// Where bead `i`'s circle sits.
pub fn grid_origin(i: usize) -> DVec2 {
    DVec2::new(3.0 * (i % 1024) as f64, 3.0 * (i / 1024) as f64)
}

fn on_circle(origin: DVec2, angle: f64) -> DVec2 {
    origin + DVec2::new(angle.sin(), -angle.cos())
}

/// An app with the plugin and `n` beads at rest, ready for
/// `world_mut().run_schedule(FixedUpdate)` (one step per call).
pub fn plugin_app(n: usize, layout: Layout, threads: Threads, kind: Kind) -> App {
    let plugin = match kind {
        Kind::Full => WireBeadPlugin::default(),
        Kind::Lean => WireBeadPlugin::default().lean(),
    };
    let harness = Headless::new(plugin).on_all_cores();
    let mut app = match threads {
        Threads::Single => harness.single_threaded().parallel(ParallelStep::OFF),
        Threads::Parallel => harness,
    }
    .build();
    let world = app.world_mut();
    match layout {
        Layout::SharedWire => {
            let wire = world.spawn(Wire::circle(1.0).expect("radius 1")).id();
            world.spawn_batch((0..n).map(move |i| {
                let bead = Bead::at_rest(1.0, on_circle(DVec2::ZERO, start_angle(i)));
                (bead.expect("valid bead"), OnWire(wire))
            }));
        }
        Layout::OwnWires => {
            let wires: Vec<Entity> = world
                .spawn_batch((0..n).map(|i| {
                    let o = grid_origin(i);
                    (
                        Wire::circle(1.0).expect("radius 1"),
                        Transform::from_xyz(o.x as f32, o.y as f32, 0.0),
                    )
                }))
                .collect();
            world.spawn_batch(wires.into_iter().enumerate().map(|(i, wire)| {
                let bead = Bead::at_rest(1.0, on_circle(grid_origin(i), start_angle(i)));
                (bead.expect("valid bead"), OnWire(wire))
            }));
        }
    }
    app
}

/// One lean bead as a plain struct: the state the plugin keeps.
#[derive(Clone, Copy, Debug)]
pub struct RawBead {
    /// Position and velocity.
    pub state: BeadState,
    /// Mass.
    pub mass: f64,
    /// Index of its wire's pose.
    pub wire: u32,
}

/// What a full bead adds: diagnostics and the rendered position.
#[derive(Clone, Copy, Debug, Default)]
pub struct RawExtras {
    /// λ.
    pub lambda: f64,
    /// `λN`.
    pub constraint_force: DVec2,
    /// `C`, `Ċ`, kinetic and potential energy.
    pub diagnostics: [f64; 4],
    /// The rendered position.
    pub rendered: [f32; 2],
}

/// The floor: the plugin's step as one fused loop over a `Vec`.
pub struct RawLoop {
    /// The beads.
    pub beads: Vec<RawBead>,
    /// Their extras, for [`Kind::Full`]; empty for [`Kind::Lean`].
    pub extras: Vec<RawExtras>,
    /// Each wire's pose.
    pub poses: Vec<Pose>,
    /// The shared shape.
    pub circle: Circle,
    /// The step's settings.
    pub settings: StepSettings,
    /// Gravity.
    pub gravity: DVec2,
}

impl RawLoop {
    /// `n` beads laid out as [`plugin_app`] lays them out.
    pub fn new(n: usize, layout: Layout, kind: Kind) -> Self {
        let params = SimParams::default();
        let poses: Vec<Pose> = match layout {
            Layout::SharedWire => vec![Pose::IDENTITY],
            Layout::OwnWires => (0..n).map(|i| Pose::new(grid_origin(i), 0.0)).collect(),
        };
        let beads = (0..n)
            .map(|i| {
                let wire = if layout == Layout::SharedWire { 0 } else { i };
                (wire, poses[wire].origin, i)
            })
            .map(|(wire, origin, i)| RawBead {
                state: BeadState {
                    position: on_circle(origin, start_angle(i)),
                    velocity: DVec2::ZERO,
                },
                mass: 1.0,
                wire: wire as u32,
            })
            .collect();
        let extras = match kind {
            Kind::Full => vec![RawExtras::default(); n],
            Kind::Lean => Vec::new(),
        };
        Self {
            beads,
            extras,
            poses,
            circle: Circle { radius: 1.0 },
            settings: params.step_settings(),
            gravity: params.gravity,
        }
    }

    /// One step of every bead; returns how many failed.
    pub fn step(&mut self) -> usize {
        if self.extras.is_empty() {
            self.step_lean()
        } else {
            self.step_full()
        }
    }

    /// Steps `beads` as the plugin does: [`solver::LANES`] at a time
    /// through the batched circle step, the lanes it hands back and the
    /// last partial chunk through `step`. `store` gets each bead's index and
    /// result.
    #[inline(always)]
    fn step_chunks(
        &self,
        beads: &mut [RawBead],
        mut store: impl FnMut(usize, &mut RawBead, Result<solver::StepOutput, solver::SolveError>),
    ) {
        let mut lanes = solver::CircleLanes::default();
        let mut outs = solver::CircleSteps::default();
        let mut chunks = beads.chunks_exact_mut(solver::LANES);
        let mut start = 0;
        for chunk in &mut chunks {
            for (lane, bead) in chunk.iter().enumerate() {
                let force = LinearForce::constant(bead.mass * self.gravity);
                let pose = self.poses[bead.wire as usize];
                lanes.set(
                    lane,
                    bead.state,
                    &force,
                    bead.mass,
                    pose.origin,
                    self.circle.radius,
                );
            }
            solver::step_on_circles(&lanes, &self.settings, &mut outs);
            for (lane, bead) in chunk.iter_mut().enumerate() {
                // Two calls, so a finished lane's result stays in registers.
                match outs.lane(lane) {
                    Some(out) => store(start + lane, bead, Ok(out)),
                    None => {
                        let out = self.step_one(bead);
                        store(start + lane, bead, out);
                    }
                }
            }
            start += solver::LANES;
        }
        for (k, bead) in chunks.into_remainder().iter_mut().enumerate() {
            let out = self.step_one(bead);
            store(start + k, bead, out);
        }
    }

    fn step_one(&self, bead: &RawBead) -> Result<solver::StepOutput, solver::SolveError> {
        let placed = Placed {
            curve: &self.circle,
            pose: self.poses[bead.wire as usize],
        };
        let force = LinearForce::constant(bead.mass * self.gravity);
        solver::step(&placed, bead.state, &force, bead.mass, &self.settings)
    }

    fn step_lean(&mut self) -> usize {
        let mut failed = 0;
        let mut beads = std::mem::take(&mut self.beads);
        self.step_chunks(&mut beads, |_, bead, out| match out {
            Ok(out) => bead.state = out.state,
            Err(_) => failed += 1,
        });
        self.beads = beads;
        failed
    }

    fn step_full(&mut self) -> usize {
        let mut failed = 0;
        let (mut beads, mut extras) = (
            std::mem::take(&mut self.beads),
            std::mem::take(&mut self.extras),
        );
        self.step_chunks(&mut beads, |i, bead, out| match out {
            Ok(out) => {
                bead.state = out.state;
                let (kinetic, potential) = out.state.energy(bead.mass, self.gravity);
                extras[i] = RawExtras {
                    lambda: out.lambda,
                    constraint_force: out.constraint_force,
                    diagnostics: [out.c, out.c_dot, kinetic, potential],
                    rendered: [out.state.position.x as f32, out.state.position.y as f32],
                };
            }
            Err(_) => failed += 1,
        });
        (self.beads, self.extras) = (beads, extras);
        failed
    }
}
