//! Tensor products of one-dimensional basis factors: one code path for 2D
//! and 3D.
//!
//! A tensor-product basis is $S_v(\mathbf x) = \prod_{i<D} S^{(i)}_{v_i}(x_i)$
//! with gradient $\partial_j S_v = S^{(j)\prime}_{v_j}\prod_{i\neq j}
//! S^{(i)}_{v_i}$ (e.g. MPoint notes eqs. 26–27). Each basis fills one
//! [`AxisFactors`] per axis with the 1D factors of its supporting nodes and
//! [`tensor_product`] loops over their Cartesian product.

use mpm_mesh::RegularGrid;
use nalgebra::SVector;

use crate::{BasisError, Stencil};

/// The 1D factors of at most `K` nodes along one axis: node index along the
/// axis, value and derivative with respect to the coordinate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AxisFactors<const K: usize> {
    len: usize,
    index: [usize; K],
    value: [f64; K],
    slope: [f64; K],
}

impl<const K: usize> AxisFactors<K> {
    pub(crate) const EMPTY: Self = Self {
        len: 0,
        index: [0; K],
        value: [0.0; K],
        slope: [0.0; K],
    };

    /// Append a factor unless both its value and slope are zero (such a node
    /// contributes nothing to any product). Callers never push more than
    /// `K` factors; a surplus factor would be dropped, never written out of
    /// bounds.
    pub(crate) fn push(&mut self, index: usize, value: f64, slope: f64) {
        if (value != 0.0 || slope != 0.0) && self.len < K {
            self.index[self.len] = index;
            self.value[self.len] = value;
            self.slope[self.len] = slope;
            self.len += 1;
        }
    }
}

/// Clear `out` and write the tensor product of the per-axis factors; node
/// ids come from `grid`. Products whose value and gradient vanish are
/// omitted.
pub(crate) fn tensor_product<const D: usize, const K: usize>(
    grid: &RegularGrid<D>,
    axes: &[AxisFactors<K>; D],
    out: &mut Stencil<D>,
) -> Result<(), BasisError> {
    out.clear();
    if axes.iter().any(|a| a.len == 0) {
        return Ok(());
    }
    let mut counter = [0usize; D];
    loop {
        let mut value = 1.0;
        let mut index = [0usize; D];
        for i in 0..D {
            value *= axes[i].value[counter[i]];
            index[i] = axes[i].index[counter[i]];
        }
        let gradient = SVector::<f64, D>::from_fn(|j, _| {
            (0..D).fold(1.0, |g, i| {
                g * if i == j {
                    axes[i].slope[counter[i]]
                } else {
                    axes[i].value[counter[i]]
                }
            })
        });
        if value != 0.0 || gradient.iter().any(|&g| g != 0.0) {
            out.push(grid.node_id(index)?, value, gradient);
        }
        let mut axis = 0;
        loop {
            counter[axis] += 1;
            if counter[axis] < axes[axis].len {
                break;
            }
            counter[axis] = 0;
            axis += 1;
            if axis == D {
                return Ok(());
            }
        }
    }
}
