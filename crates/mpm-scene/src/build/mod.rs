//! From a parsed [`Scene`] to what the solver takes: the grid, the
//! material points of every body with their masses and materials, the
//! Dirichlet conditions, the loads and the controls. Every check across
//! sections happens here, before anything is run or written, and each
//! error names the place in the file (or the override) it comes from.
//!
//! [`Problem::build_in`] reads as its stages, in the order their errors
//! are found, each in its file: the solver's kind and variant
//! (`explicit_keys.rs`, `solver.rs`), the mesh (`mesh.rs`), the curves
//! and materials (`curves.rs`, `materials.rs`), the bodies and their
//! points (`bodies.rs`), the node sets (`node_sets.rs`), the conditions
//! and mesh motion (`conditions.rs`, `motion.rs`), the absorbing
//! boundaries (`absorbing.rs`), the loads
//! (`loads.rs`), the implicit solver's controls (`solver.rs`), the
//! outputs (`outputs.rs`) and an explicit run's setup (`explicit_run.rs`).
//! This file keeps the types they build and the checks they share.

mod absorbing;
mod bodies;
mod cam_clay;
mod conditions;
mod contact;
mod curves;
mod explicit_keys;
mod explicit_run;
mod initial_stress;
mod loads;
mod materials;
mod mesh;
mod motion;
mod node_sets;
mod outputs;
mod solver;
mod strength_reduction;

use std::collections::BTreeMap;

use mpm_mesh::{RegularGrid, SimplexMesh};
use mpm_solver::{
    BodyForcePath, Constraints, LoadStepping, MeshMotion, MeshMotionError, MovableMesh, MovingMesh,
    NewtonOptions, StepView,
};
use nalgebra::SVector;
use toml::Spanned;

use crate::SceneError;
use crate::material::{MaterialModel, MaterialParams};
use crate::source::SceneSource;
use crate::variant::{LockingKind, Variant};

use crate::format::{Axes, Field, Scene, TransferKind};

pub use absorbing::AbsorbingFace;
pub use contact::ContactSetup;
pub use explicit_keys::{DEFAULT_CFL, DEFAULT_OUTPUTS};
pub use loads::MANUFACTURED_FIELDS;
pub use motion::SceneMotion;
pub use strength_reduction::{Failure, StrengthReduction};

/// Largest number of grid nodes, simplices or material points a scene may
/// ask for (a guard against a typo allocating the machine's memory).
pub const MAX_ENTITIES: usize = 50_000_000;

const AXES: [&str; 3] = ["x", "y", "z"];

/// The grid faces, as node-set names: `x_min`, `x_max`, `y_min`, …
pub fn face_name(axis: usize, upper: bool) -> String {
    format!("{}_{}", AXES[axis], if upper { "max" } else { "min" })
}

/// A piecewise-linear load curve, constant beyond its first and last rows.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// `(time, factor)` rows, times strictly increasing; empty for the
    /// default ramp (factor = load factor).
    pub rows: Vec<[f64; 2]>,
}

impl Curve {
    /// The default: the factor equals the load factor.
    pub fn ramp() -> Self {
        Self { rows: Vec::new() }
    }

    /// The factor at load factor `t`.
    pub fn at(&self, t: f64) -> f64 {
        let r = &self.rows;
        let (Some(first), Some(last)) = (r.first(), r.last()) else {
            return t;
        };
        if t <= first[0] {
            return first[1];
        }
        if t >= last[0] {
            return last[1];
        }
        let k = r.partition_point(|row| row[0] <= t);
        let (a, b) = (r[k - 1], r[k]);
        a[1] + (t - a[0]) / (b[0] - a[0]) * (b[1] - a[1])
    }
}

