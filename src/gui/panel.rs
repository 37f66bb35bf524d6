//! The egui panel: every parameter of the seed's panel plus gravity, wire
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

use crate::components::{Bead, BeadDiagnostics, Diverged, OnWire, PendingWire, Wire};
use crate::controls::{ControlKeys, StepRequests};
use crate::gui::drag::SelectedBead;
use crate::gui::render::SceneStyle;
use crate::params::{
    BeadParams, Integrator, ParamError, PendingBead, PendingParams, SimParams, Stabilization,
};
use crate::plugin::{Restart, WireBeadSystems};
use crate::preset::{ActivePreset, LoadPreset};
use crate::wire::{Circle, Ellipse, Line as LineShape, Parabola, Pose, Sine, WireShape};

/// The presets the panel offers: `(label, asset path)`.
#[derive(Resource, Clone, Debug)]
pub struct PresetCatalog(pub Vec<(String, String)>);

impl Default for PresetCatalog {
    fn default() -> Self {
        Self(
            [
                ("The seed's circle", "scenes/seed_circle.scene.ron"),
                ("Tilted ellipse", "scenes/ellipse.scene.ron"),
                ("Sine track", "scenes/sine_track.scene.ron"),
                ("Many beads", "scenes/multi_bead.scene.ron"),
                ("Bead at rest", "scenes/resting.scene.ron"),
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

/// Appends the selected bead's diagnostics to the plot history.
pub fn record_history(
    selected: Res<SelectedBead>,
    beads: Query<&BeadDiagnostics>,
    mut history: ResMut<PlotHistory>,
) {
    let Some(entity) = selected.0 else { return };
    let Ok(d) = beads.get(entity) else { return };
    if history.bead != Some(entity) || history.samples.back().is_some_and(|s| s.t > d.time) {
        history.samples.clear();
        history.bead = Some(entity);
    }
    history.samples.push_back(PlotSample {
        t: d.time,
        c: d.c,
        energy: d.energy(),
        lambda: d.lambda,
    });
    let horizon = d.time - history.seconds;
    while history.samples.front().is_some_and(|s| s.t < horizon) {
        history.samples.pop_front();
    }
}

/// A shape of the given kind sized like `scale`.
fn shape_of_kind(kind: &str, scale: f64) -> WireShape {
    match kind {
        "ellipse" => WireShape::Ellipse(Ellipse {
            a: 1.5 * scale,
            b: scale,
        }),
        "line" => WireShape::Line(LineShape),
        "parabola" => WireShape::Parabola(Parabola {
            focal_length: 0.5 * scale,
        }),
        "sine" => WireShape::Sine(Sine {
            amplitude: 0.3 * scale,
            wavelength: 2.0 * scale,
        }),
        _ => WireShape::Circle(Circle { radius: scale }),
    }
}

fn number(ui: &mut egui::Ui, label: &str, value: &mut f64, speed: f64) {
    ui.label(label);
    ui.add(egui::DragValue::new(value).speed(speed).max_decimals(6));
    ui.end_row();
}

fn vector(ui: &mut egui::Ui, label: &str, value: &mut DVec2, speed: f64) {
    ui.label(label);
    ui.horizontal(|ui| {
        ui.add(egui::DragValue::new(&mut value.x).speed(speed).prefix("x "));
        ui.add(egui::DragValue::new(&mut value.y).speed(speed).prefix("y "));
    });
    ui.end_row();
}

fn plot(
    ui: &mut egui::Ui,
    id: &str,
    name: &str,
    points: impl Iterator<Item = [f64; 2]>,
    colour: egui::Color32,
) {
    Plot::new(id)
        .height(80.0)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
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
        ),
    >,
    pending_beads: Query<'w, 's, (), With<PendingBead>>,
    pending_wires: Query<'w, 's, (), With<PendingWire>>,
}

/// The panel.
pub fn panel(
    mut contexts: EguiContexts,
    view: PanelView,
    mut pending: ResMut<PendingParams>,
    mut time: ResMut<Time<Virtual>>,
    mut steps: ResMut<StepRequests>,
    mut restarts: MessageWriter<Restart>,
    mut loads: MessageWriter<LoadPreset>,
    mut refused: Local<Option<String>>,
    mut commands: Commands,
) -> Result {
    let PanelView {
        style,
        keys,
        catalog,
        active,
        history,
        params,
        selected,
        beads,
        wires,
        pending_beads,
        pending_wires,
    } = view;
    let ctx = contexts.ctx_mut()?;
    let mut outcome: Option<Result<(), ParamError>> = None;

    egui::Area::new(egui::Id::new("wirebead-help"))
        .anchor(egui::Align2::LEFT_BOTTOM, [8.0, -8.0])
        .show(ctx, |ui| {
            ui.colored_label(egui::Color32::LIGHT_GRAY, keys.help());
        });

    let height = (ctx.content_rect().height() - 40.0).max(200.0);
    egui::Window::new("wirebead")
        .anchor(egui::Align2::RIGHT_TOP, [-6.0, 6.0])
        .fixed_size([style.panel_width - 30.0, height])
        .resizable(false)
        .collapsible(true)
        .vscroll(true)
        .show(ctx, |ui| {
            // Scene and run state.
            ui.horizontal(|ui| {
                ui.label("Scene");
                let current = active.running.clone().unwrap_or_else(|| "—".into());
                egui::ComboBox::from_id_salt("preset")
                    .selected_text(current)
                    .show_ui(ui, |ui| {
                        for (label, path) in &catalog.0 {
                            if ui.selectable_label(active.path == *path, label).clicked() {
                                loads.write(LoadPreset(path.clone()));
                            }
                        }
                    });
            });
            if let Some(error) = &active.error {
                ui.colored_label(
                    egui::Color32::from_rgb(255, 90, 90),
                    format!("Scene file error: {error}"),
                );
            }
            ui.horizontal(|ui| {
                if ui.button(format!("Restart ({:?})", keys.restart)).clicked() {
                    restarts.write(Restart);
                }
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
                    steps.0 += 1;
                }
            });
            let edits_pending =
                pending.get() != &*params || !pending_beads.is_empty() || !pending_wires.is_empty();
            if edits_pending {
                ui.colored_label(
                    egui::Color32::from_rgb(255, 190, 60),
                    "● Edits pending: press Space to apply",
                );
            }
            for (entity, _, _, _, _, diverged) in &beads {
                if let Some(d) = diverged {
                    ui.colored_label(
                        egui::Color32::from_rgb(255, 90, 90),
                        format!(
                            "Bead {entity} diverged at t = {:.2} s: {}. Press Space to restart.",
                            d.time, d.reason
                        ),
                    );
                }
            }
            if let Some(message) = refused.as_ref() {
                ui.colored_label(
                    egui::Color32::from_rgb(255, 90, 90),
                    format!("Refused: {message}"),
                );
            }

            // The selected bead and its wire.
            let bead = selected.0.and_then(|e| beads.get(e).ok());
            if let Some((entity, bead, diagnostics, on_wire, pending_bead, _)) = bead {
                ui.separator();
                ui.strong(format!("Bead {entity}"));
                let mut draft: BeadParams = pending_bead.map_or(*bead.params(), |p| *p.get());
                let before = draft;
                egui::Grid::new("bead").num_columns(2).show(ui, |ui| {
                    number(ui, "mass", &mut draft.mass, 0.01);
                    vector(ui, "initial position", &mut draft.initial_position, 0.01);
                    vector(ui, "initial velocity", &mut draft.initial_velocity, 0.01);
                });

                if let Some((wire, transform, pending_wire)) =
                    on_wire.and_then(|on| wires.get(on.0).ok())
                {
                    let mut shape =
                        pending_wire.map_or_else(|| wire.shape().clone(), |p| p.shape().clone());
                    let before_shape = format!("{shape:?}");
                    ui.strong("Wire");
                    egui::Grid::new("wire").num_columns(2).show(ui, |ui| {
                        ui.label("shape");
                        let mut kind = shape.name();
                        egui::ComboBox::from_id_salt("shape")
                            .selected_text(kind)
                            .show_ui(ui, |ui| {
                                for k in ["circle", "ellipse", "line", "parabola", "sine"] {
                                    ui.selectable_value(&mut kind, k, k);
                                }
                            });
                        ui.end_row();
                        if kind != shape.name() {
                            shape = shape_of_kind(kind, shape.curve().scale());
                        }
                        match &mut shape {
                            WireShape::Circle(c) => number(ui, "radius", &mut c.radius, 0.01),
                            WireShape::Ellipse(e) => {
                                number(ui, "semi-axis a", &mut e.a, 0.01);
                                number(ui, "semi-axis b", &mut e.b, 0.01);
                            }
                            WireShape::Parabola(p) => {
                                number(ui, "focal length", &mut p.focal_length, 0.01)
                            }
                            WireShape::Sine(s) => {
                                number(ui, "amplitude", &mut s.amplitude, 0.01);
                                number(ui, "wavelength", &mut s.wavelength, 0.01);
                            }
                            WireShape::Line(_) | WireShape::Custom(_) => {}
                        }
                    });
                    if format!("{shape:?}") != before_shape {
                        let result = PendingWire::new(shape.clone()).map(|edit| {
                            commands.entity(on_wire.unwrap().0).insert(edit);
                            // Start the bead at the new wire's lowest point.
                            let pose = Pose::from_transform(transform).unwrap_or_default();
                            draft.initial_position = pose.to_world(shape.bottom());
                        });
                        outcome = Some(result);
                    }
                }
                if draft != before {
                    outcome = Some(PendingBead::new(draft).map(|edit| {
                        commands.entity(entity).insert(edit);
                    }));
                }

                ui.separator();
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
                    ui.monospace(format!("{:.2} s", diagnostics.time));
                    ui.label("steps");
                    ui.monospace(format!("{}", diagnostics.steps));
                    ui.end_row();
                });
            }

            // The shared parameters.
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
                egui::ComboBox::from_id_salt("integrator")
                    .selected_text(draft.integrator.name())
                    .show_ui(ui, |ui| {
                        for &i in Integrator::ALL {
                            ui.selectable_value(&mut draft.integrator, i, i.name());
                        }
                    });
                ui.end_row();
                ui.label("stabilization");
                egui::ComboBox::from_id_salt("stabilization")
                    .selected_text(draft.stabilization.name())
                    .show_ui(ui, |ui| {
                        for &s in Stabilization::ALL {
                            ui.selectable_value(&mut draft.stabilization, s, s.name());
                        }
                    });
                ui.end_row();
                number(ui, "divergence bound", &mut draft.divergence_bound, 0.01);
            });
            if &draft != pending.get() {
                outcome = Some(pending.set(draft));
            }

            // Plots of the last seconds.
            ui.separator();
            let samples = &history.samples;
            ui.label("drift C");
            plot(
                ui,
                "plot-c",
                "C",
                samples.iter().map(|s| [s.t, s.c]),
                egui::Color32::LIGHT_BLUE,
            );
            ui.label("energy E");
            plot(
                ui,
                "plot-e",
                "E",
                samples.iter().map(|s| [s.t, s.energy]),
                egui::Color32::LIGHT_GREEN,
            );
            ui.label("λ");
            plot(
                ui,
                "plot-l",
                "λ",
                samples.iter().map(|s| [s.t, s.lambda]),
                egui::Color32::GOLD,
            );
        });

    match outcome {
        Some(Ok(())) => *refused = None,
        Some(Err(error)) => {
            warn!("wirebead: edit refused: {error}");
            *refused = Some(error.to_string());
        }
        None => {}
    }
    Ok(())
}
