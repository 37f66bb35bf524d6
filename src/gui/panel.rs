//! The egui panel: every parameter of the assignment's panel plus gravity, wire
//! shape and size, integrator and stabilization; a marker while edits are
//! pending; live plots of `C`, energy and λ; divergence and scene-file
//! errors in plain words.
//!
//! Edits go through the plugin's validating setters: an invalid value is
//! refused with the plugin's error message and never reaches the
//! simulation.

use std::collections::VecDeque;

use bevy::ecs::system::SystemParam;
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy_egui::{EguiContexts, EguiPrimaryContextPass, egui};
use egui_plot::{Line, Plot, PlotPoints};

use crate::controls::{ControlKeys, StepRequests};
use crate::geometry::Cycloid;
use crate::gui::drag::SelectedBead;
use crate::gui::render::SceneStyle;
use crate::preset::{ActivePreset, LoadPreset};
use crate::{
    Bead, BeadDiagnostics, BeadParams, ConstraintDiagnostics, Diverged, Integrator, Islands,
    OnWire, ParamError, PendingBead, PendingParams, PendingWire, Pin, Restart, Rod, SimClock,
    SimParams, Stabilization, Wire, WireBeadSystems, WireKind, WireShape, pose_of,
};
use crate::{PrescribedMotion, Side, Surface, WireContact, WireMotion};

/// The presets the panel offers: `(label, asset path)`.
#[derive(Resource, Clone, Debug)]
pub struct PresetCatalog(pub Vec<(String, String)>);

impl Default for PresetCatalog {
    fn default() -> Self {
        Self(
            [
                (
                    "The assignment's circle",
                    "scenes/assignment_circle.scene.ron",
                ),
                ("Tilted ellipse", "scenes/ellipse.scene.ron"),
                ("Sine track", "scenes/sine_track.scene.ron"),
                ("Many beads", "scenes/multi_bead.scene.ron"),
                ("Bead at rest", "scenes/resting.scene.ron"),
                ("Pendulum on a cart", "scenes/pendulum_on_cart.scene.ron"),
                ("Double pendulum", "scenes/double_pendulum.scene.ron"),
                ("Rope on a rail", "scenes/rope.scene.ron"),
                ("Ring of beads on a circle", "scenes/ring.scene.ron"),
                (
                    "Two beads and a spring on a track",
                    "scenes/spring_pair.scene.ron",
                ),
                ("Kapitza pendulum", "scenes/kapitza.scene.ron"),
                ("Bead on a spinning rod", "scenes/spinning_rod.scene.ron"),
                ("Tautochrone race", "scenes/tautochrone.scene.ron"),
                ("Roller coaster", "scenes/roller_coaster.scene.ron"),
            ]
            .into_iter()
            .map(|(a, b)| (a.to_owned(), b.to_owned()))
            .collect(),
        )
    }
}

/// One plotted sample of the selected bead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlotSample {
    /// Simulated time.
    pub t: f64,
    /// Drift `C`.
    pub c: f64,
    /// Energy.
    pub energy: f64,
    /// λ.
    pub lambda: f64,
}

/// The last seconds of the selected bead's diagnostics.
#[derive(Resource, Clone, Debug)]
pub struct PlotHistory {
    /// Seconds kept.
    pub seconds: f64,
    /// The samples, oldest first.
    pub samples: VecDeque<PlotSample>,
    bead: Option<Entity>,
}

impl Default for PlotHistory {
    fn default() -> Self {
        Self {
            seconds: 10.0,
            samples: VecDeque::new(),
            bead: None,
        }
    }
}

/// The egui panel and plots.
#[derive(Default)]
pub struct PanelPlugin;

impl Plugin for PanelPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<PresetCatalog>()
            .init_resource::<PlotHistory>()
            .init_resource::<SelectedBead>()
            .add_systems(
                FixedUpdate,
                record_history.after(WireBeadSystems::Writeback),
            )
            .add_systems(Update, keep_selection)
            .add_systems(EguiPrimaryContextPass, panel);
    }
}