/// Dirichlet conditions of a scene: per dof, the displacement reached
/// where its curve is 1 and the curve; conditions on sets that follow a
/// body; and the mesh motion, if any.
#[derive(Debug, Clone)]
pub struct SceneConstraints<const D: usize> {
    /// Per mesh dof `D * node + i`: `(displacement, curve index)`.
    dofs: Vec<Option<(f64, u16)>>,
    curves: Vec<Curve>,
    following: Vec<Following<D>>,
    motion: Option<MovingMesh<D, Free, SceneMotion<D>>>,
    /// The rigid tools of `kind = "contact"`.
    tools: Vec<mpm_solver::RigidTool<D>>,
    /// Per tool, its displacement where its curve is 1 and the curve.
    tool_motion: Vec<(SVector<f64, D>, u16)>,
}

/// No conditions: what a mesh motion wraps in a scene (the scene's own
/// conditions are checked after it).
#[derive(Debug, Clone, Copy)]
pub struct Free;

impl<const D: usize> Constraints<D> for Free {
    fn prescribed(&self, _: usize, _: usize, _: f64, _: f64) -> Option<f64> {
        None
    }
}

/// A displacement condition on the nodes supporting a body's boundary
/// points, found again at the start of every step.
#[derive(Debug, Clone)]
struct Following<const D: usize> {
    /// The boundary points.
    points: Vec<usize>,
    /// Initial node positions.
    nodes: Vec<SVector<f64, D>>,
    /// Which nodes support a boundary point this step.
    active: Vec<bool>,
    /// `u = d + G x` where the curve is 1.
    displacement: SVector<f64, D>,
    gradient: nalgebra::SMatrix<f64, D, D>,
    curve: u16,
}

impl<const D: usize> Following<D> {
    fn prescribed(&self, node: usize, component: usize, dc: f64) -> Option<f64> {
        if !self.active.get(node).copied().unwrap_or(false) {
            return None;
        }
        let x = self.nodes.get(node)?;
        // (G_ij dc) x_j: the increment of a homogeneous gradient.
        let affine = (0..D).fold(0.0, |u, j| u + self.gradient[(component, j)] * dc * x[j]);
        Some(self.displacement[component] * dc + affine)
    }
}

impl<const D: usize> SceneConstraints<D> {
    /// Number of prescribed dofs.
    pub fn len(&self) -> usize {
        self.dofs.iter().filter(|d| d.is_some()).count()
    }

    /// Whether nothing is prescribed.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Position at load factor `lambda` of the mesh node `node` whose
    /// initial position is `x0` (`x0` itself without a mesh motion).
    pub fn node_position(&self, node: usize, x0: &SVector<f64, D>, lambda: f64) -> SVector<f64, D> {
        match &self.motion {
            Some(m) => m.motion.position(node, x0, lambda),
            None => *x0,
        }
    }
}

impl<const D: usize> Constraints<D> for SceneConstraints<D> {
    const MOVES_MESH: bool = true;

    fn moves_mesh(&self) -> bool {
        self.motion.is_some()
    }

    fn begin_step(&mut self, step: &StepView<'_, D>) {
        for f in &mut self.following {
            f.active.iter_mut().for_each(|a| *a = false);
            for &p in &f.points {
                for v in step.nodes_of(p) {
                    if let Some(a) = f.active.get_mut(v) {
                        *a = true;
                    }
                }
            }
        }
    }

    fn move_mesh<M: MovableMesh<D>>(
        &mut self,
        mesh: &mut M,
        lambda: f64,
    ) -> Result<(), MeshMotionError> {
        match &mut self.motion {
            Some(m) => m.move_mesh(mesh, lambda),
            None => Ok(()),
        }
    }

    #[inline]
    fn prescribed(&self, node: usize, component: usize, lambda0: f64, lambda1: f64) -> Option<f64> {
        if let Some(m) = &self.motion
            && let Some(u) = m.prescribed(node, component, lambda0, lambda1)
        {
            return Some(u);
        }
        // The last body-following condition that holds the node.
        for f in self.following.iter().rev() {
            let c = &self.curves[f.curve as usize];
            if let Some(u) = f.prescribed(node, component, c.at(lambda1) - c.at(lambda0)) {
                return Some(u);
            }
        }
        let (u, curve) = (*self.dofs.get(node * D + component)?)?;
        if u == 0.0 {
            return Some(0.0);
        }
        let c = &self.curves[curve as usize];
        Some(u * (c.at(lambda1) - c.at(lambda0)))
    }

