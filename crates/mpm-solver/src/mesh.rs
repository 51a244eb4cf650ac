//! What the solver needs from a background mesh: its node count (dense
//! node-indexed maps are built once per load step) and its own linear
//! finite element shape functions, which convect domain corners and
//! mid-points (Coombs et al. 2020 eq. 35: "the corners of the domain are
//! updated according to the basis functions associated with the background
//! grid").

use mpm_basis::{BasisError, BasisFunction, LinearMpm, Stencil};
use mpm_mesh::RegularGrid;
use nalgebra::SVector;

/// A background mesh with numbered nodes and linear shape functions.
pub trait NodalMesh<const D: usize>: Send + Sync {
    /// Number of nodes; node ids are `0..node_count()`.
    fn node_count(&self) -> usize;

    /// Writes the mesh's linear shape functions $N_v(\mathbf x)$ (values
    /// and gradients) at `x` into `out`: bi/trilinear on a regular grid,
    /// barycentric on a simplex mesh.
    ///
    /// # Errors
    /// A [`BasisError`] when `x` lies outside the mesh.
    fn shape_functions(&self, x: &SVector<f64, D>, out: &mut Stencil<D>) -> Result<(), BasisError>;
}

impl<const D: usize> NodalMesh<D> for RegularGrid<D> {
    #[inline]
    fn node_count(&self) -> usize {
        RegularGrid::node_count(self)
    }

    #[inline]
    fn shape_functions(&self, x: &SVector<f64, D>, out: &mut Stencil<D>) -> Result<(), BasisError> {
        LinearMpm.evaluate(self, x, &(), out)
    }
}
