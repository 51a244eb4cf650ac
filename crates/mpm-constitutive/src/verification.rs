//! Finite-difference verification of the consistent tangents, exported so
//! that a downstream [`LogStrainLaw`] is checked by the same code as the
//! laws of this crate (as fenris exports its element property tests).
//!
//! Each check linearises the finite-strain [`update`] of a law at one
//! state, compares an analytic tangent with a fourth-order central
//! difference of the corresponding stress, and returns the relative
//! Frobenius error [`relative_error`]:
//!
//! | check | analytic | finite difference of | Coombs 2020 |
//! | --- | --- | --- | --- |
//! | [`check_previously_converged`] | $\tilde A_{ijkl}$ | $\tilde P = \tau\Delta F^{-T}/J_n$ w.r.t. $\Delta F$ | eqs. 18, A.3–A.6 |
//! | [`check_spatial`] | $a_{ijkl}$ | $J^{-1}P F^T$ and $\sigma$ along $dF = GF$ | eq. A.1 |
//! | [`check_algorithmic_tangent`] | $D^{alg}$ | $\tau$ w.r.t. $\varepsilon^{e,tr}$ | §2, eq. A.2 |
//!
//! A check returns `Ok(None)` when the stencil crosses the yield surface
//! (some stencil point is elastic and another plastic), where the stress
//! is not differentiable and the comparison means nothing; a property test
//! rejects such a case. It returns `Err` when the input itself is invalid
//! (a non-positive step, $\det\Delta F \le 0$, a $b^e_n$ that is not
//! positive definite, …), never panics.
//!
//! # Step size
//! The difference quotient [`central_difference`] has truncation error
//! $O(h^4)$ and round-off $O(\epsilon/h)$. Every check scales its step with
//! the argument so that the *relative* perturbation is `step`; with
//! [`STEP`] $= 10^{-4}$ truncation is $\sim 10^{-16}$ and round-off
//! $\sim 10^{-12}$, both far below [`TOLERANCE`] $= 10^{-6}$. For yielding
//! states the step is reduced further by [`plastic_scale`]: the flow
//! direction $N = \operatorname{dev}\varepsilon/\|\operatorname{dev}
//! \varepsilon\|$ turns on the scale of $\|\operatorname{dev}
//! \varepsilon^{e,tr}\|$, which may be small.
//!
//! ```
//! use mpm_constitutive::verification::{self, STEP, TOLERANCE};
//! use mpm_constitutive::{MaterialState, VonMises, VonMisesHistory};
//! use nalgebra::Matrix3;
//! let law = VonMises::new(1e4, 0.3, 20.0, 100.0)?;
//! let delta_f = Matrix3::new(1.2, 0.1, 0.0, 0.0, 0.9, 0.05, 0.0, 0.0, 1.0);
//! let state = MaterialState::<VonMisesHistory>::default();
//! let f_n = Matrix3::identity();
//! let err = verification::check_previously_converged(&law, &delta_f, &f_n, &state, STEP)?;
//! assert!(err.is_some_and(|e| e <= TOLERANCE));
//! let spatial = verification::check_spatial(&law, &delta_f, &f_n, &state, STEP)?;
//! assert!(spatial.is_some_and(|e| e.max() <= TOLERANCE));
//! # Ok::<(), verification::VerificationError>(())
//! ```
//!
//! The crate `mpm-constitutive-proptest` holds the random inputs of the
//! property tests and the macro `law_tangent_properties!`, which turns
//! these checks into property tests for any law (its documentation shows a
//! downstream crate's use).

use std::convert::Infallible;

use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

use crate::driver::{
    ConsistentTangent, MaterialState, PreviouslyConvergedTangent, SpatialTangent,
    cauchy_stress_derivative, update,
};
use crate::error::ConstitutiveError;
use crate::law::LogStrainLaw;
use crate::spectral::SymSpectral;
use crate::tensor::{Tensor4, idx, relative_difference};

/// Required agreement of an analytic tangent and its finite difference, in
/// [`relative_error`]: the tolerance of the crate's tests and of
/// `law_tangent_properties!`.
pub const TOLERANCE: f64 = 1e-6;

/// Finite-difference step relative to the scale of the argument (module
/// docs, "Step size").
pub const STEP: f64 = 1e-4;

