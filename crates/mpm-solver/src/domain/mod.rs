//! The `DomainUpdater` plug point: how a material point's domain (GIMP
//! half-lengths, CPDI2 corners) follows the deformation after a converged
//! load step (Coombs et al. 2020 §6.4, eqs. 32–39, Table 2).

use nalgebra::{Matrix3, SVector};

mod checks;
mod convected_corners;
mod det_f;
mod diag_f;
mod domain_volume;
mod incremental_volume_corrected_diag_f;
mod midpoint;
mod none;
mod stretch;
mod volume_corrected_diag_f;

pub use convected_corners::ConvectedCorners;
pub use det_f::DetF;
pub use diag_f::DiagF;
pub use domain_volume::DomainVolume;
pub use incremental_volume_corrected_diag_f::IncrementalVolumeCorrectedDiagF;
pub use midpoint::{CornerMidpoint, Midpoint};
pub use none::NoUpdate;
pub use stretch::StretchU;
pub use volume_corrected_diag_f::VolumeCorrectedDiagF;

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

    /// The converged volume of the point after the update, given the
    /// volume $\det(F)\,V^0_p$ of eqs. (5)/(22). Rules whose domain defines
    /// the volume (CPDI2's convected corners) return the domain's volume;
    /// the default keeps `f_volume`.
    #[inline]
    fn volume(&self, _domain: &Dom, f_volume: f64) -> f64 {
        f_volume
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
