//! What the solver needs from a background mesh: its node count (dense
//! node-indexed maps are built once per load step) and its own linear
//! finite element shape functions, which convect domain corners and
//! mid-points (Coombs et al. 2020 eq. 35: "the corners of the domain are
//! updated according to the basis functions associated with the background
//! grid").

use mpm_basis::{BasisError, BasisFunction, LinearMpm, LinearSimplex, Stencil};
use mpm_mesh::{RegularGrid, SimplexMesh};
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

impl<const D: usize> NodalMesh<D> for SimplexMesh<D> {
    #[inline]
    fn node_count(&self) -> usize {
        SimplexMesh::node_count(self)
    }

    #[inline]
    fn shape_functions(&self, x: &SVector<f64, D>, out: &mut Stencil<D>) -> Result<(), BasisError> {
        LinearSimplex.evaluate(self, x, &(), out)
    }
}

/// A background mesh whose nodes can be moved, for moving-mesh boundary
/// conditions (Beuth 2012, as used by Wang et al. 2021 §2.2 and §5).
pub trait MovableMesh<const D: usize>: NodalMesh<D> {
    /// Position of node `node` (which must exist).
    fn node_position(&self, node: usize) -> SVector<f64, D>;

    /// Moves every node to the position in `positions` (one per node).
    ///
    /// # Errors
    /// A message when the moved mesh is not admissible: an inverted
    /// simplex, or a regular grid that would stop being regular.
    fn move_nodes(&mut self, positions: Vec<SVector<f64, D>>) -> Result<(), String>;
}

impl<const D: usize> MovableMesh<D> for SimplexMesh<D> {
    #[inline]
    fn node_position(&self, node: usize) -> SVector<f64, D> {
        self.nodes()[node]
    }

    fn move_nodes(&mut self, positions: Vec<SVector<f64, D>>) -> Result<(), String> {
        SimplexMesh::move_nodes(self, positions).map_err(|e| e.to_string())
    }
}

impl<const D: usize> MovableMesh<D> for RegularGrid<D> {
    #[inline]
    fn node_position(&self, node: usize) -> SVector<f64, D> {
        RegularGrid::node_position(self, node).unwrap_or_else(|_| SVector::from_element(f64::NAN))
    }

    /// Accepts only motions that keep the grid regular: an axis-aligned
    /// affine map (translation and per-axis stretch), checked at every
    /// node to a relative 1e-12.
    fn move_nodes(&mut self, positions: Vec<SVector<f64, D>>) -> Result<(), String> {
        if positions.len() != self.node_count() {
            return Err(format!(
                "{} positions for a grid of {} nodes",
                positions.len(),
                self.node_count()
            ));
        }
        let last = self.node_count() - 1;
        let (lo, hi) = (positions[0], positions[last]);
        let cells = self.cells_per_axis();
        let spacing = SVector::<f64, D>::from_fn(|i, _| (hi[i] - lo[i]) / cells[i] as f64);
        let moved = RegularGrid::new(lo, spacing, cells).map_err(|e| e.to_string())?;
        let scale = (hi - lo).norm();
        for (n, x) in positions.iter().enumerate() {
            let expected = RegularGrid::node_position(&moved, n).map_err(|e| e.to_string())?;
            if (expected - x).norm() > 1e-12 * scale {
                return Err(format!(
                    "moving node {n} to {:?} would make the grid irregular; regular grids only stretch and translate along their axes",
                    x.as_slice()
                ));
            }
        }
        *self = moved;
        Ok(())
    }
}
