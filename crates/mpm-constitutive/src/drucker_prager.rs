//! Drucker–Prager elasto-plasticity with linear cohesion hardening and
//! non-associated flow, matched to Mohr–Coulomb's $c$, $\phi$, $\psi$ (de
//! Souza Neto, Perić & Owen 2008, §8.3), in Hencky strain
//! and Kirchhoff stress by the exponential map.
//!
//! With $p = \tfrac13\mathrm{tr}\,\tau$ (tension positive), $s$ the
//! deviator and $\sqrt{J_2} = \|s\|/\sqrt2$:
//! $$ f = \sqrt{J_2} + \eta\,p - \xi\,c(\alpha),\qquad g = \sqrt{J_2} +
//!   \bar\eta\,p,\qquad c = c_0 + H\alpha,\quad \dot\alpha = \xi\dot\gamma. $$
//! The cone's return is closed-form: $\Delta\gamma = f^{tr}/(G + K\eta
//! \bar\eta + \xi^2 H)$, $s = (1 - G\Delta\gamma/\sqrt{J_2^{tr}})\,s^{tr}$,
//! $p = p^{tr} - K\bar\eta\Delta\gamma$; when it would turn the deviator
//! over ($G\Delta\gamma > \sqrt{J_2^{tr}}$) the apex return
//! $p = \xi c/\eta$ with $\Delta\alpha = (\xi/\bar\eta)\,\Delta
//! \varepsilon^p_v$ applies ($\bar\eta\to\eta$ for $\psi = 0$, as in
//! [`crate::MohrCoulomb`]).
//!
//! [`Matching`] picks $\eta$, $\xi$ (and $\bar\eta$ with $\psi$) so that
//! the cone passes through the Mohr–Coulomb pyramid's compression edges
//! (outer), its extension edges (inner), or gives Mohr–Coulomb's limit
//! load in plane strain with associated flow.

use nalgebra::{Matrix3, Vector3};

use crate::error::Result;
use crate::law::{IsotropicElasticity, LawState, LogStrainLaw};
use crate::mohr_coulomb::check_strength;
use crate::principal::{self, Regime};
use crate::spectral::SymSpectral;
use crate::tensor::Tensor4;
use crate::von_mises::YIELD_TOLERANCE;

/// How the cone is fitted to Mohr–Coulomb (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Matching {
    /// Through the compression edges (triaxial compression):
    /// $\eta = 6\sin\phi/(\sqrt3(3 - \sin\phi))$, $\xi = 6\cos\phi/
    /// (\sqrt3(3 - \sin\phi))$.
    Outer,
    /// Through the extension edges (triaxial extension): $3 + \sin\phi$
    /// in the denominators.
    Inner,
    /// Mohr–Coulomb's plane-strain limit load: $\eta = 3\tan\phi/
    /// \sqrt{9 + 12\tan^2\phi}$, $\xi = 3/\sqrt{9 + 12\tan^2\phi}$.
    PlaneStrain,
}

impl Matching {
    /// The cone's $(\eta, \xi)$ for an angle with sine `s` and cosine `c`.
    fn coefficients(self, s: f64, c: f64) -> (f64, f64) {
        let root3 = 3f64.sqrt();
        match self {
            Self::Outer => (6.0 * s / (root3 * (3.0 - s)), 6.0 * c / (root3 * (3.0 - s))),
            Self::Inner => (6.0 * s / (root3 * (3.0 + s)), 6.0 * c / (root3 * (3.0 + s))),
            Self::PlaneStrain => {
                let t = s / c;
                let d = (9.0 + 12.0 * t * t).sqrt();
                (3.0 * t / d, 3.0 / d)
            }
        }
    }
}

/// Internal variables of [`DruckerPrager`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DruckerPragerHistory {
    /// Accumulated hardening variable $\alpha$ ($c = c_0 + H\alpha$).
    pub alpha: f64,
    /// The regime of the last return ([`Regime::Plane`]: the cone).
    pub regime: Regime,
}

/// Drucker–Prager plasticity (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DruckerPrager {
    elasticity: IsotropicElasticity,
    cohesion: f64,
    hardening: f64,
    eta: f64,
    xi: f64,
    eta_bar: f64,
    matching: Matching,
    /// φ and ψ (degrees), kept for [`DruckerPrager::reduced`].
    angles: (f64, f64),
}

impl DruckerPrager {
    /// From Young's modulus `e`, Poisson's ratio `nu`, Mohr–Coulomb's
    /// cohesion $c_0 \ge 0$, friction angle $\phi\in[0, 90)$ and dilation
    /// angle $\psi\in[0,\phi]$ in degrees, the cohesion hardening modulus
    /// $H \ge 0$, and the matching.
    pub fn new(
        e: f64,
        nu: f64,
        (cohesion, phi, psi): (f64, f64, f64),
        hardening: f64,
        matching: Matching,
    ) -> Result<Self> {
        let elasticity = IsotropicElasticity::new(e, nu)?;
        let (sin_phi, cos_phi, sin_psi) = check_strength(cohesion, phi, psi, hardening)?;
        let (eta, xi) = matching.coefficients(sin_phi, cos_phi);
        let cos_psi = (1.0 - sin_psi * sin_psi).sqrt();
        let (eta_bar, _) = matching.coefficients(sin_psi, cos_psi);
        Ok(Self {
            elasticity,
            cohesion,
            hardening,
            eta,
            xi,
            eta_bar,
            matching,
            angles: (phi, psi),
        })
    }

