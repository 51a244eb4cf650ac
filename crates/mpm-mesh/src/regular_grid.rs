//! Dimension-generic regular (Cartesian) background grid.
//!
//! The grid is the box $[\mathbf{o}, \mathbf{o} + \mathbf{n}\odot\mathbf{h}]$
//! split into $n_0 \times \dots \times n_{D-1}$ equal cells of size
//! $h_0 \times \dots \times h_{D-1}$. Nodes and cells are numbered
//! lexicographically with axis 0 fastest:
//! $\mathrm{id}(\mathbf{i}) = i_0 + (n_0+1)\,(i_1 + (n_1+1)\,i_2)$ for nodes and
//! $i_0 + n_0\,(i_1 + n_1\,i_2)$ for cells.
//!
//! Point location convention: a point belongs to the cell
//! $\lfloor (x_i - o_i)/h_i \rfloor$ along every axis, so a point on an
//! interior node line belongs to the cell above it, and a point exactly on
//! the upper boundary belongs to the last cell.

use nalgebra::SVector;

use crate::MeshError;

/// Which side of an axis a boundary face lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    /// The face $x_{\text{axis}} = o_{\text{axis}}$ (node index 0).
    Lower,
    /// The face $x_{\text{axis}} = o_{\text{axis}} + n_{\text{axis}} h_{\text{axis}}$
    /// (node index $n_{\text{axis}}$).
    Upper,
}

/// A boundary face of the grid, for example the base of a column is
/// `Face { axis: 1, side: Side::Lower }` in 2D.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Face {
    /// The axis normal to the face.
    pub axis: usize,
    /// The side of that axis.
    pub side: Side,
}

/// The cell containing a point and the point's local coordinates in it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellLocation<const D: usize> {
    /// Multi-index of the cell.
    pub cell: [usize; D],
    /// Local coordinates $t_i = (x_i - X_i)/h_i \in [0, 1]$, where
    /// $\mathbf{X}$ is the cell's lowest node.
    pub local: SVector<f64, D>,
}

/// A regular grid in `D` dimensions (`D` = 2 or 3 in practice; any `D >= 1`
/// works).
///
/// Construct with [`RegularGrid::new`] or [`RegularGrid::from_bounds`];
/// both validate their input and return a [`MeshError`] instead of building
/// an unusable grid.
///
/// ```
/// use mpm_mesh::RegularGrid;
/// use nalgebra::Vector2;
/// let grid = RegularGrid::new(Vector2::new(0.0, 0.0), Vector2::new(0.5, 0.25), [4, 8])?;
/// assert_eq!(grid.node_count(), 5 * 9);
/// assert_eq!(grid.cell_containing(&Vector2::new(1.2, 0.3))?, [2, 1]);
/// assert!(grid.cell_containing(&Vector2::new(2.1, 0.3)).is_err());
/// # Ok::<(), mpm_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct RegularGrid<const D: usize> {
    origin: SVector<f64, D>,
    spacing: SVector<f64, D>,
    upper: SVector<f64, D>,
    cells: [usize; D],
    node_strides: [usize; D],
    cell_strides: [usize; D],
    node_count: usize,
    cell_count: usize,
}

impl<const D: usize> RegularGrid<D> {
    /// A grid with lower corner `origin`, cell size `spacing` and `cells`
    /// cells per axis.
    ///
    /// # Errors
    /// [`MeshError::InvalidOrigin`] for a non-finite origin,
    /// [`MeshError::InvalidSpacing`] for a spacing that is not positive and
    /// finite, [`MeshError::NoCells`] for an axis without cells and
    /// [`MeshError::TooLarge`] if the node count overflows `usize` or the
    /// upper corner is not finite.
    pub fn new(
        origin: SVector<f64, D>,
        spacing: SVector<f64, D>,
        cells: [usize; D],
    ) -> Result<Self, MeshError> {
        const { assert!(D >= 1, "a grid needs at least one dimension") };
        for axis in 0..D {
            if !origin[axis].is_finite() {
                return Err(MeshError::InvalidOrigin {
                    axis,
                    value: origin[axis],
                });
            }
            if !(spacing[axis].is_finite() && spacing[axis] > 0.0) {
                return Err(MeshError::InvalidSpacing {
                    axis,
                    value: spacing[axis],
                });
            }
            if cells[axis] == 0 {
                return Err(MeshError::NoCells { axis });
            }
        }
        let too_large = || MeshError::TooLarge {
            cells: cells.to_vec(),
        };
        let mut node_strides = [0; D];
        let mut cell_strides = [0; D];
        let mut node_count: usize = 1;
        let mut cell_count: usize = 1;
        for axis in 0..D {
            node_strides[axis] = node_count;
            cell_strides[axis] = cell_count;
            let nodes = cells[axis].checked_add(1).ok_or_else(too_large)?;
            node_count = node_count.checked_mul(nodes).ok_or_else(too_large)?;
            cell_count = cell_count.checked_mul(cells[axis]).ok_or_else(too_large)?;
        }
        let upper =
            SVector::<f64, D>::from_fn(|axis, _| origin[axis] + cells[axis] as f64 * spacing[axis]);
        if upper.iter().any(|u| !u.is_finite()) {
            return Err(too_large());
        }
        Ok(Self {
            origin,
            spacing,
            upper,
            cells,
            node_strides,
            cell_strides,
            node_count,
            cell_count,
        })
    }