    fn tools(&self) -> &[mpm_solver::RigidTool<D>] {
        &self.tools
    }

    fn tool_increment(&self, tool: usize, lambda0: f64, lambda1: f64) -> SVector<f64, D> {
        match self.tool_motion.get(tool) {
            Some((u, curve)) => {
                let c = &self.curves[*curve as usize];
                u * (c.at(lambda1) - c.at(lambda0))
            }
            None => SVector::zeros(),
        }
    }
}

/// The background mesh of a scene.
#[derive(Debug, Clone)]
pub enum SceneMesh<const D: usize> {
    /// A regular grid.
    Grid(RegularGrid<D>),
    /// Linear triangles or tetrahedra.
    Simplex(Box<SimplexMesh<D>>),
}

impl<const D: usize> SceneMesh<D> {
    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        match self {
            SceneMesh::Grid(g) => g.node_count(),
            SceneMesh::Simplex(m) => m.node_count(),
        }
    }

    /// Position of node `v` (the origin for an id out of range).
    pub fn node_position(&self, v: usize) -> SVector<f64, D> {
        match self {
            SceneMesh::Grid(g) => g.node_position(v).unwrap_or_else(|_| SVector::zeros()),
            SceneMesh::Simplex(m) => m.nodes().get(v).copied().unwrap_or_else(SVector::zeros),
        }
    }
}

/// One body of the built scene.
#[derive(Debug, Clone, PartialEq)]
pub struct BuiltBody {
    /// Its name.
    pub name: String,
    /// Index into [`Problem::materials`].
    pub material: usize,
    /// Its points: `points` of the problem's arrays.
    pub points: std::ops::Range<usize>,
    /// Lattice step of its points per axis.
    pub step: Vec<f64>,
}

/// A material as built: its model after promotion (see
/// [`Problem::materials`]) and parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct BuiltMaterial {
    /// Name.
    pub name: String,
    /// Model the solver runs.
    pub model: MaterialModel,
    /// Parameters.
    pub params: MaterialParams,
    /// Density.
    pub density: f64,
}

/// Forces that follow one load curve: the curve and the force on every
/// point where the curve is 1.
#[derive(Debug, Clone)]
pub struct CurvedForces<const D: usize> {
    /// The curve.
    pub curve: Curve,
    /// Force per point (all points of the scene).
    pub force: Vec<SVector<f64, D>>,
}

/// What a scene with `[solver] kind = "explicit"` adds to its problem:
/// the time stepping, the transfer, the constant loads and the velocity
/// fixities. The implicit parts of the [`Problem`] (load stepping, Newton
/// controls, `constraints`, `body_force`, `point_forces`) are not used by
/// an explicit run.
#[derive(Debug, Clone)]
pub struct ExplicitSetup<const D: usize> {
    /// The simulated time the run ends at (s).
    pub end_time: f64,
    /// Simulated time between outputs (s).
    pub output_interval: f64,
    /// The time step rule.
    pub time_step: mpm_solver::TimeStep,
    /// The velocity transfer.
    pub transfer: TransferKind,
    /// Its FLIP fraction α (0 for `pic` and `tpic`, 1 for `flip` and
    /// `tflip`, `alpha` for `blend`).
    pub alpha: f64,
    /// `LockingKind::None` or `LockingKind::CellAveraged`.
    pub locking: LockingKind,
    /// Gravitational acceleration on every point (the sum of the gravity
    /// loads).
    pub gravity: SVector<f64, D>,
    /// Zero-velocity fixities of the fixed, roller and zero-displacement
    /// conditions, the constant velocities of `velocity` conditions and
    /// the friction walls of `friction` conditions and the dashpots of
    /// `absorbing` ones.
    pub fixities: mpm_solver::VelocityFixities,
    /// Initial velocity of every point.
    pub velocity: Vec<SVector<f64, D>>,
    /// Constant point forces (point loads and tractions), per point index.
    pub point_forces: Vec<(usize, SVector<f64, D>)>,
    /// Point forces that follow a curve over the simulated time (loads
    /// with a `curve`, gravity included: m_p g on each point).
    pub timed_forces: Vec<TimedForces<D>>,
    /// Material-point fixities (point, component, velocity), from
    /// `[[point_fixity]]`.
    pub point_fixities: Vec<(usize, usize, f64)>,
    /// On several processes: steps between two counts of the points per
    /// process (0: never).
    pub rebalance_every: usize,
    /// On several processes: the imbalance past which the cells are dealt
    /// anew.
    pub rebalance_threshold: f64,
    /// Multi-field contact between bodies, from `[[contact]]` (`None`:
    /// one velocity field).
    pub contact: Option<ContactSetup>,
}

