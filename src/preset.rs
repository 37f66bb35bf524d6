//! Scene presets: RON files that set the wires, the beads, the links
//! between beads and the parameters, loaded as Bevy assets
//! (`*.scene.ron`).
//!
//! ```ron
//! (
//!     name: "Pendulum on a cart",
//!     params: (integrator: Rattle),
//!     wires: [(shape: Line(()), beads: [(name: "cart", mass: 2.0, initial_position: (0.0, 0.0))])],
//!     beads: [(name: "bob", mass: 1.0, initial_position: (0.0, -1.0))],
//!     constraints: [Rod((a: "cart", b: "bob", length: 1.0))],
//!     springs: [],
//! )
//! ```
//!
//! `beads` outside `wires` are free (on no wire). Links name beads by
//! their `name`; a bead without one is `bead0`, `bead1`, … by its place in
//! the file (the wires' beads in order, then the free ones). A pin is
//! `Pin((bead: "top", at: (0.0, 2.0)))`, a spring
//! `(a: "p", b: "q", rest_length: 1.0, stiffness: 50.0, damping: 0.1)`.
//! `beads`, `constraints` and `springs` may be left out.
//!
//! [`ScenePresetPlugin`] loads the file named by [`ActivePreset`], applies it
//! when it loads and again whenever the file changes (with Bevy's
//! `file_watcher`), and on a malformed file keeps the running scene and
//! records the error in [`ActivePreset::error`].

use bevy::asset::io::Reader;
use bevy::asset::{AssetLoadError, AssetLoadFailedEvent, AssetLoader, LoadContext};
use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::dynamics::{
    Bead, BeadParams, OnWire, PendingParams, Pin, PrescribedMotion, Rod, SimParams, Spring, Wire,
};
use crate::geometry::{Friction, Pose, Side, Surface, Twist, WireMotion, WireShape};
use crate::plugin::{Restart, WireBeadSystems};
use crate::validate::{ParamError, finite, finite_vector, non_negative, positive};

/// A bead of a scene file: its name (optional) and its parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct BeadPreset {
    /// The name links refer to it by; empty for none (it is then
    /// `bead<i>`, `i` its place in the file).
    pub name: String,
    /// Mass in kg.
    pub mass: f64,
    /// Where a restart puts the bead.
    pub initial_position: DVec2,
    /// The velocity a restart gives it.
    pub initial_velocity: DVec2,
}

impl Default for BeadPreset {
    fn default() -> Self {
        let params = BeadParams::default();
        Self {
            name: String::new(),
            mass: params.mass,
            initial_position: params.initial_position,
            initial_velocity: params.initial_velocity,
        }
    }
}

impl BeadPreset {
    /// The bead's parameters.
    pub fn params(&self) -> BeadParams {
        BeadParams {
            mass: self.mass,
            initial_position: self.initial_position,
            initial_velocity: self.initial_velocity,
        }
    }
}

/// A rod of a scene file: `|x_a − x_b| = length`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RodPreset {
    /// The first bead's name.
    pub a: String,
    /// The second bead's name.
    pub b: String,
    /// The rod's length.
    pub length: f64,
}

/// A pin of a scene file: a bead held at a point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinPreset {
    /// The bead's name.
    pub bead: String,
    /// The point.
    pub at: DVec2,
}

/// A constraint of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ConstraintPreset {
    /// See [`Rod`].
    Rod(RodPreset),
    /// See [`Pin`].
    Pin(PinPreset),
}

impl ConstraintPreset {
    /// `rod` or `pin`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Rod(_) => "rod",
            Self::Pin(_) => "pin",
        }
    }
}

/// A spring of a scene file (see [`Spring`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringPreset {
    /// The first bead's name.
    pub a: String,
    /// The second bead's name.
    pub b: String,
    /// Rest length.
    pub rest_length: f64,
    /// Stiffness (N/m).
    pub stiffness: f64,
    /// Damping along the spring (N·s/m).
    #[serde(default)]
    pub damping: f64,
}

