//! Options of the explicit solver.

use nalgebra::SVector;

use crate::error::SolverError;

/// How the time increment is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeStep {
    /// The CFL condition (MPoint notes eqs. 45–46) times a safety factor
    /// in (0, 1], recomputed every step:
    /// $\Delta t = \text{factor}\cdot h / \max_p(c_p + \|v_p\|)$ with
    /// $c_p = \sqrt{(K + \tfrac43 G)\,V_p/m_p}$.
    Cfl {
        /// The safety factor.
        factor: f64,
    },
    /// A fixed increment (benchmarks; convergence studies in $\Delta t$).
    Fixed(f64),
}

/// Options of [`super::ExplicitSolver`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExplicitOptions<const D: usize> {
    /// The time increment rule. Default: CFL with factor 0.5.
    pub time_step: TimeStep,
    /// Gravitational acceleration $b$ of eq. (21). Default: none.
    pub gravity: SVector<f64, D>,
}

impl<const D: usize> Default for ExplicitOptions<D> {
    fn default() -> Self {
        Self {
            time_step: TimeStep::Cfl { factor: 0.5 },
            gravity: SVector::zeros(),
        }
    }
}

impl<const D: usize> ExplicitOptions<D> {
    /// Checks the values.
    ///
    /// # Errors
    /// A CFL factor outside (0, 1], a fixed step that is not positive and
    /// finite, a non-finite gravity.
    pub fn validate(&self) -> Result<(), SolverError> {
        match self.time_step {
            TimeStep::Cfl { factor } if !(factor > 0.0 && factor <= 1.0) => {
                return Err(SolverError::InvalidInput(format!(
                    "CFL factor {factor} must lie in (0, 1]"
                )));
            }
            TimeStep::Fixed(dt) if !(dt.is_finite() && dt > 0.0) => {
                return Err(SolverError::InvalidInput(format!(
                    "fixed time step {dt} must be positive and finite"
                )));
            }
            _ => {}
        }
        if self.gravity.iter().any(|g| !g.is_finite()) {
            return Err(SolverError::InvalidInput(format!(
                "gravity {:?} must be finite",
                self.gravity.as_slice()
            )));
        }
        Ok(())
    }
}
