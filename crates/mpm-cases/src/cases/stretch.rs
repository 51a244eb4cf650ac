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

use mpm_basis::LinearSimplex;
use mpm_constitutive::VonMises;
use mpm_mesh::{BoxMesh, GmshElements, PatchMesh, SimplexMesh, read_msh};
use mpm_solver::{
    Formulation, LoadStepping, MovingMesh, NewtonOptions, NoUpdate, NodalConstraints,
    PreviouslyConverged, SolverError, StepReport, Stretch, UpdatedLagrangian,
};
use nalgebra::{Matrix3, Vector3};

use crate::body::{Body, SimplexRule};
use crate::run::{Loads, RunControl, RunOutput, Setup, Snapshot, simulate};
use crate::variant::{FormulationKind, Variant};

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

impl crate::cases::Case for StretchCase {
    const NAME: &'static str = "stretch";
    const ABOUT: &'static str =
        "Wang 2021 §5.3: simple stretch of a cube on tetrahedra with a moving mesh (Table 1)";
    type Params = StretchParams;

    fn run(
        mut p: StretchParams,
        session: &crate::session::Session,
    ) -> Result<(), crate::CasesError> {
        use crate::session::summary;
        session.resolve(&mut p.mesh);
        let mesh = mesh(&p)?;
        let (mut obs, control) = session.start(&p, mesh)?;
        let r = run(&p, &p.variant(), &control, |s, rep, snap| {
            obs.step(s, rep, snap)
        })?;
        let mut results = serde_json::Map::new();
        results.insert(
            "analytic_stress".into(),
            serde_json::json!(r.analytic_stress),
        );
        results.insert("tau_yy_mean".into(), serde_json::json!(r.tau_yy.0));
        results.insert("tau_yy_min".into(), serde_json::json!(r.tau_yy.1));
        results.insert("tau_yy_max".into(), serde_json::json!(r.tau_yy.2));
        results.insert("elements".into(), serde_json::json!(r.elements));
        let s = summary(
            Self::NAME,
            p.variant(),
            r.material_points,
            &r.output,
            Some(r.error),
            results,
            &p,
        );
        obs.finish(s)
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

/// The background mesh of linear tetrahedra.
pub fn mesh(p: &StretchParams) -> Result<SimplexMesh<3>, SolverError> {
    let invalid = SolverError::from;
    let quadratic = match &p.mesh {
        Some(path) => match read_msh::<3>(path).map_err(invalid)?.elements {
            GmshElements::Linear(mesh) => return Ok(mesh),
            GmshElements::Quadratic(q) => q,
        },
        None => BoxMesh::new(
            Vector3::zeros(),
            Vector3::from_element(p.size),
            [p.cells, 2, p.cells],
        )
        .quadratic_mesh()
        .map_err(invalid)?,
    };
    Ok(PatchMesh::from_parents(&quadratic)
        .map_err(invalid)?
        .into_mesh())
}

/// Runs the stretch with `variant` (standard MPM on tetrahedra; UL or PC).
pub fn run<O>(
    p: &StretchParams,
    variant: &Variant,
    control: &RunControl,
    observer: O,
) -> Result<StretchResult, SolverError>
where
    O: FnMut(usize, &StepReport<3>, &Snapshot) -> Result<(), SolverError>,
{
    variant
        .require_standard_mpm("tetrahedra")
        .map_err(SolverError::InvalidInput)?;
    match variant.formulation {
        FormulationKind::Pc => go::<PreviouslyConverged, _>(p, control, observer),
        FormulationKind::Ul => go::<UpdatedLagrangian, _>(p, control, observer),
    }
}

fn go<F: Formulation, O>(
    p: &StretchParams,
    control: &RunControl,
    observer: O,
) -> Result<StretchResult, SolverError>
where
    O: FnMut(usize, &StepReport<3>, &Snapshot) -> Result<(), SolverError>,
{
    let mesh = mesh(p)?;
    let all: Vec<usize> = (0..mesh.element_count()).collect();
    let body = Body::fill_simplices(&mesh, &all, SimplexRule::Keast11);
    let set = |name: &str| -> Result<Vec<usize>, SolverError> {
        mesh.node_sets()
            .get(name)
            .map(<[usize]>::to_vec)
            .ok_or_else(|| SolverError::InvalidInput(format!("the mesh has no node set `{name}`")))
    };
    let mut rollers = NodalConstraints::<3>::new(mesh.node_count());
    for (axis, name) in ["x0", "y0", "z0"].into_iter().enumerate() {
        rollers.fix(set(name)?, axis);
    }
    let motion = Stretch {
        axis: 1,
        origin: 0.0,
        length: p.size,
        extension: p.stretch,
    };
    let constraints = MovingMesh::new(
        rollers,
        motion,
        mesh.nodes().to_vec(),
        &set("y1")?,
        [p.clamped_top, true, p.clamped_top],
    );
    let law = VonMises::new(
        p.youngs_modulus,
        p.poisson_ratio,
        p.yield_stress,
        p.hardening,
    )
    .map_err(SolverError::from)?;
    let elements = mesh.element_count();
    let setup = Setup {
        grid: mesh,
        body: &body,
        density: 0.0,
        law,
        loads: Loads::default(),
        constraints,
        stepping: LoadStepping::uniform(p.load_steps),
        newton: NewtonOptions {
            tolerance: p.tolerance,
            predictor: p.predictor,
            ..NewtonOptions::default()
        },
    };
    let output = simulate::<3, LinearSimplex, F, NoUpdate, _, _, _>(
        setup,
        LinearSimplex,
        NoUpdate,
        control,
        observer,
    )?;
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
        material_points: body.len(),
        elements,
    })
}