/// Why a check could not be evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum VerificationError {
    /// The relative step must be positive and finite.
    #[error("finite-difference step {value} must be positive and finite")]
    InvalidStep {
        /// The value given.
        value: f64,
    },
    /// The update or the analytic tangent failed at the point of
    /// linearisation: the input is not an admissible state.
    #[error("at the point of linearisation: {0}")]
    Linearisation(#[from] ConstitutiveError),
    /// The update failed at a point of the stencil (the step is too large
    /// for a nearly singular $\Delta F$).
    #[error("at the stencil point with perturbation {perturbation:?}: {source}")]
    Stencil {
        /// The perturbation of that stencil point: $d\Delta F$ for
        /// [`check_previously_converged`], $G$ in $(1 + G)\Delta F$ for
        /// [`check_spatial`], $d\varepsilon$ for [`check_algorithmic_tangent`].
        perturbation: Matrix3<f64>,
        /// What failed.
        source: ConstitutiveError,
    },
}

/// Shorthand for results of the checks.
pub type Result<T> = std::result::Result<T, VerificationError>;

/// Fourth-order central difference of `f` at 0,
/// $$ f'(0) \approx \frac{-f(2h) + 8 f(h) - 8 f(-h) + f(-2h)}{12 h}, $$
/// truncation $O(h^4)$: with $h \sim 10^{-4}$ relative to the scale of the
/// argument, truncation ($\sim 10^{-16}$) and round-off ($\sim
/// 10^{-12}$) stay far below [`TOLERANCE`]. `None` as soon as `f` is
/// `None` at a stencil point.
pub fn central_difference<F>(f: F, h: f64) -> Option<Matrix3<f64>>
where
    F: Fn(f64) -> Option<Matrix3<f64>>,
{
    let Ok(d) = try_central_difference(|t| Ok::<_, Infallible>(f(t)), h);
    d
}

/// [`central_difference`] of a fallible `f`: the first error is returned,
/// `Ok(None)` as soon as `f` is `Ok(None)` at a stencil point.
pub fn try_central_difference<F, E>(f: F, h: f64) -> std::result::Result<Option<Matrix3<f64>>, E>
where
    F: Fn(f64) -> std::result::Result<Option<Matrix3<f64>>, E>,
{
    let mut values = [Matrix3::zeros(); 4];
    for (value, t) in values.iter_mut().zip([2.0 * h, h, -h, -2.0 * h]) {
        match f(t)? {
            Some(v) => *value = v,
            None => return Ok(None),
        }
    }
    let [p2, p1, m1, m2] = values;
    Ok(Some((-p2 + 8.0 * p1 - 8.0 * m1 + m2) / (12.0 * h)))
}

/// The $9\times9$ Jacobian whose column `3k + l` ([`idx`]) is the
/// [`central_difference`] of `f` along the perturbation `direction(k, l)`:
/// column $kl$ holds $\frac{d}{dt} f(t\,D_{kl})_{ij}$ at $t = 0$.
pub fn jacobian<F, D>(f: F, direction: D, h: f64) -> Option<Tensor4>
where
    F: Fn(&Matrix3<f64>) -> Option<Matrix3<f64>>,
    D: Fn(usize, usize) -> Matrix3<f64>,
{
    let Ok(j) = try_jacobian(|d| Ok::<_, Infallible>(f(d)), direction, h);
    j
}

/// [`jacobian`] of a fallible `f`.
pub fn try_jacobian<F, D, E>(f: F, direction: D, h: f64) -> std::result::Result<Option<Tensor4>, E>
where
    F: Fn(&Matrix3<f64>) -> std::result::Result<Option<Matrix3<f64>>, E>,
    D: Fn(usize, usize) -> Matrix3<f64>,
{
    let mut out = Tensor4::zeros();
    for k in 0..3 {
        for l in 0..3 {
            let dir = direction(k, l);
            let Some(col) = try_central_difference(|t| f(&(t * dir)), h)? else {
                return Ok(None);
            };
            for i in 0..3 {
                for j in 0..3 {
                    out[(idx(i, j), idx(k, l))] = col[(i, j)];
                }
            }
        }
    }
    Ok(Some(out))
}

