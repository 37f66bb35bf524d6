//! The constraint solve and the integrators, as pure functions over plain
//! values. Nothing here knows about the ECS.
//!
//! # The constraint force (seed eq. 1.9, any wire)
//!
//! A bead of mass `m` at `x` with velocity `ẋ` under an external force `f`
//! is kept on `C(x) = 0` by a force `λN`, `N = ∇C`. Differentiating twice,
//!
//! ```text
//! Ċ = N·ẋ,    C̈ = Ṅ·ẋ + N·ẍ,    Ṅ = H ẋ,    ẍ = (f + λN)/m.
//! ```
//!
//! Asking for `C̈ = -αC - βĊ` (Baumgarte) and solving for λ:
//!
//! ```text
//! λ = ( -m ẋᵀHẋ - m α C - m β N·ẋ - N·f ) / (N·N)              (1.9)
//! ```
//!
//! With α = β = 0 this is the exact force that keeps `C̈ = 0`. On the seed's
//! circle `N·N = 1` and `ẋᵀHẋ = |ẋ_t|²/|x|`, the centripetal term.
//!
//! # External forces
//!
//! Forces are accumulated once per step at the starting position `x₀` as a
//! [`LinearForce`]: a constant part plus an isotropic stiffness, so
//! `f(x) = F - S (x - x₀)`. Gravity is constant and the drag spring
//! `k (target - x)` is exactly linear, so multi-stage integrators (RK4,
//! RATTLE) evaluate the same force law the seed does at every stage.
//!
//! # RATTLE
//!
//! With `h` the step and `N₀ = ∇C(x₀)`:
//!
//! ```text
//! x₁ = x₀ + h v₀ + h²/(2m) (f(x₀) + λ N₀),     C(x₁) = 0   (Newton in λ)
//! v½ = (x₁ - x₀)/h
//! v₁ = v½ + h/(2m) (f(x₁) + μ N₁),             N₁·v₁ = 0  (linear in μ)
//! ```
//!
//! It is symmetric and symplectic, so the energy error stays bounded instead
//! of drifting, and both constraints hold to the Newton tolerance.
//!
//! # Post-stabilization (projection)
//!
//! After an unstabilized step, Newton steps along the gradient
//! `x ← x - C N/(N·N)` bring the position back to `C = 0`, then the normal
//! component of the velocity is removed (Cline & Pai 2003).

use bevy::math::DVec2;

use crate::params::{Integrator, Stabilization};
use crate::wire::{Geometry, ImplicitCurve};

/// Position and velocity of one bead.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BeadState {
    /// Position.
    pub position: DVec2,
    /// Velocity.
    pub velocity: DVec2,
}

impl BeadState {
    /// Both vectors finite.
    pub fn is_finite(&self) -> bool {
        self.position.is_finite() && self.velocity.is_finite()
    }
}

/// An external force linearized about the step's starting position:
/// `f(x) = force - stiffness (x - at)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinearForce {
    /// The force at `at`.
    pub force: DVec2,
    /// The isotropic stiffness `S` (a spring's k).
    pub stiffness: f64,
    /// Where `force` was evaluated.
    pub at: DVec2,
}

impl LinearForce {
    /// A force that does not depend on position.
    pub fn constant(force: DVec2) -> Self {
        Self {
            force,
            ..Self::default()
        }
    }

    /// `f(x)`.
    #[inline]
    pub fn at(&self, x: DVec2) -> DVec2 {
        self.force - self.stiffness * (x - self.at)
    }
}

/// Why a step could not be taken.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// `∇C` vanishes (or is not finite) where the bead is: there is no
    /// normal to push along.
    #[error("the bead is at a singular point of its wire ({x}, {y}), where the normal ∇C vanishes")]
    Singular {
        /// x of the point.
        x: f64,
        /// y of the point.
        y: f64,
    },
    /// The RATTLE or projection Newton iteration did not reach tolerance.
    #[error(
        "the constraint solve did not converge: |C| = {residual:e} after {iterations} iterations"
    )]
    NoConvergence {
        /// Newton iterations taken.
        iterations: u32,
        /// The remaining `|C|`.
        residual: f64,
    },
    /// The new state has a NaN or infinite component.
    #[error("the state became non-finite")]
    NonFinite,
    /// The step left the bead farther off its wire than the bound: the
    /// simulation has blown up.
    #[error("the bead drifted {c:.3e} off its wire, past the bound {bound:.3e}")]
    DriftExceeded {
        /// The drift `C` after the step (before any projection).
        c: f64,
        /// The bound, in world units.
        bound: f64,
    },
}

/// The constants a step needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepConfig {
    /// Step length `h` in seconds.
    pub dt: f64,
    /// Bead mass.
    pub mass: f64,
    /// Baumgarte α (used only with [`Stabilization::Baumgarte`]).
    pub alpha: f64,
    /// Baumgarte β (used only with [`Stabilization::Baumgarte`]).
    pub beta: f64,
    /// The integrator.
    pub integrator: Integrator,
    /// The stabilization.
    pub stabilization: Stabilization,
    /// The largest `|C|` a step may leave (in world units) before the run
    /// is declared blown up; checked before any projection.
    pub drift_bound: f64,
}

