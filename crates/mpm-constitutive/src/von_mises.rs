//! Von Mises elasto-plasticity with linear isotropic hardening.

use nalgebra::{Matrix3, Vector3};

use crate::error::{ConstitutiveError, Result};
use crate::law::{IsotropicElasticity, LawState, LogStrainLaw};
use crate::spectral::SymSpectral;
use crate::tensor::{Tensor4, dyad, sym_identity};

/// Relative tolerance on the trial yield function below which a step is
/// taken as elastic: $f^{tr} \le$ `YIELD_TOLERANCE` $\cdot\,\rho_y$.
pub const YIELD_TOLERANCE: f64 = 1e-12;

/// Internal variable of [`VonMises`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct VonMisesHistory {
    /// Accumulated plastic multiplier $\alpha = \sum \Delta\gamma =
    /// \int \|\dot\varepsilon^p\|\,dt$ (the norm of the plastic Hencky
    /// strain rate, integrated).
    pub alpha: f64,
}

impl VonMisesHistory {
    /// The conventional equivalent plastic strain
    /// $\bar\varepsilon^p = \sqrt{2/3}\,\alpha$.
    pub fn equivalent_plastic_strain(&self) -> f64 {
        (2.0f64 / 3.0).sqrt() * self.alpha
    }
}

/// Von Mises plasticity in Kirchhoff stress (Coombs et al. 2020, eq. 43):
/// $$ f = \rho - \rho_y(\alpha), \quad \rho = \sqrt{2J_2} = \|s\|, \quad
/// s = \tau - \tfrac13\mathrm{tr}(\tau)\mathbf 1,\quad
/// \rho_y(\alpha) = \rho_{y} + H\alpha, $$
/// associated flow $\Delta\varepsilon^p = \Delta\gamma\, s/\|s\|$ integrated
/// by the exponential map (a backward-Euler step in Hencky strain), so the
/// return is the radial return in principal space:
/// $\Delta\gamma = f^{tr}/(2\mu + H)$,
/// $s = (1 - 2\mu\Delta\gamma/\rho^{tr})\,s^{tr}$. Perfect plasticity is
/// $H = 0$. The algorithmic tangent (derived here; the paper leaves it to
/// its refs.) is
/// $$ D^{alg} = K\,\mathbf 1\otimes\mathbf 1 + 2\mu\theta\,\mathbb I^{dev} -
///   2\mu\bar\theta\, N\otimes N,\quad
///   \theta = 1 - \frac{2\mu\Delta\gamma}{\rho^{tr}},\quad
///   \bar\theta = \frac{2\mu}{2\mu + H} - (1-\theta), $$
/// with $N = s^{tr}/\rho^{tr}$ and $\mathbb I^{dev} = \mathbb I^s -
/// \tfrac13\mathbf 1\otimes\mathbf 1$; it is checked against finite
/// differences of the return map in the tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VonMises {
    elasticity: IsotropicElasticity,
    yield_stress: f64,
    hardening: f64,
}

impl VonMises {
    /// From Young's modulus `e`, Poisson's ratio `nu`, the initial
    /// deviatoric yield stress $\rho_y$ (`yield_stress` > 0, in the
    /// $\rho = \sqrt{2J_2}$ measure of eq. 43) and the linear hardening
    /// modulus `hardening` $H \ge 0$.
    pub fn new(e: f64, nu: f64, yield_stress: f64, hardening: f64) -> Result<Self> {
        let elasticity = IsotropicElasticity::new(e, nu)?;
        if !(yield_stress.is_finite() && yield_stress > 0.0) {
            return Err(ConstitutiveError::InvalidYieldStress {
                value: yield_stress,
            });
        }
        if !(hardening.is_finite() && hardening >= 0.0) {
            return Err(ConstitutiveError::InvalidHardening { value: hardening });
        }
        Ok(Self {
            elasticity,
            yield_stress,
            hardening,
        })
    }

    /// The elastic constants.
    pub fn elasticity(&self) -> &IsotropicElasticity {
        &self.elasticity
    }

    /// Initial yield stress $\rho_y$.
    pub fn yield_stress(&self) -> f64 {
        self.yield_stress
    }

    /// Hardening modulus $H$.
    pub fn hardening(&self) -> f64 {
        self.hardening
    }

    /// Current yield stress $\rho_y + H\alpha$.
    pub fn current_yield_stress(&self, history: &VonMisesHistory) -> f64 {
        self.yield_stress + self.hardening * history.alpha
    }

    /// The yield function $f = \|s\| - \rho_y(\alpha)$ of a Kirchhoff stress.
    pub fn yield_function(&self, tau: &Matrix3<f64>, history: &VonMisesHistory) -> f64 {
        let s = tau - tau.trace() / 3.0 * Matrix3::identity();
        s.norm() - self.current_yield_stress(history)
    }

    /// The yield function of principal Kirchhoff stresses (as returned by
    /// the return map, before they are rotated into the global frame).
    pub fn yield_function_principal(&self, tau: &Vector3<f64>, history: &VonMisesHistory) -> f64 {
        let mean = tau.sum() / 3.0;
        tau.map(|t| t - mean).norm() - self.current_yield_stress(history)
    }