/// Point forces of one explicit load with a curve: at simulated time t
/// the force on point p is `force · curve.at(t)` (t in seconds).
#[derive(Debug, Clone, PartialEq)]
pub struct TimedForces<const D: usize> {
    /// The factor over the simulated time.
    pub curve: Curve,
    /// (point, force where the curve is 1).
    pub forces: Vec<(usize, SVector<f64, D>)>,
}

/// `linear = { petsc = "..." }`: PETSc's options, and the located
/// refusal a program built without PETSc gives.
#[derive(Debug, Clone, PartialEq)]
pub struct PetscRequest {
    /// The options, as on PETSc's command line.
    pub options: String,
    /// `file:line:column: ...` at the `linear` key.
    pub without_petsc: String,
}

/// A scene ready to run.
#[derive(Debug, Clone)]
pub struct Problem<const D: usize> {
    /// The background mesh (a grid with its padding, or simplices).
    pub mesh: SceneMesh<D>,
    /// Padding cells on every side.
    pub padding: usize,
    /// The bodies, in file order; their points are consecutive.
    pub bodies: Vec<BuiltBody>,
    /// The materials, in file order. When the bodies use different models,
    /// every material runs with the most general one: a `hencky` material
    /// in a scene with `von_mises` ones is von Mises with an infinite yield
    /// stress, which never yields and answers with Hencky's stress and
    /// tangent.
    pub materials: Vec<BuiltMaterial>,
    /// Point positions.
    pub position: Vec<SVector<f64, D>>,
    /// Point volumes.
    pub volume: Vec<f64>,
    /// Point domain half-lengths.
    pub half_lengths: Vec<SVector<f64, D>>,
    /// Point masses.
    pub mass: Vec<f64>,
    /// Material index of every point.
    pub material_of_point: Vec<u32>,
    /// Body index of every point.
    pub body_of_point: Vec<u32>,
    /// Dirichlet conditions.
    pub constraints: SceneConstraints<D>,
    /// The elastic left Cauchy–Green tensor every point starts from, from
    /// its body's `initial_stress` (empty: every point stress-free).
    pub initial_be: Vec<nalgebra::Matrix3<f64>>,
    /// The history every point starts from (empty: its law's default):
    /// the state of `initial_stress` (Cam-Clay's preconsolidation
    /// pressure).
    pub initial_history: Vec<crate::material::SceneHistory>,
    /// Proportional body force per point (empty if none).
    pub body_force: Vec<SVector<f64, D>>,
    /// Proportional point forces.
    pub point_forces: Vec<(usize, SVector<f64, D>)>,
    /// Forces following load curves.
    pub curved: Vec<CurvedForces<D>>,
    /// Manufactured body forces: force on point `p` at load factor λ.
    pub manufactured: Vec<BodyForcePath<D>>,
    /// Load stepping.
    pub stepping: LoadStepping,
    /// Newton controls.
    pub newton: NewtonOptions,
    /// `linear = { petsc = "..." }`: the implicit solver's linear solves
    /// go to PETSc (in a program built with it) with
    /// [`NewtonOptions::linear`]'s iterative tolerances.
    pub petsc: Option<PetscRequest>,
    /// The variant.
    pub variant: Variant,
    /// The patch (parent element) of every element of a simplex mesh split
    /// from quadratic parents (for F-patch), `None` otherwise.
    pub patch_of_element: Option<Vec<usize>>,
    /// Reaction histories.
    pub reactions: Vec<ReactionOutput<D>>,
    /// Probes: name and the point nearest the location.
    pub probes: Vec<(String, usize)>,
    /// VTU files every this many steps.
    pub every: usize,
    /// VTU fields.
    pub fields: Vec<Field>,
    /// Write a PNG of the final state.
    pub png: bool,
    /// The explicit solver's setup, for a scene with `[solver] kind =
    /// "explicit"` (run it with `run_explicit` (the `mpm-dispatch` crate)); `None` for the
    /// implicit solver.
    pub explicit: Option<ExplicitSetup<D>>,
    /// What the scene may not mean but is allowed: a simplex mesh's
    /// slivers and coincident nodes ([`mpm_mesh::MeshQuality::warnings`]),
    /// each prefixed by where it comes from. `mpm run` prints them and
    /// writes them into `summary.json`.
    pub warnings: Vec<String>,
    /// `[strength_reduction]`: run in trials of reduced strength for a
    /// factor of safety; `None` for one run.
    pub strength_reduction: Option<StrengthReduction>,
}

