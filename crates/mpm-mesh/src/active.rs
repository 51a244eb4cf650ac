//! Active cells and nodes: the part of a regular grid touched by a set of
//! material points (standard MPM) or of material point domains (GIMP,
//! CPDI2, B-spline supports) given as bounding boxes.
//!
//! These run once per load step to size the global system; they allocate
//! their result and a mask over the grid, never per material point.

use nalgebra::SVector;

use crate::{MeshError, RegularGrid};

/// An axis-aligned box $[\mathbf{l}, \mathbf{u}]$, for example the bounding
/// box of a GIMP or CPDI2 material point domain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundingBox<const D: usize> {
    /// Lower corner.
    pub lower: SVector<f64, D>,
    /// Upper corner.
    pub upper: SVector<f64, D>,
}

impl<const D: usize> BoundingBox<D> {
    /// The box `center ± half_lengths` (a GIMP domain).
    pub fn around(center: &SVector<f64, D>, half_lengths: &SVector<f64, D>) -> Self {
        Self {
            lower: center - half_lengths,
            upper: center + half_lengths,
        }
    }

    /// The smallest box containing `points` (for example a CPDI2 domain's
    /// corners); `None` for an empty slice.
    pub fn of_points(points: &[SVector<f64, D>]) -> Option<Self> {
        let first = points.first()?;
        Some(points.iter().fold(
            Self {
                lower: *first,
                upper: *first,
            },
            |b, p| Self {
                lower: b.lower.inf(p),
                upper: b.upper.sup(p),
            },
        ))
    }

    fn is_valid(&self) -> bool {
        (0..D).all(|i| {
            self.lower[i].is_finite() && self.upper[i].is_finite() && self.lower[i] <= self.upper[i]
        })
    }
}

impl<const D: usize> RegularGrid<D> {
    /// Sorted ids of the cells containing at least one of `points`.
    ///
    /// # Errors
    /// [`MeshError::ParticleOutsideGrid`] naming the first point outside
    /// the grid.
    pub fn active_cells(&self, points: &[SVector<f64, D>]) -> Result<Vec<usize>, MeshError> {
        let mut mask = vec![false; self.cell_count()];
        for (particle, point) in points.iter().enumerate() {
            let cell = self
                .cell_containing(point)
                .map_err(|_| MeshError::ParticleOutsideGrid {
                    particle,
                    point: point.iter().copied().collect(),
                })?;
            mask[self.cell_id(cell)?] = true;
        }
        Ok(collect_mask(&mask))
    }

    /// Sorted ids of the nodes of the cells containing `points`: the nodes
    /// that carry a standard MPM basis function of some point.
    ///
    /// # Errors
    /// As [`RegularGrid::active_cells`].
    pub fn active_nodes(&self, points: &[SVector<f64, D>]) -> Result<Vec<usize>, MeshError> {
        let cells = self.active_cells(points)?;
        self.nodes_of_cells(&cells)
    }

