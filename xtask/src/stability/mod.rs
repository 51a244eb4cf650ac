//! `cargo xtask stability`: the stiff and extreme cases of issue 16 as a
//! matrix of scenario × variant, each cell a measured outcome — converged,
//! recovered by step cutting, refused with a typed error (which), failed,
//! or panicked — with the Newton iterations or time steps, the wall time,
//! and the error where a reference exists. Written to
//! `docs/src/reproduction/stability.md` and `stability.json` beside it.
//!
//! Every scenario states what it expects (converge, recover by cutting,
//! refuse with a named error, or only be measured); the quick matrix runs
//! in the test suite (`quick_matrix_meets_every_expectation`), which
//! fails on a panic, a non-finite number anywhere in a row, or an outcome
//! other than the expected one.

mod contact;
mod extreme;
mod rotation;
mod scenarios;
mod soil;

use std::fmt::Write as _;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use anyhow::Result;
use mpm_cases::CasesError;
use mpm_cases::session::Session;
use serde::Serialize;

use crate::markdown::Table;
use crate::{machine, write_file};

/// How large the matrix's problems are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Coarse levels: runs inside the test suite.
    Quick,
    /// The documented matrix.
    Full,
}

/// What a scenario must do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Expect {
    /// Converge, with or without cut steps.
    Converge,
    /// Converge after at least one cut step.
    Recover,
    /// Stop with a typed error whose kind contains this name.
    Refuse(&'static str),
    /// Anything but a panic: the outcome is the measurement.
    Measure,
}

/// What a run did.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Outcome {
    /// Reached the end without a cut step.
    Converged,
    /// Reached the end after `cuts` cut steps.
    Recovered { cuts: usize },
    /// Stopped with a typed error: its kind (variant path) and message.
    Error { error: String, message: String },
    /// Panicked: a defect.
    Panicked { message: String },
}

impl Outcome {
    /// The outcome of a run that returned `result`, read with `cuts`.
    fn of<T, E: std::fmt::Debug + std::fmt::Display>(
        result: std::thread::Result<Result<T, E>>,
        cuts: impl FnOnce(&T) -> usize,
    ) -> (Outcome, Option<T>) {
        match result {
            Ok(Ok(t)) => {
                let c = cuts(&t);
                let o = if c == 0 {
                    Outcome::Converged
                } else {
                    Outcome::Recovered { cuts: c }
                };
                (o, Some(t))
            }
            Ok(Err(e)) => (
                Outcome::Error {
                    error: error_kind(&format!("{e:?}")),
                    message: e.to_string(),
                },
                None,
            ),
            Err(payload) => (
                Outcome::Panicked {
                    message: panic_message(payload.as_ref()),
                },
                None,
            ),
        }
    }

    /// The table cell.
    fn cell(&self, expect: Expect) -> String {
        match self {
            Outcome::Converged => "converged".into(),
            Outcome::Recovered { cuts } => format!("recovered ({cuts} cut steps)"),
            Outcome::Error { error, .. } if matches!(expect, Expect::Refuse(_)) => {
                format!("refused: `{error}`")
            }
            Outcome::Error { error, .. } => format!("failed: `{error}`"),
            Outcome::Panicked { .. } => "**PANICKED**".into(),
        }
    }
}

/// The variant path of an error from its `Debug` text:
/// `Solver(StepTooSmall { .., cause: Constitutive { .. } })` gives
/// `Solver::StepTooSmall (cause Constitutive)`; a wrapped `source` is
/// named the same way.
pub fn error_kind(debug: &str) -> String {
    let ident = |s: &str| {
        let end = s
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(s.len());
        (s[..end].to_owned(), end)
    };
    let mut parts = Vec::new();
    let mut rest = debug;
    loop {
        let (name, end) = ident(rest);
        if name.is_empty() {
            break;
        }
        parts.push(name);
        match rest[end..].chars().next() {
            Some('(') => rest = &rest[end + 1..],
            _ => break,
        }
    }
    let mut kind = parts.join("::");
    for field in ["cause", "source"] {
        let key = format!("{field}: ");
        if let Some(at) = debug.find(&key) {
            let (inner, _) = ident(&debug[at + key.len()..]);
            if !inner.is_empty() {
                let _ = write!(kind, " ({field} {inner})");
            }
        }
    }
    kind
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "non-string panic payload".into())
}

