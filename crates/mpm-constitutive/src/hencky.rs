//! Hencky (logarithmic-strain) hyperelasticity.

use nalgebra::{Matrix3, Vector3};

use crate::error::Result;
use crate::law::{IsotropicElasticity, LawState, LogStrainLaw};
use crate::spectral::SymSpectral;
use crate::tensor::Tensor4;

/// Hencky elasticity: Kirchhoff stress linear in the Hencky strain,
/// $\tau = \lambda\,\mathrm{tr}(\varepsilon)\mathbf 1 + 2\mu\varepsilon$ with
/// $\varepsilon = \tfrac12\ln b$, the elastic law of Coombs et al. 2020 §2.
/// Its stored energy is
/// $\psi = \tfrac12\lambda(\mathrm{tr}\,\varepsilon)^2 + \mu\,\varepsilon:\varepsilon$, and the algorithmic tangent is the
/// constant $D^e$. It carries no history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HenckyElastic {
    elasticity: IsotropicElasticity,
}

impl HenckyElastic {
    /// From Young's modulus `e` > 0 and Poisson's ratio `nu` in (-1, 0.5).
    pub fn new(e: f64, nu: f64) -> Result<Self> {
        Ok(Self {
            elasticity: IsotropicElasticity::new(e, nu)?,
        })
    }

    /// The elastic constants.
    pub fn elasticity(&self) -> &IsotropicElasticity {
        &self.elasticity
    }
}

impl LogStrainLaw for HenckyElastic {
    type History = ();

    #[inline]
    fn return_map(&self, trial: &SymSpectral, _history: &()) -> LawState<()> {
        LawState {
            tau: self.elasticity.principal_stress(&trial.values),
            elastic_strain: trial.values,
            history: (),
            yielded: false,
        }
    }

    #[inline]
    fn algorithmic_tangent(&self, _trial: &SymSpectral, _h: &(), _s: &LawState<()>) -> Tensor4 {
        self.elasticity.stiffness()
    }

    fn elasticity(&self) -> Option<IsotropicElasticity> {
        Some(self.elasticity)
    }

    fn stored_energy(&self, elastic_strain: &Vector3<f64>, _history: &()) -> Option<f64> {
        Some(self.elasticity.energy(elastic_strain))
    }
}

impl HenckyElastic {
    /// Kirchhoff stress of a Hencky strain tensor (no spectral decomposition
    /// needed: the law is linear).
    pub fn kirchhoff(&self, eps: &Matrix3<f64>) -> Matrix3<f64> {
        let e = &self.elasticity;
        e.lambda * eps.trace() * Matrix3::identity() + 2.0 * e.mu * eps
    }
}
