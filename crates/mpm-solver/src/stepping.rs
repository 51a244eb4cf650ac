//! Load stepping with automatic step control (Wang et al. 2021 §5.2): the
//! increment doubles after a converged step (up to a maximum) and halves
//! after a failed one; below a minimum the analysis stops with a typed
//! error naming the step, the last residual and the cause.

use mpm_basis::BasisFunction;
use mpm_constitutive::LogStrainLaw;

use crate::boundary::Constraints;
use crate::domain::DomainUpdater;
use crate::error::SolverError;
use crate::formulation::Formulation;
use crate::implicit::{ImplicitSolver, StepError, StepReport};
use crate::locking::LockingTreatment;
use crate::mesh::NodalMesh;
use crate::points::MaterialPoints;

/// Load-factor increments: the analysis takes the load factor from 0 to 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadStepping {
    /// First increment.
    pub initial: f64,
    /// Largest increment (doubling stops here).
    pub max: f64,
    /// Smallest increment tried before giving up.
    pub min: f64,
}

impl LoadStepping {
    /// `steps` equal increments when every step converges (the papers'
    /// set-up); a failed step is halved, then the increment grows back.
    /// At most ten halvings.
    pub fn uniform(steps: usize) -> Self {
        let initial = 1.0 / steps.max(1) as f64;
        Self {
            initial,
            max: initial,
            min: initial / 1024.0,
        }
    }
}

/// What a whole analysis did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunSummary {
    /// Converged load steps.
    pub steps: usize,
    /// Failed attempts that were retried with a smaller increment.
    pub cut_steps: usize,
    /// Newton iterations over all converged steps.
    pub iterations: usize,
}

impl<const D: usize, B, F, L, K, U, C> ImplicitSolver<D, B, F, L, K, U, C>
where
    B: BasisFunction<D>,
    B::Mesh: NodalMesh,
    F: Formulation,
    L: LogStrainLaw,
    K: LockingTreatment,
    U: DomainUpdater<D, B::Domain>,
    C: Constraints<D>,
{
    /// Runs the analysis from load factor 0 to 1, calling `observer` after
    /// every converged step (for output and progress; an error from it
    /// stops the run).
    pub fn run<O>(
        &mut self,
        points: &mut MaterialPoints<D, L::History, B::Domain>,
        stepping: &LoadStepping,
        mut observer: O,
    ) -> Result<RunSummary, SolverError>
    where
        O: FnMut(
            usize,
            &StepReport<D>,
            &MaterialPoints<D, L::History, B::Domain>,
        ) -> Result<(), SolverError>,
    {
        if !(stepping.min > 0.0
            && stepping.min <= stepping.initial
            && stepping.initial <= stepping.max)
        {
            return Err(SolverError::InvalidInput(format!(
                "load stepping needs 0 < min <= initial <= max, got {stepping:?}"
            )));
        }
        let mut summary = RunSummary::default();
        let mut lambda = 0.0f64;
        let mut increment = stepping.initial;
        const END: f64 = 1.0 - 1e-12;
        while lambda < END {
            let target = (lambda + increment).min(1.0);
            match self.solve_load_step(points, lambda, target) {
                Ok(report) => {
                    summary.steps += 1;
                    summary.iterations += report.iterations();
                    lambda = target;
                    observer(summary.steps - 1, &report, points)?;
                    increment = (2.0 * increment).min(stepping.max);
                }
                Err(StepError::Fatal(e)) => return Err(e),
                Err(StepError::Retry {
                    cause,
                    last_residual,
                }) => {
                    summary.cut_steps += 1;
                    let tried = target - lambda;
                    increment = 0.5 * tried;
                    if increment < stepping.min {
                        return Err(SolverError::StepTooSmall {
                            step: summary.steps,
                            load_factor: lambda,
                            target,
                            increment: tried,
                            min_increment: stepping.min,
                            last_residual,
                            cause,
                        });
                    }
                }
            }
        }
        Ok(summary)
    }
}
