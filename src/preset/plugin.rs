//! Scene files as Bevy assets: the loader, the preset in use, and the
//! plugin whose systems load, report and apply it.

use bevy::asset::io::Reader;
use bevy::asset::{AssetLoadError, AssetLoadFailedEvent, AssetLoader, LoadContext};
use bevy::prelude::*;

use super::SceneFile;
use super::error::PresetError;
use super::spawn::FromPreset;
use crate::dynamics::{NextParams, OnWire};
use crate::plugin::{Restart, WireBeadSystems};

/// Loads `*.scene.ron` files of either dimension as [`SceneFile`]s,
/// validating them.
#[derive(Default, TypePath)]
pub struct ScenePresetLoader;

impl AssetLoader for ScenePresetLoader {
    type Asset = SceneFile;
    type Settings = ();
    type Error = PresetError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        _load_context: &mut LoadContext<'_>,
    ) -> Result<SceneFile, PresetError> {
        let mut bytes = Vec::new();
        reader.read_to_end(&mut bytes).await?;
        let text = String::from_utf8_lossy(&bytes);
        SceneFile::from_ron(&text)
    }

    fn extensions(&self) -> &[&str] {
        &["scene.ron"]
    }
}

/// The preset in use, and the last error loading it.
#[derive(Resource, Clone, Debug, Default)]
pub struct ActivePreset {
    /// The preset's handle; set it (or send [`LoadPreset`]) to switch scenes.
    pub handle: Handle<SceneFile>,
    /// The preset's asset path.
    pub path: String,
    /// The name of the preset now running.
    pub running: Option<String>,
    /// Whether the preset now running is in space.
    pub in_space: bool,
    /// Why the last load failed, if it did; cleared by a good load.
    pub error: Option<String>,
    /// The running scene's beads, in the file's order.
    pub beads: Vec<Entity>,
    /// The running scene's rigid bodies that move (dynamic and kinematic),
    /// in the file's order.
    pub bodies: Vec<Entity>,
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
        app.init_asset::<SceneFile>()
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
    mut failures: MessageReader<AssetLoadFailedEvent<SceneFile>>,
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
    mut events: MessageReader<AssetEvent<SceneFile>>,
    presets: Res<Assets<SceneFile>>,
    mut active: ResMut<ActivePreset>,
    mut pending: ResMut<NextParams>,
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
    if let Err(err) = pending.set(preset.params().clone()) {
        active.error = Some(err.to_string());
        return;
    }
    // Wires (which take their beads along), free beads and links.
    for entity in &existing {
        commands.entity(entity).try_despawn();
    }
    (active.beads, active.bodies) = preset.spawn_recorded(&mut commands);
    active.running = Some(preset.name().to_owned());
    active.in_space = preset.in_space();
    active.error = None;
    info!("wirebead: running scene preset {:?}", preset.name());
    restarts.write(Restart);
}
