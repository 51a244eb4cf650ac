//! The `DomainUpdater` plug point: how a material point's domain (GIMP
//! half-lengths, CPDI2 corners) follows the deformation after a converged
//! load step (Coombs et al. 2020 §6.4, eqs. 32–39, Table 2).

use nalgebra::{Matrix3, SVector};

/// Why a domain update failed (the solver adds the material point).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct DomainError(pub String);

/// What a domain update may read about one material point after a
/// converged load step.
#[derive(Debug, Clone, Copy)]
pub struct DomainContext<'a, const D: usize, Dom> {
    /// The domain at the start of the analysis.
    pub initial: &'a Dom,
    /// The domain at the start of the load step.
    pub previous: &'a Dom,
    /// The converged deformation gradient $F$ (3D; plane strain embedded).
    pub f: &'a Matrix3<f64>,
    /// The converged increment $\Delta F$ over the step.
    pub delta_f: &'a Matrix3<f64>,
    /// The point's position at the start of the step.
    pub position_previous: &'a SVector<f64, D>,
    /// The point's position after the step (eq. 31).
    pub position: &'a SVector<f64, D>,
}

/// A rule that updates material point domains after a converged step.
pub trait DomainUpdater<const D: usize, Dom>: Send + Sync {
    /// Name used in outputs and scene files.
    const NAME: &'static str;

    /// The updated domain. `displacement_at(x)` interpolates the converged
    /// grid displacement increment at a point $x$ of the configuration at
    /// the start of the step (eq. 35), for rules that convect corners or
    /// mid-points.
    fn update<U>(
        &self,
        ctx: &DomainContext<'_, D, Dom>,
        displacement_at: U,
    ) -> Result<Dom, DomainError>
    where
        U: Fn(&SVector<f64, D>) -> Result<SVector<f64, D>, DomainError>;
}

/// Domains never change (the "no update" column of Table 2); also the only
/// sensible choice for bases without a domain (`()`).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoUpdate;

impl<const D: usize, Dom: Copy> DomainUpdater<D, Dom> for NoUpdate {
    const NAME: &'static str = "none";

    #[inline]
    fn update<U>(
        &self,
        ctx: &DomainContext<'_, D, Dom>,
        _displacement_at: U,
    ) -> Result<Dom, DomainError>
    where
        U: Fn(&SVector<f64, D>) -> Result<SVector<f64, D>, DomainError>,
    {
        Ok(*ctx.previous)
    }
}

/// GIMP half-lengths scaled by the diagonal of the right stretch tensor,
/// $l^p_i = l^{p0}_i U_{ii}$ (Charlton et al. 2017; Coombs 2020 eq. 34),
/// with $F = RU$. Suitable for stretch, compression and rotation; under
/// simple shear the domain volume changes although the deformation is
/// isochoric (Table 2, footnote c).
#[derive(Debug, Clone, Copy, Default)]
pub struct StretchU;

impl<const D: usize> DomainUpdater<D, SVector<f64, D>> for StretchU {
    const NAME: &'static str = "stretch";

    fn update<U>(
        &self,
        ctx: &DomainContext<'_, D, SVector<f64, D>>,
        _displacement_at: U,
    ) -> Result<SVector<f64, D>, DomainError>
    where
        U: Fn(&SVector<f64, D>) -> Result<SVector<f64, D>, DomainError>,
    {
        let u = right_stretch(ctx.f).ok_or_else(|| {
            DomainError("the right stretch tensor of F could not be computed".into())
        })?;
        Ok(SVector::<f64, D>::from_fn(|i, _| {
            ctx.initial[i] * u[(i, i)]
        }))
    }
}

/// $U = \sqrt{F^TF}$, the right stretch tensor of the polar decomposition.
pub fn right_stretch(f: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let c = f.transpose() * f;
    let s = mpm_constitutive::SymSpectral::new(&c).ok()?;
    if s.min_value() <= 0.0 {
        return None;
    }
    Some(s.map(f64::sqrt))
}

#[cfg(test)]
mod tests {
    use super::*;
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
