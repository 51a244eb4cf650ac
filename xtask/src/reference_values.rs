//! `reference-values`: runs the benchmark cases through the public API of
//! `mpm-cases` and writes the committed regression values
//! `crates/mpm-cases/tests/reference_values/<case>.json`, one file per case
//! (column, cantilever, collapse, annulus, stretch), which
//! `crates/mpm-cases/tests/regression.rs` reruns with exactly the recorded
//! settings and compares (CONVENTIONS rule 7, after fenris: a separate
//! test target, in release, whose measured values are compared with
//! committed ones).
//!
//! Every file records
//! - `source`: what the values are — computed by this code at a commit —
//!   and `reference`: the case and the paper, with where the paper's (or
//!   the analytic) values for comparison stand;
//! - per run, `settings`: the case's parameters with the variant, as a
//!   scene file would give them (mesh paths relative to the workspace
//!   root), from which the test rebuilds the run;
//! - `values` (floating point: compared relatively), `counts` (points,
//!   steps, step cuts, Newton iterations: compared exactly) and, for chosen
//!   load steps, `histories` of the normalised residual (eq. 40) per Newton
//!   iteration with the iteration-0 unbalance;
//! - where the literature or an analytic solution has the same quantity,
//!   `comparison` with its source (informative; the test does not use it).
//!
//! The runs are the settings of the existing tests (`tests/column.rs`,
//! `coombs2020.rs`, `cantilever.rs`, `collapse.rs`, `annulus.rs`,
//! `stretch.rs`), coarse enough that the whole regression test stays
//! under a minute in release on 2 cores. Regenerate only when a change
//! moves a number on purpose: the diff of the JSON then shows which.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, anyhow};
use mpm_cases::cases::Solve;
use mpm_cases::cases::annulus::{self, AnnulusParams};
use mpm_cases::cases::cantilever::{self, CantileverParams, elastica_tip};
use mpm_cases::cases::collapse::{self, CollapseParams};
use mpm_cases::cases::column::{self, ColumnParams};
use mpm_cases::cases::stretch::{self, StretchParams};
use mpm_cases::run::{RunControl, RunOutput};
use mpm_cases::variant::{BasisKind, DomainUpdateKind, FormulationKind, Variant};
use serde::Serialize;
use serde_json::Value;

use crate::coombs2020::paper;
use crate::coombs2020::variants::{GIMP_RULES, cpdi2, gimp, gimp_domain_volume, linear, variant};
use crate::wang2021::TABLE_1;
use crate::write_file;

/// The column's refinement levels, h = 50/2^k: the range of
/// `tests/coombs2020.rs` (the paper's Fig. 7 range, k = 2..7, and two more
/// levels where the stall of the rules without a consistent update shows).
const COLUMN_LEVELS: std::ops::RangeInclusive<i32> = 2..=9;

/// The cantilever's load steps whose residuals are recorded (1-based):
/// those of Table 3, which `tests/cantilever.rs` prints.
const TABLE_3_STEPS: [usize; 5] = [10, 20, 40, 49, 50];

/// The collapse's load steps whose residuals are recorded: Table 8's.
const TABLE_8_STEPS: [usize; 4] = [10, 20, 30, 40];

/// Where the files go, from the workspace root.
const OUT_DIR: &str = "crates/mpm-cases/tests/reference_values";

/// The command that writes the files.
const COMMAND: &str = "cargo run --release -p xtask -- reference-values";

/// The test that reads them.
const TEST: &str = "crates/mpm-cases/tests/regression.rs (cargo test --release -p mpm-cases --test suite regression)";

/// One case's file.
#[derive(Debug, Serialize)]
struct CaseFile {
    case: &'static str,
    source: String,
    reference: String,
    generated_by: &'static str,
    checked_by: &'static str,
    notes: Vec<String>,
    runs: Vec<Run>,
}

/// One run: its settings and what it measured.
#[derive(Debug, Serialize)]
struct Run {
    name: String,
    /// The test or study whose settings these are.
    study: String,
    settings: Value,
    values: BTreeMap<&'static str, f64>,
    counts: BTreeMap<&'static str, usize>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    histories: Vec<History>,
    #[serde(skip_serializing_if = "Option::is_none")]
    comparison: Option<Comparison>,
}

