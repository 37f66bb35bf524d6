//! Many beads for the benchmarks, the memory measurement and the profile:
//! pendulums on circles of radius 1, through the plugin or as plain structs.

#![allow(dead_code)]

use bevy::math::DVec2;
use bevy::prelude::*;
use wirebead::ParallelStep;
use wirebead::headless::Headless;
use wirebead::prelude::*;

/// How the beads are put on wires.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Layout {
    /// Each bead on a circle of its own, the circles on a grid.
    OwnWires,
    /// Every bead on one circle.
    SharedWire,
}

impl Layout {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::OwnWires => "own-wires",
            Self::SharedWire => "shared-wire",
        }
    }
}

/// How the plugin runs its loops.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Threads {
    /// One thread: single-threaded executor, [`ParallelStep::OFF`].
    Single,
    /// Bevy's default executor and [`ParallelStep::default`].
    Parallel,
}

impl Threads {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Single => "single",
            Self::Parallel => "parallel",
        }
    }
}

/// What a bead carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Kind {
    /// The default bead: `Transform` and `BeadDiagnostics` included.
    Full,
    /// [`WireBeadPlugin::lean`]: the bead's state and its wire only.
    Lean,
}

impl Kind {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Full => "full",
            Self::Lean => "lean",
        }
    }
}

/// The starting angle from the bottom of bead `i`: spread over ±120° so the
/// beads are at different phases.
pub fn start_angle(i: usize) -> f64 {
    let spread = (i % 241) as f64 / 240.0;
    (spread * 2.0 - 1.0) * 120f64.to_radians()
}

/// Where bead `i`'s circle sits.
pub fn grid_origin(i: usize) -> DVec2 {
    DVec2::new(3.0 * (i % 1024) as f64, 3.0 * (i / 1024) as f64)
}

fn on_circle(origin: DVec2, angle: f64) -> DVec2 {
    origin + DVec2::new(angle.sin(), -angle.cos())
}

/// An app with the plugin and `n` beads at rest, ready for
/// `world_mut().run_schedule(FixedUpdate)` (one step per call).
pub fn plugin_app(n: usize, layout: Layout, threads: Threads, kind: Kind) -> App {
    let plugin = match kind {
        Kind::Full => WireBeadPlugin::default(),
        Kind::Lean => WireBeadPlugin::default().lean(),
    };
    let harness = Headless::new(plugin);
    let mut app = match threads {
        Threads::Single => harness.single_threaded().parallel(ParallelStep::OFF),
        Threads::Parallel => harness,
    }
    .build();
    let world = app.world_mut();
    match layout {
        Layout::SharedWire => {
            let wire = world.spawn(Wire::circle(1.0).expect("radius 1")).id();
            world.spawn_batch((0..n).map(move |i| {
                let bead = Bead::at_rest(1.0, on_circle(DVec2::ZERO, start_angle(i)));
                (bead.expect("valid bead"), OnWire(wire))
            }));
        }
        Layout::OwnWires => {
            let wires: Vec<Entity> = world
                .spawn_batch((0..n).map(|i| {
                    let o = grid_origin(i);
                    (
                        Wire::circle(1.0).expect("radius 1"),
                        Transform::from_xyz(o.x as f32, o.y as f32, 0.0),
                    )
                }))
                .collect();
            world.spawn_batch(wires.into_iter().enumerate().map(|(i, wire)| {
                let bead = Bead::at_rest(1.0, on_circle(grid_origin(i), start_angle(i)));
                (bead.expect("valid bead"), OnWire(wire))
            }));
        }
    }
    app
}

/// The floor the plugin is measured against: the default method
/// (semi-implicit Euler with Baumgarte stabilization, eq. 3 on a circle)
/// written out by hand from the equations as one plain loop over arrays
/// (one array per scalar), with none of the plugin's or the solver's code.
/// The loop runs in a function compiled for AVX2 where the processor has
/// it (pulp's dispatch), so the compiler vectorizes it; it takes no
/// branches per bead. For full beads it also writes what the plugin
/// shows: λ, `λN`, `C`, `Ċ`, the energies and the rendered position.
pub struct RawLoop {
    x: Vec<f64>,
    y: Vec<f64>,
    vx: Vec<f64>,
    vy: Vec<f64>,
    mass: Vec<f64>,
    /// Each bead's circle's centre.
    ox: Vec<f64>,
    oy: Vec<f64>,
    /// For full beads: λ, `λN`, `C`, `Ċ`, kinetic and potential energy,
    /// the rendered position; empty for lean ones.
    extras: Vec<RawExtras>,
    radius: f64,
    dt: f64,
    alpha: f64,
    beta: f64,
    gravity: DVec2,
}

