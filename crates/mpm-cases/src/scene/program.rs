//! The `mpm` program's run of a whole-problem scene file.

use serde_json::{Map, Value, json};

use mpm_dispatch::on_ranks::{RankRun, SharedRanks, WritePiece};

use crate::CasesError;
use crate::output::CellMesh;
use crate::run::RunControl;
use crate::session::{Session, observer_error, summary};
use crate::writer::VtuOptions;

/// A scene file describing a whole problem (no `case` key).
/// Runs a scene file's text (`origin` names it in errors) with the
/// overrides `set` in `session`: builds the problem, solves it, writes
/// the reaction and probe histories, the VTU series, `final.png` when
/// asked for, and `summary.json`.
///
/// # Errors
/// A scene that is refused (with its location), solver and output errors.
pub fn run_file(
    text: &str,
    origin: &str,
    set: &[String],
    session: &Session,
) -> Result<(), CasesError> {
    let (scene, source) = crate::scene::parse(text, origin, set)?;
    match crate::scene::dimension(&scene, &source)? {
        2 => scene_run_in::<2>(&scene, &source, session),
        _ => scene_run_in::<3>(&scene, &source, session),
    }
}

fn scene_run_in<const D: usize>(
    scene: &crate::scene::Scene,
    source: &crate::scene_file::SceneSource,
    session: &Session,
) -> Result<(), CasesError>
where
    crate::scene::Problem<D>: crate::scene::RunScene<D> + crate::scene::RunExplicit<D>,
{
    use crate::scene::Problem;

    let problem =
        Problem::<D>::build_in(scene, source, scene.solver.padding(), &session.scene_dir)?;
    // Once per job, not once per process.
    let root = session.ranks.as_ref().is_none_or(|r| r.0.rank() == 0);
    for w in problem.warnings.iter().filter(|_| root) {
        eprintln!("warning: {}: {w}", source.origin());
    }
    if let Some(shared) = &session.ranks {
        if let Some(table) = &scene.strength_reduction {
            return Err(source
                .at(
                    table,
                    "strength_reduction runs on one process: run it without mpirun",
                )
                .into());
        }
        let Some(run) = on_ranks(&problem, session, shared)? else {
            return Ok(());
        };
        if problem.explicit.is_some() {
            return match &problem.mesh {
                crate::scene::build::SceneMesh::Grid(g) => {
                    explicit_run_on(scene, &problem, session, g.clone(), Some(run))
                }
                crate::scene::build::SceneMesh::Simplex(_) => Err(source
                    .error(None, "the explicit solver runs on regular grids")
                    .into()),
            };
        }
        return match &problem.mesh {
            crate::scene::build::SceneMesh::Grid(g) => {
                scene_run_on(scene, &problem, session, g.clone(), Some(run))
            }
            crate::scene::build::SceneMesh::Simplex(m) => {
                scene_run_on(scene, &problem, session, (**m).clone(), Some(run))
            }
        };
    }
    if problem.explicit.is_some() {
        if session.export_tangent {
            return Err(CasesError::from(source.error(
                None,
                "--export-tangent writes the implicit solver's stiffness; an explicit run assembles none",
            )));
        }
        return match &problem.mesh {
            crate::scene::build::SceneMesh::Grid(g) => {
                explicit_run_on(scene, &problem, session, g.clone(), None)
            }
            crate::scene::build::SceneMesh::Simplex(_) => Err(source
                .error(None, "the explicit solver runs on regular grids")
                .into()),
        };
    }
    if let Some(sr) = &problem.strength_reduction {
        return strength_reduction_on(scene, source, &problem, session, sr);
    }
    match &problem.mesh {
        crate::scene::build::SceneMesh::Grid(g) => {
            scene_run_on(scene, &problem, session, g.clone(), None)
        }
        crate::scene::build::SceneMesh::Simplex(m) => {
            scene_run_on(scene, &problem, session, (**m).clone(), None)
        }
    }
}

/// The trials of a scene with `[strength_reduction]` on one process.
fn strength_reduction_on<const D: usize>(
    scene: &crate::scene::Scene,
    source: &crate::scene_file::SceneSource,
    problem: &crate::scene::Problem<D>,
    session: &Session,
    sr: &crate::scene::build::StrengthReduction,
) -> Result<(), CasesError>
where
    crate::scene::Problem<D>: crate::scene::RunScene<D>,
{
    if session.resume || session.stop_after.is_some() || session.export_tangent {
        return Err(source
            .error(
                None,
                "strength_reduction: trials restart from the initial state; --resume, --stop-after and --export-tangent do not apply",
            )
            .into());
    }
    use super::strength_reduction::run;
    match &problem.mesh {
        crate::scene::build::SceneMesh::Grid(g) => run(scene, problem, session, g.clone(), sr),
        crate::scene::build::SceneMesh::Simplex(m) => {
            run(scene, problem, session, (**m).clone(), sr)
        }
    }
}

