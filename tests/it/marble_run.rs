//! The marble run in space ([`MarbleRun`]): marbles roll down a rail,
//! leave it at its end, drop into a bowl that catches them, and are sent
//! back to the top once they settle ([`SendsBeadsBack`]).

use bevy::math::{DVec2, DVec3};
use bevy::prelude::*;
use wirebead::headless::{Headless, run_steps};
use wirebead::prelude::*;
use wirebead::preset::{MARBLE_BOWL, MarbleRun, PILE_RADIUS};
use wirebead::solver::Contact;
use wirebead::{SceneEnergy, SceneFile, ScenePreset, SendsBeadsBack, WireContact};

/// A run of `marbles`, headless, with its scene energy kept: the app and
/// the marbles.
fn run_of(marbles: usize) -> (App, Vec<Entity>) {
    let scene = MarbleRun {
        marbles,
        ..MarbleRun::default()
    }
    .scene()
    .unwrap_or_else(|e| panic!("{e}"));
    let plugin = WireBeadPlugin::new(scene.params.0.clone()).expect("valid params");
    let mut app = Headless::new(plugin).single_threaded().build();
    app.init_resource::<SceneEnergy>();
    let spawned = scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    (app, spawned)
}

/// The worst overlap of any two marbles, in radii.
fn worst_overlap(at: &[DVec3]) -> f64 {
    let mut worst = f64::MIN;
    for (i, &a) in at.iter().enumerate() {
        for &b in &at[i + 1..] {
            worst = worst.max((2.0 * PILE_RADIUS - (b - a).length()) / PILE_RADIUS);
        }
    }
    worst
}

/// Forty marbles, RATTLE at 240 Hz for 8 s: the twelve that start on the
/// rail roll down it and drop into the bowl, and the rail sends settled
/// marbles back to its top, one at a time as the top clears, to roll
/// down again. At no step do two marbles overlap by more than 1e-9 of a
/// radius, and none leaves the bowl (its centre never farther from the
/// bowl's than the bowl's radius, to 1e-9 of a marble's). Each marble
/// sent back is put at the rail's top at rest, held on the rail, and
/// rides it alone (the one before is ahead by the same time): every ride
/// from the top to the rail's end takes the same time to a step, and
/// leaves the end with the speed its fall gives it, `½ v² = g Δy` to
/// 5e-3 of the rail's drop (RATTLE's energy error where the rail turns in
/// at 3 m/s, second order in the step). The energy rises only where a
/// marble is sent back (by its lift): between, it never rises above the
/// lowest it has been by more than that same error, a hundredth of one
/// marble's weight times the rail's drop.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes in a debug build: run with --release"
)]
fn a_marble_run_in_space_sends_its_marbles_round_and_round() {
    let (n, rate, seconds) = (40, 240, 8);
    let (mut app, marbles) = run_of(n);
    let world = app.world_mut();
    let back = *world
        .query::<&SendsBeadsBack<DVec3>>()
        .single(world)
        .expect("the rail sends marbles back");
    let top = back.to();
    let drop = top.y - MarbleRun::rail().last().expect("a rail").y;
    let g = 9.81;
    let state = |app: &mut App| -> Vec<(DVec3, DVec3, bool)> {
        let world = app.world_mut();
        marbles
            .iter()
            .map(|&m| {
                let x = world.get::<BeadPosition<DVec3>>(m).expect("a marble").0;
                let v = world.get::<BeadVelocity<DVec3>>(m).expect("a marble").0;
                let on = world.get::<WireContact>(m).expect("a marble").get() == Contact::OnWire;
                (x, v, on)
            })
            .collect()
    };
    let mut before = state(&mut app);
    // The step each marble was last sent back at, while it rides.
    let mut riding: Vec<Option<usize>> = vec![None; n];
    let (mut sends, mut rides, mut fall) = (0, Vec::new(), 0.0f64);
    let (mut worst, mut outside) = (f64::MIN, f64::MIN);
    // The energy less what the sends gave, and the most it rose above
    // its lowest.
    let mut energy = app.world().resource::<SceneEnergy>().total;
    let (mut given, mut lowest, mut above) = (0.0, f64::INFINITY, 0.0f64);
    let steps = seconds * rate;
    for step in 1..=steps {
        run_steps(&mut app, 1);
        let now = state(&mut app);
        let e = app.world().resource::<SceneEnergy>().total;
        let mut sent = false;
        for k in 0..n {
            let ((x, v, on), (was, _, held)) = (now[k], before[k]);
            // Put at the top and stepped once from there.
            let near = |x: DVec3| (x - top).length() <= PILE_RADIUS;
            if near(x) && !near(was) {
                assert!(on, "step {step}: marble {} sent back off the rail", k + 1);
                riding[k] = Some(step);
                sends += 1;
                sent = true;
            }
            if held
                && !on
                && let Some(from) = riding[k].take()
            {
                rides.push(step - from);
                // Free flight keeps ½ v² + g y: what the fall gave.
                let gained = 0.5 * v.length_squared() + g * (x.y - top.y);
                fall = fall.max(gained.abs() / (g * drop));
            }
            outside = outside.max(((x.length() - MARBLE_BOWL) / PILE_RADIUS).max(0.0));
        }
        if sent {
            given += e - energy;
        }
        energy = e;
        lowest = lowest.min(e - given);
        above = above.max(e - given - lowest);
        let positions: Vec<DVec3> = now.iter().map(|s| s.0).collect();
        let overlap = worst_overlap(&positions);
        assert!(
            overlap <= 1e-9,
            "step {step}: marbles overlap by {overlap:e} of a radius"
        );
        worst = worst.max(overlap);
        before = now;
    }
    let world = app.world_mut();
    let stopped = world.query::<&Diverged>().iter(world).count();
    let (shortest, longest) = (rides.iter().min(), rides.iter().max());
    eprintln!(
        "marble run of {n}: {sends} sends, rides of {shortest:?} to {longest:?} steps, \
         fall {fall:e} of the drop, overlap {worst:e}, outside {outside:e}, energy above its \
         lowest between sends {above:e} J"
    );
    assert_eq!(stopped, 0, "marbles stopped");
    assert!(
        sends >= n / 2,
        "only {sends} marbles were sent back in {seconds} s"
    );
    let (Some(&shortest), Some(&longest)) = (shortest, longest) else {
        panic!("no marble sent back rode to the rail's end");
    };
    assert!(
        longest - shortest <= 1,
        "rides of {shortest} to {longest} steps"
    );
    let stuck = riding
        .iter()
        .flatten()
        .filter(|&&from| steps - from > longest)
        .count();
    assert_eq!(stuck, 0, "marbles sent back that never left the rail");
    assert!(
        fall <= 5e-3,
        "a marble left the rail {fall:e} of its drop off its fall"
    );
    assert!(
        outside <= 1e-9,
        "a marble left the bowl by {outside:e} of a radius"
    );
    let weight = MarbleRun::MASS * g;
    assert!(
        above <= 1e-2 * weight * drop,
        "the energy rose {above:e} J above its lowest between sends"
    );
}

