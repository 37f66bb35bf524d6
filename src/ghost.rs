//! [`GhostPlugin`]: ghost copies of the running scene, each stepped beside
//! it in a headless world of its own with another method, other Baumgarte
//! constants or another timestep ([`GhostSpec`]). A ghost keeps to the
//! run's simulated time, takes the drag's pull on the same beads, starts
//! again when the run restarts or steps back, and records the drift and
//! energy of the bead the panel follows ([`GhostFocus`]), so that the
//! assignment's three studies (α and β, the method, the timestep) play out
//! side by side in the window.

use std::collections::VecDeque;

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;

use crate::controls::GhostRequests;
use crate::dynamics::{BeadDiagnostics, BeadPosition, Dimension, SimParams, SpringAnchor};
use crate::headless::{Headless, idle};
use crate::plugin::{SceneEnergy, SimClock, WireBeadPlugin};
use crate::preset::{ActivePreset, BeadEdits, SceneFile, WireEdits, edited_scene};
use crate::solver::Method;
use crate::validate::ParamError;

/// Steps the [`Ghosts`] beside the run. Needs the
/// [`ScenePresetPlugin`](crate::ScenePresetPlugin): a ghost is a copy of
/// the running scene file, with the run's applied edits.
#[derive(Default)]
pub struct GhostPlugin;

impl Plugin for GhostPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Ghosts>()
            .init_resource::<GhostFocus>()
            .init_resource::<GhostDraft>()
            .init_resource::<GhostRequests>()
            .add_message::<GhostRequest>()
            // After the frame's fixed steps (and a step back), so a ghost
            // catches up with the run as the frame shows it.
            .add_systems(
                RunFixedMainLoop,
                (ghost_requested, sync_ghosts)
                    .chain()
                    .in_set(RunFixedMainLoopSystems::AfterFixedMainLoop)
                    // A step back first: the ghosts go back with the run.
                    .after(crate::plugin::TimelineSystems::Seek),
            );
    }
}

/// What a ghost changes of the run's parameters: the method, the
/// Baumgarte constants and the timestep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GhostSpec {
    /// The method.
    pub method: Method,
    /// Baumgarte's spring constant α.
    pub alpha: f64,
    /// Baumgarte's damping constant β.
    pub beta: f64,
    /// The timestep, in seconds.
    pub timestep: f64,
}

impl GhostSpec {
    /// The spec of the run's own parameters.
    pub fn of(params: &SimParams) -> Self {
        Self {
            method: params.method,
            alpha: params.alpha,
            beta: params.beta,
            timestep: params.timestep,
        }
    }

    /// The run's parameters `params` with this spec's in place, if they
    /// are valid.
    pub fn apply(&self, params: &SimParams) -> Result<SimParams, ParamError> {
        let params = SimParams {
            method: self.method,
            alpha: self.alpha,
            beta: self.beta,
            timestep: self.timestep,
            ..params.clone()
        };
        params.validate()?;
        Ok(params)
    }

    /// A one-line name: the method, with α and β where it uses them, and
    /// the timestep.
    pub fn label(&self) -> String {
        let baumgarte = self.method.stabilization() == Some(crate::Stabilization::Baumgarte);
        let constants = if baumgarte {
            format!(", α {} β {}", self.alpha, self.beta)
        } else {
            String::new()
        };
        format!("{}{constants}, dt {:.4} s", self.method, self.timestep)
    }
}

/// The ghost the panel (and G) will add next.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct GhostDraft(pub Option<GhostSpec>);

/// Asks for a ghost to be added, or taken away.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub enum GhostRequest {
    /// A ghost with this spec.
    Add(GhostSpec),
    /// Takes away the ghost at this place in [`Ghosts::list`].
    Remove(usize),
}

/// The bead whose drift and energy the ghosts record (the panel's
/// selected bead).
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GhostFocus(pub Option<Entity>);

/// The colours ghosts are drawn in, in the order they are added: sRGB
/// and alpha.
pub const GHOST_COLOURS: [[f32; 4]; 4] = [
    [1.0, 0.4, 0.85, 0.8],
    [0.55, 1.0, 0.4, 0.8],
    [0.7, 0.55, 1.0, 0.8],
    [0.95, 0.95, 0.95, 0.8],
];

/// The most ghosts at once.
pub const MAX_GHOSTS: usize = GHOST_COLOURS.len();

/// The most steps a ghost takes in one frame to catch up with the run.
const CATCH_UP: usize = 20_000;

/// The ghosts of the running scene.
#[derive(Resource, Default)]
pub struct Ghosts {
    /// The ghosts, oldest first.
    pub list: Vec<Ghost>,
    /// Why the last ghost asked for could not be added, if it could not.
    pub refused: Option<String>,
}

