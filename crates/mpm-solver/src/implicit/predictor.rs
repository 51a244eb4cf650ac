//! The secant predictor ([`super::NewtonOptions::predictor`]) and its
//! memory, saved with checkpoints so that a resumed run repeats the
//! uninterrupted one.

use super::ImplicitSolver;
use crate::error::SolverError;
use crate::mesh::NodalMesh;
use crate::parts::SolverParts;
use crate::stages::system::NONE;

impl<const D: usize, P: SolverParts<D>> ImplicitSolver<D, P> {
    /// Free dofs start from the previous converged increment scaled to
    /// this step's load increment `dlambda`.
    /// Whether it set any increment.
    pub(super) fn predict(&mut self, dlambda: f64) -> bool {
        if !self.options.predictor {
            return false;
        }
        let Some((previous, dlambda_prev)) = &self.previous else {
            return false;
        };
        let scale = dlambda / dlambda_prev;
        let sys = &self.system;
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            if free != NONE {
                let mesh_dof = D * sys.active[dof / D] + dof % D;
                self.it.du[dof] = scale * previous[mesh_dof];
            }
        }
        true
    }

    /// The secant predictor's memory: the last converged increment per mesh
    /// dof and its load increment; `None` before the first step or with
    /// the predictor off. Saved with a checkpoint so that a resumed run
    /// repeats the uninterrupted one.
    pub fn predictor_state(&self) -> Option<(&[f64], f64)> {
        self.previous.as_ref().map(|(u, dl)| (u.as_slice(), *dl))
    }

    /// Restores [`Self::predictor_state`].
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] if the increment does not have one
    /// entry per mesh dof or is not finite.
    pub fn set_predictor_state(
        &mut self,
        state: Option<(Vec<f64>, f64)>,
    ) -> Result<(), SolverError> {
        if let Some((u, dl)) = &state {
            let n = D * self.mesh.node_count();
            if u.len() != n || !u.iter().all(|x| x.is_finite()) || !(dl.is_finite() && *dl > 0.0) {
                return Err(SolverError::InvalidInput(format!(
                    "predictor state has {} finite-checked entries for {n} mesh dofs and load increment {dl}",
                    u.len()
                )));
            }
        }
        self.previous = state;
        Ok(())
    }

    /// Stores the converged increment per mesh dof for the predictor.
    pub(super) fn remember_increment(&mut self, dlambda: f64) {
        if !self.options.predictor {
            return;
        }
        let n = D * self.mesh.node_count();
        let (mut store, _) = self.previous.take().unwrap_or_default();
        store.clear();
        store.resize(n, 0.0);
        for (dof, du) in self.it.du.iter().enumerate() {
            store[D * self.system.active[dof / D] + dof % D] = *du;
        }
        self.previous = Some((store, dlambda));
    }
}
