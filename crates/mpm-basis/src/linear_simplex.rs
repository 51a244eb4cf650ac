//! Standard MPM on simplex meshes: the linear shape functions of the
//! triangle or tetrahedron containing the point.

use mpm_mesh::SimplexMesh;
use nalgebra::SVector;

use crate::{BasisError, BasisFunction, Stencil};

/// The standard material point method basis on a mesh of linear triangles
/// (2D) or tetrahedra (3D), as in Wang et al. (2021) §2.3: $S_{vp} =
/// N_v(\mathbf x_p)$ with the shape functions of eq. (15),
///
/// $$N_1 = 1 - \sum_{i} \xi_i, \qquad N_{k+1} = \xi_k, \qquad
/// \boldsymbol\xi = \mathbf T^{-1}(\mathbf x_p - \mathbf x_1) \quad
/// \text{(eq. 13)},$$
///
/// and the gradients $\nabla N_v$, constant per element (precomputed by
/// [`SimplexMesh`]). The $D + 1$ nodes of the containing element are always
/// written, also those whose value is zero (point on a face), because their
/// gradient is not. $\nabla N_v$ jumps across faces; on a shared face the
/// gradient is that of the element the location returns (see
/// [`SimplexMesh::locate`] for the tie rule).
///
/// The containing element is found by [`SimplexMesh::locate`]: by walking
/// from the hint of [`BasisFunction::evaluate_hinted`] (Algorithm 1, the
/// point's previous parent element), or from the bucket grid without one.
///
/// Domain: `()`. Errors: [`mpm_mesh::MeshError::PointOutsideMesh`] (wrapped
/// in [`BasisError::Mesh`]) for a point in no element, and
/// [`mpm_mesh::MeshError::ElementIdOutOfRange`] for a hint that is neither
/// an element nor `usize::MAX`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinearSimplex;

impl<const D: usize> BasisFunction<D> for LinearSimplex {
    type Mesh = SimplexMesh<D>;
    type Domain = ();
    const MAX_NODES: usize = D + 1;

    fn initial_domain(_: &SVector<f64, D>, _: &SVector<f64, D>) {}

    fn evaluate(
        &self,
        mesh: &SimplexMesh<D>,
        position: &SVector<f64, D>,
        domain: &(),
        out: &mut Stencil<D>,
    ) -> Result<(), BasisError> {
        let mut no_hint = usize::MAX;
        self.evaluate_hinted(mesh, position, domain, &mut no_hint, out)
    }

    fn evaluate_hinted(
        &self,
        mesh: &SimplexMesh<D>,
        position: &SVector<f64, D>,
        _domain: &(),
        hint: &mut usize,
        out: &mut Stencil<D>,
    ) -> Result<(), BasisError> {
        out.clear();
        let start = (*hint != usize::MAX).then_some(*hint);
        let location = mesh.locate(position, start)?;
        *hint = location.element;
        let nodes = mesh.element_nodes(location.element);
        let gradients = mesh.shape_gradients(location.element);
        for (k, (&node, gradient)) in nodes.iter().zip(gradients).enumerate() {
            out.push(node, location.barycentric(k), *gradient);
        }
        Ok(())
    }
}