/// One drift and energy sample of a ghost's followed bead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GhostSample {
    /// The ghost's simulated time.
    pub t: f64,
    /// The bead's `C`.
    pub c: f64,
    /// The ghost scene's energy ([`SceneEnergy`]), as the run's plot
    /// shows the run's.
    pub energy: f64,
}

/// A copy of the running scene stepped with its own [`GhostSpec`].
pub struct Ghost {
    /// What it changes.
    pub spec: GhostSpec,
    /// Its colour, sRGB and alpha.
    pub colour: [f32; 4],
    /// The followed bead's drift and energy, the last ten seconds.
    pub samples: VecDeque<GhostSample>,
    world: Option<GhostWorld>,
}

/// A ghost's world: the world of a headless app running the scene (its
/// schedules in it), and its beads in the file's order.
struct GhostWorld {
    world: World,
    beads: Vec<Entity>,
    scene: AssetId<SceneFile>,
    dimension: u8,
}

impl Ghost {
    fn new(spec: GhostSpec, colour: [f32; 4]) -> Self {
        Self {
            spec,
            colour,
            samples: VecDeque::new(),
            world: None,
        }
    }

    /// Its simulated time.
    pub fn time(&self) -> f64 {
        self.world
            .as_ref()
            .map_or(0.0, |w| w.world.resource::<SimClock>().time)
    }

    /// Where each of its beads is, in the file's order (`z` zero in the
    /// plane).
    pub fn positions(&self) -> Vec<DVec3> {
        let Some(world) = &self.world else {
            return Vec::new();
        };
        let w = &world.world;
        world
            .beads
            .iter()
            .filter_map(|&b| {
                w.get::<BeadPosition>(b)
                    .map(|x| x.0.extend(0.0))
                    .or_else(|| w.get::<BeadPosition<DVec3>>(b).map(|x| x.0))
            })
            .collect()
    }
}

/// Adds and takes away ghosts, as asked.
fn ghost_requested(
    mut requests: MessageReader<GhostRequest>,
    mut keys: ResMut<GhostRequests>,
    draft: Res<GhostDraft>,
    params: Res<SimParams>,
    mut ghosts: ResMut<Ghosts>,
) {
    let from_keys = std::mem::take(&mut keys.0);
    let drafted = draft.0.unwrap_or_else(|| default_ghost(&params));
    let asked = requests
        .read()
        .copied()
        .chain((0..from_keys).map(|_| GhostRequest::Add(drafted)));
    for request in asked.collect::<Vec<_>>() {
        match request {
            GhostRequest::Add(spec) => {
                if ghosts.list.len() >= MAX_GHOSTS {
                    ghosts.refused = Some(format!("at most {MAX_GHOSTS} ghosts; none was added"));
                    continue;
                }
                if let Err(e) = spec.apply(&params) {
                    ghosts.refused = Some(format!("ghost: {e}; none was added"));
                    continue;
                }
                let used: Vec<[f32; 4]> = ghosts.list.iter().map(|g| g.colour).collect();
                let colour = GHOST_COLOURS
                    .into_iter()
                    .find(|c| !used.contains(c))
                    .unwrap_or(GHOST_COLOURS[0]);
                ghosts.list.push(Ghost::new(spec, colour));
                ghosts.refused = None;
            }
            GhostRequest::Remove(i) => {
                if i < ghosts.list.len() {
                    ghosts.list.remove(i);
                }
            }
        }
    }
}

/// The ghost a G press adds where the panel drafted none: RATTLE beside a
/// run that is not RATTLE, the assignment's semi-implicit Euler with
/// Baumgarte beside one that is.
pub fn default_ghost(params: &SimParams) -> GhostSpec {
    let method = if params.method == Method::Rattle {
        Method::default()
    } else {
        Method::Rattle
    };
    GhostSpec {
        method,
        ..GhostSpec::of(params)
    }
}

