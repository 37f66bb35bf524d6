//! The gizmo debug renderer draws what the simulation holds: a wire's
//! stroke on the wire, a rod between its beads' positions, a bead's circle
//! about the bead, read back from the gizmo buffer Bevy renders.

use bevy::asset::AssetPlugin;
use bevy::gizmos::config::DefaultGizmoConfigGroup;
use bevy::gizmos::{AppGizmoBuilder, GizmoAsset};
use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::debug_render::{DebugRenderStyle, WireBeadDebugPlugin};
use wirebead::plugin::compute_on_all_cores;
use wirebead::prelude::*;

use crate::common::run_steps;

/// Every segment end and strip vertex drawn in the last frame.
fn drawn(app: &App) -> Vec<Vec2> {
    let assets = app.world().resource::<Assets<GizmoAsset>>();
    assets
        .iter()
        .flat_map(|(_, gizmo)| {
            let buffer = gizmo.buffer();
            buffer
                .list_positions
                .iter()
                .chain(&buffer.strip_positions)
                .copied()
                .collect::<Vec<_>>()
        })
        .filter(|p| p.is_finite())
        .map(|p| p.truncate())
        .collect()
}

/// A headless app with the debug renderer, beads drawn 0.1 across.
fn debug_app() -> App {
    let mut app = App::new();
    app.add_plugins((
        // The process's task pools as every other test app asks for them.
        MinimalPlugins.set(TaskPoolPlugin {
            task_pool_options: compute_on_all_cores(),
        }),
        AssetPlugin::default(),
        WireBeadPlugin::default(),
        WireBeadDebugPlugin,
    ));
    // What `GizmoPlugin` sets up for the default gizmos, without the
    // gizmos of meshes and cameras a headless app has none of.
    app.init_asset::<GizmoAsset>()
        .init_gizmo_group::<DefaultGizmoConfigGroup>();
    app.insert_resource(DebugRenderStyle {
        bead_radius: 0.1,
        ..default()
    });
    app
}

#[test]
fn the_debug_renderer_draws_wires_rods_and_beads_where_they_are() {
    let mut app = debug_app();
    let world = app.world_mut();
    let centre = Vec2::new(2.0, 1.0);
    let wire = world
        .spawn((
            Wire::circle(1.5).unwrap(),
            Transform::from_xyz(2.0, 1.0, 0.0),
        ))
        .id();
    let on_wire = world
        .spawn((
            Bead::at_rest(1.0, DVec2::new(3.5, 1.0)).unwrap(),
            OnWire(wire),
        ))
        .id();
    let hanging = world
        .spawn(Bead::at_rest(1.0, DVec2::new(3.5, -0.5)).unwrap())
        .id();
    world.spawn(Rod::new(on_wire, hanging, 1.5).unwrap());
    run_steps(&mut app, 0);
    let points = drawn(&app);
    assert!(points.len() > 256, "only {} points drawn", points.len());
    // The wire: a closed strip of 257 points on the circle.
    let on_circle = points
        .iter()
        .filter(|p| ((**p - centre).length() - 1.5).abs() < 1e-5)
        .count();
    assert!(on_circle >= 257, "{on_circle} points on the wire");
    // The rod: a segment from one bead to the other.
    let near = |q: Vec2| points.iter().any(|p| (*p - q).length() < 1e-5);
    assert!(near(Vec2::new(3.5, 1.0)) && near(Vec2::new(3.5, -0.5)));
    // Each bead: a circle of the style's radius about it.
    for at in [Vec2::new(3.5, 1.0), Vec2::new(3.5, -0.5)] {
        let ring = points
            .iter()
            .filter(|p| ((**p - at).length() - 0.1).abs() < 1e-5)
            .count();
        assert!(ring >= 16, "{ring} points on the bead at {at}");
    }
}

/// A bead resting at the bottom of a circle gets its constraint force
/// drawn, an arrow of the style's length for its weight straight up; in a
/// scene of more beads than `force_arrows_up_to` (a pile) no arrow is.
#[test]
fn force_arrows_are_drawn_up_to_the_styles_count_of_beads() {
    for (others, drawn_arrow) in [(0, true), (64, false)] {
        let mut app = debug_app();
        let world = app.world_mut();
        let wire = world
            .spawn((Wire::circle(1.5).unwrap(), Transform::default()))
            .id();
        world.spawn((
            Bead::at_rest(1.0, DVec2::new(0.0, -1.5)).unwrap(),
            OnWire(wire),
        ));
        for k in 0..others {
            world.spawn(Bead::at_rest(1.0, DVec2::new(10.0 + k as f64, 0.0)).unwrap());
        }
        // The first update takes no step.
        run_steps(&mut app, 0);
        run_steps(&mut app, 1);
        let tip = Vec2::new(0.0, -1.5 + DebugRenderStyle::default().force_scale);
        let near = drawn(&app).iter().any(|p| (*p - tip).length() < 1e-2);
        assert_eq!(near, drawn_arrow, "{} beads", others + 1);
    }
}
