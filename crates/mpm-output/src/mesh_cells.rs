//! The background mesh as VTK cells: the cells that hold material points,
//! written beside the points so that ParaView shows the active mesh of
//! every step (moving meshes included).

use mpm_mesh::{RegularGrid, SimplexMesh};
use mpm_solver::{MeshMotionError, MovableMesh};
use nalgebra::SVector;

use super::vtk::CellType;

/// A background mesh that can be written as VTK cells.
pub trait CellMesh<const D: usize>: Clone + Send + Sync {
    /// The VTK type of its cells.
    const CELL: CellType;

    /// Node positions, padded to 3D.
    fn vtk_nodes(&self) -> Vec<[f64; 3]>;

    /// VTK connectivity of the cells holding at least one of `points`
    /// (each cell once, ascending cell id); points outside the mesh are
    /// skipped.
    fn cells_holding(&self, points: &[[f64; 3]]) -> Vec<usize>;

    /// Moves the nodes to `nodes` (for a moving mesh).
    ///
    /// # Errors
    /// A message when the mesh cannot take that shape.
    fn set_nodes(&mut self, nodes: &[[f64; 3]]) -> Result<(), MeshMotionError>;
}

fn unpad<const D: usize>(x: &[f64; 3]) -> SVector<f64, D> {
    SVector::<f64, D>::from_fn(|i, _| x[i])
}

fn pad<const D: usize>(x: &SVector<f64, D>) -> [f64; 3] {
    let mut out = [0.0; 3];
    out[..D].copy_from_slice(x.as_slice());
    out
}

/// Sorted unique cell ids → their connectivity.
fn connectivity(mut cells: Vec<usize>, nodes_of: impl Fn(usize) -> Vec<usize>) -> Vec<usize> {
    cells.sort_unstable();
    cells.dedup();
    cells.into_iter().flat_map(nodes_of).collect()
}

fn grid_nodes<const D: usize>(grid: &RegularGrid<D>) -> Vec<[f64; 3]> {
    (0..grid.node_count())
        .map(|v| pad(&MovableMesh::node_position(grid, v)))
        .collect()
}

fn grid_cells<const D: usize>(grid: &RegularGrid<D>, points: &[[f64; 3]]) -> Vec<usize> {
    points
        .iter()
        .filter_map(|x| grid.cell_containing(&unpad(x)).ok())
        .filter_map(|c| grid.cell_id(c).ok())
        .collect()
}

/// Moves a mesh's nodes to the padded positions `nodes` (one per node).
fn move_nodes<const D: usize, M: MovableMesh<D>>(
    mesh: &mut M,
    nodes: &[[f64; 3]],
) -> Result<(), MeshMotionError> {
    mesh.move_nodes(nodes.iter().map(unpad).collect())
}

/// The node ids of cell `cell` in VTK order: counter-clockwise in 2D;
/// bottom face counter-clockwise, then the top face, in 3D.
fn grid_cell_nodes<const D: usize>(grid: &RegularGrid<D>, cell: usize) -> Vec<usize> {
    const ORDER_2D: [[usize; 3]; 4] = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]];
    const ORDER_3D: [[usize; 3]; 8] = [
        [0, 0, 0],
        [1, 0, 0],
        [1, 1, 0],
        [0, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [1, 1, 1],
        [0, 1, 1],
    ];
    let Ok(base) = grid.cell_index(cell) else {
        return Vec::new();
    };
    let order: &[[usize; 3]] = if D == 2 { &ORDER_2D } else { &ORDER_3D };
    order
        .iter()
        .filter_map(|offset| {
            let index: [usize; D] = std::array::from_fn(|i| base[i] + offset[i]);
            grid.node_id(index).ok()
        })
        .collect()
}

impl<const D: usize> CellMesh<D> for RegularGrid<D> {
    /// Quadrilaterals in 2D, hexahedra in 3D (other dimensions do not
    /// compile).
    const CELL: CellType = match D {
        2 => CellType::Quad,
        3 => CellType::Hexahedron,
        _ => panic!("VTK output is for 2D and 3D grids"),
    };
    fn vtk_nodes(&self) -> Vec<[f64; 3]> {
        grid_nodes(self)
    }
    fn cells_holding(&self, points: &[[f64; 3]]) -> Vec<usize> {
        connectivity(grid_cells(self, points), |c| grid_cell_nodes(self, c))
    }
    fn set_nodes(&mut self, nodes: &[[f64; 3]]) -> Result<(), MeshMotionError> {
        move_nodes(self, nodes)
    }
}

fn simplex_cells<const D: usize>(mesh: &SimplexMesh<D>, points: &[[f64; 3]]) -> Vec<usize> {
    let mut hint = None;
    let cells = points
        .iter()
        .filter_map(|x| {
            let found = mesh.locate(&unpad(x), hint).ok()?;
            hint = Some(found.element);
            Some(found.element)
        })
        .collect();
    connectivity(cells, |e| mesh.element_nodes(e).to_vec())
}

impl<const D: usize> CellMesh<D> for SimplexMesh<D> {
    /// Triangles in 2D, tetrahedra in 3D (other dimensions do not compile).
    const CELL: CellType = match D {
        2 => CellType::Triangle,
        3 => CellType::Tetra,
        _ => panic!("VTK output is for 2D and 3D meshes"),
    };
    fn vtk_nodes(&self) -> Vec<[f64; 3]> {
        self.nodes().iter().map(pad).collect()
    }
    fn cells_holding(&self, points: &[[f64; 3]]) -> Vec<usize> {
        simplex_cells(self, points)
    }
    fn set_nodes(&mut self, nodes: &[[f64; 3]]) -> Result<(), MeshMotionError> {
        move_nodes(self, nodes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mpm_mesh::BoxMesh;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn cells_holding_points_in_every_mesh_kind() {
        let g2 = RegularGrid::new(Vector2::zeros(), Vector2::new(1.0, 1.0), [3, 2]).expect("grid");
        let pts = [
            [0.5, 0.5, 0.0],
            [0.6, 0.4, 0.0],
            [2.5, 1.5, 0.0],
            [9.0, 9.0, 0.0],
        ];
        assert_eq!(g2.cells_holding(&pts), vec![0, 1, 5, 4, 6, 7, 11, 10]);
        let g3 = RegularGrid::new(Vector3::zeros(), Vector3::new(1.0, 1.0, 1.0), [1, 1, 1])
            .expect("grid");
        assert_eq!(
            g3.cells_holding(&[[0.5, 0.5, 0.5]]),
            vec![0, 1, 3, 2, 4, 5, 7, 6]
        );
        let t = BoxMesh::new(Vector3::zeros(), Vector3::new(1.0, 1.0, 1.0), [1, 1, 1])
            .simplex_mesh()
            .expect("mesh");
        let c = t.cells_holding(&[[0.2, 0.3, 0.4], [0.21, 0.3, 0.4]]);
        assert_eq!(c.len(), 4);
        let located = t
            .locate(&Vector3::new(0.2, 0.3, 0.4), None)
            .expect("inside");
        assert_eq!(c, t.element_nodes(located.element));
        let mut moved = t.clone();
        let stretched: Vec<[f64; 3]> = t
            .vtk_nodes()
            .iter()
            .map(|x| [x[0], 2.0 * x[1], x[2]])
            .collect();
        moved.set_nodes(&stretched).expect("stretch");
        assert!((moved.total_volume() - 2.0).abs() < 1e-14);
    }
}
