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
    a: (f64, f64),
    b: (f64, f64),
    h: f64,
    g: impl FnMut(f64) -> Result<f64, SolveError>,
) -> Result<f64, SolveError> {
    bracket_root(a, b, 1e-13 * h, g)
}

/// Regula falsi with the Illinois modification within the bracket from
/// `a` (where `g` is positive) to `b` (where it is not), each with its
/// value of `g`, until the bracket is at most `width` wide (none: until
/// no number lies between its ends), at most 100 trials: the end `b` of
/// the last bracket. Where the line through the ends falls outside the
/// bracket, its middle is tried.
pub(crate) fn bracket_root<E>(
    (mut a, mut ga): (f64, f64),
    (mut b, mut gb): (f64, f64),
    width: f64,
    mut g: impl FnMut(f64) -> Result<f64, E>,
) -> Result<f64, E> {
    let mut last = 0;
    for _ in 0..100 {
        if b - a <= width || gb == 0.0 {
            break;
        }
        let mut m = b - gb * (b - a) / (gb - ga);
        if !(m > a && m < b) {
            m = 0.5 * (a + b);
            if !(m > a && m < b) {
                break; // a and b are neighbours: to the last bit
            }
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