/// One wire of a preset and the beads on it.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WirePreset {
    /// The shape, in the wire's frame.
    pub shape: WireShape,
    /// Where the wire's origin sits.
    #[serde(default)]
    pub position: DVec2,
    /// The wire's rotation, in degrees counter-clockwise.
    #[serde(default)]
    pub angle_degrees: f64,
    /// How it moves about that pose: `Fixed` (the default),
    /// `Oscillate((amplitude: (ax, ay), frequency: f))` or
    /// `Spin((angular_velocity: w))`. Its beads' initial velocities are
    /// relative to the wire's own at `t = 0`.
    #[serde(default)]
    pub motion: WireMotion,
    /// Which way it pushes: `Both` (the default), `Positive` or `Negative`
    /// (see [`Side`]).
    #[serde(default)]
    pub side: Side,
    /// On a one-sided wire, the share of the normal speed a landing bead
    /// bounces off with (0, the default: it stays on).
    #[serde(default)]
    pub restitution: f64,
    /// Coulomb friction along it, `(static: μs, kinetic: μk)`; none by
    /// default.
    #[serde(default)]
    pub friction: Friction,
    /// Viscous damping along it, N·s/m; none by default.
    #[serde(default)]
    pub damping: f64,
    /// The beads on it.
    #[serde(default)]
    pub beads: Vec<BeadPreset>,
}

impl WirePreset {
    /// Its side, restitution, friction and damping.
    pub fn surface(&self) -> Surface {
        Surface {
            side: self.side,
            restitution: self.restitution,
            friction: self.friction,
            damping: self.damping,
        }
    }
}

/// A whole scene: parameters, wires and beads.
#[derive(Asset, TypePath, Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenePreset {
    /// A human-readable name.
    pub name: String,
    /// The parameters (missing fields take their defaults).
    #[serde(default)]
    pub params: SimParams,
    /// The wires.
    #[serde(default)]
    pub wires: Vec<WirePreset>,
    /// The free beads, on no wire.
    #[serde(default)]
    pub beads: Vec<BeadPreset>,
    /// Rods and pins.
    #[serde(default)]
    pub constraints: Vec<ConstraintPreset>,
    /// Springs between beads.
    #[serde(default)]
    pub springs: Vec<SpringPreset>,
}

impl PresetError {
    /// A parse error at `path` (as `serde_path_to_error` writes it, the
    /// field last): an unknown field names itself and its item.
    fn at(path: String, error: ron::error::SpannedError) -> Self {
        match &error.code {
            ron::Error::NoSuchStructField {
                expected, found, ..
            } => {
                let item = match path.rsplit_once('.') {
                    Some((item, _)) => item.to_owned(),
                    None => "the scene".to_owned(),
                };
                PresetError::UnknownField {
                    field: found.clone(),
                    item,
                    line: error.span.start.line,
                    column: error.span.start.col,
                    known: expected.join(", "),
                }
            }
            _ => PresetError::Parse(error),
        }
    }
}

/// What is wrong with a scene file.
#[derive(Debug, thiserror::Error)]
pub enum PresetError {
    /// The file is not valid RON for a preset.
    #[error(
        "malformed scene file at line {}, column {}: {}",
        .0.span.start.line,
        .0.span.start.col,
        .0.code
    )]
    Parse(#[from] ron::error::SpannedError),
    /// A field the format does not have (a misspelt name, or one from a
    /// later version): refused rather than ignored.
    #[error(
        "unknown field `{field}` in {item} at line {line}, column {column}; the file was refused (known fields: {known})"
    )]
    UnknownField {
        /// The field as written.
        field: String,
        /// Where it is: `the scene`, `wires[2]`, `wires[0].beads[1]`.
        item: String,
        /// The line it is on.
        line: usize,
        /// Its column.
        column: usize,
        /// The fields that item has.
        known: String,
    },
    /// The file could not be read.
    #[error("cannot read scene file: {0}")]
    Io(#[from] std::io::Error),
    /// The parameters are invalid.
    #[error("invalid params: {0}")]
    Params(ParamError),
    /// A wire is invalid.
    #[error("wire {index}: {source}")]
    Wire {
        /// Its index in `wires`.
        index: usize,
        /// What is wrong.
        source: ParamError,
    },
    /// A bead is invalid.
    #[error("wire {wire}, bead {bead}: {source}")]
    Bead {
        /// The wire's index.
        wire: usize,
        /// The bead's index on it.
        bead: usize,
        /// What is wrong.
        source: ParamError,
    },
    /// A free bead is invalid.
    #[error("bead {name:?}: {source}")]
    FreeBead {
        /// Its name.
        name: String,
        /// What is wrong.
        source: ParamError,
    },
    /// Two beads have one name.
    #[error("two beads are named {0:?}")]
    DuplicateName(String),
    /// A constraint or spring is invalid.
    #[error("{item}: {problem}")]
    Link {
        /// Which, in words: `constraint 0 (rod)`, `spring 1`.
        item: String,
        /// What is wrong.
        problem: String,
    },
    /// The scene has no bead.
    #[error("the scene has no bead")]
    Empty,
}

