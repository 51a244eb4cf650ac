//! `ranks [--quick]`: a scene on 2 MPI processes against one, through the
//! `mpm` program (`mpirun -n 2 mpm run scene.toml`), each configuration
//! repeated and interleaved with the others so that the host's noise falls
//! on all alike:
//!
//! - explicit: the collapsing column of `scenes/explicit_collapse.toml` at
//!   200,704 points (h = 1/224 m), 73 CFL steps; the solver's wall time
//!   (`summary.json`, outputs excluded) and its stages, and what is outside
//!   them on 2 processes (the halo, the migration, the counts for the
//!   balance, the reductions);
//! - implicit: the double-notched plate of
//!   `scenes/wang2021_notched_plate.toml` with F-patch at h = 1 mm (33,792
//!   points), 10 steps of 0.01 mm; rank 0's seconds per stage from
//!   `steps.csv`: the per-point work (stress updates, tangents) is split
//!   over the ranks, the stiffness is summed over them and rank 0 solves
//!   it alone with the built-in solver;
//! - the same plate with PETSc over the processes (GMRES + GAMG, each rank
//!   handing PETSc the entries of its own points): the solve divides too.
//!
//! Configurations: 1 process × 1 thread, 1 process × 2 threads, 2
//! processes × 1 thread (`--bind-to none`). Written to
//! `docs/src/benchmarks/ranks_scenes.md`. Needs Open MPI (`mpirun`) and
//! PETSc; builds `mpm` with `--features mpi,petsc` itself.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, bail};

use crate::machine;
use crate::markdown::Table;

/// How a run is started.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    pub(crate) label: &'static str,
    pub(crate) processes: usize,
    pub(crate) threads: usize,
}

const LAYOUTS: [Layout; 3] = [
    Layout {
        label: "1 process × 1 thread",
        processes: 1,
        threads: 1,
    },
    Layout {
        label: "1 process × 2 threads",
        processes: 1,
        threads: 2,
    },
    Layout {
        label: "2 processes × 1 thread",
        processes: 2,
        threads: 1,
    },
];

/// A scene and its overrides.
struct Case {
    name: &'static str,
    file: &'static str,
    set: &'static [&'static str],
}

const EXPLICIT: Case = Case {
    name: "explicit: the collapsing column",
    file: "explicit_collapse.toml",
    set: &[
        "mesh.cells=[672,280]",
        "solver.end_time=0.005",
        "solver.output_interval=0.005",
    ],
};

const IMPLICIT: Case = Case {
    name: "implicit: the notched plate with F-patch",
    file: "wang2021_notched_plate.toml",
    set: &[
        "solver.locking=\"fpatch\"",
        "solver.steps=10",
        "mesh.motion.extension=1e-4",
    ],
};

/// PETSc's options of the plate's solve over the processes (F-patch's
/// system is not symmetric).
const PETSC: &str = "solver.linear={ petsc = \"-ksp_type gmres -pc_type gamg\" }";

/// The quick variant: smaller problems, one repetition.
const QUICK_EXPLICIT: &[&str] = &[
    "mesh.cells=[192,80]",
    "solver.end_time=0.005",
    "solver.output_interval=0.005",
];
const QUICK_IMPLICIT: &[&str] = &[
    "mesh.cells=[2,4,1]",
    "solver.locking=\"fpatch\"",
    "solver.steps=10",
    "mesh.motion.extension=1e-4",
];

/// What one run measured: the solver's wall time and named parts of it.
#[derive(Debug, Clone, Default)]
struct Timing {
    points: u64,
    wall: f64,
    parts: Vec<(String, f64)>,
}