/// A reaction history of `[[output.reaction]]`: the sum of the reactions
/// on a node set and, if asked, their moment about a point.
#[derive(Debug, Clone, PartialEq)]
pub struct ReactionOutput<const D: usize> {
    /// File name stem: `reaction_<name>.csv`.
    pub name: String,
    /// The set's mesh nodes (sorted).
    pub nodes: Vec<usize>,
    /// The point the moment is taken about.
    pub about: Option<SVector<f64, D>>,
}

impl<const D: usize> ReactionOutput<D> {
    /// The sum of the step's reactions on the set's nodes.
    pub fn total(&self, report: &mpm_solver::StepReport<D>) -> SVector<f64, D> {
        report.reaction_on(&self.nodes)
    }

    /// The moment $\sum_v (\mathbf x_v - \mathbf c)\times\mathbf r_v$ of
    /// the step's reactions on the set about `about` (`None` without it);
    /// in 2D only the third component is non-zero. $\mathbf x_v$ is where
    /// the step's material at the node ends: the node's position in the
    /// mesh at the start of the step plus its prescribed increment (its
    /// free components, where the reaction is zero, at their start
    /// value). With it the moments of all reactions balance, as the
    /// internal forces of a symmetric stress have no resultant moment
    /// about any point in the configuration the step's gradients are taken
    /// in.
    pub fn moment(
        &self,
        problem: &Problem<D>,
        report: &mpm_solver::StepReport<D>,
    ) -> Option<[f64; 3]> {
        let c = self.about?;
        let cons = &problem.constraints;
        let lift =
            |v: &SVector<f64, D>| nalgebra::Vector3::from_fn(|i, _| if i < D { v[i] } else { 0.0 });
        let m = report
            .node_reactions
            .iter()
            .filter(|(v, _)| self.nodes.binary_search(v).is_ok())
            .fold(nalgebra::Vector3::zeros(), |m, (v, r)| {
                let mut x = cons.node_position(*v, &problem.mesh.node_position(*v), report.lambda0);
                for i in 0..D {
                    x[i] += cons
                        .prescribed(*v, i, report.lambda0, report.lambda1)
                        .unwrap_or(0.0);
                }
                m + lift(&(x - c)).cross(&lift(r))
            });
        Some([m[0], m[1], m[2]])
    }
}

/// Lengths, positivity and finiteness checks with located errors.
struct Check<'a> {
    src: &'a SceneSource,
}