/// Values of the literature or of an analytic solution for a run.
#[derive(Debug, Serialize)]
struct Comparison {
    source: String,
    values: BTreeMap<&'static str, f64>,
}

/// The Newton residuals of one load step.
#[derive(Debug, Serialize)]
struct History {
    /// Load step, counted from 1 as in the paper.
    step: usize,
    /// Newton iterations (linear solves) of the step.
    iterations: usize,
    /// Out-of-balance force at iteration 0 over every dof before the
    /// reactions are known (`StepReport::initial_unbalance`, the paper's
    /// iteration-0 row).
    #[serde(skip_serializing_if = "Option::is_none")]
    initial_unbalance: Option<f64>,
    /// Eq. (40) at iterations 0, 1, ...
    residuals: Vec<f64>,
    /// The paper's row for this step (its iteration 0 is the
    /// `initial_unbalance` measure), where it has one for these settings.
    #[serde(skip_serializing_if = "Option::is_none")]
    paper_residuals: Option<Vec<f64>>,
}

/// Writes every case's file under the workspace root.
pub fn run(workspace: &Path) -> Result<()> {
    let started = Instant::now();
    let source = source(workspace);
    println!("{source}");
    let dir = workspace.join(OUT_DIR);
    let mut solver_time = 0.0;
    for (case, build) in [
        ("column", column_file as fn(&Path, &mut f64) -> Result<_>),
        ("cantilever", cantilever_file),
        ("collapse", collapse_file),
        ("annulus", annulus_file),
        ("stretch", stretch_file),
    ] {
        let case_started = Instant::now();
        let mut time = 0.0;
        let (reference, notes, runs) =
            build(workspace, &mut time).with_context(|| format!("case {case}"))?;
        let file = CaseFile {
            case,
            source: source.clone(),
            reference,
            generated_by: COMMAND,
            checked_by: TEST,
            notes,
            runs,
        };
        let path = dir.join(format!("{case}.json"));
        let json = serde_json::to_string_pretty(&file)?;
        write_file(&path, json + "\n")?;
        println!(
            "wrote {} ({} runs, solver {time:.2} s, wall {:.2} s)",
            path.display(),
            file.runs.len(),
            case_started.elapsed().as_secs_f64()
        );
        solver_time += time;
    }
    println!(
        "all cases: solver {solver_time:.1} s, wall {:.1} s",
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// "computed by mpm at commit X", with what was not committed.
fn source(workspace: &Path) -> String {
    let git = |args: &[&str]| {
        Command::new("git")
            .args(args)
            .current_dir(workspace)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
    };
    let Some(commit) = git(&["rev-parse", "HEAD"]) else {
        return "computed by mpm (commit unknown: git unavailable) with the settings below".into();
    };
    let changed: Vec<String> = git(&["status", "--porcelain", "--untracked-files=all"])
        .unwrap_or_default()
        .lines()
        .filter_map(|l| l.get(3..))
        .map(str::to_owned)
        .filter(|p| !p.starts_with(OUT_DIR))
        .collect();
    // What the values depend on: the library crates' sources and
    // manifests, the workspace manifest and the locked dependencies.
    let library = |p: &String| {
        (p.starts_with("crates/") && (p.contains("/src/") || p.ends_with("/Cargo.toml")))
            || p == "Cargo.toml"
            || p == "Cargo.lock"
    };
    let (lib, other): (Vec<String>, Vec<String>) = changed.into_iter().partition(library);
    let mut s = format!("computed by mpm at commit {}", commit.trim());
    if !lib.is_empty() {
        s.push_str(&format!(
            " with uncommitted changes that may affect the values: {}",
            lib.join(", ")
        ));
    } else if !other.is_empty() {
        s.push_str(&format!(
            " (library sources, manifests and Cargo.lock as committed; uncommitted at generation: {})",
            other.join(", ")
        ));
    }
    s.push_str(", with the settings of each run below");
    s
}

/// Sets the variant fields of a case's parameters, so that the recorded
/// settings name the variant the run used (`params.variant()`).
macro_rules! with_variant {
    ($params:expr, $variant:expr) => {{
        let mut p = $params;
        let v: Variant = $variant;
        p.basis = v.basis;
        p.formulation = v.formulation;
        p.locking = v.locking;
        p.domain_update = v.domain_update;
        p.gimp_volume = v.gimp_volume;
        p
    }};
}

/// A variant with formulation `f`.
fn with_formulation(v: Variant, f: FormulationKind) -> Variant {
    Variant {
        formulation: f,
        ..v
    }
}

/// The run's name: basis, domain update, integration volume, formulation.
fn variant_name(v: &Variant) -> String {
    let mut s = v.basis.name().to_owned();
    if v.basis == BasisKind::Gimp {
        s.push_str(&format!(" {}", v.domain_update));
        if v.gimp_volume != mpm_cases::variant::GimpVolumeKind::DetF {
            s.push_str(&format!(" gimp_volume={}", v.gimp_volume));
        }
    }
    s.push_str(&format!(" {}", v.formulation));
    s
}

/// Points, steps, step cuts and iterations of a run.
fn counts<const D: usize>(
    output: &RunOutput<D>,
    material_points: usize,
) -> BTreeMap<&'static str, usize> {
    BTreeMap::from([
        ("material_points", material_points),
        ("steps", output.summary.steps),
        ("cut_steps", output.summary.cut_steps),
        ("iterations", output.summary.iterations),
    ])
}

/// The residual histories of load steps `steps` (1-based), with the
/// paper's rows where `paper` has the step.
fn histories<const D: usize>(
    output: &RunOutput<D>,
    steps: &[usize],
    paper: &[(usize, &[f64])],
) -> Result<Vec<History>> {
    steps
        .iter()
        .map(|&step| {
            let report = step
                .checked_sub(1)
                .and_then(|i| output.reports.get(i))
                .ok_or_else(|| anyhow!("no report of load step {step}"))?;
            Ok(History {
                step,
                iterations: report.iterations(),
                initial_unbalance: report.initial_unbalance,
                residuals: report.residuals.clone(),
                paper_residuals: paper
                    .iter()
                    .find(|(s, _)| *s == step)
                    .map(|(_, r)| r.to_vec()),
            })
        })
        .collect()
}

/// The settings as JSON, and a one-line log of a finished run.
fn settings<T: Serialize>(p: &T) -> Result<Value> {
    Ok(serde_json::to_value(p)?)
}

fn log(case: &str, name: &str, time: f64, values: &BTreeMap<&'static str, f64>) {
    let v: Vec<String> = values.iter().map(|(k, x)| format!("{k} {x:.6e}")).collect();
    println!("{case:>10} {name:<60} {time:>7.3} s  {}", v.join(", "));
}

type CaseRuns = (String, Vec<String>, Vec<Run>);

/// Column (Coombs 2020 §7.1, Fig. 7): eq. (42) per variant and level.
fn column_file(_: &Path, time: &mut f64) -> Result<CaseRuns> {
    use DomainUpdateKind as R;
    let mut variants = vec![
        (linear(), "tests/column.rs, coombs2020 Fig. 6/7"),
        (
            with_formulation(linear(), FormulationKind::Ul),
            "tests/column.rs (UL = PC)",
        ),
        (
            variant(BasisKind::BSpline2, R::None),
            "coombs2020 Fig. 7 (quadratic B-spline)",
        ),
        (
            with_formulation(variant(BasisKind::BSpline2, R::None), FormulationKind::Ul),
            "tests/column.rs (UL = PC)",
        ),
        (cpdi2(), "tests/coombs2020.rs Fig. 7"),
    ];
    variants.extend(GIMP_RULES.map(|r| (gimp(r), "tests/coombs2020.rs Fig. 7")));
    variants.push((
        with_formulation(gimp(R::Stretch), FormulationKind::Ul),
        "tests/column.rs (UL = PC)",
    ));
    for r in [R::None, R::DetF] {
        variants.push((
            gimp_domain_volume(r),
            "tests/coombs2020.rs Fig. 7 with domain volumes",
        ));
    }
    let mut runs = Vec::new();
    for (v, study) in variants {
        for k in COLUMN_LEVELS {
            let p = with_variant!(
                ColumnParams {
                    h: 50.0 / 2f64.powi(k),
                    ..ColumnParams::default()
                },
                v
            );
            let name = format!("{}, k = {k}", variant_name(&v));
            let r =
                column::ColumnCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| Ok(()))
                    .with_context(|| name.clone())?;
            let values = BTreeMap::from([("error", r.error)]);
            *time += r.output.wall_time_s;
            log("column", &name, r.output.wall_time_s, &values);
            runs.push(Run {
                name,
                study: study.into(),
                settings: settings(&p)?,
                values,
                counts: counts(&r.output, r.material_points),
                histories: Vec::new(),
                comparison: None,
            });
        }
    }
    Ok((
        "Coombs, Augarde, Brennan et al. (2020), CMAME 358:112622, §7.1: compaction of a 50 m \
         elastic column under self weight, 2×2 points per cell, h = 50/2^k; `error` is eq. (42), \
         the volume-weighted error of the vertical stress against the analytic eq. (41). The \
         paper plots these errors (Figs. 6, 7) and tabulates none, so there is no paper value to \
         compare number by number."
            .into(),
        vec![format!(
            "k = {}..={}, the range of tests/coombs2020.rs (the paper's Fig. 7 has k = 2..7).",
            COLUMN_LEVELS.start(),
            COLUMN_LEVELS.end()
        )],
        runs,
    ))
}

