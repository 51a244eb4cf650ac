//! Committed regression values (CONVENTIONS rule 7, after fenris): reruns
//! every run recorded in `tests/reference_values/<case>.json` (column,
//! cantilever, collapse, annulus, stretch) with exactly its recorded
//! settings, through the public API of `mpm-cases`, and compares what it
//! measures with the committed values. Each file names its source (the
//! commit that computed the values; the paper's or the analytic values
//! stand beside them for comparison and are not asserted here — the
//! paper-reproduction tests `coombs2020.rs`, `collapse.rs`, ... do that).
//! The files are written by `cargo run --release -p xtask -- reference-values`;
//! regenerate them only when a change moves a number on purpose, so that
//! the move shows in review as a diff of the JSON.
//!
//! Run time: 16 s in release on 2 cores (AMD EPYC), build excluded
//! (`cargo test --release -p mpm-cases --test suite regression`; the five cases
//! run in parallel on the harness's two threads: column 8.5 s, cantilever
//! 7.5 s, collapse 10.5 s, annulus 1.4 s, stretch 3.4 s, each slowed by
//! sharing the cores); 25 to 27 s while another build used the machine.
//!
//! # Tolerances
//! - Values (errors, extents, heights, tip displacements, stresses):
//!   `|measured − recorded| <= 1e-6 |recorded|`. A rerun repeats the same
//!   Newton iterations, so the values move only with the round-off of the
//!   converged state (other processors, SIMD paths, compilers): UL and PC,
//!   which solve the same equations with different arithmetic, differ by
//!   at most 2e-11 relative in the column and annulus errors and 2.5e-10
//!   in the cantilever tip, so 1e-6 is more than three orders above
//!   round-off.
//! - The stretch `error` only: an absolute floor of 1e-10 added (see
//!   [`STRETCH_ERROR_FLOOR`]); with the predictor the homogeneous state is
//!   an exact discrete equilibrium, so that error is round-off itself.
//! - Counts (points, elements, steps, step cuts, Newton iterations): exact.
//! - Residual histories: the iterations of each recorded step exactly, the
//!   iteration-0 unbalance within 1e-6 relative, each residual within
//!   `1e-6 |recorded| + 1e-3 × tolerance` (see [`residual_floor`]).
//!
//! A failure lists every value that moved, naming the case, the run, its
//! settings and both values.
#![allow(clippy::unwrap_used)]

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

use mpm_cases::cases::Solve;
use mpm_cases::cases::annulus::{self, AnnulusParams};
use mpm_cases::cases::cantilever::{self, CantileverParams};
use mpm_cases::cases::collapse::{self, CollapseParams};
use mpm_cases::cases::column::{self, ColumnParams};
use mpm_cases::cases::stretch::{self, StretchParams};
use mpm_cases::run::{RunControl, RunOutput};
use serde::Deserialize;
use serde_json::Value;

/// One case's file (fields the test does not use, such as `study` and
/// `comparison`, are ignored).
#[derive(Debug, Deserialize)]
struct CaseFile {
    case: String,
    source: String,
    runs: Vec<Run>,
}

#[derive(Debug, Deserialize)]
struct Run {
    name: String,
    settings: Value,
    values: BTreeMap<String, f64>,
    counts: BTreeMap<String, usize>,
    #[serde(default)]
    histories: Vec<History>,
}

#[derive(Debug, Deserialize)]
struct History {
    /// Load step, from 1.
    step: usize,
    iterations: usize,
    initial_unbalance: Option<f64>,
    residuals: Vec<f64>,
}

/// What a rerun measured.
struct Measured {
    values: BTreeMap<&'static str, f64>,
    counts: BTreeMap<&'static str, usize>,
    /// Per load step: eq. (40) per iteration and the iteration-0 unbalance.
    steps: Vec<(Vec<f64>, Option<f64>)>,
}

