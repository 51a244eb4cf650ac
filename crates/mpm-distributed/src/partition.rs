//! Who owns what on N ranks: the partition of a mesh's *units* — F-patch
//! patches on a simplex mesh (Wang et al. 2021 §4.3: "the partition is
//! constrained so that no patch is split across processes"), single
//! elements otherwise — by METIS's multilevel k-way partitioning of the
//! units' dual graph (two units adjacent when they share a node), each
//! unit weighing its work: its material points (transfers, constitutive
//! updates) plus its nodes (grid update, assembly rows). One combined
//! weight rather than two constraints: METIS's k-way balance tolerance
//! (1.03) then holds for it, which two constraints traded against each
//! other do not guarantee.
//!
//! From it, deterministically on every rank (the mesh is replicated):
//! the rank of every element and of every material point (its element's;
//! a point keeps its global id when it migrates), the owner of every node
//! (the lowest rank among the units touching it), and each rank's
//! [`HaloPlan`]: for every neighbour, the nodes whose sums it sends to
//! their owner (reverse exchange) and receives back (forward exchange),
//! in ascending global order on both sides, so one message per neighbour
//! carries them all.

use mpm_solver::SolverError;
use mpm_solver::ranks::Decomposition;
use thiserror::Error;

/// Why a partition could not be made.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PartitionError {
    /// No rank, or more ranks than units.
    #[error("cannot partition {units} units over {ranks} ranks (need 1 <= ranks <= units)")]
    Ranks {
        /// Units of the mesh.
        units: usize,
        /// Ranks asked for.
        ranks: usize,
    },
    /// The mesh description is inconsistent.
    #[error("invalid mesh for partitioning: {0}")]
    Mesh(String),
    /// METIS failed.
    #[error("METIS failed: {0}")]
    Metis(String),
}

/// The mesh as the partitioner sees it.
#[derive(Debug, Clone, Copy)]
pub struct MeshView<'a> {
    /// Nodes of the mesh.
    pub nodes: usize,
    /// Nodes per element (D + 1 for simplices, 2^D for grid cells).
    pub nodes_per_element: usize,
    /// Element `e`'s nodes at `connectivity[e * nodes_per_element..]`.
    pub connectivity: &'a [usize],
    /// The unit (patch) of every element, `None`: every element its own
    /// unit.
    pub unit_of_element: Option<&'a [usize]>,
    /// The element holding every material point.
    pub element_of_point: &'a [usize],
}

impl MeshView<'_> {
    fn elements(&self) -> usize {
        self.connectivity.len() / self.nodes_per_element.max(1)
    }

    fn element_nodes(&self, e: usize) -> &[usize] {
        &self.connectivity[e * self.nodes_per_element..(e + 1) * self.nodes_per_element]
    }

    fn unit(&self, e: usize) -> usize {
        self.unit_of_element.map_or(e, |u| u[e])
    }
}

/// The ownership of every unit, element, point and node over `ranks`.
#[derive(Debug, Clone, PartialEq)]
pub struct Partition {
    /// Number of ranks.
    pub ranks: usize,
    /// Rank of every unit (patch or element).
    pub rank_of_unit: Vec<usize>,
    /// Rank of every element (its unit's).
    pub rank_of_element: Vec<usize>,
    /// Rank of every material point (its element's).
    pub rank_of_point: Vec<usize>,
    /// Owner of every node: the lowest rank among the units touching it;
    /// `None` for a node no element uses.
    pub owner_of_node: Vec<Option<usize>>,
    /// METIS's edge cut (dual-graph edges between ranks).
    pub edge_cut: usize,
}

/// One rank's halo: per neighbour rank, the nodes whose nodal sums go to
/// their owner there (`send`, nodes this rank touches and the neighbour
/// owns) and the nodes whose contributions arrive from it (`receive`,
/// nodes this rank owns and the neighbour touches), each ascending.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct HaloPlan {
    /// `(neighbour, nodes)` this rank sends to their owner, by neighbour.
    pub send: Vec<(usize, Vec<usize>)>,
    /// `(neighbour, nodes)` this rank owns and receives sums for.
    pub receive: Vec<(usize, Vec<usize>)>,
}

/// Partitions `mesh` over `ranks` (module docs).
///
/// # Errors
/// [`PartitionError`] for no rank or more ranks than units, an
/// inconsistent mesh, or METIS's failure.
pub fn partition(mesh: &MeshView<'_>, ranks: usize) -> Result<Partition, PartitionError> {
    let units = units(mesh, ranks)?;
    let weights = unit_weights(mesh, units);
    partition_with(mesh, units, &weights, ranks)
}