    /// A grid covering the box `[lower, upper]` with `cells` cells per axis.
    ///
    /// # Errors
    /// [`MeshError::InvalidBounds`] unless `lower < upper` with finite
    /// entries along every axis, and the errors of [`RegularGrid::new`].
    pub fn from_bounds(
        lower: SVector<f64, D>,
        upper: SVector<f64, D>,
        cells: [usize; D],
    ) -> Result<Self, MeshError> {
        for axis in 0..D {
            let (lo, up) = (lower[axis], upper[axis]);
            if !(lo.is_finite() && up.is_finite() && lo < up) {
                return Err(MeshError::InvalidBounds {
                    axis,
                    lower: lo,
                    upper: up,
                });
            }
            if cells[axis] == 0 {
                return Err(MeshError::NoCells { axis });
            }
        }
        let spacing =
            SVector::<f64, D>::from_fn(|axis, _| (upper[axis] - lower[axis]) / cells[axis] as f64);
        Self::new(lower, spacing, cells)
    }

    /// Lower corner of the grid (the position of node 0).
    pub fn origin(&self) -> &SVector<f64, D> {
        &self.origin
    }

    /// Cell size along every axis.
    pub fn spacing(&self) -> &SVector<f64, D> {
        &self.spacing
    }

    /// Upper corner of the grid, $o_i + n_i h_i$.
    pub fn upper(&self) -> &SVector<f64, D> {
        &self.upper
    }

    /// Number of cells along every axis.
    pub fn cells_per_axis(&self) -> [usize; D] {
        self.cells
    }

    /// Number of nodes along every axis (cells + 1).
    pub fn nodes_per_axis(&self) -> [usize; D] {
        self.cells.map(|n| n + 1)
    }

    /// Node id strides per axis: node `[i, j, ..]` has id
    /// `i * strides[0] + j * strides[1] + ..` (the first axis is fastest).
    pub fn node_strides(&self) -> [usize; D] {
        self.node_strides
    }

    /// Total number of nodes.
    pub fn node_count(&self) -> usize {
        self.node_count
    }

    /// Total number of cells.
    pub fn cell_count(&self) -> usize {
        self.cell_count
    }

    /// Whether `point` lies in the closed box of the grid (false for
    /// non-finite points).
    pub fn contains(&self, point: &SVector<f64, D>) -> bool {
        (0..D).all(|i| point[i] >= self.origin[i] && point[i] <= self.upper[i])
    }

    /// Node id of a node multi-index.
    ///
    /// # Errors
    /// [`MeshError::NodeIndexOutOfRange`] if `index[i] > cells[i]` for some
    /// axis.
    pub fn node_id(&self, index: [usize; D]) -> Result<usize, MeshError> {
        let mut id = 0;
        for axis in 0..D {
            if index[axis] > self.cells[axis] {
                return Err(MeshError::NodeIndexOutOfRange {
                    index: index.to_vec(),
                    nodes_per_axis: self.nodes_per_axis().to_vec(),
                });
            }
            id += index[axis] * self.node_strides[axis];
        }
        Ok(id)
    }

    /// Node multi-index of a node id.
    ///
    /// # Errors
    /// [`MeshError::NodeIdOutOfRange`] if `id >= node_count()`.
    pub fn node_index(&self, id: usize) -> Result<[usize; D], MeshError> {
        if id >= self.node_count {
            return Err(MeshError::NodeIdOutOfRange {
                id,
                count: self.node_count,
            });
        }
        let mut rest = id;
        let mut index = [0; D];
        for (axis, entry) in index.iter_mut().enumerate() {
            let n = self.cells[axis] + 1;
            *entry = rest % n;
            rest /= n;
        }
        Ok(index)
    }

