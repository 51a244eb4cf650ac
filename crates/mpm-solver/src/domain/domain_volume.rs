//! The integration volume of a GIMP point taken from its domain.

use nalgebra::SVector;

use super::{DisplacementField, DomainError, DomainUpdater, GimpContext};

/// A GIMP rule `U` whose points integrate with the volume of their domain,
/// $V_p = \prod_i 2 l^p_i$ (per unit thickness in plane strain), instead
/// of $\det(F)\,V^0_p$ (eqs. 5, 22).
///
/// This is the convention behind the GIMP results of Coombs et al. (2020):
/// with it, and only with it, this project reproduces Table 7's collapse
/// for eq. (33) (14.411/5.548 against 14.415/5.546) and eq. (34)
/// (13.423/6.443 against 13.425/6.441), and Fig. 7's column without domain
/// update stalling from the third refinement. For the volume-consistent
/// rules ($\prod_i l_i = \det F\prod_i l^0_i$: eqs. 32, 37, 38, 39) the two
/// conventions coincide; for the others the domain volume departs from
/// the deformed volume (no update: constant; eq. 33: shrinks under
/// rotation, footnote d; eq. 34: grows under shear, footnote c) and with
/// it the mass of material the point integrates.
#[derive(Debug, Clone, Copy, Default)]
pub struct DomainVolume<U>(pub U);

impl<const D: usize, U: DomainUpdater<D, SVector<f64, D>>> DomainUpdater<D, SVector<f64, D>>
    for DomainVolume<U>
{
    const NAME: &'static str = U::NAME;

    #[inline]
    fn update(
        &self,
        ctx: &GimpContext<'_, D>,
        displacement_at: impl DisplacementField<D>,
    ) -> Result<SVector<f64, D>, DomainError> {
        self.0.update(ctx, displacement_at)
    }

    #[inline]
    fn volume(&self, half_lengths: &SVector<f64, D>, _f_volume: f64) -> f64 {
        half_lengths.iter().map(|l| 2.0 * l).product()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::{DiagF, DomainContext, NoUpdate};
    use nalgebra::{Matrix3, Vector2, Vector3};

    #[test]
    fn the_volume_is_the_domain_s_and_the_update_the_inner_rule_s() {
        let l0 = Vector2::new(0.25, 0.5);
        let f = Matrix3::from_diagonal(&Vector3::new(1.5, 0.8, 1.0));
        let ctx = DomainContext {
            initial: &l0,
            previous: &l0,
            f: &f,
            delta_f: &f,
            position_previous: &Vector2::zeros(),
            position: &Vector2::zeros(),
        };
        let zero = |_: &Vector2<f64>| Ok(Vector2::zeros());
        let (inner, wrapped) = (
            DomainUpdater::<2, _>::update(&DiagF, &ctx, zero).expect("update"),
            DomainUpdater::<2, _>::update(&DomainVolume(DiagF), &ctx, zero).expect("update"),
        );
        assert_eq!(inner, wrapped);
        assert_eq!(
            DomainUpdater::<2, _>::volume(&DomainVolume(DiagF), &wrapped, 9.0),
            4.0 * 0.375 * 0.4
        );
        // Without update the volume stays the initial domain's.
        assert_eq!(
            DomainUpdater::<2, _>::volume(&DomainVolume(NoUpdate), &l0, 9.0),
            0.5
        );
        assert_eq!(<DomainVolume<DiagF> as DomainUpdater<2, _>>::NAME, "diag_f");
        let l3 = Vector3::new(0.1, 0.2, 0.3);
        assert!(
            (DomainUpdater::<3, _>::volume(&DomainVolume(NoUpdate), &l3, 9.0) - 0.048).abs()
                < 1e-15
        );
    }
}
