//! The band ordering of `A`'s rows: the rows' own order where its band is
//! narrow, else a reverse Cuthill–McKee order of them.

use super::{DENSE_ROWS, MAX_BAND};

/// A band ordering of the rows: no two rows that share a bead are more
/// than `width` places apart.
#[derive(Clone, Debug)]
pub(super) struct Band {
    pub(super) width: usize,
    /// Each row's place in the band (`None`: its own index).
    pub(super) position: Option<Vec<usize>>,
}

impl Band {
    /// Row `r`'s place in the band.
    #[inline(always)]
    pub(super) fn at(&self, r: usize) -> usize {
        self.position.as_ref().map_or(r, |p| p[r])
    }

    /// `rhs` (by row) into `out` (by place in the band).
    pub(super) fn gather(&self, rhs: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.resize(rhs.len(), 0.0);
        for (r, &b) in rhs.iter().enumerate() {
            out[self.at(r)] = b;
        }
    }

    /// `solved` (by place in the band) back into `rhs` (by row).
    pub(super) fn scatter(&self, solved: &[f64], rhs: &mut [f64]) {
        for (r, b) in rhs.iter_mut().enumerate() {
            *b = solved[self.at(r)];
        }
    }
}

/// The band ordering of a matrix of `n` rows whose upper entries are at
/// `(row[k], column[k])`: the rows' own order where its band is at most
/// [`MAX_BAND`] or there are at most [`DENSE_ROWS`] rows, else a reverse
/// Cuthill–McKee order where that band is at most [`MAX_BAND`].
pub(super) fn band_of(column: &[usize], row: &[usize], n: usize) -> Option<Band> {
    let width = |at: &dyn Fn(usize) -> usize| {
        column
            .iter()
            .zip(row)
            .map(|(&c, &r)| at(c).abs_diff(at(r)))
            .max()
            .unwrap_or(0)
    };
    let own = width(&|r| r);
    if n <= DENSE_ROWS || own <= MAX_BAND {
        return Some(Band {
            width: own,
            position: None,
        });
    }
    let mut neighbours = vec![Vec::new(); n];
    for (&c, &r) in column.iter().zip(row) {
        if c != r {
            neighbours[c].push(r);
            neighbours[r].push(c);
        }
    }
    let position = cuthill_mckee(&neighbours);
    let reordered = width(&|r| position[r]);
    (reordered <= MAX_BAND).then_some(Band {
        width: reordered,
        position: Some(position),
    })
}

/// Each row's place in a reverse Cuthill–McKee order of the rows, where
/// `neighbours[r]` are the rows that share a bead with row `r`: a
/// breadth-first walk from a row of fewest neighbours, each row's new
/// neighbours taken fewest first, reversed. For a chain of rods listed in
/// any order it gives back the chain's band; a ring of rods gets a band of
/// two.
fn cuthill_mckee(neighbours: &[Vec<usize>]) -> Vec<usize> {
    let n = neighbours.len();
    let degree = |r: usize| neighbours[r].len();
    let mut starts: Vec<usize> = (0..n).collect();
    starts.sort_by_key(|&r| degree(r));
    let mut placed = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut next = Vec::new();
    for start in starts {
        if placed[start] {
            continue;
        }
        placed[start] = true;
        order.push(start);
        let mut head = order.len() - 1;
        while head < order.len() {
            let r = order[head];
            head += 1;
            next.clear();
            next.extend(neighbours[r].iter().copied().filter(|&s| !placed[s]));
            next.sort_by_key(|&s| degree(s));
            for &s in &next {
                placed[s] = true;
                order.push(s);
            }
        }
    }
    let mut position = vec![0; n];
    for (place, &r) in order.iter().rev().enumerate() {
        position[r] = place;
    }
    position
}
