//! The broad phase against testing every pair, and which beads may
//! touch or are near.

use super::*;

/// Every pair of `boxes` that overlaps, by testing each pair.
fn every_overlapping(boxes: &[(DVec3, DVec3)]) -> Vec<(usize, usize)> {
    let mut every = Vec::new();
    for i in 0..boxes.len() {
        for j in i + 1..boxes.len() {
            let (a, b) = (boxes[i], boxes[j]);
            if a.0.cmple(b.1).all() && b.0.cmple(a.1).all() {
                every.push((i, j));
            }
        }
    }
    every
}

proptest::proptest! {
    /// The grid finds exactly the overlapping pairs that testing every
    /// pair finds, for boxes of a hair to many cells across, points, and
    /// boxes that share a face.
    #[test]
    fn the_broad_phase_finds_every_overlapping_pair(
        boxes in proptest::collection::vec(
            (
                (-5.0..5.0f64, -5.0..5.0f64, -5.0..5.0f64),
                proptest::prop_oneof![
                    (0.0..0.3f64, 0.0..0.3f64, 0.0..0.3f64),
                    (0.0..2.0f64, 0.0..2.0f64, 0.0..2.0f64),
                    (4.0..12.0f64, 0.0..12.0f64, 0.0..1.0f64),
                    (0.0..1e-300f64, 0.0..1e-300f64, 0.0..1e-300f64),
                ],
            ),
            0..60,
        ),
    ) {
        let mut boxes: Vec<(DVec3, DVec3)> = boxes
            .into_iter()
            .map(|((x, y, z), (w, h, d))| {
                let low = DVec3::new(x, y, z);
                (low, low + DVec3::new(w, h, d))
            })
            .collect();
        // One box that shares a face with the first.
        if let Some(&(low, high)) = boxes.first() {
            let width = DVec3::X * (high.x - low.x);
            boxes.push((low + width, high + width));
        }
        proptest::prop_assert_eq!(overlapping(&boxes), every_overlapping(&boxes));
    }
}

/// A box with a NaN corner overlaps nothing; an infinite one, or one
/// far beyond the grid, overlaps every box it meets; boxes a kilometre
/// across among beads of a centimetre are found as pairs too.
#[test]
fn the_broad_phase_takes_nan_infinite_far_and_huge_boxes() {
    let unit = |x: f64, y: f64| {
        let low = DVec3::new(x, y, 0.0);
        (low, low + DVec3::splat(0.01))
    };
    let mut boxes: Vec<(DVec3, DVec3)> = (0..200)
        .map(|k| unit(0.007 * (k % 20) as f64, 0.007 * (k / 20) as f64))
        .collect();
    boxes.push((DVec3::NAN, DVec3::ONE));
    boxes.push((DVec3::splat(f64::NEG_INFINITY), DVec3::splat(f64::INFINITY)));
    boxes.push((DVec3::splat(-500.0), DVec3::splat(500.0)));
    boxes.push((DVec3::splat(1e300), DVec3::splat(f64::INFINITY)));
    boxes.push((DVec3::new(0.05, 0.05, -1.0), DVec3::new(0.05, 0.05, 1.0)));
    let found = overlapping(&boxes);
    assert_eq!(found, every_overlapping(&boxes));
    let nan = 200;
    assert!(!found.iter().any(|&(i, j)| i == nan || j == nan));
    // The infinite box meets all but the NaN one.
    assert_eq!(
        found.iter().filter(|&&(i, j)| i == 201 || j == 201).count(),
        203
    );
}

/// Two beads of radius 0.1 m, 1 m apart: at rest they may not touch
/// within a second; closing at 0.5 m/s each they may (1 m of boxes grown
/// by twice the way), and moving along lines 0.3 m apart they may not
/// (each box grows along its motion only).
#[test]
fn beads_may_touch_only_where_their_motion_can_bring_them_together() {
    let bead = |x: f64, y: f64, vx: f64| {
        (
            BeadState {
                position: DVec2::new(x, y),
                velocity: DVec2::new(vx, 0.0),
            },
            0.1,
        )
    };
    assert!(may_touch(&[bead(0.0, 0.0, 0.0), bead(1.0, 0.0, 0.0)], 1.0, 0.0).is_empty());
    assert_eq!(
        may_touch(&[bead(0.0, 0.0, 0.5), bead(1.0, 0.0, -0.5)], 1.0, 0.0),
        vec![(0, 1)]
    );
    assert!(may_touch(&[bead(0.0, 0.0, 5.0), bead(0.5, 0.3, -5.0)], 1.0, 0.0).is_empty());
}

/// The pairs an island builder joins: in a cube of 27 marbles of 2 cm at
/// rest, 2r apart along the axes, the 54 pairs side by side along an
/// axis, not the 104 more whose boxes meet along the diagonals of a
/// cell (0.83 and 1.46 of a radius apart).
#[test]
fn beads_are_near_where_their_gap_may_close_not_where_their_boxes_meet() {
    let (r, dt) = (0.02, 1.0 / 240.0);
    let spacing = 2.0 * r * (1.0 + 1e-12);
    let beads: Vec<(BeadState<DVec3>, f64)> = (0..27)
        .map(|k| {
            let at = DVec3::new((k % 3) as f64, ((k / 3) % 3) as f64, (k / 9) as f64);
            let state = BeadState {
                position: at * spacing,
                velocity: DVec3::ZERO,
            };
            (state, r)
        })
        .collect();
    let boxes = may_touch(&beads, 2.0 * dt, 0.25);
    let near = may_touch_near(&beads, (2.0 * dt, 0.25), dt);
    assert_eq!((boxes.len(), near.len()), (158, 54));
    for (i, j) in near {
        let d = beads[j].0.position - beads[i].0.position;
        assert!((d.length() - spacing).abs() <= 1e-15, "{i} and {j} are {d}");
    }
}

proptest::proptest! {
    /// Every pair a regrouping looks for ([`may_touch`] within a step,
    /// no margin) is among those an island builder joins
    /// ([`may_touch_near`] within two steps, a quarter of the radii to
    /// spare), so that a rebuild joins every pair that asked for it.
    #[test]
    fn the_pairs_a_regrouping_looks_for_are_near(
        beads in proptest::collection::vec(
            ((-0.2..0.2f64, -0.2..0.2f64, -0.2..0.2f64), (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64), 0.005..0.03f64),
            0..60,
        ),
    ) {
        let beads: Vec<(BeadState<DVec3>, f64)> = beads
            .into_iter()
            .map(|((x, y, z), (u, v, w), r)| {
                let state = BeadState { position: DVec3::new(x, y, z), velocity: DVec3::new(u, v, w) };
                (state, r)
            })
            .collect();
        let dt = 1.0 / 60.0;
        let near = may_touch_near(&beads, (2.0 * dt, 0.25), dt);
        for pair in may_touch(&beads, dt, 0.0) {
            proptest::prop_assert!(near.binary_search(&pair).is_ok(), "{:?} is not near", pair);
        }
    }
}
