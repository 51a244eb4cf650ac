//! Linear simplex meshes: triangles ($D = 2$) and tetrahedra ($D = 3$), the
//! background meshes of Wang et al. (2021).
//!
//! Data layout (struct of arrays, element-major):
//!
//! | array | per element | use |
//! |---|---|---|
//! | `connectivity` | $D+1$ node ids | flat, stride $D+1$ |
//! | `origins` | $\mathbf x_1$, the first vertex | eq. (13) |
//! | `inverse_maps` | $\mathbf T^{-1}$ ($D\times D$) | eq. (13), local coordinates |
//! | `gradients` | $\nabla N_1,\dots,\nabla N_{D+1}$ | constant per element, stride $D+1$ |
//! | `volumes` | $\det\mathbf T / D!$ | positive |
//! | `neighbours` | one element per face, [`NO_NEIGHBOUR`] on the boundary | Algorithm 2 |
//!
//! plus a bucket grid of element bounding boxes for the location fallback.

mod buckets;
mod geometry;
mod locate;
mod neighbours;
mod quality;
mod reference;

use nalgebra::{SMatrix, SVector};

use crate::{BoundingBox, MeshError, MeshSets, NamedSets};
use buckets::Buckets;
pub(crate) use geometry::{
    check_dimension, check_element_nodes, check_nodes, element_count, signed_volume,
};
pub use locate::{BARYCENTRIC_TOLERANCE, Location, Walk};
pub use neighbours::{BoundaryFace, NO_NEIGHBOUR};
pub use quality::{COINCIDENT_TOLERANCE, MeshQuality, SLIVER_SHAPE, shape_measure};
pub use reference::quadratic_node_count;
pub(crate) use reference::{EDGES, edge_count, swap_orientation};

/// A conforming mesh of linear triangles (`D = 2`) or tetrahedra (`D = 3`)
/// with everything point location and the linear basis need precomputed:
/// per element the inverse map $\mathbf T^{-1}$ and first vertex
/// $\mathbf x_1$ of Wang et al. (2021) eq. (13), the constant shape-function
/// gradients, the volume, and the neighbour across every face
/// (Algorithm 2); plus a bucket grid for the location fallback, and named
/// node and element sets.
///
/// Local node `k` of an element has the shape function (eq. 15)
/// $N_1 = 1 - \sum_i\xi_i$, $N_{k+1} = \xi_k$, where
/// $\boldsymbol\xi = \mathbf T^{-1}(\mathbf x - \mathbf x_1)$ are the local
/// coordinates. Face `k` of an element is the face opposite its local node
/// `k`; [`SimplexMesh::neighbour`] gives the element across it.
///
/// ```
/// use mpm_mesh::SimplexMesh;
/// use nalgebra::Vector2;
/// // The unit square split along its diagonal.
/// let nodes = vec![
///     Vector2::new(0.0, 0.0),
///     Vector2::new(1.0, 0.0),
///     Vector2::new(1.0, 1.0),
///     Vector2::new(0.0, 1.0),
/// ];
/// let mesh = SimplexMesh::new(nodes, vec![0, 1, 2, 0, 2, 3])?;
/// assert_eq!(mesh.neighbour(0, 1), Some(1));
/// let location = mesh.locate(&Vector2::new(0.2, 0.7), Some(0))?;
/// assert_eq!(location.element, 1);
/// assert!((mesh.total_volume() - 1.0).abs() < 1e-15);
/// # Ok::<(), mpm_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SimplexMesh<const D: usize> {
    nodes: Vec<SVector<f64, D>>,
    connectivity: Vec<usize>,
    origins: Vec<SVector<f64, D>>,
    inverse_maps: Vec<SMatrix<f64, D, D>>,
    gradients: Vec<SVector<f64, D>>,
    volumes: Vec<f64>,
    neighbours: Vec<usize>,
    boundary_faces: Vec<BoundaryFace>,
    bounding_box: BoundingBox<D>,
    buckets: Buckets<D>,
    step_budget: usize,
    sets: MeshSets,
}

/// Per-element geometry of positively oriented elements.
struct ElementGeometry<const D: usize> {
    origins: Vec<SVector<f64, D>>,
    inverse_maps: Vec<SMatrix<f64, D, D>>,
    gradients: Vec<SVector<f64, D>>,
    volumes: Vec<f64>,
}

