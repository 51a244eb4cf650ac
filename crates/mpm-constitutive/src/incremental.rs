//! Stress updates driven by a deformation increment, the form an explicit
//! dynamic solver calls once per material point and time step.
//!
//! An explicit step (MPoint theory notes, Fig. 4 and eqs. 38–44) gives
//! each point the increment $\Delta F = \mathbf 1 + \Delta t\,\nabla v$ (eq.
//! 39) and needs the new Kirchhoff stress. The notes update a small-strain
//! stress rate (eqs. 42–44); here the update is objective and free of
//! rate-form drift: the elastic left Cauchy–Green tensor is pushed
//! forward, $b^{e,tr} = \Delta F\,b^e_n\,\Delta F^T$, and the stress follows
//! from it as in the implicit driver (Coombs et al. 2020 §2). An elastic
//! body therefore returns exactly to zero stress when it returns to its
//! initial shape, whatever the path.
//!
//! Two implementations:
//! - [`Spectral`] wraps any [`LogStrainLaw`] (Hencky, von Mises, a user's
//!   law) through the finite-strain [`crate::driver`] (one symmetric
//!   eigen-decomposition per update);
//! - [`NeoHookean`] implements it in closed form,
//!   $\tau = \mu(b - \mathbf 1) + \tfrac\lambda2\ln(\det b)\,\mathbf 1$, with
//!   no eigen-decomposition and no logarithm of a tensor: the fast path of
//!   explicit dynamics. `tests/incremental.rs` checks that both agree.

use std::fmt::Debug;

use nalgebra::Matrix3;

use crate::driver::{self, MaterialState};
use crate::error::{ConstitutiveError, Result};
use crate::law::LogStrainLaw;
use crate::material_set::{MaterialSet, Tagged};
use crate::neo_hookean::NeoHookean;
use crate::spectral::SymSpectral;

/// A stress update from a deformation increment (module docs).
pub trait IncrementalLaw: Send + Sync {
    /// Per-point state; its `Default` is the undeformed, virgin state.
    type State: Copy + Default + Debug + PartialEq + Send + Sync + 'static;

    /// Advances `state` by the deformation increment `delta_f` and returns
    /// the new Kirchhoff stress $\tau$. On error `state` is unchanged.
    ///
    /// # Errors
    /// $\det\Delta F \le 0$ (the increment inverts the material) or
    /// non-finite input.
    fn update(&self, delta_f: &Matrix3<f64>, state: &mut Self::State) -> Result<Matrix3<f64>>;

    /// The stored energy per unit reference volume held in `state`.
    ///
    /// # Errors
    /// [`ConstitutiveError::NoStoredEnergy`] when the law does not define
    /// one; decomposition errors.
    fn stored_energy(&self, state: &Self::State) -> Result<f64>;

    /// The P-wave modulus $K + \tfrac43 G$ of the wave speed
    /// $c = \sqrt{(K + \tfrac43 G)/\rho}$ (MPoint notes eq. 46, with
    /// $K = E/(3(1-2\nu))$: the notes' $E/(3(1+\nu))$ is a misprint).
    fn p_wave_modulus(&self) -> f64;

    /// The P-wave modulus of the point whose state is `state`: the law's
    /// own [`Self::p_wave_modulus`] unless the law holds several materials
    /// ([`MaterialSet`]), whose points each have their material's. The
    /// time step of eq. (45) takes $\max_p(c_p + \|v_p\|)$ with
    /// $c_p = \sqrt{M_p/\rho_p}$ from it, so a stiff layer sets the step
    /// where it is, not a soft layer's points at the stiff modulus.
    #[inline(always)]
    fn point_p_wave_modulus(&self, state: &Self::State) -> f64 {
        let _ = state;
        self.p_wave_modulus()
    }
}

/// Several materials in one explicit analysis: the update, the stored
/// energy and the wave modulus of each point's material (its [`Tagged`]
/// state). [`IncrementalLaw::p_wave_modulus`] of the set is the largest of
/// its materials' (an upper bound); the step uses each point's own.
impl<L: IncrementalLaw> IncrementalLaw for MaterialSet<L> {
    type State = Tagged<L::State>;

    #[inline]
    fn update(&self, delta_f: &Matrix3<f64>, state: &mut Self::State) -> Result<Matrix3<f64>> {
        self.law(state.material).update(delta_f, &mut state.inner)
    }

    fn stored_energy(&self, state: &Self::State) -> Result<f64> {
        self.law(state.material).stored_energy(&state.inner)
    }

    fn p_wave_modulus(&self) -> f64 {
        self.laws()
            .iter()
            .map(IncrementalLaw::p_wave_modulus)
            .fold(0.0, f64::max)
    }

    #[inline(always)]
    fn point_p_wave_modulus(&self, state: &Self::State) -> f64 {
        self.law(state.material).point_p_wave_modulus(&state.inner)
    }
}

