//! Background meshes for the material point method.
//!
//! - [`RegularGrid`]: a dimension-generic (`const D: usize`) Cartesian grid
//!   with lexicographic node and cell numbering (axis 0 fastest), point
//!   location ([`RegularGrid::cell_containing`], [`RegularGrid::locate`]),
//!   node sets per boundary [`Face`] for Dirichlet conditions, and the
//!   active cells/nodes touched by material points or by the
//!   [`BoundingBox`]es of their domains.
//! - [`MeshError`]: the crate's one error type; every variant names the
//!   point, index or axis where it happened.
//!
//! Unstructured triangle/tetrahedral meshes (Wang et al. 2021 §4.2) will
//! join this crate in a later issue.

#![cfg_attr(test, allow(clippy::unwrap_used))]

mod active;
mod error;
mod regular_grid;

pub use active::BoundingBox;
pub use error::MeshError;
pub use regular_grid::{CellLocation, CellNodes, Face, RegularGrid, Side};
