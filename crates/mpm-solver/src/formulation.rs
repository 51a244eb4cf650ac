//! The `Formulation` plug point: where equilibrium is satisfied.
//!
//! Coombs et al. 2020 compare two statements of equilibrium for implicit
//! MPM (Table 1). Both solve the same discrete equations, so they converge
//! to the same solution; they differ in what is computed per material point
//! per iteration.
//!
//! | | stress | volume | basis gradients | tangent |
//! |---|---|---|---|---|
//! | [`UpdatedLagrangian`] (§3) | $\sigma$ | $V_p = \Delta J V^n_p$ (eq. 5) | $\nabla_x S = \nabla_{\tilde X}S\,\Delta F^{-1}$ (eq. 8) | $a_{ijkl}$ (eq. A.1) |
//! | [`PreviouslyConverged`] (§5) | $\tilde P$ (eq. 18) | $V^n_p$ (eq. 22) | $\nabla_{\tilde X}S$ | $\tilde A_{ijkl}$ (eqs. A.3–A.6) |

use mpm_constitutive::{ConsistentTangent, PreviouslyConvergedTangent, Response, SpatialTangent};
use nalgebra::{Matrix3, SVector};

/// A statement of equilibrium (see the module docs).
pub trait Formulation: Copy + Default + Send + Sync + 'static {
    /// The consistent tangent that linearises this formulation.
    type Tangent: ConsistentTangent;
    /// Name used in outputs (`ul`, `pc`).
    const NAME: &'static str;
    /// Whether basis gradients must be mapped every iteration (eq. 8).
    const MAPS_GRADIENTS: bool;

    /// The stress measure of the internal force (eqs. 6, 23).
    fn stress<H: Copy>(r: &Response<H>) -> Matrix3<f64>;

    /// The integration volume of the point given its converged volume
    /// $V^n_p$.
    fn volume<H: Copy>(r: &Response<H>, volume_n: f64) -> f64;

    /// The basis gradient used in the force and stiffness, from the
    /// gradient with respect to the coordinates at the start of the step.
    fn map_gradient<H: Copy, const D: usize>(
        r: &Response<H>,
        g: &SVector<f64, D>,
    ) -> SVector<f64, D>;

    /// The direction $K$ in which a uniform dilatation $\delta\epsilon$
    /// changes the kinematic variable the tangent is the derivative with
    /// respect to: $\delta\Delta F\,\Delta F^{-1} = \delta\epsilon\,\mathbf
    /// 1$ gives $\mathbf 1$ for the spatial tangent and $\delta\Delta F =
    /// \delta\epsilon\,\Delta F$ for the previously converged one. The patch
    /// coupling of locking treatments contracts the tangent with it
    /// ([`crate::stages::patch`]).
    fn volumetric_direction<H: Copy>(r: &Response<H>) -> Matrix3<f64>;
}

/// Updated Lagrangian formulation (Coombs 2020 §3, eqs. 2–9): equilibrium in
/// the current configuration with Cauchy stress and spatial gradients.
#[derive(Debug, Clone, Copy, Default)]
pub struct UpdatedLagrangian;

impl Formulation for UpdatedLagrangian {
    type Tangent = SpatialTangent;
    const NAME: &'static str = "ul";
    const MAPS_GRADIENTS: bool = true;

    #[inline]
    fn stress<H: Copy>(r: &Response<H>) -> Matrix3<f64> {
        r.sigma
    }

    #[inline]
    fn volume<H: Copy>(r: &Response<H>, volume_n: f64) -> f64 {
        volume_n * r.j / r.j_n
    }

    /// $\partial S/\partial x_j = (\partial S/\partial\tilde X_i)(\Delta F^{-1})_{ij}$ (eq. 8).
    #[inline]
    fn map_gradient<H: Copy, const D: usize>(
        r: &Response<H>,
        g: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        SVector::<f64, D>::from_fn(|j, _| (0..D).map(|i| g[i] * r.delta_f_inv[(i, j)]).sum())
    }

    #[inline]
    fn volumetric_direction<H: Copy>(_r: &Response<H>) -> Matrix3<f64> {
        Matrix3::identity()
    }
}

/// Previously converged formulation (Coombs 2020 §5, eqs. 13–23):
/// equilibrium on the configuration at the start of the load step, so
/// basis gradients are computed once per step and never mapped.
#[derive(Debug, Clone, Copy, Default)]
pub struct PreviouslyConverged;

impl Formulation for PreviouslyConverged {
    type Tangent = PreviouslyConvergedTangent;
    const NAME: &'static str = "pc";
    const MAPS_GRADIENTS: bool = false;

    #[inline]
    fn stress<H: Copy>(r: &Response<H>) -> Matrix3<f64> {
        r.p_tilde()
    }

    #[inline]
    fn volume<H: Copy>(_r: &Response<H>, volume_n: f64) -> f64 {
        volume_n
    }

    #[inline]
    fn map_gradient<H: Copy, const D: usize>(
        _r: &Response<H>,
        g: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        *g
    }

    #[inline]
    fn volumetric_direction<H: Copy>(r: &Response<H>) -> Matrix3<f64> {
        r.delta_f
    }
}