impl ScenePreset {
    /// Parses and validates a preset.
    pub fn from_ron(text: &str) -> Result<Self, PresetError> {
        let mut de = ron::Deserializer::from_str(text)?;
        let preset: Self = match serde_path_to_error::deserialize(&mut de) {
            Ok(preset) => preset,
            Err(err) => {
                let item = err.path().to_string();
                return Err(PresetError::at(item, de.span_error(err.into_inner())));
            }
        };
        de.end().map_err(|e| de.span_error(e))?;
        preset.validate()?;
        Ok(preset)
    }

    /// Checks the parameters, every wire and every bead.
    pub fn validate(&self) -> Result<(), PresetError> {
        self.params.validate().map_err(PresetError::Params)?;
        for (index, wire) in self.wires.iter().enumerate() {
            wire.shape
                .validate()
                .map_err(|source| PresetError::Wire { index, source })?;
            finite_vector("wire position", wire.position)
                .and_then(|_| finite("wire angle", wire.angle_degrees))
                .and_then(|_| wire.motion.validate())
                .and_then(|_| wire.surface().validate())
                .map_err(|source| PresetError::Wire { index, source })?;
            for (bead, preset) in wire.beads.iter().enumerate() {
                preset
                    .params()
                    .validate()
                    .map_err(|source| PresetError::Bead {
                        wire: index,
                        bead,
                        source,
                    })?;
            }
        }
        let names = self.bead_names();
        let free_names = &names[self.wire_bead_count()..];
        for (bead, name) in self.beads.iter().zip(free_names) {
            bead.params()
                .validate()
                .map_err(|source| PresetError::FreeBead {
                    name: name.clone(),
                    source,
                })?;
        }
        for (i, name) in names.iter().enumerate() {
            if names[..i].contains(name) {
                return Err(PresetError::DuplicateName(name.clone()));
            }
        }
        self.resolve_links(&names)?;
        if names.is_empty() {
            return Err(PresetError::Empty);
        }
        Ok(())
    }

    /// Every bead of the file in order: the wires' beads, then the free
    /// ones.
    pub fn all_beads(&self) -> impl Iterator<Item = &BeadPreset> {
        self.wires.iter().flat_map(|w| &w.beads).chain(&self.beads)
    }

    fn wire_bead_count(&self) -> usize {
        self.wires.iter().map(|w| w.beads.len()).sum()
    }

    /// Each bead's name, in the file's order: its own, or `bead<i>`.
    pub fn bead_names(&self) -> Vec<String> {
        self.all_beads()
            .enumerate()
            .map(|(i, b)| {
                if b.name.is_empty() {
                    format!("bead{i}")
                } else {
                    b.name.clone()
                }
            })
            .collect()
    }

    /// The constraints, then the springs, with the beads they name as
    /// indices into [`ScenePreset::all_beads`], every value checked.
    pub fn links(&self) -> Result<Vec<SceneLink>, PresetError> {
        self.resolve_links(&self.bead_names())
    }

