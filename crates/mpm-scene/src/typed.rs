//! Scenes written in Rust: constructors and setters of the [`crate::format`]
//! types, so that a program (the built-in cases of `mpm-cases`) writes its
//! scene as data instead of formatting the text of a scene file and
//! parsing it again.
//!
//! A typed scene is the scene its file would give. A constructor takes the
//! keys that make the thing what it is (a grid's origin, size and cells; a
//! material's model and constants) and a `with_*` setter adds one optional
//! key; every key neither gives keeps the default of the format — the
//! value `serde` gives a key the file leaves out, taken from the format
//! itself ([`SolverSpec::default`], [`OutputSpec::default`], a body's
//! `points_per_cell`), never written again here. So a typed scene equals
//! the parse of the text with the same keys ([`Scene`]'s `PartialEq`
//! compares values, not places), and `toml::to_string` writes that text.
//!
//! Its values have no place in a file: each is wrapped by [`value`] with
//! the empty span `0..0`. Build it with [`SceneSource::typed`], whose
//! errors name the scene's origin without a line and column. (The empty
//! span is also how [`SolverSpec::given`] tells a default, so a typed
//! value reads as not given: the implicit-only keys of an explicit typed
//! scene are not refused by name.)
//!
//! ```
//! use mpm_scene::format::{BodySpec, BoundaryKind, BoundarySpec, LoadSpec, MaterialSpec, MeshSpec, SolverSpec};
//! use mpm_scene::material::MaterialModel;
//! use mpm_scene::source::SceneSource;
//! use mpm_scene::variant::Variant;
//! use mpm_scene::{Problem, Scene};
//!
//! // A 1 m × 10 m column on four cells, fixed at the base, under its weight.
//! let scene = Scene::new(
//!     MeshSpec::grid([0.0, 0.0], [1.0, 10.0], [1, 4]),
//!     vec![MaterialSpec::new("soil", MaterialModel::Hencky, 1e6, 0.0, 80.0)],
//!     vec![BodySpec::block("column", "soil", [0.0, 0.0], [1.0, 10.0], 2)],
//! )
//! .with_boundary(BoundarySpec::on("y_min", BoundaryKind::Fixed))
//! .with_load(LoadSpec::gravity([0.0, -10.0]))
//! .with_solver(SolverSpec::implicit(&Variant::default(), 5, 1e-9));
//!
//! // The same scene as a file says it.
//! let text = toml::to_string(&scene)?;
//! let (parsed, _) = mpm_scene::parse(&text, "column.toml", &[])?;
//! assert_eq!(parsed, scene);
//!
//! let source = SceneSource::typed("the example column");
//! let problem = Problem::<2>::build(&scene, &source, scene.solver.padding())?;
//! assert_eq!(problem.len(), 2 * 2 * 4);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`SceneSource::typed`]: crate::source::SceneSource::typed

use toml::Spanned;

use crate::format::{
    Axes, BodySpec, BoundaryKind, BoundarySpec, LoadKind, LoadSpec, MaterialSpec, MeshKind,
    MeshSpec, MotionKind, MotionSpec, NodeSetSpec, OutputSpec, Placement, RegionSpec, Scene,
    SolverKind, SolverSpec, default_points_per_cell,
};
use crate::material::{ConeMatching, MaterialModel};
use crate::variant::Variant;

/// `v` as a typed scene holds it: with the empty span `0..0`, at no place
/// of a file.
pub fn value<T>(v: T) -> Spanned<T> {
    Spanned::new(0..0, v)
}

/// A string of a typed scene (a name, an axis, a file).
fn text(s: &str) -> Spanned<String> {
    value(s.to_owned())
}

impl Scene {
    /// The scene of `mesh`, `materials` and `bodies`, without node sets,
    /// conditions, loads, fixities or curves, with the default solver and
    /// outputs (those of a file without `[solver]` and `[output]`).
    pub fn new(mesh: MeshSpec, materials: Vec<MaterialSpec>, bodies: Vec<BodySpec>) -> Self {
        Self {
            description: None,
            mesh,
            materials,
            bodies,
            node_sets: Vec::new(),
            boundaries: Vec::new(),
            loads: Vec::new(),
            point_fixities: Vec::new(),
            contacts: Vec::new(),
            curves: Vec::new(),
            solver: SolverSpec::default(),
            output: OutputSpec::default(),
            strength_reduction: None,
        }
    }

