//! Background meshes for the material point method.
//!
//! This crate will hold dimension-generic regular grids (`RegularGrid<D>`),
//! unstructured triangle/tetrahedral meshes with a neighbour table and
//! walking-in-triangulation point location (Wang et al. 2021 §4.2), Gmsh
//! input, the parent/child patches used by F-patch (Wang et al. 2021 §4.1)
//! and moving-mesh boundary conditions.