    fn resolve_links(&self, names: &[String]) -> Result<Vec<SceneLink>, PresetError> {
        let find = |item: &dyn Fn() -> String, name: &str| {
            names
                .iter()
                .position(|n| n == name)
                .ok_or_else(|| PresetError::Link {
                    item: item(),
                    problem: format!("no bead is named {name:?}"),
                })
        };
        let problem = |item: String| {
            move |e: ParamError| PresetError::Link {
                item,
                problem: e.to_string(),
            }
        };
        let mut links = Vec::new();
        for (index, constraint) in self.constraints.iter().enumerate() {
            let item = || format!("constraint {index} ({})", constraint.kind());
            links.push(match constraint {
                ConstraintPreset::Rod(rod) => {
                    let (a, b) = (find(&item, &rod.a)?, find(&item, &rod.b)?);
                    if a == b {
                        return Err(problem(item())(ParamError::Incompatible(
                            "a rod must join two different beads",
                        )));
                    }
                    positive("rod length", rod.length).map_err(problem(item()))?;
                    SceneLink::Rod {
                        a,
                        b,
                        length: rod.length,
                    }
                }
                ConstraintPreset::Pin(pin) => {
                    let bead = find(&item, &pin.bead)?;
                    finite_vector("pin point", pin.at).map_err(problem(item()))?;
                    SceneLink::Pin { bead, at: pin.at }
                }
            });
        }
        for (index, spring) in self.springs.iter().enumerate() {
            let item = || format!("spring {index}");
            let (a, b) = (find(&item, &spring.a)?, find(&item, &spring.b)?);
            if a == b {
                return Err(problem(item())(ParamError::Incompatible(
                    "a spring must join two different beads",
                )));
            }
            for (name, value) in [
                ("spring rest length", spring.rest_length),
                ("spring stiffness", spring.stiffness),
                ("spring damping", spring.damping),
            ] {
                non_negative(name, value).map_err(problem(item()))?;
            }
            links.push(SceneLink::Spring {
                a,
                b,
                spring: spring.clone(),
            });
        }
        Ok(links)
    }

    /// Spawns the wires, the beads (named with [`Name`]) and the links,
    /// each tagged [`FromPreset`]; returns the beads in the file's order.
    /// Call on a validated preset: anything invalid is left out.
    pub fn spawn(&self, commands: &mut Commands) -> Vec<Entity> {
        let names = self.bead_names();
        let mut beads = Vec::new();
        let mut spawn_bead =
            |preset: &BeadPreset, wire: Option<(Entity, Twist)>, commands: &mut Commands| {
                let name = Name::new(names[beads.len()].clone());
                let Ok(mut bead) = Bead::new(preset.params()) else {
                    beads.push(Entity::PLACEHOLDER);
                    return;
                };
                // The initial velocity is relative to the wire's own at
                // t = 0, as a restart makes it.
                if let Some((_, twist)) = &wire {
                    bead.ride(twist);
                }
                let mut entity = commands.spawn((bead, name, FromPreset));
                if let Some((wire, _)) = wire {
                    entity.insert(OnWire(wire));
                }
                beads.push(entity.id());
            };
        for wire in &self.wires {
            let transform =
                Transform::from_xyz(wire.position.x as f32, wire.position.y as f32, 0.0)
                    .with_rotation(Quat::from_rotation_z(wire.angle_degrees.to_radians() as f32));
            let made = Wire::new(wire.shape.clone()).and_then(|w| w.with_surface(wire.surface()));
            let wire_entity = made.ok().map(|component| {
                let mut entity = commands.spawn((component, transform, FromPreset));
                if let Ok(motion) = PrescribedMotion::new(wire.motion)
                    && wire.motion.moves()
                {
                    entity.insert(motion);
                }
                entity.id()
            });
            let base = Pose::new(wire.position, wire.angle_degrees.to_radians());
            let (_, twist) = wire.motion.at(base, 0.0);
            for preset in &wire.beads {
                spawn_bead(preset, wire_entity.map(|e| (e, twist)), commands);
            }
        }
        for preset in &self.beads {
            spawn_bead(preset, None, commands);
        }
        for link in self.resolve_links(&names).unwrap_or_default() {
            let spawned = match link {
                SceneLink::Rod { a, b, length } => Rod::new(beads[a], beads[b], length)
                    .map(|rod| commands.spawn((rod, FromPreset)).id()),
                SceneLink::Pin { bead, at } => {
                    Pin::new(beads[bead], at).map(|pin| commands.spawn((pin, FromPreset)).id())
                }
                SceneLink::Spring { a, b, spring: s } => {
                    Spring::new(beads[a], beads[b], s.rest_length, s.stiffness, s.damping)
                        .map(|spring| commands.spawn((spring, FromPreset)).id())
                }
            };
            if let Err(e) = spawned {
                warn!("wirebead: a link of the scene was left out: {e}");
            }
        }
        beads
    }
}