    /// Whether a trial state that the return map took as elastic lies on
    /// the yield surface to within rounding: $f^{tr} \ge -(10^{-10}\rho_y +
    /// 16\,\epsilon\,2\mu\max(1, \|\varepsilon^{e,tr}\|))$. The second term
    /// is the rounding of $\rho^{tr}$ when the trial strain is recomputed
    /// as $\ln b^e$ from a stored $b^e = \exp 2\varepsilon^e$ (an absolute
    /// error of a few $\epsilon$ in each strain). Such a state is a
    /// converged plastic state read again at $\Delta F = 1$, where a load
    /// step starts ([`LogStrainLaw::loading_tangent`]).
    #[inline]
    fn on_yield_surface(&self, rho_tr: f64, eps: &Vector3<f64>, history: &VonMisesHistory) -> bool {
        let rounding = 16.0 * f64::EPSILON * 2.0 * self.elasticity.mu * eps.norm().max(1.0);
        rho_tr - self.current_yield_stress(history) >= -(1e-10 * self.yield_stress + rounding)
    }

    /// Trial deviator (principal values) and its norm.
    #[inline]
    fn trial_deviator(&self, eps: &Vector3<f64>) -> (Vector3<f64>, f64) {
        let mean = eps.sum() / 3.0;
        let s = eps.map(|e| 2.0 * self.elasticity.mu * (e - mean));
        let rho = s.norm();
        (s, rho)
    }

    /// The algorithmic tangent of a plastic return with multiplier
    /// $\Delta\gamma$ = `state.history.alpha - history.alpha` (0 on the
    /// yield surface: the continuum tangent).
    fn plastic_tangent(
        &self,
        trial: &SymSpectral,
        history: &VonMisesHistory,
        state: &LawState<VonMisesHistory>,
    ) -> Tensor4 {
        let el = &self.elasticity;
        let (s_tr, rho_tr) = self.trial_deviator(&trial.values);
        let dgamma = state.history.alpha - history.alpha;
        let two_mu = 2.0 * el.mu;
        let theta = 1.0 - two_mu * dgamma / rho_tr;
        let theta_bar = two_mu / (two_mu + self.hardening) - (1.0 - theta);
        let n = trial.compose(&(s_tr / rho_tr));
        let one = Matrix3::identity();
        let one_one = dyad(&one, &one);
        let dev = sym_identity() - one_one / 3.0;
        el.bulk * one_one + two_mu * theta * dev - two_mu * theta_bar * dyad(&n, &n)
    }
}

impl LogStrainLaw for VonMises {
    type History = VonMisesHistory;

    fn return_map(
        &self,
        trial: &SymSpectral,
        history: &VonMisesHistory,
    ) -> LawState<VonMisesHistory> {
        let el = &self.elasticity;
        let eps = trial.values;
        let (s_tr, rho_tr) = self.trial_deviator(&eps);
        let rho_y = self.current_yield_stress(history);
        let f_tr = rho_tr - rho_y;
        if f_tr <= YIELD_TOLERANCE * self.yield_stress {
            return LawState {
                tau: el.principal_stress(&eps),
                elastic_strain: eps,
                history: *history,
                yielded: false,
            };
        }
        let dgamma = f_tr / (2.0 * el.mu + self.hardening);
        let n = s_tr / rho_tr;
        let elastic_strain = eps - dgamma * n;
        LawState {
            tau: el.principal_stress(&elastic_strain),
            elastic_strain,
            history: VonMisesHistory {
                alpha: history.alpha + dgamma,
            },
            yielded: true,
        }
    }

    fn algorithmic_tangent(
        &self,
        trial: &SymSpectral,
        history: &VonMisesHistory,
        state: &LawState<VonMisesHistory>,
    ) -> Tensor4 {
        if !state.yielded {
            return self.elasticity.stiffness();
        }
        self.plastic_tangent(trial, history, state)
    }

    /// On the yield surface ($f^{tr} = 0$ to rounding, which
    /// [`Self::return_map`] takes as elastic) the tangent of continued
    /// plastic loading: the formula of the algorithmic tangent with
    /// $\Delta\gamma = 0$, the continuum elasto-plastic tangent. Elsewhere
    /// the algorithmic tangent.
    fn loading_tangent(
        &self,
        trial: &SymSpectral,
        history: &VonMisesHistory,
        state: &LawState<VonMisesHistory>,
    ) -> Tensor4 {
        if !state.yielded {
            let (_, rho_tr) = self.trial_deviator(&trial.values);
            if !self.on_yield_surface(rho_tr, &trial.values, history) {
                return self.elasticity.stiffness();
            }
        }
        self.plastic_tangent(trial, history, state)
    }

    fn elasticity(&self) -> Option<IsotropicElasticity> {
        Some(self.elasticity)
    }

    /// The elastic part only; plastic work is dissipated.
    fn stored_energy(
        &self,
        elastic_strain: &Vector3<f64>,
        _history: &VonMisesHistory,
    ) -> Option<f64> {
        Some(self.elasticity.energy(elastic_strain))
    }
}
