//! Compressible Neo-Hookean hyperelasticity as a law in Hencky strain.
//!
//! The stored energy (Bonet & Wood, *Nonlinear continuum mechanics for
//! finite element analysis*, 2nd ed., eq. 6.27)
//! $$\psi = \tfrac{\mu}{2}(\mathrm{tr}\,C - 3) - \mu\ln J + \tfrac{\lambda}{2}(\ln J)^2$$
//! is isotropic, so it is a function of the principal logarithmic strains
//! $\varepsilon_a = \ln\lambda_a$ of $\varepsilon = \tfrac12\ln b$:
//! $\psi = \tfrac{\mu}{2}\sum_a(e^{2\varepsilon_a} - 1) - \mu\sum_a\varepsilon_a +
//! \tfrac{\lambda}{2}(\sum_a\varepsilon_a)^2$, and the Kirchhoff stress is
//! coaxial with $b$ with principal values
//! $$\tau_a = \frac{\partial\psi}{\partial\varepsilon_a} = \mu(e^{2\varepsilon_a} - 1) + \lambda\ln J,$$
//! i.e. $\tau = \mu(b - \mathbf 1) + \lambda\ln J\,\mathbf 1$ (Bonet & Wood
//! eq. 6.29). As a [`LogStrainLaw`] it plugs into the same finite-strain
//! driver as Hencky elasticity (Coombs et al. 2020 §2, with no plastic
//! flow: $b^e = b$), which gives its updated-Lagrangian tangent $a_{ijkl}$
//! (eq. A.1) and previously-converged tangent $\tilde A_{ijkl}$ (eqs.
//! A.3–A.6) from the algorithmic tangent derived here.
//!
//! **Algorithmic tangent** (derived; checked by finite differences in
//! `tests/tangents.rs`). $\tau(\varepsilon) = \lambda\,\mathrm{tr}(\varepsilon)\mathbf 1 +
//! g(\varepsilon)$ with the isotropic tensor function
//! $g(\varepsilon) = \sum_a \mu(e^{2\varepsilon_a} - 1)\,n_a\otimes n_a$, so
//! $$D = \lambda\,\mathbf 1\otimes\mathbf 1 + \sum_a g'(\varepsilon_a)N_a\otimes N_a +
//! \sum_{a<b} 2\,\theta_{ab}\,M_{ab}\otimes M_{ab},$$
//! $N_a = n_a\otimes n_a$, $M_{ab} = \tfrac12(n_a\otimes n_b + n_b\otimes n_a)$,
//! $g'(\varepsilon) = 2\mu e^{2\varepsilon}$ and the divided difference
//! $\theta_{ab} = \frac{g(\varepsilon_a) - g(\varepsilon_b)}{\varepsilon_a - \varepsilon_b}
//! = 2\mu\,e^{\varepsilon_a + \varepsilon_b}\,\frac{\sinh(\varepsilon_a - \varepsilon_b)}{\varepsilon_a - \varepsilon_b}$,
//! evaluated in this form so that it is exact to rounding for equal and
//! nearly equal strains (where it tends to $g'$). At $\varepsilon = 0$,
//! $D = \lambda\mathbf 1\otimes\mathbf 1 + 2\mu\mathbb I^s$: the law agrees with
//! Hencky (and linear) elasticity to first order.

use crate::error::Result;
use crate::law::{IsotropicElasticity, LawState, LogStrainLaw};
use crate::spectral::SymSpectral;
use crate::tensor::{Tensor4, dyad};
use nalgebra::{Matrix3, Vector3};

/// Compressible Neo-Hookean elasticity,
/// $\tau = \mu(b - \mathbf 1) + \lambda\ln J\,\mathbf 1$ (see the module
/// documentation). It carries no history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeoHookean {
    elasticity: IsotropicElasticity,
}

