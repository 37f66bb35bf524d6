//! Where within a part of a step an event falls (a leaving, a landing, a
//! stop): regula falsi on the part's length, for a lone bead and an
//! island alike.

use super::Walk;
use crate::geometry::{Coordinates, Track};
use crate::solver::solve::SolveError;
use crate::solver::state::BeadState;

impl<V: Coordinates, T: Track<V> + ?Sized> Walk<'_, T, V> {
    /// Where within a part of length `h` from `state` at `t` (sliding
    /// along `sliding`) the measure `g` (`g0` at the start, positive; not
    /// positive at the end) reaches zero: the time and the state there.
    pub(super) fn cut(
        &self,
        t: f64,
        h: f64,
        state: BeadState<V>,
        sliding: V,
        g0: f64,
        g: impl Fn(f64, BeadState<V>) -> Result<f64, SolveError>,
    ) -> Result<(f64, BeadState<V>), SolveError> {
        let tau = locate(h, g0, |tau| {
            g(tau, self.slide(t, tau, state, sliding)?.state)
        })?;
        Ok((t + tau, self.slide(t, tau, state, sliding)?.state))
    }
}

/// The sub-step length in `(0, h]` where `g` (`g0` at 0, positive;
/// not positive at `h`) reaches zero: regula falsi with the Illinois
/// modification, to a relative width of 1e-13 of `h`.
pub(crate) fn locate(
    h: f64,
    g0: f64,
    mut g: impl FnMut(f64) -> Result<f64, SolveError>,
) -> Result<f64, SolveError> {
    if g0.is_nan() || g0 <= 0.0 {
        return Ok(0.0);
    }
    let gh = g(h)?;
    locate_between((0.0, g0), (h, gh), h, g)
}

/// [`locate`] within the bracket from `a` (where `g` is positive) to `b`
/// (where it is not), each with its value of `g`, to a width of 1e-13 of
/// `h`: the end `b` of the last bracket.
pub(crate) fn locate_between(
    (mut a, mut ga): (f64, f64),
    (mut b, mut gb): (f64, f64),
    h: f64,
    mut g: impl FnMut(f64) -> Result<f64, SolveError>,
) -> Result<f64, SolveError> {
    let mut last = 0;
    for _ in 0..100 {
        if b - a <= 1e-13 * h || gb == 0.0 {
            break;
        }
        let mut m = b - gb * (b - a) / (gb - ga);
        if !(m > a && m < b) {
            m = 0.5 * (a + b);
        }
        let gm = g(m)?;
        if gm > 0.0 {
            a = m;
            ga = gm;
            if last == 1 {
                gb *= 0.5;
            }
            last = 1;
        } else {
            b = m;
            gb = gm;
            if last == -1 {
                ga *= 0.5;
            }
            last = -1;
        }
    }
    Ok(b)
}
