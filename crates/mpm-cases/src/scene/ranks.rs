//! The deal of a scene's material points over ranks: METIS on the mesh's
//! dual graph ([`mpm_distributed::partition`]), each point on the rank of
//! the element holding it; with F-patch on a simplex mesh the units are
//! the patches, so no patch is split (Wang et al. 2021 §4.3). The mesh is
//! replicated and METIS deterministic, so every rank computes the same
//! deal. An explicit run's points follow their cells as they move, and
//! its cells are dealt anew when the points per rank drift apart
//! ([`Balance`]).

use std::sync::Arc;

use mpm_dispatch::on_ranks::{Balance, RankRun};
use mpm_distributed::partition::{MeshView, partition, partition_weighted};
use mpm_solver::SolverError;
use mpm_solver::ranks::Ranks;

use crate::CasesError;
use crate::scene::Problem;
use crate::scene::build::SceneMesh;
use crate::variant::LockingKind;

/// The mesh as plain connectivity and the element of every point.
struct Cells {
    nodes: usize,
    nodes_per_element: usize,
    connectivity: Vec<usize>,
    element_of_point: Vec<usize>,
}

fn invalid(e: &dyn std::fmt::Display) -> SolverError {
    SolverError::InvalidInput(e.to_string())
}

impl Cells {
    fn of<const D: usize>(problem: &Problem<D>) -> Result<Self, SolverError> {
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
        Ok(Self {
            nodes: problem.mesh.node_count(),
            nodes_per_element,
            connectivity,
            element_of_point,
        })
    }

    fn view<'a>(&'a self, patches: Option<&'a [usize]>) -> MeshView<'a> {
        MeshView {
            nodes: self.nodes,
            nodes_per_element: self.nodes_per_element,
            connectivity: &self.connectivity,
            unit_of_element: patches,
            element_of_point: &self.element_of_point,
        }
    }
}

/// The run of `problem` on `ranks`: the rank of every point and cell,
/// and for an explicit run the new deals of its cells as its points move
/// (its `rebalance_every` and `rebalance_threshold`). An implicit run's deal is
/// METIS's over elements (whole patches under F-patch) weighed by their
/// points and nodes (the assembly's work); an explicit run's is from the
/// start the one its new deals make, weighed by the points.
///
/// # Errors
/// A point outside the mesh, more ranks than elements (or patches), or
/// METIS's failure.
pub fn rank_run<const D: usize>(
    problem: &Problem<D>,
    ranks: Arc<dyn Ranks>,
) -> Result<RankRun, CasesError> {
    let cells = Cells::of(problem)?;
    let element_of_point = cells.element_of_point.clone();
    let (rank_of_cell, balance) = if let Some(setup) = &problem.explicit {
        let (every, threshold) = (setup.rebalance_every, setup.rebalance_threshold);
        explicit_deal(cells, ranks.size(), every, threshold)?
    } else {
        (implicit_deal(problem, &cells, ranks.size())?, None)
    };
    let rank_of_point = element_of_point.iter().map(|&e| rank_of_cell[e]).collect();
    Ok(RankRun {
        ranks,
        rank_of_point,
        rank_of_cell,
        balance,
        pieces: None,
    })
}

/// METIS's deal of the elements, or of the patches under F-patch.
fn implicit_deal<const D: usize>(
    problem: &Problem<D>,
    cells: &Cells,
    ranks: usize,
) -> Result<Vec<usize>, SolverError> {
    let patches = (problem.variant.locking == LockingKind::FPatch)
        .then_some(problem.patch_of_element.as_deref())
        .flatten();
    let parts = partition(&cells.view(patches), ranks).map_err(|e| invalid(&e))?;
    Ok(parts.rank_of_element)
}

/// The first deal of an explicit run and its new deals.
fn explicit_deal(
    cells: Cells,
    ranks: usize,
    every: usize,
    threshold: f64,
) -> Result<(Vec<usize>, Option<Balance>), SolverError> {
    let mut loads = vec![0.0; cells.connectivity.len() / cells.nodes_per_element];
    for &e in &cells.element_of_point {
        loads[e] += 1.0;
    }
    let deal = repartition(cells, ranks);
    let rank_of_cell = deal(&loads)?;
    let balance = Balance {
        every,
        threshold,
        repartition: deal,
    };
    Ok((rank_of_cell, Some(balance)))
}

/// The weight of a point against an empty cell's 1 in an explicit run's
/// deal: a step's work is the points' (transfers, stress updates); an
/// empty cell costs next to nothing but must weigh something to be
/// placed. With one each, the many empty cells of a grid around a body
/// took half the balance, and the points per rank differed by half.
const POINT_WEIGHT: usize = 64;

/// A new deal of the cells over `ranks` from the points in every cell:
/// METIS weighing each cell by [`POINT_WEIGHT`] per point plus one.
fn repartition(cells: Cells, ranks: usize) -> Arc<mpm_dispatch::on_ranks::Repartition> {
    Arc::new(move |loads: &[f64]| {
        let weights: Vec<usize> = (loads.iter())
            .map(|&n| POINT_WEIGHT * n as usize + 1)
            .collect();
        let view = MeshView {
            element_of_point: &[],
            ..cells.view(None)
        };
        let parts = partition_weighted(&view, &weights, ranks).map_err(|e| invalid(&e))?;
        Ok(parts.rank_of_element)
    })
}
