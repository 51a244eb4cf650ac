//! The `[solver]` keys against the solver kind: the keys of the other
//! kind refused where they are, and the explicit solver's end time, time
//! step, transfer and output interval checked and completed with their
//! defaults.

use toml::Spanned;

use crate::SceneError;
use crate::format::{SolverKind, SolverSpec, TransferKind};
use crate::source::SceneSource;
use crate::variant::LockingKind;

/// The `[solver]` keys of an explicit run, checked.
#[derive(Debug, Clone, Copy)]
pub(super) struct ExplicitKeys {
    /// `end_time` (s).
    pub(super) end_time: f64,
    /// `output_interval` (s).
    pub(super) output_interval: f64,
    /// `cfl` or `time_step`.
    pub(super) time_step: mpm_solver::TimeStep,
    /// `transfer`.
    pub(super) transfer: TransferKind,
    /// The transfer's FLIP fraction.
    pub(super) alpha: f64,
    /// `locking`.
    pub(super) locking: LockingKind,
    /// `rebalance_every` (steps; 0: never).
    pub(super) rebalance_every: usize,
    /// `rebalance_threshold`.
    pub(super) rebalance_threshold: f64,
}

/// Checks the `[solver]` keys against the solver kind: the keys of the
/// other kind are refused where they are, and the explicit keys are
/// checked and completed with their defaults (`None` for the implicit
/// solver).
pub(super) fn solver_keys(
    s: &SolverSpec,
    src: &SceneSource,
) -> Result<Option<ExplicitKeys>, SceneError> {
    let span = |v: &Option<Spanned<f64>>| v.as_ref().map(Spanned::span);
    let explicit_keys = [
        ("end_time", span(&s.end_time)),
        ("cfl", span(&s.cfl)),
        ("time_step", span(&s.time_step)),
        ("transfer", s.transfer.as_ref().map(Spanned::span)),
        ("alpha", span(&s.alpha)),
        ("output_interval", span(&s.output_interval)),
        (
            "rebalance_every",
            s.rebalance_every.as_ref().map(Spanned::span),
        ),
        ("rebalance_threshold", span(&s.rebalance_threshold)),
    ];
    if s.kind() == SolverKind::Implicit {
        if let Some((key, Some(at))) = explicit_keys.into_iter().find(|(_, at)| at.is_some()) {
            return Err(src.error(
                Some(at),
                &format!(
                    "solver `{key}` applies to kind = \"explicit\" (the implicit solver steps the load factor: `steps`, `max_increment`, `min_increment`)"
                ),
            ));
        }
        if *s.locking.get_ref() == LockingKind::CellAveraged {
            return Err(src.at(&s.locking, crate::rules::CELL_AVERAGED_IMPLICIT));
        }
        return Ok(None);
    }
    let given = |present: bool, at: std::ops::Range<usize>| present.then_some(at);
    let implicit_keys = [
        (
            "formulation",
            given(SolverSpec::given(&s.formulation), s.formulation.span()),
        ),
        (
            "gimp_volume",
            given(SolverSpec::given(&s.gimp_volume), s.gimp_volume.span()),
        ),
        ("steps", given(SolverSpec::given(&s.steps), s.steps.span())),
        ("max_increment", span(&s.max_increment)),
        ("min_increment", span(&s.min_increment)),
        (
            "tolerance",
            given(SolverSpec::given(&s.tolerance), s.tolerance.span()),
        ),
        (
            "max_iterations",
            given(
                SolverSpec::given(&s.max_iterations),
                s.max_iterations.span(),
            ),
        ),
        (
            "predictor",
            given(SolverSpec::given(&s.predictor), s.predictor.span()),
        ),
        (
            "first_tangent",
            given(SolverSpec::given(&s.first_tangent), s.first_tangent.span()),
        ),
        (
            "linear",
            given(SolverSpec::given(&s.linear), s.linear.span()),
        ),
        ("linear_tolerance", span(&s.linear_tolerance)),
        (
            "max_direct_dofs",
            s.max_direct_dofs.as_ref().map(Spanned::span),
        ),
        ("weak_node_threshold", span(&s.weak_node_threshold)),
        ("weak_node_stiffness", span(&s.weak_node_stiffness)),
        ("ghost_penalty", span(&s.ghost_penalty)),
        ("ghost_fill", span(&s.ghost_fill)),
    ];
    if let Some((key, Some(at))) = implicit_keys.into_iter().find(|(_, at)| at.is_some()) {
        return Err(src.error(
            Some(at),
            &format!(
                "solver `{key}` applies to the implicit solver; kind = \"explicit\" steps in time (`end_time`, `cfl` or `time_step`)"
            ),
        ));
    }
    let locking = *s.locking.get_ref();
    if matches!(locking, LockingKind::FBar | LockingKind::FPatch) {
        return Err(src.at(
            &s.locking,
            format!(
                "locking = {locking} is an implicit treatment; the explicit solver takes locking = \"none\" or \"cell_averaged\""
            ),
        ));
    }
    let Some(end) = &s.end_time else {
        return Err(src.at(
            &s.kind,
            "kind = \"explicit\" needs `end_time`, the simulated time to reach (s)",
        ));
    };
    let end_time = *end.get_ref();
    if end_time <= 0.0 {
        return Err(src.at(
            end,
            format!("solver `end_time` must be positive, got {end_time}"),
        ));
    }
    let time_step = explicit_time_step(s, src, end_time)?;
    let transfer = s
        .transfer
        .as_ref()
        .map_or(TransferKind::default(), |t| *t.get_ref());
    let alpha = blend_alpha(s, src, transfer)?;
    let output_interval = output_interval(s, src, end_time)?;
    let rebalance_threshold = rebalance_threshold(s, src)?;
    Ok(Some(ExplicitKeys {
        end_time,
        output_interval,
        time_step,
        transfer,
        alpha,
        locking,
        rebalance_every: s
            .rebalance_every
            .as_ref()
            .map_or(DEFAULT_REBALANCE_EVERY, |e| *e.get_ref()),
        rebalance_threshold,
    }))
}

