//! The figures as PNGs: runs' paths in the plane, a quantity against time,
//! and the period error against the step, in one font and one palette.

use std::path::Path;

use bevy::math::DVec2;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use wirebead::{Method, WireShape};

use crate::AnalysisResult;
use crate::comparison::Comparison;
use crate::run::Row;

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

pub(crate) fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The font ships in assets/fonts, so plots never depend on system fonts.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Line colours for up to twelve series.
pub(crate) fn palette(i: usize) -> RGBColor {
    const COLOURS: [RGBColor; 12] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(23, 190, 207),
        RGBColor(188, 189, 34),
        RGBColor(127, 127, 127),
        RGBColor(0, 0, 128),
        RGBColor(0, 0, 0),
    ];
    COLOURS[i % COLOURS.len()]
}

/// The size of every figure, in pixels.
pub const FIGURE_SIZE: (u32, u32) = (900, 800);

/// Plots the wire and each run's path in the plane, like the assignment's figures.
pub fn plot_trajectories(
    path: &Path,
    title: &str,
    wire: &WireShape,
    runs: &[(String, &[Row])],
) -> AnalysisResult<()> {
    register_font();
    let points = runs
        .iter()
        .flat_map(|(_, rows)| rows.iter().map(|r| r.position));
    let wire_points: Vec<DVec2> = (0..=400)
        .filter_map(|i| {
            let a = std::f64::consts::TAU * i as f64 / 400.0;
            match wire {
                WireShape::Circle(c) => Some(DVec2::from_angle(a) * c.radius),
                WireShape::Ellipse(e) => Some(DVec2::new(e.a * a.cos(), e.b * a.sin())),
                _ => None,
            }
        })
        .collect();
    let extent = points
        .chain(wire_points.iter().copied())
        .filter(|p| p.is_finite())
        .fold(1e-3_f64, |m, p| m.max(p.x.abs()).max(p.y.abs()))
        .min(1e3)
        * 1.15;
    let root = BitMapBackend::new(path, FIGURE_SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 26))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(-extent..extent, -extent..extent)?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .draw()?;
    chart
        .draw_series(LineSeries::new(
            wire_points.iter().map(|p| (p.x, p.y)),
            ShapeStyle::from(&BLACK.mix(0.5)).stroke_width(2),
        ))?
        .label("wire")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5)));
    for (i, (label, rows)) in runs.iter().enumerate() {
        let colour = palette(i);
        chart
            .draw_series(LineSeries::new(
                rows.iter().map(|r| {
                    (
                        r.position.x.clamp(-extent, extent),
                        r.position.y.clamp(-extent, extent),
                    )
                }),
                colour.stroke_width(2),
            ))?
            .label(label.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 18))
        .draw()?;
    root.present()?;
    Ok(())
}

/// Draws one line per run (y mapped by `map_y`, points it drops skipped)
/// with a legend.
fn draw_runs<'a, Y: Ranged<ValueType = f64>>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, Cartesian2d<RangedCoordf64, Y>>,
    runs: &[(String, Vec<(f64, f64)>)],
    map_y: impl Fn(f64) -> Option<f64>,
) -> AnalysisResult<()> {
    for (i, (label, series)) in runs.iter().enumerate() {
        let colour = palette(i);
        let points = series.iter().filter_map(|&(t, y)| map_y(y).map(|y| (t, y)));
        chart
            .draw_series(LineSeries::new(points, colour.stroke_width(2)))?
            .label(label.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

/// Plots one quantity of each run against time.
pub fn plot_series(
    path: &Path,
    title: &str,
    y_label: &str,
    runs: &[(String, Vec<(f64, f64)>)],
    log_y: bool,
) -> AnalysisResult<()> {
    register_font();
    let finite = || {
        runs.iter()
            .flat_map(|(_, s)| s.iter())
            .filter(|(t, y)| t.is_finite() && y.is_finite())
    };
    let t_max = finite().map(|(t, _)| *t).fold(1e-9, f64::max);
    let root = BitMapBackend::new(path, (FIGURE_SIZE.0, FIGURE_SIZE.1 / 2)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80);
    if log_y {
        let positive = || finite().map(|(_, y)| y.abs()).filter(|y| *y > 0.0);
        let lo = positive().fold(f64::INFINITY, f64::min).max(1e-18);
        let hi = positive().fold(0.0, f64::max).max(lo * 10.0);
        let mut chart = builder.build_cartesian_2d(0.0..t_max, (lo..hi).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .y_desc(y_label)
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()?;
        draw_runs(&mut chart, runs, |y| (y.abs() > 0.0).then_some(y.abs()))?;
    } else {
        let lo = finite().map(|(_, y)| *y).fold(f64::INFINITY, f64::min);
        let hi = finite().map(|(_, y)| *y).fold(f64::NEG_INFINITY, f64::max);
        let pad = ((hi - lo) * 0.05).max(1e-9);
        let mut chart = builder.build_cartesian_2d(0.0..t_max, (lo - pad)..(hi + pad))?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .y_desc(y_label)
            .draw()?;
        draw_runs(&mut chart, runs, Some)?;
    }
    root.present()?;
    Ok(())
}

/// Plots |period error| against dt on log–log axes, one line per method.
pub fn plot_convergence(path: &Path, table: &[Comparison]) -> AnalysisResult<()> {
    register_font();
    let valid: Vec<&Comparison> = table
        .iter()
        .filter(|r| r.period_error.is_some_and(|e| e != 0.0))
        .collect();
    let (dt_lo, dt_hi) = valid.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), r| {
        (lo.min(r.dt), hi.max(r.dt))
    });
    let errors = || valid.iter().filter_map(|r| r.period_error).map(f64::abs);
    let (e_lo, e_hi) = (
        errors().fold(f64::INFINITY, f64::min),
        errors().fold(0.0, f64::max),
    );
    if valid.is_empty() {
        return Err("no run measured a period".into());
    }
    let root = BitMapBackend::new(path, FIGURE_SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("Period error against timestep", ("sans-serif", 26))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (dt_lo / 1.3..dt_hi * 1.3).log_scale(),
            (e_lo / 3.0..e_hi * 3.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("dt (s)")
        .y_desc("|period error| (relative)")
        .x_label_formatter(&|v| format!("{v:.3}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    let mut i = 0;
    for method in Method::ALL {
        let series: Vec<(f64, f64)> = valid
            .iter()
            .filter(|r| r.method == method)
            .map(|r| (r.dt, r.period_error.unwrap_or(0.0).abs()))
            .collect();
        if series.is_empty() {
            continue;
        }
        let colour = palette(i);
        i += 1;
        chart
            .draw_series(LineSeries::new(series.clone(), colour.stroke_width(2)))?
            .label(method.to_string())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart.draw_series(
            series
                .iter()
                .map(|p| plotters::prelude::Circle::new(*p, 4, colour.filled())),
        )?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()?;
    root.present()?;
    Ok(())
}
