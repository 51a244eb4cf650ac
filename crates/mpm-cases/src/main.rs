//! `mpm`: runs the benchmark cases and scene files.
//!
//! ```text
//! mpm list
//! mpm run scene.toml [--set key=value ...] [--out DIR] [--threads N]
//! mpm run --case column [--set key=value ...] [--out DIR] [--threads N]
//! mpm scene --case column [--set key=value ...] > column.toml
//! ```

use std::path::PathBuf;

use anyhow::{Context, Result, anyhow};
use clap::{Parser, Subcommand};
use mpm_cases::CasesError;
use mpm_cases::cases;
use mpm_cases::session::Session;
use mpm_cases::variant::BasisKind;
use mpm_dispatch::on_ranks::SharedRanks;
use mpm_solver::SolverError;
use mpm_solver::ranks::Ranks as _;

#[derive(Parser)]
#[command(
    name = "mpm",
    version,
    about = "Material point method (implicit quasi-static and explicit dynamic): benchmark cases and scene files"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the cases and their parameters (with defaults).
    List,
    /// Print a case's scene as a scene file (TOML), to start a scene file
    /// from a case: `mpm scene --case column --set h=1.5625 > my.toml`.
    Scene {
        /// The case.
        #[arg(long)]
        case: String,
        /// Override a case parameter, e.g. `--set h=1.5625 --set basis=gimp`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Run a scene file or a named case.
    Run {
        /// Scene file (TOML): a whole problem (`[mesh]`, `[[material]]`,
        /// `[[body]]`, ...; see docs/src/guide/scenes.md), or the
        /// parameters of the built-in case its `case` key names.
        scene: Option<PathBuf>,
        /// Case to run without a scene file.
        #[arg(long)]
        case: Option<String>,
        /// Override a scene key, e.g. `--set h=1.5625 --set basis=gimp`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Continue an interrupted run from the checkpoint in the output
        /// directory (written after every converged step); the scene and
        /// overrides must be the same as those of the interrupted run.
        #[arg(long)]
        resume: bool,
        /// Stop (with a checkpoint) after this many converged steps of this
        /// session, e.g. to split a long run into jobs; continue with
        /// `--resume`.
        #[arg(long, value_name = "N")]
        stop_after: Option<usize>,
        /// Write each step's last assembled stiffness over the free dofs
        /// as a Matrix Market file `tangent_NNNN.mtx` (for conditioning or
        /// eigenvalue studies in other tools).
        #[arg(long)]
        export_tangent: bool,
        /// Run on a pool of N threads (default: rayon's, one per core or
        /// RAYON_NUM_THREADS).
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
        threads: Option<u16>,
    },
}

fn main() {
    // MPI lives until the end of `main` (finalised when dropped).
    #[cfg(feature = "mpi")]
    let mpi = mpm_cases::distributed::mpi_ranks::Mpi::init();
    #[cfg(feature = "mpi")]
    let ranks = processes(&mpi);
    #[cfg(not(feature = "mpi"))]
    let ranks = None;
    if let Err(e) = run_cli(Cli::parse(), ranks.clone()) {
        let text = describe(&e);
        let message = match &ranks {
            Some(r) => format!("error (rank {} of {}): {text}\n", r.0.rank(), r.0.size()),
            None => format!("error: {text}\n"),
        };
        // One write, not one per formatted piece (stderr is unbuffered):
        // the processes of a job share mpirun's stderr, and pieces of their
        // messages would interleave.
        let _ = std::io::Write::write_all(&mut std::io::stderr().lock(), message.as_bytes());
        // A refusal every process reaches waits until every process has
        // said it: the first to exit makes mpirun end the others.
        if let (Some(r), Some(EveryProcess(_))) = (&ranks, e.downcast_ref()) {
            let _ = r.0.all_reduce(&mut [0.0], mpm_solver::ranks::Reduce::Sum);
        }
        // Without finalising: a rank that failed alone must not wait for
        // the others; mpirun ends the job.
        std::process::exit(1);
    }
}

/// `e` and its causes, each cause left out when the text before already
/// says it (most of our errors print their source in their own message).
fn describe(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let cause = cause.to_string();
        if !text.contains(&cause) {
            text.push_str(": ");
            text.push_str(&cause);
        }
    }
    text
}

/// An error every process of a job reaches from the same input (the
/// command line), before any communication.
#[derive(Debug)]
struct EveryProcess(String);