    /// Adds a `[[node_set]]`.
    pub fn with_node_set(mut self, set: NodeSetSpec) -> Self {
        self.node_sets.push(set);
        self
    }

    /// Adds a `[[boundary]]`.
    pub fn with_boundary(mut self, boundary: BoundarySpec) -> Self {
        self.boundaries.push(boundary);
        self
    }

    /// Adds a `[[load]]`.
    pub fn with_load(mut self, load: LoadSpec) -> Self {
        self.loads.push(load);
        self
    }

    /// Sets `[solver]`.
    pub fn with_solver(mut self, solver: SolverSpec) -> Self {
        self.solver = solver;
        self
    }
}

impl MeshSpec {
    /// `kind = "grid"`: the regular grid of `cells` over the box `origin ..
    /// origin + size` (2 or 3 numbers each), with the padding its basis
    /// needs.
    pub fn grid(
        origin: impl Into<Vec<f64>>,
        size: impl Into<Vec<f64>>,
        cells: impl Into<Vec<usize>>,
    ) -> Self {
        Self {
            kind: MeshKind::Grid,
            origin: Some(value(origin.into())),
            size: Some(value(size.into())),
            cells: Some(value(cells.into())),
            ..Self::default()
        }
    }

    /// `kind = "simplex"`: the box of [`Self::grid`], each cell split into
    /// triangles or tetrahedra.
    pub fn simplex_box(
        origin: impl Into<Vec<f64>>,
        size: impl Into<Vec<f64>>,
        cells: impl Into<Vec<usize>>,
    ) -> Self {
        Self {
            kind: MeshKind::Simplex,
            ..Self::grid(origin, size, cells)
        }
    }

    /// `kind = "gmsh"`: the MSH 4.1 `file` of `dimension` 2 or 3.
    pub fn gmsh(file: impl Into<String>, dimension: usize) -> Self {
        Self {
            kind: MeshKind::Gmsh,
            file: Some(value(file.into())),
            dimension: Some(value(dimension)),
            ..Self::default()
        }
    }

    /// `kind = "annulus"`: `layers` rings of triangles between the radii,
    /// `ring_nodes` nodes per ring.
    pub fn annulus(inner_radius: f64, outer_radius: f64, layers: usize, ring_nodes: usize) -> Self {
        Self {
            kind: MeshKind::Annulus,
            inner_radius: Some(value(inner_radius)),
            outer_radius: Some(value(outer_radius)),
            layers: Some(value(layers)),
            ring_nodes: Some(value(ring_nodes)),
            ..Self::default()
        }
    }

    /// Sets `patches` (simplex boxes: split quadratic parents).
    pub fn with_patches(mut self, patches: bool) -> Self {
        self.patches = Some(value(patches));
        self
    }

    /// Sets the annulus's `jitter` and its `seed`.
    pub fn with_jitter(mut self, jitter: f64, seed: u64) -> Self {
        self.jitter = Some(value(jitter));
        self.seed = Some(value(seed));
        self
    }

    /// Sets `[mesh.motion]`.
    pub fn with_motion(mut self, motion: MotionSpec) -> Self {
        self.motion = Some(motion);
        self
    }
}

impl MotionSpec {
    /// `kind = "stretch"` along `axis` (`x`, `y` or `z`), the nodes of set
    /// `driven` moving with the mesh; the plane that stays, the length and
    /// the extension still to give ([`Self::with_stretch`]).
    pub fn stretch(axis: &str, driven: &str) -> Self {
        Self {
            kind: value(MotionKind::Stretch),
            axis: Some(text(axis)),
            origin: None,
            length: None,
            extension: None,
            centre: None,
            angle: None,
            displacement: None,
            carried: None,
            fixed: None,
            driven: text(driven),
            components: None,
        }
    }

    /// Sets a stretch's `origin` (the plane that stays), initial `length`
    /// and `extension` at load factor 1.
    pub fn with_stretch(mut self, origin: f64, length: f64, extension: f64) -> Self {
        self.origin = Some(origin);
        self.length = Some(value(length));
        self.extension = Some(value(extension));
        self
    }

