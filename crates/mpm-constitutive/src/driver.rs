//! The finite-strain stress update, generic over the small-strain law, and
//! the consistent tangents of the two formulations.
//!
//! Given the converged state of a material point ($F_n$, $b^e_n$, history)
//! and the deformation-gradient increment $\Delta F$ of the current
//! iteration, [`update`] computes
//! 1. $F = \Delta F F_n$ (eq. 16), $J = \det F = \Delta J J_n$ (eq. 17);
//! 2. $b^{e,tr} = \Delta F b^e_n \Delta F^T$ and $\varepsilon^{e,tr} =
//!    \tfrac12\ln b^{e,tr}$;
//! 3. the law's return map, giving $\tau$, $\varepsilon^e$ and the history;
//! 4. $b^e = \exp(2\varepsilon^e)$, $\sigma = \tau/J$, and on request the
//!    previously converged stress $\tilde P = \tau\Delta F^{-T}/J_n$
//!    (eq. 18).
//!
//! The tangents are separate calls so that an explicit solver, or a
//! residual-only evaluation, does not pay for them. [`ConsistentTangent`]
//! is the plug point: [`SpatialTangent`] is $a_{ijkl}$ of the updated
//! Lagrangian formulation (eq. A.1) and [`PreviouslyConvergedTangent`] is
//! $\tilde A_{ijkl}$ of the previously converged formulation (eqs. A.3–A.6).

use nalgebra::{Matrix3, Vector3};

use crate::error::{ConstitutiveError, Result};
use crate::kinematics::{positive_determinant, require_finite, trial_elastic_left_cauchy_green};
use crate::law::{LawState, LogStrainLaw};
use crate::spectral::SymSpectral;
use crate::tensor::{Tensor4, delta, idx, mul_b_form, mul_minor_symmetric};

/// The converged state of a material point's material: elastic left
/// Cauchy–Green tensor and the law's history. (The deformation gradient
/// $F_n$ is kinematics and lives with the material point.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialState<H> {
    /// $b^e_n$.
    pub be: Matrix3<f64>,
    /// The law's internal variables.
    pub history: H,
}

impl<H: Default> Default for MaterialState<H> {
    /// The undeformed, virgin state: $b^e = \mathbf 1$.
    fn default() -> Self {
        Self {
            be: Matrix3::identity(),
            history: H::default(),
        }
    }
}

/// The result of a stress update, holding what the tangents need.
#[derive(Debug, Clone, Copy)]
pub struct Response<H> {
    /// $\Delta F$.
    pub delta_f: Matrix3<f64>,
    /// $\Delta F^{-1}$.
    pub delta_f_inv: Matrix3<f64>,
    /// $F = \Delta F F_n$.
    pub f: Matrix3<f64>,
    /// $J = \det F$.
    pub j: f64,
    /// $J_n = \det F_n$.
    pub j_n: f64,
    /// Kirchhoff stress $\tau$.
    pub tau: Matrix3<f64>,
    /// Cauchy stress $\sigma = \tau/J$.
    pub sigma: Matrix3<f64>,
    /// The updated material state ($b^e$, history) to store on convergence.
    pub state: MaterialState<H>,
    /// $b^e_n$ (needed by $\tilde B$, eq. A.5).
    pub be_n: Matrix3<f64>,
    /// Spectral decomposition of $b^{e,tr}$.
    pub trial_be: SymSpectral,
    /// Principal trial elastic Hencky strains $\tfrac12\ln\lambda_a$ of
    /// $b^{e,tr}$ (the values of [`Self::trial_strain`]), kept from the
    /// update: the tangents read them again, and a law chosen at run time
    /// (an enum over laws) cannot let the compiler drop the logarithms
    /// for the laws whose tangent ignores them, as a typed law does.
    pub trial_strain_values: Vector3<f64>,
    /// The law's return-map result (principal values in the basis of
    /// `trial_be`).
    pub law_state: LawState<H>,
    /// The converged history the step started from.
    pub history_n: H,
}

impl<H: Copy> Response<H> {
    /// The previously converged stress $\tilde P = \tau\Delta F^{-T}/J_n$
    /// (eq. 18), work-conjugate to $\Delta F$ per unit volume $V^n_p$.
    #[inline]
    pub fn p_tilde(&self) -> Matrix3<f64> {
        self.tau * self.delta_f_inv.transpose() / self.j_n
    }

    /// Spectral decomposition of the trial elastic Hencky strain
    /// $\varepsilon^{e,tr} = \tfrac12\ln b^{e,tr}$ (same basis as $b^{e,tr}$).
    #[inline]
    pub fn trial_strain(&self) -> SymSpectral {
        SymSpectral {
            values: self.trial_strain_values,
            vectors: self.trial_be.vectors,
        }
    }