/// What a full bead adds: diagnostics and the rendered position.
#[derive(Clone, Copy, Debug, Default)]
pub struct RawExtras {
    /// λ.
    pub lambda: f64,
    /// `λN`.
    pub constraint_force: [f64; 2],
    /// `C`, `Ċ`, kinetic and potential energy.
    pub diagnostics: [f64; 4],
    /// The rendered position.
    pub rendered: [f32; 2],
}

impl RawLoop {
    /// `n` beads laid out as [`plugin_app`] lays them out.
    pub fn new(n: usize, layout: Layout, kind: Kind) -> Self {
        let params = SimParams::default();
        let origin = |i: usize| match layout {
            Layout::SharedWire => DVec2::ZERO,
            Layout::OwnWires => grid_origin(i),
        };
        let at: Vec<DVec2> = (0..n)
            .map(|i| on_circle(origin(i), start_angle(i)))
            .collect();
        Self {
            x: at.iter().map(|p| p.x).collect(),
            y: at.iter().map(|p| p.y).collect(),
            vx: vec![0.0; n],
            vy: vec![0.0; n],
            mass: vec![1.0; n],
            ox: (0..n).map(|i| origin(i).x).collect(),
            oy: (0..n).map(|i| origin(i).y).collect(),
            extras: match kind {
                Kind::Full => vec![RawExtras::default(); n],
                Kind::Lean => Vec::new(),
            },
            radius: 1.0,
            dt: params.timestep,
            alpha: params.alpha,
            beta: params.beta,
            gravity: params.gravity,
        }
    }

    /// The beads' positions.
    pub fn positions(&self) -> impl Iterator<Item = DVec2> + '_ {
        self.x.iter().zip(&self.y).map(|(&x, &y)| DVec2::new(x, y))
    }

    /// One step of every bead; returns how many came out not finite.
    pub fn step(&mut self) -> usize {
        struct Kernel<'a>(&'a mut RawLoop);
        impl pulp::NullaryFnOnce for Kernel<'_> {
            type Output = usize;
            #[inline(always)]
            fn call(self) -> usize {
                if self.0.extras.is_empty() {
                    self.0.kernel::<false>()
                } else {
                    self.0.kernel::<true>()
                }
            }
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = pulp::x86::V3::try_new() {
            return simd.vectorize(Kernel(self));
        }
        pulp::NullaryFnOnce::call(Kernel(self))
    }

    /// Eq. (3) on each bead's circle, `C = |p| - r` with `p` the position
    /// from the centre: `N = p/|p|`, `vᵀHv = (|v|² - (N·v)²)/|p|`, then
    /// the semi-implicit Euler step.
    #[inline(always)]
    fn kernel<const FULL: bool>(&mut self) -> usize {
        let (h, r, alpha, beta) = (self.dt, self.radius, self.alpha, self.beta);
        let (gx, gy) = (self.gravity.x, self.gravity.y);
        let n = self.x.len();
        let (x, y, vx, vy) = (
            &mut self.x[..n],
            &mut self.y[..n],
            &mut self.vx[..n],
            &mut self.vy[..n],
        );
        let (mass, ox, oy) = (&self.mass[..n], &self.ox[..n], &self.oy[..n]);
        let mut failed = 0usize;
        for i in 0..n {
            let m = mass[i];
            let (px, py) = (x[i] - ox[i], y[i] - oy[i]);
            let len = (px * px + py * py).sqrt();
            let (nx, ny) = (px / len, py / len);
            let (u, w) = (vx[i], vy[i]);
            let nv = nx * u + ny * w;
            let vhv = (u * u + w * w - nv * nv) / len;
            let (fx, fy) = (m * gx, m * gy);
            let lambda = (-m * vhv - m * alpha * (len - r) - m * beta * nv - (nx * fx + ny * fy))
                / (nx * nx + ny * ny);
            let u1 = u + h * (fx + lambda * nx) / m;
            let w1 = w + h * (fy + lambda * ny) / m;
            let (x1, y1) = (x[i] + h * u1, y[i] + h * w1);
            (x[i], y[i], vx[i], vy[i]) = (x1, y1, u1, w1);
            failed += usize::from(!(x1.is_finite() && y1.is_finite()));
            if FULL {
                let (qx, qy) = (x1 - ox[i], y1 - oy[i]);
                let len1 = (qx * qx + qy * qy).sqrt();
                let c_dot = (qx * u1 + qy * w1) / len1;
                let speed2 = u1 * u1 + w1 * w1;
                self.extras[i] = RawExtras {
                    lambda,
                    constraint_force: [lambda * nx, lambda * ny],
                    diagnostics: [len1 - r, c_dot, 0.5 * m * speed2, -m * (gx * x1 + gy * y1)],
                    rendered: [x1 as f32, y1 as f32],
                };
            }
        }
        failed
    }
}