    /// Sets the prescribed `components` of the driven nodes (`x`, `y`,
    /// `z`).
    pub fn with_components(mut self, components: &[&str]) -> Self {
        let components = components.iter().map(|c| (*c).to_owned()).collect();
        self.components = Some(value(components));
        self
    }
}

impl MaterialSpec {
    /// `[[material]]` `name` of `model` with Young's modulus (Pa),
    /// Poisson's ratio and density (kg/m³); no yield stress, the default
    /// hardening.
    pub fn new(
        name: &str,
        model: MaterialModel,
        youngs_modulus: f64,
        poisson_ratio: f64,
        density: f64,
    ) -> Self {
        Self {
            name: text(name),
            model,
            youngs_modulus: Some(value(youngs_modulus)),
            poisson_ratio: Some(value(poisson_ratio)),
            density: value(density),
            yield_stress: None,
            // `#[serde(default)]`: the type's default.
            hardening: Default::default(),
            cohesion: None,
            friction_angle: None,
            dilation_angle: None,
            matching: None,
            tension_cutoff: None,
            compression_index: None,
            swelling_index: None,
            critical_state_slope: None,
            shear_modulus: None,
            reference_pressure: None,
            minimum_pressure: None,
            overconsolidation_ratio: None,
        }
    }

    /// Sets the soil laws' cohesion (Pa), friction and dilation angles
    /// (degrees).
    pub fn with_strength(
        mut self,
        cohesion: f64,
        friction_angle: f64,
        dilation_angle: f64,
    ) -> Self {
        self.cohesion = Some(value(cohesion));
        self.friction_angle = Some(value(friction_angle));
        self.dilation_angle = Some(value(dilation_angle));
        self
    }

    /// Sets the Drucker–Prager `matching`.
    pub fn with_matching(mut self, matching: ConeMatching) -> Self {
        self.matching = Some(value(matching));
        self
    }

    /// Sets `yield_stress` (Pa).
    pub fn with_yield_stress(mut self, yield_stress: f64) -> Self {
        self.yield_stress = Some(yield_stress);
        self
    }

    /// Sets the linear `hardening` modulus (Pa).
    pub fn with_hardening(mut self, hardening: f64) -> Self {
        self.hardening = hardening;
        self
    }
}

impl RegionSpec {
    /// `{ box = { lower, upper } }`: the box `lower ..= upper`.
    pub fn box_between(lower: impl Into<Vec<f64>>, upper: impl Into<Vec<f64>>) -> Self {
        Self::Box {
            lower: value(lower.into()),
            upper: value(upper.into()),
        }
    }

    /// `{ group = "..." }`: the elements of a Gmsh physical group.
    pub fn group(group: &str) -> Self {
        Self::Group(text(group))
    }
}

impl BodySpec {
    /// `[[body]]` `name` of `material` filling `region`, with the default
    /// `points_per_cell` and placement.
    pub fn new(name: &str, material: &str, region: RegionSpec) -> Self {
        Self {
            name: text(name),
            material: text(material),
            region,
            points_per_cell: default_points_per_cell(),
            placement: None,
            lattice_origin: None,
            velocity: None,
            initial_stress: None,
        }
    }

    /// A body filling the box `lower ..= upper` with `points_per_cell` per
    /// axis.
    pub fn block(
        name: &str,
        material: &str,
        lower: impl Into<Vec<f64>>,
        upper: impl Into<Vec<f64>>,
        points_per_cell: usize,
    ) -> Self {
        Self::new(name, material, RegionSpec::box_between(lower, upper))
            .with_points_per_cell(points_per_cell)
    }

    /// Sets `points_per_cell`.
    pub fn with_points_per_cell(mut self, points_per_cell: usize) -> Self {
        self.points_per_cell = value(points_per_cell);
        self
    }

    /// Sets `placement`.
    pub fn with_placement(mut self, placement: Placement) -> Self {
        self.placement = Some(value(placement));
        self
    }

    /// Sets `lattice_origin`: the point the lattice of points is anchored
    /// at.
    pub fn with_lattice_origin(mut self, origin: impl Into<Vec<f64>>) -> Self {
        self.lattice_origin = Some(value(origin.into()));
        self
    }
}

