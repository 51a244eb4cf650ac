//! Compaction of an elastic column under self weight (Coombs et al. 2020
//! §7.1, Figs. 6–8): a 50 m column, one cell wide, base fixed vertically,
//! sides fixed horizontally, E = 1 MPa, ν = 0, ρ₀ = 80 kg/m³, g = 10 m/s²
//! applied over 20 equal load steps.
//!
//! Reference: the vertical Cauchy stress
//! $\sigma^a_{zz} = -\varrho_0 g (l_0 - Z)$ (eq. 41, compression negative,
//! $Z$ the initial height) and the error norm (eq. 42)
//! $\sum_p |\sigma_{zz,p} - \sigma^a_{zz}(Z_p)| V^0_p / (\varrho_0 g l_0 V_0)$.

use std::marker::PhantomData;

use mpm_constitutive::LogStrainLaw;
use mpm_mesh::RegularGrid;
use mpm_solver::{
    DomainUpdater, Flat, Formulation, LoadStepping, NewtonOptions, NodalConstraints, SolverError,
};
use nalgebra::SVector;

use crate::body::{Body, InitialDomain};
use crate::material::{LawVisitor, MaterialModel, MaterialParams, dispatch_law};
use crate::run::{
    DomainBounds, HistoryOutput, Loads, RunControl, RunOutput, Setup, Snapshot, simulate,
};
use crate::variant::{Variant, VariantVisitor, dispatch};

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

impl crate::cases::Case for ColumnCase {
    const NAME: &'static str = "column";
    const ABOUT: &'static str = "Coombs 2020 §7.1: elastic column compacting under self weight (analytic eq. 41, error eq. 42)";
    type Params = ColumnParams;

    fn run(p: ColumnParams, session: &crate::session::Session) -> Result<(), crate::CasesError> {
        use crate::session::summary;
        let (grid, _, _) = geometry(&p, p.basis.padding())?;
        let (mut obs, control) = session.start(&p, grid)?;
        let r = run(&p, &p.variant(), &control, |s, rep, snap| {
            obs.step(s, rep, snap)
        })?;
        let s = summary(
            Self::NAME,
            p.variant(),
            r.material_points,
            &r.output,
            Some(r.error),
            serde_json::Map::new(),
            &p,
        );
        obs.finish(s)
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

/// The grid and body of the column: the grid spans the column exactly
/// (one cell wide); a basis that needs padding (B-spline) gets that many
/// cells on every side; nodes below the base are held like the base.
pub fn geometry(
    p: &ColumnParams,
    pad: usize,
) -> Result<(RegularGrid<2>, Body<2>, NodalConstraints<2>), SolverError> {
    let cells_y = (p.height / p.h).round() as usize;
    if cells_y == 0 || (cells_y as f64 * p.h - p.height).abs() > 1e-9 * p.height {
        return Err(SolverError::InvalidInput(format!(
            "h = {} must divide the column height {}",
            p.h, p.height
        )));
    }
    let padf = pad as f64 * p.h;
    let grid = RegularGrid::new(
        SVector::<f64, 2>::new(-padf, -padf),
        SVector::<f64, 2>::new(p.h, p.h),
        [1 + 2 * pad, cells_y + 2 * pad],
    )
    .map_err(SolverError::from)?;
    let body = Body::fill_box(
        &grid,
        &SVector::<f64, 2>::zeros(),
        &SVector::<f64, 2>::new(p.h, p.height),
        p.points_per_cell,
    );
    let mut constraints = NodalConstraints::<2>::new(grid.node_count());
    // Sides: every node fixed horizontally (the column is one cell wide).
    constraints.fix(0..grid.node_count(), 0);
    // Base (and the padding layer below it) fixed vertically.
    let base: Vec<usize> = (0..grid.node_count())
        .filter(|&n| {
            grid.node_position(n)
                .map(|x| x[1] <= 1e-9 * p.h)
                .unwrap_or(false)
        })
        .collect();
    constraints.fix(base, 1);
    Ok((grid, body, constraints))
}

struct ColumnRun<'a, O> {
    params: &'a ColumnParams,
    control: &'a RunControl,
    observer: O,
}

impl<O> VariantVisitor<2> for ColumnRun<'_, O>
where
    O: FnMut(usize, &mpm_solver::StepReport<2>, &Snapshot) -> Result<(), SolverError>,
{
    type Output = Result<ColumnResult, SolverError>;

    fn visit<B, F, U>(self, basis: B, updater: U) -> Self::Output
    where
        B: InitialDomain<2, Mesh = RegularGrid<2>, Domain: Flat + DomainBounds<2>>,
        F: Formulation,
        U: DomainUpdater<2, B::Domain>,
    {
        let p = self.params;
        let material = MaterialParams {
            youngs_modulus: p.youngs_modulus,
            poisson_ratio: p.poisson_ratio,
            yield_stress: p.yield_stress,
            hardening: p.hardening,
        };
        dispatch_law(
            p.material,
            &material,
            WithLaw::<B, F, U, O> {
                run: self,
                basis,
                updater,
                formulation: PhantomData,
            },
        )?
    }
}

/// The column with basis `B`, formulation `F`, updater `U` and the law
/// the scene names.
struct WithLaw<'a, B, F, U, O> {
    run: ColumnRun<'a, O>,
    basis: B,
    updater: U,
    formulation: PhantomData<F>,
}

impl<B, F, U, O> LawVisitor for WithLaw<'_, B, F, U, O>
where
    B: InitialDomain<2, Mesh = RegularGrid<2>, Domain: Flat + DomainBounds<2>>,
    F: Formulation,
    U: DomainUpdater<2, B::Domain>,
    O: FnMut(usize, &mpm_solver::StepReport<2>, &Snapshot) -> Result<(), SolverError>,
{
    type Output = Result<ColumnResult, SolverError>;

    fn visit<L>(self, law: L) -> Self::Output
    where
        L: LogStrainLaw,
        L::History: HistoryOutput + Flat,
    {
        let (p, basis, updater) = (self.run.params, self.basis, self.updater);
        let (grid, body, constraints) = geometry(p, B::PADDING)?;
        let setup = Setup {
            grid,
            body: &body,
            density: p.density,
            law,
            loads: Loads {
                gravity: Some(SVector::<f64, 2>::new(0.0, -p.gravity)),
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
        let output = simulate::<2, B, F, U, _, _, _>(
            setup,
            basis,
            updater,
            self.run.control,
            self.run.observer,
        )?;
        let z0: Vec<f64> = body.position.iter().map(|x| x[1]).collect();
        let error = p.error(&output.last, &z0, &body.volume);
        Ok(ColumnResult {
            output,
            error,
            material_points: body.len(),
        })
    }
}

/// Runs the column with `variant`.
pub fn run<O>(
    params: &ColumnParams,
    variant: &Variant,
    control: &RunControl,
    observer: O,
) -> Result<ColumnResult, SolverError>
where
    O: FnMut(usize, &mpm_solver::StepReport<2>, &Snapshot) -> Result<(), SolverError>,
{
    dispatch(
        variant,
        ColumnRun {
            params,
            control,
            observer,
        },
    )
    .map_err(SolverError::InvalidInput)?
}
