//! A factor of safety by strength reduction (`[strength_reduction]`):
//! trials of the whole problem with its strength divided by a factor $F$,
//! each from the initial state, bisecting between the last factor that
//! held and the first that failed (Griffiths & Lane 1999).
//!
//! A trial fails when a load step does not converge after cutting to the
//! minimum increment, or when its points leave the mesh or cannot be
//! updated in a step (the soil has flowed); with `criterion =
//! "displacement"` also when a probe moved more than the limit. Each trial
//! is a row of `srf.csv`; `summary.json` gives the factor of safety (the
//! bracket's middle), the bracket and every trial; `mechanism.png` colours
//! the points by the displacement of the last converged step of the first
//! failed trial, where the mechanism is.

use std::time::Instant;

use serde_json::{Map, Value, json};

use mpm_scene::build::{Failure, StrengthReduction};
use mpm_solver::SolverError;

use crate::CasesError;
use crate::output::{CellMesh, CsvValue};
use crate::run::RunControl;
use crate::scene::Problem;
use crate::session::Session;

/// The search for the factor at failure: widen until a factor holds and
/// one fails, then bisect.
#[derive(Debug, Clone, PartialEq)]
pub struct Bracket {
    /// The largest factor that held.
    pub held: Option<f64>,
    /// The smallest factor that failed.
    pub failed: Option<f64>,
    first: (f64, f64),
    tried: usize,
    tolerance: f64,
    max_trials: usize,
}

impl Bracket {
    /// The search of `sr`.
    pub fn new(sr: &StrengthReduction) -> Self {
        Self {
            held: None,
            failed: None,
            first: (sr.lower, sr.upper),
            tried: 0,
            tolerance: sr.tolerance,
            max_trials: sr.max_trials,
        }
    }

    /// The next factor to try; `None` when the bracket is narrow enough or
    /// the trials are spent.
    pub fn next(&self) -> Option<f64> {
        if self.tried >= self.max_trials {
            return None;
        }
        let (lower, upper) = self.first;
        let width = upper - lower;
        match (self.held, self.failed) {
            (None, None) => Some(lower),
            (Some(h), None) if self.tried == 1 => Some(upper.max(h + width)),
            (Some(h), None) => Some(h + width),
            // Below the first factor: halve towards zero.
            (None, Some(f)) => Some((f - width).max(0.5 * f)),
            (Some(h), Some(f)) if f - h > self.tolerance => Some(0.5 * (h + f)),
            _ => None,
        }
    }

    /// Records that `factor` held or failed.
    pub fn record(&mut self, factor: f64, failed: bool) {
        self.tried += 1;
        if failed {
            self.failed = Some(self.failed.map_or(factor, |f| f.min(factor)));
        } else {
            self.held = Some(self.held.map_or(factor, |h| h.max(factor)));
        }
    }

    /// The bracket `(held, failed)` once both are known.
    pub fn bounds(&self) -> Option<(f64, f64)> {
        self.held.zip(self.failed)
    }
}

/// What one trial did.
#[derive(Debug, Clone)]
struct Trial {
    factor: f64,
    /// Why it failed (`None`: it held).
    failure: Option<String>,
    /// The load factor reached.
    load_factor: f64,
    /// The watched probe's displacement magnitude at the end (the first
    /// probe's without a displacement criterion; 0 without probes).
    displacement: f64,
    steps: usize,
    iterations: usize,
    wall_time_s: f64,
    /// The last converged step's points and their displacement in it.
    mechanism: Option<Mechanism>,
}

/// The last converged step's points and the displacement in that step.
#[derive(Debug, Clone)]
struct Mechanism {
    position: Vec<[f64; 3]>,
    volume: Vec<f64>,
    step_displacement: Vec<f64>,
}

/// Whether `e` says the trial's soil could not carry its load (rather
/// than that the scene or the output is wrong).
fn is_failure(e: &SolverError) -> bool {
    matches!(
        e,
        SolverError::StepTooSmall { .. } | SolverError::InStep { .. } | SolverError::Basis { .. }
    )
}

