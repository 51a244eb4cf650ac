//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong when building or querying a background mesh.
///
/// Every variant names the offending input (the axis, the point, the index or
/// the material point) so that a caller can report where it happened.
/// Coordinates and indices are stored as `Vec`s because the error type is
/// shared by all dimensions; they are only allocated on the error path.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshError {
    /// A grid origin coordinate is NaN or infinite.
    #[error("grid origin coordinate {axis} is {value}; it must be finite")]
    InvalidOrigin {
        /// The axis of the offending coordinate.
        axis: usize,
        /// The value given.
        value: f64,
    },
    /// A grid spacing is not positive and finite.
    #[error("grid spacing along axis {axis} is {value}; it must be positive and finite")]
    InvalidSpacing {
        /// The axis of the offending spacing.
        axis: usize,
        /// The value given.
        value: f64,
    },
    /// Grid bounds along an axis are not finite or not increasing.
    #[error("grid bounds along axis {axis} are [{lower}, {upper}]; need finite lower < upper")]
    InvalidBounds {
        /// The axis of the offending bounds.
        axis: usize,
        /// The lower bound given.
        lower: f64,
        /// The upper bound given.
        upper: f64,
    },
    /// An axis has no cells.
    #[error("a grid needs at least one cell along every axis; axis {axis} has none")]
    NoCells {
        /// The axis without cells.
        axis: usize,
    },
    /// The node count does not fit in `usize`, or the upper corner of the
    /// grid is not finite.
    #[error("a grid with {cells:?} cells per axis is too large to index")]
    TooLarge {
        /// The cells per axis requested.
        cells: Vec<usize>,
    },
    /// A point lies outside the closed box of the grid (or is not finite).
    #[error("point {point:?} lies outside the grid [{lower:?}, {upper:?}]")]
    PointOutsideGrid {
        /// The point's coordinates.
        point: Vec<f64>,
        /// The grid's lower corner.
        lower: Vec<f64>,
        /// The grid's upper corner.
        upper: Vec<f64>,
    },
    /// A material point of a set lies outside the grid (or is not finite).
    #[error("material point {particle} at {point:?} lies outside the grid")]
    ParticleOutsideGrid {
        /// Index of the material point in the slice given.
        particle: usize,
        /// Its coordinates.
        point: Vec<f64>,
    },
    /// A bounding box is not finite or has `lower > upper` along some axis.
    #[error(
        "bounding box {particle} [{lower:?}, {upper:?}] is invalid; need finite lower <= upper"
    )]
    InvalidBox {
        /// Index of the box (material point) in the slice given.
        particle: usize,
        /// Its lower corner.
        lower: Vec<f64>,
        /// Its upper corner.
        upper: Vec<f64>,
    },
    /// A bounding box does not intersect the grid at all.
    #[error("bounding box {particle} [{lower:?}, {upper:?}] does not intersect the grid")]
    BoxOutsideGrid {
        /// Index of the box (material point) in the slice given.
        particle: usize,
        /// Its lower corner.
        lower: Vec<f64>,
        /// Its upper corner.
        upper: Vec<f64>,
    },
    /// A node multi-index is out of range along some axis.
    #[error("node multi-index {index:?} is outside the {nodes_per_axis:?} nodes per axis")]
    NodeIndexOutOfRange {
        /// The multi-index given.
        index: Vec<usize>,
        /// The grid's nodes per axis.
        nodes_per_axis: Vec<usize>,
    },
    /// A node id is not below the node count.
    #[error("node id {id} is not below the node count {count}")]
    NodeIdOutOfRange {
        /// The id given.
        id: usize,
        /// The grid's node count.
        count: usize,
    },
    /// A cell multi-index is out of range along some axis.
    #[error("cell multi-index {index:?} is outside the {cells_per_axis:?} cells per axis")]
    CellIndexOutOfRange {
        /// The multi-index given.
        index: Vec<usize>,
        /// The grid's cells per axis.
        cells_per_axis: Vec<usize>,
    },
    /// A cell id is not below the cell count.
    #[error("cell id {id} is not below the cell count {count}")]
    CellIdOutOfRange {
        /// The id given.
        id: usize,
        /// The grid's cell count.
        count: usize,
    },
    /// An axis number is not below the dimension.
    #[error("axis {axis} does not exist in a {dimension}-dimensional grid")]
    InvalidAxis {
        /// The axis given.
        axis: usize,
        /// The grid's dimension.
        dimension: usize,
    },
    /// A simplex mesh was requested in a dimension other than 2 or 3.
    #[error("simplex meshes exist in 2 and 3 dimensions, not in {dimension}")]
    UnsupportedDimension {
        /// The dimension requested.
        dimension: usize,
    },
    /// A mesh without elements.
    #[error("a mesh needs at least one element")]
    NoElements,
    /// The flat connectivity array is not a whole number of elements.
    #[error(
        "connectivity of length {length} is not a multiple of {nodes_per_element} nodes per element"
    )]
    ConnectivityLength {
        /// Length of the connectivity array given.
        length: usize,
        /// Nodes per element ($D + 1$ for linear, $(D+1)(D+2)/2$ for quadratic simplices).
        nodes_per_element: usize,
    },
    /// Moved nodes given for a mesh with another number of nodes.
    #[error("{found} node positions given for a mesh of {expected} nodes")]
    NodeCountMismatch {
        /// The mesh's node count.
        expected: usize,
        /// The number of positions given.
        found: usize,
    },
    /// More elements than the `u32` element ids of the location buckets can index.
    #[error("{count} elements are more than the {max} a mesh can index")]
    TooManyElements {
        /// The number of elements given.
        count: usize,
        /// The largest admissible number.
        max: usize,
    },
    /// A node coordinate is NaN or infinite.
    #[error("node {node} has a non-finite coordinate {point:?}")]
    NonFiniteNode {
        /// The node id.
        node: usize,
        /// Its coordinates.
        point: Vec<f64>,
    },
    /// An element refers to a node that does not exist.
    #[error(
        "element {element} (local node {local}) refers to node {node}, but there are {count} nodes"
    )]
    ElementNodeOutOfRange {
        /// The element id.
        element: usize,
        /// The local node number within the element.
        local: usize,
        /// The node id given.
        node: usize,
        /// The number of nodes.
        count: usize,
    },
    /// An element lists the same node twice.
    #[error("element {element} lists node {node} twice")]
    RepeatedElementNode {
        /// The element id.
        element: usize,
        /// The repeated node id.
        node: usize,
    },
    /// An element has (almost) zero volume: $|\det \mathbf T| \le 10^{-12}\,\ell^D$
    /// with $\ell$ its longest edge (Wang et al. 2021 eq. 13 needs $\mathbf T^{-1}$).
    #[error("element {element} is degenerate: signed volume {volume:e}")]
    DegenerateElement {
        /// The element id.
        element: usize,
        /// Its signed volume.
        volume: f64,
    },
    /// An element has negative signed volume and the constructor was asked
    /// not to reorient elements.
    #[error("element {element} is inverted: signed volume {volume:e}")]
    InvertedElement {
        /// The element id.
        element: usize,
        /// Its signed volume.
        volume: f64,
    },
    /// A face is shared by more than two elements: the mesh is not a
    /// conforming simplicial complex.
    #[error("face {nodes:?} is shared by elements {first}, {second} and {third}")]
    NonManifoldFace {
        /// The face's node ids (sorted).
        nodes: Vec<usize>,
        /// The first element holding it.
        first: usize,
        /// The second element holding it.
        second: usize,
        /// A third element holding it.
        third: usize,
    },
    /// Two quadratic elements put different mid-edge nodes on the same edge.
    #[error(
        "element {element} puts node {node} on edge {edge:?}, but another element put node {other} there"
    )]
    InconsistentEdgeNode {
        /// The element id.
        element: usize,
        /// The edge's vertex node ids (sorted).
        edge: Vec<usize>,
        /// The mid-edge node this element gives.
        node: usize,
        /// The mid-edge node an earlier element gave.
        other: usize,
    },
    /// An element id is not below the element count (for example a stale
    /// location hint).
    #[error("element id {id} is not below the element count {count}")]
    ElementIdOutOfRange {
        /// The id given.
        id: usize,
        /// The mesh's element count.
        count: usize,
    },
    /// A point lies in no element of a simplex mesh (or is not finite).
    #[error("point {point:?} lies in no element of the mesh")]
    PointOutsideMesh {
        /// The point's coordinates.
        point: Vec<f64>,
    },
    /// A named node or element set refers to an id that does not exist.
    #[error("set {set:?} refers to id {id}, but there are {count}")]
    SetIdOutOfRange {
        /// The set's name.
        set: String,
        /// The id given.
        id: usize,
        /// The number of nodes or elements.
        count: usize,
    },
    /// A per-element mask does not have one entry per element.
    #[error("a per-element mask needs {expected} entries, got {found}")]
    MaskLength {
        /// The number of elements.
        expected: usize,
        /// The mask's length.
        found: usize,
    },
    /// A structured generator was given a bad parameter.
    #[error("generator parameter {parameter} = {value} is invalid: {requirement}")]
    InvalidGeneratorParameter {
        /// The parameter's name.
        parameter: &'static str,
        /// The value given.
        value: f64,
        /// What it must satisfy.
        requirement: &'static str,
    },
    /// A Gmsh file could not be read from disk.
    #[error("cannot read Gmsh file {path}: {message}")]
    GmshIo {
        /// The path given.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// A Gmsh file is not MSH 4.1 ASCII: missing or malformed `$MeshFormat`
    /// or another version.
    #[error("line {line}: not an MSH 4.1 ASCII file: {found}")]
    GmshFormat {
        /// The line (1-based).
        line: usize,
        /// What was found there.
        found: String,
    },
    /// A Gmsh file is binary (`file-type` 1); only ASCII is read.
    #[error("line {line}: binary MSH files are not supported; save as ASCII (Mesh.Binary = 0)")]
    GmshBinary {
        /// The line of the `$MeshFormat` data (1-based).
        line: usize,
    },
    /// A Gmsh line does not hold what the format requires there.
    #[error("line {line}: expected {expected}, found {found:?}")]
    GmshSyntax {
        /// The line (1-based).
        line: usize,
        /// What the format requires.
        expected: &'static str,
        /// What the line holds.
        found: String,
    },
    /// A Gmsh section ends before its data, or the file ends inside it.
    #[error("line {line}: section ${section} is truncated")]
    GmshTruncated {
        /// The line where more data was expected (1-based; one past the
        /// last line at the end of the file).
        line: usize,
        /// The section's name.
        section: String,
    },
    /// A count in a Gmsh section disagrees with the data.
    #[error("line {line}: {what} is {expected} but the data holds {found}")]
    GmshCount {
        /// The line holding the count (1-based).
        line: usize,
        /// Which count.
        what: &'static str,
        /// The count declared.
        expected: usize,
        /// The count found.
        found: usize,
    },
    /// A required Gmsh section is missing.
    #[error("line {line}: the file has no ${section} section")]
    GmshMissingSection {
        /// The number of lines in the file.
        line: usize,
        /// The section's name.
        section: &'static str,
    },
    /// A Gmsh element refers to a node tag not in `$Nodes`.
    #[error("line {line}: element refers to unknown node tag {tag}")]
    GmshUnknownNode {
        /// The line (1-based).
        line: usize,
        /// The node tag.
        tag: usize,
    },
    /// A Gmsh node tag appears twice.
    #[error("line {line}: node tag {tag} appears twice")]
    GmshDuplicateNode {
        /// The line (1-based).
        line: usize,
        /// The node tag.
        tag: usize,
    },
    /// A Gmsh element type outside the supported subset (points 15, lines
    /// 1 and 8, triangles 2 and 9, tetrahedra 4 and 11).
    #[error("line {line}: Gmsh element type {element_type} is not supported")]
    GmshUnsupportedElement {
        /// The line of the element block header (1-based).
        line: usize,
        /// The Gmsh element type number.
        element_type: usize,
    },
    /// A Gmsh file mixes linear and quadratic elements of the mesh dimension.
    #[error("line {line}: element type {element_type} mixes linear and quadratic elements")]
    GmshMixedOrder {
        /// The line of the element block header (1-based).
        line: usize,
        /// The Gmsh element type number.
        element_type: usize,
    },
    /// A Gmsh file has no elements of the mesh dimension.
    #[error("line {line}: the file has no {dimension}D triangles or tetrahedra")]
    GmshNoElements {
        /// The number of lines in the file.
        line: usize,
        /// The dimension requested.
        dimension: usize,
    },
    /// A Gmsh element is invalid as a mesh element (degenerate, inconsistent
    /// mid-edge node, face of three elements, …).
    #[error("line {line}: Gmsh element {tag}: {source}")]
    GmshElement {
        /// The element's line (1-based).
        line: usize,
        /// The element's Gmsh tag.
        tag: usize,
        /// What is wrong with it (naming the element by its index in the
        /// mesh).
        #[source]
        source: Box<MeshError>,
    },
    /// A node of a 2D Gmsh mesh has a nonzero z coordinate.
    #[error("line {line}: node has z = {z}, but a 2D mesh must lie in the plane z = 0")]
    GmshNotPlanar {
        /// The line (1-based).
        line: usize,
        /// The z coordinate found.
        z: f64,
    },
}