/// Runs the comparison and writes the page.
pub fn run(quick: bool, root: &Path, docs: &Path) -> Result<()> {
    let start = Instant::now();
    let exe = build(root)?;
    let repeats = if quick { 1 } else { 3 };
    let scratch = std::env::temp_dir().join(format!("xtask-ranks-{}", std::process::id()));
    let explicit_set = if quick { QUICK_EXPLICIT } else { EXPLICIT.set };
    let implicit_set = if quick { QUICK_IMPLICIT } else { IMPLICIT.set };
    let petsc_set: Vec<&str> = implicit_set.iter().copied().chain([PETSC]).collect();
    let mut explicit = vec![Vec::new(); LAYOUTS.len()];
    let mut implicit = vec![Vec::new(); LAYOUTS.len()];
    let mut petsc = vec![Vec::new(); LAYOUTS.len()];
    let load = machine::load_average();
    for r in 0..repeats {
        for (k, layout) in LAYOUTS.iter().enumerate() {
            eprintln!("repetition {}/{repeats}: {}", r + 1, layout.label);
            let dir = scratch.join(format!("explicit-{k}-{r}"));
            run_scene(&exe, root, EXPLICIT.file, explicit_set, *layout, &dir)?;
            explicit[k].push(explicit_timing(&dir)?);
            let dir = scratch.join(format!("implicit-{k}-{r}"));
            run_scene(&exe, root, IMPLICIT.file, implicit_set, *layout, &dir)?;
            implicit[k].push(implicit_timing(&dir)?);
            let dir = scratch.join(format!("petsc-{k}-{r}"));
            run_scene(&exe, root, IMPLICIT.file, &petsc_set, *layout, &dir)?;
            petsc[k].push(implicit_timing(&dir)?);
        }
    }
    std::fs::remove_dir_all(&scratch).ok();
    let mut page = String::new();
    writeln!(page, "# A scene on 2 processes against one\n")?;
    let command = if quick { "ranks --quick" } else { "ranks" };
    writeln!(
        page,
        "{}; {repeats} repetition(s), interleaved. Times are the solver's (outputs excluded) on rank 0; median and range.\n",
        machine::generated_by(command, load),
    )?;
    write_case(&mut page, EXPLICIT.name, explicit_set, &explicit)?;
    write_case(&mut page, IMPLICIT.name, implicit_set, &implicit)?;
    let petsc_name = format!("{} and PETSc (GMRES + GAMG)", IMPLICIT.name);
    write_case(&mut page, &petsc_name, &petsc_set, &petsc)?;
    writeln!(
        page,
        "With the built-in linear solver, rank 0 solves the whole (summed) system alone on 2 processes (`solve`), so only the per-point stages divide. With PETSc each process hands it the entries of its own points and the Krylov method and GAMG run over both processes (PETSc's own work is not threaded; on 1 process × 2 threads only our stages use the second core). `other` is the wall time outside the named stages: in the explicit run on 2 processes the halo exchange, the migration, the counts for the balance and the reductions.\n"
    )?;
    let page = machine::stamp_duration(page, start);
    let path = docs.join("benchmarks/ranks_scenes.md");
    std::fs::write(&path, page).with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Builds `mpm` with MPI and PETSc and returns its path.
pub(crate) fn build(root: &Path) -> Result<PathBuf> {
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args([
            "build",
            "--release",
            "-p",
            "mpm-cases",
            "--features",
            "mpi,petsc",
        ])
        .current_dir(root)
        .status()
        .context("running cargo build")?;
    if !status.success() {
        bail!("cargo build --release -p mpm-cases --features mpi,petsc failed");
    }
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from);
    Ok(target.join("release/mpm"))
}

/// Runs `file` with the overrides `set` on `layout`, writing into `dir`.
pub(crate) fn run_scene(
    exe: &Path,
    root: &Path,
    file: &str,
    set: &[&str],
    layout: Layout,
    dir: &Path,
) -> Result<()> {
    let mut command = if layout.processes > 1 {
        let mut c = Command::new("mpirun");
        c.args([
            "-n",
            &layout.processes.to_string(),
            "--bind-to",
            "none",
            "--oversubscribe",
        ])
        .arg(exe)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
        c
    } else {
        Command::new(exe)
    };
    command
        .arg("run")
        .arg(root.join("scenes").join(file))
        .args(set.iter().flat_map(|s| ["--set", s]))
        .arg("--out")
        .arg(dir)
        .env("RAYON_NUM_THREADS", layout.threads.to_string());
    let out = command
        .output()
        .with_context(|| format!("running {file}"))?;
    if !out.status.success() {
        bail!(
            "{file} on {}: {}",
            layout.label,
            String::from_utf8_lossy(&out.stderr)
        );
    }
    Ok(())
}