/// Builds each ghost's world where it has none (or the scene changed, or
/// the run went back in time) and steps it up to the run's time, the
/// drag's anchors copied onto its beads each step.
#[allow(clippy::too_many_arguments)]
fn sync_ghosts(
    mut ghosts: ResMut<Ghosts>,
    clock: Res<SimClock>,
    params: Res<SimParams>,
    active: Option<Res<ActivePreset>>,
    scenes: Option<Res<Assets<SceneFile>>>,
    focus: Res<GhostFocus>,
    beads: Query<BeadEdits>,
    wires: WireEdits,
    anchors: Query<(Option<&SpringAnchor>, Option<&SpringAnchor<DVec3>>)>,
) {
    let (Some(active), Some(scenes)) = (active, scenes) else {
        return;
    };
    if ghosts.list.is_empty() {
        return;
    }
    let scene_id = active.handle.id();
    let Some(scene) = scenes.get(scene_id) else {
        return;
    };
    let focus = focus
        .0
        .and_then(|f| active.beads.iter().position(|&b| b == f));
    let pulls: Vec<(Option<SpringAnchor>, Option<SpringAnchor<DVec3>>)> = active
        .beads
        .iter()
        .map(|&b| {
            anchors
                .get(b)
                .map_or((None, None), |(a, s)| (a.copied(), s.copied()))
        })
        .collect();
    for ghost in &mut ghosts.list {
        let stale = ghost.world.as_ref().is_none_or(|w| {
            w.scene != scene_id
                || w.beads.len() != active.beads.len()
                || w.world.resource::<SimClock>().time > clock.time + 1e-9
        });
        if stale {
            ghost.samples.clear();
            ghost.world = ghost.spec.apply(&params).ok().map(|ghost_params| {
                let edited =
                    edited_scene(scene, &active.beads, &ghost_params, false, &beads, &wires);
                build_world(&edited, ghost_params, scene_id)
            });
        }
        let Some(world) = &mut ghost.world else {
            continue;
        };
        let dt = ghost.spec.timestep;
        for _ in 0..CATCH_UP {
            let t = world.world.resource::<SimClock>().time;
            if t + 0.5 * dt > clock.time {
                break;
            }
            world.pull(&pulls);
            world.world.run_schedule(FixedUpdate);
            if let Some(sample) = world.sample(focus) {
                ghost.samples.push_back(sample);
            }
        }
        let horizon = clock.time - 10.0;
        while ghost.samples.front().is_some_and(|s| s.t < horizon) {
            ghost.samples.pop_front();
        }
    }
}

/// A headless world running `scene` with `params`.
fn build_world(scene: &SceneFile, params: SimParams, id: AssetId<SceneFile>) -> GhostWorld {
    let plugin = WireBeadPlugin::new(params).unwrap_or_default();
    let mut app = Headless::new(plugin).single_threaded().build();
    app.init_resource::<SceneEnergy>();
    let beads = scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    idle(&mut app);
    GhostWorld {
        world: std::mem::take(app.world_mut()),
        beads,
        scene: id,
        dimension: if scene.in_space() { 3 } else { 2 },
    }
}

impl GhostWorld {
    /// Puts the run's drag anchors on the same beads.
    fn pull(&mut self, pulls: &[(Option<SpringAnchor>, Option<SpringAnchor<DVec3>>)]) {
        let world = &mut self.world;
        for (&bead, &(plane, space)) in self.beads.iter().zip(pulls) {
            let Ok(mut entity) = world.get_entity_mut(bead) else {
                continue;
            };
            if self.dimension == 2 {
                set_anchor(&mut entity, plane);
            } else {
                set_anchor(&mut entity, space);
            }
        }
    }

    /// The drift and energy of bead `focus` (its place in the file).
    fn sample(&self, focus: Option<usize>) -> Option<GhostSample> {
        let bead = *self.beads.get(focus?)?;
        let world = &self.world;
        let t = world.resource::<SimClock>().time;
        let (c, own) = if self.dimension == 2 {
            diagnosed::<DVec2>(world, bead)?
        } else {
            diagnosed::<DVec3>(world, bead)?
        };
        // Before its first step the scene's is not measured yet.
        let energy = world
            .get_resource::<SceneEnergy>()
            .filter(|e| e.time == t)
            .map_or(own, |e| e.total);
        Some(GhostSample { t, c, energy })
    }
}

/// A bead's `C` and its own energy.
fn diagnosed<V: Dimension>(world: &World, bead: Entity) -> Option<(f64, f64)> {
    let d = world.get::<BeadDiagnostics<V>>(bead)?;
    Some((d.c, d.energy()))
}

/// Sets or takes away a bead's drag anchor, touching it only on a change.
fn set_anchor<V: crate::geometry::Coordinates + Reflect + TypePath>(
    entity: &mut EntityWorldMut,
    anchor: Option<SpringAnchor<V>>,
) where
    SpringAnchor<V>: Component,
{
    let now = entity.get::<SpringAnchor<V>>().copied();
    match (now, anchor) {
        (Some(a), Some(b)) if a == b => {}
        (_, Some(b)) => {
            entity.insert(b);
        }
        (Some(_), None) => {
            entity.remove::<SpringAnchor<V>>();
        }
        (None, None) => {}
    }
}
