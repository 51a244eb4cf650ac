//! A constitutive law written outside the framework.

use mpm_constitutive::tensor::{Tensor4, dyad, sym_identity};
use mpm_constitutive::{
    ConstitutiveError, IsotropicElasticity, LawState, LogStrainLaw, SymSpectral,
};
use nalgebra::{Matrix3, Vector3};

/// Hencky elasticity with a shear modulus that grows with the deviatoric
/// Hencky strain $e = \operatorname{dev}\varepsilon$: the stored energy
/// $$\psi = \tfrac12 K(\operatorname{tr}\varepsilon)^2 + \mu_0\left(e:e + \tfrac{\beta}{2}(e:e)^2\right)$$
/// gives the Kirchhoff stress
/// $\tau = K\operatorname{tr}\varepsilon\,\mathbf 1 + 2\mu_0(1 + \beta\,e:e)\,e$
/// and the (symmetric) tangent
/// $D = K\,\mathbf 1\otimes\mathbf 1 + 2\mu_0(1 + \beta\,e:e)\,\mathbb I^{dev} + 4\mu_0\beta\,e\otimes e$,
/// with $\mathbb I^{dev} = \mathbb I^s - \tfrac13\mathbf 1\otimes\mathbf 1$.
/// With $\beta = 0$ it is the framework's `HenckyElastic`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StiffeningHencky {
    elasticity: IsotropicElasticity,
    beta: f64,
}

impl StiffeningHencky {
    /// From Young's modulus `e`, Poisson's ratio `nu` (at zero strain) and
    /// the stiffening coefficient `beta` >= 0.
    ///
    /// # Errors
    /// The framework's [`ConstitutiveError`] for `e` or `nu` out of range;
    /// a negative or non-finite `beta` is reported as an invalid modulus.
    pub fn new(e: f64, nu: f64, beta: f64) -> Result<Self, ConstitutiveError> {
        if !(beta.is_finite() && beta >= 0.0) {
            return Err(ConstitutiveError::InvalidYoungsModulus { value: beta });
        }
        Ok(Self {
            elasticity: IsotropicElasticity::new(e, nu)?,
            beta,
        })
    }

    /// Principal deviatoric strains and $1 + \beta\,e:e$.
    fn deviator(&self, eps: &Vector3<f64>) -> (Vector3<f64>, f64) {
        let mean = eps.sum() / 3.0;
        let e = eps.map(|x| x - mean);
        (e, 1.0 + self.beta * e.norm_squared())
    }
}

impl LogStrainLaw for StiffeningHencky {
    type History = ();

    fn return_map(&self, trial: &SymSpectral, _history: &()) -> LawState<()> {
        let (e, factor) = self.deviator(&trial.values);
        let (k, mu) = (self.elasticity.bulk, self.elasticity.mu);
        let tr = trial.values.sum();
        LawState {
            tau: e.map(|ea| k * tr + 2.0 * mu * factor * ea),
            elastic_strain: trial.values,
            history: (),
            yielded: false,
        }
    }

    fn algorithmic_tangent(&self, trial: &SymSpectral, _h: &(), _s: &LawState<()>) -> Tensor4 {
        let (e, factor) = self.deviator(&trial.values);
        let (k, mu) = (self.elasticity.bulk, self.elasticity.mu);
        let one = Matrix3::identity();
        let e_tensor = trial.compose(&e);
        let dev = sym_identity() - dyad(&one, &one) / 3.0;
        k * dyad(&one, &one)
            + 2.0 * mu * factor * dev
            + 4.0 * mu * self.beta * dyad(&e_tensor, &e_tensor)
    }
}
