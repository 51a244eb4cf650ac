//! A GIMP domain rule chosen at run time: every rule of Coombs et al.
//! 2020 §6.4 (eqs. 32–39) behind one type, with the integration-volume
//! convention as a value too.
//!
//! The domain update runs once per point after a converged load step (or
//! explicit time step), beside the stress update, so a branch there costs
//! nothing measurable; a program that reads the rule from a file compiles
//! one solver for all of them instead of one per rule and convention.
//! Each arm calls the typed rule, so the numbers are those of the typed
//! solver bit for bit (`tests` below, and the scene tests that compare
//! both paths).

use nalgebra::SVector;

use super::{
    CornerMidpoint, DetF, DiagF, DisplacementField, DomainError, DomainUpdater, DomainVolume,
    GimpContext, IncrementalVolumeCorrectedDiagF, Midpoint, NoUpdate, StretchU,
    VolumeCorrectedDiagF,
};

/// The GIMP domain update rules (Coombs et al. 2020 §6.4, Table 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GimpRule {
    /// No update ([`NoUpdate`]).
    #[default]
    None,
    /// Eq. (32) ([`DetF`]).
    DetF,
    /// Eq. (33) ([`DiagF`]).
    DiagF,
    /// Eq. (34) ([`StretchU`]).
    Stretch,
    /// Eqs. (35)–(37), corners tracked ([`CornerMidpoint`]).
    CornerMidpoint,
    /// Eqs. (36)–(37), mid-points mapped ([`Midpoint`]).
    Midpoint,
    /// Eq. (38) ([`VolumeCorrectedDiagF`]).
    VolumeCorrectedDiagF,
    /// Eq. (39) ([`IncrementalVolumeCorrectedDiagF`]).
    IncrementalVolumeCorrectedDiagF,
}

impl GimpRule {
    /// The typed rule's [`DomainUpdater::NAME`].
    pub fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::DetF => "det_f",
            Self::DiagF => "diag_f",
            Self::Stretch => "stretch",
            Self::CornerMidpoint => "corner_midpoint",
            Self::Midpoint => "midpoint",
            Self::VolumeCorrectedDiagF => "volume_corrected_diag_f",
            Self::IncrementalVolumeCorrectedDiagF => "incremental_volume_corrected_diag_f",
        }
    }
}

/// A [`GimpRule`] and the points' integration volume chosen at run time:
/// `det F V⁰` (eqs. 5, 22) or, with `domain_volume`, the domain's own
/// volume $\prod_i 2l_i$ ([`DomainVolume`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AnyGimpRule {
    /// The half-length update.
    pub rule: GimpRule,
    /// Integrate with the domain's volume instead of $\det(F)\,V^0_p$.
    pub domain_volume: bool,
}

impl AnyGimpRule {
    /// `rule` with the `det F` volume.
    pub fn new(rule: GimpRule) -> Self {
        Self {
            rule,
            domain_volume: false,
        }
    }
}

impl<const D: usize> DomainUpdater<D, SVector<f64, D>> for AnyGimpRule {
    const NAME: &'static str = "gimp";

    fn update(
        &self,
        ctx: &GimpContext<'_, D>,
        field: impl DisplacementField<D>,
    ) -> Result<SVector<f64, D>, DomainError> {
        match self.rule {
            GimpRule::None => NoUpdate.update(ctx, field),
            GimpRule::DetF => DetF.update(ctx, field),
            GimpRule::DiagF => DiagF.update(ctx, field),
            GimpRule::Stretch => StretchU.update(ctx, field),
            GimpRule::CornerMidpoint => CornerMidpoint.update(ctx, field),
            GimpRule::Midpoint => Midpoint.update(ctx, field),
            GimpRule::VolumeCorrectedDiagF => VolumeCorrectedDiagF.update(ctx, field),
            GimpRule::IncrementalVolumeCorrectedDiagF => {
                IncrementalVolumeCorrectedDiagF.update(ctx, field)
            }
        }
    }

    #[inline]
    fn volume(&self, half_lengths: &SVector<f64, D>, f_volume: f64) -> f64 {
        if self.domain_volume {
            DomainVolume(NoUpdate).volume(half_lengths, f_volume)
        } else {
            f_volume
        }
    }