    /// Sorted ids of the cells intersecting at least one of `boxes` (closed
    /// boxes and closed cells, so a cell touched only on a face counts).
    /// Boxes that stick out of the grid are clipped to it.
    ///
    /// # Errors
    /// [`MeshError::InvalidBox`] for a box with non-finite corners or
    /// `lower > upper`, and [`MeshError::BoxOutsideGrid`] for a box that
    /// does not intersect the grid; both name the box.
    pub fn active_cells_of_boxes(&self, boxes: &[BoundingBox<D>]) -> Result<Vec<usize>, MeshError> {
        let mut mask = vec![false; self.cell_count()];
        let cells = self.cells_per_axis();
        for (particle, b) in boxes.iter().enumerate() {
            let describe = || {
                (
                    b.lower.iter().copied().collect::<Vec<_>>(),
                    b.upper.iter().copied().collect::<Vec<_>>(),
                )
            };
            if !b.is_valid() {
                let (lower, upper) = describe();
                return Err(MeshError::InvalidBox {
                    particle,
                    lower,
                    upper,
                });
            }
            let mut first = [0usize; D];
            let mut last = [0usize; D];
            for axis in 0..D {
                let (o, h) = (self.origin()[axis], self.spacing()[axis]);
                if b.upper[axis] < o || b.lower[axis] > self.upper()[axis] {
                    let (lower, upper) = describe();
                    return Err(MeshError::BoxOutsideGrid {
                        particle,
                        lower,
                        upper,
                    });
                }
                // Cells whose closed extent [o + k h, o + (k+1) h] meets
                // [lower, upper]: k from ceil(r_lo) - 1 to floor(r_up).
                let r_lo = ((b.lower[axis] - o) / h).max(0.0);
                let r_up = ((b.upper[axis] - o) / h).min(cells[axis] as f64);
                let lo = (r_lo.ceil() as usize).saturating_sub(1);
                let up = (r_up.floor() as usize).min(cells[axis] - 1);
                first[axis] = lo.min(up);
                last[axis] = up;
            }
            let mut index = first;
            'cells: loop {
                mask[self.cell_id(index)?] = true;
                let mut axis = 0;
                while index[axis] == last[axis] {
                    index[axis] = first[axis];
                    axis += 1;
                    if axis == D {
                        break 'cells;
                    }
                }
                index[axis] += 1;
            }
        }
        Ok(collect_mask(&mask))
    }

    /// Sorted ids of the nodes of the cells intersecting `boxes`.
    ///
    /// # Errors
    /// As [`RegularGrid::active_cells_of_boxes`].
    pub fn active_nodes_of_boxes(&self, boxes: &[BoundingBox<D>]) -> Result<Vec<usize>, MeshError> {
        let cells = self.active_cells_of_boxes(boxes)?;
        self.nodes_of_cells(&cells)
    }

    fn nodes_of_cells(&self, cells: &[usize]) -> Result<Vec<usize>, MeshError> {
        let mut mask = vec![false; self.node_count()];
        for &cell in cells {
            for node in self.cell_nodes(self.cell_index(cell)?)? {
                mask[node] = true;
            }
        }
        Ok(collect_mask(&mask))
    }
}