/// Unit tensor $E_{kl}$ (the directions of a derivative with respect to a
/// general tensor, $\Delta F$ or $G$).
pub fn unit(k: usize, l: usize) -> Matrix3<f64> {
    let mut e = Matrix3::zeros();
    e[(k, l)] = 1.0;
    e
}

/// Symmetric unit direction $(E_{kl} + E_{lk})/2$ (the directions of a
/// derivative with respect to a symmetric tensor, stored with both minor
/// symmetries).
pub fn sym_unit(k: usize, l: usize) -> Matrix3<f64> {
    0.5 * (unit(k, l) + unit(l, k))
}

/// Relative Frobenius error $\|A - B\|/\|B\|$ of `a` against the reference
/// `b` (infinite or NaN if `b` vanishes).
pub fn relative_error(a: &Tensor4, b: &Tensor4) -> f64 {
    relative_difference(a, b, 0.0)
}

/// Smallest singular value of `f`: the scale of a perturbation of a
/// deformation gradient (its smallest principal stretch).
pub fn min_singular_value(f: &Matrix3<f64>) -> f64 {
    f.singular_values().min()
}

/// The floor of [`plastic_scale`]: a state returned to an apex has an
/// isotropic trial strain (no deviatoric scale) and no flow direction to
/// resolve, and the step must not vanish there.
pub const MIN_PLASTIC_SCALE: f64 = 1e-3;

/// Extra factor on the step for yielding states,
/// $\min(10\,\|\operatorname{dev}\varepsilon^{e,tr}\|, 1)$ but at least
/// [`MIN_PLASTIC_SCALE`], 1 for elastic ones. The flow direction $N = \operatorname{dev}\varepsilon /
/// \|\operatorname{dev}\varepsilon\|$ turns on the scale of
/// $\|\operatorname{dev}\varepsilon^{e,tr}\|$, so the perturbation of the
/// strain must stay well below it: with this factor it is at most
/// $10\cdot$`step` of it. `trial_strain` holds the principal trial strains.
pub fn plastic_scale(trial_strain: &Vector3<f64>, yielded: bool) -> f64 {
    if !yielded {
        return 1.0;
    }
    let dev = trial_strain.map(|e| e - trial_strain.sum() / 3.0).norm();
    (10.0 * dev).clamp(MIN_PLASTIC_SCALE, 1.0)
}

/// The Hencky strain $\varepsilon = \tfrac12\ln(FF^T)$ of a deformation
/// gradient: a symmetric strain with the eigenvalue structure (repeated,
/// nearly repeated) of `f`, the input of [`check_algorithmic_tangent`].
pub fn hencky_strain(f: &Matrix3<f64>) -> Result<Matrix3<f64>> {
    Ok(SymSpectral::new(&(f * f.transpose()))?.log()? * 0.5)
}

fn require_step(step: f64) -> Result<()> {
    if step.is_finite() && step > 0.0 {
        Ok(())
    } else {
        Err(VerificationError::InvalidStep { value: step })
    }
}

/// $\tilde A_{ijkl}$ (eqs. A.3–A.6) against $\partial\tilde P_{ij} /
/// \partial\Delta F_{kl}$ with $\tilde P = \tau\Delta F^{-T}/J_n$ (eq. 18),
/// the derivative taken by [`jacobian`] along $E_{kl}$ with the state
/// $(F_n, b^e_n, \text{history})$ held fixed.
///
/// Step: $h = $ `step` $\cdot\,\sigma_{min}(\Delta F)\cdot$
/// [`plastic_scale`], so that every principal stretch of $\Delta F$ moves
/// by at most `step` relative to itself (the logarithm is evaluated at
/// the squares of the stretches, and a near-singular $\Delta F$ stays
/// invertible across the stencil).
///
/// Returns the [`relative_error`] of $\tilde A$ against the finite
/// difference, or `None` if the stencil crosses the yield surface.
pub fn check_previously_converged<L: LogStrainLaw>(
    law: &L,
    delta_f: &Matrix3<f64>,
    f_n: &Matrix3<f64>,
    state: &MaterialState<L::History>,
    step: f64,
) -> Result<Option<f64>> {
    require_step(step)?;
    let r = update(law, delta_f, f_n, state)?;
    let a = PreviouslyConvergedTangent::tangent(law, &r)?;
    let h =
        step * min_singular_value(delta_f) * plastic_scale(&r.trial_strain().values, r.yielded());
    let fd = try_jacobian(
        |d| -> Result<_> {
            let p = update(law, &(delta_f + d), f_n, state).map_err(|source| {
                VerificationError::Stencil {
                    perturbation: *d,
                    source,
                }
            })?;
            Ok((law.regime(&p.law_state) == law.regime(&r.law_state)).then(|| p.p_tilde()))
        },
        unit,
        h,
    )?;
    Ok(fd.map(|fd| relative_error(&a, &fd)))
}

