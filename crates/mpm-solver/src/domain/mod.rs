//! The `DomainUpdater` plug point: how a material point's domain (GIMP
//! half-lengths, CPDI2 corners) follows the deformation after a converged
//! load step (Coombs et al. 2020 §6.4, eqs. 32–39, Table 2).

use nalgebra::{Matrix3, SVector};

mod checks;
mod convected_corners;
mod det_f;
mod diag_f;
mod domain_volume;
mod gimp_rule;
mod incremental_volume_corrected_diag_f;
mod midpoint;
mod none;
mod stretch;
mod volume_corrected_diag_f;

pub use convected_corners::ConvectedCorners;
pub use det_f::DetF;
pub use diag_f::DiagF;
pub use domain_volume::DomainVolume;
pub use gimp_rule::{AnyGimpRule, GimpRule};
pub use incremental_volume_corrected_diag_f::IncrementalVolumeCorrectedDiagF;
pub use midpoint::{CornerMidpoint, Midpoint};
pub use none::NoUpdate;
pub use stretch::StretchU;
pub use volume_corrected_diag_f::VolumeCorrectedDiagF;

/// Why a domain update failed (the solver adds the material point).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DomainError {
    /// A deformation gradient has a non-finite entry.
    #[error("{name}[({row}, {col})] = {value} is not finite")]
    NonFiniteTensor {
        /// `"F"` or `"ΔF"`.
        name: &'static str,
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// The entry.
        value: f64,
    },
    /// A deformation gradient is inverted or degenerate.
    #[error("det {name} = {det:e} is not positive: the deformation is inverted or degenerate")]
    NonPositiveJacobian {
        /// `"F"` or `"ΔF"`.
        name: &'static str,
        /// Its determinant.
        det: f64,
    },
    /// A half-length is negative or not finite.
    #[error(
        "the {which} half-length {value} along axis {axis} is not a finite non-negative number"
    )]
    HalfLength {
        /// `"initial"` or `"previous"`.
        which: &'static str,
        /// The axis.
        axis: usize,
        /// The value.
        value: f64,
    },
    /// The right stretch tensor of eq. (34) could not be computed.
    #[error("the right stretch tensor of F could not be computed")]
    StretchTensor,
    /// The grid displacement interpolated at a corner or mid-point is not
    /// finite.
    #[error("the displacement {value:?} at {at:?} is not finite")]
    NonFiniteDisplacement {
        /// The displacement.
        value: Vec<f64>,
        /// Where.
        at: Vec<f64>,
    },
    /// The background mesh's shape functions could not be evaluated at a
    /// corner or mid-point (it left the mesh).
    #[error("the mesh's shape functions at {at:?}: {source}")]
    Mesh {
        /// Where.
        at: Vec<f64>,
        /// The basis error.
        source: mpm_basis::BasisError,
    },
    /// A corner or mid-point lies on a node that is not active this step.
    #[error("node {node} near {at:?} is not active")]
    InactiveNode {
        /// The mesh node.
        node: usize,
        /// The point.
        at: Vec<f64>,
    },
    /// The convected CPDI2 domain is inverted or degenerate.
    #[error("the convected CPDI2 domain is not admissible: {0}")]
    Corners(#[source] mpm_basis::BasisError),
    /// The rule cannot produce an admissible domain from this deformation.
    #[error("{rule}: {reason}")]
    Inadmissible {
        /// The rule's [`DomainUpdater::NAME`].
        rule: &'static str,
        /// Why, and what to do instead.
        reason: String,
    },
}

/// The [`DomainContext`] of a GIMP point, whose domain is its vector of
/// half-lengths.
pub type GimpContext<'a, const D: usize> = DomainContext<'a, D, SVector<f64, D>>;

/// A GIMP rule whose half-lengths follow from the point's own deformation
/// (eqs. 32–34, 38, 39): it never reads the grid displacement. Such a rule
/// implements this trait only; [`DomainUpdater`] comes with it.
pub trait DeformationRule<const D: usize>: Send + Sync {
    /// Name used in outputs and scene files.
    const NAME: &'static str;

    /// The half-lengths after the converged step.
    fn half_lengths(&self, ctx: &GimpContext<'_, D>) -> Result<SVector<f64, D>, DomainError>;
}

impl<const D: usize, R: DeformationRule<D>> DomainUpdater<D, SVector<f64, D>> for R {
    const NAME: &'static str = R::NAME;

    #[inline]
    fn update(
        &self,
        ctx: &GimpContext<'_, D>,
        _: impl DisplacementField<D>,
    ) -> Result<SVector<f64, D>, DomainError> {
        self.half_lengths(ctx)
    }
}

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

/// The converged grid displacement increment as a function of a point of
/// the configuration at the start of the step (eq. 35): what rules that
/// convect corners or mid-points read. Every such closure is one.
pub trait DisplacementField<const D: usize>:
    Fn(&SVector<f64, D>) -> Result<SVector<f64, D>, DomainError>
{
}

impl<const D: usize, F> DisplacementField<D> for F where
    F: Fn(&SVector<f64, D>) -> Result<SVector<f64, D>, DomainError>
{
}

/// A rule that updates material point domains after a converged step.
pub trait DomainUpdater<const D: usize, Dom>: Send + Sync {
    /// Name used in outputs and scene files.
    const NAME: &'static str;

    /// The updated domain. `displacement_at(x)` interpolates the converged
    /// grid displacement increment at a point $x$ of the configuration at
    /// the start of the step (eq. 35), for rules that convect corners or
    /// mid-points.
    fn update(
        &self,
        ctx: &DomainContext<'_, D, Dom>,
        displacement_at: impl DisplacementField<D>,
    ) -> Result<Dom, DomainError>;

    /// The converged volume of the point after the update, given the
    /// volume $\det(F)\,V^0_p$ of eqs. (5)/(22). Rules whose domain defines
    /// the volume (CPDI2's convected corners) return the domain's volume;
    /// the default keeps `f_volume`.
    #[inline]
    fn volume(&self, _domain: &Dom, f_volume: f64) -> f64 {
        f_volume
    }

    /// The rule's name in outputs and errors: [`Self::NAME`], or the rule
    /// a run-time choice holds ([`AnyGimpRule`]).
    fn name(&self) -> &'static str {
        Self::NAME
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
