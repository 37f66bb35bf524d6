//! Checks of the example in a real window. `.ci/run` runs the example under
//! Xvfb with Mesa's software Vulkan, saves a screenshot and its report,
//! drives a real mouse drag with xdotool and edits the running preset's
//! file; these tests then check the pixels, the drag and the reload. They
//! need those files, so they are ignored by a plain `cargo test`; `.ci/run`
//! runs them with `--ignored` and `WIREBEAD_WINDOW_DIR` set.

use std::path::PathBuf;

use image::{Rgb, RgbImage};
use wirebead::gui::FrameReport;

fn dir() -> PathBuf {
    PathBuf::from(
        std::env::var("WIREBEAD_WINDOW_DIR").expect("WIREBEAD_WINDOW_DIR: run through .ci/run"),
    )
}

fn report(name: &str) -> FrameReport {
    let path = dir().join(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    ron::from_str(&text).unwrap()
}

fn rgb(colour: bevy::color::Color) -> Rgb<u8> {
    let c = colour.to_srgba();
    Rgb([c.red, c.green, c.blue].map(|v| (v * 255.0).round() as u8))
}

fn close(a: Rgb<u8>, b: Rgb<u8>, tolerance: i32) -> bool {
    a.0.iter()
        .zip(b.0)
        .all(|(x, y)| (*x as i32 - y as i32).abs() <= tolerance)
}

/// Whether a pixel of `colour` lies within `radius` pixels of `at`.
fn colour_near(image: &RgbImage, at: [f32; 2], radius: i32, colour: Rgb<u8>) -> bool {
    hue_near(image, at, radius, |rgb| {
        close(Rgb(rgb.map(|v| v as u8)), colour, 40)
    })
}

/// The screenshot `name`.png with its report, of the same size.
fn screenshot(name: &str) -> (RgbImage, FrameReport) {
    let image = image::open(dir().join(format!("{name}.png")))
        .expect("screenshot")
        .to_rgb8();
    let report = report(&format!("{name}.ron"));
    assert_eq!([image.width(), image.height()], report.window);
    (image, report)
}

/// Every bead of the report shows its colour (the bead colour, or the
/// flight colour while it is off its wire) at its simulated position.
fn beads_drawn_where_simulated(image: &RgbImage, report: &FrameReport) {
    let style = wirebead::gui::SceneStyle::default();
    assert!(!report.beads.is_empty());
    for bead in &report.beads {
        let colour = rgb(if bead.in_flight {
            style.flight
        } else {
            style.bead
        });
        let r = (0.5 * bead.radius_px).max(2.0) as i32;
        assert!(
            colour_near(image, bead.pixel, r, colour),
            "no bead colour at {:?} (in flight: {})",
            bead.pixel,
            bead.in_flight
        );
    }
}

#[test]
#[ignore = "needs the screenshot .ci/run makes under Xvfb"]
fn screenshot_shows_the_wire_and_the_bead_where_simulated() {
    let (image, report) = screenshot("shot");
    let wire_colour = rgb(wirebead::gui::SceneStyle::default().wire);
    beads_drawn_where_simulated(&image, &report);

    // The wire's stroke is where the simulated wire is, and not beside it.
    let mut on = 0;
    let mut off = 0;
    let mut total = 0;
    for wire in &report.wires {
        let n = wire.pixels.len();
        for (i, p) in wire.pixels.iter().enumerate() {
            let near_bead = report.beads.iter().any(|b| {
                let d = ((p[0] - b.pixel[0]).powi(2) + (p[1] - b.pixel[1]).powi(2)).sqrt();
                d < 3.0 * b.radius_px
            });
            if near_bead {
                continue;
            }
            total += 1;
            on += colour_near(&image, *p, 3, wire_colour) as usize;
            // 20 px along the normal (from neighbouring samples) there is no stroke.
            let (a, b) = (
                wire.pixels[i.saturating_sub(1)],
                wire.pixels[(i + 1).min(n - 1)],
            );
            let t = [b[0] - a[0], b[1] - a[1]];
            let len = (t[0] * t[0] + t[1] * t[1]).sqrt().max(1e-3);
            let beside = [p[0] - 20.0 * t[1] / len, p[1] + 20.0 * t[0] / len];
            off += colour_near(&image, beside, 1, wire_colour) as usize;
        }
    }
    assert!(total > 50, "too few wire samples in view: {total}");
    let on_fraction = on as f64 / total as f64;
    let off_fraction = off as f64 / total as f64;
    assert!(
        on_fraction > 0.6,
        "wire colour found at only {:.0}% of the wire's points",
        100.0 * on_fraction
    );
    assert!(
        off_fraction < 0.1,
        "wire colour 20 px off the wire at {:.0}% of points",
        100.0 * off_fraction
    );
}

/// The drag the report `name` holds brought its bead within half its
/// start distance of where the cursor let go.
fn drag_pulled_the_bead(name: &str) {
    let drag = report(name)
        .drag
        .unwrap_or_else(|| panic!("{name}: the drag never reached the bead through picking"));
    assert!(
        drag.closest_distance < 0.5 * drag.start_distance,
        "{name}: the bead came no closer than {:.3} to the cursor (from {:.3})",
        drag.closest_distance,
        drag.start_distance
    );
}

#[test]
#[ignore = "needs the xdotool drag .ci/run makes under Xvfb"]
fn a_real_mouse_drag_pulls_the_bead_toward_the_cursor() {
    drag_pulled_the_bead("drag.ron");
}

#[test]
#[ignore = "needs the arrow key .ci/run holds under Xvfb"]
fn the_arrow_keys_pull_the_bead_as_the_mouse_does() {
    let drag = report("keypull.ron")
        .drag
        .expect("the arrow key never pulled the bead");
    // Pulled to the right, along its circle.
    assert!(
        drag.target[0] > drag.bead_start[0] + 0.2,
        "the target moved from {:?} to {:?}",
        drag.bead_start,
        drag.target
    );
    drag_pulled_the_bead("keypull.ron");
}

#[test]
#[ignore = "needs the xdotool drag .ci/run makes under Xvfb"]
fn a_real_mouse_drag_pulls_a_bead_in_space_toward_the_cursor() {
    let ready = report("space_drag_ready.ron");
    assert_eq!(ready.preset.as_deref(), Some("Bead in a bowl"));
    assert_eq!(ready.space_beads.len(), 1);
    drag_pulled_the_bead("space_drag.ron");
}

#[test]
#[ignore = "needs the hot-reload run .ci/run makes under Xvfb"]
fn editing_the_running_preset_reloads_it() {
    let ready = report("reload_ready.ron");
    let end = report("reload.ron");
    assert_eq!(ready.preset.as_deref(), Some("Bead at rest"));
    assert_eq!(end.preset.as_deref(), Some("Bead at rest, edited"));
    assert_eq!(end.preset_error, None);
    // The edited preset hangs the bead at rest at the bottom of a circle of
    // radius 2 instead of 1.
    let [x, y] = end.beads[0].world;
    assert!(
        x.abs() < 1e-9 && (y + 2.0).abs() < 1e-9,
        "bead at ({x}, {y})"
    );
    let [_, y0] = ready.beads[0].world;
    assert!((y0 + 1.0).abs() < 1e-9, "bead started at y = {y0}");
}

#[test]
#[ignore = "needs the screenshot .ci/run makes under Xvfb"]
fn screenshot_of_a_coupled_preset_shows_its_rod_between_its_beads() {
    let (image, report) = screenshot("coupled");
    assert_eq!(report.preset.as_deref(), Some("Pendulum on a cart"));
    let rod_colour = rgb(wirebead::gui::SceneStyle::default().rod);
    assert_eq!(report.beads.len(), 2);
    beads_drawn_where_simulated(&image, &report);
    // The rod is drawn from bead to bead: its colour along the middle of
    // the segment, and not 20 px to its side.
    assert_eq!(report.rods.len(), 1);
    let [a, b] = report.rods[0];
    let (d, len) = {
        let d = [b[0] - a[0], b[1] - a[1]];
        (d, (d[0] * d[0] + d[1] * d[1]).sqrt())
    };
    assert!(len > 60.0, "the rod is only {len} px long");
    let (mut on, mut beside) = (0, 0);
    let samples = 20;
    for i in 0..samples {
        let t = 0.25 + 0.5 * i as f32 / (samples - 1) as f32;
        let p = [a[0] + t * d[0], a[1] + t * d[1]];
        on += colour_near(&image, p, 2, rod_colour) as usize;
        let side = [p[0] - 20.0 * d[1] / len, p[1] + 20.0 * d[0] / len];
        beside += colour_near(&image, side, 1, rod_colour) as usize;
    }
    assert!(
        on >= 16,
        "rod colour at {on} of {samples} points along the rod"
    );
    assert!(
        beside <= 2,
        "rod colour 20 px beside the rod at {beside} points"
    );
}

#[test]
#[ignore = "needs the screenshot .ci/run makes under Xvfb"]
fn screenshot_of_the_roller_coaster_hatches_the_closed_side_of_its_track() {
    let (image, report) = screenshot("coaster");
    assert_eq!(report.preset.as_deref(), Some("Roller coaster"));
    beads_drawn_where_simulated(&image, &report);
    let hatch_colour = rgb(wirebead::gui::SceneStyle::default().hatch);
    let [track] = report.wires.as_slice() else {
        panic!("one track expected, got {}", report.wires.len());
    };
    assert_eq!(track.shape, "spline");
    // Away from the bead, the middle of a hatch stroke shows the hatching's
    // colour on the closed side far more often than on the open side.
    let clear = |p: &[f32; 2]| {
        report.beads.iter().all(|b| {
            ((p[0] - b.pixel[0]).powi(2) + (p[1] - b.pixel[1]).powi(2)).sqrt() > 3.0 * b.radius_px
        })
    };
    let share = |probes: &[[f32; 2]]| {
        let probes: Vec<[f32; 2]> = probes.iter().copied().filter(|p| clear(p)).collect();
        let hits = probes
            .iter()
            .filter(|p| colour_near(&image, **p, 2, hatch_colour))
            .count();
        (hits as f64 / probes.len().max(1) as f64, probes.len())
    };
    let (closed, n_closed) = share(&track.closed_side);
    let (open, n_open) = share(&track.open_side);
    eprintln!(
        "hatching: {closed:.2} of {n_closed} closed-side probes, {open:.2} of {n_open} open-side"
    );
    assert!(n_closed > 100 && n_open > 100, "too few probes in view");
    assert!(
        closed > 0.15,
        "hatching at only {:.0}% of the closed side",
        100.0 * closed
    );
    assert!(
        open < closed / 3.0,
        "wire colour on the open side at {:.0}%",
        100.0 * open
    );
}

/// Whether a pixel within `radius` of `at` has the hue `hue` says of its
/// red, green and blue.
fn hue_near(image: &RgbImage, at: [f32; 2], radius: i32, hue: impl Fn([f32; 3]) -> bool) -> bool {
    let (x0, y0) = (at[0].round() as i32, at[1].round() as i32);
    (-radius..=radius).any(|dy| {
        (-radius..=radius).any(|dx| {
            let (x, y) = (x0 + dx, y0 + dy);
            x >= 0
                && y >= 0
                && (x as u32) < image.width()
                && (y as u32) < image.height()
                && hue(image.get_pixel(x as u32, y as u32).0.map(f32::from))
        })
    })
}

/// Whether a pixel within `radius` of `at` has the bead's hue: orange
/// (the bead is lit, so its brightness varies across it; the trail's
/// yellow has too much green).
fn bead_hue_near(image: &RgbImage, at: [f32; 2], radius: i32) -> bool {
    hue_near(image, at, radius, |[r, g, b]| {
        r >= 80.0 && (0.3..0.75).contains(&(g / r)) && b / r < 0.35
    })
}

#[test]
#[ignore = "needs the screenshot .ci/run makes under Xvfb"]
fn screenshot_in_space_shows_the_hoop_and_its_bead_where_simulated() {
    let (image, report) = screenshot("space");
    assert!(
        report.beads.is_empty(),
        "a scene in space has no bead in the plane"
    );
    assert_eq!(report.space_beads.len(), 1);
    let bead = &report.space_beads[0];
    assert!(
        bead.radius_px >= 3.0,
        "the bead is drawn {} px wide",
        bead.radius_px
    );
    assert!(
        bead_hue_near(&image, bead.pixel, (0.5 * bead.radius_px) as i32),
        "no bead at {:?}",
        bead.pixel
    );
    // The hoop is drawn where it is, through the 3D camera.
    let wire_colour = rgb(wirebead::gui::SceneStyle::default().wire);
    let [hoop] = report.space_curves.as_slice() else {
        panic!("one curve in space, got {}", report.space_curves.len());
    };
    let away: Vec<&[f32; 2]> = hoop
        .iter()
        .filter(|p| {
            let d = ((p[0] - bead.pixel[0]).powi(2) + (p[1] - bead.pixel[1]).powi(2)).sqrt();
            d > 3.0 * bead.radius_px
        })
        .collect();
    assert!(
        away.len() > 50,
        "too few points of the hoop in view: {}",
        away.len()
    );
    let on = away
        .iter()
        .filter(|p| colour_near(&image, ***p, 3, wire_colour))
        .count();
    assert!(
        on as f64 > 0.6 * away.len() as f64,
        "the hoop's colour at only {on} of its {} points",
        away.len()
    );
}

#[test]
#[ignore = "needs the key presses .ci/run makes under Xvfb"]
fn keys_step_the_rope_back_and_forward_bit_for_bit() {
    // Eight presses of B, then five of N.
    let report = report("timeline.ron");
    let timeline = report.timeline.expect("a timeline in the report");
    assert!(timeline.stepped_back, "{timeline:?}");
    assert_eq!(timeline.step + 3, timeline.recorded[1], "{timeline:?}");
    assert_eq!(timeline.matched, 5, "{timeline:?}");
    assert_eq!(timeline.departed, None);
    assert!(
        timeline.now.len() >= 10,
        "the rope's beads: {:?}",
        timeline.now
    );
    assert_eq!(timeline.now, timeline.at_step);
}

#[test]
#[ignore = "needs the export .ci/run makes under Xvfb"]
fn the_csv_exported_from_the_window_is_the_one_simulate_writes() {
    let read = |name: &str| {
        let path = dir().join(name);
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    };
    let exported = read("exports/rope.csv");
    let rows = exported.lines().count() - 1;
    assert!(rows > 30, "{rows} rows exported");
    for simulated in ["rope_simulated.csv", "rope_saved_simulated.csv"] {
        let simulated = read(simulated);
        let differ = exported
            .lines()
            .zip(simulated.lines())
            .position(|(a, b)| a != b);
        assert_eq!(differ, None, "the first line that differs");
        assert_eq!(simulated.lines().count(), rows + 1);
    }
}

#[test]
#[ignore = "needs the ghost .ci/run adds with G under Xvfb"]
fn a_ghost_added_with_g_is_drawn_beside_the_bead() {
    let (image, report) = screenshot("ghost");
    beads_drawn_where_simulated(&image, &report);
    assert_eq!(report.ghost_beads.len(), 1, "one ghost of one bead");
    let style = wirebead::gui::SceneStyle::default();
    let background = style.background.to_srgba();
    for ghost in &report.ghost_beads {
        // The ring's colour over the background, by its alpha.
        let [r, g, b, a] = ghost.colour;
        let over = |c: f32, bg: f32| ((a * c + (1.0 - a) * bg) * 255.0).round() as u8;
        let colour = Rgb([
            over(r, background.red),
            over(g, background.green),
            over(b, background.blue),
        ]);
        let reach = ghost.radius_px.round() as i32 + 2;
        assert!(
            colour_near(&image, ghost.pixel, reach, colour),
            "no ring of {colour:?} around {:?}",
            ghost.pixel
        );
    }
}

#[test]
#[ignore = "needs the screenshot .ci/run makes under Xvfb"]
fn the_pendulums_phase_portrait_draws_its_closed_orbit() {
    closed_orbit_drawn("phase");
}

#[test]
#[ignore = "needs the screenshot .ci/run makes under Xvfb"]
fn presentation_mode_shows_the_phase_portrait_beside_the_scene_at_1280_by_800() {
    let (image, report) = screenshot("present");
    assert_eq!(report.window, [1280, 800]);
    let plot = report.phase_plot.as_ref().expect("the phase plot is drawn");
    assert_eq!(plot.visible_px, plot.rect_px, "the whole phase plot shows");
    assert!(
        plot.rect_px[2] < 640.0,
        "the plots on the left: {:?}",
        plot.rect_px
    );
    // The scene between the two columns, its bead where it is simulated.
    beads_drawn_where_simulated(&image, &report);
    for bead in &report.beads {
        assert!(
            bead.pixel[0] > plot.rect_px[2] && bead.pixel[0] < 1280.0 - 400.0,
            "the bead at {:?}, under a column",
            bead.pixel
        );
    }
    closed_orbit_drawn("present");
}

/// The screenshot `name` of the pendulum scene shows the phase portrait's
/// closed orbit.
fn closed_orbit_drawn(name: &str) {
    let (image, report) = screenshot(name);
    let plot = report.phase_plot.expect("the phase plot is drawn");
    let [left, top, right, bottom] = plot.rect_px;
    let [x0, x1, y0, y1] = plot.bounds;
    let pixel = |x: f64, y: f64| {
        [
            left + ((x - x0) / (x1 - x0)) as f32 * (right - left),
            bottom - ((y - y0) / (y1 - y0)) as f32 * (bottom - top),
        ]
    };
    // The scene: from rest at 60° on a unit circle, g = 9.81. Energy kept:
    // θ̇² = 2 g/R (cos θ − cos θ0).
    let (g, r, theta0) = (9.81_f64, 1.0_f64, 60f64.to_radians());
    let recorded = rgb(bevy::color::Color::srgb_u8(173, 216, 230));
    // The points of the orbit the panel shows (it may scroll part of the
    // plot out of view).
    let [vl, vt, vr, vb] = plot.visible_px;
    let seen =
        |p: [f32; 2]| p[0] >= vl + 3.0 && p[0] <= vr - 3.0 && p[1] >= vt + 3.0 && p[1] <= vb - 3.0;
    let (mut on_orbit, mut shown) = (0, 0);
    let n = 60;
    for k in 0..n {
        let theta = theta0 * (-1.0 + 2.0 * (k as f64 + 0.5) / n as f64);
        let speed = (2.0 * g / r * (theta.cos() - theta0.cos())).sqrt();
        for sign in [1.0, -1.0] {
            let at = pixel(theta, sign * speed);
            if !seen(at) {
                continue;
            }
            shown += 1;
            if colour_near(&image, at, 3, recorded) {
                on_orbit += 1;
            }
        }
    }
    eprintln!(
        "the orbit's colour at {on_orbit} of the {shown} points shown, of {}",
        2 * n
    );
    assert!(
        shown >= n,
        "only {shown} of the orbit's {} points are shown",
        2 * n
    );
    assert!(
        on_orbit >= shown * 9 / 10,
        "the orbit's colour at {on_orbit} of the {shown} points shown"
    );
    // Inside the orbit, at rest at the bottom, nothing is drawn.
    assert!(
        !colour_near(&image, pixel(0.0, 0.0), 2, recorded),
        "the orbit's colour at its centre: a blot, not an orbit"
    );
}

#[test]
#[ignore = "needs the I press .ci/run makes under Xvfb"]
fn i_saves_the_plots_as_shown_as_a_png() {
    let (shot, _) = screenshot("phase");
    let plots = image::open(dir().join("exports/pendulum-plots.png"))
        .expect("the plots' PNG")
        .to_rgb8();
    // The plots, a piece of the panel: narrower than the window, and tall
    // enough for every plot and the phase plot.
    assert!(
        plots.width() >= 200 && plots.width() < shot.width() / 2,
        "{}",
        plots.width()
    );
    assert!(plots.height() >= 600, "{}", plots.height());
    // The phase plot's closed orbit and the energy line are in it.
    let has = |colour: Rgb<u8>| plots.pixels().any(|p| close(*p, colour, 30));
    assert!(has(Rgb([173, 216, 230])), "no recorded phase line");
    assert!(has(Rgb([144, 238, 144])), "no energy line");
}

/// Pixels of `colour` inside `rect` (physical pixels: left, top, right,
/// bottom).
fn pixels_of(image: &RgbImage, rect: [f32; 4], colour: Rgb<u8>) -> usize {
    let [l, t, r, b] = rect.map(|v| v.round().max(0.0) as u32);
    (t..b.min(image.height()))
        .flat_map(|y| (l..r.min(image.width())).map(move |x| (x, y)))
        .filter(|&(x, y)| close(*image.get_pixel(x, y), colour, 30))
        .count()
}

#[test]
#[ignore = "needs the screenshot .ci/run makes under Xvfb"]
fn at_1280_by_800_the_ropes_plots_show_beside_the_scene() {
    let (image, report) = screenshot("rope");
    assert_eq!(report.window, [1280, 800]);
    // The plots in a column of their own on the left, whole in the window
    // and tall enough for the drift and energy plots.
    let plots = report.plots_shown.expect("the plots show");
    let [left, top, right, bottom] = plots;
    assert!(left >= 0.0 && right < 640.0, "the plots at {plots:?}");
    assert!(top >= 0.0 && bottom <= 800.0, "the plots at {plots:?}");
    assert!(bottom - top >= 400.0, "the plots at {plots:?}");
    // The drift line (the rods' largest |C|) and the energy line are drawn.
    let drift = pixels_of(&image, plots, Rgb([173, 216, 230]));
    let energy = pixels_of(&image, plots, Rgb([144, 238, 144]));
    assert!(drift >= 100, "{drift} pixels of the drift line");
    assert!(energy >= 100, "{energy} pixels of the energy line");
    // The rope between the columns, drawn where it is simulated (its
    // small beads may lie under the force arrow, the rods or the trails).
    assert_eq!(report.beads.len(), 21);
    let colour = rgb(wirebead::gui::SceneStyle::default().bead);
    let drawn = report
        .beads
        .iter()
        .filter(|b| colour_near(&image, b.pixel, b.radius_px.round() as i32 + 1, colour))
        .count();
    assert!(drawn >= 14, "{drawn} of 21 beads drawn where simulated");
    for bead in &report.beads {
        assert!(
            bead.pixel[0] > right && bead.pixel[0] < 1280.0 - 340.0,
            "the bead at {:?}, under a column",
            bead.pixel
        );
    }
}

/// The panel's controls, in the order Tab reaches them, in the assignment's
/// scene.
const CONTROLS: [&str; 31] = [
    "menu: The assignment's circle",
    "button: Restart (Space)",
    "button: Reverse (R)",
    "menu: speed 1×",
    "section: Timeline",
    "button: ◀ Back (B)",
    "button: Step (N) ▶",
    "slider: scrub",
    "number: seconds kept",
    "button: Export CSV (E)",
    "button: Save scene (S)",
    "button: Plots PNG (I)",
    "menu: bead0",
    "number: mass",
    "number: initial position x",
    "number: initial position y",
    "number: initial velocity x",
    "number: initial velocity y",
    "menu: circle",
    "number: radius",
    "section: Solver",
    "number: timestep (s)",
    "number: spring constant α",
    "number: damping constant β",
    "number: drag scale k",
    "number: gravity x",
    "number: gravity y",
    "menu: semi-implicit-euler",
    "menu: baumgarte",
    "section: Ghosts (0)",
    "section: Plots",
];

#[test]
#[ignore = "needs the Tab presses .ci/run makes under Xvfb"]
fn tab_reaches_every_control_of_the_panel_in_order() {
    let trail = report("keys.ron").focus_trail;
    let mut rest = trail.iter();
    for control in CONTROLS {
        assert!(
            rest.any(|c| c == control),
            "Tab never reached {control} (in order) in {trail:?}"
        );
    }
    // The phase plot's menus too, in its column.
    for control in [
        "section: Phase plot",
        "menu: dθ/dt (rad/s)",
        "menu: θ (rad)",
    ] {
        assert!(trail.iter().any(|c| c == control), "no {control}");
    }
}

#[test]
#[ignore = "needs the keys .ci/run presses under Xvfb"]
fn a_mass_typed_with_the_keyboard_alone_applies_with_space() {
    let before = report("keys.ron");
    let after = report("keys_edit.ron");
    assert_eq!(before.beads[0].mass, 1.0);
    assert_eq!(
        after.focus_trail.last().map(String::as_str),
        Some("number: mass")
    );
    // A bead's mass changes only when Space applies the pending edits.
    assert_eq!(after.beads[0].mass, 0.25);
}

/// Whether a pixel within `radius` of `at` has a dynamic body's hue:
/// green over red and blue (lit in space, so its brightness varies).
fn body_hue_near(image: &RgbImage, at: [f32; 2], radius: i32) -> bool {
    hue_near(image, at, radius, |[r, g, b]| {
        g >= 50.0 && g > 1.15 * r && g > 1.08 * b
    })
}

/// The body named `name` of a report.
fn body<'a>(report: &'a FrameReport, name: &str) -> &'a wirebead::gui::BodyReport {
    report
        .bodies
        .iter()
        .find(|b| b.name == name)
        .unwrap_or_else(|| panic!("no body {name:?} in {:?}", report.bodies))
}

