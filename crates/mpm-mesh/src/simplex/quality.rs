//! Element shape and coincident nodes: what a mesh the constructors
//! accept may still hold that a user wants to hear about.
//!
//! The constructors refuse an element whose $|\det\mathbf T|$ is at most
//! $10^{-12}\ell^D$ ($\ell$ its longest edge): below that the shape
//! functions' gradients are rounding. Above it an element is valid but
//! may be a sliver whose gradients scale as $1/q$ and whose stiffness
//! conditions the linear systems badly; and two nodes at one position
//! are valid but cut the mesh along the faces they split (a crack the
//! user did not draw). [`SimplexMesh::quality`] measures both so that
//! callers can warn ([`MeshQuality::warnings`]).
//!
//! The shape measure is the volume relative to the longest edge,
//! normalised to 1 for the regular simplex:
//! $q = D!\,|V| / (\ell^D\,q_D)$ with $q_2 = \sqrt3/2$, $q_3 = 1/\sqrt2$
//! (a regular triangle of edge $a$ has $2A = \tfrac{\sqrt3}{2}a^2$, a
//! regular tetrahedron $6V = a^3/\sqrt2$). A right isosceles triangle has
//! $q = 0.577$, the corner tetrahedron of a cube $0.471$; Kuhn's six
//! tetrahedra of a cube $0.272$; the refusal threshold is
//! $q = 10^{-12}/q_D$.

use std::collections::HashMap;

use nalgebra::SVector;

use super::SimplexMesh;
use super::geometry::{determinant_and_inverse, edge_matrix};

/// Elements with a shape measure below this are counted as slivers
/// (flattened a thousand times more than a regular simplex).
pub const SLIVER_SHAPE: f64 = 1e-3;

/// Nodes closer than this fraction of the bounding-box diagonal are
/// counted as coincident.
pub const COINCIDENT_TOLERANCE: f64 = 1e-12;

/// The shape of a mesh's elements and its coincident nodes
/// ([module documentation](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshQuality {
    /// The smallest shape measure $q$ (1 for a regular simplex).
    pub worst_shape: f64,
    /// The element with the smallest $q$.
    pub worst_element: usize,
    /// Elements with $q$ below [`SLIVER_SHAPE`].
    pub slivers: usize,
    /// Pairs of distinct nodes within [`COINCIDENT_TOLERANCE`] of the
    /// bounding-box diagonal of each other.
    pub coincident_pairs: usize,
    /// The first such pair found (node ids, the smaller first).
    pub first_coincident: Option<(usize, usize)>,
    /// Of the coincident pairs, those whose two nodes are both used by
    /// elements (an unused duplicate is harmless: it cuts nothing).
    pub coincident_in_use: usize,
}

/// The regular simplex's $D!\,V/\ell^D$.
fn regular<const D: usize>() -> f64 {
    if D == 2 {
        3f64.sqrt() / 2.0
    } else {
        std::f64::consts::FRAC_1_SQRT_2
    }
}

/// The shape measure $q$ of the simplex with vertices `vertices` (module
/// documentation); 0 for a degenerate one.
pub fn shape_measure<const D: usize>(nodes: &[SVector<f64, D>], vertices: &[usize]) -> f64 {
    let (det, _) = determinant_and_inverse(&edge_matrix(nodes, vertices));
    let mut longest: f64 = 0.0;
    for a in 0..=D {
        for b in a + 1..=D {
            longest = longest.max((nodes[vertices[a]] - nodes[vertices[b]]).norm());
        }
    }
    let q = det.abs() / (longest.powi(D as i32) * regular::<D>());
    if q.is_finite() { q } else { 0.0 }
}

impl<const D: usize> SimplexMesh<D> {
    /// The shape of the elements and the coincident nodes
    /// ([module documentation](self)); $O(n)$ in nodes and elements.
    pub fn quality(&self) -> MeshQuality {
        let nodes = self.nodes();
        let mut worst_shape = f64::INFINITY;
        let mut worst_element = 0;
        let mut slivers = 0;
        for e in 0..self.element_count() {
            let q = shape_measure(nodes, self.element_nodes(e));
            if q < worst_shape {
                worst_shape = q;
                worst_element = e;
            }
            if q < SLIVER_SHAPE {
                slivers += 1;
            }
        }
        let box_ = self.bounding_box();
        let diagonal = (box_.upper - box_.lower).norm();
        let pairs = coincident_nodes(nodes, COINCIDENT_TOLERANCE * diagonal);
        let mut used = vec![false; nodes.len()];
        for &n in self.connectivity() {
            used[n] = true;
        }
        MeshQuality {
            worst_shape: if worst_shape.is_finite() {
                worst_shape
            } else {
                1.0
            },
            worst_element,
            slivers,
            coincident_pairs: pairs.len(),
            first_coincident: pairs.first().copied(),
            coincident_in_use: pairs.iter().filter(|(a, b)| used[*a] && used[*b]).count(),
        }
    }
}

