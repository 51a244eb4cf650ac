//! Patches of the F-patch method (Wang et al. 2021 §4.1, Fig. 3): every
//! six-node triangle / ten-node tetrahedron of a parent mesh is split into
//! $2^D$ linear children (4 triangles, 8 tetrahedra) that form one patch.
//!
//! Triangle (Fig. 3A), with mid-edge nodes $m_{01}, m_{12}, m_{20}$: three
//! corner triangles $(0, m_{01}, m_{20})$, $(m_{01}, 1, m_{12})$,
//! $(m_{20}, m_{12}, 2)$ and the middle one $(m_{01}, m_{12}, m_{20})$.
//!
//! Tetrahedron (Fig. 3C): four corner tetrahedra, each a vertex with the
//! midpoints of its three edges, and an inner octahedron whose six vertices
//! are the mid-edge nodes. The octahedron is split into four tetrahedra
//! around one of its three diagonals (the segments joining midpoints of
//! opposite edges: $m_{01}m_{23}$, $m_{02}m_{13}$, $m_{03}m_{12}$); the
//! shortest is chosen (the first on ties), which gives the best-shaped
//! children. No node is added: the children use the parent's ten nodes, so
//! node ids and node sets carry over unchanged.

use std::ops::Range;

use crate::{MeshError, NamedSets, QuadraticMesh, SimplexMesh};

/// Children of one six-node triangle, as local node numbers of the parent.
const TRIANGLE_CHILDREN: [[usize; 3]; 4] = [[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]];

/// Corner children of one ten-node tetrahedron (Gmsh order: 4 = m01,
/// 5 = m12, 6 = m20, 7 = m30, 8 = m32, 9 = m31): vertex `v` with the
/// midpoints of its edges, in the parent's orientation.
const TETRAHEDRON_CORNERS: [[usize; 4]; 4] =
    [[0, 4, 6, 7], [4, 1, 5, 9], [6, 5, 2, 8], [7, 9, 8, 3]];

/// The octahedron's three diagonals as pairs of opposite mid-edge nodes.
const DIAGONALS: [[usize; 2]; 3] = [[4, 8], [6, 9], [7, 5]];

/// A linear simplex mesh made of the children of a quadratic parent mesh,
/// with the patch (parent element) of every child.
///
/// Children of parent $p$ are the elements $2^D p, \dots, 2^D p + 2^D - 1$.
/// Node sets are the parent's; an element set of the parent becomes the set
/// of the children of its elements.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchMesh<const D: usize> {
    mesh: SimplexMesh<D>,
    patch_of_element: Vec<usize>,
}

impl<const D: usize> PatchMesh<D> {
    /// Children per patch, $2^D$.
    pub const CHILDREN: usize = 1 << D;

    /// Split every element of `parents` into its children.
    ///
    /// # Errors
    /// The errors of [`SimplexMesh::new`] for the children, for example
    /// [`MeshError::DegenerateElement`] for a curved parent whose mid-edge
    /// nodes make a child degenerate (the element named is the child).
    pub fn from_parents(parents: &QuadraticMesh<D>) -> Result<Self, MeshError> {
        let nodes = parents.nodes();
        let mut connectivity =
            Vec::with_capacity(parents.element_count() * Self::CHILDREN * (D + 1));
        for parent in 0..parents.element_count() {
            let ids = parents.element_nodes(parent);
            if D == 2 {
                for child in TRIANGLE_CHILDREN {
                    connectivity.extend(child.iter().map(|&k| ids[k]));
                }
            } else {
                for child in TETRAHEDRON_CORNERS {
                    connectivity.extend(child.iter().map(|&k| ids[k]));
                }
                let length = |d: &[usize; 2]| (nodes[ids[d[0]]] - nodes[ids[d[1]]]).norm();
                let mut best = 0;
                for (k, diagonal) in DIAGONALS.iter().enumerate() {
                    if length(diagonal) < length(&DIAGONALS[best]) {
                        best = k;
                    }
                }
                let [p, q] = DIAGONALS[best];
                let [a, a2] = DIAGONALS[(best + 1) % 3];
                let [b, b2] = DIAGONALS[(best + 2) % 3];
                // The equator a, b, a2, b2 is a 4-cycle of the octahedron.
                for [u, v] in [[a, b], [b, a2], [a2, b2], [b2, a]] {
                    connectivity.extend([ids[p], ids[q], ids[u], ids[v]]);
                }
            }
        }
        let mut mesh = SimplexMesh::new_reoriented(nodes.to_vec(), connectivity)?;
        let mut element_sets = NamedSets::default();
        for (name, parents) in parents.element_sets().iter() {
            let children = parents
                .iter()
                .flat_map(|&p| p * Self::CHILDREN..(p + 1) * Self::CHILDREN)
                .collect();
            element_sets.insert_trusted(name, children);
        }
        mesh.sets_mut()
            .replace(parents.node_sets().clone(), element_sets);
        let patch_of_element = (0..mesh.element_count())
            .map(|e| e / Self::CHILDREN)
            .collect();
        Ok(Self {
            mesh,
            patch_of_element,
        })
    }

