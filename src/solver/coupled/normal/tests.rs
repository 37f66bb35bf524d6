//! The band solves against faer's sparse ones, and redundant rows dropped
//! by both factorizations.

use super::*;
use bevy::math::DVec2;

/// A pinned chain of `links` rods bent at the beads, and a second set
/// of gradients turned a little from the first: rows 0 and 1 pin bead
/// 0, row 2 + i joins beads i and i + 1.
fn chain(links: usize) -> Rows {
    let mut row_start = vec![0, 1, 2];
    let mut entry_bead = vec![0, 0];
    let mut first = vec![DVec2::X, DVec2::Y];
    let mut now = vec![DVec2::X, DVec2::Y];
    for i in 0..links {
        entry_bead.extend([i, i + 1]);
        let n = DVec2::from_angle(0.4 * i as f64);
        let turned = DVec2::from_angle(0.4 * i as f64 + 0.05);
        first.extend([-n, n]);
        now.extend([-turned, turned]);
        row_start.push(entry_bead.len());
    }
    let inverse_mass = (0..=links).map(|i| 1.0 / (1.0 + i as f64)).collect();
    (row_start, entry_bead, first, now, inverse_mass)
}

/// Rows as [`chain`] gives them: row starts, each entry's bead, the
/// first and the current gradients, the inverse masses.
type Rows = (Vec<usize>, Vec<usize>, Vec<DVec2>, Vec<DVec2>, Vec<f64>);

/// A ring of `beads` rods, each bead joined to the next and the last to
/// the first, with gradients as [`chain`]'s.
fn ring(beads: usize) -> Rows {
    let (mut row_start, mut entry_bead, mut first, mut now) = (vec![0], vec![], vec![], vec![]);
    for i in 0..beads {
        entry_bead.extend([i, (i + 1) % beads]);
        let n = DVec2::from_angle(0.4 * i as f64);
        let turned = DVec2::from_angle(0.4 * i as f64 + 0.05);
        first.extend([-n, n]);
        now.extend([-turned, turned]);
        row_start.push(entry_bead.len());
    }
    let inverse_mass = (0..beads).map(|i| 1.0 / (1.0 + i as f64)).collect();
    (row_start, entry_bead, first, now, inverse_mass)
}

/// The same rows listed in another order: row `r` becomes row
/// `(r · stride) mod n` (`stride` prime to the number of rows `n`).
fn shuffled((row_start, entry_bead, first, now, inverse_mass): Rows, stride: usize) -> Rows {
    let n = row_start.len() - 1;
    let mut from = vec![usize::MAX; n];
    for r in 0..n {
        from[(r * stride) % n] = r;
    }
    assert!(!from.contains(&usize::MAX), "{stride} is not prime to {n}");
    let (mut starts, mut beads, mut firsts, mut nows) = (vec![0], vec![], vec![], vec![]);
    for &r in &from {
        let entries = row_start[r]..row_start[r + 1];
        beads.extend_from_slice(&entry_bead[entries.clone()]);
        firsts.extend_from_slice(&first[entries.clone()]);
        nows.extend_from_slice(&now[entries]);
        starts.push(beads.len());
    }
    (starts, beads, firsts, nows, inverse_mass)
}