    /// Coordinates of the node with multi-index `index`.
    ///
    /// # Errors
    /// [`MeshError::NodeIndexOutOfRange`] as for [`RegularGrid::node_id`].
    pub fn node_position_at(&self, index: [usize; D]) -> Result<SVector<f64, D>, MeshError> {
        self.node_id(index)?;
        Ok(SVector::from_fn(|axis, _| {
            self.origin[axis] + index[axis] as f64 * self.spacing[axis]
        }))
    }

    /// Coordinates of node `id`.
    ///
    /// # Errors
    /// [`MeshError::NodeIdOutOfRange`] if `id >= node_count()`.
    pub fn node_position(&self, id: usize) -> Result<SVector<f64, D>, MeshError> {
        self.node_position_at(self.node_index(id)?)
    }

    /// Cell id of a cell multi-index.
    ///
    /// # Errors
    /// [`MeshError::CellIndexOutOfRange`] if `index[i] >= cells[i]` for some
    /// axis.
    pub fn cell_id(&self, index: [usize; D]) -> Result<usize, MeshError> {
        let mut id = 0;
        for axis in 0..D {
            if index[axis] >= self.cells[axis] {
                return Err(MeshError::CellIndexOutOfRange {
                    index: index.to_vec(),
                    cells_per_axis: self.cells.to_vec(),
                });
            }
            id += index[axis] * self.cell_strides[axis];
        }
        Ok(id)
    }

    /// Cell multi-index of a cell id.
    ///
    /// # Errors
    /// [`MeshError::CellIdOutOfRange`] if `id >= cell_count()`.
    pub fn cell_index(&self, id: usize) -> Result<[usize; D], MeshError> {
        if id >= self.cell_count {
            return Err(MeshError::CellIdOutOfRange {
                id,
                count: self.cell_count,
            });
        }
        let mut rest = id;
        let mut index = [0; D];
        for (axis, entry) in index.iter_mut().enumerate() {
            *entry = rest % self.cells[axis];
            rest /= self.cells[axis];
        }
        Ok(index)
    }

    /// The ids of the $2^D$ nodes of a cell, lexicographic (corner bit `i`
    /// set means the upper node along axis `i`).
    ///
    /// # Errors
    /// [`MeshError::CellIndexOutOfRange`] for a cell that does not exist.
    pub fn cell_nodes(&self, cell: [usize; D]) -> Result<CellNodes<D>, MeshError> {
        self.cell_id(cell)?;
        let base = (0..D).map(|i| cell[i] * self.node_strides[i]).sum();
        Ok(CellNodes {
            base,
            strides: self.node_strides,
            next: 0,
        })
    }

    /// Multi-index of the cell containing `point` (see the module
    /// documentation for points on node lines and on the upper boundary).
    ///
    /// # Errors
    /// [`MeshError::PointOutsideGrid`] if the point lies outside the closed
    /// box of the grid or is not finite.
    pub fn cell_containing(&self, point: &SVector<f64, D>) -> Result<[usize; D], MeshError> {
        Ok(self.locate(point)?.cell)
    }

    /// The cell containing `point` and the point's local coordinates in it.
    ///
    /// # Errors
    /// [`MeshError::PointOutsideGrid`] as for
    /// [`RegularGrid::cell_containing`].
    #[inline]
    pub fn locate(&self, point: &SVector<f64, D>) -> Result<CellLocation<D>, MeshError> {
        if !self.contains(point) {
            return Err(self.outside(point));
        }
        let mut cell = [0; D];
        let mut local = SVector::<f64, D>::zeros();
        for axis in 0..D {
            // `contains` guarantees point >= origin, so r >= 0 and the
            // truncating conversion is the floor (without a libm call); r <= n
            // up to one rounding, so the clamp only acts on the upper face.
            let r = (point[axis] - self.origin[axis]) / self.spacing[axis];
            let k = (r as usize).min(self.cells[axis] - 1);
            cell[axis] = k;
            local[axis] = (r - k as f64).clamp(0.0, 1.0);
        }
        Ok(CellLocation { cell, local })
    }

