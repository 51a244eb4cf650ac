//! Elasto-plastic collapse of a block under self weight (Coombs et al.
//! 2020 §7.5, Figs. 20–22, Tables 6–8): a 16 m × 8 m plane-strain block, of
//! which the symmetric half (8 m × 8 m) is modelled with rollers on the
//! base and the left edge; E = 1 MPa, ν = 0.3, von Mises with
//! ρ_y = 20 kPa (perfect plasticity), body force −10 kN/m³ over 40 equal
//! load steps.
//!
//! Reference values: Table 6 (standard MPM) and Table 7 (GIMP, CPDI2) give
//! the final horizontal extent and maximum height of the body. The paper
//! measures them at the edge of the material points' domains, not at the
//! points: for standard MPM, $\max_p(x_p + l^0_p)$ with $l^0_p$ the
//! initial half-spacing of the points. With that definition our standard
//! MPM results agree with Table 6 to about 1e-3 m (h = 1 m, 3² and 6²
//! points per cell), while the bare point positions fall short by exactly
//! $l^0_p$ (1.2 % and 2.7 % for 3²).

use mpm_solver::SolverError;
use serde_json::json;

use super::{Case, Measured, Run, Solve, Solved};
use crate::material::MaterialModel;
use crate::run::RunOutput;
use crate::scene::format::{
    BoundaryKind, BoundarySpec, LoadSpec, MaterialSpec, MeshSpec, SolverSpec,
};
use crate::scene::{Problem, Scene};
use crate::variant::Variant;

crate::case_params! {
    /// Parameters of the collapse case (defaults: the paper's values).
    pub struct CollapseParams {
        /// Cell size h (m).
        pub h: f64 = 1.0,
        /// Material points per cell per direction.
        pub points_per_cell: usize = 3,
        /// Width of the modelled half block (m).
        pub width: f64 = 8.0,
        /// Height of the block l₀ (m).
        pub height: f64 = 8.0,
        /// Young's modulus (Pa).
        pub youngs_modulus: f64 = 1e6,
        /// Poisson's ratio.
        pub poisson_ratio: f64 = 0.3,
        /// Deviatoric yield stress ρ_y (Pa), eq. (43).
        pub yield_stress: f64 = 20e3,
        /// Body force magnitude (N/m³), acting downwards.
        pub body_force: f64 = 10e3,
        /// Number of equal load steps.
        pub load_steps: usize = 40,
        /// Newton tolerance on eq. (40).
        pub tolerance: f64 = 1e-9,
        /// Grid width (m): room for the block to spread.
        pub grid_width: f64 = 20.0,
    }
}

/// The registered case (see [`crate::cases::Case`]).
#[derive(Debug, Clone, Copy)]
pub struct CollapseCase;

impl Case for CollapseCase {
    const NAME: &'static str = "collapse";
    const ABOUT: &'static str = "Coombs 2020 §7.5: elasto-plastic collapse of a block (Tables 6-7)";
    type Params = CollapseParams;

    fn scene(p: &CollapseParams, variant: &Variant) -> Result<Scene, SolverError> {
        scene(p, variant)
    }
}

/// The collapse's result.
#[derive(Debug, Clone)]
pub struct CollapseResult {
    /// The run.
    pub output: RunOutput<2>,
    /// Largest $x_p + l^0_{p,x}$ at the end (m): the right edge of the
    /// body as the paper measures it.
    pub horizontal_extent: f64,
    /// Largest $y_p + l^0_{p,y}$ at the end (m).
    pub max_height: f64,
    /// Number of material points.
    pub material_points: usize,
}

/// The collapse as a typed scene (the scene of `scenes/coombs2020_collapse.toml`
/// with the parameters and variant filled in): a grid of `grid_width` by
/// `height + h` with the padding the basis needs, rollers on the base and
/// the symmetry line (their padding nodes held alike), the body force as
/// the weight of a unit density.
///
/// # Errors
/// [`SolverError::InvalidInput`] when `h` does not divide the widths and
/// the height.
pub fn scene(p: &CollapseParams, variant: &Variant) -> Result<Scene, SolverError> {
    let nx = super::cells_along(p.h, p.grid_width, "the grid width")?;
    let ny = super::cells_along(p.h, p.height, "the height")?;
    super::cells_along(p.h, p.width, "the block width")?;
    let material = MaterialSpec::new(
        "block",
        MaterialModel::VonMises,
        p.youngs_modulus,
        p.poisson_ratio,
        1.0,
    )
    .with_yield_stress(p.yield_stress);
    let mesh = MeshSpec::grid([0.0, 0.0], [p.grid_width, p.height + p.h], [nx, ny + 1]);
    Ok(
        super::one_block(mesh, material, [p.width, p.height], p.points_per_cell)
            .with_boundary(BoundarySpec::on("x_min", BoundaryKind::Roller))
            .with_boundary(BoundarySpec::on("y_min", BoundaryKind::Roller))
            .with_load(LoadSpec::gravity([0.0, -p.body_force]))
            .with_solver(SolverSpec::implicit(variant, p.load_steps, p.tolerance)),
    )
}

impl Solve<2> for CollapseCase {
    type Built = Problem<2>;
    type Result = CollapseResult;

    /// Runs the built collapse and measures the body's extent.
    fn solve(_: &CollapseParams, problem: &Problem<2>, run: Run<'_, 2>) -> Solved<CollapseResult> {
        let output = run.on(problem)?;
        // The edge of the body: of the domains where the basis has them
        // (GIMP, CPDI2), else of the points' initial half-spacing l0.
        let last = &output.last;
        let edge = |axis: usize| {
            if last.domain_bounds.is_empty() {
                last.position
                    .iter()
                    .zip(&problem.half_lengths)
                    .map(|(x, l)| x[axis] + l[axis])
                    .fold(f64::NEG_INFINITY, f64::max)
            } else {
                last.domain_bounds
                    .iter()
                    .map(|(_, hi)| hi[axis])
                    .fold(f64::NEG_INFINITY, f64::max)
            }
        };
        let (horizontal_extent, max_height) = (edge(0), edge(1));
        Ok(CollapseResult {
            output,
            horizontal_extent,
            max_height,
            material_points: problem.len(),
        })
    }

    fn measured(r: &CollapseResult) -> Measured<'_, 2> {
        Measured::new(&r.output, r.material_points, None).with([
            ("horizontal_extent", json!(r.horizontal_extent)),
            ("max_height", json!(r.max_height)),
        ])
    }
}