impl Check<'_> {
    fn positive(&self, v: &Spanned<f64>, what: &str) -> Result<f64, SceneError> {
        let x = *v.get_ref();
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.src.at(v, format!("{what} must be positive, got {x}")))
        }
    }

    fn at_least(&self, v: &Spanned<usize>, min: usize, what: &str) -> Result<usize, SceneError> {
        let x = *v.get_ref();
        if x >= min {
            Ok(x)
        } else {
            Err(self
                .src
                .at(v, format!("{what} must be at least {min}, got {x}")))
        }
    }
}

/// Unique names of a section, or an error at the second use.
fn unique_names<'a>(
    names: impl Iterator<Item = &'a Spanned<String>>,
    section: &str,
    src: &SceneSource,
) -> Result<BTreeMap<String, usize>, SceneError> {
    let mut map = BTreeMap::new();
    for (k, name) in names.enumerate() {
        if name.get_ref().is_empty() {
            return Err(src.at(name, format!("a {section} needs a non-empty name")));
        }
        if map.insert(name.get_ref().clone(), k).is_some() {
            return Err(src.at(
                name,
                format!("a second {section} named `{}`", name.get_ref()),
            ));
        }
    }
    Ok(map)
}

/// `name` looked up in `map`, or an error listing the names there are.
fn lookup(
    map: &BTreeMap<String, usize>,
    name: &Spanned<String>,
    section: &str,
    src: &SceneSource,
) -> Result<usize, SceneError> {
    lookup_ref(map, name, section, src).copied()
}

/// [`lookup`] for any value, by reference.
fn lookup_ref<'m, V>(
    map: &'m BTreeMap<String, V>,
    name: &Spanned<String>,
    section: &str,
    src: &SceneSource,
) -> Result<&'m V, SceneError> {
    map.get(name.get_ref()).ok_or_else(|| {
        let known: Vec<&str> = map.keys().map(String::as_str).collect();
        src.at(
            name,
            format!(
                "no {section} named `{}`; the scene has: {}",
                name.get_ref(),
                if known.is_empty() {
                    "none".to_owned()
                } else {
                    known.join(", ")
                }
            ),
        )
    })
}

/// The components of a per-axis table named `key`, checked against the
/// dimension (at least one given, all finite).
fn axes_of<const D: usize>(
    d: &Spanned<Axes>,
    key: &str,
    src: &SceneSource,
) -> Result<[Option<f64>; 3], SceneError> {
    let values = d.get_ref().get();
    if let Some(axis) = (D..3).find(|&i| values[i].is_some()) {
        return Err(src.at(d, format!("a {D}D scene has no {} component", AXES[axis])));
    }
    if values.iter().all(Option::is_none) {
        return Err(src.at(d, format!("`{key}` needs at least one of x, y, z")));
    }
    if let Some(v) = values.iter().flatten().find(|v| !v.is_finite()) {
        return Err(src.at(d, format!("`{key}` must be finite, got {v}")));
    }
    Ok(values)
}

impl<const D: usize> Problem<D> {
    /// Builds the scene with at least `basis_padding` cells of padding
    /// (and at least what the scene's basis needs,
    /// [`SolverSpec::padding`](crate::format::SolverSpec::padding)).
    ///
    /// # Errors
    /// [`SceneError::Scene`] (or [`SceneError::Override`]) at the value
    /// that is wrong, [`SceneError::SceneUnlocated`] for what has no single
    /// place.
    pub fn build(
        scene: &Scene,
        src: &SceneSource,
        basis_padding: usize,
    ) -> Result<Self, SceneError> {
        let dir = std::path::Path::new(src.origin())
            .parent()
            .map(std::path::Path::to_path_buf)
            .unwrap_or_default();
        Self::build_in(scene, src, basis_padding, &dir)
    }

