//! `scaling [--quick]` and `scaling --strong [--max-ranks N] [--quick]`:
//! how the distributed runs scale, through the `mpm` program under
//! `mpirun` (built with `--features mpi,petsc` by [`ranks::build`]).
//!
//! - **Weak** (`docs/src/benchmarks/scaling.md`): the points per rank
//!   fixed, N = 1, 2, 4 processes. The explicit collapsing column
//!   (`scenes/explicit_collapse.toml`, cells scaled by √N per axis): per
//!   rank and step the point work, the halo messages and bytes, the
//!   migration and the collectives, from `summary.json`'s `ranks`. The
//!   F-patch strip footing (`scenes/strip_footing_ranks.toml`) with PETSc
//!   (GMRES + GAMG) over the processes: Newton and Krylov iterations.
//!   Then an α–β model, its constants stated, predicting the explicit
//!   step's parallel efficiency at 16, 64 and 256 ranks from what a rank
//!   sends at N = 4.
//! - **Strong** (`docs/src/benchmarks/strong_scaling.md`): the plan of
//!   Wang et al. (2021) Fig. 23 — the notched plate, the footing and the
//!   full vane with F-patch at 1, 4 and 11 points per element, on 1, 2,
//!   4, ... up to `--max-ranks` processes, PETSc's GMRES + GAMG solving
//!   over them: wall time, speedup and efficiency per case. On a 16-core
//!   node: `cargo xtask scaling --strong --max-ranks 16`.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use serde_json::Value;

use crate::machine;
use crate::markdown::Table;
use crate::ranks::{self, Layout};

/// PETSc over the processes for F-patch's unsymmetric systems.
const PETSC: &str = "solver.linear={ petsc = \"-ksp_type gmres -pc_type gamg\" }";

/// The model's point-to-point latency (s): an InfiniBand-class network
/// between nodes (1–3 µs; MPI over shared memory within a node is faster).
const ALPHA: f64 = 2e-6;
/// The model's inverse bandwidth (s per byte): 10 GB/s per link.
const BETA: f64 = 1e-10;
/// How much more a rank inside a large partition sends than the ranks of
/// N = 4 measured here, which border the domain on two or more sides: a
/// part of fixed area inside the domain has all its perimeter cut, about
/// twice the cut perimeter of a corner part.
const INTERIOR: f64 = 2.0;