impl Measured {
    fn of<const D: usize>(
        output: &RunOutput<D>,
        material_points: usize,
        values: impl IntoIterator<Item = (&'static str, f64)>,
    ) -> Self {
        Self {
            values: values.into_iter().collect(),
            counts: BTreeMap::from([
                ("material_points", material_points),
                ("steps", output.summary.steps),
                ("cut_steps", output.summary.cut_steps),
                ("iterations", output.summary.iterations),
            ]),
            steps: output
                .reports
                .iter()
                .map(|r| (r.residuals.clone(), r.initial_unbalance))
                .collect(),
        }
    }
}

/// `|measured − recorded| <= relative |recorded| + absolute`.
#[derive(Debug, Clone, Copy)]
struct Tolerance {
    relative: f64,
    absolute: f64,
}

/// The tolerance of every recorded value that is not round-off.
const RELATIVE: Tolerance = Tolerance {
    relative: 1e-6,
    absolute: 0.0,
};

/// Absolute floor of the stretch `error` (Wang 2021 Table 1 set-up), on top
/// of [`RELATIVE`]. With the predictor every point carries the analytic
/// stress up to round-off, so the recorded errors are round-off
/// themselves: 3.3e-11 to 6.7e-11 (2.8e-15 on the elastic Gmsh cube),
/// i.e. τ_yy off τ_a by a few 1e-8 Pa after five steps of return mapping.
/// A different summation order or SIMD path may change such a value by its
/// own size, which no relative tolerance survives; 1e-10 lies above the
/// largest of them (so round-off cannot fail the test) and ten times below
/// the 1e-9 bound of `tests/stretch.rs` (so a state that stops being
/// homogeneous at the level that test would catch fails here too). The
/// run without the predictor is homogeneous too since 2026-12-05 (the
/// first solve of a step takes the tangent of continued loading; before,
/// it necked with an error of 0.54).
const STRETCH_ERROR_FLOOR: f64 = 1e-10;

/// Absolute floor of the residual comparisons: `1e-3 × tolerance` (1e-12
/// for the recorded tolerance 1e-9). Residuals below the tolerance come
/// from the round-off of the last iterates: the final ones (1e-15 to 1e-13)
/// are pure round-off and differ between UL and PC by up to 25 % relative;
/// the quadratic-regime ones just below the tolerance (e.g. 4.1e-10 =
/// C r² in the GIMP cantilever's step 10) differ by 1e-15, beyond 1e-6
/// relative. The largest UL–PC difference of any recorded residual below
/// 1e-6 is 3e-14; the floor is thirty times that, and three orders below
/// the tolerance at which convergence — and so the iteration count,
/// compared exactly — is decided. Larger residuals are compared at 1e-6
/// relative (UL and PC differ there by 9e-8 relative at most, and in the
/// iteration-0 unbalance by 1e-8).
fn residual_floor(newton_tolerance: f64) -> Tolerance {
    Tolerance {
        relative: 1e-6,
        absolute: 1e-3 * newton_tolerance,
    }
}

impl Tolerance {
    fn accepts(self, measured: f64, recorded: f64) -> bool {
        (measured - recorded).abs() <= self.relative * recorded.abs() + self.absolute
    }
}

impl fmt::Display for Tolerance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.1e} relative", self.relative)?;
        if self.absolute > 0.0 {
            write!(f, " + {:.1e} absolute", self.absolute)?;
        }
        Ok(())
    }
}

/// The workspace root: mesh paths in the settings are relative to it.
fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `mesh`, taken from the workspace root when relative.
fn resolve(mesh: &mut Option<PathBuf>) {
    if let Some(m) = mesh.as_mut()
        && m.is_relative()
    {
        *m = workspace().join(&*m);
    }
}

fn load(case: &str) -> CaseFile {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/reference_values")
        .join(format!("{case}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (written by `cargo run --release -p xtask -- reference-values`)",
            path.display()
        )
    });
    let file: CaseFile = serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("{}: not a reference-values file: {e}", path.display()));
    assert_eq!(file.case, case, "{}", path.display());
    assert!(!file.runs.is_empty(), "{}: no runs", path.display());
    file
}

