//! The plug point for constitutive models: a small-strain algorithmic law in
//! (Hencky) logarithmic strain / Kirchhoff stress space.
//!
//! With the multiplicative split $F = F^e F^p$ and the exponential-map
//! integration of the flow rule, finite-strain elasto-plasticity reduces to
//! a small-strain return map driven by the trial elastic Hencky strain
//! $\varepsilon^{e,tr} = \tfrac12 \ln b^{e,tr}$, with the Kirchhoff stress
//! $\tau$ conjugate to it (Coombs et al. 2020 §2 and the framework of their
//! refs. [19, 21, 26]). The finite-strain [`crate::driver`] is generic over
//! this trait, so a new material only implements the return map and its
//! algorithmic tangent $D^{alg} = \partial\tau/\partial\varepsilon^{e,tr}$.
//!
//! Isotropy makes the return coaxial with the trial strain: a law receives
//! the spectral decomposition of $\varepsilon^{e,tr}$ (which the driver has
//! anyway from $b^{e,tr}$) and returns principal values in the same basis.

use std::fmt::Debug;

use crate::error::{ConstitutiveError, Result};
use crate::spectral::SymSpectral;
use crate::tensor::{Tensor4, dyad, sym_identity};
use nalgebra::{Matrix3, Vector3};

/// The outcome of one return map, in the principal basis of the trial strain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawState<H> {
    /// Principal Kirchhoff stresses $\tau_a$.
    pub tau: Vector3<f64>,
    /// Principal elastic Hencky strains $\varepsilon^e_a$ after the return.
    pub elastic_strain: Vector3<f64>,
    /// The updated history (internal variables).
    pub history: H,
    /// Whether the step was plastic.
    pub yielded: bool,
}

/// A small-strain algorithmic law in Hencky strain / Kirchhoff stress space.
pub trait LogStrainLaw: Send + Sync {
    /// Internal variables carried by each material point: `()` for
    /// elasticity, so elastic scenes carry no plastic state.
    type History: Copy + Default + Debug + PartialEq + Send + Sync + 'static;

    /// Whether $D^{alg}$ is major-symmetric. Then the global stiffness of
    /// either formulation is symmetric (it is the Hessian of an algorithmic
    /// potential) and the solver may use Cholesky. True for hyperelastic
    /// laws and associated plasticity with a closest-point return.
    const SYMMETRIC_TANGENT: bool = true;

    /// Whether this law's $D^{alg}$ is major-symmetric: per law for a
    /// family whose [`Self::SYMMETRIC_TANGENT`] must hold for its every
    /// member (e.g. associated soil plasticity, $\psi = \phi$). Default:
    /// [`Self::SYMMETRIC_TANGENT`].
    fn symmetric_tangent(&self) -> bool {
        Self::SYMMETRIC_TANGENT
    }

    /// A code of the part of the yield surface `state` was returned to,
    /// for checks that compare like with like (a finite difference must
    /// not straddle a change of regime): 0 elastic, 1 plastic by default;
    /// multi-surface laws give their [`crate::principal::Regime`].
    fn regime(&self, state: &LawState<Self::History>) -> u8 {
        u8::from(state.yielded)
    }

    /// The return map: stress, elastic strain and history from the trial
    /// elastic strain (given spectrally) and the converged history.
    fn return_map(&self, trial: &SymSpectral, history: &Self::History) -> LawState<Self::History>;

    /// The algorithmic tangent $D^{alg}_{ijkl} = \partial\tau_{ij} /
    /// \partial\varepsilon^{e,tr}_{kl}$ (minor-symmetric) consistent with
    /// [`Self::return_map`], which produced `state` from `trial` and
    /// `history`.
    fn algorithmic_tangent(
        &self,
        trial: &SymSpectral,
        history: &Self::History,
        state: &LawState<Self::History>,
    ) -> Tensor4;

    /// The tangent for continued loading: equal to
    /// [`Self::algorithmic_tangent`] except at a trial state *on* the
    /// yield surface, where the return map has a kink (taken as elastic by
    /// [`Self::return_map`]) and this is the one-sided derivative for
    /// plastic loading. A load step starts at such states ($\Delta F = 1$
    /// for the points that yielded in the last step); the solver's first
    /// solve of a displacement-driven step (`FirstTangent::Converged`)
    /// takes its stiffness from this tangent, so that the points that
    /// flowed are not treated as elastic (docs/src/theory/constitutive.md,
    /// "The tangent on the yield surface"). The default, for laws without
    /// a yield surface, is the algorithmic tangent.
    fn loading_tangent(
        &self,
        trial: &SymSpectral,
        history: &Self::History,
        state: &LawState<Self::History>,
    ) -> Tensor4 {
        self.algorithmic_tangent(trial, history, state)
    }

    /// The law's small-strain elastic constants, when it has isotropic
    /// ones: explicit solvers take the wave speed of eq. (46) of the MPoint
    /// notes from them. `None` by default.
    fn elasticity(&self) -> Option<IsotropicElasticity> {
        None
    }

