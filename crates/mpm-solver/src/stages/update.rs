//! Grid-to-point updates: a point's deformation-gradient increment from the
//! grid displacement (eq. 7), its displacement (eq. 31), the grid
//! displacement at any point of the mesh (eq. 35), and the commit of a
//! converged step to positions, deformation, volumes (eqs. 5, 22) and
//! domains (the domain updater, §6.4).

use mpm_basis::Stencil;
use mpm_constitutive::Response;
use mpm_constitutive::tensor::embed;
use nalgebra::{Matrix3, SMatrix, SVector};

use crate::domain::{DomainContext, DomainError, DomainUpdater};
use crate::error::SolverError;
use crate::mesh::NodalMesh;
use crate::points::MaterialPoints;
use crate::stages::system::{NONE, StepSystem};

/// $\Delta F_p = \mathbf 1 + \sum_v \Delta u_v\otimes\nabla S_{vp}$ (eq. 7)
/// of point `p` from the active-dof increment `du`, embedded in 3D (plane
/// strain: $\Delta F_{33} = 1$).
#[inline]
pub fn deformation_increment<const D: usize>(
    sys: &StepSystem<D>,
    du: &[f64],
    p: usize,
) -> Matrix3<f64> {
    let mut g = SMatrix::<f64, D, D>::identity();
    for s in sys.slots(p) {
        let v = sys.nodes[s] as usize;
        for i in 0..D {
            for j in 0..D {
                g[(i, j)] += du[D * v + i] * sys.grads[s][j];
            }
        }
    }
    embed(&g)
}

/// $\Delta u_p = \sum_v S_{vp}\Delta u_v$ (eq. 31) of point `p`.
#[inline]
pub fn point_displacement<const D: usize>(
    sys: &StepSystem<D>,
    du: &[f64],
    p: usize,
) -> SVector<f64, D> {
    let mut u = SVector::<f64, D>::zeros();
    for s in sys.slots(p) {
        let v = sys.nodes[s] as usize;
        for i in 0..D {
            u[i] += sys.values[s] * du[D * v + i];
        }
    }
    u
}

/// $\sum_v N_v(\mathbf x)\,\mathbf u_v$ with the background mesh's own
/// linear shape functions at `x`: the interpolation both solvers use to
/// convect domain corners and mid-points (eq. 35). `nodal(v)` is the
/// value $\mathbf u_v$ of node `v`, or `None` for a node without one this
/// step; such a node may appear only with $|N_v(\mathbf x)| \le$
/// `negligible` (then it adds nothing).
///
/// # Errors
/// [`DomainError::Mesh`] when `x` is outside the mesh,
/// [`DomainError::InactiveNode`] for a node without a value and a larger
/// weight.
#[inline]
pub fn interpolate_nodal<const D: usize, M: NodalMesh<D>>(
    mesh: &M,
    x: &SVector<f64, D>,
    stencil: &mut Stencil<D>,
    negligible: f64,
    mut nodal: impl FnMut(usize) -> Option<SVector<f64, D>>,
) -> Result<SVector<f64, D>, DomainError> {
    let at = || x.as_slice().to_vec();
    mesh.shape_functions(x, stencil)
        .map_err(|source| DomainError::Mesh { at: at(), source })?;
    let mut u = SVector::<f64, D>::zeros();
    for (&node, &value) in stencil.nodes.iter().zip(&stencil.values) {
        match nodal(node) {
            Some(u_v) => u += u_v * value,
            None if value.abs() <= negligible => {}
            None => return Err(DomainError::InactiveNode { node, at: at() }),
        }
    }
    Ok(u)
}

/// The grid displacement increment interpolated at `x` (a point of the
/// configuration at the start of the step) with the background mesh's own
/// linear shape functions, $\Delta\mathbf u(\mathbf x) = \sum_v
/// N_v(\mathbf x)\Delta\mathbf u_v$ (eq. 35, [`interpolate_nodal`]); used by
/// domain updates that convect corners or mid-points. Nodes outside the
/// step's active set may appear only with a zero value (a corner on the
/// face of a cell the domain does not enter).
pub fn displacement_at<const D: usize, M: NodalMesh<D>>(
    mesh: &M,
    sys: &StepSystem<D>,
    du: &[f64],
    x: &SVector<f64, D>,
    stencil: &mut Stencil<D>,
) -> Result<SVector<f64, D>, DomainError> {
    interpolate_nodal(mesh, x, stencil, 0.0, |node| {
        let v = sys.active_of_mesh.get(node).copied().unwrap_or(NONE);
        (v != NONE).then(|| SVector::from_fn(|i, _| du[D * v as usize + i]))
    })
}

/// Commits a converged step: for every point with a response, the
/// position (eq. 31), total displacement, $F$, $b^e$, history, Cauchy
/// stress, the domain (`updater`, reading the grid displacement through
/// [`displacement_at`] on `mesh`) and the volume (eqs. 5/22, or the
/// domain's, [`DomainUpdater::volume`]).
///
/// # Errors
/// [`SolverError::DomainUpdate`] naming the first point whose domain
/// cannot be updated; the points before it are committed.
pub fn commit<const D: usize, H, Dom, U, M>(
    sys: &StepSystem<D>,
    du: &[f64],
    mesh: &M,
    updater: &U,
    responses: &[Option<Response<H>>],
    points: &mut MaterialPoints<D, H, Dom>,
) -> Result<(), SolverError>
where
    H: Copy,
    Dom: Copy,
    U: DomainUpdater<D, Dom>,
    M: NodalMesh<D>,
{
    let stencil = std::cell::RefCell::new(Stencil::<D>::with_capacity(1 << D));
    for (p, r) in responses.iter().enumerate().take(points.position.len()) {
        let Some(r) = r.as_ref() else {
            continue;
        };
        let previous = points.position[p];
        let du_p = point_displacement(sys, du, p);
        let position = previous + du_p;
        let ctx = DomainContext {
            initial: &points.domain0[p],
            previous: &points.domain[p],
            f: &r.f,
            delta_f: &r.delta_f,
            position_previous: &previous,
            position: &position,
        };
        let domain = updater
            .update(&ctx, |x| {
                displacement_at(mesh, sys, du, x, &mut stencil.borrow_mut())
            })
            .map_err(|reason| SolverError::DomainUpdate { point: p, reason })?;
        points.displacement[p] += du_p;
        points.position[p] = position;
        points.f[p] = r.f;
        points.be[p] = r.state.be;
        points.history[p] = r.state.history;
        points.sigma[p] = r.sigma;
        points.volume[p] = updater.volume(&domain, r.j * points.volume0[p]);
        points.domain[p] = domain;
    }
    Ok(())
}
