//! Many constraints at once: Witkin's system, eqs. (12)–(14).
//!
//! Beads joined by constraints (rods, pins, wires, a game's own
//! [`Constraint`]) and by [`SpringLink`]s form [`islands`]; each
//! [`Island`] is stepped as one system by every [`Method`](super::Method).
//! One file or folder (with a table of its own) per piece:
//!
//! | file | what it holds |
//! |---|---|
//! | `constraint` | [`Constraint`], [`RowKind`] (what one row contributes), [`SpringLink`] |
//! | `error` | [`IslandError`]: why an island cannot be built or answer |
//! | `group` | [`islands`]: which beads are joined |
//! | `lcp` | the complementarity problems of dense contact, by projected Newton steps |
//! | `normal/` (`pattern`, `order`, `band_ldlt`, `band_lu`, `sparse_ldlt`, `sparse_lu`) | `J W Jᵀ`: its patterns, band ordering, and band and sparse (faer) factorizations |
//! | `island/` (`build`, `rows`, `step`, `integrators`, `newton`, `projection`, `contact`, `dense`, …) | [`Island`]: building, row evaluation, each method, projection, contact and friction |
//! | `tests/` (`methods`, `rows`, `ropes`, `contact`) | islands against the single-bead solver and physics |

mod constraint;
mod error;
mod group;
mod island;
mod lcp;
mod normal;
#[cfg(test)]
mod tests;

pub use constraint::{Constraint, RowKind, SpringLink};
pub use error::IslandError;
pub use group::islands;
pub(crate) use island::TOUCHING;
pub use island::{Island, IslandMark, IslandRow, IslandWork, RowReport};
pub(crate) use island::{
    closes, ends_in_touch, meets_near, meets_slowly, opening_rate, pair_gap, pair_speeds, parts,
    step_speed,
};
