//! The scene file format: what a TOML scene deserialises into, before any
//! check across sections (names that refer to nothing, bodies outside the
//! mesh; [`crate::build`]). Every table refuses unknown keys. Fields that
//! other sections refer to, or whose value is checked later, keep their
//! place in the file (`Spanned`) so that the error can name it.
//!
//! The guide page `docs/src/guide/scenes.md` documents every key.

use serde::{Deserialize, Serialize};
use toml::Spanned;

use crate::material::{ConeMatching, MaterialModel};
use crate::variant::{BasisKind, DomainUpdateKind, FormulationKind, GimpVolumeKind, LockingKind};

/// A whole problem: mesh, materials, bodies, conditions, loads, solver
/// and outputs.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Free text describing the scene (copied to `summary.json`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// The background mesh.
    pub mesh: MeshSpec,
    /// The materials, referred to by name from the bodies.
    #[serde(rename = "material")]
    pub materials: Vec<MaterialSpec>,
    /// The bodies of material points.
    #[serde(rename = "body")]
    pub bodies: Vec<BodySpec>,
    /// Named node sets besides the grid faces.
    #[serde(rename = "node_set", default, skip_serializing_if = "Vec::is_empty")]
    pub node_sets: Vec<NodeSetSpec>,
    /// Dirichlet conditions on node sets.
    #[serde(rename = "boundary", default, skip_serializing_if = "Vec::is_empty")]
    pub boundaries: Vec<BoundarySpec>,
    /// Loads.
    #[serde(rename = "load", default, skip_serializing_if = "Vec::is_empty")]
    pub loads: Vec<LoadSpec>,
    /// Material-point fixities (explicit solver).
    #[serde(
        rename = "point_fixity",
        default,
        skip_serializing_if = "Vec::is_empty"
    )]
    pub point_fixities: Vec<PointFixitySpec>,
    /// Multi-field contact between bodies (explicit solver).
    #[serde(rename = "contact", default, skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<ContactSpec>,
    /// Load curves, referred to by name from loads and boundaries.
    #[serde(rename = "curve", default, skip_serializing_if = "Vec::is_empty")]
    pub curves: Vec<CurveSpec>,
    /// The solver and its variant.
    #[serde(default)]
    pub solver: SolverSpec,
    /// What is written.
    #[serde(default)]
    pub output: OutputSpec,
    /// A factor of safety by strength reduction: the implicit problem run
    /// in trials of reduced strength, bisecting for the factor at failure.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strength_reduction: Option<Spanned<StrengthReductionSpec>>,
}

crate::variant::named_enum!(
    /// When a strength-reduction trial has failed (`criterion`).
    FailureCriterion {
        /// A load step does not converge after cutting to the minimum
        /// increment.
        Convergence => "convergence",
        /// That, or a probe's displacement beyond `displacement_limit`.
        Displacement => "displacement",
    }
);

/// `[strength_reduction]`: trials of the whole problem with $c$, $\tan\phi$
/// (and von Mises' yield stress, and the hardening moduli) divided by a
/// factor $F$, each from the initial state, bisecting between the last
/// factor that held and the first that failed.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StrengthReductionSpec {
    /// The first factor tried, expected to hold (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<Spanned<f64>>,
    /// The second factor tried, expected to fail (default 2 × `lower`);
    /// while it holds, the bracket is widened by its width.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<Spanned<f64>>,
    /// The bisection stops when the bracket is this narrow (default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<Spanned<f64>>,
    /// When a trial has failed (default `convergence`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub criterion: Option<Spanned<FailureCriterion>>,
    /// With `criterion = "displacement"`: the `[[output.probe]]` watched.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe: Option<Spanned<String>>,
    /// With `criterion = "displacement"`: the probe's displacement
    /// magnitude (m) beyond which a trial has failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement_limit: Option<Spanned<f64>>,
    /// The most trials run (default 30).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_trials: Option<Spanned<usize>>,
}

/// Kinds of background mesh.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MeshKind {
    /// A regular grid of squares or cubes.
    #[default]
    Grid,
    /// A Gmsh MSH 4.1 file of triangles or tetrahedra (linear, or
    /// quadratic split into their linear children).
    Gmsh,
    /// A 2D annulus about the origin of linear triangles: `layers` rings of
    /// elements between `inner_radius` and `outer_radius`, `ring_nodes`
    /// nodes per ring, optionally jittered.
    Annulus,
    /// The box `origin .. origin + size` of `cells` squares or cubes, each
    /// split into triangles or tetrahedra (or into six-node triangles or
    /// ten-node tetrahedra split into their linear children, `patches`).
    Simplex,
}

