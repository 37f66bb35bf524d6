//! What is wrong with a scene file, in one line that names the place.

use crate::validate::ParamError;

/// What is wrong with a scene file.
#[derive(Debug, thiserror::Error)]
pub enum PresetError {
    /// The file is not valid RON for a preset.
    #[error(
        "malformed scene file at line {}, column {}: {}",
        .0.span.start.line,
        .0.span.start.col,
        .0.code
    )]
    Parse(#[from] ron::error::SpannedError),
    /// A value of the wrong form in one item: a vector with two components
    /// in a scene in space, a word where a number goes.
    #[error(
        "malformed scene file at line {}, column {} in {item}: {}",
        .error.span.start.line,
        .error.span.start.col,
        .error.code
    )]
    Malformed {
        /// Where it is: `wires[0].beads[1].initial_position`.
        item: String,
        /// What is wrong, and where in the file.
        error: Box<ron::error::SpannedError>,
    },
    /// A field the format does not have (a misspelt name, or one from a
    /// later version): refused rather than ignored.
    #[error(
        "unknown field `{field}` in {item} at line {line}, column {column}; the file was refused (known fields: {known})"
    )]
    UnknownField {
        /// The field as written.
        field: String,
        /// Where it is: `the scene`, `wires[2]`, `wires[0].beads[1]`.
        item: String,
        /// The line it is on.
        line: usize,
        /// Its column.
        column: usize,
        /// The fields that item has.
        known: String,
    },
    /// A pile ([`ScenePreset::pile`](super::ScenePreset::pile)) of more
    /// beads than its bowl holds in rows of that many: a bead would start
    /// outside the bowl, where its one-sided wire would pull it in.
    #[error(
        "a pile of {beads} beads in rows of {per_row} does not fit in its bowl: row {row} would start outside it; at most {most} fit in rows of {per_row}"
    )]
    PileTooLarge {
        /// The beads asked for.
        beads: usize,
        /// Beads to a row.
        per_row: usize,
        /// The first row (from 0 at the bottom) with a bead outside.
        row: usize,
        /// The most beads the bowl holds in rows of `per_row`.
        most: usize,
    },
    /// A pour ([`Pour`](super::Pour)) of more beads than its bowl
    /// holds on the grid they start on.
    #[error(
        "a pour of {beads} beads does not fit in a bowl of radius {bowl} m: at most {most} beads start inside it"
    )]
    PourTooLarge {
        /// The beads asked for.
        beads: usize,
        /// The bowl's radius, m.
        bowl: f64,
        /// The most beads that start inside it.
        most: usize,
    },
    /// An hourglass ([`Hourglass`](super::Hourglass)) of more grains
    /// than it is made for.
    #[error("an hourglass of {beads} grains is more than the {most} it is made for")]
    HourglassTooLarge {
        /// The grains asked for.
        beads: usize,
        /// The most it is made for.
        most: usize,
    },
    /// A marble run ([`MarbleRun`](super::MarbleRun)) of more marbles
    /// than it is made for.
    #[error("a marble run of {marbles} marbles is more than the {most} its bowl is made for")]
    MarbleRunTooLarge {
        /// The marbles asked for.
        marbles: usize,
        /// The most it is made for.
        most: usize,
    },
    /// The file could not be read.
    #[error("cannot read scene file: {0}")]
    Io(#[from] std::io::Error),
    /// The parameters are invalid.
    #[error("invalid params: {0}")]
    Params(ParamError),
    /// A wire is invalid.
    #[error("wire {index}: {source}")]
    Wire {
        /// Its index in `wires`.
        index: usize,
        /// What is wrong.
        source: ParamError,
    },
    /// A bead is invalid.
    #[error("wire {wire}, bead {bead}: {source}")]
    Bead {
        /// The wire's index.
        wire: usize,
        /// The bead's index on it.
        bead: usize,
        /// What is wrong.
        source: ParamError,
    },
    /// A free bead is invalid.
    #[error("bead {name:?}: {source}")]
    FreeBead {
        /// Its name.
        name: String,
        /// What is wrong.
        source: ParamError,
    },
    /// Two beads have one name.
    #[error("two beads are named {0:?}")]
    DuplicateName(String),
    /// Two bodies have one name.
    #[error("two bodies are named {0:?}")]
    DuplicateBody(String),
    /// Two wires have one name.
    #[error("two wires are named {0:?}")]
    DuplicateWire(String),
    /// A body is invalid.
    #[error("body {index} ({name:?}): {source}")]
    Body {
        /// Its index in `bodies`.
        index: usize,
        /// Its name.
        name: String,
        /// What is wrong.
        source: ParamError,
    },
    /// The contacts' parameters are invalid.
    #[error("contacts: {0}")]
    Contacts(ParamError),
    /// Two beads with radii overlap where they start.
    #[error(
        "beads {a:?} and {b:?} overlap by {by:.3e} m where they start; beads with radii may touch but not overlap"
    )]
    Overlap {
        /// The first bead's name.
        a: String,
        /// The second's.
        b: String,
        /// By how much (m).
        by: f64,
    },
    /// A constraint or spring is invalid.
    #[error("{item}: {problem}")]
    Link {
        /// Which, in words: `constraint 0 (rod)`, `spring 1`.
        item: String,
        /// What is wrong.
        problem: String,
    },
    /// The scene has no bead and no body.
    #[error("the scene has no bead and no body")]
    Empty,
    /// A scene in space where one in the plane was asked for.
    #[error("the scene is in space (dimension: 3); this takes scenes in the plane")]
    InSpace,
    /// A dimension other than 2 or 3.
    #[error("dimension must be 2 or 3, got {0}")]
    Dimension(u8),
}

impl PresetError {
    /// A parse error at `path` (as `serde_path_to_error` writes it, the
    /// field last): an unknown field names itself and its item.
    pub(super) fn at(path: String, error: ron::error::SpannedError) -> Self {
        match &error.code {
            ron::Error::NoSuchStructField {
                expected, found, ..
            } => {
                let item = match path.rsplit_once('.') {
                    Some((item, _)) => item.to_owned(),
                    None => "the scene".to_owned(),
                };
                PresetError::UnknownField {
                    field: found.clone(),
                    item,
                    line: error.span.start.line,
                    column: error.span.start.col,
                    known: expected.join(", "),
                }
            }
            _ if !path.is_empty() && path != "." && path != "?" => PresetError::Malformed {
                item: path,
                error: Box::new(error),
            },
            _ => PresetError::Parse(error),
        }
    }
}