    /// The ids of the nodes on a boundary face, in increasing order.
    ///
    /// # Errors
    /// [`MeshError::InvalidAxis`] if `face.axis >= D`.
    pub fn boundary_nodes(&self, face: Face) -> Result<Vec<usize>, MeshError> {
        if face.axis >= D {
            return Err(MeshError::InvalidAxis {
                axis: face.axis,
                dimension: D,
            });
        }
        let fixed = match face.side {
            Side::Lower => 0,
            Side::Upper => self.cells[face.axis],
        };
        let nodes = (0..self.node_count)
            .filter(|&id| {
                (id / self.node_strides[face.axis]) % (self.cells[face.axis] + 1) == fixed
            })
            .collect();
        Ok(nodes)
    }

    /// The error for a point outside the grid.
    pub(crate) fn outside(&self, point: &SVector<f64, D>) -> MeshError {
        MeshError::PointOutsideGrid {
            point: point.iter().copied().collect(),
            lower: self.origin.iter().copied().collect(),
            upper: self.upper.iter().copied().collect(),
        }
    }
}

/// Iterator over the node ids of one cell, returned by
/// [`RegularGrid::cell_nodes`].
#[derive(Debug, Clone)]
pub struct CellNodes<const D: usize> {
    base: usize,
    strides: [usize; D],
    next: usize,
}

impl<const D: usize> Iterator for CellNodes<D> {
    type Item = usize;

    fn next(&mut self) -> Option<usize> {
        if self.next >= 1 << D {
            return None;
        }
        let corner = self.next;
        self.next += 1;
        let offset: usize = (0..D)
            .filter(|i| corner >> i & 1 == 1)
            .map(|i| self.strides[i])
            .sum();
        Some(self.base + offset)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (1 << D) - self.next;
        (left, Some(left))
    }
}

