//! Several beads on several wires, moved and rotated; custom curves; the
//! Transform writeback; determinism.

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};

use crate::common::*;
use bevy::math::{DMat2, DVec2};
use bevy::prelude::*;
use wirebead::geometry::{Placed, Pose};
use wirebead::pose_of;
use wirebead::prelude::*;
use wirebead::{BeadForce, ImplicitCurve, Integrator, SpringAnchor, Stabilization, WireBeads};

/// A circle written as a game would write its own curve:
/// `C = (|x|² - r²) / (2r)`.
struct SquaredCircle(f64);

impl ImplicitCurve for SquaredCircle {
    fn value(&self, p: DVec2) -> f64 {
        (p.length_squared() - self.0 * self.0) / (2.0 * self.0)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        p / self.0
    }
    fn hessian(&self, _p: DVec2) -> DMat2 {
        DMat2::IDENTITY / self.0
    }
    fn scale(&self) -> f64 {
        self.0
    }
}

/// Wires of every shape, moved and rotated, with beads placed on them
/// (in local coordinates, then mapped to the world).
fn many_wires(app: &mut App) -> Vec<(Entity, Entity)> {
    let wires = [
        (
            Wire::circle(1.0).unwrap(),
            DVec2::new(0.0, 0.0),
            0.0,
            DVec2::new(0.6, -0.8),
        ),
        (
            Wire::circle(2.0).unwrap(),
            DVec2::new(5.0, 1.0),
            0.5,
            DVec2::new(2.0, 0.0),
        ),
        (
            Wire::ellipse(2.0, 1.0).unwrap(),
            DVec2::new(-4.0, 2.0),
            0.3,
            DVec2::new(2.0, 0.0),
        ),
        (
            Wire::line(),
            DVec2::new(0.0, 6.0),
            -0.4,
            DVec2::new(0.0, 0.0),
        ),
        (
            Wire::parabola(0.5).unwrap(),
            DVec2::new(3.0, -4.0),
            0.2,
            DVec2::new(1.0, 0.5),
        ),
        (
            Wire::sine(0.4, 2.0).unwrap(),
            DVec2::new(-6.0, -3.0),
            -0.25,
            DVec2::new(0.0, 0.0),
        ),
        (
            Wire::custom(SquaredCircle(1.5)),
            DVec2::new(8.0, -2.0),
            1.0,
            DVec2::new(0.0, -1.5),
        ),
    ];
    wires
        .into_iter()
        .map(|(wire, origin, angle, local_start)| {
            let pose = Pose::new(origin, angle);
            let transform = Transform::from_xyz(origin.x as f32, origin.y as f32, 0.0)
                .with_rotation(Quat::from_rotation_z(angle as f32));
            let wire_entity = spawn_wire(app, wire, transform);
            let bead = spawn_bead(
                app,
                wire_entity,
                BeadParams {
                    mass: 0.5,
                    initial_position: pose.to_world(local_start),
                    initial_velocity: DVec2::ZERO,
                },
            );
            (wire_entity, bead)
        })
        .collect()
}

#[test]
fn each_bead_stays_on_its_own_moved_and_rotated_wire() {
    for (method, tolerance) in [
        (Method::Rattle, 1e-10),
        (Method::SemiImplicitEuler(Stabilization::Projection), 1e-10),
        (Method::Rk4(Stabilization::Baumgarte), 1e-3),
        (Method::SemiImplicitEuler(Stabilization::Baumgarte), 5e-2),
    ] {
        let mut app = app(params(method, 1.0 / 120.0));
        let pairs = many_wires(&mut app);
        run_for(&mut app, 3.0);
        for (wire_entity, bead_entity) in pairs {
            assert!(app.world().get::<Diverged>(bead_entity).is_none());
            let wire = app.world().get::<Wire>(wire_entity).unwrap();
            let transform = app.world().get::<Transform>(wire_entity).unwrap();
            let placed = Placed {
                curve: wire.shape().curve(),
                pose: pose_of(transform).unwrap(),
            };
            let b = bead(&app, bead_entity);
            let drift = placed.value(b.position).abs() / placed.scale();
            assert!(
                drift <= tolerance,
                "{method}: bead on the {} is {drift:e} scales off",
                wire.shape().name()
            );
            // It moved: gravity pulled it along its wire.
            assert!((b.position - b.params.initial_position).length() > 1e-3);
            // Its Transform is its f64 position, rounded to f32.
            let t = app
                .world()
                .get::<Transform>(bead_entity)
                .unwrap()
                .translation;
            assert_eq!((t.x, t.y), (b.position.x as f32, b.position.y as f32));
        }
    }
}