/// Partitions `mesh` over `ranks` with the given `weights` of its units
/// instead of their points and nodes: e.g. during an explicit run the
/// points in every cell plus one (the work that moves with the points;
/// the one keeps an empty cell placeable). Its points are those of
/// `mesh.element_of_point`.
///
/// # Errors
/// As [`partition`], and a weight per unit missing.
pub fn partition_weighted(
    mesh: &MeshView<'_>,
    weights: &[usize],
    ranks: usize,
) -> Result<Partition, PartitionError> {
    let units = units(mesh, ranks)?;
    if weights.len() != units {
        return Err(PartitionError::Mesh(format!(
            "{} weights for {units} units",
            weights.len()
        )));
    }
    let weights: Vec<metis::Idx> = (weights.iter())
        .map(|&w| metis::Idx::try_from(w).unwrap_or(metis::Idx::MAX))
        .collect();
    partition_with(mesh, units, &weights, ranks)
}

/// The number of units of a valid `mesh` that `ranks` ranks can share.
fn units(mesh: &MeshView<'_>, ranks: usize) -> Result<usize, PartitionError> {
    check(mesh)?;
    let units = mesh
        .unit_of_element
        .map_or(mesh.elements(), |u| u.iter().max().map_or(0, |m| m + 1));
    if ranks == 0 || ranks > units {
        return Err(PartitionError::Ranks { units, ranks });
    }
    Ok(units)
}

fn partition_with(
    mesh: &MeshView<'_>,
    units: usize,
    weights: &[metis::Idx],
    ranks: usize,
) -> Result<Partition, PartitionError> {
    let (xadj, adjncy) = dual_graph(mesh, units);
    let (rank_of_unit, edge_cut) = if ranks == 1 {
        (vec![0; units], 0)
    } else {
        metis_kway(&xadj, &adjncy, weights, ranks)?
    };
    let rank_of_element: Vec<usize> = (0..mesh.elements())
        .map(|e| rank_of_unit[mesh.unit(e)])
        .collect();
    let rank_of_point = mesh
        .element_of_point
        .iter()
        .map(|&e| rank_of_element[e])
        .collect();
    let mut owner_of_node = vec![None; mesh.nodes];
    for (e, &r) in rank_of_element.iter().enumerate() {
        for &n in mesh.element_nodes(e) {
            let o: &mut Option<usize> = &mut owner_of_node[n];
            *o = Some(o.map_or(r, |o| o.min(r)));
        }
    }
    Ok(Partition {
        ranks,
        rank_of_unit,
        rank_of_element,
        rank_of_point,
        owner_of_node,
        edge_cut,
    })
}

fn check(mesh: &MeshView<'_>) -> Result<(), PartitionError> {
    let bad = |m: String| Err(PartitionError::Mesh(m));
    if mesh.nodes_per_element == 0
        || !mesh
            .connectivity
            .len()
            .is_multiple_of(mesh.nodes_per_element)
    {
        return bad("the connectivity is not a whole number of elements".into());
    }
    if let Some(n) = mesh.connectivity.iter().find(|&&n| n >= mesh.nodes) {
        return bad(format!(
            "node {n} of the connectivity is not below {}",
            mesh.nodes
        ));
    }
    let elements = mesh.elements();
    if let Some(u) = mesh.unit_of_element {
        if u.len() != elements {
            return bad(format!("{} units for {elements} elements", u.len()));
        }
        let count = u.iter().max().map_or(0, |m| m + 1);
        let mut used = vec![false; count];
        u.iter().for_each(|&i| used[i] = true);
        if let Some(i) = used.iter().position(|x| !x) {
            return bad(format!("unit {i} has no element"));
        }
    }
    if let Some(p) = mesh.element_of_point.iter().position(|&e| e >= elements) {
        return bad(format!("point {p} lies in no element of the mesh"));
    }
    Ok(())
}

/// The units' dual graph in METIS's CSR form: units sharing a node.
fn dual_graph(mesh: &MeshView<'_>, units: usize) -> (Vec<metis::Idx>, Vec<metis::Idx>) {
    let mut units_of_node: Vec<Vec<usize>> = vec![Vec::new(); mesh.nodes];
    for e in 0..mesh.elements() {
        for &n in mesh.element_nodes(e) {
            units_of_node[n].push(mesh.unit(e));
        }
    }
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); units];
    for touching in &mut units_of_node {
        touching.sort_unstable();
        touching.dedup();
        for &a in touching.iter() {
            neighbours[a].extend(touching.iter().copied().filter(|&b| b != a));
        }
    }
    let mut xadj = Vec::with_capacity(units + 1);
    let mut adjncy = Vec::new();
    xadj.push(0);
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
        adjncy.extend(list.iter().map(|&u| u as metis::Idx));
        xadj.push(adjncy.len() as metis::Idx);
    }
    (xadj, adjncy)
}