impl<const D: usize> ExactSizeIterator for CellNodes<D> {}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    fn grid2() -> RegularGrid<2> {
        RegularGrid::new(Vector2::new(-1.0, 0.5), Vector2::new(0.5, 0.25), [4, 3])
            .expect("valid grid")
    }

    fn grid3() -> RegularGrid<3> {
        RegularGrid::new(
            Vector3::new(0.0, -2.0, 1.0),
            Vector3::new(1.0, 0.5, 0.25),
            [3, 2, 4],
        )
        .expect("valid grid")
    }

    #[test]
    fn counts_and_corners() {
        let g = grid2();
        assert_eq!(g.cells_per_axis(), [4, 3]);
        assert_eq!(g.nodes_per_axis(), [5, 4]);
        assert_eq!(g.node_count(), 20);
        assert_eq!(g.cell_count(), 12);
        assert_eq!(*g.upper(), Vector2::new(1.0, 1.25));
        let g = grid3();
        assert_eq!(g.node_count(), 4 * 3 * 5);
        assert_eq!(g.cell_count(), 3 * 2 * 4);
        assert_eq!(*g.upper(), Vector3::new(3.0, -1.0, 2.0));
    }

    #[test]
    fn from_bounds_matches_new() {
        let g = RegularGrid::from_bounds(Vector2::new(-1.0, 0.5), Vector2::new(1.0, 1.25), [4, 3])
            .expect("valid bounds");
        assert_eq!(g, grid2());
        assert_eq!(
            RegularGrid::from_bounds(Vector2::new(0.0, 1.0), Vector2::new(1.0, 1.0), [1, 1]),
            Err(MeshError::InvalidBounds {
                axis: 1,
                lower: 1.0,
                upper: 1.0
            })
        );
        assert_eq!(
            RegularGrid::from_bounds(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0), [1, 0]),
            Err(MeshError::NoCells { axis: 1 })
        );
    }

    #[test]
    fn constructor_rejects_bad_input() {
        let o = Vector2::new(0.0, 0.0);
        let h = Vector2::new(1.0, 1.0);
        let err = RegularGrid::new(Vector2::new(0.0, f64::NAN), h, [1, 1]);
        assert!(
            matches!(err, Err(MeshError::InvalidOrigin { axis: 1, value }) if value.is_nan()),
            "{err:?}"
        );
        for bad in [0.0, -1.0, f64::INFINITY, f64::NAN] {
            let err = RegularGrid::new(o, Vector2::new(1.0, bad), [1, 1]);
            assert!(
                matches!(err, Err(MeshError::InvalidSpacing { axis: 1, .. })),
                "spacing {bad} gave {err:?}"
            );
        }
        assert_eq!(
            RegularGrid::new(o, h, [0, 2]),
            Err(MeshError::NoCells { axis: 0 })
        );
        assert_eq!(
            RegularGrid::new(o, h, [usize::MAX, 2]),
            Err(MeshError::TooLarge {
                cells: vec![usize::MAX, 2]
            })
        );
        assert!(matches!(
            RegularGrid::new(o, Vector2::new(1e308, 1.0), [10, 1]),
            Err(MeshError::TooLarge { .. })
        ));
    }

    #[test]
    fn node_ids_round_trip_axis_zero_fastest() {
        let g = grid3();
        assert_eq!(g.node_id([1, 0, 0]), Ok(1));
        assert_eq!(g.node_id([0, 1, 0]), Ok(4));
        assert_eq!(g.node_id([0, 0, 1]), Ok(12));
        for id in 0..g.node_count() {
            let index = g.node_index(id).expect("id in range");
            assert_eq!(g.node_id(index), Ok(id));
        }
        assert_eq!(
            g.node_id([4, 0, 0]),
            Err(MeshError::NodeIndexOutOfRange {
                index: vec![4, 0, 0],
                nodes_per_axis: vec![4, 3, 5]
            })
        );
        assert_eq!(
            g.node_index(60),
            Err(MeshError::NodeIdOutOfRange { id: 60, count: 60 })
        );
    }

    #[test]
    fn cell_ids_round_trip_axis_zero_fastest() {
        let g = grid3();
        assert_eq!(g.cell_id([1, 0, 0]), Ok(1));
        assert_eq!(g.cell_id([0, 1, 0]), Ok(3));
        assert_eq!(g.cell_id([0, 0, 1]), Ok(6));
        for id in 0..g.cell_count() {
            let index = g.cell_index(id).expect("id in range");
            assert_eq!(g.cell_id(index), Ok(id));
        }
        assert!(matches!(
            g.cell_id([0, 2, 0]),
            Err(MeshError::CellIndexOutOfRange { .. })
        ));
        assert_eq!(
            g.cell_index(24),
            Err(MeshError::CellIdOutOfRange { id: 24, count: 24 })
        );
    }

    #[test]
    fn node_positions() {
        let g = grid3();
        assert_eq!(
            g.node_position_at([3, 2, 4]),
            Ok(Vector3::new(3.0, -1.0, 2.0))
        );
        let id = g.node_id([1, 1, 2]).expect("in range");
        assert_eq!(g.node_position(id), Ok(Vector3::new(1.0, -1.5, 1.5)));
        assert!(g.node_position(g.node_count()).is_err());
        assert!(g.node_position_at([0, 3, 0]).is_err());
    }

    #[test]
    fn cell_nodes_are_the_cell_corners() {
        let g = grid3();
        let cell = [2, 1, 3];
        let nodes: Vec<usize> = g.cell_nodes(cell).expect("cell exists").collect();
        assert_eq!(nodes.len(), 8);
        for (corner, &id) in nodes.iter().enumerate() {
            let expected = [
                cell[0] + (corner & 1),
                cell[1] + (corner >> 1 & 1),
                cell[2] + (corner >> 2 & 1),
            ];
            assert_eq!(g.node_index(id), Ok(expected));
        }
        assert!(g.cell_nodes([3, 0, 0]).is_err());
    }

    #[test]
    fn cell_containing_interior_node_lines_and_boundary() {
        let g = grid2();
        // Interior point.
        assert_eq!(g.cell_containing(&Vector2::new(-0.3, 0.9)), Ok([1, 1]));
        // On an interior node line: the cell above.
        assert_eq!(g.cell_containing(&Vector2::new(0.0, 1.0)), Ok([2, 2]));
        // On the lower and upper boundary and in the corners.
        assert_eq!(g.cell_containing(&Vector2::new(-1.0, 0.5)), Ok([0, 0]));
        assert_eq!(g.cell_containing(&Vector2::new(1.0, 1.25)), Ok([3, 2]));
        assert_eq!(g.cell_containing(&Vector2::new(1.0, 0.6)), Ok([3, 0]));
        let loc = g.locate(&Vector2::new(1.0, 0.5625)).expect("inside");
        assert_eq!(loc.cell, [3, 0]);
        assert_eq!(loc.local, Vector2::new(1.0, 0.25));
    }

    #[test]
    fn outside_points_are_named_in_the_error() {
        let g = grid2();
        for p in [
            Vector2::new(-1.0 - 1e-12, 0.7),
            Vector2::new(0.0, 1.25 + 1e-12),
            Vector2::new(5.0, -3.0),
            Vector2::new(f64::NAN, 0.7),
            Vector2::new(0.0, f64::INFINITY),
        ] {
            match g.cell_containing(&p) {
                Err(MeshError::PointOutsideGrid {
                    point,
                    lower,
                    upper,
                }) => {
                    assert_eq!(point.len(), 2);
                    for (a, b) in point.iter().zip(p.iter()) {
                        assert!(a == b || (a.is_nan() && b.is_nan()));
                    }
                    assert_eq!(lower, vec![-1.0, 0.5]);
                    assert_eq!(upper, vec![1.0, 1.25]);
                }
                other => panic!("point {p:?} gave {other:?}"),
            }
        }
        let err = g
            .cell_containing(&Vector2::new(5.0, -3.0))
            .expect_err("outside");
        assert!(err.to_string().contains("[5.0, -3.0]"), "{err}");
    }

    #[test]
    fn boundary_nodes_per_face() {
        let g = grid2();
        let lower_x = g
            .boundary_nodes(Face {
                axis: 0,
                side: Side::Lower,
            })
            .expect("axis exists");
        assert_eq!(lower_x, vec![0, 5, 10, 15]);
        let upper_y = g
            .boundary_nodes(Face {
                axis: 1,
                side: Side::Upper,
            })
            .expect("axis exists");
        assert_eq!(upper_y, vec![15, 16, 17, 18, 19]);
        let g = grid3();
        for axis in 0..3 {
            for side in [Side::Lower, Side::Upper] {
                let nodes = g.boundary_nodes(Face { axis, side }).expect("axis exists");
                let n = g.nodes_per_axis();
                assert_eq!(nodes.len(), g.node_count() / n[axis]);
                for &id in &nodes {
                    let x = g.node_position(id).expect("valid id");
                    let target = match side {
                        Side::Lower => g.origin()[axis],
                        Side::Upper => g.upper()[axis],
                    };
                    assert_eq!(x[axis], target);
                }
            }
        }
        assert_eq!(
            g.boundary_nodes(Face {
                axis: 3,
                side: Side::Lower
            }),
            Err(MeshError::InvalidAxis {
                axis: 3,
                dimension: 3
            })
        );
    }
}