/// `[mesh]`: a regular grid over the box `origin .. origin + size`, or a
/// Gmsh file. The default is an empty `[mesh]` table: every key the
/// file may leave out, left out.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// The kind of mesh (`grid` or `gmsh`).
    #[serde(default)]
    pub kind: MeshKind,
    /// Grid: lower corner (m); its length (2 or 3) sets the dimension.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<Spanned<Vec<f64>>>,
    /// Grid: extent per axis (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<Spanned<Vec<f64>>>,
    /// Grid: cells per axis (give this or `spacing`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cells: Option<Spanned<Vec<usize>>>,
    /// Grid: cell size per axis (m), dividing `size` (give this or `cells`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spacing: Option<Spanned<Vec<f64>>>,
    /// Grid: extra cells on every side beyond the box; at least what the
    /// basis needs (one for quadratic B-splines), which is also the default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub padding: Option<Spanned<usize>>,
    /// Gmsh: the MSH 4.1 file, relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<Spanned<String>>,
    /// Gmsh: the dimension (2 or 3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dimension: Option<Spanned<usize>>,
    /// Simplex boxes: each simplex is a quadratic parent split into its
    /// 4 (2D) or 8 (3D) linear children, the patches of F-patch (default
    /// false: linear simplices).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patches: Option<Spanned<bool>>,
    /// Simplex boxes: the cells' node coordinates along each axis (m),
    /// from `origin` to `origin + size`, strictly increasing (instead of
    /// `cells` or `spacing`): a rectilinear box, refined where the rows
    /// are close.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinates: Option<Spanned<Vec<Vec<f64>>>>,
    /// Annulus: inner radius (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_radius: Option<Spanned<f64>>,
    /// Annulus: outer radius (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outer_radius: Option<Spanned<f64>>,
    /// Annulus: element layers across the thickness.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers: Option<Spanned<usize>>,
    /// Annulus: nodes per ring.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ring_nodes: Option<Spanned<usize>>,
    /// Annulus: jitter of the interior nodes, a fraction (at most 0.2) of
    /// the radial and angular steps (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jitter: Option<Spanned<f64>>,
    /// Annulus: seed of the jitter (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<Spanned<u64>>,
    /// The mesh moves with the load factor (moving-mesh conditions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
}

/// Kinds of mesh motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionKind {
    /// Uniform stretch along one axis: $x_a = o + (X_a - o)(L_0 +
    /// \lambda\,\Delta L)/L_0$, the other coordinates fixed.
    Stretch,
    /// Rigid rotation of the whole mesh about a centre (2D) or an axis
    /// through a centre (3D) by $\lambda\,\Theta$ (Wang et al. 2021 §5.5:
    /// "rotate the whole mesh with the vane").
    Rotation,
    /// Translation of the `carried` nodes by $\lambda\,\mathbf d$ with the
    /// `fixed` nodes held and every other node interpolated by its
    /// distances to the two sets (Wang et al. 2021 §5.2: the empty mesh
    /// above a footing moves with it, the mesh below is compressed).
    Translation,
}

/// `[mesh.motion]`: the background mesh follows the load factor, and the
/// nodes of the `driven` set have their `components` prescribed to move
/// with it (Beuth 2012; Wang et al. 2021 §2.2).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// The motion.
    pub kind: Spanned<MotionKind>,
    /// `stretch`: the stretched axis; `rotation` in 3D: the axis of
    /// rotation (`x`, `y` or `z`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<Spanned<String>>,
    /// `stretch`: coordinate of the plane that stays (default: the mesh's
    /// lower bound along the axis).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<f64>,
    /// `stretch`: initial length $L_0$ (default: the mesh's extent along
    /// the axis).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<Spanned<f64>>,
    /// `stretch`: extension $\Delta L$ at load factor 1 (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extension: Option<Spanned<f64>>,
    /// `rotation`: the centre (a point of the axis in 3D; default the
    /// origin).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre: Option<Spanned<Vec<f64>>>,
    /// `rotation`: the angle $\Theta$ at load factor 1 (radians,
    /// counter-clockwise about the axis).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<Spanned<f64>>,
    /// `translation`: the displacement $\mathbf d$ at load factor 1 (m,
    /// $D$ numbers).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement: Option<Spanned<Vec<f64>>>,
    /// `translation`: node set that moves rigidly by $\lambda\,\mathbf d$
    /// (default: `driven`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub carried: Option<Spanned<String>>,
    /// `translation`: node set that stays where it is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fixed: Option<Spanned<String>>,
    /// Node set whose nodes move with the mesh.
    pub driven: Spanned<String>,
    /// Components of the driven nodes that are prescribed (default: the
    /// axis for a stretch, every component for a rotation or a
    /// translation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub components: Option<Spanned<Vec<String>>>,
}

