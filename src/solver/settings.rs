//! [`StepSettings`]: what is the same for every bead in a step. Nothing
//! that belongs to one bead (its mass, its state, its force) lives here.

use super::method::{Integrator, Method, Stabilization};

/// The settings of one step, shared by every bead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSettings {
    /// Step length `h` in seconds.
    pub dt: f64,
    /// The integrator and its stabilization.
    pub method: Method,
    /// Baumgarte α of eq. (2) (used only with [`Stabilization::Baumgarte`]).
    pub alpha: f64,
    /// Baumgarte β of eq. (2) (used only with [`Stabilization::Baumgarte`]).
    pub beta: f64,
    /// The largest `|C|` a step may leave, in units of the wire's
    /// [`scale`](crate::geometry::ImplicitCurve::scale), before the run is
    /// declared blown up; checked before any projection.
    pub drift_bound: f64,
}

/// A part of a step shorter than this fraction of the step is best taken
/// by a method whose velocity does not come from a position difference
/// over the part (RK4 with projection): RATTLE's loses the digits the
/// part is short by.
const SHORT_PART: f64 = 1e-3;

impl StepSettings {
    /// The settings for a part `h` of this step: RK4 with projection where
    /// the part is shorter than a thousandth of the step, the step's own
    /// method otherwise.
    pub fn part(&self, h: f64) -> Self {
        let method = if h < SHORT_PART * self.dt {
            Method::new(Integrator::Rk4, Some(Stabilization::Projection)).unwrap_or_default()
        } else {
            self.method
        };
        Self {
            dt: h,
            method,
            ..*self
        }
    }

    /// The gains that enter eq. (3): the configured α and β under
    /// Baumgarte, zero otherwise.
    pub fn gains(&self) -> Gains {
        match self.method.stabilization() {
            Some(Stabilization::Baumgarte) => Gains {
                alpha: self.alpha,
                beta: self.beta,
            },
            _ => Gains::NONE,
        }
    }
}

/// Baumgarte's α and β as eq. (3) uses them: zero where the method does
/// not stabilize by Baumgarte.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Gains {
    /// α (1/s²).
    pub alpha: f64,
    /// β (1/s).
    pub beta: f64,
}

impl Gains {
    /// No stabilization: λ keeps `C̈ = 0`.
    pub const NONE: Self = Self {
        alpha: 0.0,
        beta: 0.0,
    };
}