fn summary(dir: &Path) -> Result<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join("summary.json"))?;
    Ok(serde_json::from_str(&text)?)
}

/// The explicit solver's wall time and its stages.
fn explicit_timing(dir: &Path) -> Result<Timing> {
    let s = summary(dir)?;
    let wall = s["wall_time_s"].as_f64().context("wall_time_s")?;
    let points = s["material_points"].as_u64().unwrap_or(0);
    let stage = |k: &str| s["stage_times_s"][k].as_f64().unwrap_or(0.0);
    let parts = ["p2g", "grid", "g2p"].map(|k| (k.to_owned(), stage(k)));
    let named: f64 = parts.iter().map(|p| p.1).sum();
    let mut parts = parts.to_vec();
    parts.push(("other".into(), wall - named));
    Ok(Timing {
        points,
        wall,
        parts,
    })
}

/// The implicit solver's wall time and rank 0's seconds per stage, summed
/// over the steps of `steps.csv`.
fn implicit_timing(dir: &Path) -> Result<Timing> {
    let s = summary(dir)?;
    let wall = s["wall_time_s"].as_f64().context("wall_time_s")?;
    let points = s["material_points"].as_u64().unwrap_or(0);
    let csv = std::fs::read_to_string(dir.join("steps.csv"))?;
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let mut sums = vec![0.0; header.len()];
    for line in lines {
        for (sum, x) in sums.iter_mut().zip(line.split(',')) {
            *sum += x.parse::<f64>().unwrap_or(0.0);
        }
    }
    let parts = (header.iter().zip(&sums))
        .filter_map(|(h, &v)| h.strip_prefix("seconds_").map(|n| (n.to_owned(), v)))
        .collect();
    Ok(Timing {
        points,
        wall,
        parts,
    })
}

/// The median of `xs` and their range as text.
fn spread(mut xs: Vec<f64>) -> (f64, String) {
    xs.sort_by(f64::total_cmp);
    let median = xs[xs.len() / 2];
    let range = match (xs.first(), xs.last()) {
        (Some(lo), Some(hi)) if xs.len() > 1 => format!("{lo:.2}–{hi:.2}"),
        _ => format!("{median:.2}"),
    };
    (median, range)
}

/// A case's table: per layout the wall time, the speedup over 1 process ×
/// 1 thread, and the median of every part.
fn write_case(page: &mut String, name: &str, set: &[&str], runs: &[Vec<Timing>]) -> Result<()> {
    writeln!(page, "## {name}, {} points\n", runs[0][0].points)?;
    writeln!(page, "Overrides: `{}`.\n", set.join("`, `"))?;
    let part_names: Vec<String> = runs[0][0].parts.iter().map(|p| p.0.clone()).collect();
    let mut header = vec!["layout".to_owned(), "wall (s)".into(), "speedup".into()];
    header.extend(part_names.iter().map(|p| format!("{p} (s)")));
    let mut table = Table::new(header);
    let (base, _) = spread(runs[0].iter().map(|t| t.wall).collect());
    for (layout, timings) in LAYOUTS.iter().zip(runs) {
        let (median, range) = spread(timings.iter().map(|t| t.wall).collect());
        let mut row = vec![
            layout.label.to_owned(),
            format!("{median:.2} ({range})"),
            format!("{:.2}", base / median),
        ];
        for (k, _) in part_names.iter().enumerate() {
            let (m, _) = spread(timings.iter().map(|t| t.parts[k].1).collect());
            row.push(format!("{m:.2}"));
        }
        table.row(row);
    }
    writeln!(page, "{}", table.render())?;
    Ok(())
}
