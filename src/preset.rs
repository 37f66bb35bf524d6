//! Scene presets: RON files that set the wires, the beads and the
//! parameters, loaded as Bevy assets (`*.scene.ron`).
//!
//! ```ron
//! (
//!     name: "The assignment's circle",
//!     params: (alpha: 100.0, beta: 20.0),
//!     wires: [
//!         (
//!             shape: Circle((radius: 1.0)),
//!             beads: [(mass: 1.0, initial_position: (0.0, -1.0), initial_velocity: (3.0, 0.0))],
//!         ),
//!     ],
//! )
//! ```
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

use crate::dynamics::{Bead, BeadParams, OnWire, PendingParams, SimParams, Wire};
use crate::geometry::WireShape;
use crate::plugin::{Restart, WireBeadSystems};
use crate::validate::{ParamError, finite, finite_vector};

/// One wire of a preset and the beads on it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WirePreset {
    /// The shape, in the wire's frame.
    pub shape: WireShape,
    /// Where the wire's origin sits.
    #[serde(default)]
    pub position: DVec2,
    /// The wire's rotation, in degrees counter-clockwise.
    #[serde(default)]
    pub angle_degrees: f64,
    /// The beads on it.
    #[serde(default)]
    pub beads: Vec<BeadParams>,
}

/// A whole scene: parameters, wires and beads.
#[derive(Asset, TypePath, Clone, Debug, Serialize, Deserialize)]
pub struct ScenePreset {
    /// A human-readable name.
    pub name: String,
    /// The parameters (missing fields take their defaults).
    #[serde(default)]
    pub params: SimParams,
    /// The wires.
    pub wires: Vec<WirePreset>,
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
    /// The scene has no bead.
    #[error("the scene has no bead")]
    Empty,
}

impl ScenePreset {
    /// Parses and validates a preset.
    pub fn from_ron(text: &str) -> Result<Self, PresetError> {
        let preset: Self = ron::from_str(text)?;
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
                .map_err(|source| PresetError::Wire { index, source })?;
            for (bead, params) in wire.beads.iter().enumerate() {
                params.validate().map_err(|source| PresetError::Bead {
                    wire: index,
                    bead,
                    source,
                })?;
            }
        }
        if self.wires.iter().all(|w| w.beads.is_empty()) {
            return Err(PresetError::Empty);
        }
        Ok(())
    }

    /// Spawns the wires and beads (each tagged [`FromPreset`]); returns the
    /// beads. Call on a validated preset.
    pub fn spawn(&self, commands: &mut Commands) -> Vec<Entity> {
        let mut beads = Vec::new();
        for wire in &self.wires {
            let Ok(component) = Wire::new(wire.shape.clone()) else {
                continue;
            };
            let transform =
                Transform::from_xyz(wire.position.x as f32, wire.position.y as f32, 0.0)
                    .with_rotation(Quat::from_rotation_z(wire.angle_degrees.to_radians() as f32));
            let wire_entity = commands.spawn((component, transform, FromPreset)).id();
            for params in &wire.beads {
                if let Ok(bead) = Bead::new(*params) {
                    beads.push(commands.spawn((bead, OnWire(wire_entity), FromPreset)).id());
                }
            }
        }
        beads
    }
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
    existing: Query<Entity, (With<FromPreset>, With<Wire>)>,
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
    for wire in &existing {
        commands.entity(wire).despawn();
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
        assert_eq!(preset.wires[1].beads[0], BeadParams::default());
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
}