impl<const D: usize> ElementGeometry<D> {
    /// First vertex, $\mathbf T^{-1}$ (eq. 13), shape-function gradients and
    /// volume of every element (the elements must be positively oriented).
    fn compute(nodes: &[SVector<f64, D>], connectivity: &[usize]) -> Result<Self, MeshError> {
        let stride = D + 1;
        let count = connectivity.len() / stride;
        let mut g = Self {
            origins: Vec::with_capacity(count),
            inverse_maps: Vec::with_capacity(count),
            gradients: Vec::with_capacity(count * stride),
            volumes: Vec::with_capacity(count),
        };
        for (element, vertices) in connectivity.chunks_exact(stride).enumerate() {
            let volume = signed_volume(nodes, element, vertices)?;
            let (_, inverse) =
                geometry::determinant_and_inverse(&geometry::edge_matrix(nodes, vertices));
            g.origins.push(nodes[vertices[0]]);
            g.inverse_maps.push(inverse);
            // N_{k+1} = xi_k: its gradient is row k of T^-1; N_1 = 1 - sum xi.
            let rows: [SVector<f64, D>; D] = std::array::from_fn(|k| inverse.row(k).transpose());
            g.gradients.push(-rows.iter().sum::<SVector<f64, D>>());
            g.gradients.extend_from_slice(&rows);
            g.volumes.push(volume.abs());
        }
        Ok(g)
    }
}

impl<const D: usize> SimplexMesh<D> {
    /// A mesh of the nodes `nodes` and the elements `connectivity` (flat,
    /// `D + 1` node ids per element), every element positively oriented
    /// ($\det\mathbf T > 0$).
    ///
    /// # Errors
    /// [`MeshError::UnsupportedDimension`] unless `D` is 2 or 3;
    /// [`MeshError::ConnectivityLength`], [`MeshError::NoElements`] or
    /// [`MeshError::TooManyElements`] for the connectivity's length;
    /// [`MeshError::NonFiniteNode`]; per element (naming it)
    /// [`MeshError::ElementNodeOutOfRange`],
    /// [`MeshError::RepeatedElementNode`], [`MeshError::DegenerateElement`]
    /// and [`MeshError::InvertedElement`]; and
    /// [`MeshError::NonManifoldFace`] for a face of three or more elements.
    pub fn new(nodes: Vec<SVector<f64, D>>, connectivity: Vec<usize>) -> Result<Self, MeshError> {
        Self::build(nodes, connectivity, false)
    }

