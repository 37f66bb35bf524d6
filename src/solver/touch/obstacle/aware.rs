//! A body of beads that keeps nothing between its steps (a bead alone on
//! its wire) that meets obstacles in every part of its step it is stepped
//! over ([`MeetsObstacles`]): so that the settlement of the beads' own
//! touches, which steps each body again from instants of its choosing,
//! steps it with its strikes on the bodies of the world, and what a bead
//! bounced back from a wall meets behind it is met where it is.

use super::{
    BodyPoint, BodyPush, Nearest, Obstacle, ObstaclePair, ObstacleStrike, SHORTEST, meet_obstacles,
};
use crate::geometry::Coordinates;
use crate::solver::solve::SolveError;
use crate::solver::state::BeadState;
use crate::solver::touch::{StepSpan, TouchBody, TouchError};

/// What a body's beads did to the bodies of the world: its strikes and
/// its pushes.
pub(crate) type Met<V> = (Vec<ObstacleStrike<V>>, Vec<BodyPush<V>>);

/// A body `B` that keeps nothing between its steps, meeting `obstacles`
/// (the pairs `pairs`) in each part of the step `span` it is stepped
/// over. What the parts kept (up to each [`TouchBody::keep`], and those
/// the body finishes with) did is [`MeetsObstacles::met`].
pub(crate) struct MeetsObstacles<'a, V, B> {
    inner: B,
    span: StepSpan,
    pairs: Vec<ObstaclePair>,
    obstacles: &'a [&'a dyn Obstacle<V>],
    last: Met<V>,
    kept: Met<V>,
    failed: Option<TouchError>,
}

impl<'a, V: Coordinates, B: TouchBody<V>> MeetsObstacles<'a, V, B> {
    /// `inner` meeting `obstacles` over `span` as `pairs` say.
    pub(crate) fn new(
        inner: B,
        span: StepSpan,
        (pairs, obstacles): (Vec<ObstaclePair>, &'a [&'a dyn Obstacle<V>]),
    ) -> Self {
        Self {
            inner,
            span,
            pairs,
            obstacles,
            last: (Vec::new(), Vec::new()),
            kept: (Vec::new(), Vec::new()),
            failed: None,
        }
    }

    /// Its pairs.
    pub(crate) fn pairs(&self) -> &[ObstaclePair] {
        &self.pairs
    }

    /// What the parts it kept did, and why a part failed, if one did.
    pub(crate) fn met(&mut self) -> (Met<V>, Option<TouchError>) {
        let kept = std::mem::take(&mut self.kept);
        (kept, self.failed.take())
    }

    /// Takes what the last part did as kept.
    fn commit(&mut self) {
        self.kept.0.append(&mut self.last.0);
        self.kept.1.append(&mut self.last.1);
    }
}

impl<V: Coordinates, B: TouchBody<V>> TouchBody<V> for MeetsObstacles<'_, V, B> {
    fn start(&self) -> &[BeadState<V>] {
        self.inner.start()
    }

    fn end(&self) -> &[BeadState<V>] {
        self.inner.end()
    }

    fn advance(
        &mut self,
        time: f64,
        h: f64,
        states: &mut [BeadState<V>],
    ) -> Result<(), SolveError> {
        self.last.0.clear();
        self.last.1.clear();
        // A part too short to meet anything in (what a settlement's
        // instants leave between them), stepped as it is.
        if self.pairs.is_empty() || h.is_nan() || h <= SHORTEST * self.span.dt {
            return self.inner.advance(time, h, states);
        }
        let before = states.to_vec();
        self.inner.advance(time, h, states)?;
        let from = (time - self.span.time) / self.span.dt;
        let scale = h / self.span.dt;
        let mut parts: Vec<PartOf<V>> = self
            .obstacles
            .iter()
            .map(|&obstacle| PartOf {
                obstacle,
                from,
                scale,
            })
            .collect();
        let mut obstacles: Vec<&mut dyn Obstacle<V>> = parts
            .iter_mut()
            .map(|p| p as &mut dyn Obstacle<V>)
            .collect();
        let mut part = Part {
            inner: &mut self.inner,
            start: before,
            end: states.to_vec(),
        };
        let span = StepSpan { time, dt: h };
        let (struck, pushed) = &mut self.last;
        match meet_obstacles(
            span,
            &mut part,
            (&self.pairs, &mut obstacles),
            true,
            (struck, pushed),
        ) {
            Ok(()) => states.copy_from_slice(&part.end),
            Err(TouchError::Solve(e)) => return Err(e),
            Err(e) => self.failed = Some(e),
        }
        Ok(())
    }

    fn keep(&mut self) {
        self.commit();
        self.inner.keep();
    }

    fn respond(
        &mut self,
        time: f64,
        states: &[BeadState<V>],
        bead: usize,
        impulse: V,
    ) -> Result<Vec<V>, SolveError> {
        self.inner.respond(time, states, bead, impulse)
    }

    fn push(&self, bead: usize) -> V {
        self.inner.push(bead)
    }

    fn finish(&mut self, states: &[BeadState<V>]) {
        self.commit();
        self.inner.finish(states);
    }

    fn restart(&mut self, time: f64, dt: f64) -> Result<(), SolveError> {
        self.kept.0.clear();
        self.kept.1.clear();
        let mut states = self.start().to_vec();
        self.advance(time, dt, &mut states)?;
        self.finish(&states);
        Ok(())
    }
}

/// One part of a step of a body that keeps nothing between its steps, as
/// [`meet_obstacles`] takes a whole step: from `start` to `end`.
struct Part<'a, V, B> {
    inner: &'a mut B,
    start: Vec<BeadState<V>>,
    end: Vec<BeadState<V>>,
}

impl<V: Coordinates, B: TouchBody<V>> TouchBody<V> for Part<'_, V, B> {
    fn start(&self) -> &[BeadState<V>] {
        &self.start
    }

    fn end(&self) -> &[BeadState<V>] {
        &self.end
    }

    fn advance(
        &mut self,
        time: f64,
        h: f64,
        states: &mut [BeadState<V>],
    ) -> Result<(), SolveError> {
        self.inner.advance(time, h, states)
    }

    fn keep(&mut self) {}

    fn respond(
        &mut self,
        time: f64,
        states: &[BeadState<V>],
        bead: usize,
        impulse: V,
    ) -> Result<Vec<V>, SolveError> {
        self.inner.respond(time, states, bead, impulse)
    }

    fn push(&self, bead: usize) -> V {
        self.inner.push(bead)
    }

    fn finish(&mut self, states: &[BeadState<V>]) {
        self.end = states.to_vec();
    }
}

/// An obstacle over a part of the step (from the part `from` of it, a
/// part `scale` of it long), as the part's own step: it moves on as
/// over the whole step, and the part's strikes do not move it (a part
/// may be stepped again; what the body keeps moves it after the step).
struct PartOf<'a, V> {
    obstacle: &'a dyn Obstacle<V>,
    from: f64,
    scale: f64,
}

impl<V> Obstacle<V> for PartOf<'_, V> {
    fn nearest(&self, s: f64, at: V) -> Option<Nearest<V>> {
        self.obstacle.nearest(self.from + s * self.scale, at)
    }

    fn point(&self, s: f64, at: V) -> BodyPoint {
        self.obstacle.point(self.from + s * self.scale, at)
    }

    fn reach(&self) -> f64 {
        self.obstacle.reach() * self.scale
    }

    fn surface(&self) -> (f64, f64) {
        self.obstacle.surface()
    }

    fn struck(&mut self, _: f64, _: V, _: V) {}
}