#[test]
#[ignore = "needs the screenshot .ci/run makes under Xvfb"]
fn screenshot_of_rigid_bodies_shows_each_where_avian_has_it() {
    let (image, report) = screenshot("bodies");
    assert_eq!(report.preset.as_deref(), Some("Cart on a hoop"));
    assert_eq!(report.bodies.len(), 3, "{:?}", report.bodies);
    let style = wirebead::gui::SceneStyle::default();
    // The cart at rest at the bottom of its hoop, the ball come to rest on
    // the floor (its top at y = -1.5) beside it.
    let (cart, ball, floor) = (
        body(&report, "cart"),
        body(&report, "ball"),
        body(&report, "floor"),
    );
    assert!(
        cart.world[0].abs() < 1e-3 && (cart.world[1] + 1.0).abs() < 1e-3,
        "the cart at {:?}",
        cart.world
    );
    assert!(
        (ball.world[1] + 1.35).abs() < 0.02,
        "the ball at {:?}",
        ball.world
    );
    for (what, at, colour) in [
        ("cart", cart.pixel, style.body),
        ("ball", ball.pixel, style.body),
        ("floor", floor.pixel, style.fixed_body),
    ] {
        assert!(
            colour_near(&image, at, 4, rgb(colour)),
            "no {what} colour at {at:?}"
        );
    }
    // Nothing of the bodies' colour far from them: 60 px above the cart
    // is the hoop's inside.
    let above = [cart.pixel[0], cart.pixel[1] - 60.0];
    assert!(
        !colour_near(&image, above, 2, rgb(style.body)),
        "body colour at {above:?}, above the cart"
    );
}