/// Selects the first bead when none (or a despawned one) is selected.
pub fn keep_selection(mut selected: ResMut<SelectedBead>, beads: Query<Entity, With<Bead>>) {
    if selected.0.is_none_or(|e| !beads.contains(e)) {
        selected.0 = beads.iter().min();
    }
}

/// Appends the selected bead's diagnostics to the plot history; for a
/// bead joined to others, the energy is its island's (a rod does work on
/// each of its beads, not on the two together).
pub fn record_history(
    selected: Res<SelectedBead>,
    clock: Res<SimClock>,
    beads: Query<&BeadDiagnostics>,
    islands: Res<Islands>,
    mut history: ResMut<PlotHistory>,
) {
    let Some(entity) = selected.0 else { return };
    let Ok(d) = beads.get(entity) else { return };
    let t = clock.time;
    if history.bead != Some(entity) || history.samples.back().is_some_and(|s| s.t > t) {
        history.samples.clear();
        history.bead = Some(entity);
    }
    let energy = islands
        .of(entity)
        .filter(|island| island.rows > 0)
        .map_or(d.energy(), |island| island.energy);
    history.samples.push_back(PlotSample {
        t,
        c: d.c,
        energy,
        lambda: d.lambda,
    });
    let horizon = t - history.seconds;
    while history.samples.front().is_some_and(|s| s.t < horizon) {
        history.samples.pop_front();
    }
}

fn number(ui: &mut egui::Ui, label: &str, value: &mut f64, speed: f64) {
    ui.label(label);
    ui.add(egui::DragValue::new(value).speed(speed).max_decimals(6));
    ui.end_row();
}

/// A menu of `all`, each shown by its `name`.
fn choice<T: Copy + PartialEq>(
    ui: &mut egui::Ui,
    id: &str,
    value: &mut T,
    all: &[T],
    name: fn(T) -> &'static str,
) {
    egui::ComboBox::from_id_salt(id)
        .selected_text(name(*value))
        .show_ui(ui, |ui| {
            for &c in all {
                ui.selectable_value(value, c, name(c));
            }
        });
}

fn vector(ui: &mut egui::Ui, label: &str, value: &mut DVec2, speed: f64) {
    ui.label(label);
    ui.horizontal(|ui| {
        ui.add(egui::DragValue::new(&mut value.x).speed(speed).prefix("x "));
        ui.add(egui::DragValue::new(&mut value.y).speed(speed).prefix("y "));
    });
    ui.end_row();
}

/// A plot of the last seconds with labelled axes: time in seconds, the
/// value (its unit is in the heading above) with tick labels in scientific
/// notation, so that a range of 1e-16 reads as rounding noise and not as a
/// swing.
fn plot(
    ui: &mut egui::Ui,
    id: &str,
    name: &str,
    points: impl Iterator<Item = [f64; 2]>,
    colour: egui::Color32,
) {
    Plot::new(id)
        .height(90.0)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .x_axis_label("t (s)")
        .y_axis_min_width(48.0)
        .y_axis_formatter(|mark, _| format!("{:.1e}", mark.value))
        .show(ui, |plot_ui| {
            plot_ui.line(Line::new(name, points.collect::<PlotPoints>()).color(colour));
        });
}

