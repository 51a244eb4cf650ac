//! Shared by the stiffness tests: the assembled stiffness against central
//! finite differences of the assembled residual.

use mpm_solver::{ImplicitSolver, PointsOf, SolverParts};

/// Largest column-wise relative difference (relative to the column norm)
/// between the dense stiffness `k` assembled at the free increment `du`
/// and the central finite-difference Jacobian of the residual (step 1e-6).
pub fn worst_column_error<const D: usize, P: SolverParts<D>>(
    solver: &mut ImplicitSolver<D, P>,
    points: &PointsOf<D, P>,
    du: &[f64],
    k: &[f64],
) -> f64 {
    let n = du.len();
    let step = 1e-6;
    let mut worst = 0.0f64;
    for c in 0..n {
        let mut plus = du.to_vec();
        plus[c] += step;
        let mut minus = du.to_vec();
        minus[c] -= step;
        let rp = solver.free_residual(points, &plus).unwrap();
        let rm = solver.free_residual(points, &minus).unwrap();
        let col = &k[c * n..(c + 1) * n];
        let (mut err, mut norm) = (0.0f64, 0.0f64);
        for r in 0..n {
            let fd = (rp[r] - rm[r]) / (2.0 * step);
            err += (col[r] - fd).powi(2);
            norm += fd * fd;
        }
        worst = worst.max(err.sqrt() / norm.sqrt().max(1e-300));
    }
    worst
}
