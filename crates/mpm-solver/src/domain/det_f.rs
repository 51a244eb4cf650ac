//! Uniform scaling by the volume change, Coombs et al. 2020 eq. (32).

use nalgebra::SVector;

use super::{DeformationRule, DomainError, GimpContext, checks};

/// GIMP half-lengths scaled uniformly by the volume ratio,
/// $l^p_i = l^{p0}_i\,(\det F)^{1/n_D}$ (Coombs et al. 2020 eq. 32), with
/// $n_D = D$ the physical dimension. In plane strain ($D = 2$, $F_{33} = 1$)
/// the determinant of the 3×3 embedding equals that of the in-plane 2×2
/// block, so the domain area follows $\det F$.
///
/// Table 2: suitable for hydrostatic compression/extension, simple shear
/// and pure rotation; unsuitable for simple stretch, footnote b
/// ("artificial orthogonal contraction/expansion of domains"): the volume
/// change of a stretch along one axis is shared by all axes, so the lateral
/// lengths change although the lateral extent does not.
///
/// # Errors
/// A [`DomainError`] for a non-finite $F$, $\det F \le 0$ or initial
/// half-lengths that are negative or not finite.
#[derive(Debug, Clone, Copy, Default)]
pub struct DetF;

impl<const D: usize> DeformationRule<D> for DetF {
    const NAME: &'static str = "det_f";

    fn half_lengths(&self, ctx: &GimpContext<'_, D>) -> Result<SVector<f64, D>, DomainError> {
        checks::half_lengths(ctx.initial, "initial")?;
        let j = checks::jacobian(ctx.f, "F")?;
        Ok(ctx.initial * checks::dimension_root::<D>(j))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::checks::Fixture;
    #[allow(unused_imports)]
    use crate::domain::{DomainContext, DomainUpdater};
    use nalgebra::{Matrix3, Vector2, Vector3};

    #[test]
    fn scales_by_the_root_of_the_jacobian() {
        let f = Matrix3::new(1.2, 0.3, 0.0, 0.1, 0.9, 0.0, 0.0, 0.0, 1.0);
        let p = Fixture::<2, _>::first_step(Vector2::new(0.2, 0.1), f, Vector2::zeros());
        let l = DetF
            .update(&p.ctx(), |_| Ok(Vector2::zeros()))
            .expect("update");
        let j: f64 = 1.2 * 0.9 - 0.3 * 0.1;
        assert!((l - Vector2::new(0.2, 0.1) * j.sqrt()).norm() <= 1e-15);
    }

    #[test]
    fn rejects_a_non_positive_jacobian_and_bad_lengths() {
        let f = Matrix3::from_diagonal(&Vector3::new(1.0, -0.5, 1.0));
        let p = Fixture::<3, _>::first_step(Vector3::repeat(0.1), f, Vector3::zeros());
        let e = DetF
            .update(&p.ctx(), |_| Ok(Vector3::zeros()))
            .expect_err("det < 0");
        assert!(e.to_string().contains("det F"), "{e}");
        let p = Fixture::<2, _>::first_step(
            Vector2::new(f64::NAN, 0.1),
            Matrix3::identity(),
            Vector2::zeros(),
        );
        assert!(DetF.update(&p.ctx(), |_| Ok(Vector2::zeros())).is_err());
    }
}