/// The read-only state the panel shows.
#[derive(SystemParam)]
pub struct PanelView<'w, 's> {
    style: Res<'w, SceneStyle>,
    keys: Res<'w, ControlKeys>,
    catalog: Res<'w, PresetCatalog>,
    active: Res<'w, ActivePreset>,
    history: Res<'w, PlotHistory>,
    params: Res<'w, SimParams>,
    selected: Res<'w, SelectedBead>,
    beads: Query<
        'w,
        's,
        (
            Entity,
            &'static Bead,
            &'static BeadDiagnostics,
            Option<&'static OnWire>,
            Option<&'static PendingBead>,
            Option<&'static Diverged>,
        ),
    >,
    wires: Query<
        'w,
        's,
        (
            &'static Wire,
            &'static Transform,
            Option<&'static PendingWire>,
            Option<&'static PrescribedMotion>,
        ),
    >,
    contacts: Query<'w, 's, &'static WireContact>,
    rods: Query<'w, 's, (&'static Rod, &'static ConstraintDiagnostics)>,
    pins: Query<'w, 's, (&'static Pin, &'static ConstraintDiagnostics)>,
    names: Query<'w, 's, &'static Name>,
    islands: Res<'w, Islands>,
    pending_beads: Query<'w, 's, (), With<PendingBead>>,
    pending_wires: Query<'w, 's, (), With<PendingWire>>,
    clock: Res<'w, SimClock>,
}

/// What the panel's controls ask of the world this frame.
#[derive(SystemParam)]
pub struct PanelActions<'w, 's> {
    pending: ResMut<'w, PendingParams>,
    time: ResMut<'w, Time<Virtual>>,
    steps: ResMut<'w, StepRequests>,
    restarts: MessageWriter<'w, Restart>,
    loads: MessageWriter<'w, LoadPreset>,
    commands: Commands<'w, 's>,
}

/// The result of an edit: `None` where nothing was edited.
type Edit = Option<Result<(), ParamError>>;

const ERROR_RED: egui::Color32 = egui::Color32::from_rgb(255, 90, 90);
const PENDING_ORANGE: egui::Color32 = egui::Color32::from_rgb(255, 190, 60);

/// The panel: the scene and run state, the selected bead and its wire, the
/// solver's parameters and the plots, in a window that scrolls when it is
/// taller than the screen.
pub fn panel(
    mut contexts: EguiContexts,
    view: PanelView,
    mut actions: PanelActions,
    mut refused: Local<Option<String>>,
) -> Result {
    let ctx = contexts.ctx_mut()?;
    help_line(ctx, &view.keys);
    // The window scrolls its content within the screen's height, less the
    // title bar and the margins, so nothing is cut off at the bottom.
    let height = (ctx.content_rect().height() - 80.0).max(200.0);
    let mut outcome: Edit = None;
    egui::Window::new("wirebead")
        .anchor(egui::Align2::RIGHT_TOP, [-6.0, 6.0])
        .fixed_size([view.style.panel_width - 30.0, height])
        .resizable(false)
        .collapsible(true)
        .vscroll(true)
        .show(ctx, |ui| {
            scene_section(ui, &view, &mut actions, refused.as_deref());
            let bead = bead_section(ui, &view, &mut actions.commands);
            constraints_section(ui, &view);
            let solver = solver_section(ui, &mut actions.pending);
            outcome = solver.or(bead);
            plots_section(ui, &view.history);
        });
    match outcome {
        Some(Ok(())) => *refused = None,
        Some(Err(error)) => {
            warn!("wirebead: edit refused: {error}; the previous value was kept");
            *refused = Some(error.to_string());
        }
        None => {}
    }
    Ok(())
}

/// The keys, at the bottom left of the window.
fn help_line(ctx: &egui::Context, keys: &ControlKeys) {
    egui::Area::new(egui::Id::new("wirebead-help"))
        .anchor(egui::Align2::LEFT_BOTTOM, [8.0, -8.0])
        .show(ctx, |ui| {
            ui.colored_label(egui::Color32::LIGHT_GRAY, keys.help());
        });
}

