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

/// A tensor-product stencil given by its factors: along axis `i` the nodes
/// with index `first[i]`, …, `first[i] + len[i] - 1` (consecutive), with
/// the 1D values `value[i][k]` and slopes `slope[i][k]` (per unit length);
/// the weight of node $(k_0, k_1, …)$ is $\prod_i$ `value[i][k_i]` and its
/// gradient component $j$ is `slope[j][k_j]` $\prod_{i \ne j}$
/// `value[i][k_i]`. Solvers that exploit the structure contract one axis at
/// a time (sum factorisation) instead of visiting $3^D$ full products; see
/// [`crate::BasisFunction::tensor_factors`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensorFactors<const D: usize> {
    /// Id of the node with the lowest index on every axis.
    pub first_id: usize,
    /// Node id strides per axis (1 along the first axis).
    pub strides: [usize; D],
    /// Index of the first node along every axis.
    pub first: [usize; D],
    /// Number of nodes along every axis (at most 3).
    pub len: [usize; D],
    /// 1D values.
    pub value: [[f64; 3]; D],
    /// 1D slopes (derivatives with respect to the coordinate).
    pub slope: [[f64; 3]; D],
    /// Coordinate of the first node along every axis minus the point's.
    pub first_offset: [f64; D],
    /// Grid spacing per axis.
    pub spacing: [f64; D],
}

impl<const D: usize> TensorFactors<D> {
    /// Id of the node with the highest index on every axis (the largest
    /// id of the stencil).
    #[inline]
    pub fn last_id(&self) -> usize {
        self.first_id
            + (0..D)
                .map(|i| self.len[i].saturating_sub(1) * self.strides[i])
                .sum::<usize>()
    }
}

/// The three methods shared by the point-domain tensor-product bases
/// (`Domain = ()`, `Mesh = RegularGrid<D>`): `evaluate`, `tensor_factors`
/// and `for_each_node`, each from the basis's per-axis factors, given as
/// an expression in `mesh` and `position` of type
/// `Result<[AxisFactors<K>; D], BasisError>`.
macro_rules! tensor_basis_methods {
    (|$mesh:ident, $position:ident| $factors:expr) => {
        fn evaluate(
            &self,
            $mesh: &RegularGrid<D>,
            $position: &SVector<f64, D>,
            _domain: &(),
            out: &mut Stencil<D>,
        ) -> Result<(), BasisError> {
            out.clear();
            let axes = $factors?;
            $crate::tensor::tensor_product($mesh, &axes, out)
        }

        #[inline]
        fn tensor_factors(
            &self,
            $mesh: &RegularGrid<D>,
            $position: &SVector<f64, D>,
            _domain: &(),
        ) -> Option<Result<$crate::TensorFactors<D>, BasisError>> {
            match $factors {
                Ok(axes) => $crate::tensor::tensor_factors($mesh, $position, &axes).map(Ok),
                Err(e) => Some(Err(e)),
            }
        }

        #[inline]
        fn for_each_node(
            &self,
            $mesh: &RegularGrid<D>,
            $position: &SVector<f64, D>,
            _domain: &(),
            _scratch: &mut Stencil<D>,
            visit: impl FnMut(usize, f64, &SVector<f64, D>),
        ) -> Result<(), BasisError> {
            let axes = $factors?;
            $crate::tensor::visit_product($mesh, &axes, visit)
        }
    };
}
pub(crate) use tensor_basis_methods;

/// The [`TensorFactors`] of per-axis factors of at most 3 consecutive
/// nodes, or `None` when the factors are not consecutive (the solver then
/// uses the general path).
#[inline(always)]
pub(crate) fn tensor_factors<const D: usize, const K: usize>(
    grid: &RegularGrid<D>,
    position: &SVector<f64, D>,
    axes: &[AxisFactors<K>; D],
) -> Option<TensorFactors<D>> {
    let strides = grid.node_strides();
    let mut f = TensorFactors {
        first_id: 0,
        strides,
        first: [0; D],
        len: [0; D],
        value: [[0.0; 3]; D],
        slope: [[0.0; 3]; D],
        first_offset: [0.0; D],
        spacing: [0.0; D],
    };
    for (i, a) in axes.iter().enumerate() {
        if a.len == 0 || a.len > 3 || (0..a.len).any(|c| a.index[c] != a.index[0] + c) {
            return None;
        }
        f.first[i] = a.index[0];
        f.len[i] = a.len;
        f.value[i][..a.len].copy_from_slice(&a.value[..a.len]);
        f.slope[i][..a.len].copy_from_slice(&a.slope[..a.len]);
        f.spacing[i] = grid.spacing()[i];
        f.first_offset[i] = grid.origin()[i] + a.index[0] as f64 * f.spacing[i] - position[i];
        f.first_id += a.index[0] * strides[i];
    }
    Some(f)
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
    visit_product(grid, axes, |id, value, gradient| {
        out.push(id, value, *gradient)
    })
}