#[test]
#[ignore = "needs the screenshot .ci/run makes under Xvfb"]
fn screenshot_of_rigid_bodies_in_space_shows_them_in_the_3d_view() {
    let (image, report) = screenshot("bodies_space");
    assert_eq!(report.preset.as_deref(), Some("Cart on a loop in space"));
    assert_eq!(report.bodies.len(), 3, "{:?}", report.bodies);
    for name in ["cart", "ball"] {
        let at = body(&report, name).pixel;
        assert!(body_hue_near(&image, at, 3), "no {name} at {at:?}");
    }
    // The loop is drawn where it is.
    let [hoop] = report.space_curves.as_slice() else {
        panic!("one curve in space, got {}", report.space_curves.len());
    };
    let wire_colour = rgb(wirebead::gui::SceneStyle::default().wire);
    let on = hoop
        .iter()
        .filter(|p| colour_near(&image, **p, 3, wire_colour))
        .count();
    assert!(
        on as f64 > 0.5 * hoop.len() as f64 && hoop.len() > 50,
        "the loop's colour at {on} of its {} points",
        hoop.len()
    );
}

#[test]
#[ignore = "needs the xdotool drag .ci/run makes under Xvfb"]
fn a_real_mouse_drag_pulls_a_rigid_body_by_the_point_taken() {
    let ready = report("body_drag_ready.ron");
    assert_eq!(ready.preset.as_deref(), Some("Cart on a hoop"));
    let drag = report("body_drag.ron")
        .drag
        .expect("the drag never took the cart through picking");
    // The cart, taken at its centre, is held on its unit hoop about the
    // origin: the nearest it can come to the cursor is the hoop's point
    // nearest it.
    let [x, y, _] = drag.bead_start;
    assert!(
        (x.hypot(y) - 1.0).abs() < 0.05,
        "the point taken, {:?}, is not the cart's centre on its hoop",
        drag.bead_start
    );
    let [x, y, _] = drag.target;
    let nearest = (x.hypot(y) - 1.0).abs();
    assert!(
        drag.closest_distance < nearest + 0.05 && drag.closest_distance < drag.start_distance - 0.5,
        "the cart came no closer than {:.3} to the cursor (from {:.3}; the hoop's nearest point is {nearest:.3} from it)",
        drag.closest_distance,
        drag.start_distance
    );
}
