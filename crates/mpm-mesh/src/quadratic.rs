//! Quadratic simplex meshes (six-node triangles, ten-node tetrahedra): the
//! parent meshes whose elements define the patches of the F-patch method
//! (Wang et al. 2021 §4.1).

use nalgebra::SVector;

use crate::simplex::{
    EDGES, check_dimension, check_element_nodes, check_nodes, edge_count, element_count,
    quadratic_node_count, signed_volume, swap_orientation,
};
use crate::{MeshError, MeshSets, NamedSets, SimplexMesh};

/// A mesh of six-node triangles (`D = 2`) or ten-node tetrahedra
/// (`D = 3`) with straight or curved edges.
///
/// Local node order is Gmsh's (reference manual, "Node ordering"; checked
/// against `gmsh.model.mesh.getElementProperties` of Gmsh 4.15): vertices
/// 0..=D, then node `D + 1 + k` on edge `k` of (0,1), (1,2), (2,0), and in
/// 3D (3,0), (3,2), (3,1). Every element is positively oriented (the
/// vertex simplex has $\det\mathbf T > 0$), and elements sharing an edge
/// share its mid-edge node.
#[derive(Debug, Clone, PartialEq)]
pub struct QuadraticMesh<const D: usize> {
    nodes: Vec<SVector<f64, D>>,
    connectivity: Vec<usize>,
    sets: MeshSets,
}

impl<const D: usize> QuadraticMesh<D> {
    /// Number of nodes per element, $(D+1)(D+2)/2$.
    pub const NODES_PER_ELEMENT: usize = quadratic_node_count(D);

    /// A mesh of `nodes` and the elements `connectivity` (flat,
    /// [`Self::NODES_PER_ELEMENT`] node ids per element in Gmsh order),
    /// every vertex simplex positively oriented.
    ///
    /// # Errors
    /// As [`SimplexMesh::new`] for the vertex simplices (the same variants,
    /// naming the element), and [`MeshError::InconsistentEdgeNode`] when
    /// two elements put different nodes on one edge.
    pub fn new(nodes: Vec<SVector<f64, D>>, connectivity: Vec<usize>) -> Result<Self, MeshError> {
        Self::build(nodes, connectivity, false)
    }

    /// As [`QuadraticMesh::new`], but negatively oriented elements are
    /// reoriented (vertices 1 and 2 swapped with their mid-edge nodes).
    ///
    /// # Errors
    /// As [`QuadraticMesh::new`], except [`MeshError::InvertedElement`].
    pub fn new_reoriented(
        nodes: Vec<SVector<f64, D>>,
        connectivity: Vec<usize>,
    ) -> Result<Self, MeshError> {
        Self::build(nodes, connectivity, true)
    }

    fn build(
        nodes: Vec<SVector<f64, D>>,
        mut connectivity: Vec<usize>,
        reorient: bool,
    ) -> Result<Self, MeshError> {
        check_dimension(D)?;
        let stride = Self::NODES_PER_ELEMENT;
        let count = element_count(connectivity.len(), stride)?;
        check_nodes(&nodes)?;
        for (element, ids) in connectivity.chunks_exact_mut(stride).enumerate() {
            check_element_nodes(element, ids, nodes.len())?;
            let volume = signed_volume(&nodes, element, &ids[..=D])?;
            if volume < 0.0 {
                if !reorient {
                    return Err(MeshError::InvertedElement { element, volume });
                }
                swap_orientation(D, ids);
            }
        }
        check_edge_nodes::<D>(&connectivity)?;
        Ok(Self {
            sets: MeshSets::new(nodes.len(), count),
            nodes,
            connectivity,
        })
    }

