//! What the solver needs from a background mesh: its node count (dense
//! node-indexed maps are built once per load step).

use mpm_mesh::RegularGrid;

/// A background mesh with numbered nodes.
pub trait NodalMesh: Send + Sync {
    /// Number of nodes; node ids are `0..node_count()`.
    fn node_count(&self) -> usize;
}

impl<const D: usize> NodalMesh for RegularGrid<D> {
    #[inline]
    fn node_count(&self) -> usize {
        RegularGrid::node_count(self)
    }
}