/// Pairs `(a, b)`, `a < b`, of nodes within `tolerance` of each other
/// (a hash of cells of edge `tolerance`, each node compared with the
/// nodes of its own and the neighbouring cells), sorted.
fn coincident_nodes<const D: usize>(
    nodes: &[SVector<f64, D>],
    tolerance: f64,
) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        // A mesh of one point: every node coincides, but then no element
        // survives the constructors; nothing to report.
        return pairs;
    }
    let key = |x: &SVector<f64, D>| -> [i64; D] {
        std::array::from_fn(|a| (x[a] / tolerance).floor() as i64)
    };
    let mut cells: HashMap<[i64; D], Vec<usize>> = HashMap::with_capacity(nodes.len());
    for (n, x) in nodes.iter().enumerate() {
        cells.entry(key(x)).or_default().push(n);
    }
    let neighbours = 3usize.pow(D as u32);
    for (n, x) in nodes.iter().enumerate() {
        let k = key(x);
        for m in 0..neighbours {
            let mut cell = k;
            let mut code = m;
            for c in &mut cell {
                *c = c.saturating_add((code % 3) as i64 - 1);
                code /= 3;
            }
            for &o in cells.get(&cell).map_or(&[][..], Vec::as_slice) {
                if o > n && (nodes[o] - x).norm() <= tolerance {
                    pairs.push((n, o));
                }
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

impl MeshQuality {
    /// One sentence per finding (none for a clean mesh): the slivers with
    /// the worst element, and the coincident nodes in use.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.slivers > 0 {
            out.push(format!(
                "{} element(s) are slivers (volume below {SLIVER_SHAPE:e} of a regular simplex's of the same longest edge); the worst, element {}, has {:.1e}: its shape-function gradients are {:.0e} times a regular element's and its stiffness conditions the linear systems badly",
                self.slivers,
                self.worst_element,
                self.worst_shape,
                1.0 / self.worst_shape.max(f64::MIN_POSITIVE)
            ));
        }
        if self.coincident_in_use > 0
            && let Some((a, b)) = self.first_coincident
        {
            out.push(format!(
                "{} pair(s) of nodes in use share a position (the first: nodes {a} and {b}); the elements on either side are not connected there, as if the mesh were cut (merge them in Gmsh: Geometry.Tolerance, Coherence)",
                self.coincident_in_use
            ));
        }
        out
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn regular_simplices_measure_one_and_known_shapes_their_value() {
        let h = 3f64.sqrt() / 2.0;
        let tri = [
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(0.5, h),
        ];
        assert!((shape_measure(&tri, &[0, 1, 2]) - 1.0).abs() < 1e-14);
        let right = [
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(0.0, 1.0),
        ];
        // 2A / ℓ² = 1 / 2, over √3/2.
        assert!((shape_measure(&right, &[0, 1, 2]) - 1.0 / 3f64.sqrt()).abs() < 1e-14);
        let tet = [
            Vector3::new(1.0, 1.0, 1.0),
            Vector3::new(1.0, -1.0, -1.0),
            Vector3::new(-1.0, 1.0, -1.0),
            Vector3::new(-1.0, -1.0, 1.0),
        ];
        assert!((shape_measure(&tet, &[0, 1, 2, 3]) - 1.0).abs() < 1e-14);
        // Scale, translation and orientation do not matter.
        let moved: Vec<_> = tet
            .iter()
            .map(|x| x * 0.1 + Vector3::new(7.0, 0.0, -3.0))
            .collect();
        assert!((shape_measure(&moved, &[1, 0, 2, 3]) - 1.0).abs() < 1e-12);
        let corner = [Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()];
        // 6V / ℓ³ = 1 / 2^1.5, over 1/√2.
        assert!((shape_measure(&corner, &[0, 1, 2, 3]) - 0.5).abs() < 1e-14);
    }

    #[test]
    fn a_sliver_and_coincident_nodes_are_reported() {
        let nodes = vec![
            Vector3::zeros(),
            Vector3::x(),
            Vector3::y(),
            Vector3::z(),
            // The apex of a sliver over the triangle (0, 1, 2), 1e-6
            // above its plane.
            Vector3::new(0.5, 0.5, 1e-6),
            // Node 1 again, used by the second element; node 7 again,
            // used by nothing.
            Vector3::x(),
            Vector3::new(2.0, 2.0, 2.0),
            Vector3::new(5.0, 5.0, 5.0),
            Vector3::new(5.0, 5.0, 5.0),
        ];
        let clean = SimplexMesh::new_reoriented(nodes.clone(), vec![0, 1, 2, 3]).unwrap();
        let q = clean.quality();
        assert_eq!((q.slivers, q.coincident_in_use), (0, 0));
        // The unused duplicates (1, 5) and (7, 8) are counted, not warned.
        assert_eq!(q.coincident_pairs, 2);
        assert_eq!(q.first_coincident, Some((1, 5)));
        assert!(q.warnings().is_empty(), "{:?}", q.warnings());
        assert!((q.worst_shape - 0.5).abs() < 1e-14);

        let mesh =
            SimplexMesh::new_reoriented(nodes, vec![0, 1, 2, 3, 0, 1, 2, 4, 5, 2, 3, 6]).unwrap();
        let q = mesh.quality();
        assert_eq!(q.slivers, 1);
        assert_eq!(q.worst_element, 1);
        assert!(
            q.worst_shape < 1e-5 && q.worst_shape > 1e-7,
            "{}",
            q.worst_shape
        );
        assert_eq!(q.coincident_in_use, 1);
        let w = q.warnings();
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w[0].starts_with("1 element(s) are slivers"), "{}", w[0]);
        assert!(w[0].contains("element 1"), "{}", w[0]);
        assert!(w[1].contains("nodes 1 and 5"), "{}", w[1]);
    }

    #[test]
    fn nearly_coincident_nodes_across_a_cell_boundary_are_found() {
        // 1e-13 apart on either side of a multiple of the tolerance: the
        // neighbouring cells are searched.
        let tol = 1e-12;
        let x = 3.0 * tol;
        let nodes = vec![
            Vector2::new(x - 2e-14, 0.5),
            Vector2::new(x + 2e-14, 0.5),
            Vector2::new(1.0, 1.0),
        ];
        assert_eq!(coincident_nodes(&nodes, tol), vec![(0, 1)]);
        assert!(coincident_nodes(&nodes, 1e-15).is_empty());
    }
}