/// A link of a scene with its beads as indices into
/// [`ScenePreset::all_beads`].
#[derive(Clone, Debug, PartialEq)]
pub enum SceneLink {
    /// A rod between beads `a` and `b`.
    Rod {
        /// The first bead.
        a: usize,
        /// The second bead.
        b: usize,
        /// Its length.
        length: f64,
    },
    /// A pin holding `bead` at `at`.
    Pin {
        /// The bead.
        bead: usize,
        /// The point.
        at: DVec2,
    },
    /// A spring between beads `a` and `b`.
    Spring {
        /// The first bead.
        a: usize,
        /// The second bead.
        b: usize,
        /// Its law.
        spring: SpringPreset,
    },
}

/// Loads `*.scene.ron` files as [`ScenePreset`]s, validating them.
#[derive(Default, TypePath)]
pub struct ScenePresetLoader;

impl AssetLoader for ScenePresetLoader {
    type Asset = ScenePreset;
    type Settings = ();
    type Error = PresetError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        _load_context: &mut LoadContext<'_>,
    ) -> Result<ScenePreset, PresetError> {
        let mut bytes = Vec::new();
        reader.read_to_end(&mut bytes).await?;
        let text = String::from_utf8_lossy(&bytes);
        ScenePreset::from_ron(&text)
    }

    fn extensions(&self) -> &[&str] {
        &["scene.ron"]
    }
}

/// Marks the wires and beads spawned from a preset, which the next preset
/// replaces.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct FromPreset;

/// The preset in use, and the last error loading it.
#[derive(Resource, Clone, Debug, Default)]
pub struct ActivePreset {
    /// The preset's handle; set it (or send [`LoadPreset`]) to switch scenes.
    pub handle: Handle<ScenePreset>,
    /// The preset's asset path.
    pub path: String,
    /// The name of the preset now running.
    pub running: Option<String>,
    /// Why the last load failed, if it did; cleared by a good load.
    pub error: Option<String>,
}

/// Asks to load and run the preset at an asset path.
#[derive(Message, Clone, Debug)]
pub struct LoadPreset(pub String);

/// Loads, applies and hot-reloads scene presets. Needs Bevy's `AssetPlugin`
/// and [`WireBeadPlugin`](crate::WireBeadPlugin).
#[derive(Default)]
pub struct ScenePresetPlugin;

impl Plugin for ScenePresetPlugin {
    fn build(&self, app: &mut App) {
        app.init_asset::<ScenePreset>()
            .register_asset_loader(ScenePresetLoader)
            .init_resource::<ActivePreset>()
            .add_message::<LoadPreset>()
            .add_systems(
                PreUpdate,
                (
                    load_requested_preset,
                    report_preset_errors,
                    apply_loaded_preset,
                )
                    .chain()
                    .before(WireBeadSystems::Restart),
            );
    }
}

/// Starts loading the preset a [`LoadPreset`] names.
pub fn load_requested_preset(
    mut requests: MessageReader<LoadPreset>,
    server: Res<AssetServer>,
    mut active: ResMut<ActivePreset>,
) {
    if let Some(LoadPreset(path)) = requests.read().last() {
        active.handle = server.load(path.clone());
        active.path = path.clone();
    }
}