    /// [`Self::build`] with Gmsh files relative to `mesh_dir` (the
    /// scene file's directory).
    ///
    /// # Errors
    /// As [`Self::build`].
    pub fn build_in(
        scene: &Scene,
        src: &SceneSource,
        basis_padding: usize,
        mesh_dir: &std::path::Path,
    ) -> Result<Self, SceneError> {
        let s = &scene.solver;
        // The solver's kind and the variant decide what the rest may be.
        let explicit_keys = explicit_keys::solver_keys(s, src)?;
        let explicit = explicit_keys.is_some();
        let variant = solver::variant(s, src)?;
        let basis_padding = basis_padding.max(s.padding());
        let mesh = mesh::mesh::<D>(scene, &variant, explicit, basis_padding, mesh_dir, src)?;
        let curves = curves::curves(&scene.curves, src)?;
        let (material_names, materials) = materials::materials(&scene.materials, explicit, src)?;
        let bodies = bodies::bodies(
            &scene.bodies,
            &mesh,
            &material_names,
            &materials,
            explicit,
            src,
        )?;
        let (initial_be, initial_history) =
            initial_stress::initial_state_of_points(&scene.bodies, &bodies, &materials, src)?;
        let sets = node_sets::node_sets(&scene.node_sets, &mesh, &bodies, src)?;
        let conditions = conditions::conditions(scene, &mesh, &sets, &curves, explicit, src)?;
        conditions::refuse_unreachable_gap_checks(scene, variant.basis, src)?;
        let absorbing = absorbing::absorbing_faces(
            scene,
            &mesh,
            &sets,
            &material_names,
            &materials,
            explicit,
            src,
        )?;
        let loads = loads::loads(
            &scene.loads,
            &bodies,
            &materials,
            &curves,
            &sets.faces,
            explicit,
            src,
        )?;
        let (stepping, newton) =
            solver::newton_and_stepping(s, src, matches!(mesh.mesh, SceneMesh::Grid(_)))?;
        let petsc = solver::petsc_request(s, src)?;
        let (every, reactions, probes, fields) = outputs::outputs::<D>(
            &scene.output,
            explicit,
            src,
            &|name| sets.set_of(name, src),
            &|x| bodies.points.nearest(x),
        )?;
        let strength_reduction =
            strength_reduction::strength_reduction(scene, &probes, explicit, src)?;
        let contact = contact::contact(scene, explicit, !absorbing.is_empty(), &bodies, src)?;
        let explicit =
            explicit_run::explicit_run(explicit_keys, scene, &mesh, &materials, &bodies, src)?.map(
                |run| {
                    run.setup(
                        &conditions.velocity_dofs,
                        &conditions.walls,
                        loads.explicit,
                        &absorbing,
                        contact,
                    )
                },
            );

        let points = bodies.points;
        Ok(Self {
            warnings: mesh.warnings,
            mesh: mesh.mesh,
            padding: mesh.padding,
            bodies: bodies.bodies,
            materials,
            position: points.position,
            volume: points.volume,
            half_lengths: points.half_lengths,
            mass: points.mass,
            material_of_point: points.material,
            body_of_point: points.body,
            constraints: conditions.constraints,
            initial_be,
            initial_history,
            body_force: loads.body_force,
            point_forces: loads.point_forces,
            curved: loads.curved,
            manufactured: loads.manufactured,
            stepping,
            newton,
            petsc,
            variant,
            patch_of_element: mesh.patch_of_element,
            reactions,
            probes,
            every,
            fields,
            png: scene.output.png,
            explicit,
            strength_reduction,
        })
    }

    /// Number of material points.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether the scene has no points (never, once built).
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curves_interpolate_and_hold_beyond_their_ends() {
        let c = Curve {
            rows: vec![[0.0, 0.0], [0.5, 1.0], [1.0, 1.0]],
        };
        assert_eq!(c.at(-1.0), 0.0);
        assert_eq!(c.at(0.25), 0.5);
        assert_eq!(c.at(0.75), 1.0);
        assert_eq!(c.at(2.0), 1.0);
        assert_eq!(Curve::ramp().at(0.3), 0.3);
    }
}
