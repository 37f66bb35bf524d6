//! The plots as a PNG: the part of the window the panel's plots show in,
//! cut from a screenshot of the next frame.

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};

use super::plots::PlotsShown;
use crate::controls::ExportRequests;
use crate::preset::{ActivePreset, ExportDir, LastExport, scene_stem};

/// Takes the plots' PNG where [`ExportRequests::plots`] asks: a screenshot,
/// cut to the plots shown, written to `<export dir>/<scene>-plots.png`.
pub(super) fn save_plots(
    mut requests: ResMut<ExportRequests>,
    shown: Res<PlotsShown>,
    dir: Res<ExportDir>,
    active: Res<ActivePreset>,
    mut last: ResMut<LastExport>,
    mut commands: Commands,
) {
    if std::mem::take(&mut requests.plots) == 0 {
        return;
    }
    let Some(rect) = shown.0 else {
        last.0 = Some(Err(
            "no plot is on screen (open the Plots or Phase plot section, or scroll to it); nothing was written".to_owned(),
        ));
        return;
    };
    let path = dir
        .0
        .join(format!("{}-plots.png", scene_stem(&active.path)));
    commands
        .spawn(Screenshot::primary_window())
        .observe(cut_and_save(path, rect));
}

/// Cuts `rect` (physical pixels) out of the captured frame and writes it
/// to `path` as PNG, saying what it wrote in [`LastExport`].
fn cut_and_save(
    path: PathBuf,
    rect: [f32; 4],
) -> impl FnMut(On<ScreenshotCaptured>, ResMut<LastExport>) {
    move |captured, mut last| {
        let outcome = (|| {
            let image = captured
                .image
                .clone()
                .try_into_dynamic()
                .map_err(|e| format!("the screenshot could not be read: {e}"))?;
            let (width, height) = (image.width(), image.height());
            let [left, top, right, bottom] = rect.map(|v| v.round().max(0.0) as u32);
            let (left, top) = (left.min(width), top.min(height));
            let (right, bottom) = (right.min(width), bottom.min(height));
            if right <= left || bottom <= top {
                return Err("the plots are outside the window; nothing was written".to_owned());
            }
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent)
                    .map_err(|e| format!("{}: {e}; nothing was written", parent.display()))?;
            }
            image
                .crop_imm(left, top, right - left, bottom - top)
                .to_rgb8()
                .save(&path)
                .map_err(|e| format!("{}: {e}; nothing was written", path.display()))?;
            Ok(format!(
                "wrote {} ({} × {} px)",
                path.display(),
                right - left,
                bottom - top
            ))
        })();
        match &outcome {
            Ok(message) => info!("wirebead: {message}"),
            Err(message) => warn!("wirebead: plots: {message}"),
        }
        last.0 = Some(outcome);
    }
}