/// Solves `J W Jᵀ x = b` and `J_now W J_firstᵀ x = b` for `rows` in
/// the rows' order or a band's (`natural`) and in faer's sparse order,
/// and checks the two agree to 1e-12; returns the layout of the
/// natural order's factorization and whether its band reorders the
/// rows.
fn natural_matches_sparse_for(rows: &Rows, what: &str) -> (Layout, bool) {
    let (row_start, entry_bead, first, now, inverse_mass) = rows;
    let matrix = NormalMatrix::new(row_start, entry_bead, inverse_mass.len()).unwrap();
    let n = row_start.len() - 1;
    let rhs: Vec<f64> = (0..n).map(|r| (r as f64 * 0.7).sin() - 0.2).collect();
    let inactive = vec![false; n];
    let mut solved = [rhs.clone(), rhs.clone()];
    let mut layout = Layout::Sparse;
    for (natural, x) in [true, false].into_iter().zip(&mut solved) {
        let mut f = Factored::default();
        matrix
            .factor(inverse_mass, first, &inactive, natural, &mut f)
            .unwrap();
        assert_eq!(f.redundant, 0, "{what}");
        if natural {
            layout = f.layout;
        }
        matrix.solve(&mut f, x);
    }
    let mut unsymmetric = [rhs.clone(), rhs.clone()];
    for (natural, x) in [true, false].into_iter().zip(&mut unsymmetric) {
        let mut lu = LuWork::default();
        assert!(matrix.solve_unsymmetric(inverse_mass, now, first, &inactive, &mut lu, x, natural));
    }
    for [a, b] in [solved, unsymmetric] {
        for (a, b) in a.iter().zip(&b) {
            assert!(
                (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                "{what}: {a} against {b}"
            );
        }
    }
    let reordered = matrix.band.as_ref().is_some_and(|b| b.position.is_some());
    (layout, reordered)
}

/// [`natural_matches_sparse_for`] a chain of `links` rods in order.
fn natural_matches_sparse(links: usize) -> Layout {
    natural_matches_sparse_for(&chain(links), &format!("{links} links")).0
}

#[test]
fn small_matrices_in_the_rows_order_match_the_sparse_ones() {
    for links in [1, 3, 6] {
        assert_eq!(natural_matches_sparse(links), Layout::Band);
    }
}

#[test]
fn band_solves_of_a_long_chain_match_the_sparse_ones() {
    // The pin's rows and the first rod share bead 0: a band of 2.
    for links in [7, 40, 500] {
        assert_eq!(natural_matches_sparse(links), Layout::Band);
    }
}

#[test]
fn a_chain_listed_out_of_order_and_a_ring_are_solved_as_bands_once_reordered() {
    for links in [40, 500] {
        // Out of order the rows' own band is wide; reordered it is 2.
        let rows = shuffled(chain(links), 11);
        let what = format!("{links} links out of order");
        assert_eq!(
            natural_matches_sparse_for(&rows, &what),
            (Layout::Band, true)
        );
    }
    for beads in [9, 40, 300] {
        let what = format!("a ring of {beads} rods");
        assert_eq!(
            natural_matches_sparse_for(&ring(beads), &what),
            (Layout::Band, true)
        );
    }
    // A chain in order keeps its own order.
    assert_eq!(
        natural_matches_sparse_for(&chain(40), "40 links"),
        (Layout::Band, false)
    );
}

#[test]
fn a_band_matrix_drops_a_redundant_row_and_refuses_a_singular_newton_matrix() {
    // A pinned chain of 20 rods, rod 10 listed twice.
    let (mut row_start, mut entry_bead, mut gradient, _, _) = chain(20);
    let twin = 2 + 10;
    let entries = row_start[twin]..row_start[twin + 1];
    let (beads, grads): (Vec<_>, Vec<_>) = entries
        .clone()
        .map(|e| (entry_bead[e], gradient[e]))
        .unzip();
    entry_bead.splice(entries.end..entries.end, beads);
    gradient.splice(entries.end..entries.end, grads);
    row_start.insert(twin + 1, entries.end);
    for start in &mut row_start[twin + 2..] {
        *start += 2;
    }
    let rows = row_start.len() - 1;
    let matrix = NormalMatrix::new(&row_start, &entry_bead, 21).unwrap();
    let band = matrix.band.as_ref().expect("a band");
    assert_eq!((band.width, band.position.is_none()), (2, true));
    let inverse_mass = vec![1.0; 21];
    let mut f = Factored::default();
    matrix
        .factor(&inverse_mass, &gradient, &vec![false; rows], true, &mut f)
        .unwrap();
    assert_eq!((f.layout, f.redundant), (Layout::Band, 1));
    // Every rod asks for the same push; the twins share one rod's.
    let mut rhs: Vec<f64> = (0..rows).map(|r| if r < 2 { 0.0 } else { 0.3 }).collect();
    let b = rhs.clone();
    matrix.solve(&mut f, &mut rhs);
    assert!(rhs.iter().all(|x| x.is_finite()), "{rhs:?}");
    assert_eq!(
        rhs[twin + 1],
        0.0,
        "the redundant row carries {}",
        rhs[twin + 1]
    );
    // A λ that meets every row: J W Jᵀ λ = b.
    let mut pushed = vec![DVec2::ZERO; 21];
    for r in 0..rows {
        for e in row_start[r]..row_start[r + 1] {
            pushed[entry_bead[e]] += rhs[r] * gradient[e];
        }
    }
    for r in 0..rows {
        let met: f64 = (row_start[r]..row_start[r + 1])
            .map(|e| gradient[e].dot(pushed[entry_bead[e]]))
            .sum();
        assert!(
            (met - b[r]).abs() <= 1e-12,
            "row {r}: {met} against {}",
            b[r]
        );
    }
    let mut lu = LuWork::default();
    assert!(!matrix.solve_unsymmetric(
        &inverse_mass,
        &gradient,
        &gradient,
        &vec![false; rows],
        &mut lu,
        &mut rhs,
        true
    ));
}

#[test]
fn a_small_matrix_drops_a_redundant_row_and_refuses_a_singular_newton_matrix() {
    // The same rod twice between a pinned bead and a free one.
    let row_start = [0, 1, 2, 4, 6];
    let entry_bead = [0, 0, 0, 1, 0, 1];
    let n = DVec2::new(0.6, 0.8);
    let gradient = [DVec2::X, DVec2::Y, -n, n, -n, n];
    let matrix = NormalMatrix::new(&row_start, &entry_bead, 2).unwrap();
    let mut f = Factored::default();
    matrix
        .factor(&[1.0, 1.0], &gradient, &[false; 4], true, &mut f)
        .unwrap();
    assert_eq!((f.layout, f.redundant), (Layout::Band, 1));
    // A consistent right-hand side: the two rods ask for the same.
    let mut rhs = vec![0.0, 0.0, 0.3, 0.3];
    matrix.solve(&mut f, &mut rhs);
    assert!(rhs.iter().all(|x| x.is_finite()), "{rhs:?}");
    // With the pin rows taking bead 0's share the system reduces to
    // λ₂ + λ₃ = 0.3: one rod carries it, the dropped one nothing.
    let pushed = rhs[2] + rhs[3];
    assert!((pushed - 0.3).abs() <= 1e-12, "the rods carry {pushed}");
    assert_eq!(rhs[3], 0.0, "the redundant row carries {}", rhs[3]);
    let mut lu = LuWork::default();
    let mut rhs = vec![0.0, 0.0, 0.3, 0.3];
    assert!(!matrix.solve_unsymmetric(
        &[1.0, 1.0],
        &gradient,
        &gradient,
        &[false; 4],
        &mut lu,
        &mut rhs,
        true,
    ));
}

/// `J W Jᵀ λ − b` on row `r` of `rows` (gradients `gradient`), the
/// largest over the rows not `set_aside`.
fn worst_residual(
    rows: &Rows,
    gradient: &[DVec2],
    lambda: &[f64],
    b: &[f64],
    set_aside: &[bool],
) -> f64 {
    let (row_start, entry_bead, _, _, inverse_mass) = rows;
    let mut pushed = vec![DVec2::ZERO; inverse_mass.len()];
    for r in 0..row_start.len() - 1 {
        for e in row_start[r]..row_start[r + 1] {
            pushed[entry_bead[e]] += lambda[r] * inverse_mass[entry_bead[e]] * gradient[e];
        }
    }
    (0..row_start.len() - 1)
        .filter(|&r| !set_aside[r])
        .map(|r| {
            let met: f64 = (row_start[r]..row_start[r + 1])
                .map(|e| gradient[e].dot(pushed[entry_bead[e]]))
                .sum();
            (met - b[r]).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn rows_set_aside_are_left_out_of_the_sparse_factorization() {
    let rows = ring(24);
    let (row_start, entry_bead, first, _, inverse_mass) = &rows;
    let matrix = NormalMatrix::new(row_start, entry_bead, inverse_mass.len()).unwrap();
    let n = row_start.len() - 1;
    let b: Vec<f64> = (0..n).map(|r| (r as f64 * 0.7).sin() - 0.2).collect();
    let solve = |set_aside: &[usize], f: &mut Factored| {
        let inactive: Vec<bool> = (0..n).map(|r| set_aside.contains(&r)).collect();
        // A row set aside has no gradient.
        let mut gradient = first.clone();
        for &r in set_aside {
            gradient[row_start[r]..row_start[r + 1]].fill(DVec2::ZERO);
        }
        matrix
            .factor(inverse_mass, &gradient, &inactive, false, f)
            .unwrap();
        let mut lambda = b.clone();
        matrix.solve(f, &mut lambda);
        let residual = worst_residual(&rows, &gradient, &lambda, &b, &inactive);
        // The Newton matrix with the same gradients at both ends is `A`.
        let mut stepped = b.clone();
        let mut lu = LuWork::default();
        for natural in [false, true] {
            let solved = matrix.solve_unsymmetric(
                inverse_mass,
                &gradient,
                &gradient,
                &inactive,
                &mut lu,
                &mut stepped,
                natural,
            );
            assert!(solved, "{set_aside:?} set aside");
            for (a, l) in stepped.iter().zip(&lambda) {
                assert!((a - l).abs() <= 1e-12 * (1.0 + l.abs()), "{a} against {l}");
            }
            stepped.clone_from(&b);
        }
        (f.layout, lambda, residual)
    };
    let mut f = Factored::default();
    let (layout, first_lambda, residual) = solve(&[3, 7, 8, 15], &mut f);
    assert_eq!(layout, Layout::Held);
    assert!(residual <= 1e-12, "held rows met to {residual:e}");
    for r in [3, 7, 8, 15] {
        assert_eq!(first_lambda[r], b[r], "row {r} set aside");
    }
    // Another set, every row held, and the first set again: the pattern
    // made again each time, the first answer to the bit.
    let (_, _, residual) = solve(&[0, 1, 23], &mut f);
    assert!(residual <= 1e-12, "held rows met to {residual:e}");
    let (layout, _, residual) = solve(&[], &mut f);
    assert_eq!(layout, Layout::Sparse);
    assert!(residual <= 1e-12, "every row met to {residual:e}");
    let (_, again, _) = solve(&[3, 7, 8, 15], &mut f);
    assert_eq!(again, first_lambda);
    // All rows but one set aside, and all of them.
    let all_but_one: Vec<usize> = (1..n).collect();
    let (_, lambda, residual) = solve(&all_but_one, &mut f);
    assert!(residual <= 1e-12, "the one row met to {residual:e}");
    assert!(lambda.iter().all(|x| x.is_finite()));
    let all: Vec<usize> = (0..n).collect();
    let (_, lambda, _) = solve(&all, &mut f);
    assert_eq!(lambda, b);
}
