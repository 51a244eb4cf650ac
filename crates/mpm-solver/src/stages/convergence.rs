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
    noise_of_bounds(sys, &node_bounds(sys, grads, tangent_norms))
}

/// Per active node, $\sum_p \|T_p\|_F\,\|\nabla S_{vp}\|$ over the points
/// at hand (on several ranks, each rank's part of the sum).
pub fn node_bounds<const D: usize>(
    sys: &StepSystem<D>,
    grads: &[SVector<f64, D>],
    tangent_norms: &[f64],
) -> Vec<f64> {
    let mut bound = vec![0.0; sys.n_active()];
    for (p, &norm) in tangent_norms.iter().enumerate() {
        for s in sys.slots(p) {
            bound[sys.nodes[s] as usize] += norm * grads[s].norm();
        }
    }
    bound
}

/// [`rounding_noise`] from the whole sums of [`node_bounds`].
pub fn noise_of_bounds<const D: usize>(sys: &StepSystem<D>, bound: &[f64]) -> f64 {
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

/// How far above the convergence target the residual predicted by
/// [`NewtonMonitor::expects_correction`] must lie before the next
/// iteration is expected to need a correction. A wrong "yes" costs a
/// tangent pass and a repeated update; a wrong "no" only the stored
/// responses the fused pass saves, so the prediction leans towards "no".
pub const CORRECTION_MARGIN: f64 = 100.0;

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
    first_correction: bool,
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
            first_correction: true,
        }
    }

    /// Whether [`Self::expects_correction`] says yes before the first
    /// check (the default). A solver says no after a step that converged
    /// on its first iterate: steps that carry no load change, or whose
    /// prediction is exact, come in runs.
    pub fn expecting_first_correction(mut self, expect: bool) -> Self {
        self.first_correction = expect;
        self
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

    /// Whether the next [`Self::check`] is expected to ask for another
    /// correction, so that the update before it may as well compute the
    /// tangents (`ImplicitSolver::update_material_points_with_tangents`).
    /// The next residual is predicted from the rate of the last two,
    /// $r_{k+1} \approx r_k\,(r_k/r_{k-1})^2$, which is Newton's quadratic
    /// rate $r_{k+1} = C r_k^2$ with $C = r_k/r_{k-1}^2$ and understates a
    /// linear rate; after one residual, $r_1 \approx r_0^2$; before any,
    /// yes unless [`Self::expecting_first_correction`] said no. It must
    /// exceed [`CORRECTION_MARGIN`] times the target (the
    /// tolerance, or the accepted multiple of the rounding floor if
    /// larger). No once the iteration limit is reached: the next check
    /// cannot ask for a correction.
    pub fn expects_correction(&self) -> bool {
        if self.residuals.len() >= self.max_iterations {
            return false;
        }
        let predicted = match *self.residuals.as_slice() {
            [] => return self.first_correction,
            [r0] => r0 * r0,
            [.., prev, last] if prev > 0.0 => last * (last / prev).powi(2),
            [.., last] => last,
        };
        let target = self
            .tolerance
            .max(self.floor_factor * self.rounding_floor());
        predicted > CORRECTION_MARGIN * target
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
    fn the_monitor_expects_a_correction_until_the_predicted_residual_is_near_the_target() {
        assert_eq!(CORRECTION_MARGIN, 100.0, "the figures below assume it");
        let mut m = NewtonMonitor::new(1e-9, 1e6, 4).with_rounding_floor(10.0);
        // Nothing checked yet: the first iterate is corrected.
        assert!(m.expects_correction());
        // r_1 ≈ r_0² = 1e-2.
        assert_eq!(m.check(0.1, 1.0), Verdict::Continue);
        assert!(m.expects_correction());
        // Quadratic: 1e-1, 2e-3 predicts 2e-3 · (2e-2)² = 8e-7 > 1e-7.
        assert_eq!(m.check(2e-3, 1.0), Verdict::Continue);
        assert!(m.expects_correction());
        // 2e-3, 1e-6 predicts 2.5e-13: the next iterate should converge.
        assert_eq!(m.check(1e-6, 1.0), Verdict::Continue);
        assert!(!m.expects_correction());
        // At the iteration limit the next check cannot continue.
        assert_eq!(m.check(1e-8, 1.0), Verdict::Continue);
        assert!(!m.expects_correction());

        // Either side of the margin (tolerance 1e-9, so 1e-7): 1e-4 →
        // 1.0001e-5 predicts 1.0003e-7; 1e-4 → 9e-6 predicts 7.3e-8.
        let after = |r: &[f64]| {
            let mut m = NewtonMonitor::new(1e-9, 1e6, 30);
            for &x in r {
                assert_eq!(m.check(x, 1.0), Verdict::Continue);
            }
            m.expects_correction()
        };
        assert!(after(&[1e-4, 1.0001e-5]));
        assert!(!after(&[1e-4, 9e-6]));
        assert!(!after(&[1e-4, 1e-6]));
        // One residual: r_0² against 1e-7.
        assert!(after(&[1e-3]));
        assert!(!after(&[1e-4]));
        // A solver that saw the last step converge on its first iterate
        // expects the same of the next.
        let m = NewtonMonitor::new(1e-9, 1e6, 30).expecting_first_correction(false);
        assert!(!m.expects_correction());

        // Stalling near the rounding floor (noise 1e-9 in a force of 1,
        // factor 10, so residuals up to 1e-8 are accepted once stalled):
        // 2e-8 → 1.5e-8 predicts 8.4e-9, below the accepted 1e-8 times the
        // margin.
        let mut m = NewtonMonitor::new(1e-12, 1e6, 30).with_rounding_floor(10.0);
        assert_eq!(m.check(1.0, 1.0), Verdict::Continue);
        m.set_rounding_noise(1e-9);
        assert_eq!(m.check(2e-8, 1.0), Verdict::Continue);
        assert_eq!(m.check(1.5e-8, 1.0), Verdict::Continue);
        assert!(!m.expects_correction());
        // Without the floor the same residuals predict another correction.
        let mut m = NewtonMonitor::new(1e-12, 1e6, 30);
        for r in [1.0, 2e-8, 1.5e-8] {
            assert_eq!(m.check(r, 1.0), Verdict::Continue);
        }
        assert!(m.expects_correction());
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