/// `output_interval` (s), positive and at most 1e6 outputs before
/// `end_time`; `end_time` / [`DEFAULT_OUTPUTS`] without it.
fn output_interval(s: &SolverSpec, src: &SceneSource, end_time: f64) -> Result<f64, SceneError> {
    Ok(match &s.output_interval {
        Some(o) => {
            let value = *o.get_ref();
            if value <= 0.0 {
                return Err(src.at(
                    o,
                    format!("solver `output_interval` must be positive, got {value}"),
                ));
            }
            if end_time / value > 1e6 {
                return Err(src.at(
                    o,
                    format!("solver `output_interval` {value:e} would write more than 1e6 outputs before end_time {end_time}"),
                ));
            }
            value
        }
        None => end_time / DEFAULT_OUTPUTS as f64,
    })
}

/// `rebalance_threshold`, above 1; [`DEFAULT_REBALANCE_THRESHOLD`]
/// without it.
fn rebalance_threshold(s: &SolverSpec, src: &SceneSource) -> Result<f64, SceneError> {
    Ok(match &s.rebalance_threshold {
        Some(t) if !(*t.get_ref() > 1.0 && t.get_ref().is_finite()) => {
            return Err(src.at(
                t,
                format!(
                    "solver `rebalance_threshold` is the most loaded process's points over the mean: above 1, got {}",
                    t.get_ref()
                ),
            ));
        }
        Some(t) => *t.get_ref(),
        None => DEFAULT_REBALANCE_THRESHOLD,
    })
}

/// The explicit time step of `s`: `cfl` or `time_step` (not both), a
/// CFL factor of [`DEFAULT_CFL`] without either; `end_time` bounds the
/// number of fixed steps.
///
/// # Errors
/// [`SceneError::Scene`] at `cfl` or `time_step`.
fn explicit_time_step(
    s: &SolverSpec,
    src: &SceneSource,
    end_time: f64,
) -> Result<mpm_solver::TimeStep, SceneError> {
    Ok(match (&s.cfl, &s.time_step) {
        (Some(_), Some(dt)) => {
            return Err(src.at(
                dt,
                "give solver `cfl` or `time_step`, not both (a fixed step ignores the CFL condition)",
            ));
        }
        (Some(c), None) => {
            let factor = *c.get_ref();
            if !(factor > 0.0 && factor <= 1.0) {
                return Err(src.at(c, format!("solver `cfl` must lie in (0, 1], got {factor}")));
            }
            mpm_solver::TimeStep::Cfl { factor }
        }
        (None, Some(dt)) => {
            let value = *dt.get_ref();
            if value <= 0.0 {
                return Err(src.at(
                    dt,
                    format!("solver `time_step` must be positive, got {value}"),
                ));
            }
            if end_time / value > 1e9 {
                return Err(src.at(
                    dt,
                    format!("solver `time_step` {value:e} would take more than 1e9 steps to reach end_time {end_time}"),
                ));
            }
            mpm_solver::TimeStep::Fixed(value)
        }
        (None, None) => mpm_solver::TimeStep::Cfl {
            factor: DEFAULT_CFL,
        },
    })
}

/// The FLIP fraction α of `transfer`: `alpha` for the blend (and only
/// there), 0 for PIC and TPIC, 1 for FLIP and TFLIP.
///
/// # Errors
/// [`SceneError::Scene`] at `alpha` or `transfer`.
fn blend_alpha(
    s: &SolverSpec,
    src: &SceneSource,
    transfer: TransferKind,
) -> Result<f64, SceneError> {
    Ok(match (transfer, &s.alpha) {
        (TransferKind::Blend, Some(a)) => {
            let alpha = *a.get_ref();
            if !(0.0..=1.0).contains(&alpha) {
                return Err(src.at(a, format!("solver `alpha` must lie in [0, 1], got {alpha}")));
            }
            alpha
        }
        (TransferKind::Blend, None) => {
            let at = s.transfer.as_ref().map_or(s.kind.span(), Spanned::span);
            return Err(src.error(
                Some(at),
                "transfer = \"blend\" needs `alpha`, its FLIP fraction in [0, 1]",
            ));
        }
        (other, Some(a)) => {
            return Err(src.at(
                a,
                format!(
                    "solver `alpha` applies to transfer = \"blend\" (transfer = \"{}\" has α = {})",
                    other.name(),
                    if matches!(other, TransferKind::Pic | TransferKind::Tpic) {
                        0
                    } else {
                        1
                    }
                ),
            ));
        }
        (TransferKind::Pic | TransferKind::Tpic, None) => 0.0,
        (TransferKind::Flip | TransferKind::Tflip, None) => 1.0,
    })
}

/// The CFL factor of an explicit scene without `cfl` or `time_step`.
pub const DEFAULT_CFL: f64 = 0.5;

/// Steps between two counts of an explicit run's points per process on
/// several processes.
pub const DEFAULT_REBALANCE_EVERY: usize = 50;

/// The imbalance (most loaded process's points over the mean) past which
/// an explicit run on several processes deals its cells anew: 10 %, a
/// step's work being proportional to the points and the wait at the halo
/// to the largest.
pub const DEFAULT_REBALANCE_THRESHOLD: f64 = 1.1;

/// Outputs of an explicit scene without `output_interval` (besides the
/// initial state): `end_time / 20` apart.
pub const DEFAULT_OUTPUTS: usize = 20;
