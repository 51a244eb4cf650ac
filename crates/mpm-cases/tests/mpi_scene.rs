//! `mpirun -n N mpm run scene.toml` (feature `mpi`): the F-patch strip
//! footing of `scenes/strip_footing_ranks.toml` on 2 and 3 MPI processes
//! writes what one process writes: the same steps, the footing's reaction
//! in every step equal to rounding (the ranks add the same contributions
//! in another order), the VTU series of the whole body, written by rank 0
//! alone; so does the explicit collapsing column of
//! `scenes/explicit_collapse.toml` on 2 processes, its energies at every
//! output equal to rounding; what the ranks cannot run yet is refused on
//! every process and the job ends.
#![cfg(feature = "mpi")]
#![allow(missing_docs, clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A job that has not ended in this time hangs.
const DEADLINE: Duration = Duration::from_secs(120);

fn scene() -> PathBuf {
    scene_named("strip_footing_ranks.toml")
}

fn scene_named(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
}

/// Runs `mpm run` with `args` on `n` processes (`n` = 0: without mpirun).
fn mpm(n: usize, args: &[&str]) -> Output {
    let exe = env!("CARGO_BIN_EXE_mpm");
    let mut command = if n == 0 {
        Command::new(exe)
    } else {
        let mut c = Command::new("mpirun");
        c.args(["-n", &n.to_string(), "--oversubscribe", exe]);
        c
    };
    let mut child = command
        .arg("run")
        .args(args)
        .env("RAYON_NUM_THREADS", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("mpirun (Open MPI) must be installed for the mpi feature's tests");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > DEADLINE {
            child.kill().unwrap();
            panic!("mpm on {n} processes did not end within {DEADLINE:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The rows of `reaction_footing.csv` in `dir`.
fn reactions(dir: &Path) -> Vec<Vec<f64>> {
    rows(dir, "reaction_footing.csv")
}

/// The rows of the CSV file `name` in `dir`, without its header.
fn rows(dir: &Path, name: &str) -> Vec<Vec<f64>> {
    let csv = std::fs::read_to_string(dir.join(name)).unwrap();
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

fn vtu_files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".vtu") || n.ends_with(".pvd"))
        .collect();
    names.sort();
    names
}

#[test]
fn a_scene_on_2_and_3_processes_writes_what_one_process_writes() {
    let root = std::env::temp_dir().join(format!("mpm-mpi-scene-{}", std::process::id()));
    let scene = scene();
    let scene = scene.to_str().unwrap();
    let one = root.join("one");
    let out = mpm(0, &[scene, "--out", one.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    let expected = reactions(&one);
    assert!(expected.len() >= 4, "{expected:?}");
    for n in [2, 3] {
        let dir = root.join(format!("n{n}"));
        let out = mpm(n, &[scene, "--out", dir.to_str().unwrap()]);
        assert!(out.status.success(), "{n} processes:\n{}", text(&out));
        let got = reactions(&dir);
        assert_eq!(got.len(), expected.len(), "{n} processes: the same steps");
        let mut worst = 0.0f64;
        for (a, b) in expected.iter().zip(&got) {
            assert_eq!(a[0], b[0], "{n} processes: the same load factors");
            let scale = a[1..].iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (x, y) in a[1..].iter().zip(&b[1..]) {
                worst = worst.max((x - y).abs() / scale);
            }
        }
        eprintln!("{n} processes: reactions within {worst:.1e} of one process");
        assert!(worst <= 1e-8, "{n} processes: {worst:e}");
        assert_eq!(vtu_files(&dir), vtu_files(&one), "{n} processes");
    }
    std::fs::remove_dir_all(&root).ok();
}

/// The explicit column on 2 processes: the same outputs, the energies
/// (`energy.csv`: time, kinetic, strain, gravitational, external work,
/// total) within 1e-10 of the largest (issue 42; the thread ranks of
/// `tests/explicit_ranks.rs` measure 1e-15).
#[test]
fn an_explicit_scene_on_2_processes_writes_what_one_process_writes() {
    let root = std::env::temp_dir().join(format!("mpm-mpi-explicit-{}", std::process::id()));
    let scene = scene_named("explicit_collapse.toml");
    let scene = scene.to_str().unwrap();
    let one = root.join("one");
    let out = mpm(0, &[scene, "--out", one.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    let two = root.join("two");
    let out = mpm(2, &[scene, "--out", two.to_str().unwrap()]);
    assert!(out.status.success(), "2 processes:\n{}", text(&out));
    let (a, b) = (rows(&one, "energy.csv"), rows(&two, "energy.csv"));
    assert_eq!(a.len(), b.len(), "the same outputs");
    assert!(a.len() >= 10, "{a:?}");
    let scale = (a.iter().flat_map(|r| &r[1..])).fold(0.0f64, |m, x| m.max(x.abs()));
    let mut worst = 0.0f64;
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x[0], y[0], "the same output times");
        for (p, q) in x[1..].iter().zip(&y[1..]) {
            worst = worst.max((p - q).abs() / scale);
        }
    }
    eprintln!("explicit, 2 processes: energies within {worst:.1e} of the largest");
    assert!(worst <= 1e-10, "{worst:e}");
    assert_eq!(vtu_files(&two), vtu_files(&one));
    std::fs::remove_dir_all(&root).ok();
}

#[test]
fn what_the_ranks_cannot_run_yet_is_refused_on_every_process() {
    let root = std::env::temp_dir().join(format!("mpm-mpi-refuse-{}", std::process::id()));
    let scene = scene();
    let out = mpm(
        2,
        &[
            scene.to_str().unwrap(),
            "--out",
            root.to_str().unwrap(),
            "--stop-after",
            "1",
        ],
    );
    let t = text(&out);
    assert!(!out.status.success(), "{t}");
    assert!(
        t.contains("rank 0 of 2") && t.contains("rank 1 of 2"),
        "{t}"
    );
    assert!(t.contains("on several ranks: not yet"), "{t}");
    std::fs::remove_dir_all(&root).ok();
}