/// Runs `f`, catching a panic.
pub fn guarded<T>(f: impl FnOnce() -> T) -> std::thread::Result<T> {
    catch_unwind(AssertUnwindSafe(f))
}

/// One cell of the matrix.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// The group of scenarios (a section of the page).
    pub family: &'static str,
    /// What is run.
    pub scenario: String,
    /// With which variant.
    pub variant: String,
    /// What it must do.
    pub expect: Expect,
    /// What it did.
    pub outcome: Outcome,
    /// Newton iterations, load steps, time steps.
    pub work: String,
    /// Wall time (s).
    pub seconds: f64,
    /// Error against the scenario's reference, where it has one.
    pub error: Option<f64>,
    /// What else was measured, in words.
    pub measured: String,
    /// Every number measured (checked finite).
    pub values: Vec<(String, f64)>,
}

impl Row {
    /// A row of `family` for `scenario` with `variant`, expecting `expect`,
    /// not yet run.
    pub fn new(
        family: &'static str,
        scenario: impl Into<String>,
        variant: impl Into<String>,
        expect: Expect,
    ) -> Self {
        Self {
            family,
            scenario: scenario.into(),
            variant: variant.into(),
            expect,
            outcome: Outcome::Converged,
            work: String::new(),
            seconds: 0.0,
            error: None,
            measured: String::new(),
            values: Vec::new(),
        }
    }

    /// Records a measured number (also checked finite).
    pub fn value(&mut self, name: &str, x: f64) {
        self.values.push((name.to_owned(), x));
    }

    /// Why the row does not meet its expectation, if it does not.
    pub fn defect(&self) -> Option<String> {
        let what = format!("{} / {} / {}", self.family, self.scenario, self.variant);
        if let Outcome::Panicked { message } = &self.outcome {
            return Some(format!("{what}: panicked: {message}"));
        }
        let numbers = self
            .values
            .iter()
            .map(|(n, x)| (n.as_str(), *x))
            .chain(self.error.map(|e| ("error", e)))
            .chain([("seconds", self.seconds)]);
        for (name, x) in numbers {
            if !x.is_finite() {
                return Some(format!("{what}: {name} = {x}"));
            }
        }
        match (self.expect, &self.outcome) {
            (Expect::Measure, _)
            | (Expect::Converge, Outcome::Converged | Outcome::Recovered { .. })
            | (Expect::Recover, Outcome::Recovered { .. }) => None,
            (Expect::Refuse(kind), Outcome::Error { error, .. }) if error.contains(kind) => None,
            (expect, outcome) => Some(format!("{what}: expected {expect:?}, got {outcome:?}")),
        }
    }
}

/// A temporary output directory, removed when dropped.
pub struct OutDir(pub PathBuf);

impl OutDir {
    /// A fresh, empty directory.
    pub fn new() -> Self {
        static COUNT: AtomicUsize = AtomicUsize::new(0);
        let n = COUNT.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("mpm-stability-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        Self(dir)
    }
}

impl Drop for OutDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A scene or case run through the `mpm` program's entry points.
pub struct SceneRun {
    /// What it did.
    pub outcome: Outcome,
    /// Wall time including output (s).
    pub seconds: f64,
    /// `summary.json`, when the run finished.
    pub summary: Option<serde_json::Value>,
    /// Its output directory.
    pub out: OutDir,
}

impl SceneRun {
    /// A number of `summary.json`.
    pub fn number(&self, key: &str) -> Option<f64> {
        self.summary.as_ref()?.get(key)?.as_f64()
    }

    /// `summary.json`'s value at a `/`-separated pointer.
    pub fn pointer(&self, pointer: &str) -> Option<f64> {
        self.summary.as_ref()?.pointer(pointer)?.as_f64()
    }

