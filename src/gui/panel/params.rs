//! Editing the parameters: the selected bead's, its wire's shape, and the
//! solver's, each through the plugin's validating setters.

use bevy::prelude::*;
use bevy_egui::egui;

use super::keyboard::number_field;
use super::view::PanelView;
use crate::geometry::{Coordinates, Cycloid};
use crate::{
    BeadParams, Integrator, NextBeadParams, NextParams, NextWireShape, ParamError,
    PrescribedMotion, Side, SimClock, Stabilization, Surface, WireContact, WireKind, WireMotion,
    WirePlace, WireShape, pose_of,
};

/// The result of an edit: `None` where nothing was edited.
pub(super) type Edit = Option<Result<(), ParamError>>;

fn number(ui: &mut egui::Ui, label: &str, value: &mut f64, speed: f64) {
    ui.label(label);
    number_field(ui, value, label, |d| d.speed(speed).max_decimals(6));
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

/// A vector's components, each edited by dragging, labelled x, y (and z).
fn vector<V: Coordinates>(ui: &mut egui::Ui, label: &str, value: &mut V, speed: f64) {
    ui.label(label);
    ui.horizontal(|ui| {
        for (axis, component) in ["x ", "y ", "z "].into_iter().zip(value.components_mut()) {
            let name = format!("{label} {}", axis.trim());
            number_field(ui, component, &name, |d| d.speed(speed).prefix(axis));
        }
    });
    ui.end_row();
}

/// A bead's mass and start in a grid, edited as a draft of its pending
/// [`NextBeadParams`] (or its [`BeadParams`] where none is pending).
/// Returns what was shown and the draft, for [`keep_bead_edit`]; an edit of
/// the wire may move the draft's start before it is kept.
pub(super) fn bead_start_editor<V: Coordinates + Reflect + TypePath>(
    ui: &mut egui::Ui,
    id: &str,
    params: &BeadParams<V>,
    pending: Option<&NextBeadParams<V>>,
) -> (BeadParams<V>, BeadParams<V>) {
    let shown = pending.map_or(*params, |p| *p.get());
    let mut draft = shown;
    egui::Grid::new(id).num_columns(2).show(ui, |ui| {
        number(ui, "mass", &mut draft.mass, 0.01);
        vector(ui, "initial position", &mut draft.initial_position, 0.01);
        vector(ui, "initial velocity", &mut draft.initial_velocity, 0.01);
    });
    (shown, draft)
}

/// Keeps `draft` as the bead's pending edit if it differs from `before`.
pub(super) fn keep_bead_edit<V: Coordinates + Reflect + TypePath>(
    commands: &mut Commands,
    entity: Entity,
    before: BeadParams<V>,
    draft: BeadParams<V>,
) -> Edit {
    (draft != before).then(|| {
        NextBeadParams::validated(draft).map(|edit| {
            commands.entity(entity).insert(edit);
        })
    })
}

/// The bead the panel shows, picked from every bead by its name (in the
/// plane and in space), as clicking or dragging a bead picks it: a menu
/// the keyboard reaches. Returns the bead picked, if another was.
pub(super) fn bead_menu(ui: &mut egui::Ui, view: &PanelView) -> Option<Entity> {
    let selected = view.selected.0?;
    let mut beads: Vec<Entity> = view
        .beads
        .iter()
        .map(|b| b.0)
        .chain(view.space_beads.iter().map(|b| b.0))
        .collect();
    beads.sort();
    let mut chosen = selected;
    ui.separator();
    ui.horizontal(|ui| {
        ui.strong("Bead");
        egui::ComboBox::from_id_salt("bead")
            .selected_text(view.name(selected))
            .show_ui(ui, |ui| {
                for bead in beads {
                    ui.selectable_value(&mut chosen, bead, view.name(bead));
                }
            });
        if view.space_beads.contains(selected) {
            ui.label("in space");
        }
    });
    (chosen != selected).then_some(chosen)
}

/// The selected bead's parameters, its wire's shape, and its diagnostics.
pub(super) fn bead_section(ui: &mut egui::Ui, view: &PanelView, commands: &mut Commands) -> Edit {
    let (entity, bead, diagnostics, on_wire, pending_bead, _) =
        view.selected.0.and_then(|e| view.beads.get(e).ok())?;
    let (before, mut draft) = bead_start_editor(ui, "bead", bead, pending_bead);
    let mut outcome = None;
    if let Some(on_wire) = on_wire
        && let Ok((wire, transform, pending_wire, motion, place)) = view.wires.get(on_wire.0)
    {
        let shape = pending_wire.map_or_else(|| wire.shape().clone(), |p| p.shape().clone());
        if let Some(edited) = wire_editor(ui, &shape) {
            outcome = Some(NextWireShape::new(edited.clone()).map(|edit| {
                commands.entity(on_wire.0).insert(edit);
                // Start the bead at the new wire's lowest point, where the
                // restart rests the wire: at its place, in `f64`.
                let pose = place
                    .and_then(WirePlace::taken)
                    .or_else(|| pose_of(transform).ok())
                    .unwrap_or_default();
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
    if let Some(kept) = keep_bead_edit(commands, entity, before, draft) {
        outcome = Some(kept);
    }

    ui.separator();
    egui::Grid::new("values").num_columns(4).show(ui, |ui| {
        let row = RowValues {
            wire: on_wire.map(|_| [diagnostics.c, diagnostics.c_dot, diagnostics.lambda]),
            energy: diagnostics.energy(),
            from_start: view
                .positions
                .get(entity)
                .ok()
                .map(|x| (x.0 - bead.initial_position).length()),
        };
        value_rows(ui, Some(row), &view.clock);
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

/// A bead's wire row (`C`, `Ċ`, λ; none for a bead on no wire), its
/// energy and how far it is from where it started (a run turned round
/// comes back to it), as the panel shows them.
pub(super) struct RowValues {
    pub(super) wire: Option<[f64; 3]>,
    pub(super) energy: f64,
    pub(super) from_start: Option<f64>,
}

/// The rows of a bead's values in a four-column grid: `C` and `Ċ`, λ and
/// the energy (a bead on no wire has no `C`, `Ċ` or λ to show), then the
/// time and the steps.
pub(super) fn value_rows(ui: &mut egui::Ui, row: Option<RowValues>, clock: &SimClock) {
    if let Some(row) = row {
        if let Some([c, c_dot, lambda]) = row.wire {
            ui.label("C");
            ui.monospace(format!("{c:+.3e}"));
            ui.label("Ċ");
            ui.monospace(format!("{c_dot:+.3e}"));
            ui.end_row();
            ui.label("λ");
            ui.monospace(format!("{lambda:+.3e}"));
        }
        ui.label("E");
        ui.monospace(format!("{:+.4}", row.energy));
        ui.end_row();
        if let Some(distance) = row.from_start {
            ui.label("from start");
            ui.monospace(format!("{distance:.3e} m"));
            ui.end_row();
        }
    }
    ui.label("t");
    ui.monospace(format!("{:.2} s", clock.time));
    ui.label("steps");
    ui.monospace(format!("{}", clock.steps));
    ui.end_row();
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

/// The parameters every bead shares; gravity's third component in space:
/// a section that folds away.
pub(super) fn solver_section(ui: &mut egui::Ui, pending: &mut NextParams, in_space: bool) -> Edit {
    ui.separator();
    egui::CollapsingHeader::new("Solver")
        .default_open(true)
        .show(ui, |ui| solver_grid(ui, pending, in_space))
        .body_returned
        .flatten()
}

/// The solver's parameters, one a row.
fn solver_grid(ui: &mut egui::Ui, pending: &mut NextParams, in_space: bool) -> Edit {
    let mut draft = pending.get().clone();
    egui::Grid::new("solver").num_columns(2).show(ui, |ui| {
        number(ui, "timestep (s)", &mut draft.timestep, 0.0005);
        number(ui, "spring constant α", &mut draft.alpha, 1.0);
        number(ui, "damping constant β", &mut draft.beta, 0.1);
        number(ui, "drag scale k", &mut draft.drag_stiffness, 0.1);
        vector(ui, "gravity", &mut draft.gravity, 0.01);
        if in_space {
            number(ui, "gravity z", &mut draft.gravity_z, 0.01);
        }
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
