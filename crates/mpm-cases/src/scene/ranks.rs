//! The deal of a scene's material points over ranks: METIS on the mesh's
//! dual graph ([`mpm_distributed::partition`]), each point on the rank of
//! the element holding it; with F-patch on a simplex mesh the units are
//! the patches, so no patch is split (Wang et al. 2021 §4.3). The mesh is
//! replicated and METIS deterministic, so every rank computes the same
//! deal.

use mpm_distributed::partition::{MeshView, partition};
use mpm_solver::SolverError;

use crate::CasesError;
use crate::scene::Problem;
use crate::scene::build::SceneMesh;
use crate::variant::LockingKind;

/// The rank of every material point of `problem` on `ranks` ranks.
///
/// # Errors
/// A point outside the mesh, more ranks than elements (or patches), or
/// METIS's failure.
pub fn rank_of_point<const D: usize>(
    problem: &Problem<D>,
    ranks: usize,
) -> Result<Vec<usize>, CasesError> {
    let invalid = |e: &dyn std::fmt::Display| SolverError::InvalidInput(e.to_string());
    let (connectivity, nodes_per_element, element_of_point) = match &problem.mesh {
        SceneMesh::Grid(grid) => {
            let mut connectivity = Vec::with_capacity(grid.cell_count() << D);
            for c in 0..grid.cell_count() {
                let cell = grid.cell_index(c).map_err(|e| invalid(&e))?;
                connectivity.extend(grid.cell_nodes(cell).map_err(|e| invalid(&e))?);
            }
            let cells = (problem.position.iter())
                .map(|x| grid.cell_id(grid.cell_containing(x)?))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| invalid(&e))?;
            (connectivity, 1 << D, cells)
        }
        SceneMesh::Simplex(mesh) => {
            let elements = (problem.position.iter())
                .map(|x| mesh.locate(x, None).map(|l| l.element))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| invalid(&e))?;
            (mesh.connectivity().to_vec(), D + 1, elements)
        }
    };
    let patches = (problem.variant.locking == LockingKind::FPatch)
        .then_some(problem.patch_of_element.as_deref())
        .flatten();
    let view = MeshView {
        nodes: problem.mesh.node_count(),
        nodes_per_element,
        connectivity: &connectivity,
        unit_of_element: patches,
        element_of_point: &element_of_point,
    };
    let parts = partition(&view, ranks).map_err(|e| invalid(&e))?;
    Ok(parts.rank_of_point)
}
