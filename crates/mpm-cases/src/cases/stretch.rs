//! Simple stretch of a cube on tetrahedra with a moving mesh (Wang et al.
//! 2021 §5.3, Figs. 12–14, Table 1): a 2 m cube, E = 1 kPa, ν = 0, von
//! Mises (eq. 16) with ρ_y = 400 Pa and no hardening; rollers on the faces
//! x = 0, y = 0, z = 0; the face y = 2 m pulled to y = 4 m over 5 equal
//! steps. The mesh stretches along y with the pulled face (moving-mesh
//! condition), so points never cross element faces along y, but after
//! yielding the plastic flow is isochoric and the body narrows, so they
//! cross along x and z.
//!
//! # The analytic stress
//! The stress is uniaxial and homogeneous. Eq. (16) reads
//! $f = \varrho - \varrho_y$ with $\varrho = \sqrt{2J_2}$; a uniaxial
//! Kirchhoff stress $\tau$ has deviator $\tau\,\mathrm{diag}(-\frac13,
//! \frac23, -\frac13)$ and $2J_2 = \frac23\tau^2$, so it yields at
//! $$\tau_a = \sqrt{3/2}\;\varrho_y \approx 489.9\ \text{Pa}$$
//! for $\varrho_y = 400$ Pa, and with perfect plasticity stays there. The
//! paper quotes $\tau_a = \varrho_y = 400$ Pa, which is the same model
//! when its 400 Pa is the uniaxial (von Mises equivalent) yield stress
//! $\sqrt{3J_2}$: $\varrho_y = 400\sqrt{2/3} \approx 326.6$ Pa in eq. (16).
//! Elastically ($\nu = 0$) the stress is $E\ln\lambda$ with no lateral
//! strain; it yields at $\ln\lambda = \tau_a/E$ ($\lambda = 1.63$ for
//! 489.9 Pa, 1.49 for 400 Pa), before the final $\lambda = 2$.
//!
//! Error (Wang 2021 §5.3): $\frac1V\sum_p |\tau^p_{yy} - \tau_a|\,V_p /
//! \tau_a$, with $V_p$ the initial volumes and $V = 8$ m³.

use std::path::PathBuf;

use mpm_solver::SolverError;
use nalgebra::Matrix3;
use serde_json::json;

use super::{Case, Measured, Run, Solve, Solved};
use crate::material::MaterialModel;
use crate::run::RunOutput;
use crate::scene::format::{
    Axes, BodySpec, BoundaryKind, BoundarySpec, MaterialSpec, MeshSpec, MotionSpec, Placement,
    RegionSpec, SolverSpec,
};
use crate::scene::{Problem, Scene};
use crate::session::Session;
use crate::variant::Variant;

crate::case_params! {
    /// Parameters of the stretch case (defaults: Wang 2021 Table 1).
    pub struct StretchParams {
        /// Cells along x and z (Table 1's nelsx = nelsz: 2, 4, 8, 16); two
        /// along y. Each cell is split into six ten-node tetrahedra (the
        /// F-patch parents), each into eight linear children.
        pub cells: usize = 2,
        /// Edge of the cube (m).
        pub size: f64 = 2.0,
        /// Displacement of the face y = size (m).
        pub stretch: f64 = 2.0,
        /// Young's modulus (Pa).
        pub youngs_modulus: f64 = 1e3,
        /// Poisson's ratio.
        pub poisson_ratio: f64 = 0.0,
        /// ρ_y of eq. (16) (Pa).
        pub yield_stress: f64 = 400.0,
        /// Linear isotropic hardening modulus H of the von Mises law (Pa);
        /// the paper's material is perfectly plastic (0). The analytic
        /// stress of this case holds for H = 0 only.
        pub hardening: f64 = 0.0,
        /// Number of equal load steps.
        pub load_steps: usize = 5,
        /// Newton tolerance on eq. (40).
        pub tolerance: f64 = 1e-9,
        /// Start each step from the previous increment (the solver's secant
        /// predictor): after first yield the perfectly plastic equations
        /// also admit necked solutions, and Newton started from zero
        /// increments at the free nodes finds one (as in the shear case).
        pub predictor: bool = true,
        /// Whether the pulled face is also held laterally (x and z fixed),
        /// instead of free to contract.
        pub clamped_top: bool = false,
        /// A Gmsh MSH 4.1 file of the cube instead of the generated mesh:
        /// four-node tetrahedra, or ten-node ones (split into eight linear
        /// children each), with physical surfaces `x0`, `y0`, `z0` (rollers)
        /// and `y1` (pulled); relative paths start at the scene file.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub mesh: Option<PathBuf> = None,
    }
}

/// The registered case (see [`crate::cases::Case`]).
#[derive(Debug, Clone, Copy)]
pub struct StretchCase;

impl Case for StretchCase {
    const NAME: &'static str = "stretch";
    const ABOUT: &'static str =
        "Wang 2021 §5.3: simple stretch of a cube on tetrahedra with a moving mesh (Table 1)";
    type Params = StretchParams;

    fn scene(p: &StretchParams, variant: &Variant) -> Result<Scene, SolverError> {
        scene(p, variant)
    }
}

impl StretchParams {
    /// The analytic uniaxial Kirchhoff stress at the end (no hardening):
    /// $\min(E\ln\lambda, \sqrt{3/2}\,\varrho_y)$ with
    /// $\lambda = (\text{size} + \text{stretch})/\text{size}$ (Hencky is
    /// linear in the log strain, so the elastic branch holds for any ν).
    pub fn analytic_stress(&self) -> f64 {
        let elastic = self.youngs_modulus * ((self.size + self.stretch) / self.size).ln();
        elastic.min(1.5f64.sqrt() * self.yield_stress)
    }
}

