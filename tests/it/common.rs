//! Helpers on top of `wirebead::headless`: a recorder of every bead's state
//! after every step, scene builders and measurements.
#![allow(dead_code)]

use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::BeadForce;
use wirebead::SimClock;
use wirebead::headless::{Headless, bead_state};
pub use wirebead::headless::{run_for, run_steps};
use wirebead::prelude::*;
use wirebead::reference;
use wirebead::solver::BeadState;

/// One recorded step of one bead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub t: f64,
    pub position: DVec2,
    pub velocity: DVec2,
    pub diagnostics: BeadDiagnostics,
}

/// Every bead's samples, in step order.
#[derive(Resource, Default)]
pub struct Recording(pub Vec<(Entity, Sample)>);

impl Recording {
    pub fn of(&self, bead: Entity) -> Vec<Sample> {
        self.0
            .iter()
            .filter(|(e, _)| *e == bead)
            .map(|(_, s)| *s)
            .collect()
    }
}

fn record(
    beads: Query<(Entity, &BeadPosition, &BeadVelocity, &BeadDiagnostics)>,
    clock: Res<SimClock>,
    mut recording: ResMut<Recording>,
) {
    for (entity, position, velocity, diagnostics) in &beads {
        recording.0.push((
            entity,
            Sample {
                t: clock.time,
                position: position.0,
                velocity: velocity.0,
                diagnostics: *diagnostics,
            },
        ));
    }
}

/// A headless app with the plugin and the recorder, single-threaded, ready
/// to step.
pub fn app(params: SimParams) -> App {
    let plugin = WireBeadPlugin::new(params).expect("valid params");
    let mut app = Headless::new(plugin).single_threaded().build();
    app.init_resource::<Recording>()
        .add_systems(FixedUpdate, record.after(WireBeadSystems::Writeback));
    app
}

/// Has the islands built again before the next step: spawns a free bead
/// far from everything (the `k`-th such, apart from the others).
pub fn build_islands_again(app: &mut App, k: u32) {
    let far = BeadParams {
        mass: 1.0,
        initial_position: DVec2::new(100.0 * f64::from(k), 100.0),
        initial_velocity: DVec2::ZERO,
    };
    app.world_mut().spawn(Bead::new(far).expect("a bead"));
}

pub fn spawn_wire(app: &mut App, wire: Wire, transform: Transform) -> Entity {
    app.world_mut().spawn((wire, transform)).id()
}

pub fn spawn_bead(app: &mut App, wire: Entity, params: BeadParams) -> Entity {
    app.world_mut()
        .spawn((Bead::new(params).expect("valid bead"), OnWire(wire)))
        .id()
}

/// A bead of 1 kg at rest on `wire`, a unit circle about `centre`, at
/// (0.6, −0.8) from it.
pub fn bead_at_rest_on(app: &mut App, wire: Entity, centre: DVec2) -> Entity {
    spawn_bead(
        app,
        wire,
        BeadParams {
            mass: 1.0,
            initial_position: centre + DVec2::new(0.6, -0.8),
            initial_velocity: DVec2::ZERO,
        },
    )
}

/// A circle of radius `r` at the origin with one bead of mass 1 starting at
/// `x0` with velocity `v0`. Returns the bead.
pub fn circle_bead(app: &mut App, r: f64, x0: DVec2, v0: DVec2) -> Entity {
    let wire = spawn_wire(app, Wire::circle(r).unwrap(), Transform::default());
    spawn_bead(
        app,
        wire,
        BeadParams {
            mass: 1.0,
            initial_position: x0,
            initial_velocity: v0,
        },
    )
}

/// A vertical circle of radius `r` at the origin with a bead released from
/// rest `theta0` radians from the bottom. Returns the bead.
pub fn pendulum(app: &mut App, r: f64, theta0: f64) -> Entity {
    circle_bead(app, r, reference::point_on_circle(r, theta0), DVec2::ZERO)
}

/// What a test reads of a bead: its columns, copied out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeadNow {
    pub position: DVec2,
    pub velocity: DVec2,
    pub mass: f64,
    pub params: BeadParams,
    pub force: (DVec2, f64),
}

impl BeadNow {
    pub fn state(&self) -> BeadState {
        BeadState {
            position: self.position,
            velocity: self.velocity,
        }
    }
}

pub fn bead(app: &App, bead: Entity) -> BeadNow {
    let world = app.world();
    let state = bead_state(world, bead).expect("bead");
    BeadNow {
        position: state.position,
        velocity: state.velocity,
        mass: world.get::<BeadMass>(bead).expect("bead").get(),
        params: *world.get::<BeadParams>(bead).expect("bead"),
        force: world.get::<BeadForce>(bead).expect("bead").get(),
    }
}

pub fn diagnostics(app: &App, bead: Entity) -> BeadDiagnostics {
    *app.world().get::<BeadDiagnostics>(bead).expect("bead")
}

pub fn params(method: Method, dt: f64) -> SimParams {
    SimParams {
        timestep: dt,
        method,
        ..default()
    }
}

/// Steps since the last restart.
pub fn steps(app: &App) -> u64 {
    app.world().resource::<SimClock>().steps
}

/// The largest `|C|` over the samples.
pub fn max_drift(samples: &[Sample]) -> f64 {
    samples
        .iter()
        .map(|s| s.diagnostics.c.abs())
        .fold(0.0, f64::max)
}

/// The period from upward zero crossings of x.
pub fn measured_period(samples: &[Sample]) -> f64 {
    let xs: Vec<(f64, f64)> = samples.iter().map(|s| (s.t, s.position.x)).collect();
    reference::period_from_crossings(&xs).expect("at least two crossings")
}

/// Whether a step can split over threads here: the `parallel` feature
/// (Bevy's thread pools) on a machine of more than one core. Where it can,
/// the parallel tests assert that it did.
pub fn splits() -> bool {
    cfg!(feature = "parallel") && bevy::tasks::available_parallelism() > 1
}

/// The messages of type `M` sent this update.
pub fn sent<M: Message + Clone>(app: &App) -> Vec<M> {
    let messages = app.world().resource::<Messages<M>>();
    messages.iter_current_update_messages().cloned().collect()
}
