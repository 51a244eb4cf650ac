//! Finite-strain kinematics of one load step (Coombs et al. 2020 §3, §5,
//! Appendix A).

use nalgebra::Matrix3;

use crate::error::{ConstitutiveError, Result};
use crate::tensor::{Tensor4, delta};

/// Fails with a typed error unless every entry of `a` is finite.
pub fn require_finite(which: &'static str, a: &Matrix3<f64>) -> Result<()> {
    match a.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(ConstitutiveError::NonFinite { which, value }),
        None => Ok(()),
    }
}

/// $\det A$, failing unless it is positive (and `a` finite).
pub fn positive_determinant(which: &'static str, a: &Matrix3<f64>) -> Result<f64> {
    require_finite(which, a)?;
    let det = a.determinant();
    if det > 0.0 && det.is_finite() {
        Ok(det)
    } else {
        Err(ConstitutiveError::NonPositiveJacobian { which, det })
    }
}

/// Trial elastic left Cauchy–Green tensor
/// $b^{e,tr} = \Delta F\, b^e_n\, \Delta F^T$.
#[inline]
pub fn trial_elastic_left_cauchy_green(
    delta_f: &Matrix3<f64>,
    be_n: &Matrix3<f64>,
) -> Matrix3<f64> {
    delta_f * be_n * delta_f.transpose()
}

/// $B_{pqkl} = \delta_{pk} b_{ql} + \delta_{qk} b_{pl}$ (eq. A.2): with
/// $G = dF\,F^{-1}$, $B : G = G b + b G^T = db$.
pub fn spatial_b(b: &Matrix3<f64>) -> Tensor4 {
    Tensor4::from_fn(|r, c| {
        let (p, q, k, l) = (r / 3, r % 3, c / 3, c % 3);
        delta(p, k) * b[(q, l)] + delta(q, k) * b[(p, l)]
    })
}

/// $\tilde B_{ijkl} = \partial b^{e,tr}_{ij}/\partial\Delta F_{kl}
/// = \delta_{ik}(b^e_n)_{lb}\Delta F_{jb} + \Delta F_{ia}(b^e_n)_{al}\delta_{jk}$
/// (eq. A.5).
pub fn previously_converged_b(delta_f: &Matrix3<f64>, be_n: &Matrix3<f64>) -> Tensor4 {
    let fb = delta_f * be_n;
    Tensor4::from_fn(|r, c| {
        let (i, j, k, l) = (r / 3, r % 3, c / 3, c % 3);
        delta(i, k) * fb[(j, l)] + fb[(i, l)] * delta(j, k)
    })
}