fn params<T: for<'de> Deserialize<'de>>(settings: &Value) -> Result<T, String> {
    serde_json::from_value(settings.clone()).map_err(|e| format!("bad settings: {e}"))
}

fn differ(measured: f64, recorded: f64) -> String {
    let d = measured - recorded;
    format!(
        "measured {measured:e}, recorded {recorded:e} (difference {d:.3e}, {:.3e} relative)",
        d / recorded.abs()
    )
}

/// Reruns every run of `case` with `measure` and compares; panics with
/// every difference.
fn check_case(
    case: &str,
    measure: impl Fn(&Value) -> Result<Measured, String>,
    tolerance: impl Fn(&str) -> Tolerance,
) {
    let started = Instant::now();
    let file = load(case);
    let mut failures: Vec<String> = Vec::new();
    let mut checked = 0usize;
    for run in &file.runs {
        let fail = |what: String| {
            format!(
                "{case}: run `{}`\n    settings {}\n    {what}",
                run.name,
                serde_json::to_string(&run.settings).unwrap_or_default()
            )
        };
        let m = match measure(&run.settings) {
            Ok(m) => m,
            Err(e) => {
                failures.push(fail(format!("the run failed: {e}")));
                continue;
            }
        };
        for (key, &recorded) in &run.values {
            checked += 1;
            match m.values.get(key.as_str()) {
                None => failures.push(fail(format!("`{key}` is recorded but not measured"))),
                Some(&measured) => {
                    let t = tolerance(key);
                    if !t.accepts(measured, recorded) {
                        failures.push(fail(format!(
                            "{key}: {} — allowed {t}",
                            differ(measured, recorded)
                        )));
                    }
                }
            }
        }
        for (key, &recorded) in &run.counts {
            checked += 1;
            match m.counts.get(key.as_str()) {
                None => failures.push(fail(format!("`{key}` is recorded but not measured"))),
                Some(&measured) if measured != recorded => failures.push(fail(format!(
                    "{key}: measured {measured}, recorded {recorded} (compared exactly)"
                ))),
                Some(_) => {}
            }
        }
        let unrecorded: Vec<&str> = m
            .values
            .keys()
            .chain(m.counts.keys())
            .filter(|k| !run.values.contains_key(**k) && !run.counts.contains_key(**k))
            .copied()
            .collect();
        if !unrecorded.is_empty() {
            failures.push(fail(format!(
                "measured but not recorded: {} (regenerate the file)",
                unrecorded.join(", ")
            )));
        }
        let newton_tolerance = run.settings["tolerance"].as_f64().unwrap_or(f64::NAN);
        let floor = residual_floor(newton_tolerance);
        for h in &run.histories {
            let Some((residuals, unbalance)) = h.step.checked_sub(1).and_then(|i| m.steps.get(i))
            else {
                failures.push(fail(format!(
                    "step {}: recorded, but the run has {} steps",
                    h.step,
                    m.steps.len()
                )));
                continue;
            };
            checked += 1 + h.residuals.len();
            let iterations = residuals.len().saturating_sub(1);
            if iterations != h.iterations || h.residuals.len() != h.iterations + 1 {
                failures.push(fail(format!(
                    "step {}: {iterations} Newton iterations, recorded {} (compared exactly)\n    measured residuals {residuals:?}\n    recorded residuals {:?}",
                    h.step, h.iterations, h.residuals
                )));
                continue;
            }
            for (i, (&measured, &recorded)) in residuals.iter().zip(&h.residuals).enumerate() {
                if !floor.accepts(measured, recorded) {
                    failures.push(fail(format!(
                        "step {}, residual of iteration {i}: {} — allowed {floor}",
                        h.step,
                        differ(measured, recorded)
                    )));
                }
            }
            match (*unbalance, h.initial_unbalance) {
                (None, None) => {}
                (Some(measured), Some(recorded)) if RELATIVE.accepts(measured, recorded) => {}
                (measured, recorded) => failures.push(fail(format!(
                    "step {}, iteration-0 unbalance: measured {measured:?}, recorded {recorded:?} — allowed {RELATIVE}",
                    h.step
                ))),
            }
        }
    }
    println!(
        "{case}: {} runs, {checked} recorded values, {} moved, {:.1} s ({})",
        file.runs.len(),
        failures.len(),
        started.elapsed().as_secs_f64(),
        file.source
    );
    assert!(
        failures.is_empty(),
        "{} recorded value(s) of `{case}` moved (values {}; regenerate with \
         `cargo run --release -p xtask -- reference-values` only if the change is meant):\n{}",
        failures.len(),
        file.source,
        failures.join("\n")
    );
}

