//! Developer tasks, run as `cargo xtask <task>` (the alias builds in
//! release, so the timings on the pages it writes are those of the
//! command it prints).
//!
//! - `reproduce coombs2020 [--full] [--kmax K]`: the reproduction report of
//!   Coombs et al. (2020) — column convergence per domain-update rule
//!   (Fig. 7), error against run time, collapse extent and height (Tables
//!   6, 7), Newton residuals (Tables 3, 8) and the cantilever against the
//!   elastica (Figs. 13, 15, 17), the annulus on unstructured triangles
//!   (Fig. 19) — written to
//!   `docs/src/reproduction/coombs2020.md` with PNG plots in
//!   `docs/src/reproduction/img/` ([`coombs2020`]).
//! - `reproduce wang2021 [--full]`: the simple stretch on tetrahedra with a
//!   moving mesh (Table 1, standard MPM and F-patch), the small-deformation
//!   footing in 3D (§5.1, Fig. 8C), the elastic indentation (§5.2,
//!   Fig. 11C), the double-notched plate (§5.4, Figs. 15C, 16), the vane
//!   slice and the full vane (§5.5–5.6, Figs. 18C, 20C, 21) and point
//!   location by walking against brute force (§5.7), written to
//!   `docs/src/reproduction/wang2021.md` ([`wang2021`], [`footing3d`],
//!   [`indentation`], [`plate`], [`vane`]).
//! - `reproduce locking`: Cook's membrane against refinement for standard
//!   MPM, F-patch and F-bar, written to `docs/src/reproduction/locking.md`
//!   ([`locking`]).
//! - `stability [--quick]`: the stiff and extreme cases of issue 16, a
//!   matrix of scenario × variant with measured outcomes, written to
//!   `docs/src/reproduction/stability.md` ([`stability`]).
//! - `report [--quick]`: every case with an analytic or published
//!   reference, every variant that applies, error and wall time over a
//!   refinement series, the cheapest variant per accuracy level and the
//!   observed orders (issue 16), written to
//!   `docs/src/reproduction/report.md` with a PNG per case ([`report`]).
//! - `column-table`: error and solver time of the column for standard MPM
//!   and GIMP (eq. 34), written to `docs/src/benchmarks/column.md`
//!   ([`column_table`]).
//! - `linear-petsc [--full]`: the full vane's linear solves by our
//!   ILU(0)/BiCGSTAB and by PETSc's preconditioners, written to
//!   `docs/src/benchmarks/petsc.md` ([`petsc`]; xtask built with
//!   `--features petsc`).
//! - `structure [--deny]`: functions over 150 lines and import circles
//!   between files ([`structure`]).
//! - `reference-values`: reruns the cases of `mpm-cases` with the settings
//!   of its tests and writes the committed regression values
//!   `crates/mpm-cases/tests/reference_values/*.json` (column, cantilever,
//!   collapse, annulus, stretch), which
//!   `crates/mpm-cases/tests/regression.rs` checks ([`reference_values`]).

mod column_table;
mod coombs2020;
mod footing3d;
mod indentation;
mod locking;
mod machine;
mod markdown;
mod mpoint;
mod petsc;
mod plate;
mod plot;
mod ranks;
mod reference_values;
mod report;
mod scaling;
mod scene_run;
mod stability;
mod structure;
mod vane;
mod wang2021;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

const USAGE: &str = "usage: cargo run --release -p xtask -- <task>

