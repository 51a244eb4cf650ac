//! Material point bodies filling rectangular (box) regions of a grid.

use mpm_basis::{BasisFunction, Corners, Cpdi2, Gimp, LinearMpm, QuadraticBSpline};
use mpm_mesh::RegularGrid;
use nalgebra::SVector;

/// Material points laid out `points_per_cell` per direction in every cell
/// of a grid-aligned box, each with the volume of its sub-cell and the
/// half-lengths of its sub-cell as initial domain size (GIMP's
/// $l^0_p$, CPDI2's undeformed rectangle).
#[derive(Debug, Clone)]
pub struct Body<const D: usize> {
    /// Positions.
    pub position: Vec<SVector<f64, D>>,
    /// Initial volumes (plane strain: per unit thickness).
    pub volume: Vec<f64>,
    /// Initial domain half-lengths.
    pub half_lengths: Vec<SVector<f64, D>>,
    /// Sub-cell multi-index of each point within the box, for selecting
    /// points by their place in the lattice (boundary layers, load points).
    pub lattice: Vec<[usize; D]>,
    /// Points per direction in the whole box.
    pub lattice_size: [usize; D],
}

impl<const D: usize> Body<D> {
    /// Fills the box `lower..upper` (grid-aligned up to rounding) with
    /// `points_per_cell` points per direction per cell of `grid`.
    pub fn fill_box(
        grid: &RegularGrid<D>,
        lower: &SVector<f64, D>,
        upper: &SVector<f64, D>,
        points_per_cell: usize,
    ) -> Self {
        let ppc = points_per_cell.max(1);
        let h = grid.spacing();
        let mut lattice_size = [0usize; D];
        let mut step = SVector::<f64, D>::zeros();
        for i in 0..D {
            let cells = ((upper[i] - lower[i]) / h[i]).round().max(1.0) as usize;
            lattice_size[i] = cells * ppc;
            step[i] = (upper[i] - lower[i]) / lattice_size[i] as f64;
        }
        let total: usize = lattice_size.iter().product();
        let volume = step.iter().product::<f64>();
        let mut body = Self {
            position: Vec::with_capacity(total),
            volume: vec![volume; total],
            half_lengths: vec![step / 2.0; total],
            lattice: Vec::with_capacity(total),
            lattice_size,
        };
        for flat in 0..total {
            let mut rest = flat;
            let mut index = [0usize; D];
            let mut x = SVector::<f64, D>::zeros();
            for i in 0..D {
                index[i] = rest % lattice_size[i];
                rest /= lattice_size[i];
                x[i] = lower[i] + (index[i] as f64 + 0.5) * step[i];
            }
            body.position.push(x);
            body.lattice.push(index);
        }
        body
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether the body is empty.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
}

/// How a basis builds the initial domain of a point from its position and
/// half-lengths.
pub trait InitialDomain<const D: usize>: BasisFunction<D> {
    /// Cells of padding the basis needs between the body and a grid
    /// boundary (the B-spline stencil must stay inside the grid).
    const PADDING: usize = 0;

    /// Half-width of a point's support in cells, per axis (an upper bound
    /// for domain-based bases with domains of at most half a cell).
    const SUPPORT_RADIUS: f64 = 1.0;

    /// The undeformed domain.
    fn initial_domain(position: &SVector<f64, D>, half_lengths: &SVector<f64, D>) -> Self::Domain;
}

impl<const D: usize> InitialDomain<D> for LinearMpm {
    fn initial_domain(_: &SVector<f64, D>, _: &SVector<f64, D>) {}
}

impl<const D: usize> InitialDomain<D> for QuadraticBSpline {
    const PADDING: usize = 1;
    const SUPPORT_RADIUS: f64 = 1.5;

    fn initial_domain(_: &SVector<f64, D>, _: &SVector<f64, D>) {}
}

impl<const D: usize> InitialDomain<D> for Gimp {
    const SUPPORT_RADIUS: f64 = 1.5;
    fn initial_domain(_: &SVector<f64, D>, half_lengths: &SVector<f64, D>) -> SVector<f64, D> {
        *half_lengths
    }
}

impl<const D: usize> InitialDomain<D> for Cpdi2 {
    const SUPPORT_RADIUS: f64 = 1.5;
    fn initial_domain(position: &SVector<f64, D>, half_lengths: &SVector<f64, D>) -> Corners<D> {
        Corners::rectangle(position, half_lengths)
    }
}