/// `[[material]]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Name the bodies use.
    pub name: Spanned<String>,
    /// Constitutive model.
    pub model: MaterialModel,
    /// Young's modulus E (Pa); every model but `modified_cam_clay`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub youngs_modulus: Option<Spanned<f64>>,
    /// Poisson's ratio ν; every model but `modified_cam_clay`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson_ratio: Option<Spanned<f64>>,
    /// Density ϱ₀ (kg/m³).
    pub density: Spanned<f64>,
    /// Yield stress ρ_y (Pa), for `von_mises`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yield_stress: Option<f64>,
    /// Linear hardening modulus (Pa): of the yield stress (`von_mises`) or
    /// of the cohesion (`mohr_coulomb`, `drucker_prager`).
    #[serde(default)]
    pub hardening: f64,
    /// Cohesion c (Pa), for `mohr_coulomb` and `drucker_prager`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cohesion: Option<Spanned<f64>>,
    /// Friction angle φ (degrees, in [0, 90)), for the soil laws.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_angle: Option<Spanned<f64>>,
    /// Dilation angle ψ (degrees, in [0, φ]; default 0), for the soil laws.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dilation_angle: Option<Spanned<f64>>,
    /// The Drucker–Prager cone's fit to Mohr–Coulomb: `outer`, `inner` or
    /// `plane_strain`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matching: Option<Spanned<ConeMatching>>,
    /// `mohr_coulomb`: the tension cut-off σ_t (Pa, ≥ 0, at most c cot φ):
    /// no principal stress above it (Rankine). Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tension_cutoff: Option<Spanned<f64>>,
    /// `modified_cam_clay`: the slope λ̂ of the normal compression line in
    /// ln p against the volumetric log strain (> κ̂).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compression_index: Option<Spanned<f64>>,
    /// `modified_cam_clay`: the slope κ̂ of the swelling line (> 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub swelling_index: Option<Spanned<f64>>,
    /// `modified_cam_clay`: the critical-state slope M = q/p (> 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub critical_state_slope: Option<Spanned<f64>>,
    /// `modified_cam_clay`: the shear modulus G (Pa, > 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear_modulus: Option<Spanned<f64>>,
    /// `modified_cam_clay`: the pressure p_r at zero elastic volumetric
    /// strain (Pa, > 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_pressure: Option<Spanned<f64>>,
    /// `modified_cam_clay`: the floor of the preconsolidation pressure
    /// (Pa, ≥ 0; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub minimum_pressure: Option<Spanned<f64>>,
    /// `modified_cam_clay`: the over-consolidation ratio of the initial
    /// state (≥ 1; default 1: normally consolidated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overconsolidation_ratio: Option<Spanned<f64>>,
}

/// A region of space: a box, a polygon (2D), a sphere or disc, or a union
/// or difference of regions.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum RegionSpec {
    /// The box `lower ..= upper`.
    Box {
        /// Lower corner.
        lower: Spanned<Vec<f64>>,
        /// Upper corner.
        upper: Spanned<Vec<f64>>,
    },
    /// A simple polygon (2D), vertices in order.
    Polygon(Spanned<Vec<[f64; 2]>>),
    /// A disc (2D) or ball (3D).
    Sphere {
        /// Centre.
        centre: Spanned<Vec<f64>>,
        /// Radius (m).
        radius: Spanned<f64>,
    },
    /// Points in any of the regions.
    Union(Vec<RegionSpec>),
    /// Points in the first region and in none of the others.
    Difference(Spanned<Vec<RegionSpec>>),
    /// The elements of a Gmsh physical group (Gmsh meshes; bodies only).
    Group(Spanned<String>),
}

