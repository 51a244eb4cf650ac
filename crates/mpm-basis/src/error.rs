//! The crate's error type.

use mpm_mesh::MeshError;
use thiserror::Error;

/// Everything that can go wrong when evaluating a basis function.
///
/// Every variant names the point (or domain corner) where it happened; the
/// solver adds the material point index. Coordinates are stored as `Vec`s
/// because the type is shared by all dimensions; they are only allocated on
/// the error path.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BasisError {
    /// The background mesh rejected a query, typically
    /// [`MeshError::PointOutsideGrid`] for a material point outside the grid.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The quadratic B-spline stencil of a point needs a node beyond the
    /// grid: the point lies less than half a cell from the grid boundary.
    #[error(
        "the quadratic B-spline stencil of the point {point:?} leaves the grid along axis \
         {axis}: points must stay at least half a cell inside the grid (pad it with a cell)"
    )]
    StencilOutsideGrid {
        /// The point's coordinates.
        point: Vec<f64>,
        /// The axis along which the stencil leaves the grid.
        axis: usize,
    },
    /// A GIMP half-length is negative, non-finite or larger than half the
    /// cell size.
    #[error(
        "GIMP half-length {half_length} along axis {axis} of the point {point:?} must be \
         finite and within [0, h/2 = {max}]"
    )]
    InvalidHalfLength {
        /// The point's coordinates.
        point: Vec<f64>,
        /// The axis of the offending half-length.
        axis: usize,
        /// The half-length given.
        half_length: f64,
        /// The largest admissible half-length, half the cell size.
        max: f64,
    },
    /// A CPDI2 domain corner has a non-finite coordinate.
    #[error("CPDI2 domain corner {corner} at {point:?} is not finite")]
    NonFiniteCorner {
        /// Index of the corner (lexicographic, see `Corners`).
        corner: usize,
        /// Its coordinates.
        point: Vec<f64>,
    },
    /// A CPDI2 domain corner lies outside the grid.
    #[error("CPDI2 domain corner {corner} at {point:?} lies outside the grid")]
    CornerOutsideGrid {
        /// Index of the corner (lexicographic, see `Corners`).
        corner: usize,
        /// Its coordinates.
        point: Vec<f64>,
    },
    /// A CPDI2 domain is inverted or degenerate: the Jacobian determinant
    /// of its corner map is not positive at a Gauss point.
    #[error(
        "CPDI2 domain {corners:?} is inverted or degenerate: det J = {determinant:e} at \
         Gauss point {gauss_point}"
    )]
    DegenerateDomain {
        /// The domain's corners.
        corners: Vec<Vec<f64>>,
        /// The Gauss point (lexicographic, like the corners).
        gauss_point: usize,
        /// The Jacobian determinant found there.
        determinant: f64,
    },
    /// A CPDI2 domain was built from the wrong number of corners.
    #[error("a CPDI2 domain in {dimension}D needs {expected} corners, got {found}")]
    WrongCornerCount {
        /// The dimension.
        dimension: usize,
        /// The number of corners needed, $2^D$.
        expected: usize,
        /// The number given.
        found: usize,
    },
}