/// The scene menu, its file error, the run buttons, and what is pending,
/// diverged or refused.
fn scene_section(
    ui: &mut egui::Ui,
    view: &PanelView,
    actions: &mut PanelActions,
    refused: Option<&str>,
) {
    ui.horizontal(|ui| {
        ui.label("Scene");
        let current = view.active.running.clone().unwrap_or_else(|| "—".into());
        egui::ComboBox::from_id_salt("preset")
            .selected_text(current)
            .show_ui(ui, |ui| {
                for (label, path) in &view.catalog.0 {
                    if ui
                        .selectable_label(view.active.path == *path, label)
                        .clicked()
                    {
                        actions.loads.write(LoadPreset(path.clone()));
                    }
                }
            });
    });
    if let Some(error) = &view.active.error {
        ui.colored_label(
            ERROR_RED,
            format!("Scene file {error}; the running scene was kept."),
        );
    }
    ui.horizontal(|ui| {
        if ui
            .button(format!("Restart ({:?})", view.keys.restart))
            .clicked()
        {
            actions.restarts.write(Restart);
        }
        let time = &mut actions.time;
        let pause = if time.is_paused() { "Resume" } else { "Pause" };
        if ui.button(pause).clicked() {
            if time.is_paused() {
                time.unpause();
            } else {
                time.pause();
            }
        }
        if ui
            .add_enabled(time.is_paused(), egui::Button::new("Step"))
            .clicked()
        {
            actions.steps.0 += 1;
        }
    });
    let edits_pending = actions.pending.get() != &*view.params
        || !view.pending_beads.is_empty()
        || !view.pending_wires.is_empty();
    if edits_pending {
        ui.colored_label(PENDING_ORANGE, "● Edits pending: press Space to apply");
    }
    for (entity, _, _, _, _, diverged) in &view.beads {
        if let Some(d) = diverged {
            ui.colored_label(
                ERROR_RED,
                format!(
                    "Bead {entity} diverged at t = {:.2} s: {}. Press Space to restart.",
                    d.time, d.reason
                ),
            );
        }
    }
    if let Some(message) = refused {
        ui.colored_label(ERROR_RED, format!("Refused: {message}"));
    }
}

/// The selected bead's parameters, its wire's shape, and its diagnostics.
fn bead_section(ui: &mut egui::Ui, view: &PanelView, commands: &mut Commands) -> Edit {
    let (entity, bead, diagnostics, on_wire, pending_bead, _) =
        view.selected.0.and_then(|e| view.beads.get(e).ok())?;
    ui.separator();
    ui.strong(format!("Bead {}", view.name(entity)));
    let mut draft: BeadParams = pending_bead.map_or(*bead.params(), |p| *p.get());
    let before = draft;
    egui::Grid::new("bead").num_columns(2).show(ui, |ui| {
        number(ui, "mass", &mut draft.mass, 0.01);
        vector(ui, "initial position", &mut draft.initial_position, 0.01);
        vector(ui, "initial velocity", &mut draft.initial_velocity, 0.01);
    });
    let mut outcome = None;
    if let Some(on_wire) = on_wire
        && let Ok((wire, transform, pending_wire, motion)) = view.wires.get(on_wire.0)
    {
        let shape = pending_wire.map_or_else(|| wire.shape().clone(), |p| p.shape().clone());
        if let Some(edited) = wire_editor(ui, &shape) {
            outcome = Some(PendingWire::new(edited.clone()).map(|edit| {
                commands.entity(on_wire.0).insert(edit);
                // Start the bead at the new wire's lowest point.
                let pose = pose_of(transform).unwrap_or_default();
                draft.initial_position = pose.to_world(edited.bottom());
            }));
        }
        let contact = view.contacts.get(entity).ok();
        track_lines(
            ui,
            wire.surface(),
            motion.map(PrescribedMotion::motion),
            contact,
        );
    }
    if draft != before {
        outcome = Some(PendingBead::new(draft).map(|edit| {
            commands.entity(entity).insert(edit);
        }));
    }

    ui.separator();
    let clock = &view.clock;
    egui::Grid::new("values").num_columns(4).show(ui, |ui| {
        ui.label("C");
        ui.monospace(format!("{:+.3e}", diagnostics.c));
        ui.label("Ċ");
        ui.monospace(format!("{:+.3e}", diagnostics.c_dot));
        ui.end_row();
        ui.label("λ");
        ui.monospace(format!("{:+.3e}", diagnostics.lambda));
        ui.label("E");
        ui.monospace(format!("{:+.4}", diagnostics.energy()));
        ui.end_row();
        ui.label("t");
        ui.monospace(format!("{:.2} s", clock.time));
        ui.label("steps");
        ui.monospace(format!("{}", clock.steps));
        ui.end_row();
        if let Some(island) = view.islands.of(entity).filter(|i| i.rows > 0) {
            ui.label("island E");
            ui.monospace(format!("{:+.4}", island.energy));
            ui.label("beads");
            ui.monospace(format!("{}", island.beads.len()));
            ui.end_row();
        }
    });
    outcome
}