/// The shipped `marble_run_in_space.scene.ron` is the marble run preset
/// of 200 marbles ([`MarbleRun`]): read back, it writes the same scene
/// file, to the digit.
#[test]
fn the_shipped_marble_run_is_the_preset_of_200_marbles() {
    let made = MarbleRun::default()
        .scene()
        .unwrap_or_else(|e| panic!("{e}"));
    crate::presets::assert_shipped_is("marble_run_in_space.scene.ron", SceneFile::Space(made));
}

/// In the plane as in space: a marble of 2 cm rides an open ramp (a
/// Catmull–Rom spline) down from its top, flies off its end, lands in a
/// rough bowl that catches it (a one-sided circle with friction 0.5),
/// slides to rest there, and the ramp sends it back to its top, held on
/// it again; from there it goes round again. Each round starts from the
/// same state (at rest at the top, the bowl as it was), so each takes the
/// same time to a step (the clock's rounding decides the step it settles
/// at), and the marble is at the top, on the ramp, after each send.
#[test]
fn a_ramp_in_the_plane_sends_its_marble_back_round_after_round() {
    let top = DVec2::new(-0.8, 0.5);
    let text = format!(
        "(name: \"ramp\", params: (timestep: {:?}, integrator: Rattle), \
         wires: [(shape: Circle((radius: 1.0)), side: Negative, catches: true, \
         friction: (static: 0.5, kinetic: 0.5)), \
         (shape: Spline((kind: CatmullRom, points: [({:?}, {:?}), (-0.5, 0.25), (-0.2, 0.1)])), \
         sends_back: (to: ({:?}, {:?}), speed: 0.01, after: 0.1), \
         beads: [(name: \"marble\", mass: 0.01, radius: 0.02, initial_position: ({:?}, {:?}))])])",
        1.0 / 240.0,
        top.x,
        top.y,
        top.x,
        top.y,
        top.x,
        top.y
    );
    let scene = ScenePreset::from_ron(&text).unwrap_or_else(|e| panic!("{e}"));
    let plugin = WireBeadPlugin::new(scene.params.clone()).expect("valid params");
    let mut app = Headless::new(plugin).single_threaded().build();
    let marble = scene.spawn(&mut app.world_mut().commands())[0];
    app.world_mut().flush();
    let mut sends = Vec::new();
    let mut was = top;
    for step in 1..=6 * 240 {
        run_steps(&mut app, 1);
        let world = app.world();
        let at = world.get::<BeadPosition>(marble).expect("a marble").0;
        let on = world.get::<WireContact>(marble).expect("a marble").get() == Contact::OnWire;
        if (at - top).length() <= 0.01 && (was - top).length() > 0.01 {
            assert!(on, "step {step}: sent back off the ramp");
            sends.push(step);
        }
        assert!(
            at.length() <= 1.0 + 1e-9,
            "step {step}: the marble left the bowl: {at}"
        );
        was = at;
    }
    eprintln!("ramp in the plane: sent back at steps {sends:?}");
    assert!(sends.len() >= 2, "sent back {} times in 6 s", sends.len());
    let rounds: Vec<usize> = sends.windows(2).map(|w| w[1] - w[0]).collect();
    let first = sends[0];
    assert!(
        rounds.iter().all(|&r| r.abs_diff(first) <= 2),
        "rounds of {first} and then {rounds:?} steps"
    );
}