/// The deal of `problem` over the session's ranks, for rank 0 to run
/// and write; `None` on the other ranks, which take their part of the run
/// here and write nothing.
///
/// # Errors
/// The deal's, and the run's on the other ranks: they resume from the
/// checkpoint rank 0 wrote, and end without error when rank 0 stops the
/// run after `--stop-after` steps or outputs.
fn on_ranks<const D: usize>(
    problem: &crate::scene::Problem<D>,
    session: &Session,
    shared: &SharedRanks,
) -> Result<Option<RankRun>, CasesError>
where
    crate::scene::Problem<D>: crate::scene::RunScene<D> + crate::scene::RunExplicit<D>,
{
    let explicit = problem.explicit.is_some();
    let mut run = super::ranks::rank_run(problem, shared.0.clone())?;
    run.pieces = Some(piece_writer(problem, session, explicit));
    if run.is_root() {
        return Ok(Some(run));
    }
    let resume = if session.resume {
        Some(crate::checkpoint::read(&session.out)?.1)
    } else {
        None
    };
    let control = RunControl {
        ranks: Some(run),
        // Rank 0 keeps checkpoints; the points are joined for them at
        // every step or output, by every rank.
        checkpoint: true,
        resume,
        external_linear: mpm_distributed::external_linear(),
        ..RunControl::default()
    };
    let result = if explicit {
        crate::scene::run_explicit(problem, &control, |_| Ok(())).map(|_| ())
    } else {
        crate::scene::run(problem, &control, |_, _, _| Ok(())).map(|_| ())
    };
    match result {
        Err(mpm_solver::SolverError::Rank { rank: 0, message })
            if session.stop_after.is_some() && message.starts_with("stopped after load step") =>
        {
            Ok(None)
        }
        other => other.map(|()| None).map_err(CasesError::from),
    }
}