/// `[[body]]`: material points filling a region.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Name (for messages and outputs).
    pub name: Spanned<String>,
    /// Name of its `[[material]]`.
    pub material: Spanned<String>,
    /// Where its points are.
    pub region: RegionSpec,
    /// Grids: points per cell per axis (on a regular lattice: each point
    /// at the centre of its sub-cell, kept when the centre is in the
    /// region). Simplex meshes: each element split into `n^D` equal
    /// sub-simplices, one point at each centroid.
    #[serde(default = "default_points_per_cell")]
    pub points_per_cell: Spanned<usize>,
    /// How the points are placed: `regular` (the lattice or the
    /// sub-simplices of `points_per_cell`, the default), `gauss4` (the
    /// 4-point Gauss rule in every tetrahedron) or `keast11` (Keast's
    /// 11-point rule).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<Spanned<Placement>>,
    /// Grids: a point the lattice of points is anchored at (the lower
    /// corner of a sub-cell), instead of the grid's origin — for a body
    /// that is not aligned with the grid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lattice_origin: Option<Spanned<Vec<f64>>>,
    /// Explicit solver: the initial velocity of the body's points (m/s;
    /// default at rest).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<Spanned<Vec<f64>>>,
    /// The stress the body's points start from (Pa, compression
    /// negative): geostatic or isotropic. Default: stress-free.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_stress: Option<Spanned<InitialStressSpec>>,
}

/// `initial_stress` of a `[[body]]`.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum InitialStressSpec {
    /// σ_v = −γ (surface − x_v) below the surface (zero above), the
    /// vertical axis the last one (y in 2D, z in 3D); σ_h = K0 σ_v on the
    /// other axes, the out-of-plane one of plane strain included.
    Geostatic {
        /// The surface's height on the vertical axis (m).
        surface: f64,
        /// Unit weight γ = ϱ₀ g (N/m³).
        unit_weight: f64,
        /// Coefficient of lateral earth pressure K0 > 0.
        k0: f64,
    },
    /// σ = −p 1.
    Isotropic {
        /// Pressure p (Pa, compression positive).
        pressure: f64,
    },
}

/// Placement of a body's points.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Placement {
    /// Sub-cell centres of a lattice (grids) or sub-simplex centroids.
    #[default]
    Regular,
    /// Keast's 11 points per tetrahedron, equal volumes (3D simplex meshes).
    Keast11,
    /// The 4 Gauss points of the degree-2 rule per tetrahedron, equal
    /// volumes (3D simplex meshes).
    Gauss4,
}

pub(crate) fn default_points_per_cell() -> Spanned<usize> {
    Spanned::new(0..0, 2)
}

/// `[[node_set]]`: the mesh nodes in a region, or the nodes that support
/// a body's boundary points, by name.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct NodeSetSpec {
    /// Name the boundaries and outputs use.
    pub name: Spanned<String>,
    /// The nodes inside it (boundary included) form the set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<RegionSpec>,
    /// The nodes whose basis stencil reaches a boundary point of this body
    /// (a grid body's points with a lattice neighbour outside its region),
    /// found again at the start of every load step as the body moves.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub around: Option<Spanned<String>>,
}

/// Kinds of Dirichlet condition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundaryKind {
    /// Every component fixed.
    Fixed,
    /// The normal component of a grid face fixed.
    Roller,
    /// Components given in `displacement` prescribed, following `curve`.
    Displacement,
    /// The components given in `velocity` prescribed at a constant nodal
    /// velocity (explicit solver; refused by the implicit one).
    Velocity,
    /// A rigid wall beyond a grid face with Coulomb friction coefficient
    /// `friction`: a node moving into it loses its normal velocity and up
    /// to `friction` times that of its tangential velocity; a node moving
    /// away is free (explicit solver; refused by the implicit one).
    Friction,
    /// An absorbing (viscous) boundary on a grid face, with the
    /// impedances of `material` (explicit solver; refused by the implicit
    /// one).
    Absorbing,
    /// A rigid flat tool (footing, platen, base) in frictional contact
    /// with the set's nodes: a penalty normal force that lets go in
    /// tension and Coulomb friction `friction` (or `rough = true`), the
    /// tool moving by `displacement` along `curve` (implicit solver;
    /// refused by the explicit one, whose wall is kind = friction).
    Contact,
}