/// The two errors of [`check_spatial`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpatialErrors {
    /// [`relative_error`] of $a$ against the finite-difference push-forward
    /// $J^{-1}F_{jm}(\partial P_{im}/\partial F_{kn})F_{ln}$.
    pub push_forward: f64,
    /// Error of $a - \sigma_{ij}\delta_{kl} + \sigma_{il}\delta_{jk}$
    /// ([`cauchy_stress_derivative`]) against the finite difference of
    /// $(\partial\sigma_{ij}/\partial F_{km})F_{lm}$, relative to
    /// $\max(\|(\partial\sigma/\partial F)F\|, \|a\|)$.
    pub cauchy_derivative: f64,
}

impl SpatialErrors {
    /// The larger of the two errors.
    pub fn max(&self) -> f64 {
        self.push_forward.max(self.cauchy_derivative)
    }
}

/// The spatial tangent $a_{ijkl}$ of the updated Lagrangian formulation
/// (eq. A.1) against two finite differences along $dF = GF$, i.e.
/// $\Delta F \to (1 + tE_{kl})\Delta F$:
/// 1. the push-forward $J^{-1}F_{jm}(\partial P_{im}/\partial F_{kn})F_{ln}$
///    of the first elasticity tensor, $P = \tau F^{-T}$, which $a$ equals;
/// 2. the derivative of the Cauchy stress, $(\partial\sigma_{ij}/\partial
///    F_{km})F_{lm} = a_{ijkl} - \sigma_{ij}\delta_{kl} +
///    \sigma_{il}\delta_{jk}$, the paper's shorthand for $a$ plus the
///    geometric terms. The geometric terms are of the size of $\sigma$;
///    where they nearly cancel $a$, the accuracy of their difference is
///    limited by the size of the terms, so this error is measured against
///    $\max(\|(\partial\sigma/\partial F)F\|, \|a\|)$.
///
/// Step: $h = $ `step` $\cdot\,\sigma_{min}(\Delta F)/\|\Delta F\|\cdot$
/// [`plastic_scale`]: the perturbation $d\Delta F = hE_{kl}\Delta F$ has
/// size up to $h\|\Delta F\|$, so this gives the same relative
/// perturbation of the stretches as [`check_previously_converged`].
///
/// Returns both errors, or `None` if the stencil crosses the yield
/// surface.
pub fn check_spatial<L: LogStrainLaw>(
    law: &L,
    delta_f: &Matrix3<f64>,
    f_n: &Matrix3<f64>,
    state: &MaterialState<L::History>,
    step: f64,
) -> Result<Option<SpatialErrors>> {
    require_step(step)?;
    let r = update(law, delta_f, f_n, state)?;
    let a = SpatialTangent::tangent(law, &r)?;
    let h = step * min_singular_value(delta_f) / delta_f.norm()
        * plastic_scale(&r.trial_strain().values, r.yielded());
    let perturbed = |g: &Matrix3<f64>| -> Result<_> {
        let stencil = |source| VerificationError::Stencil {
            perturbation: *g,
            source,
        };
        let p = update(law, &((Matrix3::identity() + g) * delta_f), f_n, state).map_err(stencil)?;
        Ok((law.regime(&p.law_state) == law.regime(&r.law_state)).then_some(p))
    };
    let fd_push = try_jacobian(
        |g| -> Result<_> {
            let Some(p) = perturbed(g)? else {
                return Ok(None);
            };
            let f_inv = p.f.try_inverse().ok_or(VerificationError::Stencil {
                perturbation: *g,
                source: ConstitutiveError::NonPositiveJacobian {
                    which: "F",
                    det: p.j,
                },
            })?;
            Ok(Some(p.tau * f_inv.transpose() * r.f.transpose() / r.j))
        },
        unit,
        h,
    )?;
    let Some(fd_push) = fd_push else {
        return Ok(None);
    };
    let Some(fd_cauchy) = try_jacobian(
        |g| Ok::<_, VerificationError>(perturbed(g)?.map(|p| p.sigma)),
        unit,
        h,
    )?
    else {
        return Ok(None);
    };
    let literal = cauchy_stress_derivative(&a, &r.sigma);
    Ok(Some(SpatialErrors {
        push_forward: relative_error(&a, &fd_push),
        cauchy_derivative: relative_difference(&literal, &fd_cauchy, a.norm()),
    }))
}