    /// As [`SimplexMesh::new`], but an element with negative signed volume
    /// is reoriented (its local nodes 1 and 2 swapped) instead of rejected;
    /// for input of unknown orientation such as Gmsh files.
    ///
    /// # Errors
    /// As [`SimplexMesh::new`], except [`MeshError::InvertedElement`].
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
        let stride = D + 1;
        let count = element_count(connectivity.len(), stride)?;
        check_nodes(&nodes)?;
        for (element, vertices) in connectivity.chunks_exact_mut(stride).enumerate() {
            check_element_nodes(element, vertices, nodes.len())?;
            let volume = signed_volume(&nodes, element, vertices)?;
            if volume < 0.0 {
                if !reorient {
                    return Err(MeshError::InvertedElement { element, volume });
                }
                swap_orientation(D, vertices);
            }
        }
        let geometry = ElementGeometry::compute(&nodes, &connectivity)?;
        let (neighbours, boundary_faces) = neighbours::neighbour_table::<D>(&connectivity)?;
        let bounding_box = BoundingBox::of_points(&nodes).ok_or(MeshError::NoElements)?;
        let buckets = Buckets::new(
            &nodes,
            &connectivity,
            bounding_box.lower,
            bounding_box.upper,
        );
        // A walk from any start crosses about count^(1/D) elements per
        // unit of relative distance; allow a generous multiple.
        let step_budget = 8 * (count as f64).powf(1.0 / D as f64).ceil() as usize + 64;
        Ok(Self {
            connectivity,
            origins: geometry.origins,
            inverse_maps: geometry.inverse_maps,
            gradients: geometry.gradients,
            volumes: geometry.volumes,
            neighbours,
            boundary_faces,
            bounding_box,
            buckets,
            step_budget,
            sets: MeshSets::new(nodes.len(), count),
            nodes,
        })
    }

    /// Moves the nodes to `nodes` (same count, same connectivity) and
    /// recomputes the element geometry, bounding box and location buckets;
    /// the neighbour table and the named sets are kept. Used by
    /// moving-mesh boundary conditions (Wang et al. 2021 §2.2).
    ///
    /// # Errors
    /// [`MeshError::NodeCountMismatch`] for a wrong node count,
    /// [`MeshError::NonFiniteNode`], and [`MeshError::InvertedElement`] or
    /// [`MeshError::DegenerateElement`] (naming the element) when the
    /// motion would invert or flatten an element; the mesh is then
    /// unchanged.
    pub fn move_nodes(&mut self, nodes: Vec<SVector<f64, D>>) -> Result<(), MeshError> {
        if nodes.len() != self.nodes.len() {
            return Err(MeshError::NodeCountMismatch {
                expected: self.nodes.len(),
                found: nodes.len(),
            });
        }
        check_nodes(&nodes)?;
        for (element, vertices) in self.connectivity.chunks_exact(D + 1).enumerate() {
            let volume = signed_volume(&nodes, element, vertices)?;
            if volume < 0.0 {
                return Err(MeshError::InvertedElement { element, volume });
            }
        }
        let geometry = ElementGeometry::compute(&nodes, &self.connectivity)?;
        let bounding_box = BoundingBox::of_points(&nodes).ok_or(MeshError::NoElements)?;
        self.buckets = Buckets::new(
            &nodes,
            &self.connectivity,
            bounding_box.lower,
            bounding_box.upper,
        );
        self.origins = geometry.origins;
        self.inverse_maps = geometry.inverse_maps;
        self.gradients = geometry.gradients;
        self.volumes = geometry.volumes;
        self.bounding_box = bounding_box;
        self.nodes = nodes;
        Ok(())
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of elements.
    pub fn element_count(&self) -> usize {
        self.volumes.len()
    }

    /// Node coordinates.
    pub fn nodes(&self) -> &[SVector<f64, D>] {
        &self.nodes
    }

    /// The flat connectivity, `D + 1` node ids per element (after any
    /// reorientation by [`SimplexMesh::new_reoriented`]).
    pub fn connectivity(&self) -> &[usize] {
        &self.connectivity
    }

    /// The `D + 1` node ids of `element`.
    ///
    /// # Panics
    /// If `element >= self.element_count()`.
    pub fn element_nodes(&self, element: usize) -> &[usize] {
        &self.connectivity[element * (D + 1)..(element + 1) * (D + 1)]
    }

    /// The node ids of face `face` of `element`: its nodes but local node
    /// `face`, in local order.
    ///
    /// # Panics
    /// If `element >= self.element_count()`.
    pub fn face_nodes(&self, element: usize, face: usize) -> impl Iterator<Item = usize> + '_ {
        self.element_nodes(element)
            .iter()
            .enumerate()
            .filter_map(move |(k, &n)| (k != face).then_some(n))
    }

    /// Element volumes (areas in 2D), all positive.
    pub fn volumes(&self) -> &[f64] {
        &self.volumes
    }

    /// Sum of the element volumes.
    pub fn total_volume(&self) -> f64 {
        self.volumes.iter().sum()
    }

    /// The first vertex $\mathbf x_1$ of `element` (eq. 13).
    ///
    /// # Panics
    /// If `element >= self.element_count()`.
    pub fn origin(&self, element: usize) -> &SVector<f64, D> {
        &self.origins[element]
    }

    /// The inverse map $\mathbf T^{-1}$ of `element` (eq. 13).
    ///
    /// # Panics
    /// If `element >= self.element_count()`.
    pub fn inverse_map(&self, element: usize) -> &SMatrix<f64, D, D> {
        &self.inverse_maps[element]
    }

    /// The constant gradients $\nabla N_1, \dots, \nabla N_{D+1}$ of the
    /// shape functions (eq. 15) of `element`, in local node order.
    ///
    /// # Panics
    /// If `element >= self.element_count()`.
    pub fn shape_gradients(&self, element: usize) -> &[SVector<f64, D>] {
        &self.gradients[element * (D + 1)..(element + 1) * (D + 1)]
    }

    /// Local coordinates $\boldsymbol\xi = \mathbf T^{-1}(\mathbf x - \mathbf
    /// x_1)$ of `x` with respect to `element` (eq. 13), whether inside it or
    /// not.
    ///
    /// # Panics
    /// If `element >= self.element_count()`.
    pub fn local_coordinates(&self, element: usize, x: &SVector<f64, D>) -> SVector<f64, D> {
        self.inverse_maps[element] * (x - self.origins[element])
    }

    /// The neighbour table, `D + 1` entries per element: entry `k` is the
    /// element across face `k` (opposite local node `k`), or
    /// [`NO_NEIGHBOUR`] on the boundary.
    pub fn neighbours(&self) -> &[usize] {
        &self.neighbours
    }

    /// The element across face `face` of `element`, `None` on the boundary.
    ///
    /// # Panics
    /// If `element >= self.element_count()` or `face > D`.
    pub fn neighbour(&self, element: usize, face: usize) -> Option<usize> {
        assert!(face <= D, "a {D}-simplex has faces 0..={D}");
        let n = self.neighbours[element * (D + 1) + face];
        (n != NO_NEIGHBOUR).then_some(n)
    }

    /// The boundary faces, sorted by element and face.
    pub fn boundary_faces(&self) -> &[BoundaryFace] {
        &self.boundary_faces
    }

    /// The bounding box of the nodes.
    pub fn bounding_box(&self) -> &BoundingBox<D> {
        &self.bounding_box
    }

    /// Named node sets (boundary sets of the generators, Gmsh physical
    /// groups).
    pub fn node_sets(&self) -> &NamedSets {
        self.sets.nodes()
    }

    /// Named element sets (Gmsh physical groups of the mesh dimension).
    pub fn element_sets(&self) -> &NamedSets {
        self.sets.elements()
    }

    /// The named sets, to insert more.
    pub fn sets_mut(&mut self) -> &mut MeshSets {
        &mut self.sets
    }
}