impl NodeSetSpec {
    /// `[[node_set]]` `name`: the nodes inside `region`.
    pub fn inside(name: &str, region: RegionSpec) -> Self {
        Self {
            name: text(name),
            region: Some(region),
            around: None,
        }
    }

    /// `[[node_set]]` `name`: the nodes that support a boundary point of
    /// `body`, found again every step.
    pub fn around(name: &str, body: &str) -> Self {
        Self {
            name: text(name),
            region: None,
            around: Some(text(body)),
        }
    }
}

impl Axes {
    /// Sets the x component.
    pub fn with_x(self, x: f64) -> Self {
        Self { x: Some(x), ..self }
    }

    /// Sets the y component.
    pub fn with_y(self, y: f64) -> Self {
        Self { y: Some(y), ..self }
    }

    /// Sets the z component.
    pub fn with_z(self, z: f64) -> Self {
        Self { z: Some(z), ..self }
    }
}

impl BoundarySpec {
    /// `[[boundary]]` of `kind` on the node `set` (a grid face or a
    /// `[[node_set]]`), nothing else given.
    pub fn on(set: &str, kind: BoundaryKind) -> Self {
        Self {
            set: text(set),
            kind: value(kind),
            displacement: None,
            gradient: None,
            curve: None,
            velocity: None,
            friction: None,
            gap_check: None,
            normal: None,
            rough: None,
            normal_stiffness: None,
            tangential_stiffness: None,
            material: None,
            spring: None,
        }
    }

    /// Sets the prescribed `displacement` components.
    pub fn with_displacement(mut self, displacement: Axes) -> Self {
        self.displacement = Some(value(displacement));
        self
    }

    /// Sets the displacement `gradient` (rows of D numbers).
    pub fn with_gradient(mut self, rows: Vec<Vec<f64>>) -> Self {
        self.gradient = Some(value(rows));
        self
    }
}

impl LoadSpec {
    /// A `[[load]]` of `kind` with nothing else given.
    fn of(kind: LoadKind) -> Self {
        Self {
            kind: value(kind),
            acceleration: None,
            force: None,
            at: None,
            region: None,
            traction: None,
            side: None,
            field: None,
            parameters: None,
            body: None,
            curve: None,
        }
    }

    /// `kind = "gravity"`: the `acceleration` (m/s²) on every body.
    pub fn gravity(acceleration: impl Into<Vec<f64>>) -> Self {
        Self {
            acceleration: Some(value(acceleration.into())),
            ..Self::of(LoadKind::Gravity)
        }
    }

    /// `kind = "point"`: the total `force` shared by the points in
    /// `region`.
    pub fn point_in(region: RegionSpec, force: impl Into<Vec<f64>>) -> Self {
        Self {
            region: Some(region),
            force: Some(value(force.into())),
            ..Self::of(LoadKind::Point)
        }
    }

    /// `kind = "manufactured"`: the body force of `field` with its
    /// `parameters`.
    pub fn manufactured<'a>(
        field: &str,
        parameters: impl IntoIterator<Item = (&'a str, f64)>,
    ) -> Self {
        let parameters = parameters
            .into_iter()
            .map(|(k, v)| (k.to_owned(), v))
            .collect();
        Self {
            field: Some(text(field)),
            parameters: Some(value(parameters)),
            ..Self::of(LoadKind::Manufactured)
        }
    }
}

impl SolverSpec {
    /// `kind = "implicit"` with `variant` (every one of its keys given),
    /// `steps` equal load steps and the Newton `tolerance`; every other key
    /// the default.
    pub fn implicit(variant: &Variant, steps: usize, tolerance: f64) -> Self {
        Self {
            kind: value(SolverKind::Implicit),
            basis: Some(value(variant.basis)),
            formulation: value(variant.formulation),
            locking: value(variant.locking),
            domain_update: value(variant.domain_update),
            gimp_volume: value(variant.gimp_volume),
            steps: value(steps),
            tolerance: value(tolerance),
            ..Self::default()
        }
    }

    /// Sets `predictor` (the secant predictor of each step).
    pub fn with_predictor(mut self, predictor: bool) -> Self {
        self.predictor = value(predictor);
        self
    }
}