/// The weight of every unit: its material points plus its nodes.
pub fn unit_weights(mesh: &MeshView<'_>, units: usize) -> Vec<metis::Idx> {
    let mut points = vec![0 as metis::Idx; units];
    for &e in mesh.element_of_point {
        points[mesh.unit(e)] += 1;
    }
    let mut nodes_of_unit: Vec<Vec<usize>> = vec![Vec::new(); units];
    for e in 0..mesh.elements() {
        nodes_of_unit[mesh.unit(e)].extend_from_slice(mesh.element_nodes(e));
    }
    nodes_of_unit
        .iter_mut()
        .zip(points)
        .map(|(nodes, p)| {
            nodes.sort_unstable();
            nodes.dedup();
            p + nodes.len() as metis::Idx
        })
        .collect()
}

fn metis_kway(
    xadj: &[metis::Idx],
    adjncy: &[metis::Idx],
    weights: &[metis::Idx],
    ranks: usize,
) -> Result<(Vec<usize>, usize), PartitionError> {
    let metis_error = |e: &dyn std::fmt::Display| PartitionError::Metis(e.to_string());
    // METIS 5 keeps process-wide state (its error handling's jump buffers,
    // its memory accounting): two threads partitioning at once hung here
    // (four thread ranks repartitioning together). One call at a time.
    static METIS: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one_at_a_time = METIS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let nparts = metis::Idx::try_from(ranks).map_err(|e| metis_error(&e))?;
    let mut part = vec![0 as metis::Idx; xadj.len() - 1];
    let cut = metis::Graph::new(1, nparts, xadj, adjncy)
        .map_err(|e| metis_error(&e))?
        .set_vwgt(weights)
        .part_kway(&mut part)
        .map_err(|e| metis_error(&e))?;
    let ranks_of_units = part
        .into_iter()
        .map(|p| usize::try_from(p).map_err(|e| metis_error(&e)))
        .collect::<Result<_, _>>()?;
    Ok((ranks_of_units, usize::try_from(cut).unwrap_or(0)))
}

impl Partition {
    /// Rank `rank`'s [`Decomposition`] for the explicit solver on several
    /// ranks (`mpm_solver::ranks`): the elements' ranks, the nodes' owners
    /// (as here) and the neighbours within `reach` rings of its elements
    /// (1 for linear shape functions, 2 for GIMP and quadratic B-splines).
    ///
    /// # Errors
    /// A mesh that does not fit the partition.
    pub fn decomposition(
        &self,
        mesh: &MeshView<'_>,
        rank: usize,
        reach: usize,
    ) -> Result<Decomposition, SolverError> {
        Decomposition::from_cells(
            rank,
            self.rank_of_element.clone(),
            mesh.connectivity,
            mesh.nodes_per_element,
            mesh.nodes,
            reach,
        )
    }

    /// Rank `rank`'s halo plan on `mesh` (module docs).
    pub fn halo_plan(&self, mesh: &MeshView<'_>, rank: usize) -> HaloPlan {
        let touches = self.ranks_touching_nodes(mesh);
        let mut send: Vec<Vec<usize>> = vec![Vec::new(); self.ranks];
        let mut receive: Vec<Vec<usize>> = vec![Vec::new(); self.ranks];
        for (node, ranks) in touches.iter().enumerate() {
            let Some(owner) = self.owner_of_node[node] else {
                continue;
            };
            if owner != rank && ranks.contains(&rank) {
                send[owner].push(node);
            }
            if owner == rank {
                for &r in ranks.iter().filter(|&&r| r != rank) {
                    receive[r].push(node);
                }
            }
        }
        let nonempty = |lists: Vec<Vec<usize>>| {
            lists
                .into_iter()
                .enumerate()
                .filter(|(_, l)| !l.is_empty())
                .collect()
        };
        HaloPlan {
            send: nonempty(send),
            receive: nonempty(receive),
        }
    }

    /// The ranks whose elements touch each node, ascending.
    fn ranks_touching_nodes(&self, mesh: &MeshView<'_>) -> Vec<Vec<usize>> {
        let mut touching: Vec<Vec<usize>> = vec![Vec::new(); mesh.nodes];
        for (e, &r) in self.rank_of_element.iter().enumerate() {
            for &n in mesh.element_nodes(e) {
                if !touching[n].contains(&r) {
                    touching[n].push(r);
                }
            }
        }
        touching.iter_mut().for_each(|t| t.sort_unstable());
        touching
    }
}