impl StepConfig {
    /// The (α, β) that enter eq. 1.9: the configured ones under Baumgarte,
    /// zero otherwise.
    pub fn gains(&self) -> (f64, f64) {
        match self.stabilization {
            Stabilization::Baumgarte => (self.alpha, self.beta),
            Stabilization::Projection | Stabilization::None => (0.0, 0.0),
        }
    }
}

/// The constraint force at one state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Solved {
    /// λ of eq. 1.9.
    pub lambda: f64,
    /// `λN`.
    pub constraint_force: DVec2,
    /// `(f + λN)/m`.
    pub acceleration: DVec2,
}

/// The result of one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutput {
    /// The new state.
    pub state: BeadState,
    /// The constraint multiplier the step applied (for RATTLE the mean of
    /// its position and velocity multipliers).
    pub lambda: f64,
    /// The constraint force the step applied.
    pub constraint_force: DVec2,
    /// `C` at the new state.
    pub c: f64,
    /// `Ċ` at the new state.
    pub c_dot: f64,
}

/// Tolerance on `|C|` for the Newton solves (RATTLE, projection), in units
/// of the wire's scale: a few ulps, which Newton's quadratic convergence
/// reaches in two or three iterations.
pub const NEWTON_TOLERANCE: f64 = 4.0 * f64::EPSILON;
/// Where rounding keeps `|C|` from reaching [`NEWTON_TOLERANCE`], a residual
/// below this (in wire scales) after the last iteration is accepted.
pub const NEWTON_ACCEPT: f64 = 1e-10;
const NEWTON_MAX_ITERATIONS: u32 = 20;

fn newton_done(residual: f64, scale: f64, last: bool) -> bool {
    residual <= NEWTON_TOLERANCE * scale || (last && residual <= NEWTON_ACCEPT * scale)
}

fn nonsingular(normal: DVec2, x: DVec2) -> Result<f64, SolveError> {
    let nn = normal.length_squared();
    if nn.is_finite() && nn > 1e-24 {
        Ok(nn)
    } else {
        Err(SolveError::Singular { x: x.x, y: x.y })
    }
}

/// λ of eq. 1.9 at a point whose geometry is `g`.
#[inline(always)]
pub fn lambda(
    g: &Geometry,
    x: DVec2,
    v: DVec2,
    f: DVec2,
    mass: f64,
    alpha: f64,
    beta: f64,
) -> Result<f64, SolveError> {
    let nn = nonsingular(g.normal, x)?;
    let vhv = v.dot(g.hessian * v);
    Ok((-mass * vhv - mass * alpha * g.c - mass * beta * g.normal.dot(v) - g.normal.dot(f)) / nn)
}

/// Solves eq. 1.9 at `state` and returns λ, `λN` and the acceleration.
#[inline(always)]
pub fn solve<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
    force: &LinearForce,
    mass: f64,
    alpha: f64,
    beta: f64,
) -> Result<Solved, SolveError> {
    let BeadState {
        position: x,
        velocity: v,
    } = state;
    let g = curve.geometry(x);
    let f = force.at(x);
    let lambda = lambda(&g, x, v, f, mass, alpha, beta)?;
    let constraint_force = lambda * g.normal;
    Ok(Solved {
        lambda,
        constraint_force,
        // The reciprocal does not wait for λ; a division here would.
        acceleration: (f + constraint_force) * mass.recip(),
    })
}