/// Every rod and pin with its drift `C` and multiplier λ (a rod under
/// tension pulls: λ < 0).
fn constraints_section(ui: &mut egui::Ui, view: &PanelView) {
    if view.rods.is_empty() && view.pins.is_empty() {
        return;
    }
    ui.separator();
    egui::CollapsingHeader::new("Constraints")
        .default_open(true)
        .show(ui, |ui| {
            egui::Grid::new("constraints")
                .num_columns(3)
                .striped(true)
                .show(ui, |ui| {
                    ui.strong("");
                    ui.strong("C");
                    ui.strong("λ");
                    ui.end_row();
                    let mut row = |label: String, d: &ConstraintDiagnostics| {
                        ui.label(label);
                        ui.monospace(format!("{:+.2e}", d.c));
                        ui.monospace(format!("{:+.3e}", d.lambda));
                        ui.end_row();
                    };
                    for (rod, d) in &view.rods {
                        let [a, b] = rod.beads().map(|e| view.name(e));
                        row(format!("rod {a}–{b}"), d);
                    }
                    for (pin, d) in &view.pins {
                        row(format!("pin {}", view.name(pin.bead())), d);
                    }
                });
        });
}

impl PanelView<'_, '_> {
    /// A bead's name, or its entity where it has none.
    fn name(&self, bead: Entity) -> String {
        self.names
            .get(bead)
            .map_or_else(|_| bead.to_string(), |n| n.as_str().to_owned())
    }
}

/// What the wire does besides holding the bead, in words: its motion, its
/// side, restitution, friction and damping, and whether the bead is on it.
fn track_lines(
    ui: &mut egui::Ui,
    surface: &Surface,
    motion: Option<WireMotion>,
    contact: Option<&WireContact>,
) {
    let moving = match motion {
        Some(WireMotion::Oscillate(o)) => Some(format!(
            "oscillates by ({:.2}, {:.2}) at {:.2} Hz",
            o.amplitude.x, o.amplitude.y, o.frequency
        )),
        Some(WireMotion::Spin(s)) => Some(format!("spins at {:.2} rad/s", s.angular_velocity)),
        _ => None,
    };
    let mut lines: Vec<String> = moving.into_iter().collect();
    if surface.side != Side::Both {
        lines.push(format!(
            "pushes one way ({} side), restitution {:.2}",
            surface.side.name(),
            surface.restitution
        ));
    }
    if surface.friction.is_some() {
        lines.push(format!(
            "friction μs {:.2}, μk {:.2}",
            surface.friction.static_coefficient, surface.friction.kinetic_coefficient
        ));
    }
    if surface.damping > 0.0 {
        lines.push(format!("damping {:.2} N·s/m", surface.damping));
    }
    if let Some(contact) = contact
        && (surface.side != Side::Both || !contact.is_on())
    {
        lines.push(
            if contact.is_on() {
                "on its wire"
            } else {
                "in flight"
            }
            .to_owned(),
        );
    }
    for line in lines {
        ui.label(line);
    }
}

