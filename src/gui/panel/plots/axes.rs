//! The axes of the panel's plots: fixed plots whose value axis steps by 1,
//! 2 or 5 times a power of ten, tick labels that tell neighbouring ticks
//! apart at any scale, and log scales in whole decades.

use bevy_egui::egui;
use egui_plot::{Plot, uniform_grid_spacer};

/// A plot of the panel, `height` points tall and fixed (no drag, zoom or
/// scroll, and no stop for the keyboard's Tab), its value axis with room for its labels, stepped by
/// [`grid_steps`] and labelled by [`tick_label`], or on a log scale in
/// whole decades ([`decade_label`]).
pub(in crate::gui::panel) fn panel_plot(id: &str, height: f32, log: bool) -> Plot<'static> {
    Plot::new(id)
        .height(height)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .allow_axis_zoom_drag(false)
        .sense(egui::Sense::hover())
        .y_axis_min_width(48.0)
        .y_grid_spacer(uniform_grid_spacer(move |input| {
            grid_steps(input.bounds, log)
        }))
        .y_axis_formatter(move |mark, _| {
            if log {
                decade_label(mark.value)
            } else {
                tick_label(mark.value, mark.step_size)
            }
        })
}

/// How many labelled ticks a plot's value axis aims at.
const LABELLED_TICKS: f64 = 3.5;

/// The three steps of a value axis's grid over `bounds`, finest first:
/// the middle one a 1, 2 or 5 times a power of ten that puts about
/// [`LABELLED_TICKS`] labelled ticks on the axis, a fifth (a quarter for
/// a 2) of it between them, and ten of it. On a log scale (decades) the
/// steps are whole decades.
pub fn grid_steps(bounds: (f64, f64), log: bool) -> [f64; 3] {
    let span = bounds.1 - bounds.0;
    let wanted = if span.is_finite() && span > 0.0 {
        span / LABELLED_TICKS
    } else {
        1.0
    };
    let decade = 10f64.powf(wanted.log10().floor());
    let (step, fine) = [(1.0, 5.0), (2.0, 4.0), (5.0, 5.0), (10.0, 5.0)]
        .into_iter()
        .map(|(m, parts)| (m * decade, parts))
        .find(|&(step, _)| step >= wanted)
        .unwrap_or((10.0 * decade, 5.0));
    if log {
        let step = step.max(1.0).round();
        return [1.0f64.min(step), step, 10.0 * step];
    }
    [step / fine, step, 10.0 * step]
}

/// The smallest magnitude a log scale shows: a drift of exactly zero is
/// drawn here, below every drift rounding leaves.
const LOG_FLOOR: f64 = 1e-20;

/// `log10 |value|`, from [`LOG_FLOOR`] up.
pub fn log_magnitude(value: f64) -> f64 {
    value.abs().max(LOG_FLOOR).log10()
}

/// The label of a tick at `exponent` on a log scale: `1e-16` at a whole
/// decade, none between.
pub fn decade_label(exponent: f64) -> String {
    let whole = exponent.round();
    if (exponent - whole).abs() > 1e-9 {
        return String::new();
    }
    format!("1e{}", whole as i64)
}

