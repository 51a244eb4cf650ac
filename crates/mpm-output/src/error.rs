//! The crate's error type.

use std::path::PathBuf;

use thiserror::Error;

/// Everything that can go wrong while writing a result file.
///
/// Every variant names where the problem is: the file, or the data array
/// and index.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum OutputError {
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file (or, for a temporary file, the file it was to replace).
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A path that cannot be written to or referred to.
    #[error("{}: {reason}", path.display())]
    InvalidPath {
        /// The offending path.
        path: PathBuf,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// An output array holds NaN or infinity.
    #[error("array `{array}` has the non-finite value {value} at index {index}")]
    NonFinite {
        /// The array (or CSV column) name.
        array: String,
        /// Index of the offending entry: the point, cell or row, not the
        /// flattened component.
        index: usize,
        /// The value found.
        value: f64,
    },
    /// A value to be serialised (e.g. into `summary.json`) is NaN or infinity.
    #[error("field `{field}` has the non-finite value {value}")]
    NonFiniteField {
        /// Path of the field, e.g. `cases[2].error_l2`.
        field: String,
        /// The value found.
        value: f64,
    },
    /// An array's length does not match the number of points, cells,
    /// columns or components it belongs to.
    #[error("array `{array}` has {found} entries, expected {expected}")]
    LengthMismatch {
        /// The array (or CSV row) name.
        array: String,
        /// The required length.
        expected: usize,
        /// The length given.
        found: usize,
    },
    /// A data array declared with zero components per tuple.
    #[error("array `{array}` has zero components per tuple")]
    ZeroComponents {
        /// The array name.
        array: String,
    },
    /// Points of a dimension VTK cannot hold.
    #[error("points of dimension {dim} cannot be written: VTK takes 1 to 3 coordinates")]
    InvalidDimension {
        /// The dimension given.
        dim: usize,
    },
    /// A cell refers to a point that does not exist.
    #[error("cell {cell} refers to point {node}, but there are only {n_points} points")]
    NodeOutOfRange {
        /// Index of the cell.
        cell: usize,
        /// The offending point index.
        node: usize,
        /// The number of points.
        n_points: usize,
    },
    /// A cell's connectivity does not have the node count its type requires.
    #[error("{cell_type} cells have {expected} nodes each, but {found} node indices were given")]
    CellNodeCount {
        /// The VTK cell type's name.
        cell_type: &'static str,
        /// Nodes per cell of this type.
        expected: usize,
        /// Length of the connectivity given.
        found: usize,
    },
    /// An empty, duplicate or otherwise unusable name for an array or column.
    #[error("{what} name `{name}`: {reason}")]
    InvalidName {
        /// What the name is for, e.g. `"point data array"`.
        what: &'static str,
        /// The name given.
        name: String,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// A time series must advance: each step's time finite and larger than
    /// the previous one.
    #[error("time {time} of a series must be finite and after the previous time {previous}")]
    InvalidTime {
        /// The time of the previous step (`-inf` if none).
        previous: f64,
        /// The time given.
        time: f64,
    },
    /// `serde_json` could not serialise a value.
    #[error("{}: cannot serialise to JSON: {source}", path.display())]
    Json {
        /// The file that was to be written.
        path: PathBuf,
        /// The serialiser's error.
        source: serde_json::Error,
    },
}
