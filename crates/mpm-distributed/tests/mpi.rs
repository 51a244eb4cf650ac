//! Distributed runs over MPI processes (feature `mpi`): the colliding
//! disks ([`mpm_solver::ranks::disks`], explicit) and the strip-loaded von
//! Mises block ([`mpm_solver::ranks::strip_load`], implicit, with and
//! without F-bar) under `mpirun -n 1, 2, 4` equal the one-solver run to
//! rounding (one process bit for bit for the block); a failure on one rank
//! stops every rank with the same error, in either solver; a panic on one
//! rank aborts the job instead of hanging it. The tests start `mpirun` on this test binary
//! itself, whose `child_*` tests (ignored unless `MPM_MPI_CHILD` names
//! them) run on each process.
#![cfg(feature = "mpi")]
#![allow(missing_docs, clippy::unwrap_used)]

use std::process::{Command, Output};
use std::time::{Duration, Instant};

use mpm_distributed::mpi_ranks::Mpi;
use mpm_solver::NewtonOptions;
use mpm_solver::SolverError;
use mpm_solver::ranks::disks::{Deal, Disks};
use mpm_solver::ranks::strip_load::{self, Treatment};
use mpm_solver::ranks::{Ranks, Reduce};

/// Rounding only (as `mpm-solver`'s `tests/ranks.rs` argues).
const BOUND: f64 = 1e-12;

/// A job that has not ended in this time hangs.
const DEADLINE: Duration = Duration::from_secs(120);

/// A session directory of Open MPI's own for one `mpirun` job (the
/// `orte_tmpdir_base` MCA parameter): jobs started side by side by the
/// test harness otherwise share `/tmp/ompi.<host>.<uid>`, and one job's
/// cleanup removed it while another was creating its own part of it
/// ("A call to mkdir was unable to create the desired directory", a CI
/// run of 2026-12-07).
fn ompi_session_dir() -> std::path::PathBuf {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("mpm-ompi-{}-{k}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a session directory for mpirun");
    dir
}