/// `|a - b|` of padded 3D displacements.
fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Runs the trial at `factor`.
fn trial<const D: usize>(
    problem: &Problem<D>,
    sr: &StrengthReduction,
    factor: f64,
) -> Result<Trial, CasesError>
where
    Problem<D>: crate::scene::RunScene<D>,
{
    let probe = match sr.failure {
        Failure::Displacement { probe, .. } => problem.probes.get(probe),
        Failure::Convergence => problem.probes.first(),
    }
    .map(|(_, p)| *p);
    let reduced = problem.with_reduced_strength(factor);
    let control = RunControl {
        external_linear: mpm_distributed::external_linear(),
        ..RunControl::default()
    };
    let start = Instant::now();
    // The last two converged steps' displacements; the last step's points.
    let mut displaced: [Vec<[f64; 3]>; 2] = [Vec::new(), Vec::new()];
    let mut points: Option<(Vec<[f64; 3]>, Vec<f64>)> = None;
    let mut load_factor = 0.0;
    let (mut steps, mut iterations) = (0, 0);
    let result = crate::scene::run(&reduced, &control, |_, report, snap| {
        steps += 1;
        iterations += report.iterations();
        load_factor = report.lambda1;
        displaced.swap(0, 1);
        displaced[1].clone_from(&snap.displacement);
        let (position, volume) = points.get_or_insert_with(Default::default);
        position.clone_from(&snap.position);
        volume.clone_from(&snap.volume);
        Ok(())
    });
    let [before, last] = displaced;
    let displacement = probe.map_or(0.0, |p| last.get(p).map_or(0.0, |u| distance(u, &[0.0; 3])));
    let failure = match &result {
        Ok(_) => match sr.failure {
            Failure::Displacement { limit, .. } if displacement > limit => Some(format!(
                "the probe moved {displacement:.4e} m > {limit:e} m"
            )),
            _ => None,
        },
        Err(e) if is_failure(e) => Some(e.to_string()),
        Err(e) => return Err(e.clone().into()),
    };
    let mechanism = points.map(|(position, volume)| Mechanism {
        position,
        volume,
        step_displacement: last
            .iter()
            .enumerate()
            .map(|(p, u)| distance(u, before.get(p).unwrap_or(&[0.0; 3])))
            .collect(),
    });
    Ok(Trial {
        factor,
        displacement,
        load_factor,
        failure,
        steps,
        iterations,
        wall_time_s: start.elapsed().as_secs_f64(),
        mechanism,
    })
}

/// Runs the trials of `problem`'s `[strength_reduction]` with the outputs
/// of `session` on `mesh` (module docs).
///
/// # Errors
/// A trial's error other than a failure of the soil (module docs);
/// output errors; a search that finds no factor that holds or none that
/// fails within the trials.
pub(super) fn run<const D: usize, M: CellMesh<D>>(
    scene: &crate::scene::Scene,
    problem: &Problem<D>,
    session: &Session,
    mesh: M,
    sr: &StrengthReduction,
) -> Result<(), CasesError>
where
    Problem<D>: crate::scene::RunScene<D>,
{
    let (mut obs, _) = session.start(scene, mesh)?;
    let start = Instant::now();
    let mut bracket = Bracket::new(sr);
    let mut trials: Vec<Trial> = Vec::new();
    while let Some(factor) = bracket.next() {
        let t = trial(problem, sr, factor)?;
        eprintln!(
            "strength reduction: F = {factor:.5}: {} ({} steps, load factor {:.4}, {:.2} s)",
            t.failure.as_deref().unwrap_or("held"),
            t.steps,
            t.load_factor,
            t.wall_time_s
        );
        write_row(&mut obs.writer, &t)?;
        bracket.record(factor, t.failure.is_some());
        trials.push(t);
    }
    let Some((held, failed)) = bracket.bounds() else {
        return Err(CasesError::NoBracket {
            held: bracket.held,
            failed: bracket.failed,
            trials: trials.len(),
        });
    };
    let mut results = Map::new();
    results.insert(
        "strength_reduction".into(),
        json!({
            "factor_of_safety": 0.5 * (held + failed),
            "last_held": held,
            "first_failed": failed,
            "criterion": criterion_name(sr),
            "trials": trials.iter().map(trial_json).collect::<Vec<_>>(),
        }),
    );
    let first_failed = trials.iter().find(|t| t.factor == failed);
    if let Some(m) = first_failed.and_then(|t| t.mechanism.as_ref()) {
        results.insert("mechanism".into(), mechanism_json(problem, m));
        results.insert(
            "mechanism_png".into(),
            write_mechanism(problem, m, obs.dir())?,
        );
    }
    println!(
        "strength reduction: factor of safety {:.4} (held at {held:.4}, failed at {failed:.4}; {} trials, {:.2} s)",
        0.5 * (held + failed),
        trials.len(),
        start.elapsed().as_secs_f64()
    );
    obs.finish(summary(problem, &trials, start, results, scene))
}