/// The label of an axis tick at `value`, ticks `step` apart: plain
/// decimals (`69.25`, `150`) for values from 1e-3 to 1e5 that need no more
/// than six decimals, else scientific notation (`1.4e-16`), each with just
/// the digits that tell it from the next tick; `0` for a tick within a
/// millionth of a step of zero.
pub fn tick_label(value: f64, step: f64) -> String {
    if !value.is_finite() {
        return format!("{value}");
    }
    let step = step.abs();
    if value == 0.0 || (step > 0.0 && value.abs() < 1e-6 * step) {
        return "0".to_owned();
    }
    // The decade of the step's last digit, and of the value's first.
    let last = if step > 0.0 && step.is_finite() {
        step.log10().floor() as i32
    } else {
        value.abs().log10().floor() as i32 - 2
    };
    let first = value.abs().log10().floor() as i32;
    let decimals = (-last).max(0);
    if (1e-3..1e5).contains(&value.abs()) && decimals <= 6 {
        format!("{value:.*}", decimals as usize)
    } else {
        format!("{value:.*e}", (first - last).clamp(0, 15) as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::{decade_label, grid_steps, log_magnitude, tick_label};

    #[test]
    fn tick_labels_read_at_every_scale() {
        assert_eq!(tick_label(69.25, 0.05), "69.25");
        assert_eq!(tick_label(69.5, 0.5), "69.5");
        assert_eq!(tick_label(150.0, 50.0), "150");
        assert_eq!(tick_label(1.4e-16, 2e-17), "1.4e-16");
        assert_eq!(tick_label(-3e-16, 1e-16), "-3e-16");
        assert_eq!(tick_label(2.5e6, 5e5), "2.5e6");
        assert_eq!(tick_label(0.0, 1e-16), "0");
        assert_eq!(tick_label(1e-25, 1e-16), "0");
    }

    /// The labelled step puts two to four ticks on any span (never closer
    /// than a plot's height allows labels), and their labels tell them
    /// apart.
    #[test]
    fn grid_steps_put_a_few_readable_ticks_on_any_span() {
        for (low, high) in [
            (3.6, 3.7),
            (68.9, 69.4),
            (-1e-16, 3e-16),
            (0.0, 1e2),
            (-5.0, 12.0),
            (1e6, 1.3e6),
        ] {
            let [fine, step, coarse] = grid_steps((low, high), false);
            let first = (low / step).ceil();
            let ticks = (high / step).floor() - first + 1.0;
            assert!(
                (2.0..=4.0).contains(&ticks),
                "{ticks} ticks of {step:e} on [{low}, {high}]"
            );
            assert!(fine < step && step < coarse);
            let labels: Vec<String> = (0..ticks as i64)
                .map(|k| tick_label((first + k as f64) * step, step))
                .collect();
            for pair in labels.windows(2) {
                assert_ne!(pair[0], pair[1], "on [{low}, {high}]");
            }
        }
        assert_eq!(grid_steps((-16.0, -2.0), true)[1], 5.0);
        assert_eq!(grid_steps((-3.0, -2.5), true)[1], 1.0);
        assert!(grid_steps((1.0, 1.0), false)[1].is_finite());
    }

    #[test]
    fn a_log_scale_reads_in_whole_decades() {
        assert_eq!(log_magnitude(-3e-16), 3e-16f64.log10());
        assert_eq!(log_magnitude(0.0), -20.0);
        assert_eq!(decade_label(-16.0), "1e-16");
        assert_eq!(decade_label(2.0), "1e2");
        assert_eq!(decade_label(-15.5), "");
    }

    /// Neighbouring ticks never share a label, and each label reads back
    /// within a tenth of a step of its tick, from steps of 1e-17 to 1e6
    /// and ticks far from zero.
    #[test]
    fn neighbouring_ticks_have_labels_that_tell_them_apart() {
        for exponent in -17..=6 {
            for mantissa in [1.0, 2.0, 5.0] {
                let step = mantissa * 10f64.powi(exponent);
                for offset in [0.0, 7.0, 1234.0, -40.0, 1e6] {
                    let ticks: Vec<f64> = (0..6).map(|k| (offset + k as f64) * step).collect();
                    let labels: Vec<String> = ticks.iter().map(|&t| tick_label(t, step)).collect();
                    for (pair, ticks) in labels.windows(2).zip(ticks.windows(2)) {
                        assert_ne!(pair[0], pair[1], "ticks {ticks:?} at step {step:e}");
                    }
                    for (label, &tick) in labels.iter().zip(&ticks) {
                        let read: f64 = label.parse().expect("a number");
                        assert!(
                            (read - tick).abs() <= 0.1 * step,
                            "{label} for {tick:e} at step {step:e}"
                        );
                    }
                }
            }
        }
    }
}