/// Per-axis values; axes not given are left alone.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axes {
    /// x component.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    /// y component.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<f64>,
    /// z component.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<f64>,
}

impl Axes {
    /// The components, `x, y, z`.
    pub fn get(&self) -> [Option<f64>; 3] {
        [self.x, self.y, self.z]
    }
}

/// `[[boundary]]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// Node set: a grid face (`x_min`, `x_max`, `y_min`, `y_max`, `z_min`,
    /// `z_max`) or a `[[node_set]]` name.
    pub set: Spanned<String>,
    /// What is prescribed.
    pub kind: Spanned<BoundaryKind>,
    /// For `displacement`: the displacement reached where the curve is 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement: Option<Spanned<Axes>>,
    /// For `displacement`: a displacement gradient $\mathbf G$ (rows of
    /// $D$ numbers), so that node $v$ at initial position $\mathbf x_v$
    /// reaches $\mathbf u = \mathbf d + \mathbf G\,\mathbf x_v$ where the
    /// curve is 1 ($\mathbf d$: `displacement`, zero if absent); every
    /// component is then prescribed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gradient: Option<Spanned<Vec<Vec<f64>>>>,
    /// For `displacement`: the load curve (default: linear in the load
    /// factor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve: Option<Spanned<String>>,
    /// For `velocity` (explicit solver): the constant nodal velocity of the
    /// given components (m/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<Spanned<Axes>>,
    /// For `friction` (explicit solver): the Coulomb coefficient μ ≥ 0
    /// (dimensionless; 0 is a slip wall that lets go).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<Spanned<f64>>,
    /// For `friction` (explicit solver): `true` makes the wall act on a
    /// node only where a point touches the wall over it (the gap check:
    /// a rolling body); default `false`, wherever the node has mass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gap_check: Option<Spanned<bool>>,
    /// For `contact`: the unit normal of the tool's face, pointing into
    /// the body (normalised here). Default on a grid face: the face's
    /// inward normal; needed on a `[[node_set]]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<Spanned<Axes>>,
    /// For `contact`: a rough tool (pure stick: no slip whatever the
    /// normal force), instead of `friction`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rough: Option<Spanned<bool>>,
    /// For `contact`: the normal penalty per unit area (Pa/m, > 0).
    /// Default: 100 × 2G/h (G: the largest shear modulus of the points,
    /// h: the mean grid spacing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_stiffness: Option<Spanned<f64>>,
    /// For `contact`: the tangential penalty per unit area (Pa/m, > 0).
    /// Default: `normal_stiffness`'s value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential_stiffness: Option<Spanned<f64>>,
    /// For `absorbing` (explicit solver): the `[[material]]` whose
    /// density and P- and S-wave speeds give the dashpots ρ c_p and ρ c_s
    /// per unit area.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<Spanned<String>>,
    /// For `absorbing` (explicit solver): a spring layer behind the
    /// dashpots, `{ normal = k_n, tangential = k_t }` per unit area
    /// (Pa/m, each ≥ 0, a missing one 0), so a body under gravity rests
    /// on the boundary instead of sinking through it. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spring: Option<Spanned<SpringSpec>>,
}

/// The spring layer of an absorbing boundary: stiffnesses per unit area
/// (Pa/m) on the normal and on each tangential component.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringSpec {
    /// k_n (Pa/m).
    #[serde(default)]
    pub normal: f64,
    /// k_t (Pa/m).
    #[serde(default)]
    pub tangential: f64,
}

/// `[[point_fixity]]`: material-point fixities (explicit solver; the
/// MPoint alternative to nodal fixities): the given velocity components
/// of the material points in `region` (of `body`, if given) are held at
/// the given values, on the points and, through a Lagrange multiplier per
/// point, on the grid.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PointFixitySpec {
    /// The points held: those inside the region at the start.
    pub region: RegionSpec,
    /// Only the points of this body (default: every body).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<Spanned<String>>,
    /// The held components and their velocities (m/s).
    pub velocity: Spanned<Axes>,
}

/// `[[contact]]`: the bodies named get a velocity field each on the
/// shared grid and meet every other field by the multi-field contact of
/// Bardenhagen et al. (2000, 2001) with Coulomb friction `friction`
/// (explicit solver).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// The bodies, by name; each in one contact at most.
    pub bodies: Spanned<Vec<Spanned<String>>>,
    /// The Coulomb coefficient μ ≥ 0 (default 0: frictionless).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<Spanned<f64>>,
}