#[test]
fn column_errors_per_variant_and_level() {
    check_case(
        "column",
        |settings| {
            let p: ColumnParams = params(settings)?;
            let r =
                column::ColumnCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| Ok(()))
                    .map_err(|e| e.to_string())?;
            Ok(Measured::of(
                &r.output,
                r.material_points,
                [("error", r.error)],
            ))
        },
        |_| RELATIVE,
    );
}

#[test]
fn cantilever_tip_and_table3_residuals() {
    check_case(
        "cantilever",
        |settings| {
            let p: CantileverParams = params(settings)?;
            let r = cantilever::CantileverCase::run(
                &p,
                &p.variant(),
                &RunControl::default(),
                |_, _, _| Ok(()),
            )
            .map_err(|e| e.to_string())?;
            let &(_, u, v) = r.tip.last().ok_or("no load step")?;
            Ok(Measured::of(
                &r.output,
                r.material_points,
                [("tip_u", u), ("tip_v", v)],
            ))
        },
        |_| RELATIVE,
    );
}

#[test]
fn collapse_tables_6_7_8() {
    check_case(
        "collapse",
        |settings| {
            let p: CollapseParams = params(settings)?;
            let r =
                collapse::CollapseCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| {
                    Ok(())
                })
                .map_err(|e| e.to_string())?;
            Ok(Measured::of(
                &r.output,
                r.material_points,
                [
                    ("horizontal_extent", r.horizontal_extent),
                    ("max_height", r.max_height),
                ],
            ))
        },
        |_| RELATIVE,
    );
}

#[test]
fn annulus_errors_on_the_committed_meshes() {
    check_case(
        "annulus",
        |settings| {
            let mut p: AnnulusParams = params(settings)?;
            resolve(&mut p.mesh);
            let r =
                annulus::AnnulusCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| {
                    Ok(())
                })
                .map_err(|e| e.to_string())?;
            let mut m = Measured::of(
                &r.output,
                r.material_points,
                [
                    ("error", r.error),
                    ("max_error", r.max_error),
                    ("element_size", r.element_size),
                ],
            );
            m.counts.insert("elements", r.elements);
            Ok(m)
        },
        |_| RELATIVE,
    );
}

#[test]
fn stretch_table1_errors() {
    check_case(
        "stretch",
        |settings| {
            let mut p: StretchParams = params(settings)?;
            resolve(&mut p.mesh);
            let r =
                stretch::StretchCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| {
                    Ok(())
                })
                .map_err(|e| e.to_string())?;
            let mut m = Measured::of(
                &r.output,
                r.material_points,
                [
                    ("error", r.error),
                    ("analytic_stress", r.analytic_stress),
                    ("tau_yy_mean", r.tau_yy.0),
                    ("tau_yy_min", r.tau_yy.1),
                    ("tau_yy_max", r.tau_yy.2),
                ],
            );
            m.counts.insert("elements", r.elements);
            Ok(m)
        },
        |key| match key {
            "error" => Tolerance {
                absolute: STRETCH_ERROR_FLOOR,
                ..RELATIVE
            },
            _ => RELATIVE,
        },
    );
}