/// Advances one step from `state`, given `first`, the solve at `state`
/// (what [`solve`] returns with the config's gains). Post-stabilization is
/// applied when configured.
#[inline(always)]
pub fn integrate<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
    force: &LinearForce,
    first: &Solved,
    cfg: &StepConfig,
) -> Result<StepOutput, SolveError> {
    let h = cfg.dt;
    let (alpha, beta) = cfg.gains();
    let BeadState {
        position: x,
        velocity: v,
    } = state;
    let mut out = match cfg.integrator {
        Integrator::ExplicitEuler => StepOutput {
            state: BeadState {
                position: x + h * v,
                velocity: v + h * first.acceleration,
            },
            lambda: first.lambda,
            constraint_force: first.constraint_force,
            c: 0.0,
            c_dot: 0.0,
        },
        Integrator::SemiImplicitEuler => {
            let v1 = v + h * first.acceleration;
            StepOutput {
                state: BeadState {
                    position: x + h * v1,
                    velocity: v1,
                },
                lambda: first.lambda,
                constraint_force: first.constraint_force,
                c: 0.0,
                c_dot: 0.0,
            }
        }
        Integrator::Rk4 => {
            let accel = |s: BeadState| {
                solve(curve, s, force, cfg.mass, alpha, beta).map(|solved| solved.acceleration)
            };
            let k1 = (v, first.acceleration);
            let s2 = BeadState {
                position: x + 0.5 * h * k1.0,
                velocity: v + 0.5 * h * k1.1,
            };
            let k2 = (s2.velocity, accel(s2)?);
            let s3 = BeadState {
                position: x + 0.5 * h * k2.0,
                velocity: v + 0.5 * h * k2.1,
            };
            let k3 = (s3.velocity, accel(s3)?);
            let s4 = BeadState {
                position: x + h * k3.0,
                velocity: v + h * k3.1,
            };
            let k4 = (s4.velocity, accel(s4)?);
            StepOutput {
                state: BeadState {
                    position: x + h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0),
                    velocity: v + h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1),
                },
                lambda: first.lambda,
                constraint_force: first.constraint_force,
                c: 0.0,
                c_dot: 0.0,
            }
        }
        Integrator::Rattle => rattle(curve, state, force, cfg.mass, h)?,
    };
    if !out.state.is_finite() {
        return Err(SolveError::NonFinite);
    }
    let g = curve.geometry(out.state.position);
    if g.c.is_nan() || g.c.abs() > cfg.drift_bound {
        return Err(SolveError::DriftExceeded {
            c: g.c,
            bound: cfg.drift_bound,
        });
    }
    if cfg.stabilization == Stabilization::Projection && cfg.integrator != Integrator::Rattle {
        out.state = project(curve, out.state)?;
        (out.c, out.c_dot) = drift(curve, out.state);
    } else {
        (out.c, out.c_dot) = (g.c, g.normal.dot(out.state.velocity));
    }
    Ok(out)
}

/// [`solve`] then [`integrate`]: one whole step.
#[inline(always)]
pub fn step<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
    force: &LinearForce,
    cfg: &StepConfig,
) -> Result<StepOutput, SolveError> {
    let (alpha, beta) = cfg.gains();
    let first = solve(curve, state, force, cfg.mass, alpha, beta)?;
    integrate(curve, state, force, &first, cfg)
}

/// How many beads [`step_on_circles`] steps at once.
pub const LANES: usize = 8;

/// [`LANES`] beads on circles, as arrays of their scalars (one entry per
/// bead), the layout the batched step vectorizes over.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CircleLanes {
    /// Position x.
    pub x: [f64; LANES],
    /// Position y.
    pub y: [f64; LANES],
    /// Velocity x.
    pub vx: [f64; LANES],
    /// Velocity y.
    pub vy: [f64; LANES],
    /// The external force's [`LinearForce::force`], x.
    pub fx: [f64; LANES],
    /// The external force's [`LinearForce::force`], y.
    pub fy: [f64; LANES],
    /// The external force's [`LinearForce::stiffness`].
    pub stiffness: [f64; LANES],
    /// The external force's [`LinearForce::at`], x.
    pub at_x: [f64; LANES],
    /// The external force's [`LinearForce::at`], y.
    pub at_y: [f64; LANES],
    /// Mass.
    pub mass: [f64; LANES],
    /// The circle's centre, x.
    pub ox: [f64; LANES],
    /// The circle's centre, y.
    pub oy: [f64; LANES],
    /// The circle's radius.
    pub radius: [f64; LANES],
}

impl CircleLanes {
    /// Puts bead `lane`'s state, force, mass and circle in place.
    #[inline(always)]
    pub fn set(
        &mut self,
        lane: usize,
        state: BeadState,
        force: &LinearForce,
        mass: f64,
        centre: DVec2,
        radius: f64,
    ) {
        (self.x[lane], self.y[lane]) = (state.position.x, state.position.y);
        (self.vx[lane], self.vy[lane]) = (state.velocity.x, state.velocity.y);
        (self.fx[lane], self.fy[lane]) = (force.force.x, force.force.y);
        self.stiffness[lane] = force.stiffness;
        (self.at_x[lane], self.at_y[lane]) = (force.at.x, force.at.y);
        self.mass[lane] = mass;
        (self.ox[lane], self.oy[lane]) = (centre.x, centre.y);
        self.radius[lane] = radius;
    }
}

/// What [`step_on_circles`] returns: each lane's step, as arrays of the
/// fields of a [`StepOutput`] (one entry per bead), and which lanes it
/// finished.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CircleSteps {
    /// New position x.
    pub x: [f64; LANES],
    /// New position y.
    pub y: [f64; LANES],
    /// New velocity x.
    pub vx: [f64; LANES],
    /// New velocity y.
    pub vy: [f64; LANES],
    /// λ.
    pub lambda: [f64; LANES],
    /// The constraint force `λN`, x.
    pub fx: [f64; LANES],
    /// The constraint force `λN`, y.
    pub fy: [f64; LANES],
    /// `C` at the new state.
    pub c: [f64; LANES],
    /// `Ċ` at the new state.
    pub c_dot: [f64; LANES],
    /// Whether the lane finished as [`step`] would (if not, the other
    /// entries of the lane mean nothing).
    pub done: [bool; LANES],
}