/// Records and logs a failed load of the active preset; the scene keeps
/// running.
pub fn report_preset_errors(
    mut failures: MessageReader<AssetLoadFailedEvent<ScenePreset>>,
    mut active: ResMut<ActivePreset>,
) {
    for failure in failures.read() {
        if failure.id == active.handle.id() {
            let message = format!("{}: {}", failure.path, load_error_in_words(&failure.error));
            error!("wirebead: scene file {message}; the running scene was kept");
            active.error = Some(message);
        }
    }
}

/// What went wrong loading a scene file, in one line: the loader's own
/// [`PresetError`] where there is one (not the asset server's wrapping of
/// it, which may carry a backtrace), else the first line of the error.
fn load_error_in_words(error: &AssetLoadError) -> String {
    let text = match error {
        AssetLoadError::AssetLoaderError(e) => match e.error().downcast_ref::<PresetError>() {
            Some(preset) => return preset.to_string(),
            None => e.error().to_string(),
        },
        other => other.to_string(),
    };
    text.lines().next().unwrap_or_default().to_owned()
}

/// Replaces the scene when the active preset loads or its file changes.
pub fn apply_loaded_preset(
    mut events: MessageReader<AssetEvent<ScenePreset>>,
    presets: Res<Assets<ScenePreset>>,
    mut active: ResMut<ActivePreset>,
    mut pending: ResMut<PendingParams>,
    existing: Query<Entity, (With<FromPreset>, Without<OnWire>)>,
    mut restarts: MessageWriter<Restart>,
    mut commands: Commands,
) {
    let id = active.handle.id();
    let changed = events.read().any(|event| match event {
        AssetEvent::LoadedWithDependencies { id: e } | AssetEvent::Modified { id: e } => *e == id,
        _ => false,
    });
    if !changed {
        return;
    }
    let Some(preset) = presets.get(id) else {
        return;
    };
    if let Err(err) = pending.set(preset.params.clone()) {
        active.error = Some(err.to_string());
        return;
    }
    // Wires (which take their beads along), free beads and links.
    for entity in &existing {
        commands.entity(entity).try_despawn();
    }
    preset.spawn(&mut commands);
    active.running = Some(preset.name.clone());
    active.error = None;
    info!("wirebead: running scene preset {:?}", preset.name);
    restarts.write(Restart);
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"(
        name: "two",
        params: (alpha: 50.0, integrator: Rattle),
        wires: [
            (shape: Circle((radius: 2.0)), position: (1.0, 0.5), angle_degrees: 30.0,
             beads: [(mass: 1.0, initial_position: (3.0, 0.5))]),
            (shape: Sine((amplitude: 0.3, wavelength: 2.0)), beads: [()]),
        ],
    )"#;

    #[test]
    fn a_preset_parses_with_defaults_filled_in() {
        let preset = ScenePreset::from_ron(GOOD).unwrap();
        assert_eq!(preset.params.alpha, 50.0);
        assert_eq!(preset.params.method, crate::Method::Rattle);
        assert_eq!(preset.params.beta, SimParams::default().beta);
        assert_eq!(preset.wires[1].beads[0].params(), BeadParams::default());
        assert_eq!(preset.wires[0].angle_degrees, 30.0);
    }

    #[test]
    fn malformed_files_say_where_and_what() {
        let err = ScenePreset::from_ron("(name: \"x\", wires: [ (shape: Circle((radius: 1.0)) ]")
            .unwrap_err();
        let text = err.to_string();
        assert!(
            text.starts_with("malformed scene file at line 1, column "),
            "{text}"
        );
        let err = ScenePreset::from_ron(&GOOD.replace("radius: 2.0", "radius: 0.0")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "wire 0: radius must be positive and finite, got 0"
        );
        let err = ScenePreset::from_ron(&GOOD.replace("mass: 1.0", "mass: -1.0")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "wire 0, bead 0: mass must be positive and finite, got -1"
        );
        let err =
            ScenePreset::from_ron(&GOOD.replace("alpha: 50.0", "timestep: -0.1")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "invalid params: timestep must be positive and finite, got -0.1"
        );
    }

    /// The format as the module doc gives it, with a spring and a pin.
    const CART: &str = r#"(
        name: "Pendulum on a cart",
        params: (integrator: Rattle),
        wires: [(shape: Line(()), beads: [(name: "cart", mass: 2.0, initial_position: (0.0, 0.0))])],
        beads: [(name: "bob", mass: 1.0, initial_position: (0.0, -1.0)), (initial_position: (1.0, -1.0))],
        constraints: [Rod((a: "cart", b: "bob", length: 1.0)), Pin((bead: "bead2", at: (1.0, -1.0)))],
        springs: [(a: "bob", b: "bead2", rest_length: 1.0, stiffness: 50.0, damping: 0.1)],
    )"#;

    #[test]
    fn an_unknown_field_is_refused_in_one_line_naming_it_and_its_item() {
        let refuse = |from: &str, to: &str| {
            let text = GOOD.replace(from, to);
            assert_ne!(text, GOOD, "{from} is not in the file");
            ScenePreset::from_ron(&text).unwrap_err().to_string()
        };
        let err = refuse(
            "angle_degrees: 30.0,",
            "angle_degrees: 30.0, restitutoin: 0.5,",
        );
        assert!(
            err.starts_with("unknown field `restitutoin` in wires[0] at line 5, column "),
            "{err}"
        );
        assert!(err.contains("known fields: shape, position,"), "{err}");
        assert!(!err.contains('\n'), "{err}");
        let err = refuse("mass: 1.0", "mas: 1.0");
        assert!(
            err.starts_with("unknown field `mas` in wires[0].beads[0] at line 6"),
            "{err}"
        );
        let err = refuse("alpha: 50.0", "alhpa: 50.0");
        assert!(
            err.starts_with("unknown field `alhpa` in params at line 3"),
            "{err}"
        );
        let err = refuse("name: \"two\",", "name: \"two\", wire: [],");
        assert!(
            err.starts_with("unknown field `wire` in the scene at line 2"),
            "{err}"
        );
        let err = refuse("radius: 2.0", "radius: 2.0, centre: (0.0, 0.0)");
        assert!(
            err.starts_with("unknown field `centre` in wires[0].shape"),
            "{err}"
        );
    }

    #[test]
    fn a_coupled_scene_names_its_beads_and_links() {
        let preset = ScenePreset::from_ron(CART).unwrap();
        assert_eq!(preset.bead_names(), ["cart", "bob", "bead2"]);
        assert_eq!(preset.all_beads().count(), 3);
        assert_eq!(preset.constraints.len(), 2);
        assert_eq!(preset.springs[0].damping, 0.1);
        // Today's files, with no names, free beads or links, still load.
        assert!(ScenePreset::from_ron(GOOD).unwrap().constraints.is_empty());
    }

    #[test]
    fn bad_links_are_refused_naming_the_item() {
        let refuse = |from: &str, to: &str| {
            ScenePreset::from_ron(&CART.replace(from, to))
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            refuse("b: \"bob\", length", "b: \"bobby\", length"),
            "constraint 0 (rod): no bead is named \"bobby\""
        );
        assert_eq!(
            refuse("b: \"bob\", length", "b: \"cart\", length"),
            "constraint 0 (rod): a rod must join two different beads"
        );
        assert_eq!(
            refuse("length: 1.0", "length: 0.0"),
            "constraint 0 (rod): rod length must be positive and finite, got 0"
        );
        assert_eq!(
            refuse("at: (1.0, -1.0)", "at: (NaN, -1.0)"),
            "constraint 1 (pin): pin point must be finite, got (NaN, -1)"
        );
        assert_eq!(
            refuse("(name: \"bob\"", "(name: \"cart\""),
            "two beads are named \"cart\""
        );
        assert_eq!(
            refuse("stiffness: 50.0", "stiffness: -50.0"),
            "spring 0: spring stiffness must be zero or more and finite, got -50"
        );
        assert_eq!(
            refuse(
                "mass: 1.0, initial_position: (0.0, -1.0)",
                "mass: 0.0, initial_position: (0.0, -1.0)"
            ),
            "bead \"bob\": mass must be positive and finite, got 0"
        );
    }
}
