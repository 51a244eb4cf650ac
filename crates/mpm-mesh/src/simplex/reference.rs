//! Tables of the reference triangle and tetrahedron: edges in Gmsh order,
//! node counts, and the vertex swap that reverses an element's orientation.

/// Edges of the reference simplex in Gmsh order (Gmsh reference manual,
/// "Node ordering"): the triangle's edges are the first three, the
/// tetrahedron's all six. The mid-edge node of edge `k` of a six-node
/// triangle or ten-node tetrahedron is its local node `D + 1 + k`.
pub(crate) const EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [3, 0], [3, 2], [3, 1]];

/// Number of edges of a `D`-simplex, $D(D+1)/2$.
pub(crate) const fn edge_count(dimension: usize) -> usize {
    dimension * (dimension + 1) / 2
}

/// Nodes of a quadratic `D`-simplex: vertices and one node per edge,
/// $(D+1)(D+2)/2$ (6 for tri6, 10 for tet10).
pub const fn quadratic_node_count(dimension: usize) -> usize {
    (dimension + 1) * (dimension + 2) / 2
}

/// Reverse the orientation of a linear or quadratic simplex in place by
/// swapping its local vertices 1 and 2, and for a quadratic element the
/// mid-edge nodes so that node `D + 1 + k` stays on edge [`EDGES`]`[k]`.
pub(crate) fn swap_orientation(dimension: usize, element: &mut [usize]) {
    element.swap(1, 2);
    if element.len() == dimension + 1 {
        return;
    }
    let relabel = |v: usize| match v {
        1 => 2,
        2 => 1,
        other => other,
    };
    let edges = &EDGES[..edge_count(dimension)];
    let mut old = [0; 6];
    old[..edges.len()].copy_from_slice(&element[dimension + 1..]);
    for (k, edge) in edges.iter().enumerate() {
        let (a, b) = (relabel(edge[0]), relabel(edge[1]));
        if let Some(j) = edges
            .iter()
            .position(|e| (e[0] == a && e[1] == b) || (e[0] == b && e[1] == a))
        {
            element[dimension + 1 + k] = old[j];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_swap_keeps_mid_nodes_on_their_edges() {
        let mut tri6 = [0, 1, 2, 3, 4, 5];
        swap_orientation(2, &mut tri6);
        assert_eq!(tri6, [0, 2, 1, 5, 4, 3]);
        let mut tet10 = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9];
        swap_orientation(3, &mut tet10);
        assert_eq!(tet10, [0, 2, 1, 3, 6, 5, 4, 7, 9, 8]);
        let mut tet4 = [7, 8, 9, 10];
        swap_orientation(3, &mut tet4);
        assert_eq!(tet4, [7, 9, 8, 10]);
    }

    #[test]
    fn counts() {
        assert_eq!(edge_count(2), 3);
        assert_eq!(edge_count(3), 6);
        assert_eq!(quadratic_node_count(2), 6);
        assert_eq!(quadratic_node_count(3), 10);
    }
}