fn criterion_name(sr: &StrengthReduction) -> &'static str {
    match sr.failure {
        Failure::Convergence => "convergence",
        Failure::Displacement { .. } => "displacement",
    }
}

fn trial_json(t: &Trial) -> Value {
    json!({
        "factor": t.factor,
        "held": t.failure.is_none(),
        "failure": t.failure,
        "load_factor": t.load_factor,
        "displacement": t.displacement,
        "wall_time_s": t.wall_time_s,
    })
}

/// A row of `srf.csv`.
fn write_row<const D: usize, M: CellMesh<D>>(
    writer: &mut crate::writer::RunWriter<D, M>,
    t: &Trial,
) -> Result<(), CasesError> {
    let header = [
        "factor",
        "held",
        "load_factor",
        "probe_displacement",
        "steps",
        "newton_iterations",
        "wall_time_s",
        "failure",
    ];
    let row = [
        CsvValue::from(t.factor),
        CsvValue::from(u64::from(t.failure.is_none())),
        CsvValue::from(t.load_factor),
        CsvValue::from(t.displacement),
        CsvValue::from(t.steps),
        CsvValue::from(t.iterations),
        CsvValue::from(t.wall_time_s),
        CsvValue::from(t.failure.clone().unwrap_or_default()),
    ];
    writer.case_row("srf.csv", &header, &row)
}

/// The largest displacement in the mechanism's step, and each probe's
/// as a fraction of it: where the mechanism is.
fn mechanism_json<const D: usize>(problem: &Problem<D>, m: &Mechanism) -> Value {
    let max = m.step_displacement.iter().copied().fold(0.0, f64::max);
    let probes: Map<String, Value> = problem
        .probes
        .iter()
        .map(|(name, p)| {
            let share = if max > 0.0 {
                m.step_displacement[*p] / max
            } else {
                0.0
            };
            (name.clone(), json!(share))
        })
        .collect();
    json!({"step_displacement_max": max, "probe_share": probes})
}

/// `mechanism.png`: the points of the first failed trial's last converged
/// step coloured by their displacement in that step.
fn write_mechanism<const D: usize>(
    problem: &Problem<D>,
    m: &Mechanism,
    dir: &std::path::Path,
) -> Result<Value, CasesError> {
    super::program::points_png(
        problem,
        "mechanism.png",
        "step_displacement",
        (&m.position, &m.volume),
        &m.step_displacement,
        dir,
    )
}

/// `summary.json` over all trials.
fn summary<'s, const D: usize>(
    problem: &Problem<D>,
    trials: &[Trial],
    start: Instant,
    results: Map<String, Value>,
    scene: &'s crate::scene::Scene,
) -> crate::writer::Summary<&'s crate::scene::Scene> {
    crate::writer::Summary {
        case: "scene".into(),
        variant: problem.variant.resolved(),
        material_points: problem.len(),
        load_steps: trials.iter().map(|t| t.steps).sum(),
        cut_steps: 0,
        newton_iterations: trials.iter().map(|t| t.iterations).sum(),
        wall_time_s: start.elapsed().as_secs_f64(),
        error: None,
        results,
        parameters: scene,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn search(lower: f64, upper: f64) -> Bracket {
        Bracket::new(&StrengthReduction {
            lower,
            upper,
            tolerance: 0.01,
            failure: Failure::Convergence,
            max_trials: 40,
        })
    }

    /// Runs the search against a problem failing above `fos`.
    fn find(mut b: Bracket, fos: f64) -> (Bracket, usize) {
        let mut n = 0;
        while let Some(f) = b.next() {
            b.record(f, f > fos);
            n += 1;
        }
        (b, n)
    }

    #[test]
    fn the_bracket_closes_on_the_factor_within_the_tolerance() {
        for fos in [0.37, 1.0, 1.4, 1.999, 2.0, 7.3] {
            let (b, n) = find(search(1.0, 2.0), fos);
            let (h, f) = b.bounds().expect("bracketed");
            assert!(h <= fos && fos < f && f - h <= 0.01, "{fos}: [{h}, {f}]");
            assert!(n <= 20, "{fos}: {n} trials");
        }
    }

    #[test]
    fn a_search_out_of_trials_has_no_bracket() {
        let mut b = search(1.0, 2.0);
        b.max_trials = 3;
        let (b, n) = find(b, 100.0);
        assert_eq!((n, b.bounds()), (3, None));
    }
}
