//! Scaling by the diagonal of the deformation gradient, Coombs et al. 2020
//! eq. (33).

use nalgebra::SVector;

use super::{DeformationRule, DomainError, GimpContext, checks};

/// GIMP half-lengths scaled by the leading diagonal of $F$,
/// $l^p_i = l^{p0}_i\,|F_{ii}|$ (no sum on $i$; Coombs et al. 2020
/// eq. 33, "a commonly adopted approach").
///
/// **Sign.** Eq. (33) reads $l^{p0}_i F_{ii}$; a rotation beyond 90° makes
/// $F_{ii}$ negative. A half-length is a magnitude, and $l^{p0}_i|F_{ii}|$
/// is what Fig. 4(a) draws: the half-extent along $\mathbf e_i$ of the
/// deformed mid-line $\mathbf x_p \pm l^{p0}_i F\mathbf e_i$ of the domain.
/// So the absolute value is taken. Under pure rotation by $\theta$ about a
/// coordinate axis the in-plane lengths are $l^{p0}_i|\cos\theta|$: the
/// domain still vanishes as $\theta \to 90°$ (Table 2, footnote d:
/// "vanishing material point domains with increasing rotation") and
/// comes back to its initial size at 180°. A zero half-length is admissible
/// for GIMP (it is standard MPM along that axis), so $F_{ii} = 0$ is not an
/// error here.
///
/// Table 2: suitable for simple stretch, hydrostatic compression/extension
/// and simple shear; unsuitable for pure rotation (footnote d).
///
/// # Errors
/// A [`DomainError`] for a non-finite $F$, $\det F \le 0$ or initial
/// half-lengths that are negative or not finite.
#[derive(Debug, Clone, Copy, Default)]
pub struct DiagF;

impl<const D: usize> DeformationRule<D> for DiagF {
    const NAME: &'static str = "diag_f";

    fn half_lengths(&self, ctx: &GimpContext<'_, D>) -> Result<SVector<f64, D>, DomainError> {
        checks::half_lengths(ctx.initial, "initial")?;
        checks::jacobian(ctx.f, "F")?;
        Ok(SVector::from_fn(|i, _| {
            ctx.initial[i] * ctx.f[(i, i)].abs()
        }))
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
    fn takes_the_magnitude_of_the_diagonal() {
        let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), 2.0).into_inner();
        let f = rot * Matrix3::from_diagonal(&Vector3::new(1.5, 0.8, 1.0));
        let p = Fixture::<2, _>::first_step(Vector2::new(0.2, 0.1), f, Vector2::zeros());
        let l = DiagF
            .update(&p.ctx(), |_| Ok(Vector2::zeros()))
            .expect("update");
        assert!(f[(0, 0)] < 0.0 && f[(1, 1)] < 0.0);
        let expected = Vector2::new(0.2 * f[(0, 0)].abs(), 0.1 * f[(1, 1)].abs());
        assert!((l - expected).norm() <= 1e-16);
    }

    #[test]
    fn a_quarter_turn_gives_a_zero_length_and_an_inversion_an_error() {
        let quarter = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let p = Fixture::<3, _>::first_step(Vector3::new(0.1, 0.2, 0.3), quarter, Vector3::zeros());
        let l = DiagF
            .update(&p.ctx(), |_| Ok(Vector3::zeros()))
            .expect("update");
        assert_eq!(l, Vector3::new(0.0, 0.0, 0.3));
        let inverted = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
        let p = Fixture::<3, _>::first_step(Vector3::repeat(0.1), inverted, Vector3::zeros());
        let e = DiagF
            .update(&p.ctx(), |_| Ok(Vector3::zeros()))
            .expect_err("det < 0");
        assert!(e.to_string().contains("not positive"), "{e}");
    }
}