/// Runs the child test `name` on `n` processes; the output once it ends.
fn mpirun(n: usize, name: &str) -> Output {
    let exe = std::env::current_exe().unwrap();
    let mut child = Command::new("mpirun")
        .args(["-n", &n.to_string(), "--oversubscribe"])
        .arg(&exe)
        .args([
            "--exact",
            name,
            "--ignored",
            "--nocapture",
            "--test-threads=1",
        ])
        .env("MPM_MPI_CHILD", name)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .env("OMPI_MCA_orte_tmpdir_base", ompi_session_dir())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("mpirun (Open MPI) must be installed for the mpi feature's tests");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > DEADLINE {
            child.kill().unwrap();
            panic!("{name} on {n} processes did not end within {DEADLINE:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// Whether this process is the child `name` (and not the parent test).
fn is_child(name: &str) -> bool {
    std::env::var("MPM_MPI_CHILD").as_deref() == Ok(name)
}

fn text(o: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn disks_on_1_2_4_processes_equal_one_solver() {
    for n in [1, 2, 4] {
        let out = mpirun(n, "child_disks");
        let t = text(&out);
        assert!(out.status.success(), "{n} processes:\n{t}");
        // The harness's "test child_disks ... " may precede it.
        let line = t
            .lines()
            .find_map(|l| l.find("disks on").map(|at| &l[at..]))
            .unwrap_or_else(|| panic!("{t}"));
        eprintln!("{line}");
        assert!(line.contains(&format!("disks on {n} processes")), "{line}");
    }
}

#[test]
#[ignore = "run on each process by disks_on_1_2_4_processes_equal_one_solver"]
fn child_disks() {
    if !is_child("child_disks") {
        return;
    }
    let mpi = Mpi::init();
    let ranks = mpi.ranks();
    let single = Disks::STANDARD.single().unwrap();
    let mine = Disks::STANDARD
        .on_ranks(Box::new(ranks), Deal::Scattered)
        .unwrap();
    // Every rank compares its own points by id; the worst and the count
    // are reduced.
    let mut worst = [0.0f64, 0.0];
    for (id, x, v) in &mine.points {
        let (_, xs, vs) = single.points[*id];
        worst[0] = worst[0].max((x - xs).norm());
        worst[1] = worst[1].max((v - vs).norm());
    }
    let mut counts = [mine.points.len() as f64, mine.migrated as f64];
    ranks.all_reduce(&mut worst, Reduce::Max).unwrap();
    ranks.all_reduce(&mut counts, Reduce::Sum).unwrap();
    assert_eq!(
        counts[0] as usize,
        single.points.len(),
        "every point on exactly one rank"
    );
    assert!(worst[0] < BOUND && worst[1] < BOUND, "{worst:?}");
    assert_eq!(mine.steps, single.steps);
    assert!(
        ranks.size() == 1 || counts[1] > 0.0,
        "the disks must cross between ranks"
    );
    if ranks.rank() == 0 {
        println!(
            "disks on {} processes: max |Δx| {:.2e} m, |Δv| {:.2e} m/s, {} migrations, {} steps",
            ranks.size(),
            worst[0],
            worst[1],
            counts[1],
            mine.steps
        );
    }
}

/// Runs the child `name` on `n` processes, each of which prints how it
/// stopped: the job ends normally and exactly one process reports the
/// typed error. The `n` reports.
fn stop_reports(n: usize, name: &str) -> Vec<String> {
    let out = mpirun(n, name);
    let t = text(&out);
    assert!(out.status.success(), "{t}");
    let reports: Vec<String> = t
        .lines()
        .filter_map(|l| l.find("stopped:").map(|at| l[at..].to_owned()))
        .collect();
    assert_eq!(reports.len(), n, "{t}");
    let typed = reports.iter().filter(|l| l.contains("typed")).count();
    assert_eq!(typed, 1, "one rank reports the typed error: {reports:?}");
    reports
}

#[test]
fn a_failure_on_one_process_stops_all_with_its_error() {
    let reports = stop_reports(3, "child_thrown");
    let step = |l: &str| {
        l.split("explicit step ")
            .nth(1)
            .map(|r| r.split(' ').next().map(str::to_owned))
    };
    let first = step(&reports[0]);
    assert!(
        first.is_some() && reports.iter().all(|l| step(l) == first),
        "{reports:?}"
    );
}

#[test]
#[ignore = "run on each process by a_failure_on_one_process_stops_all_with_its_error"]
fn child_thrown() {
    if !is_child("child_thrown") {
        return;
    }
    let mpi = Mpi::init();
    let thrown = Disks {
        speed: 50.0,
        ..Disks::STANDARD
    };
    match thrown.on_ranks(Box::new(mpi.ranks()), Deal::Scattered) {
        Err(e @ SolverError::ExplicitPoint { .. }) => println!("stopped: typed {e}"),
        Err(e @ SolverError::Rank { .. }) => println!("stopped: {e}"),
        other => panic!("expected the point to leave the grid: {other:?}"),
    }
}

#[test]
fn a_panic_on_one_process_aborts_the_job() {
    let out = mpirun(2, "child_panic");
    assert!(!out.status.success(), "{}", text(&out));
}

#[test]
#[ignore = "run on each process by a_panic_on_one_process_aborts_the_job"]
fn child_panic() {
    if !is_child("child_panic") {
        return;
    }
    let mpi = Mpi::init();
    let ranks = mpi.ranks();
    if ranks.rank() == 1 {
        panic!("rank 1 fails");
    }
    // Rank 0 waits for rank 1 for ever unless the hook aborts the job.
    let mut v = [0.0];
    ranks.all_reduce(&mut v, Reduce::Sum).unwrap();
}

/// Runs the child `name` on 1, 2 and 4 processes: each job succeeds and
/// rank 0 prints two lines starting with `label`, one per treatment.
fn strip_jobs(name: &str, label: &str) {
    for n in [1, 2, 4] {
        let out = mpirun(n, name);
        let t = text(&out);
        assert!(out.status.success(), "{n} processes:\n{t}");
        let lines: Vec<&str> = t
            .lines()
            .filter_map(|l| l.find(label).map(|at| &l[at..]))
            .collect();
        lines.iter().for_each(|l| eprintln!("{l}"));
        assert_eq!(lines.len(), 2, "{t}");
        let on = format!("on {n} processes");
        assert!(lines.iter().all(|l| l.contains(&on)), "{t}");
    }
}

/// This rank's outcome of the strip load against the single solver's:
/// every point on one rank, the same Newton iterations per step, the
/// displacements within 10× the Newton tolerance, stresses within 1e-9
/// and reactions within 1e-8 (issue 42); rank 0 prints them after
/// `label`.
fn check_strip(
    ranks: &impl Ranks,
    single: &strip_load::Outcome,
    mine: &strip_load::Outcome,
    label: &str,
) {
    let tolerance = NewtonOptions::default().tolerance;
    let d = strip_load::differences(single, mine);
    let mut worst = [d.displacement, d.stress, d.reaction];
    let mut count = [mine.ids.len() as f64];
    ranks.all_reduce(&mut worst, Reduce::Max).unwrap();
    ranks.all_reduce(&mut count, Reduce::Sum).unwrap();
    assert_eq!(
        count[0] as usize,
        single.ids.len(),
        "every point on one rank"
    );
    let iterations =
        |o: &strip_load::Outcome| -> Vec<usize> { o.residuals.iter().map(Vec::len).collect() };
    assert_eq!(iterations(mine), iterations(single));
    assert!(
        worst[0] <= 10.0 * tolerance && worst[1] <= 1e-9 && worst[2] <= 1e-8,
        "{worst:?}"
    );
    if ranks.rank() == 0 {
        println!(
            "{label} on {} processes: iterations {:?}, |Δu|/|u| {:.1e}, |Δσ|/|σ| {:.1e}, |ΔR|/|R| {:.1e}",
            ranks.size(),
            iterations(mine),
            worst[0],
            worst[1],
            worst[2]
        );
    }
}

#[test]
fn strip_load_on_1_2_4_processes_equals_one_solver() {
    strip_jobs("child_strip_load", "strip load");
}

#[test]
#[ignore = "run on each process by strip_load_on_1_2_4_processes_equals_one_solver"]
fn child_strip_load() {
    if !is_child("child_strip_load") {
        return;
    }
    let mpi = Mpi::init();
    let ranks = mpi.ranks();
    for treatment in [Treatment::Standard, Treatment::FBar] {
        let single = strip_load::single(treatment).unwrap();
        let mine =
            strip_load::on_ranks(Box::new(ranks), treatment, strip_load::Deal::Cells).unwrap();
        if ranks.size() == 1 {
            assert_eq!(mine, single, "one process is the single solver bit for bit");
        }
        check_strip(
            &ranks,
            &single,
            &mine,
            &format!("strip load ({treatment:?})"),
        );
    }
}

#[test]
fn an_implicit_failure_on_one_process_stops_all_with_its_error() {
    stop_reports(3, "child_strip_load_stray");
}

#[test]
#[ignore = "run on each process by an_implicit_failure_on_one_process_stops_all_with_its_error"]
fn child_strip_load_stray() {
    if !is_child("child_strip_load_stray") {
        return;
    }
    let mpi = Mpi::init();
    let ranks = mpi.ranks();
    let outcome = strip_load::on_ranks(
        Box::new(ranks),
        Treatment::Standard,
        strip_load::Deal::Stray,
    );
    let Err(SolverError::InStep {
        step: 0, source, ..
    }) = outcome
    else {
        panic!("expected the first step to stop: {outcome:?}");
    };
    match (ranks.rank(), *source) {
        (1, e @ SolverError::Basis { .. }) => println!("stopped: typed {e}"),
        (0 | 2, e @ SolverError::Rank { rank: 1, .. }) => println!("stopped: {e}"),
        (rank, e) => panic!("rank {rank}: {e:?}"),
    }
}

/// PETSc over the processes ([`mpm_petsc::PetscLinear`] started by
/// `mpirun -n N`: each rank gives the entries of its own points, PETSc
/// owns an even split of the rows, GAMG builds its aggregates over the
/// processes): the strip-loaded block takes the Newton iterations of the
/// one-solver run with the direct solver in every step, and lands within
/// the same bounds as the replicated solve. The Krylov solves stop at a
/// relative residual of 1e-13, so each is as good as a direct one well
/// below the Newton tolerance; CG for the symmetric system without
/// locking, GMRES for F-bar's unsymmetric one.
#[cfg(feature = "petsc")]
#[test]
fn petsc_over_1_2_4_processes_solves_the_strip_load() {
    strip_jobs("child_petsc_strip_load", "PETSc strip load");
}

#[cfg(feature = "petsc")]
#[test]
#[ignore = "run on each process by petsc_over_1_2_4_processes_solves_the_strip_load"]
fn child_petsc_strip_load() {
    use mpm_solver::{IterativeOptions, LinearSolver as _};
    if !is_child("child_petsc_strip_load") {
        return;
    }
    let mpi = Mpi::init();
    let ranks = mpi.ranks();
    let tight = IterativeOptions {
        rel_tolerance: 1e-13,
        max_iterations: 2000,
    };
    for (treatment, options) in [
        (Treatment::Standard, "-ksp_type cg -pc_type gamg"),
        (Treatment::FBar, "-ksp_type gmres -pc_type gamg"),
    ] {
        let single = strip_load::single(treatment).unwrap();
        let linear = mpm_petsc::PetscLinear::new(options, tight);
        assert_eq!(linear.solves_over_ranks(), ranks.size() > 1);
        let deal = strip_load::Deal::Cells;
        let mine =
            strip_load::on_ranks_with(Box::new(ranks), treatment, deal, Box::new(linear)).unwrap();
        let label = format!("PETSc strip load ({treatment:?}, {options})");
        check_strip(&ranks, &single, &mine, &label);
    }
}
