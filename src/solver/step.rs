//! One whole step of one bead: the method's integrator, the divergence
//! check, the projection where the method asks for it, and `C`, `Ċ` at the
//! end.

use bevy::math::DVec2;

use super::euler::Euler;
use super::method::Method;
use super::projection::project_on;
use super::rattle::rattle_on;
use super::restore::restore;
use super::rk4::rk4_on;
use super::settings::StepSettings;
use super::solve::{SolveError, solve_on};
use super::state::{BeadState, LinearForce};
use crate::geometry::{Coordinates, FixedTrack, ImplicitCurve, Track};
use crate::lane::Lane;

/// The result of one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutput<V = DVec2> {
    /// The new state.
    pub state: BeadState<V>,
    /// The constraint multiplier the step applied (for RATTLE the mean of
    /// its position and velocity multipliers).
    pub lambda: f64,
    /// The constraint force the step applied.
    pub constraint_force: V,
    /// `C` at the new state.
    pub c: f64,
    /// `Ċ` at the new state.
    pub c_dot: f64,
}

/// One step of a bead of mass `mass` from `state` on `curve` under
/// `force` (gravity included): the method's integrator, then the
/// divergence check (a non-finite state, or `|C|` past the bound), then
/// post-stabilization where the method projects.
#[inline(always)]
pub fn step<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
    force: &LinearForce,
    mass: f64,
    settings: &StepSettings,
) -> Result<StepOutput, SolveError> {
    step_on(&FixedTrack(curve), 0.0, state, force, mass, settings)
}

/// [`step`] on a wire that may move (see [`Track`]), the step starting at
/// time `t`: a curve in the plane or a surface in space. Every method takes the wire's motion into account: the
/// explicit ones through eq. (3) in the wire's frame at each stage's time,
/// RATTLE and projection by solving `C(x, t + h) = 0` and
/// `∇C·(ẋ − w) = 0` at the step's end. On a moving wire eq. (10) restores
/// the speed relative to the wire, and eq. (11) is not applied: a moving
/// wire does work on the bead, so there is no energy to keep.
#[inline(always)]
pub fn step_on<V: Coordinates, T: Track<V> + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState<V>,
    force: &LinearForce<V>,
    mass: f64,
    settings: &StepSettings,
) -> Result<StepOutput<V>, SolveError> {
    let h = settings.dt;
    let t1 = t + h;
    let gains = settings.gains();
    let advance = match (settings.method, Euler::of(settings.method)) {
        (Method::Rattle, _) => rattle_on(track, t, state, force, mass, h)?,
        (_, Some(euler)) => {
            euler.advance(state, &solve_on(track, t, state, force, mass, gains)?, h)
        }
        // RK4.
        _ => {
            let first = solve_on(track, t, state, force, mass, gains)?;
            rk4_on(track, t, state, force, mass, gains, &first, h)?
        }
    };
    if !advance.state.is_finite() {
        return Err(SolveError::NonFinite);
    }
    let g = track.geometry(t1, advance.state.position);
    let (bound, within) = drift_check(settings, g.c, track.scale());
    if !within {
        return Err(SolveError::DriftExceeded { c: g.c, bound });
    }
    let (state, (c, c_dot)) = if settings.method.projects() {
        let projected = project_on(track, t1, advance.state)?;
        let euler = settings.method.is_euler();
        let projected = restore(track, t, h, euler, state, projected, force, mass)?;
        (projected, constraint_state_on(track, t1, projected))
    } else {
        let relative = if T::MOVES {
            advance.state.velocity - track.twist(t1).velocity_at(advance.state.position)
        } else {
            advance.state.velocity
        };
        (advance.state, (g.c, g.normal.dot(relative)))
    };
    Ok(StepOutput {
        state,
        lambda: advance.lambda,
        constraint_force: advance.constraint_force,
        c,
        c_dot,
    })
}

/// The divergence check, for a lone bead, the lanes and each row of an
/// island: the drift bound of a constraint of size `scale`, and whether
/// the `C` a step left is within it (not where `C` or the bound is NaN).
#[inline(always)]
pub(crate) fn drift_check<T: Lane>(settings: &StepSettings, c: T, scale: T) -> (T, T::Mask) {
    let bound = scale.splat(settings.drift_bound) * scale;
    (bound, c.abs_le(bound))
}