impl CircleSteps {
    /// Lane `i`'s step, bit for bit what [`step`] returns, or `None` if the
    /// bead must go through [`step`].
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Option<StepOutput> {
        self.done[i].then(|| StepOutput {
            state: BeadState {
                position: DVec2::new(self.x[i], self.y[i]),
                velocity: DVec2::new(self.vx[i], self.vy[i]),
            },
            lambda: self.lambda[i],
            constraint_force: DVec2::new(self.fx[i], self.fy[i]),
            c: self.c[i],
            c_dot: self.c_dot[i],
        })
    }
}

/// Runs `$body` once per lane, as a loop the compiler turns into vector
/// instructions.
macro_rules! lanes {
    ($i:ident => $body:expr) => {
        for $i in 0..LANES {
            $body;
        }
    };
}

/// Whether [`step_on_circles`] takes steps of this config: explicit or
/// semi-implicit Euler or RK4, with Baumgarte stabilization or none.
pub fn batches(cfg: &StepConfig) -> bool {
    cfg.integrator != Integrator::Rattle && cfg.stabilization != Stabilization::Projection
}

/// A step of eq. 1.9 for [`LANES`] beads on unrotated
/// [`Circle`](crate::wire::Circle)s at once, for the configs
/// [`batches`] accepts.
///
/// It performs the operations of [`step`] on a
/// [`Placed`](crate::wire::Placed) circle in the same order, lane by lane,
/// so each lane's result is bit for bit what [`step`] returns; what differs
/// is that the square roots and divisions of [`LANES`] beads run side by side
/// instead of one after another. A lane the batch cannot finish (a
/// non-finite state, the circle's centre, a step past the drift bound)
/// comes back not [`done`](CircleSteps::done): take that bead through
/// [`step`], which reports why. A config [`batches`] refuses finishes no
/// lane. `cfg.mass` and `cfg.drift_bound` are unused (each lane has its own
/// mass, and its bound is `bound_per_radius` times its radius).
///
/// On an x86-64 processor with AVX2 (checked once, at run time) the lanes
/// run four to an instruction instead of two; the operations, and so the
/// bits of the results, are the same either way.
#[inline]
pub fn step_on_circles(b: &CircleLanes, cfg: &StepConfig, bound_per_radius: f64) -> CircleSteps {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has just been found to support AVX2.
        return unsafe { step_on_circles_avx2(b, cfg, bound_per_radius) };
    }
    step_on_circles_portable(b, cfg, bound_per_radius)
}

/// [`step_on_circles`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn step_on_circles_avx2(b: &CircleLanes, cfg: &StepConfig, bound_per_radius: f64) -> CircleSteps {
    step_on_circles_portable(b, cfg, bound_per_radius)
}

/// Eq. 1.9 solved on each lane's circle, as [`solve`] solves it.
#[derive(Clone, Copy, Default)]
struct LaneSolve {
    /// `|x - centre|`.
    len: [f64; LANES],
    /// The normal (the gradient of `C`).
    nx: [f64; LANES],
    ny: [f64; LANES],
    /// `|N|²`.
    nn: [f64; LANES],
    lambda: [f64; LANES],
    /// `(f + λN) / m`.
    ax: [f64; LANES],
    ay: [f64; LANES],
}

impl LaneSolve {
    /// Whether `nonsingular` accepts the lane's normal.
    #[inline(always)]
    fn regular(&self, i: usize) -> bool {
        (self.len[i] != 0.0) & self.nn[i].is_finite() & (self.nn[i] > 1e-24)
    }
}

/// [`solve`] on each lane at `(x, y)` moving at `(vx, vy)`, with
/// `Circle::geometry` after `Placed`'s translation and
/// [`LinearForce::at`].
#[inline(always)]
fn solve_lanes(
    b: &CircleLanes,
    [x, y, vx, vy]: [&[f64; LANES]; 4],
    alpha: f64,
    beta: f64,
) -> LaneSolve {
    let mut s = LaneSolve::default();
    let mut inv = [0.0; LANES];
    lanes!(i => {
        let (px, py) = (x[i] - b.ox[i], y[i] - b.oy[i]);
        s.len[i] = (px * px + py * py).sqrt();
        inv[i] = 1.0 / s.len[i];
        (s.nx[i], s.ny[i]) = (px * inv[i], py * inv[i]);
    });
    // λ of eq. 1.9, with H = (I - n nᵀ)/|x| as Circle::geometry builds it.
    lanes!(i => {
        let (nx, ny) = (s.nx[i], s.ny[i]);
        let (h00, h10) = ((1.0 - nx * nx) * inv[i], (-nx * ny) * inv[i]);
        let (h01, h11) = ((-nx * ny) * inv[i], (1.0 - ny * ny) * inv[i]);
        let (hvx, hvy) = (h00 * vx[i] + h01 * vy[i], h10 * vx[i] + h11 * vy[i]);
        let vhv = vx[i] * hvx + vy[i] * hvy;
        let c = s.len[i] - b.radius[i];
        let m = b.mass[i];
        let k = b.stiffness[i];
        let fx = b.fx[i] - k * (x[i] - b.at_x[i]);
        let fy = b.fy[i] - k * (y[i] - b.at_y[i]);
        s.nn[i] = nx * nx + ny * ny;
        let ndv = nx * vx[i] + ny * vy[i];
        let ndf = nx * fx + ny * fy;
        s.lambda[i] = (-m * vhv - m * alpha * c - m * beta * ndv - ndf) / s.nn[i];
        let inv_m = m.recip();
        s.ax[i] = (fx + s.lambda[i] * nx) * inv_m;
        s.ay[i] = (fy + s.lambda[i] * ny) * inv_m;
    });
    s
}