tasks:
  reproduce coombs2020 [--full] [--kmax K]
                Coombs et al. (2020): column convergence (Fig. 7), error against
                run time, collapse (Tables 6-8), cantilever (Figs. 13-17, Table 3),
                annulus on unstructured triangles (Fig. 19); writes
                docs/src/reproduction/coombs2020.md and its PNG plots.
                --full   adds the collapse with h = 0.25 m (Table 6) and 6², 8²
                         points per triangle on the finest annulus meshes (slow)
                --kmax K refines the column to h = 50/2^K (2..=9, default 7)
  reproduce wang2021 [--full]
                Wang et al. (2021): simple stretch on tetrahedra (Table 1, standard
                MPM and F-patch), small-deformation footing in 3D (§5.1, Fig. 8C),
                walking point location (§5.7); writes docs/src/reproduction/wang2021.md
                and its PNG. --full adds 16 subdivisions and runs the footing on the
                scene's 6 x 6 x 6 mesh (4 x 4 x 4 otherwise).
  reproduce locking
                Cook's membrane (plane strain, nu = 0.3 and 0.4999, small and full
                load) for standard MPM, F-patch and F-bar against refinement;
                writes docs/src/reproduction/locking.md and its PNG plots.
  reproduce mpoint [--full]
                the explicit solver (MPoint theory notes): vibrating bar in h and dt,
                energy by transfer, colliding disks, cell-averaged dilatation,
                dynamic collapse, elastic-cube throughput on 1 and 2 threads;
                writes docs/src/reproduction/mpoint.md and its PNG plots.
                --full adds the 128^3 cube.
  stability [--quick]
                the stiff and extreme cases (issue 16): nu x locking x formulation,
                stiffness contrast 1e6, 10x/100x load steps, 360 degree rotation per
                domain rule, stretches 0.05/20, points leaving the grid, inversion,
                explicit dt beyond CFL, impacts, degenerate Gmsh meshes; writes
                docs/src/reproduction/stability.md and stability.json.
                --quick  the coarse matrix of the test suite
  report [--quick]
                every case with an analytic or published reference (column, shear,
                annulus, stretch, Cook's membrane, Prandtl footing, vibrating bar,
                colliding disks) over every variant that applies: error and wall time
                per refinement level, error-against-time PNG per case, the fastest run
                reaching each error level, observed convergence orders; writes
                docs/src/reproduction/report.md and img/report-*.png (about 8 min).
                --quick  coarse levels and a few variants per case (about a minute)
  column-table  error and run time of the column case, written to
                docs/src/benchmarks/column.md
  reference-values
                reruns the cases with the settings of the tests and writes the
                committed regression values crates/mpm-cases/tests/reference_values/
                (*.json, one per case) that tests/regression.rs compares against
  linear-petsc [--full]
                the full vane with F-patch solved by our ILU(0)/BiCGSTAB and by PETSc's
                GAMG, BoomerAMG and block Jacobi (xtask built with --features petsc);
                writes docs/src/benchmarks/petsc.md. --full: the paper's mesh (slow)
  ranks [--quick]
                a scene on 2 MPI processes against 1 process with 1 and 2 threads
                (mpirun -n 2 mpm run): the explicit column at 200,704 points and the
                F-patch notched plate, solver time per stage, repeated and
                interleaved; builds mpm with --features mpi, needs Open MPI; writes
                docs/src/benchmarks/ranks_scenes.md (about 3 min; --quick: small)
  scaling [--quick]
                weak scaling at N = 1, 2, 4 processes (fixed points per rank): the
                explicit column's per-rank work, halo and migration traffic and
                collectives, the F-patch footing's Krylov iterations with PETSc, and
                an α–β model of the explicit step at 16, 64, 256 ranks; writes
                docs/src/benchmarks/scaling.md (builds mpm with --features mpi,petsc)
  scaling --strong [--max-ranks N] [--quick]
                the strong-scaling plan of Wang et al. (2021) Fig. 23: plate, footing
                and full vane with F-patch at 1, 4, 11 points per element on 1, 2, 4,
                ... N processes (default 16), PETSc over them; writes
                docs/src/benchmarks/strong_scaling.md (--quick: the plate, small)
  structure [--deny]
                functions over 150 lines and import circles between files in every
                crate's src/ (tests left out); --deny fails on any
  help          this message";

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        None | Some("help" | "--help" | "-h") => {
            println!("{USAGE}");
            Ok(())
        }
        Some("stability") => {
            let mode = match &args[1..] {
                [] => stability::Mode::Full,
                [flag] if flag == "--quick" => stability::Mode::Quick,
                [other, ..] => bail!("unexpected argument `{other}` (expected --quick)"),
            };
            stability::run(&docs_dir(), mode)
        }
        Some("report") => {
            let mode = match &args[1..] {
                [] => report::Mode::Full,
                [flag] if flag == "--quick" => report::Mode::Quick,
                [other, ..] => bail!("unexpected argument `{other}` (expected --quick)"),
            };
            report::run(&docs_dir(), mode)
        }
        Some("ranks") => {
            let quick = flag(&args[1..], "--quick")?;
            ranks::run(quick, &workspace_dir(), &docs_dir())
        }
        Some("scaling") => scaling_command(&args[1..]),
        Some("structure") => {
            let deny = flag(&args[1..], "--deny")?;
            structure::run(&workspace_dir(), deny)
        }
        Some("linear-petsc") => {
            let full = flag(&args[1..], "--full")?;
            petsc::linear_petsc(full, &workspace_dir())
        }
        Some("column-table") => {
            no_more_arguments(&args[1..])?;
            column_table::run(&docs_dir())
        }
        Some("reference-values") => {
            no_more_arguments(&args[1..])?;
            reference_values::run(&workspace_dir())
        }
        Some("reproduce") => match args.get(1).map(String::as_str) {
            Some("coombs2020") => {
                let options = coombs2020::Options::parse(&args[2..])?;
                coombs2020::run(&options, &docs_dir())
            }
            Some("wang2021") => {
                let full = flag(&args[2..], "--full")?;
                wang2021::run_report(full, &docs_dir())
            }
            Some("locking") => {
                no_more_arguments(&args[2..])?;
                locking::run(&docs_dir())
            }
            Some("mpoint") => {
                let full = flag(&args[2..], "--full")?;
                mpoint::run(full, &docs_dir())
            }
            Some(other) => {
                bail!("unknown paper `{other}`; known: coombs2020, wang2021, locking, mpoint")
            }
            None => {
                bail!("`reproduce` needs a paper: `reproduce coombs2020` or `reproduce wang2021`")
            }
        },
        Some(other) => bail!("unknown task `{other}`\n\n{USAGE}"),
    }
}