/// Cantilever (Coombs 2020 §7.3): tip displacement at full load and the
/// residuals of Table 3's steps.
fn cantilever_file(_: &Path, time: &mut f64) -> Result<CaseRuns> {
    let gimp37 = gimp(DomainUpdateKind::CornerMidpoint);
    let mut setups: Vec<(Variant, usize, f64, &str)> = Vec::new();
    for f in [FormulationKind::Pc, FormulationKind::Ul] {
        setups.push((
            with_formulation(linear(), f),
            4,
            0.5,
            "tests/cantilever.rs (default settings)",
        ));
    }
    for f in [FormulationKind::Pc, FormulationKind::Ul] {
        setups.push((with_formulation(gimp37, f), 6, 0.5, "tests/coombs2020.rs"));
        setups.push((with_formulation(cpdi2(), f), 4, 0.5, "tests/coombs2020.rs"));
    }
    setups.push((gimp37, 6, 0.25, "tests/coombs2020.rs (refined)"));
    setups.push((gimp37, 6, 0.125, "Table 3 (the paper's settings)"));
    let (ua, va) = elastica_tip(10.0);
    let mut runs = Vec::new();
    for (v, ppc, h, study) in setups {
        let p = with_variant!(
            CantileverParams {
                h,
                points_per_cell: ppc,
                ..CantileverParams::default()
            },
            v
        );
        let name = format!("{}, {ppc}x{ppc} points, h = {h}", variant_name(&v));
        let r =
            cantilever::CantileverCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| {
                Ok(())
            })
            .with_context(|| name.clone())?;
        let &(_, u, w) = r
            .tip
            .last()
            .ok_or_else(|| anyhow!("{name}: no load step"))?;
        let values = BTreeMap::from([("tip_u", u), ("tip_v", w)]);
        *time += r.output.wall_time_s;
        log("cantilever", &name, r.output.wall_time_s, &values);
        let table3 = h == 0.125 && ppc == 6 && v == gimp37;
        runs.push(Run {
            name,
            study: study.into(),
            settings: settings(&p)?,
            values,
            counts: counts(&r.output, r.material_points),
            histories: histories(
                &r.output,
                &TABLE_3_STEPS,
                if table3 { &paper::TABLE_3 } else { &[] },
            )?,
            comparison: Some(Comparison {
                source: "the elastica at α = P l0²/EI = 10 \
                         (mpm_cases::cases::cantilever::elastica_tip), times l0"
                    .into(),
                values: BTreeMap::from([("tip_u", ua * p.length), ("tip_v", va * p.length)]),
            }),
        });
    }
    Ok((
        "Coombs et al. (2020) §7.3, Figs. 13–17 and Table 3: elastic cantilever 10 m × 1 m \
         under a 100 kN end load in 50 steps. `tip_u`, `tip_v`: the tip displacement at full \
         load (m, mean of the two loaded points); histories: eq. (40) per Newton iteration in \
         Table 3's load steps 10, 20, 40, 49, 50. The paper's Table 3 (GIMP eq. 37, 6² points, \
         h = 0.125 m) is quoted beside the run with those settings; the tip is compared with \
         the elastica."
            .into(),
        vec![
            "The paper's iteration 0 is the `initial_unbalance` measure (all dofs, reactions not \
             yet known); its later iterations are eq. (40) with a reaction estimate, so the \
             values differ from ours in detail (docs/src/reproduction/coombs2020.md §4)."
                .into(),
        ],
        runs,
    ))
}

