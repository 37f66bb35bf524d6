//! What the tests of scene runs share: a run written by `simulate --scene`
//! beside the same run exported from the window's timeline.

use wirebead::geometry::Coordinates;
use wirebead::prelude::*;
use wirebead_analysis as analysis;

/// `simulate --scene`'s CSV of `scene` over `steps` steps, and the CSV the
/// window's export writes of the same run recorded by a `TimelinePlugin`
/// (its beads' columns, and with avian its moving bodies').
pub fn both_csvs<S: analysis::Scene>(
    scene: &S,
    file: &wirebead::SceneFile,
    steps: u32,
) -> (String, String) {
    use wirebead::headless::{Headless, idle, run_steps};
    use wirebead::plugin::Timeline;
    let params = scene.params().clone();
    let dt = params.timestep;
    let run = analysis::simulate_scene(scene, params.clone(), f64::from(steps) * dt).unwrap();
    let mut simulated = Vec::new();
    wirebead::preset::table::write_scene_csv(&mut simulated, &run).unwrap();

    let mut headless = Headless::new(WireBeadPlugin::new(params).unwrap()).single_threaded();
    if !scene.body_names().is_empty() {
        headless = headless.bodies(S::V::DIMENSION == 3);
    }
    let mut app = headless.timeline().build();
    let (beads, bodies) = scene.spawn_recorded(&mut app.world_mut().commands());
    app.world_mut().flush();
    idle(&mut app);
    run_steps(&mut app, steps);
    let timeline = app.world().resource::<Timeline>();
    let mut exported = Vec::new();
    let rows = wirebead::preset::table::write_recorded_csv(
        &mut exported,
        file,
        (&beads, &bodies),
        timeline,
    )
    .unwrap();
    assert_eq!(rows, steps as usize + 1, "t = 0 and every step");
    (
        String::from_utf8(simulated).unwrap(),
        String::from_utf8(exported).unwrap(),
    )
}
