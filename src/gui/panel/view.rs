//! What the panel reads from the world and what its controls write to it,
//! gathered as system parameters the sections share.

use bevy::ecs::system::SystemParam;
use bevy::math::DVec3;
use bevy::prelude::*;

use super::PresetCatalog;
use super::phase::{PhasePlot, PhasePlotFrame};
use super::plots::PlotsShown;
use super::plots::{PlotHistory, RecentStrikes};
use crate::controls::{ControlKeys, ExportRequests, Presentation, ReverseRequests, StepRequests};
use crate::ghost::{GhostDraft, GhostRequest, Ghosts};
use crate::gui::drag::SelectedBead;
use crate::gui::render::SceneStyle;
use crate::plugin::{Timeline, TimelineSeek};
use crate::preset::{ActivePreset, LastExport, LoadPreset};
use crate::{
    BeadDiagnostics, BeadParams, BeadPosition, ConstraintDiagnostics, Diverged, Islands,
    NextBeadParams, NextParams, NextWireShape, OnWire, Pin, PrescribedMotion, Restart, Rod,
    SimClock, SimParams, SpaceWire, Wire, WireContact, WirePlace,
};

/// The colour of what went wrong: a refused edit, a divergence, a failed
/// export.
pub(super) const ERROR_RED: bevy_egui::egui::Color32 =
    bevy_egui::egui::Color32::from_rgb(255, 90, 90);

/// The colour of what waits on the user: edits pending, a run that
/// changed from its recording.
pub(super) const PENDING_ORANGE: bevy_egui::egui::Color32 =
    bevy_egui::egui::Color32::from_rgb(255, 190, 60);

/// The read-only state the panel shows.
#[derive(SystemParam)]
pub struct PanelView<'w, 's> {
    pub(super) style: Res<'w, SceneStyle>,
    pub(super) keys: Res<'w, ControlKeys>,
    pub(super) catalog: Res<'w, PresetCatalog>,
    pub(super) active: Res<'w, ActivePreset>,
    pub(super) history: Res<'w, PlotHistory>,
    pub(super) params: Res<'w, SimParams>,
    pub(super) selected: Res<'w, SelectedBead>,
    pub(super) beads: Query<
        'w,
        's,
        (
            Entity,
            &'static BeadParams,
            &'static BeadDiagnostics,
            Option<&'static OnWire>,
            Option<&'static NextBeadParams>,
            Option<&'static Diverged>,
        ),
    >,
    pub(super) wires: Query<
        'w,
        's,
        (
            &'static Wire,
            &'static Transform,
            Option<&'static NextWireShape>,
            Option<&'static PrescribedMotion>,
            Option<&'static WirePlace>,
        ),
    >,
    pub(super) space_beads: Query<
        'w,
        's,
        (
            Entity,
            &'static BeadParams<DVec3>,
            Option<&'static BeadDiagnostics<DVec3>>,
            Option<&'static OnWire>,
            Option<&'static NextBeadParams<DVec3>>,
            Option<&'static Diverged>,
        ),
    >,
    pub(super) space_wires:
        Query<'w, 's, (&'static SpaceWire, Option<&'static PrescribedMotion<DVec3>>)>,
    pub(super) contacts: Query<'w, 's, &'static WireContact>,
    pub(super) rods: Query<'w, 's, (&'static Rod, &'static ConstraintDiagnostics)>,
    pub(super) pins: Query<'w, 's, (&'static Pin, &'static ConstraintDiagnostics)>,
    pub(super) names: Query<'w, 's, &'static Name>,
    pub(super) islands: Res<'w, Islands>,
    pub(super) pending_beads:
        Query<'w, 's, (), Or<(With<NextBeadParams>, With<NextBeadParams<DVec3>>)>>,
    pub(super) pending_wires: Query<'w, 's, (), With<NextWireShape>>,
    pub(super) clock: Res<'w, SimClock>,
    pub(super) positions: Query<'w, 's, &'static BeadPosition>,
    pub(super) space_positions: Query<'w, 's, &'static BeadPosition<DVec3>>,
    pub(super) strikes: Res<'w, RecentStrikes>,
    pub(super) last_export: Res<'w, LastExport>,
    pub(super) ghosts: Res<'w, Ghosts>,
    pub(super) presentation: Res<'w, Presentation>,
    pub(super) windows: Query<'w, 's, &'static Window>,
}

/// What the panel's controls ask of the world this frame.
#[derive(SystemParam)]
pub struct PanelActions<'w, 's> {
    pub(super) pending: ResMut<'w, NextParams>,
    pub(super) time: ResMut<'w, Time<Virtual>>,
    pub(super) steps: ResMut<'w, StepRequests>,
    pub(super) reversals: ResMut<'w, ReverseRequests>,
    pub(super) restarts: MessageWriter<'w, Restart>,
    pub(super) loads: MessageWriter<'w, LoadPreset>,
    pub(super) phase: ResMut<'w, PhasePlot>,
    pub(super) phase_frame: ResMut<'w, PhasePlotFrame>,
    pub(super) plots_shown: ResMut<'w, PlotsShown>,
    pub(super) timeline: ResMut<'w, Timeline>,
    pub(super) exports: ResMut<'w, ExportRequests>,
    pub(super) ghost_draft: ResMut<'w, GhostDraft>,
    pub(super) ghost_requests: MessageWriter<'w, GhostRequest>,
    pub(super) seeks: MessageWriter<'w, TimelineSeek>,
    pub(super) commands: Commands<'w, 's>,
}

impl PanelView<'_, '_> {
    /// A bead's name, or its entity where it has none.
    pub(super) fn name(&self, bead: Entity) -> String {
        self.names
            .get(bead)
            .map_or_else(|_| bead.to_string(), |n| n.as_str().to_owned())
    }
}
