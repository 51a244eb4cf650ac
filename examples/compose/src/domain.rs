//! A GIMP domain-update rule written outside the framework.

use mpm_solver::{DeformationRule, DomainError, GimpContext};
use nalgebra::SVector;

/// GIMP half-lengths that follow the material fibres along the axes:
/// $l_i = l^0_i\,|F\mathbf e_i| = l^0_i\sqrt{C_{ii}}$, the stretch of the
/// fibre that was aligned with axis $i$. Under rotation the lengths stay
/// (like eq. 34 of Coombs et al. 2020); under stretch along an axis they
/// follow it (like eqs. 33, 34); under simple shear the fibre across the
/// shear lengthens, so the domain grows (like eq. 34, Table 2 footnote c).
#[derive(Debug, Clone, Copy, Default)]
pub struct FibreLength;

impl<const D: usize> DeformationRule<D> for FibreLength {
    const NAME: &'static str = "fibre_length";

    fn half_lengths(&self, ctx: &GimpContext<'_, D>) -> Result<SVector<f64, D>, DomainError> {
        let det = ctx.f.determinant();
        if !(det.is_finite() && det > 0.0) {
            return Err(DomainError::NonPositiveJacobian { name: "F", det });
        }
        Ok(SVector::from_fn(|i, _| {
            ctx.initial[i] * ctx.f.column(i).norm()
        }))
    }
}