#[test]
fn beads_sharing_a_wire_are_its_beads() {
    let mut app = app(SimParams::default());
    let wire = spawn_wire(&mut app, Wire::circle(1.0).unwrap(), Transform::default());
    let a = spawn_bead(
        &mut app,
        wire,
        BeadParams {
            initial_position: DVec2::new(1.0, 0.0),
            ..default()
        },
    );
    let b = spawn_bead(
        &mut app,
        wire,
        BeadParams {
            initial_position: DVec2::new(-1.0, 0.0),
            ..default()
        },
    );
    let beads: Vec<Entity> = app.world().get::<WireBeads>(wire).unwrap().iter().collect();
    assert_eq!(beads, vec![a, b]);
    run_for(&mut app, 1.0);
    // Released symmetrically, they mirror each other.
    let (pa, pb) = (bead(&app, a).position, bead(&app, b).position);
    assert!((pa.x + pb.x).abs() < 1e-12 && (pa.y - pb.y).abs() < 1e-12);
    // Despawning the wire takes its beads.
    app.world_mut().entity_mut(wire).despawn();
    assert!(app.world().get_entity(a).is_err() && app.world().get_entity(b).is_err());
}

fn state_hash(integrator: Integrator) -> u64 {
    let method = Method::new(integrator, None).unwrap();
    let mut app = app(params(method, 1.0 / 60.0));
    let pairs = many_wires(&mut app);
    let dragged = pairs[0].1;
    app.world_mut()
        .entity_mut(dragged)
        .insert(SpringAnchor::new(DVec2::new(1.5, 0.5)).unwrap());
    run_steps(&mut app, 90);
    app.world_mut().entity_mut(dragged).remove::<SpringAnchor>();
    run_steps(&mut app, 90);
    let mut hasher = DefaultHasher::new();
    for (_, b) in pairs {
        let bead = bead(&app, b);
        for v in [bead.position, bead.velocity] {
            v.x.to_bits().hash(&mut hasher);
            v.y.to_bits().hash(&mut hasher);
        }
    }
    hasher.finish()
}

#[test]
fn same_inputs_give_bit_identical_state() {
    for &integrator in Integrator::ALL {
        assert_eq!(
            state_hash(integrator),
            state_hash(integrator),
            "{integrator}"
        );
    }
    assert_ne!(state_hash(Integrator::Rk4), state_hash(Integrator::Rattle));
}

/// The force each bead has accumulated when the step starts.
#[derive(Resource, Default)]
struct ForceAtStepStart(Vec<DVec2>);

fn record_force(beads: Query<&BeadForce>, mut seen: ResMut<ForceAtStepStart>) {
    seen.0.extend(beads.iter().map(|b| b.get().0));
}

#[test]
fn drag_pulls_the_bead_toward_the_target_and_release_stops_it() {
    let mut app = app(SimParams {
        gravity: DVec2::ZERO,
        ..default()
    });
    app.init_resource::<ForceAtStepStart>().add_systems(
        FixedUpdate,
        record_force
            .after(WireBeadSystems::Forces)
            .before(WireBeadSystems::Step),
    );
    let wire = spawn_wire(&mut app, Wire::circle(1.0).unwrap(), Transform::default());
    let b = spawn_bead(
        &mut app,
        wire,
        BeadParams {
            initial_position: DVec2::new(0.0, -1.0),
            ..default()
        },
    );
    let target = DVec2::new(1.0, 0.0);
    app.world_mut()
        .entity_mut(b)
        .insert(SpringAnchor::new(target).unwrap());
    run_steps(&mut app, 1);
    // The assignment's force, k (target - x), accumulated at the step's start and
    // consumed by the step.
    let k = app.world().resource::<SimParams>().drag_stiffness;
    let seen = |app: &App| *app.world().resource::<ForceAtStepStart>().0.last().unwrap();
    assert_eq!(seen(&app), k * (target - DVec2::new(0.0, -1.0)));
    assert_eq!(bead(&app, b).force, (DVec2::ZERO, 0.0));
    run_steps(&mut app, 60);
    // With no friction it swings about the target; it comes close to it.
    let start = (DVec2::new(0.0, -1.0) - target).length();
    let closest = app
        .world()
        .resource::<Recording>()
        .of(b)
        .iter()
        .map(|s| (s.position - target).length())
        .fold(f64::INFINITY, f64::min);
    assert!(
        closest < 0.2 * start,
        "closest approach {closest} from {start}"
    );
    app.world_mut().entity_mut(b).remove::<SpringAnchor>();
    run_steps(&mut app, 1);
    assert_eq!(seen(&app), DVec2::ZERO);
}

