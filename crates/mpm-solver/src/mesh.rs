//! What the solver needs from a background mesh: its node count (dense
//! node-indexed maps are built once per load step) and its own linear
//! finite element shape functions, which convect domain corners and
//! mid-points (Coombs et al. 2020 eq. 35: "the corners of the domain are
//! updated according to the basis functions associated with the background
//! grid").

use mpm_basis::{BasisError, BasisFunction, LinearSimplex, Stencil};
use mpm_mesh::{MeshError, RegularGrid, SimplexMesh};

use crate::error::MeshMotionError;
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

    /// The mesh as a regular grid, for the stages defined on one (the
    /// ghost penalty, [`crate::stages::ghost`]); `None` (the default) for
    /// other meshes.
    fn regular_grid(&self) -> Option<&RegularGrid<D>> {
        None
    }
}

impl<const D: usize> NodalMesh<D> for RegularGrid<D> {
    #[inline]
    fn node_count(&self) -> usize {
        RegularGrid::node_count(self)
    }

    fn regular_grid(&self) -> Option<&RegularGrid<D>> {
        Some(self)
    }

    /// The multilinear functions of the cell containing `x`. A point up to
    /// half a cell outside the grid (a GIMP domain corner beyond a boundary
    /// the body fills: the domain update of eq. 37 rescales domains about
    /// their point without regard to the boundary) gets the functions of
    /// the boundary cell, extended linearly; farther out is an error.
    fn shape_functions(&self, x: &SVector<f64, D>, out: &mut Stencil<D>) -> Result<(), BasisError> {
        out.clear();
        let (o, h, cells) = (self.origin(), self.spacing(), self.cells_per_axis());
        let mut cell = [0usize; D];
        let mut t = [0.0f64; D];
        for i in 0..D {
            let s = (x[i] - o[i]) / h[i];
            if !(s >= -0.5 && s <= cells[i] as f64 + 0.5) {
                return Err(BasisError::Mesh(MeshError::PointOutsideGrid {
                    point: x.iter().copied().collect(),
                    lower: o.iter().copied().collect(),
                    upper: self.upper().iter().copied().collect(),
                }));
            }
            cell[i] = (s.floor().max(0.0) as usize).min(cells[i] - 1);
            t[i] = s - cell[i] as f64;
        }
        for corner in 0..(1usize << D) {
            let mut index = cell;
            let mut value = 1.0;
            let mut gradient = SVector::<f64, D>::from_element(1.0);
            for i in 0..D {
                let upper = corner >> i & 1 == 1;
                index[i] += usize::from(upper);
                let (f, df) = if upper {
                    (t[i], 1.0 / h[i])
                } else {
                    (1.0 - t[i], -1.0 / h[i])
                };
                value *= f;
                for j in 0..D {
                    gradient[j] *= if j == i { df } else { f };
                }
            }
            let node = self.node_id(index).map_err(BasisError::Mesh)?;
            out.push(node, value, gradient);
        }
        Ok(())
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
    fn move_nodes(&mut self, positions: Vec<SVector<f64, D>>) -> Result<(), MeshMotionError>;
}

impl<const D: usize> MovableMesh<D> for SimplexMesh<D> {
    #[inline]
    fn node_position(&self, node: usize) -> SVector<f64, D> {
        self.nodes()[node]
    }

    fn move_nodes(&mut self, positions: Vec<SVector<f64, D>>) -> Result<(), MeshMotionError> {
        Ok(SimplexMesh::move_nodes(self, positions)?)
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
    fn move_nodes(&mut self, positions: Vec<SVector<f64, D>>) -> Result<(), MeshMotionError> {
        if positions.len() != self.node_count() {
            return Err(MeshMotionError::NodeCount {
                got: positions.len(),
                expected: self.node_count(),
            });
        }
        let last = self.node_count() - 1;
        let (lo, hi) = (positions[0], positions[last]);
        let cells = self.cells_per_axis();
        let spacing = SVector::<f64, D>::from_fn(|i, _| (hi[i] - lo[i]) / cells[i] as f64);
        let moved = RegularGrid::new(lo, spacing, cells)?;
        let scale = (hi - lo).norm();
        for (n, x) in positions.iter().enumerate() {
            let expected = RegularGrid::node_position(&moved, n)?;
            if (expected - x).norm() > 1e-12 * scale {
                return Err(MeshMotionError::Irregular {
                    node: n,
                    position: x.as_slice().to_vec(),
                });
            }
        }
        *self = moved;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mpm_basis::LinearMpm;
    use nalgebra::Vector2;

    #[test]
    fn grid_shape_functions_match_the_basis_inside_and_extend_linearly_outside() {
        let grid = RegularGrid::new(Vector2::new(-1.0, 0.0), Vector2::new(0.5, 0.25), [4, 8])
            .expect("grid");
        let (mut a, mut b) = (Stencil::with_capacity(4), Stencil::with_capacity(4));
        for x in [
            Vector2::new(-0.3, 0.61),
            Vector2::new(0.999, 1.999),
            Vector2::new(-1.0, 0.0),
        ] {
            NodalMesh::shape_functions(&grid, &x, &mut a).expect("inside");
            LinearMpm.evaluate(&grid, &x, &(), &mut b).expect("inside");
            // The basis omits nodes whose value and gradient are both zero.
            for (v, s, g) in a.iter() {
                match b.position(v) {
                    Some(k) => assert!(b.values[k] == s && b.gradients[k] == *g),
                    None => assert!(s == 0.0 && g.norm() == 0.0),
                }
            }
            assert!(b.nodes.iter().all(|v| a.position(*v).is_some()));
        }
        // Outside: an affine field is reproduced exactly, values sum to one.
        let field = |y: &SVector<f64, 2>| 2.0 * y[0] - 3.0 * y[1] + 0.5;
        for x in [
            Vector2::new(-1.2, 0.3),
            Vector2::new(0.1, 2.1),
            Vector2::new(1.24, -0.12),
        ] {
            NodalMesh::shape_functions(&grid, &x, &mut a).expect("near the boundary");
            let sum: f64 = a.values.iter().sum();
            let interpolated: f64 = a
                .iter()
                .map(|(v, s, _)| s * field(&RegularGrid::node_position(&grid, v).expect("node")))
                .sum();
            assert!((sum - 1.0).abs() < 1e-14 && (interpolated - field(&x)).abs() < 1e-13);
        }
        assert!(NodalMesh::shape_functions(&grid, &Vector2::new(-1.26, 0.3), &mut a).is_err());
        assert!(NodalMesh::shape_functions(&grid, &Vector2::new(0.0, f64::NAN), &mut a).is_err());
    }
}