/// `a + t k`, lane by lane.
#[inline(always)]
fn axpy(a: &[f64; LANES], t: f64, k: &[f64; LANES]) -> [f64; LANES] {
    std::array::from_fn(|i| a[i] + t * k[i])
}

/// [`step_on_circles`] for any processor.
#[inline(always)]
fn step_on_circles_portable(
    b: &CircleLanes,
    cfg: &StepConfig,
    bound_per_radius: f64,
) -> CircleSteps {
    if !batches(cfg) {
        return CircleSteps::default();
    }
    let h = cfg.dt;
    let (alpha, beta) = cfg.gains();
    let first = solve_lanes(b, [&b.x, &b.y, &b.vx, &b.vy], alpha, beta);
    let mut regular: [bool; LANES] = std::array::from_fn(|i| first.regular(i));
    // `integrate`'s update.
    let (x1, y1, vx1, vy1) = match cfg.integrator {
        Integrator::ExplicitEuler => (
            axpy(&b.x, h, &b.vx),
            axpy(&b.y, h, &b.vy),
            axpy(&b.vx, h, &first.ax),
            axpy(&b.vy, h, &first.ay),
        ),
        Integrator::Rk4 => {
            let half = 0.5 * h;
            let stage = |t: f64, vx: &[f64; LANES], vy: &[f64; LANES], s: &LaneSolve| {
                let x = axpy(&b.x, t, vx);
                let y = axpy(&b.y, t, vy);
                let (vx, vy) = (axpy(&b.vx, t, &s.ax), axpy(&b.vy, t, &s.ay));
                let solved = solve_lanes(b, [&x, &y, &vx, &vy], alpha, beta);
                (vx, vy, solved)
            };
            let (vx2, vy2, s2) = stage(half, &b.vx, &b.vy, &first);
            let (vx3, vy3, s3) = stage(half, &vx2, &vy2, &s2);
            let (vx4, vy4, s4) = stage(h, &vx3, &vy3, &s3);
            lanes!(i => regular[i] &= s2.regular(i) & s3.regular(i) & s4.regular(i));
            let sixth = h / 6.0;
            let sum =
                |k1: &[f64; LANES], k2: &[f64; LANES], k3: &[f64; LANES], k4: &[f64; LANES]| {
                    std::array::from_fn(|i| k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                };
            (
                axpy(&b.x, sixth, &sum(&b.vx, &vx2, &vx3, &vx4)),
                axpy(&b.y, sixth, &sum(&b.vy, &vy2, &vy3, &vy4)),
                axpy(&b.vx, sixth, &sum(&first.ax, &s2.ax, &s3.ax, &s4.ax)),
                axpy(&b.vy, sixth, &sum(&first.ay, &s2.ay, &s3.ay, &s4.ay)),
            )
        }
        // Semi-implicit Euler (RATTLE returned above).
        Integrator::SemiImplicitEuler | Integrator::Rattle => {
            let (vx1, vy1) = (axpy(&b.vx, h, &first.ax), axpy(&b.vy, h, &first.ay));
            (axpy(&b.x, h, &vx1), axpy(&b.y, h, &vy1), vx1, vy1)
        }
    };
    let mut out = CircleSteps {
        x: x1,
        y: y1,
        vx: vx1,
        vy: vy1,
        lambda: first.lambda,
        ..CircleSteps::default()
    };
    // λN; C and Ċ at the new state.
    let mut len1 = [0.0; LANES];
    lanes!(i => {
        (out.fx[i], out.fy[i]) = (first.lambda[i] * first.nx[i], first.lambda[i] * first.ny[i]);
        let (px, py) = (x1[i] - b.ox[i], y1[i] - b.oy[i]);
        len1[i] = (px * px + py * py).sqrt();
        let k = 1.0 / len1[i];
        out.c[i] = len1[i] - b.radius[i];
        out.c_dot[i] = (px * k) * vx1[i] + (py * k) * vy1[i];
    });
    // Which lanes finished as `step` would: `&`, not `&&`, so the checks
    // vectorize too.
    lanes!(i => {
        let finite = |v: f64| v.is_finite();
        let states = finite(b.x[i]) & finite(b.y[i]) & finite(b.vx[i]) & finite(b.vy[i]);
        let ends = finite(x1[i]) & finite(y1[i]) & finite(vx1[i]) & finite(vy1[i]);
        let bounded = out.c[i].abs() <= bound_per_radius * b.radius[i];
        out.done[i] = states & ends & regular[i] & (len1[i] != 0.0) & bounded;
    });
    out
}

/// Newton's method on `s ↦ C(base + s dir)`, returning the root `s` and the
/// residual `C` there.
fn newton_along<C: ImplicitCurve + ?Sized>(
    curve: &C,
    base: DVec2,
    dir: DVec2,
) -> Result<(f64, f64), SolveError> {
    let scale = curve.scale().max(f64::MIN_POSITIVE);
    let mut s = 0.0;
    let mut residual = f64::INFINITY;
    for i in 0..=NEWTON_MAX_ITERATIONS {
        let p = base + s * dir;
        let g = curve.geometry(p);
        residual = g.c.abs();
        if newton_done(residual, scale, i == NEWTON_MAX_ITERATIONS) {
            return Ok((s, g.c));
        }
        if i == NEWTON_MAX_ITERATIONS {
            break;
        }
        let slope = g.normal.dot(dir);
        if !(slope.is_finite() && slope.abs() > 1e-300) {
            return Err(SolveError::Singular { x: p.x, y: p.y });
        }
        s -= g.c / slope;
    }
    Err(SolveError::NoConvergence {
        iterations: NEWTON_MAX_ITERATIONS,
        residual,
    })
}

/// One RATTLE step (see the module docs).
pub fn rattle<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
    force: &LinearForce,
    mass: f64,
    h: f64,
) -> Result<StepOutput, SolveError> {
    let BeadState {
        position: x0,
        velocity: v0,
    } = state;
    let n0 = curve.gradient(x0);
    nonsingular(n0, x0)?;
    let free = x0 + h * v0 + (h * h / (2.0 * mass)) * force.at(x0);
    let (s, c1) = newton_along(curve, free, n0)?;
    let x1 = free + s * n0;
    let lambda = 2.0 * mass * s / (h * h);
    let v_half = (x1 - x0) / h;
    let n1 = curve.gradient(x1);
    let nn1 = nonsingular(n1, x1)?;
    let w = v_half + (h / (2.0 * mass)) * force.at(x1);
    let mu_scaled = -n1.dot(w) / nn1;
    let v1 = w + mu_scaled * n1;
    let mu = 2.0 * mass * mu_scaled / h;
    Ok(StepOutput {
        state: BeadState {
            position: x1,
            velocity: v1,
        },
        lambda: 0.5 * (lambda + mu),
        constraint_force: 0.5 * (lambda * n0 + mu * n1),
        c: c1,
        c_dot: n1.dot(v1),
    })
}

