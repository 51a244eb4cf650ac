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

/// A bound on the rounding noise of the out-of-balance force over the free
/// dofs, from the Frobenius norms `tangent_norms` of the weighted $9\times
/// 9$ tangents ($\|T_p\|_F$, volume included) and the force gradients
/// `grads`. The law evaluates each point's stress
/// from a strain whose components carry an absolute rounding error of the
/// order of the unit round-off $u$ (logarithms and eigenvalues of tensors
/// near the identity), so the stress carries $\|\delta\tau_p\|\lesssim
/// u\,\|T_p\|_F$ whatever the strain level, and node $v$'s force at most
/// $e_v = u\sum_p\|T_p\|_F\,|\nabla S_{vp}|$; the bound is the norm of
/// $e_v$ over the free dofs. Small load steps on stiff or nearly
/// incompressible bodies (a 0.1 mm footing increment on a 10 GPa cube)
/// have reactions so small beside it that eq. (40) cannot reach a
/// tolerance of $10^{-9}$: see [`NewtonMonitor::set_rounding_noise`].
pub fn rounding_noise<const D: usize>(
    sys: &StepSystem<D>,
    grads: &[SVector<f64, D>],
    tangent_norms: &[f64],
) -> f64 {
    let mut bound = vec![0.0; sys.n_active()];
    for (p, &norm) in tangent_norms.iter().enumerate() {
        for s in sys.slots(p) {
            bound[sys.nodes[s] as usize] += norm * grads[s].norm();
        }
    }
    let b2: f64 = sys
        .free_of_dof
        .iter()
        .enumerate()
        .filter(|&(_, &free)| free != NONE)
        .map(|(dof, _)| bound[dof / D] * bound[dof / D])
        .sum();
    0.5 * f64::EPSILON * b2.sqrt()
}

/// A Newton iteration has stalled when it removes less than this fraction
/// of the residual ([`NewtonMonitor::check`] then accepts a residual at
/// the rounding floor).
pub const STALL_RATIO: f64 = 0.5;

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
///
/// Given the rounding noise of the residual
/// ([`Self::set_rounding_noise`], from [`rounding_noise`]), the test also
/// accepts an iterate whose out-of-balance force is within
/// `floor_factor` times that noise once Newton has stalled (the last
/// iteration removed less than [`STALL_RATIO`] of the residual): below the
/// noise no iteration can reduce it further, and eq. (40) alone would cut
/// such steps down to failure although they are solved to the accuracy
/// floating point allows. [`Self::at_rounding_floor`] says when that
/// happened.
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonMonitor {
    tolerance: f64,
    divergence_factor: f64,
    max_iterations: usize,
    force_scale: f64,
    residuals: Vec<f64>,
    floor_factor: f64,
    noise: f64,
    at_floor: bool,
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
            floor_factor: 0.0,
            noise: 0.0,
            at_floor: false,
        }
    }

    /// Accept stalled iterates within `floor_factor` times the rounding
    /// noise of the residual (zero, the default of [`Self::new`], keeps
    /// eq. (40) alone).
    pub fn with_rounding_floor(mut self, floor_factor: f64) -> Self {
        self.floor_factor = floor_factor;
        self
    }

    /// The rounding noise of $\|f^R\|$ (absolute, [`rounding_noise`]) for
    /// the checks that follow.
    pub fn set_rounding_noise(&mut self, noise: f64) {
        self.noise = noise;
    }

    /// The rounding noise normalised like the residual, i.e. the smallest
    /// normalised residual the step can be expected to reach (zero until
    /// [`Self::set_rounding_noise`]).
    pub fn rounding_floor(&self) -> f64 {
        ratio(self.noise, self.force_scale)
    }

    /// Whether the step was accepted at the rounding floor rather than by
    /// the tolerance.
    pub fn at_rounding_floor(&self) -> bool {
        self.at_floor
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
        let stalled = iteration > 0 && residual >= STALL_RATIO * self.residuals[iteration - 1];
        if stalled && residual_norm <= self.floor_factor * self.noise {
            self.at_floor = true;
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

    #[test]
    fn a_stalled_residual_within_the_rounding_noise_is_accepted() {
        // Noise 1e-9 in a force of 1 (normalised floor 1e-9), tolerance
        // 1e-12, floor factor 10.
        let monitor = || {
            let mut m = NewtonMonitor::new(1e-12, 1e6, 30).with_rounding_floor(10.0);
            assert_eq!(m.check(1.0, 1.0), Verdict::Continue);
            m.set_rounding_noise(1e-9);
            m
        };
        // Still falling fast below the floor: iterate on.
        let mut m = monitor();
        assert_eq!(m.check(1e-3, 1.0), Verdict::Continue);
        assert_eq!(m.check(5e-9, 1.0), Verdict::Continue);
        // Stalled within 10 x noise: accepted at the floor.
        assert_eq!(m.check(4e-9, 1.0), Verdict::Converged);
        assert!(m.at_rounding_floor());
        assert_eq!(m.rounding_floor(), 1e-9);
        // Stalled above 10 x noise: not accepted.
        let mut m = monitor();
        assert_eq!(m.check(3e-8, 1.0), Verdict::Continue);
        assert_eq!(m.check(2e-8, 1.0), Verdict::Continue);
        assert!(!m.at_rounding_floor());
        // Without the factor (the plain eq. 40 test) nothing changes.
        let mut m = NewtonMonitor::new(1e-12, 1e6, 30);
        m.set_rounding_noise(1e-9);
        assert_eq!(m.check(1.0, 1.0), Verdict::Continue);
        assert_eq!(m.check(2e-9, 1.0), Verdict::Continue);
        assert_eq!(m.check(2e-9, 1.0), Verdict::Continue);
        // Below the tolerance the step converges by eq. (40), not the floor.
        let mut m = monitor();
        assert_eq!(m.check(1e-13, 1.0), Verdict::Converged);
        assert!(!m.at_rounding_floor());
    }
}
