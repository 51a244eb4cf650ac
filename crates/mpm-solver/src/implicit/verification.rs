//! Verification helpers: the residual and the assembled stiffness as dense
//! arrays at a chosen displacement increment, so that tests can compare
//! the stiffness with finite differences of the residual, and one Newton
//! iteration's assembly for benchmarks.

use super::ImplicitSolver;
use crate::error::{SolverError, StepFailure};
use crate::parts::{PointsOf, SolverParts};
use crate::stages::system::NONE;

impl<const D: usize, P: SolverParts<D>> ImplicitSolver<D, P> {
    /// A load step from `lambda0` to `lambda1` up to its Newton
    /// iterations — mesh position, then stages 1–3 of the module docs
    /// (basis, constraints and system, external force) —
    /// [`Self::solve_load_step`] starts with it; returns the number of free
    /// dofs.
    pub fn prepare_step(
        &mut self,
        points: &PointsOf<D, P>,
        lambda0: f64,
        lambda1: f64,
    ) -> Result<usize, SolverError> {
        self.move_mesh(lambda0)?;
        self.evaluate_basis(points)?;
        self.begin_constraints(points);
        self.build_system(points, lambda0, lambda1)?;
        self.assemble_external_force(points, lambda1);
        Ok(self.system.n_free)
    }

    /// The out-of-balance force $f^{int} - f^{ext}$ on the free dofs at the
    /// free-dof increment `du_free` (prescribed dofs at their prescribed
    /// increments).
    pub fn free_residual(
        &mut self,
        points: &PointsOf<D, P>,
        du_free: &[f64],
    ) -> Result<Vec<f64>, StepFailure> {
        self.set_free_increment(du_free);
        self.update_material_points(points)?;
        self.assemble_internal_force();
        let sys = &self.system;
        let mut r = vec![0.0; sys.n_free];
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            if free != NONE {
                r[free as usize] = self.it.f_int[dof] - self.it.f_ext[dof];
            }
        }
        Ok(r)
    }

    /// The assembled stiffness over free dofs at `du_free`, dense and
    /// column-major (`n_free × n_free`).
    pub fn free_stiffness_dense(
        &mut self,
        points: &PointsOf<D, P>,
        du_free: &[f64],
    ) -> Result<Vec<f64>, StepFailure> {
        self.assemble_at(points, du_free)?;
        let sys = &self.system;
        let n = sys.n_free;
        let mut k = vec![0.0; n * n];
        for c in 0..n {
            for e in sys.col_ptr[c]..sys.col_ptr[c + 1] {
                k[c * n + sys.row_idx[e]] = self.it.values[e];
            }
        }
        Ok(k)
    }

    /// One Newton iteration's assembly at `du_free` as Newton runs it on
    /// an iterate it expects to correct: material update with the
    /// consistent tangents in one pass
    /// ([`Self::update_material_points_with_tangents`]), internal force
    /// and sparse stiffness in one pass over the nodes
    /// ([`Self::assemble_internal_force_and_stiffness`]); what the
    /// benchmarks time. Returns the normalised residual.
    pub fn assemble_at(
        &mut self,
        points: &PointsOf<D, P>,
        du_free: &[f64],
    ) -> Result<f64, StepFailure> {
        self.set_free_increment(du_free);
        self.update_material_points_with_tangents(points)?;
        self.assemble_internal_force_and_stiffness();
        Ok(self.normalised_residual())
    }

    /// [`Self::assemble_at`] through the separate stages: the update
    /// keeping every response, the internal force, the tangents from the
    /// stored responses, the stiffness (as Newton runs an iterate it
    /// expected to converge but must correct). The same numbers bit for
    /// bit.
    pub fn assemble_in_stages_at(
        &mut self,
        points: &PointsOf<D, P>,
        du_free: &[f64],
    ) -> Result<f64, StepFailure> {
        self.set_free_increment(du_free);
        self.update_material_points(points)?;
        self.assemble_internal_force();
        self.update_tangents(points)?;
        self.assemble_stiffness();
        Ok(self.normalised_residual())
    }

    /// The current increment at the free dofs (after a converged step: the
    /// converged increment of that step), in the numbering of
    /// [`Self::prepare_step`].
    pub fn free_increment(&self) -> Vec<f64> {
        let sys = &self.system;
        let mut du = vec![0.0; sys.n_free];
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            if free != NONE {
                du[free as usize] = self.it.du[dof];
            }
        }
        du
    }

    fn set_free_increment(&mut self, du_free: &[f64]) {
        let sys = &self.system;
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            self.it.du[dof] = if free == NONE {
                sys.prescribed[dof]
            } else {
                du_free.get(free as usize).copied().unwrap_or(0.0)
            };
        }
    }
}