/// The law's algorithmic tangent $D^{alg} = \partial\tau /
/// \partial\varepsilon^{e,tr}$ ([`LogStrainLaw::algorithmic_tangent`])
/// against the finite difference of the return map's Kirchhoff stress
/// ([`LogStrainLaw::kirchhoff_stress`]) with respect to the symmetric
/// trial strain `eps`, along [`sym_unit`] (so both carry the minor
/// symmetries), from the converged `history`. This is the ingredient of
/// both consistent tangents (eqs. A.1, A.3) that a law supplies; the
/// kinematic factors $L$ (eq. A.2), $B$, $\tilde B$ (eq. A.5) are the
/// crate's.
///
/// Step: $h = $ `step` $\cdot$ [`plastic_scale`]: the strain is perturbed
/// additively in logarithmic space, where its natural scale is 1.
///
/// Returns the [`relative_error`] of $D^{alg}$, or `None` if the stencil
/// crosses the yield surface.
pub fn check_algorithmic_tangent<L: LogStrainLaw>(
    law: &L,
    eps: &Matrix3<f64>,
    history: &L::History,
    step: f64,
) -> Result<Option<f64>> {
    require_step(step)?;
    let trial = SymSpectral::new(eps)?;
    let state = law.return_map(&trial, history);
    let d = law.algorithmic_tangent(&trial, history, &state);
    let h = step * plastic_scale(&trial.values, state.yielded);
    let fd = try_jacobian(
        |de| -> Result<_> {
            let (tau, s) = law
                .kirchhoff_stress(&(eps + de), history)
                .map_err(|source| VerificationError::Stencil {
                    perturbation: *de,
                    source,
                })?;
            Ok((law.regime(&s) == law.regime(&state)).then_some(tau))
        },
        sym_unit,
        h,
    )?;
    Ok(fd.map(|fd| relative_error(&d, &fd)))
}

/// The loading tangent ([`LogStrainLaw::loading_tangent`]) where a load
/// step starts: at the converged state of the plastic step from the trial
/// strain `eps` (its elastic strain re-read as a trial, which the return
/// map takes as elastic, on the surface to rounding), against the
/// one-sided difference $(\tau(\varepsilon + h d) - \tau(\varepsilon))/h$
/// along the direction $d$ of `eps` (continued loading), $h$ = `step`.
///
/// Returns the relative error of $D : d$, or `None` when the step from
/// `eps` is elastic or its converged state reads as plastic again.
pub fn check_loading_tangent<L: LogStrainLaw>(
    law: &L,
    eps: &Matrix3<f64>,
    history: &L::History,
    step: f64,
) -> Result<Option<f64>> {
    require_step(step)?;
    let trial = SymSpectral::new(eps)?;
    let first = law.return_map(&trial, history);
    if !first.yielded {
        return Ok(None);
    }
    let on = trial.compose(&first.elastic_strain);
    let on_trial = SymSpectral::new(&on)?;
    let again = law.return_map(&on_trial, &first.history);
    if again.yielded {
        return Ok(None);
    }
    let d = law.loading_tangent(&on_trial, &first.history, &again);
    let dir = eps / eps.norm();
    let (ahead, _) = law.kirchhoff_stress(&(on + step * dir), &first.history)?;
    let (here, _) = law.kirchhoff_stress(&on, &first.history)?;
    let fd = (ahead - here) / step;
    Ok(Some(
        (crate::tensor::contract(&d, &dir) - fd).norm() / fd.norm(),
    ))
}
