//! The incremental volume-corrected diagonal rule, Coombs et al. 2020
//! eq. (39).

use nalgebra::SVector;

use super::volume_corrected_diag_f::volume_corrected_diagonal;
use super::{DeformationRule, DomainError, GimpContext, checks};

/// Eq. (38) applied to the load step's increment (Coombs et al. 2020
/// eq. 39, no sum on $i$):
///
/// $$l^p_i = l^{pn}_i\,|\Delta F_{ii}|\left(\frac{\det\Delta F}
/// {\prod_{j=1}^{n_D}|\Delta F_{jj}|}\right)^{1/n_D},$$
///
/// with $l^{pn}$ the half-lengths at the start of the step. The domain
/// volume follows $\prod_i l^p_i = \det\Delta F\prod_i l^{pn}_i$, hence
/// $\det F\prod_i l^{p0}_i$ over the steps. Magnitudes and the zero-diagonal
/// test as in [`super::VolumeCorrectedDiagF`].
///
/// Not in Table 2; the paper's text: it "partially overcomes" the 90°
/// issue of eq. (38), "provided that excessive rotations are not
/// experienced within a single load step": in 2D a rotation applied in
/// steps of less than 90° leaves the domain unchanged, a step of exactly
/// 90° is an error. In 3D each rotation step $\Delta\theta$ about a
/// coordinate axis scales the in-plane lengths by
/// $|\cos\Delta\theta|^{1/3}$ and the length along the axis by
/// $|\cos\Delta\theta|^{-2/3}$ (the uniform correction spreads the in-plane
/// shrinkage over all axes, as for [`super::CornerMidpoint`]): the volume
/// stays exact, the shape drifts with the number of steps.
///
/// # Errors
/// A [`DomainError`] for a non-finite $\Delta F$, $\det\Delta F \le 0$, a
/// zero diagonal component of $\Delta F$, or half-lengths at the start of
/// the step that are negative or not finite.
#[derive(Debug, Clone, Copy, Default)]
pub struct IncrementalVolumeCorrectedDiagF;

impl<const D: usize> DeformationRule<D> for IncrementalVolumeCorrectedDiagF {
    const NAME: &'static str = "incremental_volume_corrected_diag_f";

    fn half_lengths(&self, ctx: &GimpContext<'_, D>) -> Result<SVector<f64, D>, DomainError> {
        checks::half_lengths(ctx.previous, "previous")?;
        volume_corrected_diagonal(ctx.previous, ctx.delta_f, "ΔF")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::checks::Fixture;
    #[allow(unused_imports)]
    use crate::domain::{DomainContext, DomainUpdater};
    use nalgebra::{Matrix3, Rotation3, Vector2, Vector3};

    #[test]
    fn uses_the_previous_lengths_and_the_increment() {
        let delta_f = Matrix3::new(1.1, 0.2, 0.0, 0.0, 0.95, 0.0, 0.0, 0.0, 1.0);
        let mut p = Fixture::<2, _>::first_step(Vector2::new(0.2, 0.2), delta_f, Vector2::zeros());
        p.previous = Vector2::new(0.3, 0.1);
        p.f = Matrix3::identity() * 7.0;
        let l = IncrementalVolumeCorrectedDiagF
            .update(&p.ctx(), |_| Ok(Vector2::zeros()))
            .expect("update");
        // ΔF_00 ΔF_11 = det ΔF: no correction.
        assert!((l - Vector2::new(0.33, 0.095)).norm() <= 1e-15);
    }

    #[test]
    fn a_quarter_turn_in_one_step_is_an_error() {
        let quarter =
            Rotation3::from_axis_angle(&Vector3::y_axis(), 90f64.to_radians()).into_inner();
        let p = Fixture::<3, _>::first_step(Vector3::repeat(0.2), quarter, Vector3::zeros());
        let e = IncrementalVolumeCorrectedDiagF
            .update(&p.ctx(), |_| Ok(Vector3::zeros()))
            .expect_err("ΔF_00 = 0");
        assert!(e.to_string().contains("ΔF[(0, 0)]"), "{e}");
        let inverted = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0));
        let p = Fixture::<3, _>::first_step(Vector3::repeat(0.2), inverted, Vector3::zeros());
        let e = IncrementalVolumeCorrectedDiagF
            .update(&p.ctx(), |_| Ok(Vector3::zeros()))
            .expect_err("det < 0");
        assert!(e.to_string().contains("det ΔF"), "{e}");
    }
}
