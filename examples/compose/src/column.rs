//! The self-weight column of Coombs et al. 2020 §7.1 composed from the
//! framework's parts: a grid one cell wide, material points filling it, a
//! law, gravity, rollers, and the generic implicit solver.

use mpm_basis::BasisFunction;
use mpm_constitutive::LogStrainLaw;
use mpm_mesh::RegularGrid;
use mpm_solver::{
    DomainUpdater, Formulation, ImplicitBuilder, LoadStepping, MaterialPoints, NewtonOptions,
    NodalConstraints, SolverError,
};
use nalgebra::Vector2;

/// The column's settings (Coombs et al. 2020 §7.1: l₀ = 50 m, ϱ₀ = 80
/// kg/m³, g = 10 m/s², 20 load steps).
#[derive(Debug, Clone, Copy)]
pub struct ColumnSettings {
    /// Cell size (m); the column is one cell wide.
    pub h: f64,
    /// Material points per cell and direction.
    pub points_per_cell: usize,
    /// Equal load steps.
    pub load_steps: usize,
}

/// The final state of the column's points.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnState {
    /// Final σ_yy, initial height Z and initial volume of each point.
    pub points: Vec<(f64, f64, f64)>,
    /// Final height of the highest point.
    pub top: f64,
}

/// Runs the column with any basis, formulation, law and domain rule.
pub fn run_column<B, F, L, U>(
    basis: B,
    formulation: F,
    law: L,
    updater: U,
    s: &ColumnSettings,
) -> Result<ColumnState, SolverError>
where
    B: BasisFunction<2, Mesh = RegularGrid<2>>,
    F: Formulation,
    L: LogStrainLaw,
    U: DomainUpdater<2, B::Domain>,
{
    let (height, density, gravity) = (50.0, 80.0, 10.0);
    let cells = (height / s.h).round() as usize;
    let grid = RegularGrid::new(Vector2::zeros(), Vector2::new(s.h, s.h), [1, cells])?;
    let mut fixed = NodalConstraints::<2>::new(grid.node_count());
    fixed.fix(0..grid.node_count(), 0);
    let base = (0..grid.node_count()).filter(|&n| grid.node_position(n).is_ok_and(|x| x[1] <= 0.0));
    fixed.fix(base.collect::<Vec<_>>(), 1);
    // Points at the centres of a regular sub-lattice.
    let (nx, ny) = (s.points_per_cell, cells * s.points_per_cell);
    let step = Vector2::new(s.h / nx as f64, height / ny as f64);
    let position: Vec<Vector2<f64>> = (0..nx * ny)
        .map(|k| Vector2::new((k % nx) as f64 + 0.5, (k / nx) as f64 + 0.5).component_mul(&step))
        .collect();
    let n = position.len();
    let domains = position
        .iter()
        .map(|x| B::initial_domain(x, &(step / 2.0)))
        .collect();
    let mut points: MaterialPoints<2, L::History, B::Domain> =
        MaterialPoints::new(position, vec![step.product(); n], density, domains)?;
    points.set_gravity(Vector2::new(0.0, -gravity));
    let z0: Vec<f64> = points.position.iter().map(|x| x[1]).collect();
    let mut solver = ImplicitBuilder::new(basis, grid, law)
        .formulation(formulation)
        .domain_update(updater)
        .constraints(fixed)
        .options(NewtonOptions {
            tolerance: 1e-9,
            ..NewtonOptions::default()
        })
        .build();
    solver.run(
        &mut points,
        &LoadStepping::uniform(s.load_steps),
        |_, _, _| Ok(()),
    )?;
    Ok(ColumnState {
        points: (0..n)
            .map(|p| (points.sigma[p][(1, 1)], z0[p], points.volume0[p]))
            .collect(),
        top: points
            .position
            .iter()
            .map(|x| x[1])
            .fold(f64::MIN, f64::max),
    })
}

/// The normalised stress error of eq. (42) against
/// $\sigma_{yy} = -\varrho_0 g(l_0 - Z)$ (eq. 41).
pub fn column_error(state: &ColumnState) -> f64 {
    let points = &state.points;
    let (height, rho_g) = (50.0, 800.0);
    let total: f64 = points.iter().map(|p| p.2).sum();
    let sum: f64 = points
        .iter()
        .map(|(s, z, v)| (s + rho_g * (height - z)).abs() * v)
        .sum();
    sum / (rho_g * height * total)
}
