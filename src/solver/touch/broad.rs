//! The broad phase: which boxes overlap, by a uniform grid of cells as
//! large as a typical box, so that a pile of ten thousand beads costs a
//! few entries per bead however deep it is (a sweep along one axis holds
//! a whole column of the pile open at once).

use bevy::math::{DVec3, I64Vec3};

/// A box spanning more cells than this is tested against every other box
/// instead of entered into its cells: a bead so fast that its swept box
/// is many beads long.
const MOST_CELLS: i64 = 64;

/// A cell coordinate beyond this (in cells from the origin) is not
/// entered into the grid: a box that far away is tested against every
/// other. Each coordinate so fits in 21 bits of a cell's key.
const FARTHEST_CELL: i64 = (1 << 20) - 1;

/// Up to this many boxes are tested pair by pair, without a grid.
const FEW: usize = 16;

/// The grid's cells are this many times the median box's largest side:
/// a box covers one or two of them along each axis.
const CELL_BOXES: f64 = 2.0;

/// The pairs of boxes `(lowest, highest corner)` that overlap (touching
/// faces count), each as `(i, j)` with `i < j`, in order. A box with a
/// NaN corner overlaps nothing.
///
/// Each box is entered into the cells of a grid it covers, from the
/// boxes' lowest corner, the cell's side [`CELL_BOXES`] times the median
/// of the boxes' largest sides; the boxes sharing a cell
/// are tested pairwise, and a pair that overlaps is reported from one
/// cell only: the one holding the lowest corner of their intersection.
/// A box covering more than [`MOST_CELLS`] cells (or an infinite one) is
/// tested against every box instead.
pub(crate) fn overlapping(boxes: &[(DVec3, DVec3)]) -> Vec<(usize, usize)> {
    let overlap = |i: usize, j: usize| {
        let ((a_low, a_high), (b_low, b_high)) = (boxes[i], boxes[j]);
        a_low.cmple(b_high).all() && b_low.cmple(a_high).all()
    };
    // A few boxes: every pair, already in order.
    if boxes.len() <= FEW {
        let mut pairs = Vec::new();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if overlap(i, j) {
                    pairs.push((i, j));
                }
            }
        }
        return pairs;
    }
    let side = CELL_BOXES * cell_side(boxes);
    // The grid starts at the lowest corner, so that boxes all alike
    // along an axis (beads in the plane along z) share one cell on it.
    let origin = boxes
        .iter()
        .map(|b| b.0)
        .filter(|low| low.is_finite())
        .reduce(DVec3::min)
        .unwrap_or(DVec3::ZERO);
    // Where `p` is in cells from the origin: a box entered in the grid
    // lies at or above it, so that each coordinate's cell is its whole
    // part (a conversion, not a call to `floor`).
    let inverse = side.recip();
    let scaled = |p: DVec3| (p - origin) * inverse;
    // A cell's coordinates, each within FARTHEST_CELL, packed in one key.
    let key = |c: I64Vec3| {
        let c = (c + FARTHEST_CELL + 1).as_u64vec3();
        (c.x << 42) | (c.y << 21) | c.z
    };
    let mut entries: Vec<(u64, u32)> = Vec::with_capacity(4 * boxes.len());
    let mut large = Vec::new();
    for (i, &(low, high)) in boxes.iter().enumerate() {
        if low.is_nan() || high.is_nan() {
            continue;
        }
        let (from, to) = (scaled(low), scaled(high));
        let within = |c: DVec3| c.min_element() >= 0.0 && c.max_element() <= FARTHEST_CELL as f64;
        // Within the grid, each coordinate's cell is its whole part.
        let cells = (within(from) && within(to)).then(|| (from.as_i64vec3(), to.as_i64vec3()));
        let Some((from, to)) = cells.filter(|(from, to)| {
            let span = (*to - *from + 1).max(I64Vec3::ONE);
            span.x * span.y * span.z <= MOST_CELLS
        }) else {
            large.push(i);
            continue;
        };
        for x in from.x..=to.x {
            for y in from.y..=to.y {
                for z in from.z..=to.z {
                    entries.push((key(I64Vec3::new(x, y, z)), i as u32));
                }
            }
        }
    }
    let mut pairs = Vec::new();
    for bucket in bucketed(&entries).chunk_by(|a, b| a.0 == b.0) {
        for (k, &(_, here, i)) in bucket.iter().enumerate() {
            for &(_, there, j) in &bucket[k + 1..] {
                let (i, j) = (i as usize, j as usize);
                if here != there || !overlap(i, j) {
                    continue;
                }
                // Reported from the cell of the intersection's lowest
                // corner, which both boxes cover, and from no other.
                let corner = scaled(boxes[i].0.max(boxes[j].0)).as_i64vec3();
                if key(corner) == here {
                    pairs.push((i.min(j), i.max(j)));
                }
            }
        }
    }
    for (k, &i) in large.iter().enumerate() {
        for j in 0..boxes.len() {
            // Two large boxes once; a NaN box never overlaps.
            let once = large[..=k].binary_search(&j).is_err();
            if j != i && once && overlap(i, j) {
                pairs.push((i.min(j), i.max(j)));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

/// The grid's entries `(cell key, box)` gathered by a hash of their key,
/// each as `(hash, key, box)`, those of one hash together (a counting
/// sort, in time linear in the entries): the boxes sharing a cell share a
/// hash, and a hash's few entries of other cells are told apart by key.
fn bucketed(entries: &[(u64, u32)]) -> Vec<(u32, u64, u32)> {
    let bits = entries.len().max(2).next_power_of_two().trailing_zeros();
    // Fibonacci hashing: the top `bits` bits of the key times 2⁶⁴/φ.
    let hash = |key: u64| (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - bits)) as u32;
    let mut starts = vec![0u32; (1usize << bits) + 1];
    for &(key, _) in entries {
        starts[hash(key) as usize + 1] += 1;
    }
    for b in 1..starts.len() {
        starts[b] += starts[b - 1];
    }
    let mut gathered = vec![(0u32, 0u64, 0u32); entries.len()];
    for &(key, i) in entries {
        let h = hash(key);
        let slot = &mut starts[h as usize];
        gathered[*slot as usize] = (h, key, i);
        *slot += 1;
    }
    gathered
}

/// The side of the grid's cells: the median of the finite boxes' largest
/// sides, or 1 where that is not positive (every box a point).
fn cell_side(boxes: &[(DVec3, DVec3)]) -> f64 {
    let mut sides: Vec<f64> = boxes
        .iter()
        .map(|(low, high)| (*high - *low).max_element())
        .filter(|s| s.is_finite() && *s > 0.0)
        .collect();
    if sides.is_empty() {
        return 1.0;
    }
    let middle = sides.len() / 2;
    *sides.select_nth_unstable_by(middle, f64::total_cmp).1
}