    /// Fills `row` with the outcome, the time and the work.
    pub fn fill(&self, row: &mut Row) {
        row.outcome = self.outcome.clone();
        row.seconds = self.seconds;
        if let Some(steps) = self.number("time_steps") {
            row.work = format!("{steps} time steps");
        } else if let (Some(steps), Some(it)) =
            (self.number("load_steps"), self.number("newton_iterations"))
        {
            row.work = format!("{steps} steps, {it} iterations");
        }
        row.error = self.number("error");
    }
}

/// The workspace's `scenes/` directory (relative mesh paths start there).
pub fn scenes_dir() -> PathBuf {
    crate::workspace_dir().join("scenes")
}

/// Runs the scene `text` (or the built-in `case` with the parameters
/// `text`) with the overrides `set`, writing to a fresh directory.
pub fn run_scene(text: &str, case: Option<&str>, set: &[String]) -> SceneRun {
    let out = OutDir::new();
    let session = Session {
        case: case.unwrap_or("scene").to_owned(),
        out: out.0.clone(),
        resume: false,
        stop_after: None,
        export_tangent: false,
        scene_dir: scenes_dir(),
        ranks: None,
    };
    let started = Instant::now();
    let result = guarded(|| -> Result<(), CasesError> {
        match case {
            None => mpm_cases::scene::run_file(text, "stability scene", set, &session),
            Some(name) => match mpm_cases::cases::find(name) {
                Some(c) => (c.run)(text, name, set, &session),
                None => Err(CasesError::Solver(mpm_solver::SolverError::InvalidInput(
                    format!("no case `{name}`"),
                ))),
            },
        }
    });
    let seconds = started.elapsed().as_secs_f64();
    let summary = std::fs::read_to_string(out.0.join("summary.json"))
        .ok()
        .and_then(|s| serde_json::from_str::<serde_json::Value>(&s).ok());
    let (mut outcome, _) = Outcome::of(result, |_| 0);
    if outcome == Outcome::Converged {
        let cuts = summary
            .as_ref()
            .and_then(|s| s.get("cut_steps")?.as_u64())
            .unwrap_or(0) as usize;
        if cuts > 0 {
            outcome = Outcome::Recovered { cuts };
        }
    }
    SceneRun {
        outcome,
        seconds,
        summary,
        out,
    }
}

/// Builds the scene `text` and runs it in memory (no output files),
/// filling `row`'s outcome, time and work; the run's output when it
/// finished.
pub fn run_problem<const D: usize>(
    text: &str,
    row: &mut Row,
) -> Option<mpm_cases::run::RunOutput<D>>
where
    mpm_cases::scene::Problem<D>: mpm_cases::scene::RunScene<D>,
{
    let started = Instant::now();
    let result = guarded(|| -> Result<_, CasesError> {
        let (scene, source) = mpm_cases::scene::parse(text, "stability scene", &[])?;
        let problem = mpm_cases::scene::Problem::<D>::build_in(
            &scene,
            &source,
            scene.solver.padding(),
            &scenes_dir(),
        )?;
        Ok(mpm_cases::scene::run(
            &problem,
            &mpm_cases::run::RunControl::default(),
            |_, _, _| Ok(()),
        )?)
    });
    row.seconds = started.elapsed().as_secs_f64();
    let (outcome, out) = Outcome::of(result, |o: &mpm_cases::run::RunOutput<D>| {
        o.summary.cut_steps
    });
    row.outcome = outcome;
    if let Some(o) = &out {
        row.work = format!(
            "{} steps, {} iterations",
            o.summary.steps, o.summary.iterations
        );
    }
    out
}

/// Checks that every output file of `dir` is whole: VTU and PVD files end
/// with their closing tag and a series names only files that exist, CSV
/// rows have the header's field count and finite numbers, JSON parses.
/// Returns the number of VTU files (0 when the run stopped before it
/// made the directory).
pub fn outputs_intact(dir: &Path) -> Result<usize, String> {
    if !dir.exists() {
        return Ok(0);
    }
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut vtu = 0;
    for entry in entries {
        let path = entry.map_err(|e| e.to_string())?.path();
        let name = path.display().to_string();
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !matches!(ext, "vtu" | "pvd" | "csv" | "json") {
            continue;
        }
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{name}: {e}"))?;
        match ext {
            "vtu" | "pvd" => {
                if !text.trim_end().ends_with("</VTKFile>") {
                    return Err(format!("{name}: no closing </VTKFile>"));
                }
                if ext == "vtu" {
                    vtu += 1;
                }
                for part in text.split("file=\"").skip(1) {
                    let file = part.split('"').next().unwrap_or("");
                    if !dir.join(file).exists() {
                        return Err(format!("{name}: names {file}, which does not exist"));
                    }
                }
            }
            "csv" => {
                let mut lines = text.lines();
                let fields = lines.next().map_or(0, |h| h.split(',').count());
                for (i, line) in lines.enumerate() {
                    let cells: Vec<&str> = line.split(',').collect();
                    if cells.len() != fields {
                        return Err(format!("{name}: line {} has {} fields", i + 2, cells.len()));
                    }
                    if let Some(bad) = cells
                        .iter()
                        .find(|c| c.parse::<f64>().is_ok_and(|x| !x.is_finite()))
                    {
                        return Err(format!("{name}: line {}: {bad}", i + 2));
                    }
                }
            }
            _ => {
                serde_json::from_str::<serde_json::Value>(&text)
                    .map_err(|e| format!("{name}: {e}"))?;
            }
        }
    }
    Ok(vtu)
}

/// Every scenario of the matrix.
pub fn matrix(mode: Mode) -> Vec<Row> {
    FAMILY_RUNS.iter().flat_map(|run| run(mode)).collect()
}

/// What builds each family's rows, in page order (the families are
/// independent: the test runs them side by side).
const FAMILY_RUNS: [fn(Mode) -> Vec<Row>; 10] = [
    scenarios::locking,
    scenarios::contrast,
    scenarios::step_size,
    rotation::rows,
    extreme::rows,
    soil::rows,
    scenarios::failures,
    scenarios::explicit,
    contact::rows,
    |_| scenarios::meshes(),
];

/// The families in page order, with their introductions.
const FAMILIES: [(&str, &str); 10] = [
    (
        "locking",
        "ν ∈ {0.3, 0.49, 0.4999} × locking treatment × formulation on the cases with references: the column (eq. 42 error against σ_zz = −ϱ₀g(l₀ − Z), which holds for any ν in uniaxial strain), Cook's membrane (small load, linear response; the tip displacement scaled to a load of 100) and the Prandtl footing (error = plateau pressure / ((2 + π)k) − 1). Cook's membrane and the footing run the previously converged formulation (`mpm_cases::locking`).",
    ),
    (
        "contrast",
        "Two layers with a stiffness contrast of 10⁶ (`scenes/two_layer_column.toml` with E = 10¹¹ and 10⁵ Pa). Error: the top displacement against the layer-by-layer closed form, relative to it.",
    ),
    (
        "step size",
        "Load steps 10× and 100× the nominal: automatic cutting (halving on failure, doubling back up to `max_increment`) must recover, and the result is compared with the nominal run. Error: the difference from the nominal run's top displacement, relative to it. The elasto-plastic collapse in 2× and 2.5× its 40 steps: standard MPM stops at λ = 0.95 in both, with every cut step failing down to the minimum increment (consistent with standard MPM's cell-crossing error, which GIMP was made to remove; not traced further), GIMP reaches λ = 1.",
    ),
    (
        "rotation",
        "A 360° rigid rotation: every node of a fixed regular grid prescribed with the rigid increment, so the body turns through the grid (GIMP with each domain rule, CPDI2, standard MPM, B-spline), and a triangle mesh turned by the moving mesh (`[mesh.motion] kind = \"rotation\"`, every node driven). Measured: the largest |V/V₀ − 1| of the points, the largest |σ|/E, the position error relative to the body size.",
    ),
    (
        "extreme",
        "Principal stretches 0.05 and 20 in the constitutive driver (stress finite, consistent tangents against finite differences: `mpm_constitutive::verification`) and in a one-cell case stretched or compressed by a moving mesh.",
    ),
    (
        "soil",
        "The soil laws (issue 43): the Mohr–Coulomb strip footing of `scenes/footing_mohr_coulomb.toml` (error: q/c against Prandtl–Reissner's N_c, 14.835 at φ = 20°, 2 + π at φ = 0, on a coarse grid) with φ → 0, associated against non-associated flow and 10× steps; a laterally confined block pulled apart to the apex in tension (error: the top traction against c cot φ); modified Cam-Clay's undrained triaxial cell (`scenes/triaxial_cam_clay.toml`) normally and very heavily (OCR = 1000) over-consolidated and in 10× steps, and a geostatic Cam-Clay column under a surface load of twice its base pressure in 5 steps and in 1.",
    ),
    (
        "failure",
        "Points driven out of the grid and elements inverted: a typed error naming the point and the step, and the outputs of the steps before it intact (every VTU, PVD, CSV and JSON file whole).",
    ),
    (
        "explicit",
        "The explicit solver: a fixed Δt at 1.5× and 3× the CFL limit (refused before the step, with the Courant number), a very soft / very stiff pair (E = 10³ and 10⁹ Pa: a stiffness contrast of 10⁶, each point stepping with its own wave speed) and a light / heavy pair (densities 10³ and 10⁻³: the same wave-speed contrast, one law), high-speed impacts (on a fixed wall, on a friction wall that lets the block go and books the friction and impact losses in the energy total, and on an absorbing wall whose dashpots slow the block but do not stop it).",
    ),
    (
        "contact",
        "Contact (issue 44): soft blocks at ±40 m/s meeting by multi-field contact, alike and against a block 10⁵ times stiffer (the energy drift with the contact's friction and impact losses booked), a block into a friction wall with and without the gap check on the boundary-modified B-splines (at ten times the wave speed a corner point crosses the wall and the run stops with a typed error: the trapezoidal position update moves a point by half its approach in the step the wall stops its nodes), and the refusal of a gap check with the B-splines that keep points a cell inside the grid (a block went through it before the refusal); the implicit solver's rigid platen of `scenes/platen_cube.toml` (error: the platen's force against E ln 0.99 on the unit face) with its penalty 10⁻³ and 10⁴ times the default, partial slip (a non-symmetric tangent, LU) and the whole stroke in one step.",
    ),
    (
        "mesh",
        "Degenerate Gmsh input (MSH 4.1): a zero-volume tetrahedron, a sliver, duplicated nodes.",
    ),
];

/// `cargo xtask stability [--quick]`.
pub fn run(docs: &Path, mode: Mode) -> Result<()> {
    let started = Instant::now();
    let rows = matrix(mode);
    let elapsed = started.elapsed().as_secs_f64();
    let defects: Vec<String> = rows.iter().filter_map(Row::defect).collect();
    let mut md = String::new();
    writeln!(
        md,
        "# Stability: stiff and extreme cases\n\n\
         Generated by `cargo xtask stability{}` on {} ({}); the matrix took {elapsed:.0} s. \
         Each row is one run with its measured outcome: *converged*, *recovered* (steps cut \
         and retried), *refused* with the typed error it was expected to raise, *failed* with \
         an unexpected typed error, or a panic (a defect). The error column is the run's error \
         against the scenario's reference where one exists. The test \
         `stability::tests::quick_matrix_meets_every_expectation` runs the quick matrix in \
         the suite and fails on a panic, a non-finite number or an unexpected outcome.\n",
        if mode == Mode::Quick { " --quick" } else { "" },
        machine::today(),
        machine::description()
    )?;
    writeln!(
        md,
        "**{} rows; {} panics; {} rows with a non-finite number; {} outcomes other than expected.**\n",
        rows.len(),
        rows.iter()
            .filter(|r| matches!(r.outcome, Outcome::Panicked { .. }))
            .count(),
        rows.iter()
            .filter(|r| r.values.iter().any(|v| !v.1.is_finite())
                || r.error.is_some_and(|e| !e.is_finite()))
            .count(),
        defects.len()
    )?;
    for d in &defects {
        writeln!(md, "- {d}")?;
    }
    for (family, intro) in FAMILIES {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.family == family).collect();
        if mine.is_empty() {
            continue;
        }
        writeln!(md, "## {}\n\n{intro}\n", capitalised(family))?;
        let mut t = Table::new([
            "scenario", "variant", "expected", "outcome", "work", "time (s)", "error", "measured",
        ]);
        for r in &mine {
            t.row(vec![
                r.scenario.clone(),
                r.variant.clone(),
                match r.expect {
                    Expect::Converge => "converge".into(),
                    Expect::Recover => "recover".into(),
                    Expect::Refuse(k) => format!("refuse (`{k}`)"),
                    Expect::Measure => "measure".into(),
                },
                r.outcome.cell(r.expect),
                r.work.clone(),
                format!("{:.2}", r.seconds),
                r.error.map_or("–".into(), |e| format!("{e:.3e}")),
                r.measured.clone(),
            ]);
        }
        md.push_str(&t.render());
        let messages: Vec<_> = mine
            .iter()
            .filter_map(|r| match &r.outcome {
                Outcome::Error { message, .. } | Outcome::Panicked { message } => {
                    Some((r, message))
                }
                _ => None,
            })
            .collect();
        if !messages.is_empty() {
            writeln!(md, "Diagnoses, as the runs reported them:\n")?;
            for (r, m) in messages {
                writeln!(md, "- {} / {}: «{}»", r.scenario, r.variant, m.trim())?;
            }
            writeln!(md)?;
        }
    }
    write_file(&docs.join("reproduction/stability.md"), md)?;
    write_file(
        &docs.join("reproduction/stability.json"),
        serde_json::to_string_pretty(&rows)?,
    )?;
    println!(
        "stability: {} rows, {} defects, {elapsed:.0} s",
        rows.len(),
        defects.len()
    );
    for d in &defects {
        println!("  {d}");
    }
    Ok(())
}

fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().collect::<String>() + c.as_str())
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn error_kinds_read_the_variant_path_and_the_cause() {
        assert_eq!(
            error_kind("Solver(StepTooSmall { step: 3, cause: Constitutive { point: 1 } })"),
            "Solver::StepTooSmall (cause Constitutive)"
        );
        assert_eq!(
            error_kind("Solver(CflExceeded { step: 1 })"),
            "Solver::CflExceeded"
        );
        assert_eq!(error_kind("Mesh(Parse { line: 4 })"), "Mesh::Parse");
        assert_eq!(
            error_kind("Solver(InStep { step: 7, source: Basis { point: 1 } })"),
            "Solver::InStep (source Basis)"
        );
    }

    #[test]
    fn a_row_with_a_nan_or_an_unexpected_outcome_is_a_defect() {
        let mut row = Row::new("x", "s", "v", Expect::Refuse("CflExceeded"));
        row.outcome = Outcome::Converged;
        assert!(row.defect().is_some());
        row.outcome = Outcome::Error {
            error: "Solver::CflExceeded".into(),
            message: String::new(),
        };
        assert!(row.defect().is_none());
        row.value("drift", f64::NAN);
        assert!(row.defect().is_some());
    }

    /// The quick matrix: no panic, no non-finite number, every outcome the
    /// expected one.
    #[test]
    fn quick_matrix_meets_every_expectation() {
        // The families side by side: the same rows as `matrix`, in a
        // fraction of the wall time of the test suite.
        let rows: Vec<Row> = FAMILY_RUNS
            .par_iter()
            .flat_map_iter(|run| run(Mode::Quick))
            .collect();
        let defects: Vec<String> = rows.iter().filter_map(Row::defect).collect();
        assert!(rows.len() > 40, "{} rows", rows.len());
        assert!(defects.is_empty(), "{}", defects.join("\n"));
    }
}
