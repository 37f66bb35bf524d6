//! [`Island::new`]: an island's beads, rows and springs checked and laid
//! out, and why one cannot be built ([`IslandError`]).

use bevy::math::DVec2;
use std::sync::Arc;

use super::Island;
use crate::geometry::WireSpace;
use crate::solver::coupled::IslandError;
use crate::solver::coupled::constraint::{RowKind, SpringLink};
use crate::solver::coupled::normal::NormalMatrix;

/// One constraint row of an island: what it is and the beads it joins
/// (indices into the island's beads).
#[derive(Clone, Debug)]
pub struct IslandRow<V: WireSpace = DVec2> {
    /// The kind of constraint.
    pub kind: RowKind<V>,
    /// The beads, in the order the kind takes them.
    pub beads: Vec<usize>,
}

fn describe<V: WireSpace>(r: usize, kind: &RowKind<V>) -> String {
    let what = match kind {
        RowKind::Wire { .. } => "wire",
        RowKind::Rod { .. } => "rod",
        RowKind::Axis { .. } => "pin",
        RowKind::Custom(_) => "custom",
    };
    format!("constraint {r} ({what})")
}

impl<V: WireSpace> Island<V> {
    /// An island of beads of the given masses, joined by `rows` and
    /// `springs`; every index and value is checked.
    pub fn new(
        masses: &[f64],
        rows: Vec<IslandRow<V>>,
        springs: Vec<SpringLink>,
    ) -> Result<Self, IslandError> {
        let beads = masses.len();
        let mut inverse_mass = Vec::with_capacity(beads);
        for (bead, &mass) in masses.iter().enumerate() {
            if !(mass.is_finite() && mass > 0.0) {
                return Err(IslandError::Mass { bead, mass });
            }
            inverse_mass.push(mass.recip());
        }
        let check_beads = |item: &dyn Fn() -> String, named: &[usize]| {
            for (i, &bead) in named.iter().enumerate() {
                if bead >= beads {
                    return Err(IslandError::MissingBead {
                        item: item(),
                        bead,
                        beads,
                    });
                }
                if named[..i].contains(&bead) {
                    return Err(IslandError::SameBead { item: item(), bead });
                }
            }
            Ok(())
        };
        let mut row_start = vec![0];
        let mut entry_bead = Vec::new();
        let mut kinds = Vec::with_capacity(rows.len());
        for (r, row) in rows.into_iter().enumerate() {
            let item = || describe(r, &row.kind);
            let expected = row.kind.arity().unwrap_or(row.beads.len().max(1));
            if row.beads.len() != expected {
                return Err(IslandError::Arity {
                    item: item(),
                    expected,
                    got: row.beads.len(),
                });
            }
            check_beads(&item, &row.beads)?;
            let bad = |what, range, value| IslandError::Value {
                item: item(),
                what,
                range,
                value,
            };
            match &row.kind {
                RowKind::Rod { length } if !(length.is_finite() && *length > 0.0) => {
                    return Err(bad("length", "positive and finite", *length));
                }
                RowKind::Axis { axis, offset } => {
                    let off = (axis.dot(*axis).sqrt() - 1.0).abs();
                    if off.is_nan() || off >= 1e-12 {
                        return Err(bad("|axis|", "1", axis.dot(*axis).sqrt()));
                    }
                    if !offset.is_finite() {
                        return Err(bad("the point", "finite", *offset));
                    }
                }
                _ => {}
            }
            entry_bead.extend_from_slice(&row.beads);
            row_start.push(entry_bead.len());
            kinds.push(row.kind);
        }
        for (s, spring) in springs.iter().enumerate() {
            let item = || format!("spring {s}");
            check_beads(&item, &[spring.a, spring.b])?;
            for (what, value) in [
                ("rest length", spring.rest_length),
                ("stiffness", spring.stiffness),
                ("damping", spring.damping),
            ] {
                if !(value.is_finite() && value >= 0.0) {
                    return Err(IslandError::Value {
                        item: item(),
                        what,
                        range: "zero or more and finite",
                        value,
                    });
                }
            }
        }
        let normal = NormalMatrix::new(&row_start, &entry_bead, beads)
            .map(Arc::new)
            .ok_or(IslandError::OutOfMemory)?;
        let paths = vec![None; kinds.len()];
        let sides = vec![(0.0, 0.0); kinds.len()];
        let rough = vec![None; kinds.len()];
        let contacts = vec![false; kinds.len()];
        let catching = vec![false; kinds.len()];
        let mut island = Self {
            inverse_mass,
            rows: kinds,
            row_start,
            entry_bead,
            springs,
            normal,
            paths,
            moving: 0,
            sides,
            contacts,
            contact_rows: 0,
            catching,
            ended: 0,
            rough,
            rough_rows: 0,
        };
        island.count_ends();
        Ok(island)
    }
}
