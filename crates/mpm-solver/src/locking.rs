//! The `LockingTreatment` plug point: how a material point's deformation
//! gradient is formed from the grid displacements.
//!
//! Standard MPM uses the point's own $\Delta F$ (eq. 7). Anti-locking
//! treatments replace its volumetric part with an average over a patch —
//! F-bar, F-patch (Wang et al. 2021, eq. 12) or cell-averaged dilatation —
//! so that one material point's stress depends on the displacements of the
//! nodes of the other points of its patch. The solver therefore asks the
//! treatment for the modified $\Delta\bar F$ after a pass that lets the
//! treatment gather patch averages, and the stiffness of a coupled
//! treatment has columns beyond the point's own stencil
//! ([`LockingTreatment::COUPLES_POINTS`]); the assembly is organised by
//! column blocks so that these extra columns fit without changing the
//! solver.

use nalgebra::Matrix3;

/// How a material point's deformation-gradient increment is formed.
pub trait LockingTreatment: Send + Sync {
    /// Name used in outputs.
    const NAME: &'static str;
    /// Whether a point's stress depends on other points' kinematics (then
    /// the stiffness couples stencils and a patch-average pass runs first).
    const COUPLES_POINTS: bool;

    /// Gathers patch averages from every point's own increment and
    /// integration volume; called once per iteration before
    /// [`Self::modified_increment`], and only when
    /// [`Self::COUPLES_POINTS`] is true.
    fn prepare(&mut self, _increments: &[Matrix3<f64>], _volumes: &[f64]) {}

    /// The increment used by the constitutive update of point `p`, from its
    /// own increment (eq. 7).
    fn modified_increment(&self, p: usize, delta_f: &Matrix3<f64>) -> Matrix3<f64>;
}

/// No treatment: standard MPM, each point uses its own $\Delta F$.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoLocking;

impl LockingTreatment for NoLocking {
    const NAME: &'static str = "none";
    const COUPLES_POINTS: bool = false;

    #[inline(always)]
    fn modified_increment(&self, _p: usize, delta_f: &Matrix3<f64>) -> Matrix3<f64> {
        *delta_f
    }
}