/// `C` and `Ċ = N·ẋ` at a state: how far off its wire the bead is, and how
/// fast it leaves it.
pub fn constraint_state<C: ImplicitCurve + ?Sized>(curve: &C, state: BeadState) -> (f64, f64) {
    constraint_state_on(&FixedTrack(curve), 0.0, state)
}

/// `C` and `Ċ = ∇C·(ẋ − w)` at a state on a wire that may move, at time
/// `t`.
pub fn constraint_state_on<V: Coordinates, T: Track<V> + ?Sized>(
    track: &T,
    t: f64,
    state: BeadState<V>,
) -> (f64, f64) {
    let g = track.geometry(t, state.position);
    let relative = if T::MOVES {
        state.velocity - track.twist(t).velocity_at(state.position)
    } else {
        state.velocity
    };
    (g.c, g.normal.dot(relative))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Circle, Sine};
    use crate::solver::Stabilization;
    use crate::solver::newton::NEWTON_ACCEPT;
    use crate::solver::test_support::{G, settings};

    #[test]
    fn singular_point_is_an_error_not_a_nan() {
        let circle = Circle { radius: 1.0 };
        let state = BeadState::default();
        for method in Method::ALL {
            let err = step(
                &circle,
                state,
                &LinearForce::constant(G),
                1.0,
                &settings(method, 0.01),
            )
            .unwrap_err();
            assert_eq!(err, SolveError::Singular { x: 0.0, y: 0.0 });
        }
    }

    #[test]
    fn rattle_and_projection_hold_the_constraint_to_tolerance() {
        let sine = Sine {
            amplitude: 0.5,
            wavelength: 3.0,
        };
        for method in [
            Method::Rattle,
            Method::SemiImplicitEuler(Stabilization::Projection),
            Method::Rk4(Stabilization::Projection),
        ] {
            let mut state = BeadState {
                position: DVec2::new(0.0, 0.0),
                velocity: DVec2::new(2.0, 2.0 * 0.5 * std::f64::consts::TAU / 3.0),
            };
            let s = settings(method, 1.0 / 60.0);
            for _ in 0..600 {
                state = step(&sine, state, &LinearForce::constant(G), 1.0, &s)
                    .unwrap()
                    .state;
                let (drift, drift_rate) = constraint_state(&sine, state);
                assert!(
                    drift.abs() <= NEWTON_ACCEPT * 3.0,
                    "{method}: C = {drift:e}"
                );
                assert!(drift_rate.abs() <= 1e-12, "{method}: Ċ = {drift_rate:e}");
            }
        }
    }

    #[test]
    fn rk4_is_fourth_order_on_the_pendulum() {
        // Halving dt divides the end-point error by about 16.
        let circle = Circle { radius: 1.0 };
        let start = BeadState {
            position: DVec2::new(1.0, 0.0),
            velocity: DVec2::ZERO,
        };
        let run = |dt: f64| {
            let s = settings(Method::Rk4(Stabilization::None), dt);
            let mut state = start;
            for _ in 0..(1.0 / dt).round() as usize {
                state = step(&circle, state, &LinearForce::constant(G), 1.0, &s)
                    .unwrap()
                    .state;
            }
            state.position
        };
        let reference = run(1.0 / 2560.0);
        let e1 = (run(1.0 / 80.0) - reference).length();
        let e2 = (run(1.0 / 160.0) - reference).length();
        let order = (e1 / e2).log2();
        assert!((3.7..4.3).contains(&order), "observed order {order}");
    }

    /// The largest energy change, in m·g·r, of a unit bead released from
    /// rest at `start` on the unit circle, 600 steps of 1/60 s.
    fn pendulum_energy_error(method: Method, start: DVec2) -> f64 {
        let circle = Circle { radius: 1.0 };
        let energy = |s: &BeadState| {
            let (kinetic, potential) = s.energy(1.0, G);
            kinetic + potential
        };
        let s = settings(method, 1.0 / 60.0);
        let start = BeadState {
            position: start,
            velocity: DVec2::ZERO,
        };
        let mut state = start;
        let mut worst = 0.0f64;
        for _ in 0..600 {
            state = step(&circle, state, &LinearForce::constant(G), 1.0, &s)
                .unwrap()
                .state;
            worst = worst.max((energy(&state) - energy(&start)).abs() / 9.81);
        }
        worst
    }

    #[test]
    fn euler_with_projection_adds_no_energy_on_the_pendulum() {
        // The 135° pendulum (r = 1) for 10 s at 1/60 s: without eq. (10)
        // semi-implicit Euler with projection gained 184 m·g·r; with it the
        // energy stays within a few hundredths of m·g·r, for both Euler
        // steps.
        let theta0 = 135f64.to_radians();
        let start = DVec2::new(theta0.sin(), -theta0.cos());
        for (method, bound) in [
            (Method::SemiImplicitEuler(Stabilization::Projection), 0.05),
            (Method::ExplicitEuler(Stabilization::Projection), 1.0),
        ] {
            let worst = pendulum_energy_error(method, start);
            assert!(worst < bound, "{method}: energy moved {worst} m·g·r");
        }
    }

    #[test]
    fn rk4_with_projection_keeps_the_pendulums_energy_to_rounding() {
        // Eq. (11): the 135° pendulum (r = 1) for 10 s at 1/60 s keeps its
        // energy to 1e-12 m·g·r (RK4 alone: 8.6e-6), and a bead at rest
        // at the bottom stays at rest.
        let theta0 = 135f64.to_radians();
        for (start, bound) in [
            (DVec2::new(theta0.sin(), -theta0.cos()), 1e-12),
            (DVec2::new(0.0, -1.0), 1e-15),
        ] {
            let worst = pendulum_energy_error(Method::Rk4(Stabilization::Projection), start);
            assert!(
                worst < bound,
                "from {start:?}: energy moved {worst:e} m·g·r"
            );
        }
    }

    /// A bead on a line spinning at ω about a point of it, with no
    /// gravity, from rest on the line at r₀, slides out as
    /// `r₀ cosh(ωt)` (docs/method.md, "Moving wires"). Every method
    /// follows it to its order, and the constraint-holding ones stay on
    /// the turning line.
    #[test]
    fn a_bead_on_a_spinning_rod_slides_out_as_cosh() {
        use crate::geometry::{Line, MovingTrack, Pose, PosePath, Spin, WireMotion};
        let omega = 2.0;
        let path = PosePath::Prescribed {
            base: Pose::IDENTITY,
            motion: WireMotion::Spin(Spin {
                angular_velocity: omega,
            }),
        };
        let track = MovingTrack {
            curve: &Line,
            path: &path,
        };
        let (r0, end) = (0.5, 1.5);
        let exact = r0 * (omega * end).cosh();
        let run = |method: Method, dt: f64| {
            let s = settings(method, dt);
            let position = DVec2::new(r0, 0.0);
            let mut state = BeadState {
                position,
                velocity: path.at(0.0).1.velocity_at(position),
            };
            let steps = (end / dt).round() as usize;
            let mut worst_c = 0.0f64;
            for k in 0..steps {
                let out = step_on(
                    &track,
                    k as f64 * dt,
                    state,
                    &LinearForce::default(),
                    1.0,
                    &s,
                )
                .unwrap();
                state = out.state;
                worst_c = worst_c.max(out.c.abs());
            }
            ((state.position.length() - exact).abs() / exact, worst_c)
        };
        for (method, order, on_wire) in [
            (
                Method::SemiImplicitEuler(Stabilization::Baumgarte),
                1.0,
                5e-2,
            ),
            (
                Method::SemiImplicitEuler(Stabilization::Projection),
                1.0,
                1e-12,
            ),
            (Method::Rk4(Stabilization::None), 4.0, 1e-6),
            (Method::Rk4(Stabilization::Projection), 4.0, 1e-12),
            (Method::Rattle, 2.0, 1e-12),
        ] {
            let (e1, c1) = run(method, 1.0 / 200.0);
            let (e2, _) = run(method, 1.0 / 400.0);
            let observed = (e1 / e2).log2();
            eprintln!("{method}: error at 1/200 s {e1:e}, order {observed:.3}, |C| {c1:e}");
            assert!(
                (observed - order).abs() < 0.3,
                "{method}: relative errors {e1:e}, {e2:e}, order {observed}"
            );
            assert!(c1 <= on_wire, "{method}: |C| reached {c1:e}");
        }
    }
}
