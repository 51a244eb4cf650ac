//! `mpm`: runs the benchmark cases and scene files.
//!
//! ```text
//! mpm list
//! mpm run scene.toml [--set key=value ...] [--out DIR]
//! mpm run --case column [--set key=value ...] [--out DIR]
//! ```

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context, Result, anyhow, bail};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use mpm_cases::cases::{annulus, cantilever, collapse, column, shear, stretch};
use mpm_cases::checkpoint;
use mpm_cases::output::CellMesh;
use mpm_cases::run::{RunControl, Snapshot};
use mpm_cases::scene_file::parse_scene;
use mpm_cases::variant::{BasisKind, Variant};
use mpm_cases::writer::{RunWriter, Summary};
use mpm_solver::{ObserverError, SolverError, StepReport};
use serde::Serialize;
use serde_json::{Map, Value, json};

#[derive(Parser)]
#[command(
    name = "mpm",
    version,
    about = "Implicit material point method: benchmark cases and scene files"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the cases and their parameters (with defaults).
    List,
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
    },
}

/// A built-in case: its name, what it is, its parameters' defaults (as
/// TOML) and how it runs from the scene text. Adding a case is one module
/// in `mpm_cases::cases` and one line here.
struct CaseEntry {
    name: &'static str,
    about: &'static str,
    defaults: fn() -> Result<String, toml::ser::Error>,
    run: fn(&str, &str, &[String], &Run) -> Result<()>,
}

/// `run` of a case whose parameters deserialise from the scene.
macro_rules! case {
    ($name:literal, $about:literal, $params:ty, $run:expr) => {
        CaseEntry {
            name: $name,
            about: $about,
            defaults: || toml::to_string(&<$params>::default()),
            run: |text, origin, set, run| $run(parse_scene(text, origin, set)?, run),
        }
    };
}

const CASES: [CaseEntry; 6] = [
    case!(
        "column",
        "Coombs 2020 §7.1: elastic column compacting under self weight (analytic eq. 41, error eq. 42)",
        column::ColumnParams,
        |p, run| column_run(&p, run)
    ),
    case!(
        "shear",
        "Coombs 2020 §7.2: simple shear of a unit square, elastic or perfectly plastic (homogeneous)",
        shear::ShearParams,
        |p, run| shear_run(&p, run)
    ),
    case!(
        "cantilever",
        "Coombs 2020 §7.3: elastic cantilever under an end load (tip history, Newton residuals)",
        cantilever::CantileverParams,
        |p, run| cantilever_run(&p, run)
    ),
    case!(
        "annulus",
        "Coombs 2020 §7.4: elastic annulus under torsion on triangles (manufactured solution, Fig. 19)",
        annulus::AnnulusParams,
        annulus_run
    ),
    case!(
        "collapse",
        "Coombs 2020 §7.5: elasto-plastic collapse of a block (Tables 6-7)",
        collapse::CollapseParams,
        |p, run| collapse_run(&p, run)
    ),
    case!(
        "stretch",
        "Wang 2021 §5.3: simple stretch of a cube on tetrahedra with a moving mesh (Table 1)",
        stretch::StretchParams,
        stretch_run
    ),
];