/// Runs a built scene, writing its results on the mesh `mesh`; on rank 0
/// of a run on several ranks with `ranks`, its deal.
fn scene_run_on<const D: usize, M: CellMesh<D>>(
    scene: &crate::scene::Scene,
    problem: &crate::scene::Problem<D>,
    session: &Session,
    mesh: M,
    ranks: Option<RankRun>,
) -> Result<(), CasesError>
where
    crate::scene::Problem<D>: crate::scene::RunScene<D>,
{
    use crate::output::CsvValue;

    let (mut obs, mut control) = session.start(scene, mesh)?;
    obs.writer
        .set_pieces(ranks.as_ref().map_or(0, |r| r.ranks.size()));
    control.ranks = ranks;
    obs.writer.set_vtu_options(vtu_options(problem, false));
    let axes = ["x", "y", "z"];
    let reaction_header: Vec<String> = std::iter::once("load_factor".to_owned())
        .chain(axes.iter().take(D).map(|a| format!("reaction_{a}")))
        .collect();
    let probe_header: Vec<String> = std::iter::once("load_factor".to_owned())
        .chain(axes.iter().take(D).map(|a| format!("u{a}")))
        .collect();
    let mut last_reactions = Map::new();
    let mut last_probes = Map::new();
    let r = crate::scene::run(problem, &control, |s, rep, snap| {
        let io = observer_error;
        for reaction in &problem.reactions {
            let total = reaction.total(rep);
            let mut row = vec![CsvValue::from(rep.lambda1)];
            row.extend(total.iter().map(|x| CsvValue::from(*x)));
            let mut header: Vec<&str> = reaction_header.iter().map(String::as_str).collect();
            let moment = reaction.moment(problem, rep);
            if let Some(m) = moment {
                if D == 2 {
                    header.push("moment");
                    row.push(CsvValue::from(m[2]));
                } else {
                    header.extend(["moment_x", "moment_y", "moment_z"]);
                    row.extend(m.iter().map(|x| CsvValue::from(*x)));
                }
            }
            obs.writer
                .case_row(&format!("reaction_{}.csv", reaction.name), &header, &row)
                .map_err(io)?;
            let mut entry = json!(total.as_slice());
            if let Some(m) = moment {
                entry = json!({"force": total.as_slice(), "moment": if D == 2 { json!(m[2]) } else { json!(m) }});
            }
            last_reactions.insert(reaction.name.clone(), entry);
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
    let mut results = scene_results(problem, last_probes, &r.last, obs.writer.dir())?;
    results.insert("reactions".into(), Value::Object(last_reactions));
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

/// The `results` of a scene's `summary.json` shared by both solvers: the
/// last probe values, the bodies with their point counts and, when asked
/// for, `final.png` of the final state `last` written in `dir`.
fn scene_results<const D: usize>(
    problem: &crate::scene::Problem<D>,
    last_probes: Map<String, Value>,
    last: &crate::run::Snapshot,
    dir: &std::path::Path,
) -> Result<Map<String, Value>, CasesError> {
    let mut results = Map::new();
    results.insert("probes".into(), Value::Object(last_probes));
    if !problem.warnings.is_empty() {
        results.insert("warnings".into(), json!(problem.warnings));
    }
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
        results.insert("png".into(), write_png(problem, last, dir)?);
    }
    Ok(results)
}

/// `final.png` of the final state `last` in `dir`: the points coloured by
/// the equivalent plastic strain if any point yielded, else by the
/// displacement magnitude; returns its `summary.json` entry.
fn write_png<const D: usize>(
    problem: &crate::scene::Problem<D>,
    last: &crate::run::Snapshot,
    dir: &std::path::Path,
) -> Result<Value, CasesError> {
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
    points_png(
        problem,
        "final.png",
        name,
        (&last.position, &last.volume),
        &value,
        dir,
    )
}

/// `dir/file` of the points at `position` with volumes `volume` (each
/// drawn as a square of its domain's size scaled with its volume)
/// coloured by `value`; returns its `summary.json` entry (`colour` names
/// the value).
pub(super) fn points_png<const D: usize>(
    problem: &crate::scene::Problem<D>,
    file: &str,
    colour: &str,
    (position, volume): (&[[f64; 3]], &[f64]),
    value: &[f64],
    dir: &std::path::Path,
) -> Result<Value, CasesError> {
    let half: Vec<f64> = problem
        .half_lengths
        .iter()
        .zip(volume)
        .zip(&problem.volume)
        .map(|((l, v), v0)| l[0] * (v / v0).sqrt())
        .collect();
    let (lo, hi) = crate::scene::png::write_points_png(&dir.join(file), position, &half, value)?;
    Ok(json!({"file": file, "colour": colour, "blue": lo, "red": hi}))
}

/// The per-point constants of the VTU files: body and material indices.
/// What the VTU files of `problem` hold: every output of an explicit run,
/// every `problem.every` steps of an implicit one.
fn vtu_options<const D: usize>(problem: &crate::scene::Problem<D>, explicit: bool) -> VtuOptions {
    VtuOptions {
        every: if explicit { 1 } else { problem.every },
        fields: problem.fields.clone(),
        constants: point_constants(problem),
    }
}

/// The writer of this rank's pieces of the points' files, into the
/// session's folder: at the outputs rank 0's writer writes the points'
/// files of (every output of an explicit run; the steps of an implicit
/// one that [`crate::writer::writes_vtu`] names).
fn piece_writer<const D: usize>(
    problem: &crate::scene::Problem<D>,
    session: &Session,
    explicit: bool,
) -> WritePiece {
    let options = vtu_options(problem, explicit);
    let dir = session.out.clone();
    let rank = session.ranks.as_ref().map_or(0, |r| r.0.rank());
    std::sync::Arc::new(move |index, snap, ids, fields| {
        if !explicit && !crate::writer::writes_vtu(options.every, index, snap.load_factor) {
            return Ok(());
        }
        crate::writer::write_piece(&dir, &options, (index, rank), snap, ids, fields)
            .map_err(observer_error)
    })
}

fn point_constants<const D: usize>(problem: &crate::scene::Problem<D>) -> Vec<(String, Vec<f64>)> {
    vec![
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
    ]
}

/// The energies as `summary.json` writes them.
fn energies_json(e: &mpm_solver::explicit::Energies) -> Value {
    json!({
        "kinetic": e.kinetic,
        "strain": e.strain,
        "gravitational": e.gravitational,
        "external_work": e.external_work,
        "friction_work": e.friction_work,
        "wall_work": e.wall_work,
        "absorbed_work": e.absorbed_work,
        "spring_energy": e.spring_energy,
        "total": e.total(),
    })
}

/// Runs a built explicit scene on its grid: the VTU series and a row of
/// `energy.csv` (and of every probe's history) at every output time, a
/// checkpoint with each output, `summary.json` at the end; on rank 0 of a
/// run on several ranks with `ranks`, its deal (no checkpoints; the new
/// deals of the cells in `summary.json`).
fn explicit_run_on<const D: usize>(
    scene: &crate::scene::Scene,
    problem: &crate::scene::Problem<D>,
    session: &Session,
    grid: mpm_mesh::RegularGrid<D>,
    ranks: Option<RankRun>,
) -> Result<(), CasesError>
where
    crate::scene::Problem<D>: crate::scene::RunExplicit<D>,
{
    use crate::output::CsvValue;
    use crate::scene::ExplicitEvent;
    use crate::writer::ExplicitSummary;

    let Some(setup) = problem.explicit.as_ref() else {
        return Err(CasesError::Solver(mpm_solver::SolverError::InvalidInput(
            "the scene's solver is implicit".into(),
        )));
    };
    let end_time = setup.end_time;
    let (mut obs, mut control) = session.start(scene, grid)?;
    obs.writer
        .set_pieces(ranks.as_ref().map_or(0, |r| r.ranks.size()));
    control.ranks = ranks;
    let mut rebalances = Vec::new();
    obs.show_time();
    obs.writer.set_vtu_options(vtu_options(problem, true));
    const ENERGY_HEADER: [&str; 10] = [
        "time",
        "kinetic",
        "strain",
        "gravitational",
        "external_work",
        "friction_work",
        "wall_work",
        "absorbed_work",
        "spring_energy",
        "total",
    ];
    let axes = ["x", "y", "z"];
    let probe_header: Vec<String> = std::iter::once("time".to_owned())
        .chain(axes.iter().take(D).map(|a| format!("u{a}")))
        .collect();
    let probe_header: Vec<&str> = probe_header.iter().map(String::as_str).collect();
    let mut last_probes = Map::new();
    let run = crate::scene::run_explicit(problem, &control, |event| match event {
        ExplicitEvent::Step(info) => {
            obs.explicit_step(info.time, end_time, info.step, info.dt);
            Ok(())
        }
        ExplicitEvent::Rebalanced(b) => {
            rebalances.push(json!({
                "step": b.step,
                "imbalance_before": b.before,
                "imbalance_after": b.after,
                "points_moved": b.moved,
            }));
            Ok(())
        }
        ExplicitEvent::Output(frame) => {
            let e = &frame.energies;
            let row = [
                frame.time,
                e.kinetic,
                e.strain,
                e.gravitational,
                e.external_work,
                e.friction_work,
                e.wall_work,
                e.absorbed_work,
                e.spring_energy,
                e.total(),
            ]
            .map(CsvValue::from);
            obs.writer
                .case_row("energy.csv", &ENERGY_HEADER, &row)
                .map_err(observer_error)?;
            for (name, p) in &problem.probes {
                let u = &frame.snapshot.displacement[*p][..D];
                let mut row = vec![CsvValue::from(frame.time)];
                row.extend(u.iter().map(|x| CsvValue::from(*x)));
                obs.writer
                    .case_row(&format!("probe_{name}.csv"), &probe_header, &row)
                    .map_err(observer_error)?;
                last_probes.insert(name.clone(), json!(u));
            }
            obs.explicit_output(
                frame.index,
                frame.time,
                end_time,
                frame.steps,
                frame.snapshot,
            )
        }
    });
    let r = match run {
        Err(mpm_solver::SolverError::Stopped { step, load_factor }) => {
            println!(
                "stopped after output {step} at t = {} s; continue with --resume",
                crate::session::shown(load_factor)
            );
            return Ok(());
        }
        other => other?,
    };
    let results = scene_results(problem, last_probes, &r.last, obs.writer.dir())?;
    let summary = ExplicitSummary {
        case: "scene".into(),
        solver: "explicit".into(),
        basis: problem.variant.basis,
        transfer: setup.transfer,
        alpha: setup.alpha,
        locking: setup.locking,
        material_points: problem.len(),
        time_steps: r.steps,
        end_time: r.time,
        outputs: r.outputs,
        wall_time_s: r.wall_time_s,
        stage_times_s: json!({
            "p2g": r.stage_times.p2g,
            "grid": r.stage_times.grid,
            "g2p": r.stage_times.g2p,
        }),
        initial_energies: energies_json(&r.initial),
        final_energies: energies_json(&r.last_energies),
        energy_drift: r.energy_drift,
        rebalances,
        ranks: r.ranks.as_ref().map(ranks_json),
        results,
        parameters: scene,
    };
    obs.finish_explicit(summary)
}

/// A run's [`mpm_dispatch::explicit::RanksReport`] as `summary.json` holds
/// it: each measure as `{ "max": ..., "mean": ... }` over the ranks.
fn ranks_json(r: &mpm_dispatch::explicit::RanksReport) -> Value {
    let pair = |p: [f64; 2]| json!({ "max": p[0], "mean": p[1] });
    json!({
        "ranks": r.ranks,
        "point_seconds": pair(r.point_seconds),
        "grid_seconds": pair(r.grid_seconds),
        "halo_messages": pair(r.halo_messages),
        "halo_bytes": pair(r.halo_bytes),
        "migration_messages": pair(r.migration_messages),
        "migration_bytes": pair(r.migration_bytes),
        "collectives": pair(r.collectives),
        "migrated_points": pair(r.migrated_points),
    })
}