/// A collapse run: variant, points per cell per direction, the study, and
/// the paper's extent and height where it has them.
type CollapseSetup = (Variant, usize, String, Option<(f64, f64)>);

/// Collapse (Coombs 2020 §7.5): Tables 6, 7 and 8.
fn collapse_file(_: &Path, time: &mut f64) -> Result<CaseRuns> {
    use DomainUpdateKind as R;
    let mut setups: Vec<CollapseSetup> = Vec::new();
    for (ppc, rows) in paper::TABLE_6 {
        let (_, x, y) = rows
            .iter()
            .copied()
            .find(|(h, _, _)| *h == 1.0)
            .ok_or_else(|| anyhow!("Table 6 has no h = 1 m row"))?;
        setups.push((
            linear(),
            ppc,
            format!("Table 6, h = 1 m, {ppc}² points (tests/collapse.rs)"),
            Some((x, y)),
        ));
    }
    let table7 = |rule: R| match rule {
        R::DetF => Some(paper::table7::EQ32),
        R::DiagF => Some(paper::table7::EQ33),
        R::Stretch => Some(paper::table7::EQ34),
        R::CornerMidpoint | R::Midpoint => Some(paper::table7::EQ37),
        R::VolumeCorrectedDiagF | R::IncrementalVolumeCorrectedDiagF => {
            Some(paper::table7::EQ38_39)
        }
        R::None | R::Cpdi2 => None,
    };
    for rule in GIMP_RULES {
        setups.push((
            gimp_domain_volume(rule),
            6,
            "Table 7, the paper's convention V = ∏2l (tests/coombs2020.rs)".into(),
            table7(rule),
        ));
    }
    setups.push((
        cpdi2(),
        6,
        "Table 7 (tests/coombs2020.rs)".into(),
        Some(paper::table7::CPDI2),
    ));
    for rule in GIMP_RULES {
        let study = if rule == R::CornerMidpoint {
            "Table 7 with V = det F V0, and Table 8 (tests/coombs2020.rs)"
        } else {
            "Table 7 with V = det F V0 (tests/coombs2020.rs)"
        };
        setups.push((gimp(rule), 6, study.into(), table7(rule)));
    }
    let table8 = gimp(R::CornerMidpoint);
    let mut runs = Vec::new();
    for (v, ppc, study, paper_values) in setups {
        let p = with_variant!(
            CollapseParams {
                points_per_cell: ppc,
                ..CollapseParams::default()
            },
            v
        );
        let name = format!("{}, {ppc}x{ppc} points, h = {}", variant_name(&v), p.h);
        let r =
            collapse::CollapseCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| Ok(()))
                .with_context(|| name.clone())?;
        let values = BTreeMap::from([
            ("horizontal_extent", r.horizontal_extent),
            ("max_height", r.max_height),
        ]);
        *time += r.output.wall_time_s;
        log("collapse", &name, r.output.wall_time_s, &values);
        let histories = if v == table8 {
            histories(&r.output, &TABLE_8_STEPS, &paper::TABLE_8)?
        } else {
            Vec::new()
        };
        let table = if v.basis == BasisKind::Linear {
            "Table 6"
        } else {
            "Table 7"
        };
        runs.push(Run {
            name,
            study,
            settings: settings(&p)?,
            values,
            counts: counts(&r.output, r.material_points),
            histories,
            comparison: paper_values.map(|(x, y)| Comparison {
                source: format!("Coombs et al. (2020) {table}"),
                values: BTreeMap::from([("horizontal_extent", x), ("max_height", y)]),
            }),
        });
    }
    Ok((
        "Coombs et al. (2020) §7.5, Tables 6–8: elasto-plastic collapse of a block under self \
         weight (symmetric half 8 m × 8 m, h = 1 m, 40 load steps). `horizontal_extent`, \
         `max_height`: the edge of the body at the end (m), of the points' domains for GIMP and \
         CPDI2, else x_p + l0_p. The paper's Table 6 and 7 values stand beside each run; Table \
         8's residuals (GIMP eq. 37) beside the histories of the run with its settings (the \
         paper's code integrates GIMP with V = ∏2l; Table 8 is quoted beside our default \
         V = det F V0 run, as in tests/coombs2020.rs)."
            .into(),
        vec![
            "The paper's eq. 37 height (6.392 m) is not reproduced (ours 6.258 m); see \
             docs/src/reproduction/coombs2020.md §3. Its iteration-0 unbalance agrees within \
             0.04 %."
                .into(),
        ],
        runs,
    ))
}