/// Calls `visit(node, value, gradient)` for every product of the per-axis
/// factors whose value or gradient is non-zero, the first axis running
/// fastest (the order of a lexicographic loop).
///
/// The node indices are checked once per axis and turned into id offsets,
/// so the loops do no bounds checking, no division and no allocation.
// The loops index several parallel arrays (values, slopes, offsets) by
// the same factor number.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
pub(crate) fn visit_product<const D: usize, const K: usize>(
    grid: &RegularGrid<D>,
    axes: &[AxisFactors<K>; D],
    mut visit: impl FnMut(usize, f64, &SVector<f64, D>),
) -> Result<(), BasisError> {
    if axes.iter().any(|a| a.len == 0) {
        return Ok(());
    }
    let nodes = grid.nodes_per_axis();
    let strides = grid.node_strides();
    let mut offset = [[0usize; K]; D];
    for i in 0..D {
        for c in 0..axes[i].len {
            let j = axes[i].index[c];
            if j >= nodes[i] {
                let mut index = [0; D];
                index[i] = j;
                // Produces the grid's own out-of-range error.
                grid.node_id(index)?;
            }
            offset[i][c] = j * strides[i];
        }
    }
    // Nested loops for the planar and spatial cases (the first axis
    // innermost), with the products associated as in the counter loop so
    // that every path gives the same bits.
    let mut emit = |id: usize, value: f64, gradient: SVector<f64, D>| {
        if value != 0.0 || gradient.iter().any(|&g| g != 0.0) {
            visit(id, value, &gradient);
        }
    };
    if D == 3 {
        let (a0, a1, a2) = (&axes[0], &axes[1], &axes[2]);
        for c in 0..a2.len {
            let (v2, s2, o2) = (a2.value[c], a2.slope[c], offset[2][c]);
            for b in 0..a1.len {
                let (v1, s1, o1) = (a1.value[b], a1.slope[b], offset[1][b] + o2);
                for a in 0..a0.len {
                    let (v0, s0) = (a0.value[a], a0.slope[a]);
                    let p01 = v0 * v1;
                    let mut g = SVector::<f64, D>::zeros();
                    g[0] = s0 * v1 * v2;
                    g[1] = v0 * s1 * v2;
                    g[2] = p01 * s2;
                    emit(offset[0][a] + o1, p01 * v2, g);
                }
            }
        }
        Ok(())
    } else if D == 2 {
        let (a0, a1) = (&axes[0], &axes[1]);
        for b in 0..a1.len {
            let (v1, s1, o1) = (a1.value[b], a1.slope[b], offset[1][b]);
            for a in 0..a0.len {
                let (v0, s0) = (a0.value[a], a0.slope[a]);
                let mut g = SVector::<f64, D>::zeros();
                g[0] = s0 * v1;
                g[1] = v0 * s1;
                emit(offset[0][a] + o1, v0 * v1, g);
            }
        }
        Ok(())
    } else {
        visit_product_counter(axes, &offset, visit)
    }
}

/// The same product by a counter loop, for any dimension.
fn visit_product_counter<const D: usize, const K: usize>(
    axes: &[AxisFactors<K>; D],
    offset: &[[usize; K]; D],
    mut visit: impl FnMut(usize, f64, &SVector<f64, D>),
) -> Result<(), BasisError> {
    let mut counter = [0usize; D];
    loop {
        let mut id = 0;
        let mut value = 1.0;
        for i in 0..D {
            id += offset[i][counter[i]];
            value *= axes[i].value[counter[i]];
        }
        let mut gradient = SVector::<f64, D>::zeros();
        for j in 0..D {
            let mut g = axes[j].slope[counter[j]];
            for i in 0..D {
                if i != j {
                    g *= axes[i].value[counter[i]];
                }
            }
            gradient[j] = g;
        }
        if value != 0.0 || gradient.iter().any(|&g| g != 0.0) {
            visit(id, value, &gradient);
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