    /// The small-strain shear modulus $\mu$ at a point of internal
    /// variables `history`: the law's own ([`Self::elasticity`]) unless the
    /// law holds several materials ([`crate::MaterialSet`]), whose points
    /// each have their material's. Stabilisations that scale with the
    /// stiffness take it per point (the implicit solver's ghost penalty,
    /// `mpm_solver::stages::ghost`), so a soft body's cut cells are not
    /// penalised at a stiff body's modulus. `None` when the law has no
    /// elastic constants.
    #[inline]
    fn point_shear_modulus(&self, history: &Self::History) -> Option<f64> {
        let _ = history;
        self.elasticity().map(|e| e.mu)
    }

    /// The P-wave modulus $K + \tfrac43G$ of a point whose elastic left
    /// Cauchy–Green tensor is `be`, when the law's stiffness depends on
    /// its state (Cam-Clay's bulk modulus $p/\hat\kappa$): the explicit
    /// solver's time step takes each point's wave speed from it. `None`
    /// (the default): the constant modulus of [`Self::elasticity`].
    #[inline]
    fn state_p_wave_modulus(&self, be: &Matrix3<f64>, history: &Self::History) -> Option<f64> {
        let _ = (be, history);
        None
    }

    /// The stored (recoverable) energy per unit reference volume of the
    /// elastic Hencky strain with principal values `elastic_strain`, for
    /// energy balances; plastic dissipation is not included. `None` when
    /// the law does not define it (the default).
    fn stored_energy(&self, elastic_strain: &Vector3<f64>, history: &Self::History) -> Option<f64> {
        let _ = (elastic_strain, history);
        None
    }

    /// Convenience for tests and callers holding a plain tensor: the return
    /// map of the symmetric trial strain `eps`, with the Kirchhoff stress as
    /// a tensor.
    fn kirchhoff_stress(
        &self,
        eps: &Matrix3<f64>,
        history: &Self::History,
    ) -> Result<(Matrix3<f64>, LawState<Self::History>)> {
        let trial = SymSpectral::new(eps)?;
        let state = self.return_map(&trial, history);
        Ok((trial.compose(&state.tau), state))
    }
}

/// Isotropic linear elasticity between Hencky strain and Kirchhoff stress,
/// $\tau = \lambda\,\mathrm{tr}(\varepsilon)\mathbf 1 + 2\mu\varepsilon$,
/// shared by the models of this crate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsotropicElasticity {
    youngs_modulus: f64,
    poisson_ratio: f64,
    /// Lamé's first parameter $\lambda$.
    pub lambda: f64,
    /// Shear modulus $\mu$.
    pub mu: f64,
    /// Bulk modulus $K = \lambda + 2\mu/3$.
    pub bulk: f64,
}

impl IsotropicElasticity {
    /// From Young's modulus `e` > 0 and Poisson's ratio `nu` in (-1, 0.5).
    pub fn new(e: f64, nu: f64) -> Result<Self> {
        if !(e.is_finite() && e > 0.0) {
            return Err(ConstitutiveError::InvalidYoungsModulus { value: e });
        }
        if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
            return Err(ConstitutiveError::InvalidPoissonRatio { value: nu });
        }
        let mu = e / (2.0 * (1.0 + nu));
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        Ok(Self {
            youngs_modulus: e,
            poisson_ratio: nu,
            lambda,
            mu,
            bulk: lambda + 2.0 * mu / 3.0,
        })
    }

    /// Young's modulus $E$.
    pub fn youngs_modulus(&self) -> f64 {
        self.youngs_modulus
    }

    /// Poisson's ratio $\nu$.
    pub fn poisson_ratio(&self) -> f64 {
        self.poisson_ratio
    }

    /// Principal stresses $\tau_a = \lambda\sum_b\varepsilon_b + 2\mu\varepsilon_a$.
    #[inline]
    pub fn principal_stress(&self, eps: &Vector3<f64>) -> Vector3<f64> {
        let tr = eps.sum();
        eps.map(|e| self.lambda * tr + 2.0 * self.mu * e)
    }

    /// The quadratic strain energy $\psi = \tfrac\lambda2(\sum_a\varepsilon_a)^2 +
    /// \mu\sum_a\varepsilon_a^2$ of principal strains `eps`, whose
    /// derivative is [`Self::principal_stress`].
    #[inline]
    pub fn energy(&self, eps: &Vector3<f64>) -> f64 {
        let tr = eps.sum();
        0.5 * self.lambda * tr * tr + self.mu * eps.norm_squared()
    }

    /// The P-wave modulus $K + \tfrac43 G = \lambda + 2\mu$ (MPoint notes
    /// eq. 46 with the bulk modulus $K = E/(3(1-2\nu))$; the notes print
    /// $E/(3(1+\nu))$, a misprint).
    #[inline]
    pub fn p_wave_modulus(&self) -> f64 {
        self.bulk + 4.0 / 3.0 * self.mu
    }

    /// The elastic stiffness $D^e = \lambda\,\mathbf 1\otimes\mathbf 1 + 2\mu\,\mathbb I^s$.
    pub fn stiffness(&self) -> Tensor4 {
        let one = Matrix3::identity();
        self.lambda * dyad(&one, &one) + 2.0 * self.mu * sym_identity()
    }
}