/// Post-stabilization: moves the position onto `C = 0` by Newton steps along
/// the local gradient, then removes the velocity's normal component.
pub fn project<C: ImplicitCurve + ?Sized>(
    curve: &C,
    state: BeadState,
) -> Result<BeadState, SolveError> {
    let scale = curve.scale().max(f64::MIN_POSITIVE);
    let mut x = state.position;
    let mut converged = false;
    let mut residual = f64::INFINITY;
    for i in 0..=NEWTON_MAX_ITERATIONS {
        let g = curve.geometry(x);
        residual = g.c.abs();
        if newton_done(residual, scale, i == NEWTON_MAX_ITERATIONS) {
            converged = true;
            break;
        }
        if i == NEWTON_MAX_ITERATIONS {
            break;
        }
        let nn = nonsingular(g.normal, x)?;
        x -= (g.c / nn) * g.normal;
    }
    if !converged {
        return Err(SolveError::NoConvergence {
            iterations: NEWTON_MAX_ITERATIONS,
            residual,
        });
    }
    let n = curve.gradient(x);
    let nn = nonsingular(n, x)?;
    let v = state.velocity - (n.dot(state.velocity) / nn) * n;
    Ok(BeadState {
        position: x,
        velocity: v,
    })
}

/// `C` and `Ċ = N·ẋ` at a state.
pub fn drift<C: ImplicitCurve + ?Sized>(curve: &C, state: BeadState) -> (f64, f64) {
    let g = curve.geometry(state.position);
    (g.c, g.normal.dot(state.velocity))
}

