//! The out-of-balance force, the reactions and the Newton convergence test
//! (Coombs et al. 2020 eq. 40).

use nalgebra::SVector;

use crate::error::StepFailure;
use crate::stages::system::{NONE, StepSystem};

/// $r/d$, with $0/0 = 0$ and $r/0 = \infty$.
#[inline]
pub fn ratio(r: f64, d: f64) -> f64 {
    if r == 0.0 {
        0.0
    } else if d == 0.0 {
        f64::INFINITY
    } else {
        r / d
    }
}

/// $(\|f^R\|, \|f^{ext} + f^{react}\|)$ of eq. (40): the out-of-balance
/// force over free dofs, and the external force over free dofs together
/// with the reactions ($f^{int}$) at prescribed ones.
pub fn residual_parts<const D: usize>(
    sys: &StepSystem<D>,
    f_int: &[f64],
    f_ext: &[f64],
) -> (f64, f64) {
    let (mut r2, mut d2) = (0.0, 0.0);
    for (dof, &free) in sys.free_of_dof.iter().enumerate() {
        let (fi, fe) = (f_int[dof], f_ext[dof]);
        if free == NONE {
            d2 += fi * fi;
        } else {
            r2 += (fi - fe) * (fi - fe);
            d2 += fe * fe;
        }
    }
    (r2.sqrt(), d2.sqrt())
}

/// $\|f^{ext} - f^{int}\| / \|f^{ext}\|$ over every active dof (see
/// [`crate::StepReport::initial_unbalance`]); `None` without external
/// force or when not finite.
pub fn unbalance_all_dofs(f_int: &[f64], f_ext: &[f64]) -> Option<f64> {
    let (mut r2, mut e2) = (0.0, 0.0);
    for (fi, fe) in f_int.iter().zip(f_ext) {
        r2 += (fe - fi) * (fe - fi);
        e2 += fe * fe;
    }
    let u = r2.sqrt() / e2.sqrt();
    (e2 > 0.0 && u.is_finite()).then_some(u)
}

/// Sum of the reactions $f^{int} - f^{ext}$ per component at prescribed
/// dofs.
pub fn reaction<const D: usize>(
    sys: &StepSystem<D>,
    f_int: &[f64],
    f_ext: &[f64],
) -> SVector<f64, D> {
    let mut r = SVector::<f64, D>::zeros();
    for (dof, &free) in sys.free_of_dof.iter().enumerate() {
        if free == NONE {
            r[dof % D] += f_int[dof] - f_ext[dof];
        }
    }
    r
}

/// The reaction at each active node with a prescribed dof (mesh id,
/// ascending; zero at its free components).
pub fn node_reactions<const D: usize>(
    sys: &StepSystem<D>,
    f_int: &[f64],
    f_ext: &[f64],
) -> Vec<(usize, SVector<f64, D>)> {
    let mut out = Vec::new();
    for v in 0..sys.n_active() {
        let dofs = D * v..D * v + D;
        if sys.free_of_dof[dofs.clone()].iter().all(|&f| f != NONE) {
            continue;
        }
        let r = SVector::<f64, D>::from_fn(|i, _| {
            let dof = D * v + i;
            if sys.free_of_dof[dof] == NONE {
                f_int[dof] - f_ext[dof]
            } else {
                0.0
            }
        });
        out.push((sys.active[v], r));
    }
    out
}

/// What the convergence test says after an iteration.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// The normalised residual is within the tolerance.
    Converged,
    /// Iterate on.
    Continue,
    /// The step failed (it may succeed with a smaller increment).
    Failed(StepFailure),
}

/// The Newton convergence test of one load step: eq. (40) normalised by
/// the largest external-plus-reaction force of the step so far (when the
/// solution is stress free — a rigid motion imposed on the boundary — the
/// reactions vanish with the residual and the plain ratio would stay of
/// order one), with divergence and iteration limits.
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonMonitor {
    tolerance: f64,
    divergence_factor: f64,
    max_iterations: usize,
    force_scale: f64,
    residuals: Vec<f64>,
}

impl NewtonMonitor {
    /// A test with tolerance `tolerance` on the normalised residual, which
    /// declares divergence beyond `divergence_factor` times the first
    /// residual and gives up after `max_iterations` linear solves.
    pub fn new(tolerance: f64, divergence_factor: f64, max_iterations: usize) -> Self {
        Self {
            tolerance,
            divergence_factor,
            max_iterations,
            force_scale: 0.0,
            residuals: Vec::new(),
        }
    }

    /// Records the residual parts `(‖f^R‖, ‖f^ext + f^react‖)` of the
    /// current iterate and judges it.
    pub fn check(&mut self, residual_norm: f64, force_norm: f64) -> Verdict {
        let iteration = self.residuals.len();
        self.force_scale = self.force_scale.max(force_norm);
        let residual = ratio(residual_norm, self.force_scale);
        self.residuals.push(residual);
        if residual <= self.tolerance {
            return Verdict::Converged;
        }
        if !residual.is_finite()
            || residual > self.divergence_factor * self.residuals[0].max(self.tolerance)
        {
            return Verdict::Failed(StepFailure::Diverged {
                iteration,
                residual,
            });
        }
        if iteration >= self.max_iterations {
            return Verdict::Failed(StepFailure::IterationLimit {
                iterations: iteration,
                residual,
            });
        }
        Verdict::Continue
    }

    /// The iteration about to be checked (0 before the first solve).
    pub fn iteration(&self) -> usize {
        self.residuals.len()
    }

    /// The normalised residuals so far.
    pub fn residuals(&self) -> &[f64] {
        &self.residuals
    }

    /// The last normalised residual, NaN before the first.
    pub fn last(&self) -> f64 {
        self.residuals.last().copied().unwrap_or(f64::NAN)
    }

    /// The residual history, consuming the monitor.
    pub fn into_residuals(self) -> Vec<f64> {
        self.residuals
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monitor_converges_diverges_and_stops() {
        let mut m = NewtonMonitor::new(1e-9, 1e6, 2);
        assert_eq!(m.check(1.0, 1.0), Verdict::Continue);
        assert_eq!(m.check(1e-3, 0.5), Verdict::Continue);
        assert!(matches!(
            m.check(1e-2, 1.0),
            Verdict::Failed(StepFailure::IterationLimit { iterations: 2, .. })
        ));
        let mut m = NewtonMonitor::new(1e-9, 10.0, 30);
        assert_eq!(m.check(1.0, 1.0), Verdict::Continue);
        assert!(matches!(
            m.check(100.0, 1.0),
            Verdict::Failed(StepFailure::Diverged { iteration: 1, .. })
        ));
        let mut m = NewtonMonitor::new(1e-9, 10.0, 30);
        // Normalised by the largest force so far: 1e-10 / 2.
        assert_eq!(m.check(1.0, 2.0), Verdict::Continue);
        assert_eq!(m.check(1e-10, 0.0), Verdict::Converged);
        assert_eq!(m.residuals(), &[0.5, 5e-11]);
        assert_eq!(ratio(0.0, 0.0), 0.0);
        assert_eq!(ratio(1.0, 0.0), f64::INFINITY);
    }
}