/// The stretch's result.
#[derive(Debug, Clone)]
pub struct StretchResult {
    /// The run.
    pub output: RunOutput<3>,
    /// Normalised Kirchhoff stress error of Wang 2021 §5.3.
    pub error: f64,
    /// The analytic stress $\tau_a$ (Pa).
    pub analytic_stress: f64,
    /// Mean, smallest and largest $\tau_{yy}$ over the points (Pa).
    pub tau_yy: (f64, f64, f64),
    /// Number of material points.
    pub material_points: usize,
    /// Number of linear tetrahedra.
    pub elements: usize,
}

/// The stretch as a typed scene (the scene of `scenes/wang2021_stretch.toml`
/// with the parameters filled in): the cube of `cells` × 2 × `cells`
/// cells, each split into six ten-node tetrahedra and those into their
/// eight linear children (or the Gmsh file `mesh`), Keast's 11 points per
/// child, the faces x0, y0, z0 on rollers, the mesh stretching along y
/// with the face y1 driven (also laterally with `clamped_top`).
///
/// # Errors
/// [`SolverError::InvalidInput`] for a variant other than standard MPM or
/// F-patch.
pub fn scene(p: &StretchParams, variant: &Variant) -> Result<Scene, SolverError> {
    // The built-in mesh splits ten-node parents (patches); a Gmsh mesh has
    // patches when it is quadratic, which the scene checks.
    variant
        .require_simplex("tetrahedra", true)
        .map_err(SolverError::InvalidInput)?;
    let a = p.size;
    let mesh = match &p.mesh {
        Some(path) => MeshSpec::gmsh(path.display().to_string(), 3),
        None => MeshSpec::simplex_box([0.0; 3], [a; 3], [p.cells, 2, p.cells]).with_patches(true),
    };
    let components: &[&str] = if p.clamped_top {
        &["x", "y", "z"]
    } else {
        &["y"]
    };
    let motion = MotionSpec::stretch("y", "y1")
        .with_stretch(0.0, a, p.stretch)
        .with_components(components);
    let material = MaterialSpec::new(
        "cube",
        MaterialModel::VonMises,
        p.youngs_modulus,
        p.poisson_ratio,
        0.0,
    )
    .with_yield_stress(p.yield_stress)
    .with_hardening(p.hardening);
    let body = BodySpec::new("cube", "cube", RegionSpec::box_between([0.0; 3], [a; 3]))
        .with_placement(Placement::Keast11);
    let roller = |set: &str, axes: Axes| {
        BoundarySpec::on(set, BoundaryKind::Displacement).with_displacement(axes)
    };
    let free = Axes::default();
    Ok(
        Scene::new(mesh.with_motion(motion), vec![material], vec![body])
            .with_boundary(roller("x0", free.with_x(0.0)))
            .with_boundary(roller("y0", free.with_y(0.0)))
            .with_boundary(roller("z0", free.with_z(0.0)))
            .with_solver(
                SolverSpec::implicit(variant, p.load_steps, p.tolerance)
                    .with_predictor(p.predictor),
            ),
    )
}

impl Solve<3> for StretchCase {
    type Built = Problem<3>;
    type Result = StretchResult;

    /// Runs the built stretch (standard MPM or F-patch; UL or PC) and
    /// measures it against the uniaxial stress.
    fn solve(p: &StretchParams, problem: &Problem<3>, run: Run<'_, 3>) -> Solved<StretchResult> {
        let output = run.on(problem)?;
        let elements = match &problem.mesh {
            crate::scene::build::SceneMesh::Simplex(m) => m.element_count(),
            crate::scene::build::SceneMesh::Grid(_) => 0,
        };
        let body = problem;
        let tau_a = p.analytic_stress();
        let taus: Vec<f64> = output
            .last
            .sigma
            .iter()
            .zip(&output.last.f)
            .map(|(s, f)| s[4] * Matrix3::from_row_slice(f).determinant())
            .collect();
        let total: f64 = body.volume.iter().sum();
        let error = taus
            .iter()
            .zip(&body.volume)
            .map(|(t, v)| (t - tau_a).abs() * v)
            .sum::<f64>()
            / (total * tau_a);
        let mean = taus
            .iter()
            .zip(&body.volume)
            .map(|(t, v)| t * v)
            .sum::<f64>()
            / total;
        let (lo, hi) = taus
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| {
                (a.min(t), b.max(t))
            });
        Ok(StretchResult {
            output,
            error,
            analytic_stress: tau_a,
            tau_yy: (mean, lo, hi),
            material_points: problem.len(),
            elements,
        })
    }

    fn measured(r: &StretchResult) -> Measured<'_, 3> {
        let (mean, min, max) = r.tau_yy;
        Measured::new(&r.output, r.material_points, Some(r.error)).with([
            ("analytic_stress", json!(r.analytic_stress)),
            ("tau_yy_mean", json!(mean)),
            ("tau_yy_min", json!(min)),
            ("tau_yy_max", json!(max)),
            ("elements", json!(r.elements)),
        ])
    }

    /// A relative mesh path is taken from the scene file's directory.
    fn prepare(p: &mut StretchParams, session: &Session) {
        session.resolve(&mut p.mesh);
    }
}