/// Kinds of load.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoadKind {
    /// A body force per unit mass on every body (or on `body`).
    Gravity,
    /// A force on the point nearest `at`, or shared by the points in
    /// `region`.
    Point,
    /// A traction on one side of a body, shared by its points on that side
    /// by their face areas.
    Traction,
    /// The body force of a manufactured solution: the force that makes a
    /// named displacement field exact (method of manufactured solutions).
    Manufactured,
}

/// `[[load]]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// What kind of load.
    pub kind: Spanned<LoadKind>,
    /// `gravity`: the acceleration (m/s²).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub acceleration: Option<Spanned<Vec<f64>>>,
    /// `point`: the total force (N; per unit thickness in 2D).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force: Option<Spanned<Vec<f64>>>,
    /// `point`: the location whose nearest point takes the force.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<Spanned<Vec<f64>>>,
    /// `point`: the region whose points share the force equally.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<RegionSpec>,
    /// `traction`: the traction (Pa).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub traction: Option<Spanned<Vec<f64>>>,
    /// `traction`: the side of the body (`x_min` … `z_max`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<Spanned<String>>,
    /// `manufactured`: the field (`annulus_torsion`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<Spanned<String>>,
    /// `manufactured`: the field's parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parameters: Option<Spanned<std::collections::BTreeMap<String, f64>>>,
    /// `gravity` (optional) and `traction` (required): the body loaded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<Spanned<String>>,
    /// The load curve (default: linear in the load factor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve: Option<Spanned<String>>,
}

/// `[[curve]]`: a piecewise-linear factor over the load factor (implicit
/// solver) or over the simulated time in seconds (explicit solver), from a
/// table of `[time, factor]` rows with increasing times; constant beyond
/// the first and last row.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CurveSpec {
    /// Name the loads and boundaries use.
    pub name: Spanned<String>,
    /// `[time, factor]` rows; time is the load factor, 0 to 1 (implicit
    /// solver), or the simulated time in seconds (explicit solver).
    pub points: Spanned<Vec<[f64; 2]>>,
}

/// Kinds of solver.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverKind {
    /// Quasi-static implicit Newton–Raphson.
    #[default]
    Implicit,
    /// Explicit dynamics (`mpm_solver::ExplicitSolver`): update-stress-last
    /// with a lumped mass matrix, in time up to `end_time`.
    Explicit,
}

pub use crate::variant::TransferKind;

