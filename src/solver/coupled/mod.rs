//! Many constraints at once: Witkin's system, eqs. (10)–(12).
//!
//! Beads joined by constraints (rods, pins, wires, a game's own
//! [`Constraint`]) and by [`SpringLink`]s form [`islands`]; each
//! [`Island`] is stepped as one system by every [`Method`](super::Method):
//!
//! | file | what it holds |
//! |---|---|
//! | `constraint` | [`Constraint`], [`RowKind`] (what one row contributes), [`SpringLink`] |
//! | `group` | [`islands`]: which beads are joined |
//! | `normal` | `J W Jᵀ`: its pattern, symbolic and numeric factorization (faer) |
//! | `island` | [`Island`]: eq. (10) and each method on an island |

mod constraint;
mod group;
mod island;
mod normal;
#[cfg(test)]
mod tests;

pub use constraint::{Constraint, RowKind, SpringLink};
pub use group::islands;
pub use island::{
    CALM_STEPS, EXACT_STEPS, Island, IslandError, IslandRow, IslandWork, MAX_HALVINGS,
    OFF_THE_WIRE, RowReport,
};
pub use normal::{MAX_BAND, REDUNDANT_PIVOT};