/// `C` of a bead at `p` on a circle of radius `r` centred at `o`.
fn circle_c(p: DVec2, o: DVec2, r: f64) -> f64 {
    (p - o).length() - r
}

#[test]
fn a_wire_moved_reshaped_or_taken_away_between_steps_is_what_its_beads_see() {
    let mut app = app(SimParams::default());
    let b = circle_bead(&mut app, 1.0, DVec2::new(1.0, 0.0), DVec2::ZERO);
    let wire = app.world().get::<OnWire>(b).unwrap().0;
    run_steps(&mut app, 10);
    let c = diagnostics(&app, b).c;
    assert!(c.abs() < 1e-3, "on its wire: C = {c}");

    // Moved: the next step measures C from the new centre.
    let centre = DVec2::new(f64::from(0.2f32), 0.0);
    app.world_mut()
        .entity_mut(wire)
        .insert(Transform::from_xyz(0.2, 0.0, 0.0));
    run_steps(&mut app, 1);
    let (p, c) = (bead(&app, b).position, diagnostics(&app, b).c);
    let expected = circle_c(p, centre, 1.0);
    assert!(expected.abs() > 0.05, "the move puts the bead off the wire");
    assert!(
        (c - expected).abs() < 1e-12,
        "C = {c}, from the moved wire {expected}"
    );

    // Reshaped: the next step uses the new radius.
    app.world_mut()
        .entity_mut(wire)
        .insert(Wire::circle(1.5).unwrap());
    run_steps(&mut app, 1);
    let (p, c) = (bead(&app, b).position, diagnostics(&app, b).c);
    let expected = circle_c(p, centre, 1.5);
    assert!(
        expected < -0.3,
        "the new radius puts the bead inside: {expected}"
    );
    assert!(
        (c - expected).abs() < 1e-12,
        "C = {c}, on the new radius {expected}"
    );

    // Taken away: the bead stops with a reason in words.
    app.world_mut().entity_mut(wire).remove::<Wire>();
    let before = bead(&app, b).position;
    run_steps(&mut app, 1);
    let diverged = app.world().get::<Diverged>(b).expect("diverged");
    assert!(
        matches!(&diverged.reason, wirebead::DivergenceReason::InvalidWire(why) if why.contains("has no Wire")),
        "{}",
        diverged.reason
    );
    assert_eq!(
        bead(&app, b).position,
        before,
        "a stopped bead keeps its state"
    );
}

/// Moves every bead to (0.25, -0.5) after the step, before the writeback.
fn move_after_step(mut beads: Query<&mut BeadPosition>) {
    for mut position in &mut beads {
        position.0 = DVec2::new(0.25, -0.5);
    }
}

#[test]
fn the_transform_follows_a_bead_moved_after_the_step_too() {
    let mut app = app(SimParams::default());
    let b = pendulum(&mut app, 1.0, 0.5);
    run_steps(&mut app, 5);
    let stepped = bead(&app, b).position;
    let t = app.world().get::<Transform>(b).unwrap().translation;
    assert_eq!((t.x, t.y), (stepped.x as f32, stepped.y as f32));
    app.add_systems(
        FixedUpdate,
        move_after_step
            .after(WireBeadSystems::Step)
            .before(WireBeadSystems::Writeback),
    );
    run_steps(&mut app, 1);
    let t = app.world().get::<Transform>(b).unwrap().translation;
    assert_eq!((t.x, t.y), (0.25, -0.5));
}

#[test]
fn a_bead_put_where_it_cannot_step_shows_where_it_was_put() {
    let mut app = app(SimParams::default());
    let b = pendulum(&mut app, 1.0, 0.5);
    run_steps(&mut app, 5);
    // The centre of its circle, where the constraint has no normal.
    app.world_mut().get_mut::<BeadPosition>(b).unwrap().0 = DVec2::ZERO;
    run_steps(&mut app, 1);
    let diverged = app.world().get::<Diverged>(b).expect("diverged");
    assert!(
        diverged.reason.to_string().contains("singular"),
        "{}",
        diverged.reason
    );
    assert_eq!(bead(&app, b).position, DVec2::ZERO);
    let t = app.world().get::<Transform>(b).unwrap().translation;
    assert_eq!((t.x, t.y), (0.0, 0.0));
}
