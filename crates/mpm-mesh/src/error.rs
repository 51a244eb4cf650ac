//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong when building or querying a background mesh.
///
/// Every variant names the offending input (the axis, the point, the index or
/// the material point) so that a caller can report where it happened.
/// Coordinates and indices are stored as `Vec`s because the error type is
/// shared by all dimensions; they are only allocated on the error path.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshError {
    /// A grid origin coordinate is NaN or infinite.
    #[error("grid origin coordinate {axis} is {value}; it must be finite")]
    InvalidOrigin {
        /// The axis of the offending coordinate.
        axis: usize,
        /// The value given.
        value: f64,
    },
    /// A grid spacing is not positive and finite.
    #[error("grid spacing along axis {axis} is {value}; it must be positive and finite")]
    InvalidSpacing {
        /// The axis of the offending spacing.
        axis: usize,
        /// The value given.
        value: f64,
    },
    /// Grid bounds along an axis are not finite or not increasing.
    #[error("grid bounds along axis {axis} are [{lower}, {upper}]; need finite lower < upper")]
    InvalidBounds {
        /// The axis of the offending bounds.
        axis: usize,
        /// The lower bound given.
        lower: f64,
        /// The upper bound given.
        upper: f64,
    },
    /// An axis has no cells.
    #[error("a grid needs at least one cell along every axis; axis {axis} has none")]
    NoCells {
        /// The axis without cells.
        axis: usize,
    },
    /// The node count does not fit in `usize`, or the upper corner of the
    /// grid is not finite.
    #[error("a grid with {cells:?} cells per axis is too large to index")]
    TooLarge {
        /// The cells per axis requested.
        cells: Vec<usize>,
    },
    /// A point lies outside the closed box of the grid (or is not finite).
    #[error("point {point:?} lies outside the grid [{lower:?}, {upper:?}]")]
    PointOutsideGrid {
        /// The point's coordinates.
        point: Vec<f64>,
        /// The grid's lower corner.
        lower: Vec<f64>,
        /// The grid's upper corner.
        upper: Vec<f64>,
    },
    /// A material point of a set lies outside the grid (or is not finite).
    #[error("material point {particle} at {point:?} lies outside the grid")]
    ParticleOutsideGrid {
        /// Index of the material point in the slice given.
        particle: usize,
        /// Its coordinates.
        point: Vec<f64>,
    },
    /// A bounding box is not finite or has `lower > upper` along some axis.
    #[error(
        "bounding box {particle} [{lower:?}, {upper:?}] is invalid; need finite lower <= upper"
    )]
    InvalidBox {
        /// Index of the box (material point) in the slice given.
        particle: usize,
        /// Its lower corner.
        lower: Vec<f64>,
        /// Its upper corner.
        upper: Vec<f64>,
    },
    /// A bounding box does not intersect the grid at all.
    #[error("bounding box {particle} [{lower:?}, {upper:?}] does not intersect the grid")]
    BoxOutsideGrid {
        /// Index of the box (material point) in the slice given.
        particle: usize,
        /// Its lower corner.
        lower: Vec<f64>,
        /// Its upper corner.
        upper: Vec<f64>,
    },
    /// A node multi-index is out of range along some axis.
    #[error("node multi-index {index:?} is outside the {nodes_per_axis:?} nodes per axis")]
    NodeIndexOutOfRange {
        /// The multi-index given.
        index: Vec<usize>,
        /// The grid's nodes per axis.
        nodes_per_axis: Vec<usize>,
    },
    /// A node id is not below the node count.
    #[error("node id {id} is not below the node count {count}")]
    NodeIdOutOfRange {
        /// The id given.
        id: usize,
        /// The grid's node count.
        count: usize,
    },
    /// A cell multi-index is out of range along some axis.
    #[error("cell multi-index {index:?} is outside the {cells_per_axis:?} cells per axis")]
    CellIndexOutOfRange {
        /// The multi-index given.
        index: Vec<usize>,
        /// The grid's cells per axis.
        cells_per_axis: Vec<usize>,
    },
    /// A cell id is not below the cell count.
    #[error("cell id {id} is not below the cell count {count}")]
    CellIdOutOfRange {
        /// The id given.
        id: usize,
        /// The grid's cell count.
        count: usize,
    },
    /// An axis number is not below the dimension.
    #[error("axis {axis} does not exist in a {dimension}-dimensional grid")]
    InvalidAxis {
        /// The axis given.
        axis: usize,
        /// The grid's dimension.
        dimension: usize,
    },
}