/// Kinetic and gravitational potential energy `(½ m |v|², -m g·x)`.
pub fn energy(mass: f64, gravity: DVec2, state: BeadState) -> (f64, f64) {
    (
        0.5 * mass * state.velocity.length_squared(),
        -mass * gravity.dot(state.position),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{Circle, Ellipse, Placed, Pose, Sine};
    use approx::assert_relative_eq;

    const G: DVec2 = DVec2::new(0.0, -9.81);

    fn cfg(integrator: Integrator, stabilization: Stabilization, dt: f64) -> StepConfig {
        StepConfig {
            dt,
            mass: 1.0,
            alpha: 100.0,
            beta: 20.0,
            integrator,
            stabilization,
            drift_bound: 1.0,
        }
    }

    #[test]
    fn batched_step_on_circles_is_bit_identical_to_step() {
        // Beads in all directions, at all speeds, on circles of different
        // sizes and centres, with a spring's stiffness on some.
        let bound = 0.5;
        for integrator in [
            Integrator::ExplicitEuler,
            Integrator::SemiImplicitEuler,
            Integrator::Rk4,
        ] {
            for stabilization in [Stabilization::Baumgarte, Stabilization::None] {
                let mut batch_cfg = cfg(integrator, stabilization, 1.0 / 60.0);
                batch_cfg.mass = f64::NAN; // each lane has its own
                for k in 0..50 {
                    let mut lanes = CircleLanes::default();
                    let mut inputs = Vec::new();
                    for lane in 0..LANES {
                        let j = (k * LANES + lane) as f64;
                        let radius = 0.5 + (j * 0.37) % 3.0;
                        let centre = DVec2::new((j * 1.3) % 5.0 - 2.5, (j * 0.7) % 4.0 - 2.0);
                        let angle = j * 0.91;
                        let off = 1.0 + 0.02 * ((j * 0.13).sin());
                        let state = BeadState {
                            position: centre + radius * off * DVec2::from_angle(angle),
                            velocity: DVec2::new((j * 0.29).sin(), (j * 0.41).cos()) * 4.0,
                        };
                        let mass = 0.3 + (j * 0.17) % 2.0;
                        let force = LinearForce {
                            force: mass * G + DVec2::new(j % 3.0, -(j % 2.0)),
                            stiffness: j % 4.0,
                            at: state.position + DVec2::new(0.01, -0.02) * (j % 5.0),
                        };
                        lanes.set(lane, state, &force, mass, centre, radius);
                        inputs.push((state, force, mass, centre, radius));
                    }
                    // The dispatching entry point and the portable code
                    // (the same where there is no AVX2).
                    let outs = step_on_circles(&lanes, &batch_cfg, bound);
                    let portable = step_on_circles_portable(&lanes, &batch_cfg, bound);
                    let both = (0..LANES).flat_map(|i| [outs.lane(i), portable.lane(i)]);
                    let inputs = inputs.iter().flat_map(|i| [*i, *i]);
                    for (out, (state, force, mass, centre, radius)) in both.zip(inputs) {
                        let placed = Placed {
                            curve: &Circle { radius },
                            pose: Pose::new(centre, 0.0),
                        };
                        let cfg = StepConfig {
                            mass,
                            drift_bound: bound * radius,
                            ..batch_cfg
                        };
                        let expected = step(&placed, state, &force, &cfg).unwrap();
                        let out = out.expect("an ordinary lane");
                        let bits = |o: &StepOutput| {
                            [o.state.position, o.state.velocity, o.constraint_force]
                                .map(|v| v.to_array().map(f64::to_bits))
                        };
                        assert_eq!(
                            bits(&out),
                            bits(&expected),
                            "{integrator} {stabilization} lane {k}"
                        );
                        for (a, b) in [
                            (out.lambda, expected.lambda),
                            (out.c, expected.c),
                            (out.c_dot, expected.c_dot),
                        ] {
                            assert_eq!(a.to_bits(), b.to_bits());
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn batched_step_hands_back_the_lanes_it_cannot_finish() {
        let centre = DVec2::new(1.0, 2.0);
        let mut lanes = CircleLanes::default();
        let at = |angle: f64| centre + DVec2::from_angle(angle);
        let states = [
            (at(0.3), DVec2::new(1.0, 0.0)),      // ordinary
            (centre, DVec2::ZERO),                // the singular centre
            (at(1.0), DVec2::new(f64::NAN, 0.0)), // not finite
            (at(2.0), DVec2::new(1e6, 0.0)),      // flung past the bound
        ];
        for (lane, (position, velocity)) in states.into_iter().enumerate() {
            let state = BeadState { position, velocity };
            lanes.set(lane, state, &LinearForce::constant(G), 1.0, centre, 1.0);
        }
        let cfg = cfg(
            Integrator::SemiImplicitEuler,
            Stabilization::Baumgarte,
            0.01,
        );
        let outs = step_on_circles(&lanes, &cfg, 1.0);
        // The unused lanes 4 to 7 are all at their circle's centre.
        let mut done = [false; LANES];
        done[0] = true;
        assert_eq!(outs.done, done, "{outs:?}");
        assert!(outs.lane(0).is_some() && outs.lane(1).is_none());
        // What `batches` refuses, the batch finishes no lane of.
        for (integrator, stabilization) in [
            (Integrator::Rattle, Stabilization::Baumgarte),
            (Integrator::Rk4, Stabilization::Projection),
            (Integrator::SemiImplicitEuler, Stabilization::Projection),
        ] {
            let refused = StepConfig {
                integrator,
                stabilization,
                ..cfg
            };
            assert!(!batches(&refused));
            assert_eq!(step_on_circles(&lanes, &refused, 1.0).done, [false; LANES]);
        }
    }

    #[test]
    fn lambda_on_circle_is_the_centripetal_and_gravity_balance() {
        // At the bottom of a unit circle moving at speed u: λ = -(m u²/r + m|g|)
        // (pointing inward, N points outward).
        let circle = Circle { radius: 1.0 };
        let u = 3.0;
        let state = BeadState {
            position: DVec2::new(0.0, -1.0),
            velocity: DVec2::new(u, 0.0),
        };
        let s = solve(
            &circle,
            state,
            &LinearForce::constant(2.0 * G),
            2.0,
            0.0,
            0.0,
        )
        .unwrap();
        assert_relative_eq!(s.lambda, -(2.0 * u * u + 2.0 * 9.81), epsilon = 1e-12);
        assert_relative_eq!(s.acceleration.y, u * u, epsilon = 1e-12);
    }

    #[test]
    fn baumgarte_lambda_makes_c_double_dot_follow_the_law() {
        // Check C̈ = -αC - βĊ numerically on an ellipse, off the wire, placed and rotated.
        let ellipse = Ellipse { a: 2.0, b: 1.0 };
        let placed = Placed {
            curve: &ellipse,
            pose: Pose::new(DVec2::new(0.5, 0.2), 0.4),
        };
        let state = BeadState {
            position: placed.pose.to_world(DVec2::new(1.2, 0.9)),
            velocity: DVec2::new(0.3, -0.8),
        };
        let force = LinearForce::constant(DVec2::new(0.7, -9.81));
        let (alpha, beta, m) = (50.0, 7.0, 1.5);
        let s = solve(&placed, state, &force, m, alpha, beta).unwrap();
        let g = placed.geometry(state.position);
        let c_dot = g.normal.dot(state.velocity);
        let c_ddot = state.velocity.dot(g.hessian * state.velocity) + g.normal.dot(s.acceleration);
        assert_relative_eq!(c_ddot, -alpha * g.c - beta * c_dot, epsilon = 1e-12);
    }

    #[test]
    fn singular_point_is_an_error_not_a_nan() {
        let circle = Circle { radius: 1.0 };
        let state = BeadState::default();
        for integrator in Integrator::ALL {
            let err = step(
                &circle,
                state,
                &LinearForce::constant(G),
                &cfg(*integrator, Stabilization::Baumgarte, 0.01),
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
        for (integrator, stabilization) in [
            (Integrator::Rattle, Stabilization::None),
            (Integrator::SemiImplicitEuler, Stabilization::Projection),
            (Integrator::Rk4, Stabilization::Projection),
        ] {
            let mut state = BeadState {
                position: DVec2::new(0.0, 0.0),
                velocity: DVec2::new(2.0, 2.0 * 0.5 * std::f64::consts::TAU / 3.0),
            };
            let c = cfg(integrator, stabilization, 1.0 / 60.0);
            for _ in 0..600 {
                state = step(&sine, state, &LinearForce::constant(G), &c)
                    .unwrap()
                    .state;
                let (drift, drift_rate) = drift(&sine, state);
                assert!(
                    drift.abs() <= NEWTON_ACCEPT * 3.0,
                    "{integrator:?}: C = {drift:e}"
                );
                assert!(
                    drift_rate.abs() <= 1e-12,
                    "{integrator:?}: Ċ = {drift_rate:e}"
                );
            }
        }
    }

    #[test]
    fn linear_force_reproduces_the_drag_spring() {
        let target = DVec2::new(2.0, 1.0);
        let k = 30.0;
        let at = DVec2::new(0.5, -0.5);
        let f = LinearForce {
            force: k * (target - at),
            stiffness: k,
            at,
        };
        let x = DVec2::new(-0.3, 0.8);
        let expect = k * (target - x);
        assert_relative_eq!(f.at(x).x, expect.x, epsilon = 1e-12);
        assert_relative_eq!(f.at(x).y, expect.y, epsilon = 1e-12);
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
            let c = cfg(Integrator::Rk4, Stabilization::None, dt);
            let mut s = start;
            for _ in 0..(1.0 / dt).round() as usize {
                s = step(&circle, s, &LinearForce::constant(G), &c)
                    .unwrap()
                    .state;
            }
            s.position
        };
        let reference = run(1.0 / 2560.0);
        let e1 = (run(1.0 / 80.0) - reference).length();
        let e2 = (run(1.0 / 160.0) - reference).length();
        let order = (e1 / e2).log2();
        assert!((3.7..4.3).contains(&order), "observed order {order}");
    }
}
