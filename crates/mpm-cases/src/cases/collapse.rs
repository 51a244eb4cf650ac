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

use mpm_constitutive::VonMises;
use mpm_mesh::RegularGrid;
use mpm_solver::{
    DomainUpdater, Flat, Formulation, LoadStepping, NewtonOptions, NodalConstraints, SolverError,
    StepReport,
};
use nalgebra::SVector;

use crate::body::{Body, InitialDomain};
use crate::run::{DomainBounds, Loads, RunControl, RunOutput, Setup, Snapshot, simulate};
use crate::variant::{Variant, VariantVisitor, dispatch};

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

impl crate::cases::Case for CollapseCase {
    const NAME: &'static str = "collapse";
    const ABOUT: &'static str = "Coombs 2020 §7.5: elasto-plastic collapse of a block (Tables 6-7)";
    type Params = CollapseParams;

    fn run(p: CollapseParams, session: &crate::session::Session) -> Result<(), crate::CasesError> {
        use crate::session::summary;
        let (grid, _, _) = geometry(&p, p.basis.padding())?;
        let (mut obs, control) = session.start(&p, grid)?;
        let r = run(&p, &p.variant(), &control, |s, rep, snap| {
            obs.step(s, rep, snap)
        })?;
        let mut results = serde_json::Map::new();
        results.insert(
            "horizontal_extent".into(),
            serde_json::json!(r.horizontal_extent),
        );
        results.insert("max_height".into(), serde_json::json!(r.max_height));
        let s = summary(
            Self::NAME,
            p.variant(),
            r.material_points,
            &r.output,
            None,
            results,
            &p,
        );
        obs.finish(s)
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

/// Grid, body and rollers; a basis that needs padding gets that many cells
/// beyond the rollers, whose nodes are held like the roller they extend.
pub fn geometry(
    p: &CollapseParams,
    pad: usize,
) -> Result<(RegularGrid<2>, Body<2>, NodalConstraints<2>), SolverError> {
    let cells = |len: f64, what: &str| {
        let n = (len / p.h).round();
        if n < 1.0 || (n * p.h - len).abs() > 1e-9 * len {
            Err(SolverError::InvalidInput(format!(
                "h = {} must divide the {what} {len}",
                p.h
            )))
        } else {
            Ok(n as usize)
        }
    };
    let (nx, ny) = (
        cells(p.grid_width, "grid width")?,
        cells(p.height, "height")?,
    );
    cells(p.width, "block width")?;
    let padf = pad as f64 * p.h;
    let grid = RegularGrid::new(
        SVector::<f64, 2>::new(-padf, -padf),
        SVector::<f64, 2>::new(p.h, p.h),
        [nx + 2 * pad, ny + 1 + 2 * pad],
    )
    .map_err(SolverError::from)?;
    let body = Body::fill_box(
        &grid,
        &SVector::<f64, 2>::zeros(),
        &SVector::<f64, 2>::new(p.width, p.height),
        p.points_per_cell,
    );
    let mut constraints = NodalConstraints::<2>::new(grid.node_count());
    let tol = 1e-9 * p.h;
    for n in 0..grid.node_count() {
        let x = grid.node_position(n).map_err(SolverError::from)?;
        if x[0] <= tol {
            constraints.fix([n], 0);
        }
        if x[1] <= tol {
            constraints.fix([n], 1);
        }
    }
    Ok((grid, body, constraints))
}

struct CollapseRun<'a, O> {
    params: &'a CollapseParams,
    control: &'a RunControl,
    observer: O,
}

impl<O> VariantVisitor<2> for CollapseRun<'_, O>
where
    O: FnMut(usize, &StepReport<2>, &Snapshot) -> Result<(), SolverError>,
{
    type Output = Result<CollapseResult, SolverError>;

    fn visit<B, F, U>(self, basis: B, updater: U) -> Self::Output
    where
        B: InitialDomain<2, Mesh = RegularGrid<2>, Domain: Flat + DomainBounds<2>>,
        F: Formulation,
        U: DomainUpdater<2, B::Domain>,
    {
        let p = self.params;
        let (grid, body, constraints) = geometry(p, B::PADDING)?;
        let law = VonMises::new(p.youngs_modulus, p.poisson_ratio, p.yield_stress, 0.0)
            .map_err(SolverError::from)?;
        // The body force is applied as m_p g with unit density.
        let setup = Setup {
            grid,
            body: &body,
            density: 1.0,
            law,
            loads: Loads {
                gravity: Some(SVector::<f64, 2>::new(0.0, -p.body_force)),
                point_forces: Vec::new(),
                body_force_path: None,
            },
            constraints,
            stepping: LoadStepping::uniform(p.load_steps),
            newton: NewtonOptions {
                tolerance: p.tolerance,
                ..NewtonOptions::default()
            },
        };
        let output =
            simulate::<2, B, F, U, _, _, _>(setup, basis, updater, self.control, self.observer)?;
        // The edge of the body: of the domains where the basis has them
        // (GIMP, CPDI2), else of the points' initial half-spacing l0.
        let last = &output.last;
        let edge = |axis: usize| {
            if last.domain_bounds.is_empty() {
                last.position
                    .iter()
                    .zip(&body.half_lengths)
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
            material_points: body.len(),
        })
    }
}

/// Runs the collapse with `variant`.
pub fn run<O>(
    params: &CollapseParams,
    variant: &Variant,
    control: &RunControl,
    observer: O,
) -> Result<CollapseResult, SolverError>
where
    O: FnMut(usize, &StepReport<2>, &Snapshot) -> Result<(), SolverError>,
{
    dispatch(
        variant,
        CollapseRun {
            params,
            control,
            observer,
        },
    )
    .map_err(SolverError::InvalidInput)?
}