fn collect_mask(mask: &[bool]) -> Vec<usize> {
    mask.iter()
        .enumerate()
        .filter_map(|(id, &on)| on.then_some(id))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    fn grid2() -> RegularGrid<2> {
        // Cells of 0.5 x 0.25 on [-1, 1] x [0.5, 1.25]: 4 x 3 cells, 5 x 4 nodes.
        RegularGrid::new(Vector2::new(-1.0, 0.5), Vector2::new(0.5, 0.25), [4, 3])
            .expect("valid grid")
    }

    #[test]
    fn active_cells_and_nodes_of_points() {
        let g = grid2();
        let points = [
            Vector2::new(-0.9, 0.6), // cell [0, 0] = 0
            Vector2::new(-0.8, 0.7), // cell [0, 0] again
            Vector2::new(0.75, 1.2), // cell [3, 2] = 11
            Vector2::new(1.0, 1.25), // upper corner: cell [3, 2]
            Vector2::new(0.0, 0.75), // node line: cell [2, 1] = 6
        ];
        assert_eq!(g.active_cells(&points), Ok(vec![0, 6, 11]));
        // Nodes of cell 0: 0, 1, 5, 6; of cell 6: 7, 8, 12, 13; of cell 11: 13, 14, 18, 19.
        assert_eq!(
            g.active_nodes(&points),
            Ok(vec![0, 1, 5, 6, 7, 8, 12, 13, 14, 18, 19])
        );
        assert_eq!(g.active_cells(&[]), Ok(vec![]));
    }

    #[test]
    fn active_sets_name_the_outside_point() {
        let g = grid2();
        let points = [Vector2::new(0.0, 0.75), Vector2::new(1.5, 0.75)];
        assert_eq!(
            g.active_cells(&points),
            Err(MeshError::ParticleOutsideGrid {
                particle: 1,
                point: vec![1.5, 0.75]
            })
        );
        assert!(matches!(
            g.active_nodes(&[Vector2::new(f64::NAN, 0.75)]),
            Err(MeshError::ParticleOutsideGrid { particle: 0, .. })
        ));
    }

    #[test]
    fn active_cells_of_boxes_include_touched_cells_and_clip() {
        let g = grid2();
        // Strictly inside cell [1, 1] (id 5).
        let inside = BoundingBox::around(&Vector2::new(-0.25, 0.875), &Vector2::new(0.1, 0.05));
        assert_eq!(g.active_cells_of_boxes(&[inside]), Ok(vec![5]));
        // Straddles the node line x = 0 and y = 1.0: cells [1..=2] x [1..=2].
        let straddle = BoundingBox::around(&Vector2::new(0.0, 1.0), &Vector2::new(0.1, 0.1));
        assert_eq!(g.active_cells_of_boxes(&[straddle]), Ok(vec![5, 6, 9, 10]));
        // Touches x = 0 from below only on the face: both neighbours count.
        let touch = BoundingBox {
            lower: Vector2::new(-0.2, 0.8),
            upper: Vector2::new(0.0, 0.9),
        };
        assert_eq!(g.active_cells_of_boxes(&[touch]), Ok(vec![5, 6]));
        // Sticks out of the lower-left corner: clipped to cell 0.
        let out = BoundingBox::around(&Vector2::new(-1.0, 0.5), &Vector2::new(0.2, 0.1));
        assert_eq!(g.active_cells_of_boxes(&[out]), Ok(vec![0]));
        // Covers everything.
        let all = BoundingBox::around(&Vector2::new(0.0, 0.9), &Vector2::new(5.0, 5.0));
        assert_eq!(
            g.active_cells_of_boxes(&[all]),
            Ok((0..12).collect::<Vec<_>>())
        );
        assert_eq!(g.active_nodes_of_boxes(&[inside]), Ok(vec![6, 7, 11, 12]));
    }

    #[test]
    fn boxes_agree_with_points_for_degenerate_interior_boxes() {
        let g = RegularGrid::new(
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.5, 0.25),
            [3, 4, 5],
        )
        .expect("valid grid");
        let p = Vector3::new(1.3, 0.7, 0.6);
        let b = BoundingBox::around(&p, &Vector3::zeros());
        assert_eq!(g.active_cells_of_boxes(&[b]), g.active_cells(&[p]));
        assert_eq!(g.active_nodes_of_boxes(&[b]), g.active_nodes(&[p]));
    }

    #[test]
    fn bad_boxes_are_named() {
        let g = grid2();
        let ok = BoundingBox::around(&Vector2::new(0.0, 1.0), &Vector2::new(0.1, 0.1));
        let inverted = BoundingBox {
            lower: Vector2::new(0.1, 0.8),
            upper: Vector2::new(0.0, 0.9),
        };
        assert_eq!(
            g.active_cells_of_boxes(&[ok, inverted]),
            Err(MeshError::InvalidBox {
                particle: 1,
                lower: vec![0.1, 0.8],
                upper: vec![0.0, 0.9]
            })
        );
        let nan = BoundingBox::around(&Vector2::new(f64::NAN, 1.0), &Vector2::new(0.1, 0.1));
        assert!(matches!(
            g.active_cells_of_boxes(&[nan]),
            Err(MeshError::InvalidBox { particle: 0, .. })
        ));
        let far = BoundingBox::around(&Vector2::new(3.0, 1.0), &Vector2::new(0.1, 0.1));
        assert!(matches!(
            g.active_nodes_of_boxes(&[ok, ok, far]),
            Err(MeshError::BoxOutsideGrid { particle: 2, .. })
        ));
    }

    #[test]
    fn bounding_box_of_points() {
        assert_eq!(BoundingBox::<2>::of_points(&[]), None);
        let b = BoundingBox::of_points(&[
            Vector2::new(0.0, 1.0),
            Vector2::new(-1.0, 2.0),
            Vector2::new(0.5, 1.5),
        ])
        .expect("non-empty");
        assert_eq!(b.lower, Vector2::new(-1.0, 1.0));
        assert_eq!(b.upper, Vector2::new(0.5, 2.0));
    }
}