    /// The quadratic mesh of a linear one: its nodes followed by one new node
    /// at the midpoint of every edge (shared edges get one node, numbered in
    /// order of first appearance). Node sets carry over; a mid-edge node
    /// joins a set when both ends of its edge are in it. Element sets carry
    /// over unchanged.
    pub fn from_linear(mesh: &SimplexMesh<D>) -> Self {
        let mut nodes = mesh.nodes().to_vec();
        let edges = &EDGES[..edge_count(D)];
        let mut mid = std::collections::HashMap::new();
        let mut connectivity = Vec::with_capacity(mesh.element_count() * Self::NODES_PER_ELEMENT);
        let mut edge_ends = Vec::new();
        for element in 0..mesh.element_count() {
            let vertices = mesh.element_nodes(element);
            connectivity.extend_from_slice(vertices);
            for edge in edges {
                let (a, b) = (vertices[edge[0]], vertices[edge[1]]);
                let key = (a.min(b), a.max(b));
                let id = *mid.entry(key).or_insert_with(|| {
                    nodes.push((nodes[a] + nodes[b]) * 0.5);
                    edge_ends.push(key);
                    nodes.len() - 1
                });
                connectivity.push(id);
            }
        }
        let first_mid = mesh.node_count();
        let mut node_sets = NamedSets::default();
        for (name, ids) in mesh.node_sets().iter() {
            let inside = |n: usize| ids.binary_search(&n).is_ok();
            let extra = edge_ends
                .iter()
                .enumerate()
                .filter(|(_, (a, b))| inside(*a) && inside(*b))
                .map(|(k, _)| first_mid + k);
            node_sets.insert_trusted(name, ids.iter().copied().chain(extra).collect());
        }
        let mut sets = MeshSets::new(nodes.len(), mesh.element_count());
        sets.replace(node_sets, mesh.element_sets().clone());
        Self {
            nodes,
            connectivity,
            sets,
        }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of elements.
    pub fn element_count(&self) -> usize {
        self.connectivity.len() / Self::NODES_PER_ELEMENT
    }

    /// Node coordinates.
    pub fn nodes(&self) -> &[SVector<f64, D>] {
        &self.nodes
    }

    /// The flat connectivity, [`Self::NODES_PER_ELEMENT`] ids per element.
    pub fn connectivity(&self) -> &[usize] {
        &self.connectivity
    }

    /// The node ids of `element` in Gmsh order.
    ///
    /// # Panics
    /// If `element >= self.element_count()`.
    pub fn element_nodes(&self, element: usize) -> &[usize] {
        let n = Self::NODES_PER_ELEMENT;
        &self.connectivity[element * n..(element + 1) * n]
    }

    /// Named node sets.
    pub fn node_sets(&self) -> &NamedSets {
        self.sets.nodes()
    }

    /// Named element sets.
    pub fn element_sets(&self) -> &NamedSets {
        self.sets.elements()
    }

    /// The named sets, to insert more.
    pub fn sets_mut(&mut self) -> &mut MeshSets {
        &mut self.sets
    }
}

/// Every edge (sorted vertex pair) must carry one mid-edge node.
fn check_edge_nodes<const D: usize>(connectivity: &[usize]) -> Result<(), MeshError> {
    let stride = quadratic_node_count(D);
    let edges = &EDGES[..edge_count(D)];
    let mut records: Vec<((usize, usize), usize, usize)> = connectivity
        .chunks_exact(stride)
        .enumerate()
        .flat_map(|(element, ids)| {
            edges.iter().enumerate().map(move |(k, e)| {
                let (a, b) = (ids[e[0]], ids[e[1]]);
                ((a.min(b), a.max(b)), element, ids[D + 1 + k])
            })
        })
        .collect();
    records.sort_unstable();
    for pair in records.windows(2) {
        let (first, second) = (pair[0], pair[1]);
        if first.0 == second.0 && first.2 != second.2 {
            return Err(MeshError::InconsistentEdgeNode {
                element: second.1,
                edge: vec![second.0.0, second.0.1],
                node: second.2,
                other: first.2,
            });
        }
    }
    Ok(())
}