impl std::fmt::Display for EveryProcess {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for EveryProcess {}

/// The MPI processes this program was started on by `mpirun`, when more
/// than one.
#[cfg(feature = "mpi")]
fn processes(mpi: &mpm_cases::distributed::mpi_ranks::Mpi) -> Option<SharedRanks> {
    let ranks = mpi.ranks();
    // Counted: an explicit run's summary reports each rank's traffic.
    let counted = mpm_solver::ranks::Counted::new(ranks);
    (counted.size() > 1).then(|| SharedRanks(std::sync::Arc::new(counted)))
}

fn run_cli(cli: Cli, ranks: Option<SharedRanks>) -> Result<()> {
    match cli.command {
        Command::List => {
            use std::fmt::Write as _;
            let mut text = String::new();
            for case in &cases::ALL {
                writeln!(text, "{}: {}", case.name, case.about)?;
                for line in (case.defaults)()?.lines() {
                    writeln!(text, "    {line}")?;
                }
            }
            writeln!(
                text,
                "\nscene files without a `case` key describe a whole problem ([mesh], [[material]], [[body]], [[boundary]], [[load]], [[curve]], [solver], [output]), quasi-static or, with [solver] kind = \"explicit\", in time: see docs/src/guide/scenes.md and scenes/"
            )?;
            writeln!(
                text,
                "\nvariant values: basis = {}; formulation = ul | pc; domain_update = {}; gimp_volume = det_f | domain",
                BasisKind::ALL
                    .iter()
                    .map(|b| b.name())
                    .collect::<Vec<_>>()
                    .join(" | "),
                mpm_cases::variant::DomainUpdateKind::ALL
                    .iter()
                    .map(|d| d.name())
                    .collect::<Vec<_>>()
                    .join(" | ")
            )?;
            print(&text)
        }
        Command::Scene { case, set } => {
            let entry = find_case(&case)?;
            let scene = (entry.scene)(&set)?;
            print(&format!(
                "# The {case} case's scene (`mpm scene --case {case}{}`): {}.\n# `mpm run` runs this file as a scene, without the case's check against its reference.\n\n{scene}",
                set.iter()
                    .map(|s| format!(" --set {s}"))
                    .collect::<String>(),
                entry.about
            ))
        }
        Command::Run {
            scene,
            case,
            set,
            out,
            resume,
            stop_after,
            export_tangent,
            threads,
        } => {
            let (text, origin) = match &scene {
                Some(path) => (
                    std::fs::read_to_string(path)
                        .with_context(|| format!("cannot read scene file {}", path.display()))?,
                    path.display().to_string(),
                ),
                None => (String::new(), "command line".to_string()),
            };
            let scene_case = if scene.is_some() {
                let table: toml::Table =
                    toml::from_str(&text).map_err(|e| anyhow!("{origin}: {e}"))?;
                table
                    .get("case")
                    .and_then(|v| v.as_str())
                    .map(str::to_owned)
            } else {
                None
            };
            let is_scene = scene.is_some() && case.is_none() && scene_case.is_none();
            let name = if is_scene {
                "scene".to_owned()
            } else {
                case.or(scene_case).ok_or_else(|| {
                    anyhow!("no case: give --case NAME or a scene file with `case = \"...\"`")
                })?
            };
            if ranks.is_some() && !is_scene {
                return Err(EveryProcess(format!(
                    "the built-in cases run on one process; run a scene file on several (`mpm scene --case {name} > {name}.toml`)"
                ))
                .into());
            }
            let session = Session {
                ranks,
                case: name.clone(),
                out,
                resume,
                stop_after,
                export_tangent,
                scene_dir: scene
                    .as_deref()
                    .and_then(|p| p.parent())
                    .map(PathBuf::from)
                    .unwrap_or_default(),
            };
            let case = if is_scene {
                None
            } else {
                Some(find_case(&name)?)
            };
            let run = || match case {
                None => mpm_cases::scene::run_file(&text, &origin, &set, &session),
                Some(case) => (case.run)(&text, &origin, &set, &session),
            };
            let result = match threads {
                Some(n) => rayon::ThreadPoolBuilder::new()
                    .num_threads(usize::from(n))
                    .build()
                    .context("cannot start the thread pool")?
                    .install(run),
                None => run(),
            }
            .map_err(anyhow::Error::from);
            match result {
                Err(e) => match e.downcast_ref::<CasesError>() {
                    Some(CasesError::Solver(SolverError::Stopped { step, load_factor })) => {
                        println!(
                            "stopped after load step {step} at load factor {load_factor}; continue with --resume"
                        );
                        Ok(())
                    }
                    _ => Err(e),
                },
                ok => ok,
            }
        }
    }
}

/// The registered case `name`, or an error listing the cases.
fn find_case(name: &str) -> Result<&'static cases::CaseEntry> {
    cases::find(name).ok_or_else(|| {
        anyhow!(
            "unknown case `{name}`; cases: {}",
            cases::ALL
                .iter()
                .map(|c| c.name)
                .collect::<Vec<_>>()
                .join(", ")
        )
    })
}

/// Writes `text` to standard output; a closed pipe (`mpm list | head`) is
/// not an error.
fn print(text: &str) -> Result<()> {
    match std::io::Write::write_all(&mut std::io::stdout(), text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}