/// Whether the task's only optional argument `name` (`--full`) is given;
/// anything else is refused.
fn flag(rest: &[String], name: &str) -> Result<bool> {
    match rest {
        [] => Ok(false),
        [given] if given == name => Ok(true),
        [other, ..] => bail!("unexpected argument `{other}` (expected {name})"),
    }
}

/// Fails on arguments a task does not take.
fn no_more_arguments(rest: &[String]) -> Result<()> {
    match rest.first() {
        None => Ok(()),
        Some(a) => bail!("unexpected argument `{a}`\n\n{USAGE}"),
    }
}

/// The mdBook sources, `docs/src` of the workspace.
fn docs_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/src")
}

/// The workspace root.
fn workspace_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Writes `contents` to `path`, creating its folder.
fn write_file(path: &Path, contents: impl AsRef<[u8]>) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    std::fs::write(path, contents).with_context(|| format!("writing {}", path.display()))
}

/// `scaling [--strong] [--max-ranks N] [--quick]`.
fn scaling_command(args: &[String]) -> Result<()> {
    let (mut strong, mut quick, mut max_ranks) = (false, false, 16);
    let mut rest = args.iter();
    while let Some(a) = rest.next() {
        match a.as_str() {
            "--strong" => strong = true,
            "--quick" => quick = true,
            "--max-ranks" => {
                let n = rest.next().context("--max-ranks needs a number")?;
                max_ranks = n
                    .parse()
                    .with_context(|| format!("--max-ranks {n}: not a number"))?;
            }
            other => {
                bail!("unexpected argument `{other}` (expected --strong, --max-ranks N or --quick)")
            }
        }
    }
    if strong {
        scaling::strong(max_ranks, quick, &workspace_dir(), &docs_dir())
    } else {
        scaling::weak(quick, &workspace_dir(), &docs_dir())
    }
}
