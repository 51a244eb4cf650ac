//! Compaction of an elastic column under self weight (Coombs et al. 2020
//! §7.1, Figs. 6–8): a 50 m column, one cell wide, base fixed vertically,
//! sides fixed horizontally, E = 1 MPa, ν = 0, ρ₀ = 80 kg/m³, g = 10 m/s²
//! applied over 20 equal load steps.
//!
//! Reference: the vertical Cauchy stress
//! $\sigma^a_{zz} = -\varrho_0 g (l_0 - Z)$ (eq. 41, compression negative,
//! $Z$ the initial height) and the error norm (eq. 42)
//! $\sum_p |\sigma_{zz,p} - \sigma^a_{zz}(Z_p)| V^0_p / (\varrho_0 g l_0 V_0)$.

use mpm_solver::SolverError;

use super::{Case, Measured, Run, Solve, Solved};
use crate::material::MaterialModel;
use crate::run::{RunOutput, Snapshot};
use crate::scene::format::{
    BoundaryKind, BoundarySpec, LoadSpec, MaterialSpec, MeshSpec, SolverSpec,
};
use crate::scene::{Problem, Scene};
use crate::variant::Variant;

crate::case_params! {
    /// Parameters of the column case (defaults: the paper's values).
    pub struct ColumnParams {
        /// Cell size h (m); the column is one cell wide.
        pub h: f64 = 50.0 / 16.0,
        /// Material points per cell per direction.
        pub points_per_cell: usize = 2,
        /// Initial height l₀ (m).
        pub height: f64 = 50.0,
        /// Young's modulus (Pa).
        pub youngs_modulus: f64 = 1e6,
        /// Poisson's ratio.
        pub poisson_ratio: f64 = 0.0,
        /// Density ϱ₀ (kg/m³).
        pub density: f64 = 80.0,
        /// Gravitational acceleration g (m/s²).
        pub gravity: f64 = 10.0,
        /// Number of equal load steps.
        pub load_steps: usize = 20,
        /// Newton tolerance on eq. (40).
        pub tolerance: f64 = 1e-9,
        /// Constitutive model (the paper's: Hencky elasticity).
        pub material: MaterialModel = MaterialModel::Hencky,
        /// Yield stress ρ_y (Pa) for plastic models.
        pub yield_stress: Option<f64> = None,
        /// Linear hardening modulus (Pa) for plastic models.
        pub hardening: f64 = 0.0,
    }
}

/// The registered case (see [`crate::cases::Case`]).
#[derive(Debug, Clone, Copy)]
pub struct ColumnCase;

impl Case for ColumnCase {
    const NAME: &'static str = "column";
    const ABOUT: &'static str = "Coombs 2020 §7.1: elastic column compacting under self weight (analytic eq. 41, error eq. 42)";
    type Params = ColumnParams;

    fn scene(p: &ColumnParams, variant: &Variant) -> Result<Scene, SolverError> {
        scene(p, variant)
    }
}

impl ColumnParams {
    /// The analytic vertical Cauchy stress at initial height `z` (eq. 41).
    pub fn analytic_sigma_zz(&self, z: f64) -> f64 {
        -self.density * self.gravity * (self.height - z)
    }

    /// The normalised stress error of eq. (42) for a final state whose
    /// points started at heights `z0` with volumes `v0`.
    pub fn error(&self, last: &Snapshot, z0: &[f64], v0: &[f64]) -> f64 {
        let total: f64 = v0.iter().sum();
        let sum: f64 = last
            .sigma
            .iter()
            .zip(z0)
            .zip(v0)
            .map(|((s, z), v)| (s[4] - self.analytic_sigma_zz(*z)).abs() * v)
            .sum();
        sum / (self.density * self.gravity * self.height * total)
    }
}

/// The column's result.
#[derive(Debug, Clone)]
pub struct ColumnResult {
    /// The run.
    pub output: RunOutput<2>,
    /// Error of eq. (42).
    pub error: f64,
    /// Number of material points.
    pub material_points: usize,
}

/// The column as a typed scene (the scene of `scenes/coombs2020_column.toml`
/// with the parameters and variant filled in): a grid one cell wide that
/// spans the column exactly, with the padding the basis needs; every node
/// held horizontally (both faces of the one-cell grid, padding included),
/// the base and the padding below it held vertically; gravity on the
/// column's weight.
///
/// # Errors
/// [`SolverError::InvalidInput`] when `h` does not divide the height.
pub fn scene(p: &ColumnParams, variant: &Variant) -> Result<Scene, SolverError> {
    let cells_y = super::cells_along(p.h, p.height, "the column height")?;
    let material = MaterialSpec::new(
        "column",
        p.material,
        p.youngs_modulus,
        p.poisson_ratio,
        p.density,
    );
    let material = match p.yield_stress {
        Some(y) => material.with_yield_stress(y).with_hardening(p.hardening),
        None => material,
    };
    let mesh = MeshSpec::grid([0.0, 0.0], [p.h, p.height], [1, cells_y]);
    Ok(
        super::one_block(mesh, material, [p.h, p.height], p.points_per_cell)
            .with_boundary(BoundarySpec::on("x_min", BoundaryKind::Roller))
            .with_boundary(BoundarySpec::on("x_max", BoundaryKind::Roller))
            .with_boundary(BoundarySpec::on("y_min", BoundaryKind::Roller))
            .with_load(LoadSpec::gravity([0.0, -p.gravity]))
            .with_solver(SolverSpec::implicit(variant, p.load_steps, p.tolerance)),
    )
}

impl Solve<2> for ColumnCase {
    type Built = Problem<2>;
    type Result = ColumnResult;

    /// Runs the built column and measures it against eq. (42).
    fn solve(p: &ColumnParams, problem: &Problem<2>, run: Run<'_, 2>) -> Solved<ColumnResult> {
        let output = run.on(problem)?;
        let z0: Vec<f64> = problem.position.iter().map(|x| x[1]).collect();
        let error = p.error(&output.last, &z0, &problem.volume);
        Ok(ColumnResult {
            output,
            error,
            material_points: problem.len(),
        })
    }

    fn measured(r: &ColumnResult) -> Measured<'_, 2> {
        Measured::new(&r.output, r.material_points, Some(r.error))
    }
}
