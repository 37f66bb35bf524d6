//! What automation writes: a [`FrameReport`] of where everything is on
//! screen (beads, wires, plots, ghosts, the timeline), as RON.

use std::path::Path;

use serde::{Deserialize, Serialize};

/// Where one bead is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BeadReport {
    /// Simulated position.
    pub world: [f64; 2],
    /// Window position in physical pixels, from the top left.
    pub pixel: [f32; 2],
    /// The drawn radius in physical pixels.
    pub radius_px: f32,
    /// Why it diverged, if it did.
    pub diverged: Option<String>,
    /// Whether it is in flight off a one-sided wire.
    #[serde(default)]
    pub in_flight: bool,
    /// Its mass (kg), as the run uses it.
    #[serde(default)]
    pub mass: f64,
}

/// Where one bead in space is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpaceBeadReport {
    /// Simulated position.
    pub world: [f64; 3],
    /// Window position in physical pixels, from the top left, through the
    /// 3D view's camera.
    pub pixel: [f32; 2],
    /// The drawn radius in physical pixels.
    pub radius_px: f32,
    /// Why it diverged, if it did.
    pub diverged: Option<String>,
}

/// Where one rigid body is (features `avian2d`, `avian3d`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodyReport {
    /// Its name, if it has one.
    pub name: String,
    /// Its origin (`z` zero in the plane).
    pub world: [f64; 3],
    /// Its origin's window position in physical pixels, from the top
    /// left, through the camera of the view shown.
    pub pixel: [f32; 2],
}

/// Where one wire is drawn.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WireReport {
    /// Its shape's name.
    pub shape: String,
    /// Points on the simulated wire, in physical pixels (only those inside
    /// the window).
    pub pixels: Vec<[f32; 2]>,
    /// On a one-sided wire, the middle of the hatch stroke each point would
    /// have on the wire's closed side, in physical pixels.
    #[serde(default)]
    pub closed_side: Vec<[f32; 2]>,
    /// The same points mirrored to the open side, where no stroke is drawn.
    #[serde(default)]
    pub open_side: Vec<[f32; 2]>,
}

/// What a mouse drag did, in the plane (`z = 0`) or in space, to a bead
/// or to the point of a body it took.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DragReport {
    /// The bead's position (or the point taken) when the drag began.
    pub bead_start: [f64; 3],
    /// The last drag target (where the cursor was released).
    pub target: [f64; 3],
    /// The distance from the bead's start to that target.
    pub start_distance: f64,
    /// The bead's (or point's) closest approach to that target while
    /// dragged.
    pub closest_distance: f64,
}

/// A report of one frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FrameReport {
    /// The frame number.
    pub frame: u32,
    /// The window size in physical pixels.
    pub window: [u32; 2],
    /// The beads.
    pub beads: Vec<BeadReport>,
    /// The wires.
    pub wires: Vec<WireReport>,
    /// Each rod's two ends, in physical pixels.
    #[serde(default)]
    pub rods: Vec<[[f32; 2]; 2]>,
    /// Each pin's point, in physical pixels.
    #[serde(default)]
    pub pins: Vec<[f32; 2]>,
    /// The beads in space.
    #[serde(default)]
    pub space_beads: Vec<SpaceBeadReport>,
    /// The rigid bodies drawn.
    #[serde(default)]
    pub bodies: Vec<BodyReport>,
    /// Each curve in space: its drawn points inside the window, in
    /// physical pixels.
    #[serde(default)]
    pub space_curves: Vec<Vec<[f32; 2]>>,
    /// The drag seen so far, if any.
    pub drag: Option<DragReport>,
    /// The preset running.
    pub preset: Option<String>,
    /// The last scene-file error.
    pub preset_error: Option<String>,
    /// Mean wall-clock frame time in milliseconds after the first 30 frames.
    pub mean_frame_ms: f64,
    /// Where the run is on its timeline.
    #[serde(default)]
    pub timeline: Option<TimelineReport>,
    /// Each ghost bead drawn.
    #[serde(default)]
    pub ghost_beads: Vec<GhostBeadReport>,
    /// Where the phase plot is drawn, if it is.
    #[serde(default)]
    pub phase_plot: Option<PlotReport>,
    /// The part of the window the plots and the phase plot show in, in
    /// physical pixels (left, top, right, bottom), if they show.
    #[serde(default)]
    pub plots_shown: Option<[f32; 4]>,
    /// The panel's controls the keyboard went to, oldest first
    /// ([`FocusTrail`](crate::gui::panel::FocusTrail)).
    #[serde(default)]
    pub focus_trail: Vec<String>,
}

/// Where a plot is drawn and what it spans.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlotReport {
    /// Left, top, right and bottom, in physical pixels.
    pub rect_px: [f32; 4],
    /// The part of it on screen (the rest scrolled out of the panel's
    /// view), the same way.
    pub visible_px: [f32; 4],
    /// The values at the left and right edges, then at the bottom and the
    /// top.
    pub bounds: [f64; 4],
}

/// Where one ghost bead is drawn.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GhostBeadReport {
    /// Its simulated position (`z` zero in the plane).
    pub world: [f64; 3],
    /// Window position in physical pixels, from the top left.
    pub pixel: [f32; 2],
    /// The drawn radius in physical pixels.
    pub radius_px: f32,
    /// Its ghost's colour, sRGB and alpha.
    pub colour: [f32; 4],
}

/// Where the run is on its [`Timeline`](crate::plugin::Timeline), and every bead's state now and as
/// recorded at that step, bit for bit.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TimelineReport {
    /// The step the run is at ([`SimClock::steps`](crate::SimClock::steps)).
    pub step: u64,
    /// The first and last steps recorded.
    pub recorded: [u64; 2],
    /// Whether the run is at a recorded step before the newest.
    pub stepped_back: bool,
    /// Steps run again from a step back that came out as recorded.
    pub matched: u64,
    /// The step a run from a step back first differed at, if one did.
    pub departed: Option<u64>,
    /// Each bead's position and velocity now, as the bits of each number
    /// in hex.
    pub now: Vec<String>,
    /// The same, as recorded at `step`.
    pub at_step: Vec<String>,
}

/// Writes `report` to `path` as pretty RON; the error in words.
pub(super) fn write_report(path: &Path, report: &FrameReport) -> Result<(), String> {
    let text = ron::ser::to_string_pretty(report, ron::ser::PrettyConfig::default())
        .map_err(|e| e.to_string())?;
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}
