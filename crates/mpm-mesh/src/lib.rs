//! Background meshes for the material point method.
//!
//! - [`RegularGrid`]: a dimension-generic (`const D: usize`) Cartesian grid
//!   with lexicographic node and cell numbering (axis 0 fastest), point
//!   location ([`RegularGrid::cell_containing`], [`RegularGrid::locate`]),
//!   node sets per boundary [`Face`] for Dirichlet conditions, and the
//!   active cells/nodes touched by material points or by the
//!   [`BoundingBox`]es of their domains.
//! - [`SimplexMesh`]: linear triangles and tetrahedra (Wang et al. 2021
//!   §4.2) with the inverse element maps of eq. (13), the neighbour table
//!   of Algorithm 2 and point location by walking (Algorithm 1,
//!   [`SimplexMesh::locate`]) with a bucket-grid fallback.
//! - [`QuadraticMesh`]: six-node triangles and ten-node tetrahedra, the
//!   parents whose elements are the patches of the F-patch method;
//!   [`PatchMesh`] splits them into linear children (§4.1, Fig. 3) and
//!   lists the active elements of every patch ([`ActivePatches`]).
//! - Generators: [`BoxMesh`] (structured, graded, [`DiagonalPattern`]) and
//!   [`AnnulusMesh`]; a Gmsh MSH 4.1 ASCII reader ([`read_msh`],
//!   [`parse_msh`]); physical groups and boundaries as [`NamedSets`].
//! - [`MeshError`]: the crate's one error type; every variant names the
//!   point, index, element, axis or file line where it happened.
//!
//! The meshes are data, not plug points: the bases of `mpm-basis` name the
//! mesh they live on as an associated type, and `mpm-solver`'s
//! `NodalMesh`/`MovableMesh` traits are implemented for both mesh types.
//!
//! ```
//! use mpm_mesh::{BoxMesh, RegularGrid};
//! use nalgebra::{Vector2, Vector3};
//! // A regular grid: the cell of a point, and an error for one outside.
//! let grid = RegularGrid::new(Vector2::zeros(), Vector2::new(0.5, 0.5), [4, 2])?;
//! assert_eq!(grid.cell_containing(&Vector2::new(1.2, 0.7))?, [2, 1]);
//! assert!(grid.cell_containing(&Vector2::new(3.0, 0.2)).is_err());
//! // A tetrahedral box mesh located by walking from a hint (Wang et al.
//! // 2021 Algorithm 1) finds the same element as brute force.
//! let tets = BoxMesh::new(Vector3::zeros(), Vector3::repeat(1.0), [4, 4, 4]).simplex_mesh()?;
//! let x = Vector3::new(0.313, 0.771, 0.529);
//! let walked = tets.locate(&x, Some(0))?;
//! assert_eq!(walked.element, tets.locate_brute_force(&x)?.element);
//! # Ok::<(), mpm_mesh::MeshError>(())
//! ```

#![cfg_attr(test, allow(clippy::unwrap_used))]

mod active;
mod error;
mod generate;
mod gmsh;
mod patches;
mod quadratic;
mod random;
mod regular_grid;
mod sets;
mod simplex;

pub use active::BoundingBox;
pub use error::MeshError;
pub use generate::{AnnulusMesh, BoxMesh, DiagonalPattern, permutations};
pub use gmsh::{GmshElements, GmshMesh, parse_msh, read_msh};
pub use patches::{ActivePatches, PatchMesh};
pub use quadratic::QuadraticMesh;
pub use random::SplitMix64;
pub use regular_grid::{CellLocation, CellNodes, Face, RegularGrid, Side};
pub use sets::{MeshSets, NamedSets};
pub use simplex::{
    BARYCENTRIC_TOLERANCE, BoundaryFace, COINCIDENT_TOLERANCE, Location, MeshQuality, NO_NEIGHBOUR,
    SLIVER_SHAPE, SimplexMesh, Walk, quadratic_node_count, shape_measure,
};
