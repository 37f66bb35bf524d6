//! The batched step: [`LANES`] beads on unrotated circles at once, the
//! same operations as [`step`] in the same order, so each lane's result is
//! bit for bit what [`step`] returns.

use bevy::math::DVec2;

use super::method::{Method, Stabilization};
use super::settings::{Gains, StepSettings};
use super::state::{BeadState, LinearForce};
use super::step::StepOutput;
#[cfg(doc)]
use super::{solve::solve, step::step};

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

/// Whether [`step_on_circles`] takes steps of this method: explicit or
/// semi-implicit Euler or RK4, with Baumgarte stabilization or none.
pub fn is_batched(method: Method) -> bool {
    !matches!(
        method.stabilization(),
        None | Some(Stabilization::Projection)
    )
}

/// A step of eq. (3) for [`LANES`] beads on unrotated
/// [`Circle`](crate::geometry::Circle)s at once, for the configs
/// [`is_batched`] accepts.
///
/// It performs the operations of [`step`] on a
/// [`Placed`](crate::geometry::Placed) circle in the same order, lane by lane,
/// so each lane's result is bit for bit what [`step`] returns; what differs
/// is that the square roots and divisions of [`LANES`] beads run side by side
/// instead of one after another. A lane the batch cannot finish (a
/// non-finite state, the circle's centre, a step past the drift bound)
/// comes back not [`done`](CircleSteps::done): take that bead through
/// [`step`], which reports why. A method [`is_batched`] refuses finishes
/// no lane. Each lane has its own mass; its drift bound is
/// `settings.drift_bound` times its radius, as [`step`] takes it.
///
/// On an x86-64 processor with AVX2 (checked once, at run time) the lanes
/// run four to an instruction instead of two; the operations, and so the
/// bits of the results, are the same either way.
#[inline]
pub fn step_on_circles(b: &CircleLanes, settings: &StepSettings) -> CircleSteps {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has just been found to support AVX2.
        return unsafe { step_on_circles_avx2(b, settings) };
    }
    step_on_circles_portable(b, settings)
}

/// [`step_on_circles`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn step_on_circles_avx2(b: &CircleLanes, settings: &StepSettings) -> CircleSteps {
    step_on_circles_portable(b, settings)
}

/// Eq. (3) solved on each lane's circle, as [`solve`] solves it.
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
    // λ of eq. (3), with H = (I - n nᵀ)/|x| as Circle::geometry builds it.
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
fn step_on_circles_portable(b: &CircleLanes, settings: &StepSettings) -> CircleSteps {
    if !is_batched(settings.method) {
        return CircleSteps::default();
    }
    let h = settings.dt;
    let Gains { alpha, beta } = settings.gains();
    let bound_per_radius = settings.drift_bound;
    let first = solve_lanes(b, [&b.x, &b.y, &b.vx, &b.vy], alpha, beta);
    let mut regular: [bool; LANES] = std::array::from_fn(|i| first.regular(i));
    // `integrate`'s update.
    let (x1, y1, vx1, vy1) = match settings.method {
        Method::ExplicitEuler(_) => (
            axpy(&b.x, h, &b.vx),
            axpy(&b.y, h, &b.vy),
            axpy(&b.vx, h, &first.ax),
            axpy(&b.vy, h, &first.ay),
        ),
        Method::Rk4(_) => {
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
        Method::SemiImplicitEuler(_) | Method::Rattle => {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Circle, Placed, Pose};
    use crate::solver::step;

    const G: DVec2 = DVec2::new(0.0, -9.81);

    fn settings(method: Method, dt: f64) -> StepSettings {
        StepSettings {
            dt,
            method,
            alpha: 100.0,
            beta: 20.0,
            drift_bound: 1.0,
        }
    }

    #[test]
    fn batched_step_on_circles_is_bit_identical_to_step() {
        // Beads in all directions, at all speeds, on circles of different
        // sizes and centres, with a spring's stiffness on some.
        let bound = 0.5;
        for method in Method::ALL.into_iter().filter(|m| is_batched(*m)) {
            let batch_settings = StepSettings {
                drift_bound: bound,
                ..settings(method, 1.0 / 60.0)
            };
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
                let outs = step_on_circles(&lanes, &batch_settings);
                let portable = step_on_circles_portable(&lanes, &batch_settings);
                let both = (0..LANES).flat_map(|i| [outs.lane(i), portable.lane(i)]);
                let inputs = inputs.iter().flat_map(|i| [*i, *i]);
                for (out, (state, force, mass, centre, radius)) in both.zip(inputs) {
                    let placed = Placed {
                        curve: &Circle { radius },
                        pose: Pose::new(centre, 0.0),
                    };
                    let expected = step(&placed, state, &force, mass, &batch_settings).unwrap();
                    let out = out.expect("an ordinary lane");
                    let bits = |o: &StepOutput| {
                        [o.state.position, o.state.velocity, o.constraint_force]
                            .map(|v| v.to_array().map(f64::to_bits))
                    };
                    assert_eq!(bits(&out), bits(&expected), "{method} lane {k}");
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
        let s = settings(Method::SemiImplicitEuler(Stabilization::Baumgarte), 0.01);
        let outs = step_on_circles(&lanes, &s);
        // The unused lanes 4 to 7 are all at their circle's centre.
        let mut done = [false; LANES];
        done[0] = true;
        assert_eq!(outs.done, done, "{outs:?}");
        assert!(outs.lane(0).is_some() && outs.lane(1).is_none());
        // What `is_batched` refuses, the batch finishes no lane of.
        for method in [
            Method::Rattle,
            Method::Rk4(Stabilization::Projection),
            Method::SemiImplicitEuler(Stabilization::Projection),
        ] {
            assert!(!is_batched(method));
            let refused = StepSettings { method, ..s };
            assert_eq!(step_on_circles(&lanes, &refused).done, [false; LANES]);
        }
    }
}