/// `[solver]`. The keys of one solver kind are refused with the other
/// ([`crate::build`]): Newton and load-stepping keys with `kind =
/// "explicit"`, time-stepping keys with `kind = "implicit"`. Values whose
/// presence matters keep their place (`Spanned`; a default has the empty
/// span `0..0`).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSpec {
    /// The solver.
    pub kind: Spanned<SolverKind>,
    /// Basis functions (default: `linear` for the implicit solver,
    /// `bspline2` for the explicit one; [`SolverSpec::basis`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub basis: Option<Spanned<BasisKind>>,
    /// Statement of equilibrium (implicit).
    pub formulation: Spanned<FormulationKind>,
    /// Locking treatment.
    pub locking: Spanned<LockingKind>,
    /// GIMP domain update (implicit).
    pub domain_update: Spanned<DomainUpdateKind>,
    /// Integration volume of GIMP points (implicit).
    pub gimp_volume: Spanned<GimpVolumeKind>,
    /// Number of equal load steps (the first increment is 1/steps).
    pub steps: Spanned<usize>,
    /// Largest load increment with automatic stepping (default 1/steps:
    /// uniform steps, halved after a failure).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_increment: Option<Spanned<f64>>,
    /// Smallest load increment before the run stops (default
    /// 1/(1024 steps)).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_increment: Option<Spanned<f64>>,
    /// Newton tolerance on the normalised residual (eq. 40).
    pub tolerance: Spanned<f64>,
    /// Newton iteration limit per step.
    pub max_iterations: Spanned<usize>,
    /// Start each step from the previous step's increment (a secant
    /// predictor; keeps Newton on the branch of the previous step where
    /// perfectly plastic equilibrium paths bifurcate).
    pub predictor: Spanned<bool>,
    /// The tangent of a step's first solve when it starts from prescribed
    /// increments alone ([`mpm_solver::FirstTangent`]).
    pub first_tangent: Spanned<FirstTangentSpec>,
    /// The linear solver of each Newton iteration.
    pub linear: Spanned<LinearKind>,
    /// Relative tolerance of the iterative linear solver (default 1e-12).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub linear_tolerance: Option<Spanned<f64>>,
    /// With `linear = "auto"`: the largest number of free dofs solved
    /// directly (default [`mpm_solver::DEFAULT_MAX_DIRECT_DOFS_3D`] in 3D,
    /// [`mpm_solver::DEFAULT_MAX_DIRECT_DOFS_2D`] in 2D).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_direct_dofs: Option<Spanned<usize>>,
    /// Implicit: nodes whose support volume and stiffness weight are both
    /// below this fraction of the largest are held over a step
    /// ([`mpm_solver::NewtonOptions::weak_node_threshold`]; default 1e-6,
    /// 0 disables).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weak_node_threshold: Option<Spanned<f64>>,
    /// Implicit: nodes whose stiffness weight is below this fraction of the
    /// largest are held over a step
    /// ([`mpm_solver::NewtonOptions::weak_node_stiffness`]; default 1e-4,
    /// 0 disables).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weak_node_stiffness: Option<Spanned<f64>>,
    /// Implicit, grid meshes: the ghost penalty on the faces of cut cells
    /// as a multiple γ of the law's 2μ
    /// ([`mpm_solver::NewtonOptions::ghost`]; default 0, off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ghost_penalty: Option<Spanned<f64>>,
    /// Implicit, with `ghost_penalty`: a cell is cut when its points'
    /// volume is below this fraction of its own (default 0.5).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ghost_fill: Option<Spanned<f64>>,
    /// Explicit: the simulated time the run ends at (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_time: Option<Spanned<f64>>,
    /// Explicit: the CFL safety factor in (0, 1] (default 0.5).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cfl: Option<Spanned<f64>>,
    /// Explicit: a fixed time step (s) instead of the CFL condition.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_step: Option<Spanned<f64>>,
    /// Explicit: the velocity transfer (default `flip`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub transfer: Option<Spanned<TransferKind>>,
    /// Explicit, `transfer = "blend"`: the FLIP fraction in [0, 1].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha: Option<Spanned<f64>>,
    /// Explicit: simulated time between outputs (default `end_time`/20).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub output_interval: Option<Spanned<f64>>,
    /// Explicit, on several processes: steps between two counts of the
    /// points per process (default 50; 0: the cells are never dealt
    /// anew).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rebalance_every: Option<Spanned<usize>>,
    /// Explicit, on several processes: the imbalance (most loaded
    /// process's points over the mean, above 1) past which the cells are
    /// dealt anew (default 1.1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rebalance_threshold: Option<Spanned<f64>>,
}

impl SolverSpec {
    /// Whether `value` was given in the scene or an override (a default
    /// has the empty span `0..0`).
    pub fn given<T>(value: &Spanned<T>) -> bool {
        value.span() != (0..0)
    }

    /// The solver kind.
    pub fn kind(&self) -> SolverKind {
        *self.kind.get_ref()
    }

    /// The basis: the one given, or the default of the solver kind
    /// (`linear` implicit, `bspline2` explicit: the MPoint notes' default,
    /// free of the cell-crossing noise of linear MPM in dynamics).
    pub fn basis(&self) -> BasisKind {
        match (&self.basis, self.kind()) {
            (Some(b), _) => *b.get_ref(),
            (None, SolverKind::Implicit) => crate::variant::Variant::default().basis,
            (None, SolverKind::Explicit) => BasisKind::BSpline2,
        }
    }

    /// Padding cells the scene's basis needs ([`BasisKind::padding`]).
    pub fn padding(&self) -> usize {
        self.basis().padding()
    }
}

/// `solver.linear`: `"auto"`, `"direct"`, `"iterative"`, or
/// `{ petsc = "-ksp_type cg -pc_type gamg" }`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum LinearKind {
    /// Direct up to `max_direct_dofs` free dofs, iterative beyond.
    #[default]
    Auto,
    /// Sparse Cholesky with an LU fallback (faer).
    Direct,
    /// ILU(0)-preconditioned BiCGSTAB (faer, faer-precond).
    Iterative,
    /// PETSc's Krylov method and preconditioner chosen by these options,
    /// as on PETSc's command line (an `mpm` built with the `petsc`
    /// feature).
    Petsc(String),
}