/// The wire's kind (from [`WireKind::ALL`]) and dimensions; the edited
/// shape if anything changed.
fn wire_editor(ui: &mut egui::Ui, shape: &WireShape) -> Option<WireShape> {
    let mut edited = shape.clone();
    ui.strong("Wire");
    egui::Grid::new("wire").num_columns(2).show(ui, |ui| {
        ui.label("shape");
        let mut kind = edited.kind();
        egui::ComboBox::from_id_salt("shape")
            .selected_text(edited.name())
            .show_ui(ui, |ui| {
                for k in WireKind::ALL {
                    ui.selectable_value(&mut kind, Some(k), k.name());
                }
            });
        ui.end_row();
        if let Some(kind) = kind.filter(|k| Some(*k) != edited.kind()) {
            edited = kind.shape(edited.curve().scale());
        }
        match &mut edited {
            WireShape::Circle(c) => number(ui, "radius", &mut c.radius, 0.01),
            WireShape::Ellipse(e) => {
                number(ui, "semi-axis a", &mut e.a, 0.01);
                number(ui, "semi-axis b", &mut e.b, 0.01);
            }
            WireShape::Parabola(p) => number(ui, "focal length", &mut p.focal_length, 0.01),
            WireShape::Sine(s) => {
                number(ui, "amplitude", &mut s.amplitude, 0.01);
                number(ui, "wavelength", &mut s.wavelength, 0.01);
            }
            WireShape::Cycloid(c) => {
                let mut radius = c.radius();
                number(ui, "radius", &mut radius, 0.01);
                if radius != c.radius() {
                    *c = Cycloid::new(radius);
                }
            }
            WireShape::Line(_) | WireShape::Spline(_) | WireShape::Custom(_) => {}
        }
    });
    (format!("{edited:?}") != format!("{shape:?}")).then_some(edited)
}

/// The parameters every bead shares.
fn solver_section(ui: &mut egui::Ui, pending: &mut PendingParams) -> Edit {
    ui.separator();
    ui.strong("Solver");
    let mut draft = pending.get().clone();
    egui::Grid::new("solver").num_columns(2).show(ui, |ui| {
        number(ui, "timestep (s)", &mut draft.timestep, 0.0005);
        number(ui, "spring constant α", &mut draft.alpha, 1.0);
        number(ui, "damping constant β", &mut draft.beta, 0.1);
        number(ui, "drag scale k", &mut draft.drag_stiffness, 0.1);
        vector(ui, "gravity", &mut draft.gravity, 0.01);
        ui.label("integrator");
        let mut integrator = draft.method.integrator();
        choice(
            ui,
            "integrator",
            &mut integrator,
            Integrator::ALL,
            Integrator::name,
        );
        draft.method = draft.method.with_integrator(integrator);
        ui.end_row();
        ui.label("stabilization");
        match draft.method.stabilization() {
            Some(mut stabilization) => {
                let all = Stabilization::ALL;
                choice(
                    ui,
                    "stabilization",
                    &mut stabilization,
                    all,
                    Stabilization::name,
                );
                draft.method = draft.method.with_stabilization(stabilization);
            }
            None => {
                ui.label("none: RATTLE holds the wire itself");
            }
        }
        ui.end_row();
        number(ui, "divergence bound", &mut draft.divergence_bound, 0.01);
    });
    (&draft != pending.get()).then(|| pending.set(draft))
}

/// Plots of the selected bead's last seconds, each with its axes labelled.
fn plots_section(ui: &mut egui::Ui, history: &PlotHistory) {
    ui.separator();
    let samples = &history.samples;
    for (id, label, unit, colour, value) in [
        (
            "plot-c",
            "drift C",
            "m",
            egui::Color32::LIGHT_BLUE,
            (|s: &PlotSample| s.c) as fn(&PlotSample) -> f64,
        ),
        ("plot-e", "energy E", "J", egui::Color32::LIGHT_GREEN, |s| {
            s.energy
        }),
        ("plot-l", "λ", "N", egui::Color32::GOLD, |s| s.lambda),
    ] {
        ui.label(format!("{label} ({unit})"));
        plot(
            ui,
            id,
            label,
            samples.iter().map(|s| [s.t, value(s)]),
            colour,
        );
    }
}
