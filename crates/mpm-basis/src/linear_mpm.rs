//! Standard MPM: multilinear shape functions of the cell containing the
//! point.

use mpm_mesh::RegularGrid;
use nalgebra::SVector;

use crate::tensor::AxisFactors;
use crate::{BasisError, BasisFunction, Stencil};

/// The standard material point method basis: $S_{vp} = N_v(\mathbf x_p)$,
/// $\nabla S_{vp} = \nabla N_v(\mathbf x_p)$ with $N_v$ the bilinear (2D) /
/// trilinear (3D) finite element shape functions of the grid (Sulsky et al.
/// 1994; Coombs et al. 2020 §6.1: "the same as conventional finite element
/// analysis"). On a regular grid
///
/// $$N_v(\mathbf x) = \prod_{i<D} \hat N\!\left(\frac{x_i - X_{v,i}}{h_i}\right),
/// \qquad \hat N(r) = \max(0, 1 - |r|),$$
///
/// built per axis from the local coordinate $t_i\in[0, 1]$ of the point in
/// its cell $k$: factors $(1-t_i, -1/h_i)$ at node $k_i$ and $(t_i, 1/h_i)$
/// at node $k_i+1$.
///
/// The $2^D$ nodes of the containing cell are always written, also a node
/// whose value is zero (point on a face), because its gradient is not.
/// $\nabla N_v$ jumps across cell faces; on a face the gradient is the one
/// of the cell above (the [`RegularGrid`] location convention).
///
/// Domain: `()`. Errors: [`mpm_mesh::MeshError::PointOutsideGrid`] (wrapped
/// in [`BasisError::Mesh`]) for a point outside the grid.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinearMpm;

impl<const D: usize> BasisFunction<D> for LinearMpm {
    type Mesh = RegularGrid<D>;
    type Domain = ();
    const MAX_NODES: usize = 1 << D;

    fn initial_domain(_: &SVector<f64, D>, _: &SVector<f64, D>) {}

    crate::tensor::tensor_basis_methods!(|mesh, position| axis_factors(mesh, position));
}

/// The two 1D hat factors per axis of the point at `position`.
#[inline(always)]
fn axis_factors<const D: usize>(
    mesh: &RegularGrid<D>,
    position: &SVector<f64, D>,
) -> Result<[AxisFactors<2>; D], BasisError> {
    let location = mesh.locate(position)?;
    let mut axes = [AxisFactors::<2>::EMPTY; D];
    for (i, axis) in axes.iter_mut().enumerate() {
        let (k, t, h) = (location.cell[i], location.local[i], mesh.spacing()[i]);
        axis.push(k, 1.0 - t, -1.0 / h);
        axis.push(k + 1, t, 1.0 / h);
    }
    Ok(axes)
}