    /// Whether the step was plastic.
    pub fn yielded(&self) -> bool {
        self.law_state.yielded
    }
}

/// The finite-strain stress update of a material point (module docs).
///
/// Errors: non-finite input, $\det\Delta F \le 0$, $\det F_n \le 0$, or a
/// $b^e_n$ that is not positive definite.
pub fn update<L: LogStrainLaw>(
    law: &L,
    delta_f: &Matrix3<f64>,
    f_n: &Matrix3<f64>,
    state_n: &MaterialState<L::History>,
) -> Result<Response<L::History>> {
    let delta_j = positive_determinant("ΔF", delta_f)?;
    let j_n = positive_determinant("F_n", f_n)?;
    require_finite("b_e^n", &state_n.be)?;
    let delta_f_inv = delta_f
        .try_inverse()
        .ok_or(ConstitutiveError::NonPositiveJacobian {
            which: "ΔF",
            det: delta_j,
        })?;
    let trial_be = SymSpectral::new(&trial_elastic_left_cauchy_green(delta_f, &state_n.be))?;
    let eigenvalue = trial_be.min_value();
    if eigenvalue <= 0.0 {
        return Err(ConstitutiveError::NotPositiveDefinite { eigenvalue });
    }
    let trial_eps = SymSpectral {
        values: trial_be.values.map(|l| 0.5 * l.ln()),
        vectors: trial_be.vectors,
    };
    let law_state = law.return_map(&trial_eps, &state_n.history);
    let tau = trial_be.compose(&law_state.tau);
    let be = trial_be.compose(&law_state.elastic_strain.map(|e| (2.0 * e).exp()));
    let j = delta_j * j_n;
    Ok(Response {
        delta_f: *delta_f,
        delta_f_inv,
        f: delta_f * f_n,
        j,
        j_n,
        tau,
        sigma: tau / j,
        state: MaterialState {
            be,
            history: law_state.history,
        },
        be_n: state_n.be,
        trial_strain_values: trial_eps.values,
        trial_be,
        law_state,
        history_n: state_n.history,
    })
}

/// The ingredients shared by both consistent tangents.
#[derive(Debug, Clone, Copy)]
pub struct TangentParts {
    /// $D^{alg}$ from the law.
    pub d_alg: Tensor4,
    /// $L = \partial\ln b^{e,tr}/\partial b^{e,tr}$ (eq. A.2).
    pub dlog: Tensor4,
}

impl TangentParts {
    /// $D^{alg}$ and $L$ of a response.
    #[inline(always)]
    pub fn new<L: LogStrainLaw>(law: &L, r: &Response<L::History>) -> Result<Self> {
        let d_alg = law.algorithmic_tangent(&r.trial_strain(), &r.history_n, &r.law_state);
        Ok(Self {
            d_alg,
            dlog: r.trial_be.dlog()?,
        })
    }

    /// $D$ for continued loading ([`LogStrainLaw::loading_tangent`]) and
    /// $L$ of a response.
    #[inline(always)]
    pub fn loading<L: LogStrainLaw>(law: &L, r: &Response<L::History>) -> Result<Self> {
        let d_alg = law.loading_tangent(&r.trial_strain(), &r.history_n, &r.law_state);
        Ok(Self {
            d_alg,
            dlog: r.trial_be.dlog()?,
        })
    }
}

/// A consistent tangent of one formulation: the plug point through which
/// the solver's `Formulation` picks its tangent at compile time.
pub trait ConsistentTangent: Send + Sync + 'static {
    /// The $9\times 9$ tangent of a response.
    fn assemble<H: Copy>(r: &Response<H>, parts: &TangentParts) -> Tensor4;

    /// Convenience: the tangent straight from the law and the response.
    #[inline(always)]
    fn tangent<L: LogStrainLaw>(law: &L, r: &Response<L::History>) -> Result<Tensor4> {
        Ok(Self::assemble(r, &TangentParts::new(law, r)?))
    }

    /// The tangent for continued loading ([`TangentParts::loading`]).
    #[inline(always)]
    fn loading_tangent<L: LogStrainLaw>(law: &L, r: &Response<L::History>) -> Result<Tensor4> {
        Ok(Self::assemble(r, &TangentParts::loading(law, r)?))
    }
}