/// Weak scaling and the model: writes `docs/src/benchmarks/scaling.md`.
pub fn weak(quick: bool, root: &Path, docs: &Path) -> Result<()> {
    let start = Instant::now();
    let exe = ranks::build(root)?;
    let scratch = std::env::temp_dir().join(format!("xtask-scaling-{}", std::process::id()));
    let load = machine::load_average();
    let base: [f64; 2] = if quick { [96.0, 40.0] } else { [192.0, 80.0] };
    let mut explicit = Vec::new();
    let mut implicit = Vec::new();
    for n in [1usize, 2, 4] {
        let scale = (n as f64).sqrt();
        let cells = base.map(|c| (c * scale).round());
        let set = [
            format!("mesh.cells=[{},{}]", cells[0], cells[1]),
            "solver.end_time=0.1".to_owned(),
            "solver.output_interval=0.1".to_owned(),
        ];
        let dir = scratch.join(format!("explicit-{n}"));
        run(&exe, root, "explicit_collapse.toml", &set, n, &dir)?;
        explicit.push(ExplicitRow::read(n, &dir)?);
        let footing = [16.0, 8.0].map(|c: f64| (c * scale).round());
        // 1 mm: the same load steps on every mesh (with the scene's 10 mm
        // the finer meshes' Newton cuts steps, and their surface points
        // heave out of the mesh, which has no room above the surface).
        let set = [
            format!("mesh.cells=[{},{}]", footing[0], footing[1]),
            "boundary.3.displacement={ y = -0.001 }".to_owned(),
            PETSC.to_owned(),
        ];
        let dir = scratch.join(format!("implicit-{n}"));
        run(&exe, root, "strip_footing_ranks.toml", &set, n, &dir)?;
        implicit.push(ImplicitRow::read(n, &dir)?);
    }
    std::fs::remove_dir_all(&scratch).ok();
    let mut page = String::new();
    writeln!(page, "# Weak scaling, measured and modelled\n")?;
    let command = if quick { "scaling --quick" } else { "scaling" };
    writeln!(
        page,
        "{}. The points per rank are held fixed (the cells scaled by √N per axis); N processes × 1 thread each, `--bind-to none --oversubscribe`. On this 2-core machine N = 4 shares 2 cores among 4 processes, so its seconds include waiting for a core: the counts (messages, bytes, iterations) are what this page measures at N = 4, not the times.\n",
        machine::generated_by(command, load),
    )?;
    write_explicit(&mut page, &explicit)?;
    write_implicit(&mut page, &implicit)?;
    write_model(&mut page, &explicit)?;
    let page = machine::stamp_duration(page, start);
    let path = docs.join("benchmarks/scaling.md");
    std::fs::write(&path, page).with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Runs `file` with `set` on `n` processes of one thread into `dir`.
fn run(exe: &Path, root: &Path, file: &str, set: &[String], n: usize, dir: &Path) -> Result<()> {
    eprintln!("{file} on {n} process(es): {}", set.join(" "));
    let set: Vec<&str> = set.iter().map(String::as_str).collect();
    let layout = Layout {
        label: "N processes × 1 thread",
        processes: n,
        threads: 1,
    };
    ranks::run_scene(exe, root, file, &set, layout, dir)
}

fn summary(dir: &Path) -> Result<Value> {
    let text = std::fs::read_to_string(dir.join("summary.json"))?;
    Ok(serde_json::from_str(&text)?)
}

/// One explicit run of the weak series, per rank and step.
struct ExplicitRow {
    ranks: usize,
    points: f64,
    steps: f64,
    /// Point work per step, the slowest rank's and the mean (s).
    point: [f64; 2],
    /// Halo messages, bytes, migration bytes, collectives and migrated
    /// points per step, the busiest rank's.
    messages: f64,
    bytes: f64,
    migration_bytes: f64,
    collectives: f64,
    migrated: f64,
}

impl ExplicitRow {
    fn read(n: usize, dir: &Path) -> Result<Self> {
        let s = summary(dir)?;
        let steps = s["time_steps"].as_f64().context("time_steps")?.max(1.0);
        let points = s["material_points"].as_f64().context("material_points")?;
        let r = &s["ranks"];
        let max = |k: &str| r[k]["max"].as_f64().unwrap_or(0.0) / steps;
        let point = if n == 1 {
            let stage = |k: &str| s["stage_times_s"][k].as_f64().unwrap_or(0.0);
            let t = (stage("p2g") + stage("g2p")) / steps;
            [t, t]
        } else {
            let mean = r["point_seconds"]["mean"].as_f64().unwrap_or(0.0) / steps;
            [max("point_seconds"), mean]
        };
        Ok(Self {
            ranks: n,
            points,
            steps,
            point,
            messages: max("halo_messages"),
            bytes: max("halo_bytes"),
            migration_bytes: max("migration_bytes"),
            collectives: max("collectives"),
            migrated: max("migrated_points"),
        })
    }
}

fn write_explicit(page: &mut String, rows: &[ExplicitRow]) -> Result<()> {
    writeln!(
        page,
        "## Explicit: the collapsing column\n\nPer step, the busiest rank's (point work: the slowest rank's and the mean). `halo`: the point-to-point messages of the steps (the reverse and forward halo exchanges); `collectives`: the reductions of the steps, migrations and new deals (time step, energies, every agreed decision). The outputs' gathers onto rank 0 are in neither.\n"
    )?;
    let mut table = Table::new([
        "N",
        "points",
        "points per rank",
        "steps",
        "point work per step (ms), slowest / mean",
        "halo messages",
        "halo bytes",
        "migrated points",
        "migration bytes",
        "collectives",
    ]);
    for r in rows {
        table.row(vec![
            r.ranks.to_string(),
            format!("{:.0}", r.points),
            format!("{:.0}", r.points / r.ranks as f64),
            format!("{:.0}", r.steps),
            format!("{:.2} / {:.2}", 1e3 * r.point[0], 1e3 * r.point[1]),
            format!("{:.2}", r.messages),
            format!("{:.0}", r.bytes),
            format!("{:.2}", r.migrated),
            format!("{:.0}", r.migration_bytes),
            format!("{:.2}", r.collectives),
        ]);
    }
    writeln!(page, "{}", table.render())?;
    Ok(())
}

/// One implicit run of the weak series.
struct ImplicitRow {
    ranks: usize,
    points: f64,
    dofs: f64,
    steps: usize,
    newton: f64,
    krylov: f64,
    solve: f64,
    wall: f64,
}

impl ImplicitRow {
    fn read(n: usize, dir: &Path) -> Result<Self> {
        let s = summary(dir)?;
        let csv = std::fs::read_to_string(dir.join("steps.csv"))?;
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
        let column = |name: &str| header.iter().position(|h| *h == name);
        let (it, lin, solve, dofs) = (
            column("iterations"),
            column("linear_iterations"),
            column("seconds_solve"),
            column("free_dofs"),
        );
        let mut sums = [0.0; 4];
        let mut steps = 0;
        for line in lines {
            let cells: Vec<f64> = line.split(',').map(|x| x.parse().unwrap_or(0.0)).collect();
            let at = |c: Option<usize>| c.and_then(|k| cells.get(k)).copied().unwrap_or(0.0);
            sums[0] += at(it);
            sums[1] += at(lin);
            sums[2] += at(solve);
            sums[3] = sums[3].max(at(dofs));
            steps += 1;
        }
        Ok(Self {
            ranks: n,
            points: s["material_points"].as_f64().unwrap_or(0.0),
            dofs: sums[3],
            steps,
            newton: sums[0],
            krylov: sums[1],
            solve: sums[2],
            wall: s["wall_time_s"].as_f64().unwrap_or(0.0),
        })
    }
}

fn write_implicit(page: &mut String, rows: &[ImplicitRow]) -> Result<()> {
    writeln!(
        page,
        "## Implicit: the F-patch strip footing with PETSc over the processes\n\nGMRES + GAMG (`{PETSC}`), each process handing PETSc the entries of its own points. What grows with N at fixed points per rank is the Krylov iterations per Newton iteration: GAMG's aggregates and smoothers change with the partition and the problem grows.\n"
    )?;
    let mut table = Table::new([
        "N",
        "points",
        "free dofs (largest step)",
        "converged steps",
        "Newton iterations",
        "Krylov iterations per Newton iteration",
        "solve (s)",
        "wall (s)",
    ]);
    for r in rows {
        table.row(vec![
            r.ranks.to_string(),
            format!("{:.0}", r.points),
            format!("{:.0}", r.dofs),
            r.steps.to_string(),
            format!("{:.0}", r.newton),
            format!("{:.1}", r.krylov / r.newton.max(1.0)),
            format!("{:.2}", r.solve),
            format!("{:.2}", r.wall),
        ]);
    }
    writeln!(page, "{}", table.render())?;
    Ok(())
}

/// The explicit step's time on `n` ranks by the α–β model from the
/// per-step compute `t` and what the busiest rank sends at N = 4 (`at4`).
fn modelled(t: f64, at4: &ExplicitRow, n: f64) -> f64 {
    let halo = INTERIOR * (at4.messages * ALPHA + (at4.bytes + at4.migration_bytes) * BETA);
    let collectives = at4.collectives * 2.0 * n.log2().ceil() * ALPHA;
    t + halo + collectives
}

fn write_model(page: &mut String, rows: &[ExplicitRow]) -> Result<()> {
    let (Some(one), Some(at4)) = (rows.first(), rows.last()) else {
        return Ok(());
    };
    let t = one.point[1];
    writeln!(
        page,
        "## An α–β model of the explicit step\n\nA step on N ranks takes T(N) = t + g (m α + b β) + c · 2⌈log₂ N⌉ α: t the point work of a rank (measured on 1 process, {:.2} ms per step here, the same at fixed points per rank), m and b the messages and bytes the busiest rank sends per step (halo and migration, measured at N = 4: {:.2} messages, {:.0} bytes), c its collectives per step ({:.2}; each a reduction tree of ⌈log₂ N⌉ levels up and down), g = {INTERIOR} for a rank inside a large partition (all its perimeter cut, against the corner parts of N = 4), α = {:.0} µs and β = {:.1} ns per byte (stated, not measured here: an InfiniBand-class link of 10 GB/s; within one node MPI over shared memory is faster). The parallel efficiency is t / T(N).\n",
        1e3 * t,
        at4.messages,
        at4.bytes + at4.migration_bytes,
        at4.collectives,
        ALPHA * 1e6,
        BETA * 1e9,
    )?;
    let mut table = Table::new(["N", "T(N) per step (ms)", "efficiency"]);
    for n in [16.0, 64.0, 256.0] {
        let total = modelled(t, at4, n);
        table.row(vec![
            format!("{n:.0}"),
            format!("{:.3}", 1e3 * total),
            format!("{:.3}", t / total),
        ]);
    }
    writeln!(page, "{}", table.render())?;
    writeln!(
        page,
        "The collectives dominate the model's communication: the step's reductions (the stable time step, the energies, the agreed errors) cost latency, not bandwidth, and grow with log₂ N; the halo stays fixed per rank. The model leaves out load imbalance (the `rebalance_threshold` bounds it at 1.1 by default) and the contention of many ranks on a node's memory bandwidth, which the 2 processes × 1 thread against 1 process × 2 threads runs of [the ranks page](ranks_scenes.md) bound on this machine.\n"
    )?;
    Ok(())
}

/// A case of the strong-scaling plan.
struct StrongCase {
    name: &'static str,
    file: &'static str,
    set: &'static [&'static str],
    quick: &'static [&'static str],
}