    /// The linear mesh of all children.
    pub fn mesh(&self) -> &SimplexMesh<D> {
        &self.mesh
    }

    /// The linear mesh of all children, by value.
    pub fn into_mesh(self) -> SimplexMesh<D> {
        self.mesh
    }

    /// The patch (parent element id) of every child element.
    pub fn patch_of_element(&self) -> &[usize] {
        &self.patch_of_element
    }

    /// Number of patches (parent elements).
    pub fn patch_count(&self) -> usize {
        self.patch_of_element.len() / Self::CHILDREN
    }

    /// The child elements of `patch`.
    pub fn children(&self, patch: usize) -> Range<usize> {
        patch * Self::CHILDREN..(patch + 1) * Self::CHILDREN
    }

    /// The active elements of every patch that has any (Fig. 3B): `active`
    /// holds one flag per child element (for example "contains a material
    /// point"). The result is written into `out`, which is cleared first
    /// and reuses its capacity, so repeated calls do not allocate once it
    /// has grown.
    ///
    /// # Errors
    /// [`MeshError::MaskLength`] when `active` does not have one entry per
    /// element; `out` is then left empty.
    pub fn active_elements(
        &self,
        active: &[bool],
        out: &mut ActivePatches,
    ) -> Result<(), MeshError> {
        out.clear();
        if active.len() != self.patch_of_element.len() {
            return Err(MeshError::MaskLength {
                expected: self.patch_of_element.len(),
                found: active.len(),
            });
        }
        for (patch, flags) in active.chunks_exact(Self::CHILDREN).enumerate() {
            let before = out.elements.len();
            out.elements.extend(
                flags
                    .iter()
                    .enumerate()
                    .filter_map(|(k, &on)| on.then_some(patch * Self::CHILDREN + k)),
            );
            if out.elements.len() > before {
                out.patches.push(patch);
                out.offsets.push(out.elements.len());
            }
        }
        Ok(())
    }
}

/// Active elements per patch in compressed-row layout, filled by
/// [`PatchMesh::active_elements`]: patch `patches[i]` has the active
/// elements `elements[offsets[i]..offsets[i + 1]]` (ascending). Only
/// patches with at least one active element are listed, in ascending
/// order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ActivePatches {
    patches: Vec<usize>,
    offsets: Vec<usize>,
    elements: Vec<usize>,
}

impl Default for ActivePatches {
    fn default() -> Self {
        Self {
            patches: Vec::new(),
            offsets: vec![0],
            elements: Vec::new(),
        }
    }
}

impl ActivePatches {
    /// Empty, with room for `patches` patches and `elements` elements.
    pub fn with_capacity(patches: usize, elements: usize) -> Self {
        let mut offsets = Vec::with_capacity(patches + 1);
        offsets.push(0);
        Self {
            patches: Vec::with_capacity(patches),
            offsets,
            elements: Vec::with_capacity(elements),
        }
    }

    fn clear(&mut self) {
        self.patches.clear();
        self.offsets.truncate(1);
        self.elements.clear();
    }

    /// Number of patches with an active element.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// Whether no patch has an active element.
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// The ids of the patches with an active element, ascending.
    pub fn patches(&self) -> &[usize] {
        &self.patches
    }

    /// The active elements of the `i`-th listed patch.
    ///
    /// # Panics
    /// If `i >= self.len()`.
    pub fn elements(&self, i: usize) -> &[usize] {
        &self.elements[self.offsets[i]..self.offsets[i + 1]]
    }

    /// `(patch, active elements)` pairs.
    pub fn iter(&self) -> impl Iterator<Item = (usize, &[usize])> {
        self.patches
            .iter()
            .enumerate()
            .map(|(i, &p)| (p, self.elements(i)))
    }
}
