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
    /// [`ImplicitSolver::contact_state`] after the step.
    pub contact: &'a [f64],
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
        let mut control = StepControl::new(stepping, state)?;
        while let Some((lambda, target)) = control.next_step() {
            match self.solve_load_step(points, lambda, target) {
                Ok(report) => {
                    let (step, report) = control.converged(report);
                    let context = StepContext {
                        state: control.state(),
                        predictor: self.predictor_state(),
                        contact: self.contact_state(),
                        mesh: &self.mesh,
                        stiffness: self.free_stiffness(),
                    };
                    observer(step, &report, points, &context)?;
                }
                Err(e) => control.failed(e)?,
            }
        }
        Ok(control.state().summary)
    }
}

/// The automatic step control of a run, apart from the solver: which step
/// to try next, what a converged or failed step changes, when to give
/// up. Compiled once per dimension, whatever solver it drives.
#[derive(Debug)]
pub struct StepControl {
    stepping: LoadStepping,
    summary: RunSummary,
    lambda: f64,
    increment: f64,
    /// The failed attempts since the last converged step.
    cuts: Vec<CutStep>,
    /// The target of the step being tried.
    target: f64,
}

impl StepControl {
    /// Continues a run from `state` with `stepping`.
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] for increments out of order or below
    /// [`MIN_LOAD_INCREMENT`], or a state that cannot be resumed.
    pub fn new(stepping: &LoadStepping, state: RunState) -> Result<Self, SolverError> {
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
        Ok(Self {
            stepping: *stepping,
            summary: state.summary,
            lambda: state.load_factor,
            increment: state.increment.min(stepping.max),
            cuts: Vec::new(),
            target: state.load_factor,
        })
    }

    /// The load factors from and to which the next step goes, or `None`
    /// when the run has reached 1.
    pub fn next_step(&mut self) -> Option<(f64, f64)> {
        const END: f64 = 1.0 - 1e-12;
        (self.lambda < END).then(|| {
            self.target = (self.lambda + self.increment).min(1.0);
            (self.lambda, self.target)
        })
    }

    /// Accepts the converged step: its number and its report with the
    /// cuts that preceded it; the increment doubles up to the maximum.
    pub fn converged<const D: usize>(
        &mut self,
        mut report: StepReport<D>,
    ) -> (usize, StepReport<D>) {
        report.cuts = std::mem::take(&mut self.cuts);
        self.summary.steps += 1;
        self.summary.iterations += report.iterations();
        self.lambda = self.target;
        self.increment = (2.0 * self.increment).min(self.stepping.max);
        (self.summary.steps - 1, report)
    }

    /// Records the failed step: the increment halves.
    ///
    /// # Errors
    /// [`SolverError::InStep`] for a fatal failure,
    /// [`SolverError::StepTooSmall`] when the halved increment falls below
    /// the minimum.
    pub fn failed(&mut self, error: StepError) -> Result<(), SolverError> {
        let (lambda, target) = (self.lambda, self.target);
        let (cause, last_residual) = match error {
            StepError::Fatal(e) => {
                return Err(SolverError::InStep {
                    step: self.summary.steps,
                    load_factor: lambda,
                    target,
                    source: Box::new(e),
                });
            }
            StepError::Retry {
                cause,
                last_residual,
            } => (cause, last_residual),
        };
        self.summary.cut_steps += 1;
        let tried = target - lambda;
        self.increment = 0.5 * tried;
        if self.increment < self.stepping.min {
            return Err(SolverError::StepTooSmall {
                step: self.summary.steps,
                load_factor: lambda,
                target,
                increment: tried,
                min_increment: self.stepping.min,
                last_residual,
                cause,
            });
        }
        self.cuts.push(CutStep {
            lambda0: lambda,
            target,
            last_residual,
            cause,
        });
        Ok(())
    }

    /// Where the run stands: the state to resume from.
    pub fn state(&self) -> RunState {
        RunState {
            load_factor: self.lambda,
            increment: self.increment,
            summary: self.summary,
        }
    }
}