/// Annulus (Coombs 2020 §7.4, Fig. 19) on the committed Gmsh meshes.
fn annulus_file(workspace: &Path, time: &mut f64) -> Result<CaseRuns> {
    let mut setups: Vec<(usize, usize, FormulationKind, &str)> = Vec::new();
    for mesh in 1..=3 {
        setups.push((
            mesh,
            4,
            FormulationKind::Pc,
            "tests/annulus.rs, rate with 4² points",
        ));
    }
    for n in 1..=3 {
        setups.push((
            2,
            n,
            FormulationKind::Pc,
            "tests/annulus.rs, error against points",
        ));
    }
    for f in [FormulationKind::Pc, FormulationKind::Ul] {
        setups.push((1, 3, f, "tests/annulus.rs (UL = PC, default 3² points)"));
    }
    let mut runs = Vec::new();
    for (mesh, n, f, study) in setups {
        let relative = PathBuf::from(format!("scenes/meshes/annulus_{mesh}.msh"));
        let v = with_formulation(linear(), f);
        let recorded = with_variant!(
            AnnulusParams {
                mesh: Some(relative.clone()),
                points_per_element: n,
                ..AnnulusParams::default()
            },
            v
        );
        let p = AnnulusParams {
            mesh: Some(workspace.join(&relative)),
            ..recorded.clone()
        };
        let name = format!(
            "{}, {}, {n}² points per triangle",
            variant_name(&v),
            relative.display()
        );
        let r =
            annulus::AnnulusCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| Ok(()))
                .with_context(|| name.clone())?;
        let values = BTreeMap::from([
            ("error", r.error),
            ("max_error", r.max_error),
            ("element_size", r.element_size),
        ]);
        *time += r.output.wall_time_s;
        log("annulus", &name, r.output.wall_time_s, &values);
        let mut counts = counts(&r.output, r.material_points);
        counts.insert("elements", r.elements);
        runs.push(Run {
            name,
            study: study.into(),
            settings: settings(&recorded)?,
            values,
            counts,
            histories: Vec::new(),
            comparison: None,
        });
    }
    Ok((
        "Coombs et al. (2020) §7.4, Fig. 19: elastic annulus under the manufactured torsion of \
         eq. (44), standard MPM on the committed unstructured Gmsh triangles \
         (scenes/meshes/annulus_*.msh), n² points per triangle. `error`: the volume-weighted \
         mean of |u_p − u^a(X_p)| (m) against the exact displacement; `max_error` its largest \
         value; `element_size` √(2A/n_e). The paper plots these errors (Fig. 19) and tabulates \
         none."
            .into(),
        vec!["Mesh paths in the settings are relative to the workspace root.".into()],
        runs,
    ))
}

