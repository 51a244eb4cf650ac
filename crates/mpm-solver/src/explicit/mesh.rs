//! What the explicit solver needs from its background mesh.

use mpm_mesh::RegularGrid;
use nalgebra::SVector;

use super::touch::Lattice;

/// A background mesh for explicit MPM: node positions (the Taylor term of
/// eq. 29), cells (the cell-averaged dilatation of eq. 53) and the length
/// $h$ of the CFL condition (eq. 45).
pub trait ExplicitMesh<const D: usize>: Send + Sync {
    /// Number of nodes.
    fn node_count(&self) -> usize;
    /// Position of node `node` (< `node_count()`).
    fn node_position(&self, node: usize) -> SVector<f64, D>;
    /// Number of cells.
    fn cell_count(&self) -> usize;
    /// The cell containing `x`, `None` outside the mesh.
    fn cell_of(&self, x: &SVector<f64, D>) -> Option<usize>;
    /// The smallest cell size, $h$ of eq. (45).
    fn min_spacing(&self) -> f64;
    /// The regular lattice of the nodes (the gap check of the friction
    /// walls finds the nodes under a point from it).
    fn lattice(&self) -> Lattice<D>;
    /// The volume of a cell (area in 2D; the contact's full node,
    /// [`super::contact`]): $h^D$ unless the mesh says otherwise.
    fn cell_volume(&self) -> f64 {
        self.min_spacing().powi(D as i32)
    }
}

impl<const D: usize> ExplicitMesh<D> for RegularGrid<D> {
    fn node_count(&self) -> usize {
        RegularGrid::node_count(self)
    }

    fn node_position(&self, node: usize) -> SVector<f64, D> {
        let n = self.nodes_per_axis();
        let mut rest = node;
        let mut x = *self.origin();
        for (axis, count) in n.iter().enumerate() {
            x[axis] += (rest % count) as f64 * self.spacing()[axis];
            rest /= count;
        }
        x
    }

    fn cell_count(&self) -> usize {
        RegularGrid::cell_count(self)
    }

    #[inline]
    fn cell_of(&self, x: &SVector<f64, D>) -> Option<usize> {
        let cell = self.cell_containing(x).ok()?;
        self.cell_id(cell).ok()
    }

    fn min_spacing(&self) -> f64 {
        self.spacing().min()
    }

    fn lattice(&self) -> Lattice<D> {
        Lattice {
            origin: *self.origin(),
            spacing: *self.spacing(),
            nodes: self.nodes_per_axis(),
        }
    }

    fn cell_volume(&self) -> f64 {
        self.spacing().product()
    }
}