    /// The same law with $c$ and $\tan\phi$ divided by `factor` (strength
    /// reduction), the dilation angle capped at the reduced friction angle,
    /// the same matching.
    pub fn reduced(&self, factor: f64) -> Result<Self> {
        let (phi, psi) = self.angles;
        let phi_f = (phi.to_radians().tan() / factor).atan().to_degrees();
        let el = &self.elasticity;
        Self::new(
            el.youngs_modulus(),
            el.poisson_ratio(),
            (self.cohesion / factor, phi_f, psi.min(phi_f)),
            self.hardening / factor,
            self.matching,
        )
    }

    /// The elastic constants.
    pub fn elasticity(&self) -> &IsotropicElasticity {
        &self.elasticity
    }

    /// How the cone is fitted to Mohr–Coulomb.
    pub fn matching(&self) -> Matching {
        self.matching
    }

    /// The cone's $(\eta, \xi, \bar\eta)$.
    pub fn coefficients(&self) -> (f64, f64, f64) {
        (self.eta, self.xi, self.eta_bar)
    }

    /// Cohesion $c_0 + H\alpha$ of a history.
    pub fn cohesion(&self, history: &DruckerPragerHistory) -> f64 {
        self.cohesion + self.hardening * history.alpha
    }

    /// The yield function of principal Kirchhoff stresses.
    pub fn yield_function(&self, tau: &Vector3<f64>, history: &DruckerPragerHistory) -> f64 {
        let p = tau.sum() / 3.0;
        let q = tau.map(|t| t - p).norm() / 2f64.sqrt();
        q + self.eta * p - self.xi * self.cohesion(history)
    }

    /// $\sqrt{J_2}$ of the trial, its unit deviator direction $\hat u$
    /// ($s/\|s\|$, zero for an isotropic trial) and $p$.
    fn trial_invariants(&self, eps: &Vector3<f64>) -> (f64, Vector3<f64>, f64) {
        let el = &self.elasticity;
        let mean = eps.sum() / 3.0;
        let s = eps.map(|e| 2.0 * el.mu * (e - mean));
        let norm = s.norm();
        let u = if norm > 0.0 {
            s / norm
        } else {
            Vector3::zeros()
        };
        (norm / 2f64.sqrt(), u, el.bulk * eps.sum())
    }

    fn denominator(&self) -> f64 {
        let el = &self.elasticity;
        el.mu + el.bulk * self.eta * self.eta_bar + self.xi * self.xi * self.hardening
    }

    /// $\bar\eta$ of the apex's hardening ($\eta$ for $\psi = 0$).
    fn apex_eta_bar(&self) -> f64 {
        if self.eta_bar > 0.0 {
            self.eta_bar
        } else {
            self.eta
        }
    }

    /// $r$ of the apex return $p(1 + r) = \xi c_n/\eta + r p^{tr}$.
    fn apex_ratio(&self) -> f64 {
        self.hardening * self.xi * self.xi / (self.eta * self.apex_eta_bar() * self.elasticity.bulk)
    }

    /// The flow direction $\partial g/\partial\tau$ in principal values.
    fn flow(&self, u: &Vector3<f64>) -> Vector3<f64> {
        u / 2f64.sqrt() + Vector3::from_element(self.eta_bar / 3.0)
    }

    /// The elastic strain, the multiplier (apex: the volumetric plastic
    /// strain) and the regime of the trial `eps`.
    fn principal_return(
        &self,
        eps: &Vector3<f64>,
        history: &DruckerPragerHistory,
    ) -> (Vector3<f64>, f64, Regime) {
        let el = &self.elasticity;
        let (q, u, p) = self.trial_invariants(eps);
        let c = self.cohesion(history);
        let f = q + self.eta * p - self.xi * c;
        let scale = (self.xi * c).max(q).max(p.abs());
        if f <= YIELD_TOLERANCE * scale {
            return (*eps, 0.0, Regime::Elastic);
        }
        let dgamma = f / self.denominator();
        if el.mu * dgamma <= q || self.eta == 0.0 {
            return (eps - dgamma * self.flow(&u), dgamma, Regime::Plane);
        }
        let r = self.apex_ratio();
        let p_new = (self.xi * c / self.eta + r * p) / (1.0 + r);
        let strain = Vector3::from_element(p_new / (3.0 * el.bulk));
        (strain, (p - p_new) / el.bulk, Regime::Apex)
    }