fn main() {
    if let Err(e) = run_cli(Cli::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run_cli(cli: Cli) -> Result<()> {
    match cli.command {
        Command::List => {
            use std::fmt::Write as _;
            let mut text = String::new();
            for case in &CASES {
                writeln!(text, "{}: {}", case.name, case.about)?;
                for line in (case.defaults)()?.lines() {
                    writeln!(text, "    {line}")?;
                }
            }
            writeln!(
                text,
                "\nscene files without a `case` key describe a whole problem ([mesh], [[material]], [[body]], [[boundary]], [[load]], [[curve]], [solver], [output]): see docs/src/guide/scenes.md and scenes/"
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
            // A closed pipe (`mpm list | head`) is not an error.
            match std::io::Write::write_all(&mut std::io::stdout(), text.as_bytes()) {
                Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
                _ => Ok(()),
            }
        }
        Command::Run {
            scene,
            case,
            set,
            out,
            resume,
            stop_after,
            export_tangent,
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
            let run = Run {
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
            let result = if is_scene {
                scene_run(&text, &origin, &set, &run)
            } else {
                match CASES.iter().find(|c| c.name == name) {
                    Some(case) => (case.run)(&text, &origin, &set, &run),
                    None => bail!(
                        "unknown case `{name}`; cases: {}",
                        CASES.iter().map(|c| c.name).collect::<Vec<_>>().join(", ")
                    ),
                }
            };
            match result {
                Err(e) => match e.downcast_ref::<SolverError>() {
                    Some(SolverError::Stopped { step, load_factor }) => {
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

fn pad(basis: BasisKind) -> usize {
    usize::from(basis == BasisKind::BSpline2)
}

/// Where a run writes and whether it resumes.
struct Run {
    case: String,
    out: PathBuf,
    resume: bool,
    stop_after: Option<usize>,
    export_tangent: bool,
    /// Directory of the scene file: relative mesh paths start there.
    scene_dir: PathBuf,
}

impl Run {
    /// `path` taken from the scene file's directory when relative.
    fn resolve(&self, path: &mut Option<PathBuf>) {
        if let Some(p) = path
            && p.is_relative()
        {
            *p = self.scene_dir.join(&*p);
        }
    }

    /// The observer and the run control for a case with parameters `p`:
    /// checkpoints always; with `--resume`, the checkpoint of the output
    /// directory, which must have been written by the same case and
    /// parameters.
    fn start<const D: usize, M: CellMesh<D>, P: Serialize>(
        &self,
        p: &P,
        grid: M,
    ) -> Result<(Observer<D, M>, RunControl)> {
        let parameters = serde_json::to_value(p)?;
        let (writer, resume) = if self.resume {
            let (header, checkpoint) = checkpoint::read(&self.out)?;
            if header.case != self.case || header.parameters != parameters {
                bail!(
                    "--resume: {} was written by case `{}` with other parameters; run again without --resume, or with the scene and --set keys of that run",
                    self.out.join(checkpoint::FILE_NAME).display(),
                    header.case
                );
            }
            (
                RunWriter::resume(&self.out, grid, header.writer)?,
                Some(checkpoint),
            )
        } else {
            (RunWriter::new(&self.out, grid)?, None)
        };
        let control = RunControl {
            checkpoint: true,
            resume,
            export_tangent: self.export_tangent,
        };
        let mut observer = Observer::new(writer, self.case.clone(), parameters)?;
        observer.stop_after = self.stop_after;
        Ok((observer, control))
    }
}

/// Progress display and file output, called after every converged step.
struct Observer<const D: usize, M> {
    writer: RunWriter<D, M>,
    bar: ProgressBar,
    plain: bool,
    case: String,
    parameters: Value,
    stop_after: Option<usize>,
    steps: usize,
}

impl<const D: usize, M: CellMesh<D>> Observer<D, M> {
    fn new(writer: RunWriter<D, M>, case: String, parameters: Value) -> Result<Self> {
        let plain = !std::io::stderr().is_terminal();
        let bar = if plain {
            ProgressBar::hidden()
        } else {
            let bar = ProgressBar::new(1000);
            bar.set_style(
                ProgressStyle::with_template(
                    "{elapsed_precise} [{bar:30}] load {percent:>3}% {msg}",
                )
                .map_err(|e| anyhow!("{e}"))?
                .progress_chars("=> "),
            );
            bar.enable_steady_tick(Duration::from_millis(200));
            bar
        };
        Ok(Self {
            writer,
            bar,
            plain,
            case,
            parameters,
            stop_after: None,
            steps: 0,
        })
    }

    fn step(
        &mut self,
        step: usize,
        report: &StepReport<D>,
        snap: &Snapshot,
    ) -> Result<(), SolverError> {
        let residual = report.residuals.last().copied().unwrap_or(0.0);
        let line = format!(
            "step {} to load factor {:.4} (increment {:.3e}): {} iterations, residual {:.2e}",
            step + 1,
            report.lambda1,
            report.lambda1 - report.lambda0,
            report.iterations(),
            residual
        );
        if self.plain {
            eprintln!("{line}");
        } else {
            self.bar
                .set_position((report.lambda1 * 1000.0).round() as u64);
            self.bar.set_message(line);
        }
        let io = |e: mpm_cases::CasesError| SolverError::Observer(ObserverError::new(e));
        self.writer.step(step, report, snap).map_err(io)?;
        if let Some(c) = &snap.checkpoint {
            checkpoint::write(
                self.writer.dir(),
                &self.case,
                self.parameters.clone(),
                c,
                self.writer.state(),
            )
            .map_err(io)?;
        }
        self.steps += 1;
        if self.stop_after.is_some_and(|n| self.steps >= n) && report.lambda1 < 1.0 {
            self.bar.finish_and_clear();
            return Err(SolverError::Stopped {
                step: step + 1,
                load_factor: report.lambda1,
            });
        }
        Ok(())
    }

    fn finish<P: Serialize>(self, summary: Summary<P>) -> Result<()> {
        self.bar.finish_and_clear();
        self.writer.summary(&summary)?;
        println!(
            "{} [{} {} {} {}{}]: {} points, {} steps ({} cut), {} Newton iterations, {:.3} s{}",
            summary.case,
            summary.variant.basis,
            summary.variant.formulation,
            summary.variant.locking,
            summary.variant.domain_update,
            summary.variant.gimp_volume_note(),
            summary.material_points,
            summary.load_steps,
            summary.cut_steps,
            summary.newton_iterations,
            summary.wall_time_s,
            summary
                .error
                .map(|e| format!(", error {e:.4e}"))
                .unwrap_or_default()
        );
        Ok(())
    }
}

fn summary<const D: usize, P: Serialize>(
    case: &str,
    variant: Variant,
    points: usize,
    output: &mpm_cases::run::RunOutput<D>,
    error: Option<f64>,
    results: Map<String, Value>,
    parameters: P,
) -> Summary<P> {
    Summary {
        case: case.to_string(),
        variant: variant.resolved(),
        material_points: points,
        load_steps: output.summary.steps,
        cut_steps: output.summary.cut_steps,
        newton_iterations: output.summary.iterations,
        wall_time_s: output.wall_time_s,
        error,
        results,
        parameters,
    }
}

fn column_run(p: &column::ColumnParams, run: &Run) -> Result<()> {
    let (grid, _, _) = column::geometry(p, pad(p.basis))?;
    let (mut obs, control) = run.start(p, grid)?;
    let r = column::run(p, &p.variant(), &control, |s, rep, snap| {
        obs.step(s, rep, snap)
    })?;
    let s = summary(
        "column",
        p.variant(),
        r.material_points,
        &r.output,
        Some(r.error),
        Map::new(),
        p,
    );
    obs.finish(s)
}

fn shear_run(p: &shear::ShearParams, run: &Run) -> Result<()> {
    let grid = shear::grid(p, pad(p.basis))?;
    let (mut obs, control) = run.start(p, grid)?;
    let r = shear::run(p, &p.variant(), &control, |s, rep, snap| {
        obs.step(s, rep, snap)
    })?;
    let s = summary(
        "shear",
        p.variant(),
        r.material_points,
        &r.output,
        Some(r.error),
        Map::new(),
        p,
    );
    obs.finish(s)
}

fn cantilever_run(p: &cantilever::CantileverParams, run: &Run) -> Result<()> {
    let (grid, _, _, loaded) = cantilever::geometry(p, pad(p.basis))?;
    let (mut obs, control) = run.start(p, grid)?;
    let r = cantilever::run(p, &p.variant(), &control, |s, rep, snap| {
        // The case table first: the step's checkpoint must hold its row.
        let (ux, uy) = cantilever::tip_displacement(snap, loaded);
        obs.writer
            .case_row(
                "tip.csv",
                &["load_factor", "tip_u_over_l0", "tip_v_over_l0"],
                &[
                    rep.lambda1.into(),
                    (ux / p.length).into(),
                    (uy / p.length).into(),
                ],
            )
            .map_err(|e| SolverError::Observer(ObserverError::new(e)))?;
        obs.step(s, rep, snap)
    })?;
    let mut results = Map::new();
    if let Some((_, ux, uy)) = r.tip.last() {
        results.insert("tip_displacement".into(), json!([ux, uy]));
    }
    let s = summary(
        "cantilever",
        p.variant(),
        r.material_points,
        &r.output,
        None,
        results,
        p,
    );
    obs.finish(s)
}

fn collapse_run(p: &collapse::CollapseParams, run: &Run) -> Result<()> {
    let (grid, _, _) = collapse::geometry(p, pad(p.basis))?;
    let (mut obs, control) = run.start(p, grid)?;
    let r = collapse::run(p, &p.variant(), &control, |s, rep, snap| {
        obs.step(s, rep, snap)
    })?;
    let mut results = Map::new();
    results.insert("horizontal_extent".into(), json!(r.horizontal_extent));
    results.insert("max_height".into(), json!(r.max_height));
    let s = summary(
        "collapse",
        p.variant(),
        r.material_points,
        &r.output,
        None,
        results,
        p,
    );
    obs.finish(s)
}

fn annulus_run(mut p: annulus::AnnulusParams, run: &Run) -> Result<()> {
    run.resolve(&mut p.mesh);
    let mesh = annulus::mesh(&p)?;
    let (mut obs, control) = run.start(&p, mesh)?;
    let r = annulus::run(&p, &p.variant(), &control, |s, rep, snap| {
        obs.step(s, rep, snap)
    })?;
    let mut results = Map::new();
    results.insert("max_error".into(), json!(r.max_error));
    results.insert("elements".into(), json!(r.elements));
    results.insert("element_size".into(), json!(r.element_size));
    let s = summary(
        "annulus",
        p.variant(),
        r.material_points,
        &r.output,
        Some(r.error),
        results,
        &p,
    );
    obs.finish(s)
}

fn stretch_run(mut p: stretch::StretchParams, run: &Run) -> Result<()> {
    run.resolve(&mut p.mesh);
    let mesh = stretch::mesh(&p)?;
    let (mut obs, control) = run.start(&p, mesh)?;
    let r = stretch::run(&p, &p.variant(), &control, |s, rep, snap| {
        obs.step(s, rep, snap)
    })?;
    let mut results = Map::new();
    results.insert("analytic_stress".into(), json!(r.analytic_stress));
    results.insert("tau_yy_mean".into(), json!(r.tau_yy.0));
    results.insert("tau_yy_min".into(), json!(r.tau_yy.1));
    results.insert("tau_yy_max".into(), json!(r.tau_yy.2));
    results.insert("elements".into(), json!(r.elements));
    let s = summary(
        "stretch",
        p.variant(),
        r.material_points,
        &r.output,
        Some(r.error),
        results,
        &p,
    );
    obs.finish(s)
}

/// A scene file describing a whole problem (no `case` key).
fn scene_run(text: &str, origin: &str, set: &[String], run: &Run) -> Result<()> {
    let (scene, source) = mpm_cases::scene::parse(text, origin, set)?;
    match mpm_cases::scene::dimension(&scene, &source)? {
        2 => scene_run_in::<2>(&scene, &source, run),
        _ => scene_run_in::<3>(&scene, &source, run),
    }
}

fn scene_run_in<const D: usize>(
    scene: &mpm_cases::scene::Scene,
    source: &mpm_cases::scene_file::SceneSource,
    run: &Run,
) -> Result<()> {
    use mpm_cases::scene::Problem;

    let problem =
        Problem::<D>::build_in(scene, source, scene.solver.basis.padding(), &run.scene_dir)?;
    match &problem.mesh {
        mpm_cases::scene::build::SceneMesh::Grid(g) => {
            scene_run_on(scene, &problem, run, g.clone())
        }
        mpm_cases::scene::build::SceneMesh::Simplex(m) => {
            scene_run_on(scene, &problem, run, (**m).clone())
        }
    }
}

/// Runs a built scene, writing its results on the mesh `mesh`.
fn scene_run_on<const D: usize, M: CellMesh<D>>(
    scene: &mpm_cases::scene::Scene,
    problem: &mpm_cases::scene::Problem<D>,
    run: &Run,
    mesh: M,
) -> Result<()> {
    use mpm_cases::output::CsvValue;
    use mpm_cases::writer::VtuOptions;

    let (mut obs, control) = run.start(scene, mesh)?;
    obs.writer.set_vtu_options(VtuOptions {
        every: problem.every,
        fields: problem.fields.clone(),
        constants: vec![
            (
                "body".into(),
                problem
                    .body_of_point
                    .iter()
                    .map(|&b| f64::from(b))
                    .collect(),
            ),
            (
                "material".into(),
                problem
                    .material_of_point
                    .iter()
                    .map(|&m| f64::from(m))
                    .collect(),
            ),
        ],
    });
    let axes = ["x", "y", "z"];
    let reaction_header: Vec<String> = std::iter::once("load_factor".to_owned())
        .chain(axes.iter().take(D).map(|a| format!("reaction_{a}")))
        .collect();
    let probe_header: Vec<String> = std::iter::once("load_factor".to_owned())
        .chain(axes.iter().take(D).map(|a| format!("u{a}")))
        .collect();
    let mut last_reactions = Map::new();
    let mut last_probes = Map::new();
    let r = mpm_cases::scene::run(problem, &control, |s, rep, snap| {
        let io = |e: mpm_cases::CasesError| SolverError::Observer(ObserverError::new(e));
        for (name, nodes) in &problem.reactions {
            let total = rep
                .node_reactions
                .iter()
                .filter(|(v, _)| nodes.binary_search(v).is_ok())
                .fold(nalgebra::SVector::<f64, D>::zeros(), |t, (_, r)| t + r);
            let mut row = vec![CsvValue::from(rep.lambda1)];
            row.extend(total.iter().map(|x| CsvValue::from(*x)));
            let header: Vec<&str> = reaction_header.iter().map(String::as_str).collect();
            obs.writer
                .case_row(&format!("reaction_{name}.csv"), &header, &row)
                .map_err(io)?;
            last_reactions.insert(name.clone(), json!(total.as_slice()));
        }
        for (name, p) in &problem.probes {
            let u = &snap.displacement[*p][..D];
            let mut row = vec![CsvValue::from(rep.lambda1)];
            row.extend(u.iter().map(|x| CsvValue::from(*x)));
            let header: Vec<&str> = probe_header.iter().map(String::as_str).collect();
            obs.writer
                .case_row(&format!("probe_{name}.csv"), &header, &row)
                .map_err(io)?;
            last_probes.insert(name.clone(), json!(u));
        }
        obs.step(s, rep, snap)
    })?;
    let mut results = Map::new();
    results.insert("reactions".into(), Value::Object(last_reactions));
    results.insert("probes".into(), Value::Object(last_probes));
    results.insert(
        "bodies".into(),
        json!(
            problem
                .bodies
                .iter()
                .map(|b| json!({"name": b.name, "material_points": b.points.len()}))
                .collect::<Vec<_>>()
        ),
    );
    if problem.png {
        let last = &r.last;
        let plastic = last.plastic_strain.iter().any(|&e| e > 0.0);
        let (name, value): (&str, Vec<f64>) = if plastic {
            ("equivalent_plastic_strain", last.plastic_strain.clone())
        } else {
            (
                "displacement_magnitude",
                last.displacement
                    .iter()
                    .map(|u| (u[0] * u[0] + u[1] * u[1]).sqrt())
                    .collect(),
            )
        };
        let half: Vec<f64> = problem
            .half_lengths
            .iter()
            .zip(&last.volume)
            .zip(&problem.volume)
            .map(|((l, v), v0)| l[0] * (v / v0).sqrt())
            .collect();
        let path = obs.writer.dir().join("final.png");
        let (lo, hi) =
            mpm_cases::scene::png::write_points_png(&path, &last.position, &half, &value)?;
        results.insert(
            "png".into(),
            json!({"file": "final.png", "colour": name, "blue": lo, "red": hi}),
        );
    }
    let s = summary(
        "scene",
        problem.variant,
        problem.len(),
        &r,
        None,
        results,
        scene,
    );
    obs.finish(s)
}