/// `solver.first_tangent`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum FirstTangentSpec {
    /// The converged state at the start of the step.
    #[default]
    Converged,
    /// The trial state of the prescribed increments.
    Trial,
}

impl From<FirstTangentSpec> for mpm_solver::FirstTangent {
    fn from(s: FirstTangentSpec) -> Self {
        match s {
            FirstTangentSpec::Converged => Self::Converged,
            FirstTangentSpec::Trial => Self::Trial,
        }
    }
}

impl Default for SolverSpec {
    fn default() -> Self {
        let v = crate::variant::Variant::default();
        let newton = mpm_solver::NewtonOptions::default();
        fn at<T>(x: T) -> Spanned<T> {
            Spanned::new(0..0, x)
        }
        Self {
            kind: at(SolverKind::Implicit),
            basis: None,
            formulation: at(v.formulation),
            locking: at(v.locking),
            domain_update: at(v.domain_update),
            gimp_volume: at(v.gimp_volume),
            steps: Spanned::new(0..0, 10),
            max_increment: None,
            min_increment: None,
            tolerance: Spanned::new(0..0, 1e-9),
            max_iterations: Spanned::new(0..0, newton.max_iterations),
            predictor: at(newton.predictor),
            first_tangent: at(FirstTangentSpec::default()),
            linear: at(LinearKind::default()),
            linear_tolerance: None,
            max_direct_dofs: None,
            weak_node_threshold: None,
            weak_node_stiffness: None,
            ghost_penalty: None,
            ghost_fill: None,
            end_time: None,
            cfl: None,
            time_step: None,
            transfer: None,
            alpha: None,
            output_interval: None,
            rebalance_every: None,
            rebalance_threshold: None,
        }
    }
}

/// Fields of the material-point VTU files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Field {
    /// Total displacement (`displacement`).
    Displacement,
    /// Velocity (`velocity`; explicit runs).
    Velocity,
    /// Cauchy stress (`cauchy_stress`).
    Stress,
    /// Deformation gradient (`deformation_gradient`).
    DeformationGradient,
    /// Volume (`volume`).
    Volume,
    /// Equivalent plastic strain (`equivalent_plastic_strain`).
    PlasticStrain,
    /// GIMP/CPDI2 domain bounds (`domain_lower`, `domain_upper`).
    Domain,
    /// The per-point constants of the writer's per-point constants (e.g. a scene's
    /// body and material indices).
    Body,
}

impl Field {
    /// Every field.
    pub const ALL: [Field; 8] = [
        Field::Displacement,
        Field::Velocity,
        Field::Stress,
        Field::DeformationGradient,
        Field::Volume,
        Field::PlasticStrain,
        Field::Domain,
        Field::Body,
    ];
}

/// A reaction history: the sum of the reactions on a node set.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ReactionSpec {
    /// File name stem: `reaction_<name>.csv`.
    pub name: Spanned<String>,
    /// The node set.
    pub set: Spanned<String>,
    /// Also write the moment of the reactions about this point (2D: a
    /// scalar about the out-of-plane axis; 3D: a vector); see
    /// [`crate::build::ReactionOutput::moment`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub about: Option<Spanned<Vec<f64>>>,
}

/// A displacement history of the material point nearest a location.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    /// File name stem: `probe_<name>.csv`.
    pub name: Spanned<String>,
    /// The location (in the initial configuration).
    pub at: Spanned<Vec<f64>>,
}

/// `[output]`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct OutputSpec {
    /// Write the VTU files every this many steps (and always the last).
    pub every: Spanned<usize>,
    /// Fields of the material-point VTU files (default: all).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fields: Option<Vec<Field>>,
    /// Reaction histories.
    #[serde(rename = "reaction", skip_serializing_if = "Vec::is_empty")]
    pub reactions: Vec<ReactionSpec>,
    /// Displacement histories.
    #[serde(rename = "probe", skip_serializing_if = "Vec::is_empty")]
    pub probes: Vec<ProbeSpec>,
    /// Also write a PNG of the final state (2D scenes).
    pub png: bool,
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self {
            every: Spanned::new(0..0, 1),
            fields: None,
            reactions: Vec::new(),
            probes: Vec::new(),
            png: false,
        }
    }
}