    /// $\partial\tau_a/\partial\varepsilon_b$ of `regime` (module docs;
    /// on the cone $dτ = D - \mathbf m\otimes\mathbf n/d - (2G^2\Delta\gamma
    /// /\sqrt{J_2})(\mathbb I^{dev} - \hat u\otimes\hat u)$ with $\mathbf m
    /// = \sqrt2G\hat u + K\bar\eta\mathbf 1$, $\mathbf n = \sqrt2G\hat u +
    /// K\eta\mathbf 1$).
    fn principal_tangent(&self, eps: &Vector3<f64>, dgamma: f64, regime: Regime) -> Matrix3<f64> {
        let el = &self.elasticity;
        let de = principal::elastic_matrix(el.lambda, el.mu);
        match regime {
            Regime::Elastic => de,
            Regime::Apex => {
                let r = self.apex_ratio();
                Matrix3::from_element(el.bulk * r / (1.0 + r))
            }
            _ => {
                let (q, u, _) = self.trial_invariants(eps);
                let root2g = 2f64.sqrt() * el.mu;
                let one = Vector3::from_element(1.0);
                let m = root2g * u + el.bulk * self.eta_bar * one;
                let n = root2g * u + el.bulk * self.eta * one;
                let mut d = de - m * n.transpose() / self.denominator();
                if dgamma > 0.0 && q > 0.0 {
                    let dev = Matrix3::identity() - Matrix3::from_element(1.0 / 3.0);
                    d -= 2.0 * el.mu * el.mu * dgamma / q * (dev - u * u.transpose());
                }
                d
            }
        }
    }

    /// The regime for continued loading from an elastic trial: the cone,
    /// or the apex when the stress sits there, if the trial lies on the
    /// surface to rounding (a state a load step starts from after plastic
    /// flow); elastic otherwise.
    fn loading_regime(&self, eps: &Vector3<f64>, history: &DruckerPragerHistory) -> Regime {
        let (q, _, p) = self.trial_invariants(eps);
        let c = self.cohesion(history);
        let scale = (self.xi * c).max(q).max(p.abs());
        if q + self.eta * p - self.xi * c < -1e-10 * scale {
            Regime::Elastic
        } else if q <= 1e-10 * scale {
            if self.eta > 0.0 {
                Regime::Apex
            } else {
                Regime::Elastic
            }
        } else {
            Regime::Plane
        }
    }

    fn tangent_of(
        &self,
        trial: &SymSpectral,
        state: &LawState<DruckerPragerHistory>,
        dgamma: f64,
        regime: Regime,
    ) -> Tensor4 {
        let d = self.principal_tangent(&trial.values, dgamma, regime);
        principal::tangent(trial, &state.tau, &d)
    }
}

impl LogStrainLaw for DruckerPrager {
    type History = DruckerPragerHistory;

    /// Non-associated flow makes the tangent unsymmetric;
    /// [`DruckerPrager::symmetric_tangent`] says per law.
    const SYMMETRIC_TANGENT: bool = false;

    fn symmetric_tangent(&self) -> bool {
        self.eta_bar == self.eta
    }

    fn return_map(
        &self,
        trial: &SymSpectral,
        history: &DruckerPragerHistory,
    ) -> LawState<DruckerPragerHistory> {
        let (strain, gamma, regime) = self.principal_return(&trial.values, history);
        let alpha = history.alpha
            + match regime {
                Regime::Elastic => 0.0,
                Regime::Apex => self.xi / self.apex_eta_bar() * gamma,
                _ => self.xi * gamma,
            };
        LawState {
            tau: self.elasticity.principal_stress(&strain),
            elastic_strain: strain,
            history: DruckerPragerHistory { alpha, regime },
            yielded: regime != Regime::Elastic,
        }
    }

    fn algorithmic_tangent(
        &self,
        trial: &SymSpectral,
        history: &DruckerPragerHistory,
        state: &LawState<DruckerPragerHistory>,
    ) -> Tensor4 {
        if !state.yielded {
            return self.elasticity.stiffness();
        }
        let dgamma = (state.history.alpha - history.alpha) / self.xi;
        self.tangent_of(trial, state, dgamma, state.history.regime)
    }

    fn loading_tangent(
        &self,
        trial: &SymSpectral,
        history: &DruckerPragerHistory,
        state: &LawState<DruckerPragerHistory>,
    ) -> Tensor4 {
        if state.yielded {
            return self.algorithmic_tangent(trial, history, state);
        }
        match self.loading_regime(&trial.values, history) {
            Regime::Elastic => self.elasticity.stiffness(),
            regime => self.tangent_of(trial, state, 0.0, regime),
        }
    }

    fn regime(&self, state: &LawState<DruckerPragerHistory>) -> u8 {
        state.history.regime as u8
    }

    fn elasticity(&self) -> Option<IsotropicElasticity> {
        Some(self.elasticity)
    }

    fn stored_energy(
        &self,
        elastic_strain: &Vector3<f64>,
        _h: &DruckerPragerHistory,
    ) -> Option<f64> {
        Some(self.elasticity.energy(elastic_strain))
    }
}