/// The spatial consistent tangent of the updated Lagrangian formulation
/// (eq. A.1):
/// $$ a_{ijkl} = \frac{1}{2J} D^{alg}_{ijmn} L_{mnpq} B_{pqkl} - \sigma_{il}\delta_{jk}. $$
/// It linearises the updated Lagrangian internal force (eq. 6) with spatial
/// basis gradients (eq. 8): for a perturbation $dF = G F$,
/// $d(\sigma_{ij}\,\partial_{x_j}S\;V) = a_{ijkl}G_{kl}\,\partial_{x_j}S\;V$.
/// Equivalently it is the push-forward of the first elasticity tensor,
/// $a_{ijkl} = J^{-1}F_{jm}(\partial P_{im}/\partial F_{kn})F_{ln}$ with
/// $P = \tau F^{-T}$, and it differs from $(\partial\sigma_{ij}/\partial
/// F_{km})F_{lm}$ — the paper's shorthand for it — by the geometric terms
/// $\sigma_{ij}\delta_{kl} - \sigma_{il}\delta_{jk}$ from the changing
/// volume and spatial gradients. The tests check all three statements
/// against finite differences. (The extracted text's
/// "$S_{ijkl} = \sigma_{ij}\delta_{jk}$" is a typesetting slip for
/// $\sigma_{il}\delta_{jk}$.)
#[derive(Debug, Clone, Copy, Default)]
pub struct SpatialTangent;

impl ConsistentTangent for SpatialTangent {
    fn assemble<H: Copy>(r: &Response<H>, parts: &TangentParts) -> Tensor4 {
        let b = r.trial_be.compose(&r.trial_be.values);
        // D L B with the structure of L and B exploited (tensor module);
        // equal to the dense product to rounding (unit test below).
        let mut a = mul_b_form(&mul_minor_symmetric(&parts.d_alg, &parts.dlog), &b) / (2.0 * r.j);
        for i in 0..3 {
            for j in 0..3 {
                for l in 0..3 {
                    a[(idx(i, j), idx(j, l))] -= r.sigma[(i, l)];
                }
            }
        }
        a
    }
}

/// The previously converged consistent tangent (eqs. A.3–A.6):
/// $$ \tilde A_{ijkl} = \frac{\partial\tilde P_{ij}}{\partial\Delta F_{kl}}
///  = \frac1{J_n}\Big(\frac{\partial\tau_{im}}{\partial\Delta F_{kl}}(\Delta F^{-1})_{jm} -
///    \tau_{im}(\Delta F^{-1})_{jk}(\Delta F^{-1})_{lm}\Big),\quad
///   \frac{\partial\tau_{ij}}{\partial\Delta F_{kl}} = \tfrac12 D^{alg}_{ijmn}L_{mnpq}\tilde B_{pqkl}. $$
#[derive(Debug, Clone, Copy, Default)]
pub struct PreviouslyConvergedTangent;

impl ConsistentTangent for PreviouslyConvergedTangent {
    fn assemble<H: Copy>(r: &Response<H>, parts: &TangentParts) -> Tensor4 {
        let dtau = 0.5
            * mul_b_form(
                &mul_minor_symmetric(&parts.d_alg, &parts.dlog),
                &(r.delta_f * r.be_n),
            );
        let finv = &r.delta_f_inv;
        // τ ΔF^{-T}: the second term is -(τΔF^{-T})_il (ΔF^{-1})_jk.
        let tau_finv_t = r.tau * finv.transpose();
        let mut out = Tensor4::zeros();
        for i in 0..3 {
            for j in 0..3 {
                let row = idx(i, j);
                for c in 0..9 {
                    let (k, l) = (c / 3, c % 3);
                    let mut v = 0.0;
                    for m in 0..3 {
                        v += dtau[(idx(i, m), c)] * finv[(j, m)];
                    }
                    out[(row, c)] = (v - tau_finv_t[(i, l)] * finv[(j, k)]) / r.j_n;
                }
            }
        }
        out
    }
}

/// The geometric difference between [`SpatialTangent`] and the plain
/// derivative of the Cauchy stress:
/// $(\partial\sigma_{ij}/\partial F_{km})F_{lm} = a_{ijkl} - \sigma_{ij}\delta_{kl} + \sigma_{il}\delta_{jk}$.
pub fn cauchy_stress_derivative(a: &Tensor4, sigma: &Matrix3<f64>) -> Tensor4 {
    Tensor4::from_fn(|r, c| {
        let (i, j, k, l) = (r / 3, r % 3, c / 3, c % 3);
        a[(r, c)] - sigma[(i, j)] * delta(k, l) + sigma[(i, l)] * delta(j, k)
    })
}

/// Principal values helper for callers that want the elastic Hencky strain
/// tensor of a response.
pub fn elastic_strain<H: Copy>(r: &Response<H>) -> Matrix3<f64> {
    let e: Vector3<f64> = r.law_state.elastic_strain;
    r.trial_be.compose(&e)
}
