//! Load stepping with automatic step control (Wang et al. 2021 §5.2): the
//! increment doubles after a converged step (up to a maximum) and halves
//! after a failed one; below a minimum the analysis stops with a typed
//! error naming the step, the last residual and the cause.

use crate::error::SolverError;
use crate::implicit::{CutStep, FreeStiffness, ImplicitSolver, StepError, StepReport};
use crate::parts::{PointsOf, SolverParts};

/// The smallest load increment an analysis accepts. The load factor in
/// [0, 1] resolves about 1e-16, so far smaller increments would not move it
/// at all (a run that never ends), and steps of 1e-12 already take 1e12
/// of them; a minimum below this is refused as invalid input.
pub const MIN_LOAD_INCREMENT: f64 = 1e-12;

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

/// Where an analysis stands between two load steps: enough, together with
/// the material points and [`ImplicitSolver::predictor_state`], to resume
/// it with the same results as an uninterrupted run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunState {
    /// Load factor reached.
    pub load_factor: f64,
    /// Increment the next step will try.
    pub increment: f64,
    /// Counters so far.
    pub summary: RunSummary,
}

impl RunState {
    /// The start of an analysis.
    pub fn start(stepping: &LoadStepping) -> Self {
        Self {
            load_factor: 0.0,
            increment: stepping.initial,
            summary: RunSummary::default(),
        }
    }
}

/// What the observer of [`ImplicitSolver::run_from`] learns besides the
/// step report and the points: the state to resume from.
#[derive(Debug, Clone, Copy)]
pub struct StepContext<'a, M> {
    /// Load stepping state after the step.
    pub state: RunState,
    /// [`ImplicitSolver::predictor_state`] after the step.
    pub predictor: Option<(&'a [f64], f64)>,
    /// The background mesh the step was solved on (it moves with
    /// moving-mesh conditions).
    pub mesh: &'a M,
    /// [`ImplicitSolver::free_stiffness`] of the step.
    pub stiffness: Option<FreeStiffness<'a>>,
}

/// What a whole analysis did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RunSummary {
    /// Converged load steps.
    pub steps: usize,
    /// Failed attempts that were retried with a smaller increment.
    pub cut_steps: usize,
    /// Newton iterations over all converged steps.
    pub iterations: usize,
}

impl<const D: usize, P: SolverParts<D>> ImplicitSolver<D, P> {
    /// Runs the analysis from load factor 0 to 1, calling `observer` after
    /// every converged step (for output and progress; an error from it
    /// stops the run).
    pub fn run<O>(
        &mut self,
        points: &mut PointsOf<D, P>,
        stepping: &LoadStepping,
        mut observer: O,
    ) -> Result<RunSummary, SolverError>
    where
        O: FnMut(usize, &StepReport<D>, &PointsOf<D, P>) -> Result<(), SolverError>,
    {
        self.run_from(points, stepping, RunState::start(stepping), |s, r, p, _| {
            observer(s, r, p)
        })
    }

    /// Runs the analysis from `state` (for example one saved by a
    /// checkpoint) to load factor 1. The observer also receives the state
    /// after the step, from which the run can later be resumed.
    pub fn run_from<O>(
        &mut self,
        points: &mut PointsOf<D, P>,
        stepping: &LoadStepping,
        state: RunState,
        mut observer: O,
    ) -> Result<RunSummary, SolverError>
    where
        O: FnMut(
            usize,
            &StepReport<D>,
            &PointsOf<D, P>,
            &StepContext<'_, P::Mesh>,
        ) -> Result<(), SolverError>,
    {
        if !(stepping.min >= MIN_LOAD_INCREMENT
            && stepping.min <= stepping.initial
            && stepping.initial <= stepping.max)
        {
            return Err(SolverError::InvalidInput(format!(
                "load stepping needs {MIN_LOAD_INCREMENT:e} <= min <= initial <= max, got {stepping:?}"
            )));
        }
        if !(state.load_factor.is_finite()
            && (0.0..=1.0).contains(&state.load_factor)
            && state.increment > 0.0)
        {
            return Err(SolverError::InvalidInput(format!(
                "cannot resume from {state:?}: need 0 <= load factor <= 1 and a positive increment"
            )));
        }
        let mut summary = state.summary;
        let mut lambda = state.load_factor;
        let mut increment = state.increment.min(stepping.max);
        const END: f64 = 1.0 - 1e-12;
        let mut cuts = Vec::new();
        while lambda < END {
            let target = (lambda + increment).min(1.0);
            match self.solve_load_step(points, lambda, target) {
                Ok(mut report) => {
                    report.cuts = std::mem::take(&mut cuts);
                    summary.steps += 1;
                    summary.iterations += report.iterations();
                    lambda = target;
                    increment = (2.0 * increment).min(stepping.max);
                    let now = RunState {
                        load_factor: lambda,
                        increment,
                        summary,
                    };
                    let context = StepContext {
                        state: now,
                        predictor: self.predictor_state(),
                        mesh: &self.mesh,
                        stiffness: self.free_stiffness(),
                    };
                    observer(summary.steps - 1, &report, points, &context)?;
                }
                Err(StepError::Fatal(e)) => {
                    return Err(SolverError::InStep {
                        step: summary.steps,
                        load_factor: lambda,
                        target,
                        source: Box::new(e),
                    });
                }
                Err(StepError::Retry {
                    cause,
                    last_residual,
                }) => {
                    summary.cut_steps += 1;
                    let tried = target - lambda;
                    increment = 0.5 * tried;
                    if increment >= stepping.min {
                        cuts.push(CutStep {
                            lambda0: lambda,
                            target,
                            last_residual,
                            cause,
                        });
                    } else {
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