#[cfg(test)]
mod properties {
    use super::*;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    fn grid() -> RegularGrid<3> {
        RegularGrid::new(
            Vector3::new(-1.3, 0.2, 7.0),
            Vector3::new(0.3, 0.7, 0.125),
            [5, 3, 8],
        )
        .expect("valid grid")
    }

    proptest! {
        /// The located cell's closed extent contains the point and the local
        /// coordinates reproduce it.
        #[test]
        fn located_cell_contains_the_point(t in proptest::array::uniform3(0.0..=1.0f64)) {
            let g = grid();
            let x = g.origin() + (g.upper() - g.origin()).component_mul(&Vector3::from(t));
            let loc = g.locate(&x).expect("inside");
            let lo = g.node_position_at(loc.cell).expect("cell node");
            let hi = g.node_position_at(loc.cell.map(|k| k + 1)).expect("cell node");
            for i in 0..3 {
                let tol = 1e-14 * (1.0 + x[i].abs());
                prop_assert!(lo[i] - tol <= x[i] && x[i] <= hi[i] + tol);
                prop_assert!((0.0..=1.0).contains(&loc.local[i]));
                let back = lo[i] + loc.local[i] * g.spacing()[i];
                prop_assert!((back - x[i]).abs() <= tol, "axis {}: {} vs {}", i, back, x[i]);
            }
        }

        /// Points outside the box always give the typed error, never a cell.
        #[test]
        fn outside_points_are_rejected(
            t in proptest::array::uniform3(-2.0..3.0f64),
            axis in 0usize..3,
            beyond in prop_oneof![-2.0..-1e-9f64, (1.0 + 1e-9)..3.0f64],
        ) {
            let g = grid();
            let mut t = t;
            t[axis] = beyond;
            let x = g.origin() + (g.upper() - g.origin()).component_mul(&Vector3::from(t));
            let is_outside_error = matches!(
                g.cell_containing(&x),
                Err(MeshError::PointOutsideGrid { .. })
            );
            prop_assert!(is_outside_error);
        }
    }
}
