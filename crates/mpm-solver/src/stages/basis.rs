//! Basis evaluation: the values $S_{vp}$ and gradients
//! $\partial S_{vp}/\partial\tilde X$ of every material point at the start
//! of a load step (Coombs et al. 2020 eqs. 8, 21), into the fixed-stride
//! slots of a [`StepSystem`].

use mpm_basis::{BasisFunction, Stencil};
use nalgebra::SVector;

use crate::error::SolverError;
use crate::mesh::NodalMesh;
use crate::par::{self, Rows};
use crate::stages::system::StepSystem;

/// Evaluates `basis` on `mesh` at every point (`position`, `domain`) into
/// `sys` (stencils in mesh node numbering; [`StepSystem::number_nodes`]
/// renumbers them). `hints` holds, per point, the cell where its location
/// starts (the parent cell of the last step; walking on unstructured
/// meshes, Wang et al. 2021 Algorithm 1), `usize::MAX` when unknown; it is
/// resized to the number of points and updated. No allocation per point:
/// each part of the parallel loop ([`crate::par`]) reuses one stencil
/// buffer.
///
/// # Errors
/// [`SolverError::Basis`] naming the lowest failing point (one outside the
/// mesh, a domain leaving the grid, a basis returning too many nodes).
pub fn evaluate<const D: usize, B>(
    basis: &B,
    mesh: &B::Mesh,
    position: &[SVector<f64, D>],
    domain: &[B::Domain],
    hints: &mut Vec<usize>,
    sys: &mut StepSystem<D>,
) -> Result<(), SolverError>
where
    B: BasisFunction<D>,
    B::Mesh: NodalMesh<D>,
{
    let n = position.len();
    let stride = B::MAX_NODES;
    sys.stride = stride;
    sys.nodes.clear();
    sys.nodes.resize(n * stride, 0);
    sys.values.clear();
    sys.values.resize(n * stride, 0.0);
    sys.grads.clear();
    sys.grads.resize(n * stride, SVector::zeros());
    sys.counts.clear();
    sys.counts.resize(n, 0);
    let node_count = mesh.node_count();
    hints.resize(n, usize::MAX);
    let data = (
        Rows::new(&mut sys.nodes, stride),
        Rows::new(&mut sys.values, stride),
        Rows::new(&mut sys.grads, stride),
        &mut sys.counts[..],
        &mut hints[..],
    );
    let failure = par::first(data, 1, &|start,
                                        (
        mut nodes,
        mut values,
        mut grads,
        counts,
        hints,
    )| {
        let mut stencil = Stencil::<D>::with_capacity(stride);
        for k in 0..counts.len() {
            let p = start + k;
            let x = &position[p];
            let fail = |reason| SolverError::Basis {
                point: p,
                position: x.iter().copied().collect(),
                reason,
            };
            if let Err(e) = basis.evaluate_hinted(mesh, x, &domain[p], &mut hints[k], &mut stencil)
            {
                return Some(fail(crate::error::BasisFailure::Basis(e)));
            }
            let m = stencil.nodes.len();
            if m > stride || stencil.nodes.iter().any(|&v| v >= node_count) {
                return Some(fail(crate::error::BasisFailure::Stencil {
                    nodes: m,
                    max: stride,
                }));
            }
            let (nodes, values, grads) = (nodes.row(k), values.row(k), grads.row(k));
            for a in 0..m {
                nodes[a] = stencil.nodes[a] as u32;
                values[a] = stencil.values[a];
                grads[a] = stencil.gradients[a];
            }
            counts[k] = m as u32;
        }
        None
    });
    failure.map_or(Ok(()), Err)
}