const STRONG: [StrongCase; 3] = [
    StrongCase {
        name: "double-notched plate",
        file: "wang2021_notched_plate.toml",
        set: &["solver.steps=10", "mesh.motion.extension=1e-4"],
        quick: &[
            "mesh.cells=[2,4,1]",
            "solver.steps=4",
            "mesh.motion.extension=4e-5",
        ],
    },
    StrongCase {
        name: "footing",
        file: "wang2021_footing.toml",
        set: &["solver.steps=5"],
        quick: &["solver.steps=1"],
    },
    StrongCase {
        name: "full vane",
        file: "wang2021_vane_full.toml",
        set: &["solver.steps=4"],
        quick: &["solver.steps=1"],
    },
];

/// Points per element as Wang et al. (2021) Fig. 23: 1, 4 (Gauss) and 11
/// (Keast).
const PLACEMENTS: [(&str, &[&str]); 3] = [
    (
        "1",
        &["body.0.placement=\"regular\"", "body.0.points_per_cell=1"],
    ),
    ("4", &["body.0.placement=\"gauss4\""]),
    ("11", &["body.0.placement=\"keast11\""]),
];

/// The strong-scaling plan: writes `docs/src/benchmarks/strong_scaling.md`.
pub fn strong(max_ranks: usize, quick: bool, root: &Path, docs: &Path) -> Result<()> {
    let start = Instant::now();
    let exe = ranks::build(root)?;
    let scratch = std::env::temp_dir().join(format!("xtask-strong-{}", std::process::id()));
    let load = machine::load_average();
    let counts: Vec<usize> = std::iter::successors(Some(1usize), |n| Some(n * 2))
        .take_while(|&n| n <= max_ranks.max(1))
        .collect();
    let cases: &[StrongCase] = if quick { &STRONG[..1] } else { &STRONG };
    let mut page = String::new();
    writeln!(
        page,
        "# Strong scaling: the plan of Wang et al. (2021) Fig. 23\n"
    )?;
    let quick_flag = if quick { " --quick" } else { "" };
    let command = format!("scaling --strong --max-ranks {max_ranks}{quick_flag}");
    writeln!(
        page,
        "{}. F-patch, PETSc's GMRES + GAMG over the processes (`{PETSC}`), 1 thread per process; wall time of the solver (outputs excluded), speedup and efficiency against 1 process. On a node with 16 cores: `cargo xtask scaling --strong --max-ranks 16` (needs Open MPI and PETSc, README \"Distributed runs\").\n",
        machine::generated_by(&command, load),
    )?;
    for case in cases {
        let base = if quick { case.quick } else { case.set };
        let mut table = Table::new([
            "points per element",
            "points",
            "N",
            "wall (s)",
            "speedup",
            "efficiency",
            "Krylov iterations",
        ]);
        for (per_element, placement) in PLACEMENTS {
            let mut first = None;
            for &n in &counts {
                let set: Vec<String> = base
                    .iter()
                    .map(|s| (*s).to_owned())
                    .chain(["solver.locking=\"fpatch\"".to_owned(), PETSC.to_owned()])
                    .chain(placement.iter().map(|s| (*s).to_owned()))
                    .collect();
                let dir = scratch.join(format!("{}-{per_element}-{n}", case.file));
                run(&exe, root, case.file, &set, n, &dir)?;
                let row = ImplicitRow::read(n, &dir)?;
                let t1 = *first.get_or_insert(row.wall);
                table.row(vec![
                    per_element.to_owned(),
                    format!("{:.0}", row.points),
                    n.to_string(),
                    format!("{:.2}", row.wall),
                    format!("{:.2}", t1 / row.wall),
                    format!("{:.2}", t1 / row.wall / n as f64),
                    format!("{:.0}", row.krylov),
                ]);
            }
        }
        writeln!(
            page,
            "## {}\n\nOverrides: `{}`.\n",
            case.name,
            base.join("`, `")
        )?;
        writeln!(page, "{}", table.render())?;
    }
    std::fs::remove_dir_all(&scratch).ok();
    let page = machine::stamp_duration(page, start);
    let path = docs.join("benchmarks/strong_scaling.md");
    std::fs::write(&path, page).with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}
