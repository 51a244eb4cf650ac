//! One measured run of a 3D scene for the reproduction sections: a
//! quantity read from a reaction after every converged step, the Newton
//! residual histories, the counts, the wall time and the peak memory, or
//! why the run stopped.

use std::path::Path;

use anyhow::{Context, Result};
use mpm_cases::run::{RunControl, RunOutput};
use mpm_cases::scene::Problem;
use mpm_cases::scene::build::{ReactionOutput, SceneMesh};
use mpm_solver::StepReport;

use crate::machine::{measured, print_run};
use crate::plot::{Line, Marker, PALETTE, Series};

/// A finished (or stopped) run.
pub struct Run {
    /// What the run is, for tables and legends.
    pub label: String,
    /// `(0, 0)`, then one `(x, y)` per converged step.
    pub points: Vec<(f64, f64)>,
    /// The Newton residuals (eq. 40) of every converged step.
    pub residuals: Vec<Vec<f64>>,
    /// Elements of the mesh and material points.
    pub elements: usize,
    pub material_points: usize,
    /// Newton iterations in all and the most in one step.
    pub iterations: usize,
    pub max_iterations: usize,
    /// Steps repeated with a smaller increment.
    pub cuts: usize,
    /// Wall time (s) and peak resident memory (MB).
    pub seconds: f64,
    pub peak_mb: Option<f64>,
    /// Why the run stopped early.
    pub failure: Option<String>,
    /// Per converged step: Newton iterations, seconds, iterative-solver
    /// iterations.
    pub steps: Vec<(usize, f64, usize)>,
    /// The solver's stage times summed over the run.
    pub times: mpm_solver::StageTimes,
    /// Free dofs of the last step.
    pub free_dofs: usize,
}

impl Run {
    /// `(steps, cut)` or the steps and the failure, for a table cell.
    pub fn steps_cell(&self) -> String {
        match &self.failure {
            None => format!("{} ({})", self.points.len() - 1, self.cuts),
            Some(f) => format!("{} (then failed: {f})", self.points.len() - 1),
        }
    }

    /// `iterations (most)`, for a table cell.
    pub fn iterations_cell(&self) -> String {
        format!("{} ({})", self.iterations, self.max_iterations)
    }

    /// The peak memory, for a table cell.
    pub fn peak_cell(&self) -> String {
        self.peak_mb.map_or("–".to_owned(), |m| format!("{m:.0}"))
    }

    /// The last point's `y`.
    pub fn end(&self) -> f64 {
        self.points.last().map_or(f64::NAN, |p| p.1)
    }
}

/// Runs the scene `text` (named `file`, relative paths resolved in
/// `scenes/`) with `overrides`; after every converged step `point` maps the
/// problem, the reaction named `reaction` and the step's report to a point
/// of the curve.
pub fn run(
    text: &str,
    file: &str,
    overrides: &[String],
    label: String,
    reaction: &str,
    mut point: impl FnMut(&Problem<3>, &ReactionOutput<3>, &StepReport<3>) -> (f64, f64),
) -> Result<Run> {
    let (scene, src) = mpm_cases::scene::parse(text, file, overrides)
        .with_context(|| format!("parsing {file}"))?;
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let problem = Problem::<3>::build_in(&scene, &src, 0, &scenes)
        .with_context(|| format!("building {file}"))?;
    let on = problem
        .reactions
        .iter()
        .find(|r| r.name == reaction)
        .cloned()
        .with_context(|| format!("{file} has no `{reaction}` reaction"))?;
    let elements = match &problem.mesh {
        SceneMesh::Simplex(m) => m.element_count(),
        SceneMesh::Grid(_) => 0,
    };
    let mut run = Run {
        label,
        points: vec![(0.0, 0.0)],
        residuals: Vec::new(),
        elements,
        material_points: problem.len(),
        iterations: 0,
        max_iterations: 0,
        cuts: 0,
        seconds: 0.0,
        peak_mb: None,
        failure: None,
        steps: Vec::new(),
        times: mpm_solver::StageTimes::default(),
        free_dofs: 0,
    };
    // PETSc's solvers when xtask is built with them (`--features petsc`).
    let control = RunControl {
        external_linear: mpm_cases::distributed::external_linear(),
        ..RunControl::default()
    };
    let (result, seconds, peak): (Result<RunOutput<3>, _>, _, _) = measured(|| {
        mpm_cases::scene::run(&problem, &control, |_, report, _| {
            run.points.push(point(&problem, &on, report));
            run.residuals.push(report.residuals.clone());
            run.iterations += report.iterations();
            run.max_iterations = run.max_iterations.max(report.iterations());
            let t = &report.times;
            run.steps
                .push((report.iterations(), t.total(), report.linear_iterations));
            let c = &mut run.times;
            c.basis += t.basis;
            c.system += t.system;
            c.material += t.material;
            c.force += t.force;
            c.tangent += t.tangent;
            c.stiffness += t.stiffness;
            c.solve += t.solve;
            c.commit += t.commit;
            run.free_dofs = report.free_dofs;
            Ok(())
        })
    });
    (run.seconds, run.peak_mb) = (seconds, peak);
    match result {
        Ok(out) => run.cuts = out.summary.cut_steps,
        Err(e) => run.failure = Some(e.to_string()),
    }
    print_run(
        &format!("{file}, {}", run.label),
        run.points.len() - 1,
        run.iterations,
        run.seconds,
        run.failure.as_deref(),
    );
    Ok(run)
}

/// One solid line per run with its own colour and marker (the first
/// filled), for a figure of a few runs' curves.
pub fn series(runs: &[Run]) -> Vec<Series> {
    runs.iter()
        .enumerate()
        .map(|(i, r)| Series {
            label: r.label.clone(),
            points: r.points.clone(),
            color: PALETTE[i % PALETTE.len()],
            marker: Some(Marker::CYCLE[i % Marker::CYCLE.len()]),
            filled: i == 0,
            line: Line::Solid,
        })
        .collect()
}