/// Any [`LogStrainLaw`] as an [`IncrementalLaw`], through the finite-strain
/// driver: $b^{e,tr} = \Delta F b^e_n\Delta F^T$, the return map in
/// principal Hencky strains, $\tau$ coaxial with $b^{e,tr}$.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spectral<L> {
    law: L,
    p_wave_modulus: f64,
}

impl<L: LogStrainLaw> Spectral<L> {
    /// Wraps `law`, taking the wave speed from its elastic constants.
    ///
    /// # Errors
    /// [`ConstitutiveError::NoElasticConstants`] when the law has none;
    /// use [`Spectral::with_p_wave_modulus`] then.
    pub fn new(law: L) -> Result<Self> {
        let m = law
            .elasticity()
            .ok_or(ConstitutiveError::NoElasticConstants)?
            .p_wave_modulus();
        Self::with_p_wave_modulus(law, m)
    }

    /// Wraps `law` with the given P-wave modulus $K + \tfrac43 G$.
    ///
    /// # Errors
    /// A modulus that is not positive and finite.
    pub fn with_p_wave_modulus(law: L, p_wave_modulus: f64) -> Result<Self> {
        if !(p_wave_modulus.is_finite() && p_wave_modulus > 0.0) {
            return Err(ConstitutiveError::InvalidWaveModulus {
                value: p_wave_modulus,
            });
        }
        Ok(Self {
            law,
            p_wave_modulus,
        })
    }

    /// The wrapped law.
    pub fn law(&self) -> &L {
        &self.law
    }
}

impl<L: LogStrainLaw> IncrementalLaw for Spectral<L> {
    type State = MaterialState<L::History>;

    #[inline]
    fn update(&self, delta_f: &Matrix3<f64>, state: &mut Self::State) -> Result<Matrix3<f64>> {
        // F_n only enters the driver's determinant check and its outputs
        // F and J, which the explicit solver tracks itself.
        let response = driver::update(&self.law, delta_f, &Matrix3::identity(), state)?;
        *state = response.state;
        Ok(response.tau)
    }

    fn stored_energy(&self, state: &Self::State) -> Result<f64> {
        let be = SymSpectral::new(&state.be)?;
        let eps = be.values.map(|l| 0.5 * l.ln());
        self.law
            .stored_energy(&eps, &state.history)
            .ok_or(ConstitutiveError::NoStoredEnergy)
    }

    fn p_wave_modulus(&self) -> f64 {
        self.p_wave_modulus
    }

    /// The law's modulus at the point's state when it depends on it
    /// ([`LogStrainLaw::state_p_wave_modulus`]), the constant otherwise.
    #[inline(always)]
    fn point_p_wave_modulus(&self, state: &Self::State) -> f64 {
        self.law
            .state_p_wave_modulus(&state.be, &state.history)
            .unwrap_or(self.p_wave_modulus)
    }
}

/// Closed form: $b = \Delta F b_n \Delta F^T$,
/// $\tau = \mu(b - \mathbf 1) + \lambda\ln J\,\mathbf 1$ with
/// $\ln J = \tfrac12\ln\det b$ (Bonet & Wood eq. 6.29). The state is $b$.
impl IncrementalLaw for NeoHookean {
    type State = MaterialState<()>;

    #[inline]
    fn update(&self, delta_f: &Matrix3<f64>, state: &mut Self::State) -> Result<Matrix3<f64>> {
        let det = delta_f.determinant();
        if det.is_nan() || det <= 0.0 {
            return Err(if det.is_nan() {
                ConstitutiveError::NonFinite {
                    which: "ΔF",
                    value: det,
                }
            } else {
                ConstitutiveError::NonPositiveJacobian { which: "ΔF", det }
            });
        }
        let b = delta_f * state.be * delta_f.transpose();
        let det_b = b.determinant();
        if !(det_b > 0.0 && det_b.is_finite()) {
            return Err(ConstitutiveError::NonFinite {
                which: "b",
                value: det_b,
            });
        }
        state.be = b;
        let e = self.elasticity();
        let mut tau = e.mu * b;
        let diagonal = 0.5 * e.lambda * det_b.ln() - e.mu;
        for i in 0..3 {
            tau[(i, i)] += diagonal;
        }
        Ok(tau)
    }

    /// $\psi = \tfrac\mu2(\mathrm{tr}\,b - 3) - \mu\ln J + \tfrac\lambda2(\ln J)^2$.
    fn stored_energy(&self, state: &Self::State) -> Result<f64> {
        let det_b = state.be.determinant();
        if !(det_b > 0.0 && det_b.is_finite()) {
            return Err(ConstitutiveError::NotPositiveDefinite { eigenvalue: det_b });
        }
        let e = self.elasticity();
        let ln_j = 0.5 * det_b.ln();
        Ok(0.5 * e.mu * (state.be.trace() - 3.0) - e.mu * ln_j + 0.5 * e.lambda * ln_j * ln_j)
    }

    fn p_wave_modulus(&self) -> f64 {
        self.elasticity().p_wave_modulus()
    }
}