/// Stretch (Wang 2021 §5.3, Table 1).
fn stretch_file(workspace: &Path, time: &mut f64) -> Result<CaseRuns> {
    let paper_yield = 400.0 * (2.0f64 / 3.0).sqrt();
    let mut setups: Vec<(StretchParams, Variant, String, Option<f64>)> = Vec::new();
    for (yield_stress, convention) in [
        (400.0, "ρ_y = 400 Pa in eq. (16)"),
        (paper_yield, "ρ_y = 400 √(2/3) Pa, the paper's τ_a = 400 Pa"),
    ] {
        for cells in [2, 4] {
            let paper = (yield_stress == paper_yield)
                .then(|| TABLE_1.iter().find(|r| r.0 == cells).map(|r| r.2))
                .flatten();
            setups.push((
                StretchParams {
                    cells,
                    yield_stress,
                    ..StretchParams::default()
                },
                linear(),
                format!("Table 1, {convention} (tests/stretch.rs)"),
                paper,
            ));
        }
    }
    setups.push((
        StretchParams::default(),
        with_formulation(linear(), FormulationKind::Ul),
        "tests/stretch.rs (UL = PC)".into(),
        None,
    ));
    for f in [FormulationKind::Pc, FormulationKind::Ul] {
        setups.push((
            StretchParams {
                predictor: false,
                ..StretchParams::default()
            },
            with_formulation(linear(), f),
            "tests/stretch.rs, no predictor: the homogeneous branch".into(),
            None,
        ));
    }
    let cube = PathBuf::from("scenes/meshes/cube_tet10.msh");
    setups.push((
        StretchParams {
            mesh: Some(cube.clone()),
            stretch: 0.5,
            load_steps: 2,
            ..StretchParams::default()
        },
        linear(),
        "tests/stretch.rs, elastic stretch of the unstructured Gmsh cube".into(),
        None,
    ));
    let mut runs = Vec::new();
    for (params, v, study, paper) in setups {
        let recorded = with_variant!(params, v);
        let p = StretchParams {
            mesh: recorded.mesh.as_ref().map(|m| workspace.join(m)),
            ..recorded.clone()
        };
        let name = format!(
            "{}, {}, rho_y = {:.4}{}",
            variant_name(&v),
            recorded
                .mesh
                .as_ref()
                .map_or(format!("{} cells", p.cells), |m| m.display().to_string()),
            p.yield_stress,
            if p.predictor { "" } else { ", no predictor" }
        );
        let r =
            stretch::StretchCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| Ok(()))
                .with_context(|| name.clone())?;
        let values = BTreeMap::from([
            ("error", r.error),
            ("analytic_stress", r.analytic_stress),
            ("tau_yy_mean", r.tau_yy.0),
            ("tau_yy_min", r.tau_yy.1),
            ("tau_yy_max", r.tau_yy.2),
        ]);
        *time += r.output.wall_time_s;
        log("stretch", &name, r.output.wall_time_s, &values);
        let mut counts = counts(&r.output, r.material_points);
        counts.insert("elements", r.elements);
        runs.push(Run {
            name,
            study,
            settings: settings(&recorded)?,
            values,
            counts,
            histories: Vec::new(),
            comparison: paper.map(|e| Comparison {
                source: "Wang et al. (2021) Table 1, standard MPM: a non-homogeneous solution \
                         this set-up does not produce (see tests/stretch.rs)"
                    .into(),
                values: BTreeMap::from([("error", e)]),
            }),
        });
    }
    Ok((
        "Wang, Coombs, Augarde et al. (2021), IJNME 122, §5.3, Table 1: simple stretch of a 2 m \
         cube on tetrahedra with a moving mesh, von Mises, perfect plasticity. `error`: the \
         normalised Kirchhoff stress error (1/V) Σ_p |τ_yy − τ_a| V_p / τ_a; `tau_yy_*`: mean, \
         smallest and largest τ_yy over the points (Pa); `analytic_stress`: τ_a. With the \
         predictor the homogeneous state is an exact discrete equilibrium, so `error` is \
         round-off (about 1e-11); the paper's standard MPM errors stand beside those runs for \
         comparison only."
            .into(),
        vec!["Mesh paths in the settings are relative to the workspace root.".into()],
        runs,
    ))
}