impl NeoHookean {
    /// From Young's modulus `e` > 0 and Poisson's ratio `nu` in (-1, 0.5):
    /// the small-strain Lamé constants $\lambda$ and $\mu$ of the energy.
    pub fn new(e: f64, nu: f64) -> Result<Self> {
        Ok(Self {
            elasticity: IsotropicElasticity::new(e, nu)?,
        })
    }

    /// The elastic constants.
    pub fn elasticity(&self) -> &IsotropicElasticity {
        &self.elasticity
    }

    /// The stored energy per unit reference volume of a Hencky strain
    /// given by its principal values.
    pub fn energy(&self, principal_strain: &[f64; 3]) -> f64 {
        let (lambda, mu) = (self.elasticity.lambda, self.elasticity.mu);
        let ln_j: f64 = principal_strain.iter().sum();
        principal_strain
            .iter()
            .map(|e| 0.5 * mu * ((2.0 * e).exp() - 1.0))
            .sum::<f64>()
            - mu * ln_j
            + 0.5 * lambda * ln_j * ln_j
    }

    /// The Kirchhoff stress of a deformation gradient directly,
    /// $\mu(FF^T - \mathbf 1) + \lambda\ln J\,\mathbf 1$ (no logarithm):
    /// the reference the law is tested against.
    pub fn kirchhoff_of_f(&self, f: &Matrix3<f64>) -> Matrix3<f64> {
        let (lambda, mu) = (self.elasticity.lambda, self.elasticity.mu);
        let one = Matrix3::identity();
        mu * (f * f.transpose() - one) + lambda * f.determinant().ln() * one
    }
}

/// $\sinh(x)/x$, exact to rounding near 0.
fn sinhc(x: f64) -> f64 {
    if x.abs() < 1e-4 {
        // The series to x^4: the next term, x^6/5040, is below 1e-27.
        let x2 = x * x;
        1.0 + x2 / 6.0 * (1.0 + x2 / 20.0)
    } else {
        x.sinh() / x
    }
}

impl LogStrainLaw for NeoHookean {
    type History = ();

    #[inline]
    fn return_map(&self, trial: &SymSpectral, _history: &()) -> LawState<()> {
        let (lambda, mu) = (self.elasticity.lambda, self.elasticity.mu);
        let eps = trial.values;
        let ln_j = eps.sum();
        LawState {
            tau: eps.map(|e| mu * (2.0 * e).exp_m1() + lambda * ln_j),
            elastic_strain: eps,
            history: (),
            yielded: false,
        }
    }

    fn algorithmic_tangent(&self, trial: &SymSpectral, _h: &(), _s: &LawState<()>) -> Tensor4 {
        let (lambda, mu) = (self.elasticity.lambda, self.elasticity.mu);
        let one = Matrix3::identity();
        lambda * dyad(&one, &one) + trial.derivative(|a, b| 2.0 * mu * (a + b).exp() * sinhc(a - b))
    }

    fn elasticity(&self) -> Option<IsotropicElasticity> {
        Some(self.elasticity)
    }

    fn stored_energy(&self, elastic_strain: &Vector3<f64>, _history: &()) -> Option<f64> {
        Some(self.energy(&[elastic_strain[0], elastic_strain[1], elastic_strain[2]]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sinhc_is_continuous_at_the_switch() {
        for x in [1e-4f64, -1e-4] {
            let series = 1.0 + x * x / 6.0 * (1.0 + x * x / 20.0);
            assert!((series - x.sinh() / x).abs() < 1e-15);
        }
        assert_eq!(sinhc(0.0), 1.0);
    }

    #[test]
    fn small_strain_tangent_is_the_linear_elastic_one() {
        let law = NeoHookean::new(2e5, 0.3).expect("valid constants");
        let trial = SymSpectral::new(&Matrix3::zeros()).expect("zero strain");
        let state = law.return_map(&trial, &());
        let d = law.algorithmic_tangent(&trial, &(), &state);
        let de = law.elasticity().stiffness();
        assert!((d - de).norm() < 1e-9 * de.norm());
    }
}
