//! Why an island cannot be built or answer what it is asked
//! ([`IslandError`]).

/// Why an island cannot be built (a constraint or spring that names a bead
/// it cannot join, a bad mass or value) or cannot answer what it is asked
/// (a slice or row that does not fit it).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum IslandError {
    /// A bead's mass is not positive and finite.
    #[error("bead {bead} has mass {mass}; a mass must be positive and finite")]
    Mass {
        /// The bead.
        bead: usize,
        /// Its mass.
        mass: f64,
    },
    /// A constraint or spring names a bead the island does not have.
    #[error("{item} names bead {bead}, but there are only {beads} beads")]
    MissingBead {
        /// The constraint or spring, in words.
        item: String,
        /// The index it named.
        bead: usize,
        /// How many beads there are.
        beads: usize,
    },
    /// A constraint or spring joins a bead to itself.
    #[error("{item} joins bead {bead} to itself")]
    SameBead {
        /// The constraint or spring, in words.
        item: String,
        /// The bead.
        bead: usize,
    },
    /// A constraint names the wrong number of beads for its kind.
    #[error("{item} names {got} beads, but it joins {expected}")]
    Arity {
        /// The constraint, in words.
        item: String,
        /// How many its kind joins.
        expected: usize,
        /// How many it named.
        got: usize,
    },
    /// A length, stiffness or damping out of range.
    #[error("{item}: {what} must be {range}, got {value}")]
    Value {
        /// The constraint or spring, in words.
        item: String,
        /// Which value.
        what: &'static str,
        /// What it must be.
        range: &'static str,
        /// What it was.
        value: f64,
    },
    /// A slice meant to hold one entry per bead of the island holds
    /// another number.
    #[error("{what}: {given} given, but the island has {beads} beads")]
    Length {
        /// The slice, in words.
        what: &'static str,
        /// How many entries it holds.
        given: usize,
        /// How many beads the island has.
        beads: usize,
    },
    /// A row named for friction is not a wire's row of the island, or the
    /// row named to hold its bead still is not an axis row of that bead.
    #[error("{what} {row} is not {expected} (the island has {rows} rows)")]
    Row {
        /// The argument, in words.
        what: &'static str,
        /// The row it named.
        row: usize,
        /// What that row had to be.
        expected: &'static str,
        /// How many rows the island has.
        rows: usize,
    },
    /// faer could not allocate the symbolic factorization.
    #[error("the island's matrix could not be set up (out of memory)")]
    OutOfMemory,
}
