//! The panel by keyboard: Tab and Shift+Tab move through its controls,
//! Space or Enter presses a button or opens a menu, the arrows move a
//! slider, typing edits a number, and Esc gives the keys back to the
//! scene. While a control of the panel has the keys, the scene's keys
//! wait, so a value typed into a field (`1e-3`) exports nothing. The
//! controls the keys went through are kept for the window's report.

use std::cell::RefCell;

use bevy::input::InputSystems;
use bevy::prelude::*;
use bevy_egui::input::EguiWantsInput;
use bevy_egui::{EguiContexts, egui};

/// The panel's controls the keyboard went to, oldest first (the last
/// [`FOCUS_KEPT`]): each as its kind and name, `"number: mass"`,
/// `"button: Restart (Space)"`.
#[derive(Resource, Clone, Debug, Default, PartialEq, Eq)]
pub struct FocusTrail(pub Vec<String>);

/// How many of the controls the keyboard went to [`FocusTrail`] keeps.
pub const FOCUS_KEPT: usize = 256;

/// Adds the panel's keyboard focus: the scene's keys wait while a control
/// has it, and [`FocusTrail`].
pub(super) fn build(app: &mut App) {
    app.init_resource::<FocusTrail>().add_systems(
        PreUpdate,
        hold_scene_keys
            .after(InputSystems)
            .before(crate::controls::keyboard_controls),
    );
}

/// Lets the scene's keys wait while a control of the panel has the
/// keyboard (a field being typed into, a button reached by Tab).
fn hold_scene_keys(egui: Option<Res<EguiWantsInput>>, mut keys: ResMut<ButtonInput<KeyCode>>) {
    if egui.is_some_and(|e| e.wants_any_keyboard_input()) {
        keys.reset_all();
    }
}

/// Names a control for the keyboard's trail (and a screen reader): a
/// number edited by dragging or typing has no text of its own.
fn named(response: egui::Response, name: &str) -> egui::Response {
    let enabled = response.enabled();
    response.widget_info(|| egui::WidgetInfo::labeled(egui::WidgetType::DragValue, enabled, name));
    response
}

/// A number field named `name` (see [`named`]), set up by `setup`
/// (speed, range, suffix). Dragged, or typed into, it reads what was typed
/// by [`read_number`]: a field gone through by Tab, its text left as
/// shown, keeps its value to the bit. Its id is its name's (a panel
/// shows one field of a name), so it keeps the keys while a line above it
/// comes or goes: the edits-pending line its first typed digit brings, or
/// a refusal of a value half typed.
pub(super) fn number_field(
    ui: &mut egui::Ui,
    value: &mut f64,
    name: &str,
    setup: impl for<'b> FnOnce(egui::DragValue<'b>) -> egui::DragValue<'b>,
) -> egui::Response {
    let exact = *value;
    let shown = RefCell::new(String::new());
    let formatter = ui.style().number_formatter.clone();
    // A typed number counts once it is done (Enter, Tab, a click
    // elsewhere), not at each key: `0.25` is not refused as a mass of 0.
    let field = egui::DragValue::new(value)
        .update_while_editing(false)
        .custom_formatter(|v, decimals| {
            let text = formatter.format(v, decimals);
            if v == exact {
                shown.replace(text.clone());
            }
            text
        })
        .custom_parser(|text| read_number(text, &shown.borrow(), exact));
    // An id of its own, not one counted from the widgets above it.
    let id = egui::Id::new(("wirebead number", name));
    let response = ui
        .scope_builder(egui::UiBuilder::new().id(id), |ui| ui.add(setup(field)))
        .inner;
    named(response, name)
}

/// The number `text` says, typed into a field that shows `current` as
/// `shown`: `current` itself where the text is still `shown` (`0.016667`
/// for 1/60), so that leaving the text as it was changes nothing. Spaces
/// are ignored and `−` reads as `-`; `None` where the text is no number.
pub fn read_number(text: &str, shown: &str, current: f64) -> Option<f64> {
    let plain = |text: &str| -> String {
        text.chars()
            .filter(|c| !c.is_whitespace())
            .map(|c| if c == '−' { '-' } else { c })
            .collect()
    };
    let text = plain(text);
    if text == plain(shown) {
        return Some(current);
    }
    text.parse().ok()
}

/// Appends the control the keyboard went to in this pass, if it went to
/// one, to the [`FocusTrail`]: by its kind and name, or as `"control"`
/// where it has none. Runs after the panel is drawn.
pub(super) fn record_focus(
    mut contexts: EguiContexts,
    mut trail: ResMut<FocusTrail>,
    mut last: Local<Option<egui::Id>>,
) -> Result {
    let ctx = contexts.ctx_mut()?;
    let focused = ctx.memory(|m| m.focused());
    if focused == *last {
        return Ok(());
    }
    *last = focused;
    if focused.is_none() {
        return Ok(());
    }
    // A control may say it gained the keys more than once in a pass (a
    // number field as it turns into a text edit, then by its name): the
    // last says the most.
    let control = ctx.output(|o| {
        o.events.iter().rev().find_map(|event| match event {
            egui::output::OutputEvent::FocusGained(info) => Some(describe(info)),
            _ => None,
        })
    });
    trail
        .0
        .push(control.unwrap_or_else(|| "control".to_owned()));
    let extra = trail.0.len().saturating_sub(FOCUS_KEPT);
    trail.0.drain(..extra);
    Ok(())
}

/// A control as its kind and its text: `"number: mass"`.
fn describe(info: &egui::WidgetInfo) -> String {
    use egui::WidgetType as W;
    let kind = match info.typ {
        W::Button | W::Link | W::SelectableLabel | W::ColorButton => "button",
        W::Checkbox | W::RadioButton | W::RadioGroup => "choice",
        W::ComboBox => "menu",
        W::Slider => "slider",
        W::DragValue | W::TextEdit => "number",
        W::CollapsingHeader => "section",
        _ => "control",
    };
    match info.label.as_deref().or(info.current_text_value.as_deref()) {
        Some(text) => format!("{kind}: {}", text.trim()),
        None => kind.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::read_number;

    #[test]
    fn a_number_left_as_shown_keeps_its_value_to_the_bit() {
        let step = 1.0 / 60.0;
        assert_eq!(read_number("0.016667", "0.016667", step), Some(step));
        assert_eq!(read_number(" 0.016667 ", "0.016667", step), Some(step));
        assert_eq!(
            read_number("-0.5981", "−0.5981", -0.598_076),
            Some(-0.598_076)
        );
    }

    #[test]
    fn a_number_typed_is_read_as_typed() {
        let step = 1.0 / 60.0;
        assert_eq!(read_number("0.016", "0.016667", step), Some(0.016));
        assert_eq!(read_number("2.5", "1", 1.0), Some(2.5));
        assert_eq!(read_number("−0.5", "0.5", 0.5), Some(-0.5));
        assert_eq!(read_number("1e-3", "0.0011", 0.0011), Some(1e-3));
        // Typed as a rounder number than shown: the number typed.
        assert_eq!(read_number("100", "99.7", 99.7), Some(100.0));
        assert_eq!(read_number("nothing", "1", 1.0), None);
        assert_eq!(read_number("", "1", 1.0), None);
    }
}
