//! The stretch-tensor rule, Coombs et al. 2020 eq. (34).

use nalgebra::SVector;

use super::{DeformationRule, DomainError, GimpContext, right_stretch};

/// GIMP half-lengths scaled by the diagonal of the right stretch tensor,
/// $l^p_i = l^{p0}_i U_{ii}$ (Charlton et al. 2017; Coombs 2020 eq. 34),
/// with $F = RU$. Suitable for stretch, compression and rotation; under
/// simple shear the domain volume changes although the deformation is
/// isochoric (Table 2, footnote c).
#[derive(Debug, Clone, Copy, Default)]
pub struct StretchU;

impl<const D: usize> DeformationRule<D> for StretchU {
    const NAME: &'static str = "stretch";

    fn half_lengths(&self, ctx: &GimpContext<'_, D>) -> Result<SVector<f64, D>, DomainError> {
        let u = right_stretch(ctx.f).ok_or(DomainError::StretchTensor)?;
        Ok(SVector::<f64, D>::from_fn(|i, _| {
            ctx.initial[i] * u[(i, i)]
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::NoUpdate;
    #[allow(unused_imports)]
    use crate::domain::{DomainContext, DomainUpdater};
    use nalgebra::Matrix3;
    use nalgebra::{Rotation3, Vector2};

    #[test]
    fn stretch_rule_follows_stretch_and_ignores_rotation() {
        let l0 = Vector2::new(0.25, 0.5);
        let stretch = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.5, 0.8, 1.0));
        let rot = Rotation3::from_axis_angle(&nalgebra::Vector3::z_axis(), 1.2).into_inner();
        let f = rot * stretch;
        let ctx = DomainContext {
            initial: &l0,
            previous: &l0,
            f: &f,
            delta_f: &f,
            position_previous: &Vector2::zeros(),
            position: &Vector2::zeros(),
        };
        let l = DomainUpdater::<2, _>::update(&StretchU, &ctx, |_| Ok(Vector2::zeros()))
            .expect("update");
        assert!((l - Vector2::new(0.375, 0.4)).norm() < 1e-14);
        let same = DomainUpdater::<2, _>::update(&NoUpdate, &ctx, |_| Ok(Vector2::zeros()))
            .expect("update");
        assert_eq!(same, l0);
    }
}