    fn name(&self) -> &'static str {
        self.rule.name()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::DomainContext;
    use nalgebra::{Matrix3, Vector2, Vector3};

    const ALL: [GimpRule; 8] = [
        GimpRule::None,
        GimpRule::DetF,
        GimpRule::DiagF,
        GimpRule::Stretch,
        GimpRule::CornerMidpoint,
        GimpRule::Midpoint,
        GimpRule::VolumeCorrectedDiagF,
        GimpRule::IncrementalVolumeCorrectedDiagF,
    ];

    /// The typed rule's update and volume.
    fn typed<U: DomainUpdater<2, Vector2<f64>>>(
        rule: U,
        ctx: &GimpContext<'_, 2>,
        field: impl DisplacementField<2>,
    ) -> (Result<Vector2<f64>, DomainError>, &'static str) {
        (rule.update(ctx, field), U::NAME)
    }

    #[test]
    fn every_rule_is_its_typed_rule_bit_for_bit() {
        let l0 = Vector2::new(0.25, 0.5);
        let previous = Vector2::new(0.3, 0.45);
        // A sheared, stretched, rotated deformation, so the rules differ.
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let rot = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        let f = rot * Matrix3::new(1.4, 0.3, 0.0, 0.1, 0.8, 0.0, 0.0, 0.0, 1.0);
        let delta_f = Matrix3::new(1.1, 0.05, 0.0, -0.02, 0.95, 0.0, 0.0, 0.0, 1.0);
        let (x0, x1) = (Vector2::new(1.0, 2.0), Vector2::new(1.1, 1.9));
        let ctx = DomainContext {
            initial: &l0,
            previous: &previous,
            f: &f,
            delta_f: &delta_f,
            position_previous: &x0,
            position: &x1,
        };
        // A non-uniform displacement field for the mid-point rules.
        let field = |x: &Vector2<f64>| Ok(Vector2::new(0.1 * x[0] * x[1], -0.05 * x[0]));
        let mut seen = Vec::new();
        for rule in ALL {
            let (want, name) = match rule {
                GimpRule::None => typed(NoUpdate, &ctx, field),
                GimpRule::DetF => typed(DetF, &ctx, field),
                GimpRule::DiagF => typed(DiagF, &ctx, field),
                GimpRule::Stretch => typed(StretchU, &ctx, field),
                GimpRule::CornerMidpoint => typed(CornerMidpoint, &ctx, field),
                GimpRule::Midpoint => typed(Midpoint, &ctx, field),
                GimpRule::VolumeCorrectedDiagF => typed(VolumeCorrectedDiagF, &ctx, field),
                GimpRule::IncrementalVolumeCorrectedDiagF => {
                    typed(IncrementalVolumeCorrectedDiagF, &ctx, field)
                }
            };
            let want = want.expect("typed rule");
            for domain_volume in [false, true] {
                let any = AnyGimpRule {
                    rule,
                    domain_volume,
                };
                let got = DomainUpdater::<2, _>::update(&any, &ctx, field).expect("run-time rule");
                assert_eq!(got, want, "{rule:?}");
                assert_eq!(DomainUpdater::<2, _>::name(&any), name);
                let volume = DomainUpdater::<2, _>::volume(&any, &got, 7.0);
                let typed_volume = if domain_volume {
                    DomainUpdater::<2, _>::volume(&DomainVolume(NoUpdate), &got, 7.0)
                } else {
                    7.0
                };
                assert_eq!(volume.to_bits(), typed_volume.to_bits(), "{rule:?}");
            }
            seen.push(want);
        }
        // The deformation tells the rules apart: at least six distinct
        // domains among the eight rules (none and det F coincide with
        // nothing else here).
        seen.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        seen.dedup();
        assert!(seen.len() >= 6, "{seen:?}");
    }

    #[test]
    fn the_domain_volume_is_the_product_of_the_full_lengths_in_3d() {
        let any = AnyGimpRule {
            rule: GimpRule::None,
            domain_volume: true,
        };
        let l = Vector3::new(0.1, 0.2, 0.3);
        let v = DomainUpdater::<3, _>::volume(&any, &l, 9.0);
        assert!((v - 0.048).abs() < 1e-15, "{v}");
        assert_eq!(
            DomainUpdater::<3, _>::volume(&AnyGimpRule::default(), &l, 9.0),
            9.0
        );
    }
}
