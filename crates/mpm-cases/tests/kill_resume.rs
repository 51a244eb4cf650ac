//! Kill and resume: an `mpm run` killed with SIGKILL at random moments —
//! several times per run, some of them in the middle of writing a file —
//! and continued each time with `--resume` ends with exactly the files of
//! an uninterrupted run, and no kill ever leaves a torn file behind.
//!
//! For each scene (the elasto-plastic collapse, implicit, many short load
//! steps; the colliding disks, explicit, many outputs and a PNG) the test
//!
//! 1. runs the scene once without interruption (the reference) and
//!    measures its wall time T;
//! 2. runs it again in another directory and kills the process
//!    (`Child::kill`, SIGKILL on Unix) `MPM_KILL_ROUNDS` times (default
//!    6), restarting with `--resume` after each kill; after the last kill
//!    the run is left to finish. The first kill comes as soon as the
//!    first file appears, before the first checkpoint exists. The others
//!    take turns at three kinds of moment, each with a delay drawn from a
//!    small seeded generator (`MPM_KILL_SEED` to vary it), uniform in
//!    (0, T) and bounded by the part of the run still to go so that most
//!    kills land mid-run: half are killed after the delay; a quarter wait
//!    after it for the next temporary file of `atomic_write` to appear and
//!    are killed at once, in the middle of a write; a quarter wait after it
//!    for the next file to change (new, replaced or grown) and are killed
//!    right after, between the files of one step.
//!
//!    A kill before the first checkpoint makes the next `--resume` fail.
//!    That is legitimate: the test then requires the error to name
//!    `checkpoint.mpm` and the file to be absent (so that a valid
//!    checkpoint is never refused), and starts afresh without `--resume`.
//!    Any other failure fails the test. Should the run finish before all
//!    the kills are spent (a delay longer than the rest of the run), the
//!    whole interrupted run is repeated in a fresh directory, up to five
//!    times;
//! 3. after every kill checks every file with a final name: JSON parses;
//!    CSV ends with a line break and every line has the header's number
//!    of fields, each a number (or empty); VTU and PVD are well-formed XML
//!    (quick-xml, `common::parse_xml`) ending with `</VTKFile>`, and every
//!    file a PVD lists exists; `checkpoint.mpm` reads back
//!    (`mpm_cases::checkpoint::read` checks its length against its
//!    header); a PNG starts with the signature and ends with the `IEND`
//!    chunk. Any other name fails the test, except `atomic_write`'s
//!    temporary files (`.<name>.<pid>.<n>.tmp`), which a kill may leave
//!    and the resumed run must ignore; a temporary file of the killed
//!    process is how the test knows that a kill landed during a write;
//! 4. after the run that succeeds requires that no temporary file is left
//!    (every run removes those of killed runs when it starts,
//!    `mpm_cases::output::remove_temporaries`) and that the directory holds the same file names as the reference,
//!    each byte for byte the same, except wall-clock times, which differ
//!    between any two runs (`tests/cli.rs` and `tests/explicit.rs` make
//!    the same exclusions):
//!    - `steps.csv`: the `seconds*` columns (`common::without_timings`),
//!      the rest byte for byte;
//!    - `summary.json`: the top-level entries `wall_time_s` and
//!      `stage_times_s` (the explicit solver's per-stage times of the last
//!      session) are cut out as lines, the rest of the text byte for byte;
//!    - `checkpoint.mpm`: in its JSON header `wall_time_s` and the
//!      `seconds*` columns of the steps table it carries; the rest of the
//!      header equal, the first line and all the binary numbers (material
//!      points, predictor) byte for byte.
//!
//! It prints (with `--nocapture`) the kills per scene, how they were
//! timed, how many landed during a write and in which files, and the
//! fresh starts. A third test shows that these checks can fail: a file of
//! each kind cut short is found torn, a byte changed in any file is found
//! to differ.
#![cfg(unix)]
#![allow(clippy::unwrap_used)]

use super::common;

use std::collections::BTreeMap;
use std::fs::File;
use std::os::unix::fs::MetadataExt;
use std::os::unix::process::ExitStatusExt;
use std::panic::AssertUnwindSafe;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The scenes run one after the other, so that T is measured on a quiet
/// machine and the kill moments mean what they say.
static SERIAL: Mutex<()> = Mutex::new(());

/// The longest a single `mpm` process may take before the test gives up.
const ATTEMPT_TIMEOUT: Duration = Duration::from_secs(120);

/// At most this many interrupted runs per scene (see step 2 above).
const MAX_SEQUENCES: usize = 5;

/// The implicit scene: the collapse of Coombs et al. (2020) over 60 short
/// load steps (plastic history in the checkpoint).
#[test]
fn an_implicit_run_killed_and_resumed_writes_the_uninterrupted_files() {
    kill_and_resume(&Scene {
        name: "collapse",
        file: "collapse.toml",
        set: &["load_steps=60"],
    });
}

/// The explicit scene: the colliding disks, 60 outputs and a PNG.
#[test]
fn an_explicit_run_killed_and_resumed_writes_the_uninterrupted_files() {
    kill_and_resume(&Scene {
        name: "explicit_disks",
        file: "explicit_disks.toml",
        set: &["solver.output_interval=0.05"],
    });
}

/// The checks of this file can fail: a file of each kind a run writes,
/// cut short, is found torn; a byte changed in any file is found to
/// differ; unknown files are refused, temporary ones recognised.
#[test]
fn the_checks_find_torn_and_differing_files() {
    let _serial = SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let base = common::fresh_dir("kill_resume_checks");
    let short = [
        Scene {
            name: "collapse",
            file: "collapse.toml",
            set: &["load_steps=2"],
        },
        Scene {
            name: "explicit_disks",
            file: "explicit_disks.toml",
            set: &["solver.end_time=0.1"],
        },
    ];
    let mut kinds = std::collections::BTreeSet::new();
    for scene in &short {
        let dir = base.join(scene.name);
        let args = scene.args(&dir, false);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (ok, _, err) = common::mpm(&args);
        assert!(ok, "{err}");
        check_complete(&dir);
        assert_same_outputs(scene.name, &dir, &dir);
        for name in common::dir_entries(&dir) {
            kinds.insert(name.rsplit_once('.').unwrap().1.to_string());
            let bytes = std::fs::read(dir.join(&name)).unwrap();
            let copy = base.join("copy");
            let fails = |change: &dyn Fn(&mut Vec<u8>), check: &dyn Fn(&Path)| {
                let _ = std::fs::remove_dir_all(&copy);
                std::fs::create_dir_all(&copy).unwrap();
                for other in common::dir_entries(&dir) {
                    std::fs::copy(dir.join(&other), copy.join(&other)).unwrap();
                }
                let mut changed = bytes.clone();
                change(&mut changed);
                std::fs::write(copy.join(&name), changed).unwrap();
                panics(|| check(&copy))
            };
            // Cut in the middle of a line, so that a CSV is not merely
            // shorter.
            let cut = |b: &mut Vec<u8>| {
                let mut n = b.len() / 2;
                while b[n - 1] == b'\n' {
                    n -= 1;
                }
                b.truncate(n);
            };
            assert!(fails(&cut, &check_complete), "{name} cut short passes");
            let flip = |b: &mut Vec<u8>| {
                let i = b.iter().position(|&c| c == b'\n').unwrap() + 1;
                b[i] ^= 1;
            };
            let compare = |copy: &Path| assert_same_outputs(scene.name, &dir, copy);
            assert!(fails(&flip, &compare), "{name} changed passes");
        }
    }
    let expected = ["csv", "json", "mpm", "png", "pvd", "vtu"];
    assert_eq!(kinds.iter().collect::<Vec<_>>(), expected);

    let dir = base.join("collapse");
    std::fs::write(dir.join(".points.pvd.123.4.tmp"), "<VTKFile").unwrap();
    check_complete(&dir);
    assert_eq!(temporaries(&dir), [".points.pvd.123.4.tmp"]);
    assert_eq!(original_name(".points.pvd.123.4.tmp"), "points.pvd");
    for name in [
        "points.pvd",
        ".points.pvd.tmp",
        ".points.pvd.1.x.tmp",
        ".1.2.tmp",
    ] {
        assert!(!is_temporary(name), "{name}");
    }
    std::fs::write(dir.join("notes.txt"), "").unwrap();
    assert!(panics(|| check_complete(&dir)));
}

/// Whether `f` panics (quietly: the panics are expected).
fn panics(f: impl FnOnce()) -> bool {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let panicked = std::panic::catch_unwind(AssertUnwindSafe(f)).is_err();
    std::panic::set_hook(hook);
    panicked
}

/// A scene file of `scenes/` with `--set` overrides.
struct Scene {
    name: &'static str,
    file: &'static str,
    set: &'static [&'static str],
}

impl Scene {
    /// The arguments of `mpm` writing to `out`.
    fn args(&self, out: &Path, resume: bool) -> Vec<String> {
        let scene = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes")
            .join(self.file);
        let mut args = vec!["run".to_string(), scene.to_str().unwrap().to_string()];
        for s in self.set {
            args.push("--set".into());
            args.push((*s).to_string());
        }
        args.push("--out".into());
        args.push(out.to_str().unwrap().to_string());
        if resume {
            args.push("--resume".into());
        }
        args
    }
}

/// Number of kills per scene: `MPM_KILL_ROUNDS`, default 6.
fn kill_rounds() -> usize {
    std::env::var("MPM_KILL_ROUNDS").map_or(6, |v| {
        v.parse()
            .unwrap_or_else(|_| panic!("MPM_KILL_ROUNDS={v} is not a count"))
    })
}

/// SplitMix64: a small deterministic generator, seeded per scene.
struct Rng(u64);

impl Rng {
    fn for_scene(name: &str) -> Self {
        let base = std::env::var("MPM_KILL_SEED").map_or(0x5eed_0016, |v| {
            v.parse()
                .unwrap_or_else(|_| panic!("MPM_KILL_SEED={v} is not a number"))
        });
        // FNV-1a of the name, so that each scene draws its own moments.
        let hash = name.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
        Self(base ^ hash)
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in the open interval (0, 1).
    fn open01(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
}

/// When an attempt is killed.
#[derive(Debug, Clone, Copy)]
enum Moment {
    /// Never: the attempt runs to its end.
    Never,
    /// After this delay.
    After(Duration),
    /// After this delay, as soon as a temporary file of the process appears.
    DuringWrite(Duration),
    /// After this delay, as soon as a file of the directory changes.
    AfterChange(Duration),
}

/// How an attempt ended.
enum Outcome {
    /// Killed; the temporary files the process left (its writes in flight).
    Killed { left: Vec<String> },
    /// Exited by itself; success and its standard error.
    Exited { success: bool, stderr: String },
}

/// What happened to one scene's interrupted runs.
#[derive(Default)]
struct Tally {
    kills: usize,
    by_delay: usize,
    waiting_for_a_write: usize,
    after_a_change: usize,
    /// Kills after which the process's temporary files were left, and
    /// their names.
    during_write: usize,
    interrupted_files: BTreeMap<String, usize>,
    /// `--resume` refused for lack of a checkpoint, then a fresh start.
    fresh_starts: usize,
    attempts: usize,
}

fn kill_and_resume(scene: &Scene) {
    let _serial = SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let clock = Instant::now();
    let rounds = kill_rounds();
    let mut rng = Rng::for_scene(scene.name);
    let base = common::fresh_dir(&format!("kill_resume_{}", scene.name));

    let reference = base.join("reference");
    let args = scene.args(&reference, false);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let started = Instant::now();
    let (ok, _, err) = common::mpm(&args);
    let t = started.elapsed();
    assert!(ok, "{}: the uninterrupted run failed: {err}", scene.name);
    check_complete(&reference);
    assert!(
        temporaries(&reference).is_empty(),
        "{}: the uninterrupted run left temporary files: {:?}",
        scene.name,
        temporaries(&reference)
    );
    let total_steps = mpm_cases::checkpoint::read(&reference).unwrap().0.steps;
    assert!(total_steps > 0);

    let logs = base.join("logs");
    std::fs::create_dir_all(&logs).unwrap();
    let mut tally = Tally::default();
    let mut sequences = 0;
    while sequences == 0 || tally.kills < rounds {
        sequences += 1;
        assert!(
            sequences <= MAX_SEQUENCES,
            "{}: {MAX_SEQUENCES} interrupted runs finished with only {} of {rounds} kills",
            scene.name,
            tally.kills
        );
        let dir = base.join(format!("killed_{sequences}"));
        std::fs::create_dir_all(&dir).unwrap();
        let mut resume = false;
        loop {
            let moment = if tally.kills >= rounds {
                Moment::Never
            } else if tally.attempts == 0 {
                // The first kill comes as soon as the first file appears,
                // before the first checkpoint: the refused --resume and
                // the fresh start are then taken at least once.
                Moment::AfterChange(Duration::ZERO)
            } else {
                let done = progress(&dir, total_steps);
                choose_moment(&mut rng, t, done, tally.kills, rounds)
            };
            tally.attempts += 1;
            let log = logs.join(format!("attempt_{}", tally.attempts));
            let args = scene.args(&dir, resume);
            match attempt(&args, &dir, &log, moment) {
                Outcome::Killed { left } => {
                    tally.kills += 1;
                    match moment {
                        Moment::After(_) => tally.by_delay += 1,
                        Moment::DuringWrite(_) => tally.waiting_for_a_write += 1,
                        Moment::AfterChange(_) => tally.after_a_change += 1,
                        Moment::Never => unreachable!("a run not to be killed was killed"),
                    }
                    if !left.is_empty() {
                        tally.during_write += 1;
                    }
                    for name in left {
                        *tally
                            .interrupted_files
                            .entry(original_name(&name))
                            .or_default() += 1;
                    }
                    check_complete(&dir);
                    resume = true;
                }
                Outcome::Exited {
                    success: true,
                    stderr,
                } => {
                    assert!(!stderr.contains("panicked"), "{stderr}");
                    break;
                }
                Outcome::Exited {
                    success: false,
                    stderr,
                } => {
                    // The only legitimate failure: a resume after a kill
                    // that came before the first checkpoint was written.
                    let checkpoint = dir.join(mpm_cases::checkpoint::FILE_NAME);
                    assert!(
                        resume && !checkpoint.exists(),
                        "{}: mpm failed (resume: {resume}, checkpoint present: {}):\n{stderr}",
                        scene.name,
                        checkpoint.exists()
                    );
                    assert!(
                        stderr.contains("checkpoint.mpm") && !stderr.contains("panicked"),
                        "{}: --resume without a checkpoint must say so: {stderr}",
                        scene.name
                    );
                    tally.fresh_starts += 1;
                    resume = false;
                }
            }
        }
        check_complete(&dir);
        let left = temporaries(&dir);
        assert!(
            left.is_empty(),
            "{}: the finished run left temporary files: {left:?}",
            scene.name
        );
        assert_same_outputs(scene.name, &reference, &dir);
    }

    let files: Vec<String> = tally
        .interrupted_files
        .iter()
        .map(|(f, n)| format!("{f} ×{n}"))
        .collect();
    println!(
        "kill_resume {}: T = {:.2} s, {} kills in {} attempts over {} interrupted run(s): \
         {} after a random delay, {} waiting for a write, {} right after a file changed; \
         {} landed during a write ({}); {} fresh start(s) after a kill before the first \
         checkpoint; {:.1} s in all",
        scene.name,
        t.as_secs_f64(),
        tally.kills,
        tally.attempts,
        sequences,
        tally.by_delay,
        tally.waiting_for_a_write,
        tally.after_a_change,
        tally.during_write,
        if files.is_empty() {
            "none".to_string()
        } else {
            files.join(", ")
        },
        tally.fresh_starts,
        clock.elapsed().as_secs_f64()
    );
    assert!(tally.kills >= rounds, "only {} kills", tally.kills);
}

/// The fraction of the run's steps done by the checkpoint in `dir`.
fn progress(dir: &Path, total_steps: usize) -> f64 {
    mpm_cases::checkpoint::read(dir).map_or(0.0, |(header, _)| {
        (header.steps as f64 / total_steps as f64).min(1.0)
    })
}

/// The moment of kill number `kill` (from 0) of `rounds`, a fraction
/// `done` of a run of wall time `t` behind. The delay is uniform in
/// (0, 1.3 × rest / (kills to go + 1)), so that the kills spread over the
/// rest of the run and leave it some to finish; the kind of moment takes
/// turns, so that each scene sees each kind whatever the seed.
fn choose_moment(rng: &mut Rng, t: Duration, done: f64, kill: usize, rounds: usize) -> Moment {
    let rest = t.as_secs_f64() * (1.0 - done).max(0.05);
    let bound = (1.3 * rest / ((rounds - kill) as f64 + 1.0)).max(0.005);
    let delay = Duration::from_secs_f64(rng.open01() * bound);
    match kill % 4 {
        1 => Moment::DuringWrite(delay),
        3 => Moment::AfterChange(delay),
        _ => Moment::After(delay),
    }
}

/// Runs `mpm args` (standard output and error into `log.*`) and kills it
/// at `moment`.
fn attempt(args: &[String], dir: &Path, log: &Path, moment: Moment) -> Outcome {
    let stderr_path = log.with_extension("err");
    let mut child = Command::new(env!("CARGO_BIN_EXE_mpm"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(File::create(log.with_extension("out")).unwrap())
        .stderr(File::create(&stderr_path).unwrap())
        .spawn()
        .unwrap();
    let pid = child.id();
    let started = Instant::now();
    let mut stamps: Option<BTreeMap<String, (u64, i64, u64)>> = None;
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        let now = started.elapsed();
        assert!(
            now < ATTEMPT_TIMEOUT,
            "mpm {args:?} still running after {ATTEMPT_TIMEOUT:?}"
        );
        let fire = match moment {
            Moment::Never => false,
            Moment::After(d) => now >= d,
            Moment::DuringWrite(d) => now >= d && !temporaries_of(dir, pid).is_empty(),
            Moment::AfterChange(d) => {
                if now < d {
                    false
                } else {
                    let new = file_stamps(dir);
                    let changed = stamps.as_ref().is_some_and(|old| *old != new);
                    stamps = Some(new);
                    changed
                }
            }
        };
        if fire {
            // The process may have exited in between: then the kill does
            // nothing and the status below tells how it ended.
            let _ = child.kill();
            break child.wait().unwrap();
        }
        let pause = match moment {
            Moment::Never => Duration::from_millis(5),
            Moment::After(d) => d.saturating_sub(now).min(Duration::from_millis(2)),
            Moment::DuringWrite(_) | Moment::AfterChange(_) => Duration::from_micros(200),
        };
        std::thread::sleep(pause);
    };
    if status.signal() == Some(9) {
        return Outcome::Killed {
            left: temporaries_of(dir, pid),
        };
    }
    assert!(
        status.code().is_some(),
        "mpm {args:?} ended by signal {:?}",
        status.signal()
    );
    Outcome::Exited {
        success: status.success(),
        stderr: std::fs::read_to_string(&stderr_path).unwrap(),
    }
}

/// Whether `name` is a temporary file of `atomic_write`:
/// `.<name>.<pid>.<n>.tmp`.
fn is_temporary(name: &str) -> bool {
    let Some(inner) = name.strip_prefix('.').and_then(|s| s.strip_suffix(".tmp")) else {
        return false;
    };
    let parts: Vec<&str> = inner.rsplitn(3, '.').collect();
    parts.len() == 3
        && !parts[2].is_empty()
        && parts[..2]
            .iter()
            .all(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()))
}

/// The file a temporary file was to replace.
fn original_name(temporary: &str) -> String {
    let inner = &temporary[1..temporary.len() - ".tmp".len()];
    inner.rsplitn(3, '.').nth(2).unwrap().to_string()
}

/// The temporary files in `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    common::dir_entries(dir)
        .into_iter()
        .filter(|n| is_temporary(n))
        .collect()
}

/// The temporary files of process `pid` in `dir`.
fn temporaries_of(dir: &Path, pid: u32) -> Vec<String> {
    let tag = format!(".{pid}.");
    entries(dir)
        .into_iter()
        .filter(|n| is_temporary(n) && n.contains(&tag))
        .collect()
}

/// Names in `dir` (none if it does not exist yet); files may come and go
/// while it is read.
fn entries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir).map_or_else(
        |_| Vec::new(),
        |rd| {
            rd.filter_map(Result::ok)
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        },
    )
}

/// Inode, modification time (ns) and length of every file with a final
/// name in `dir`: a rename over a file changes its inode.
fn file_stamps(dir: &Path) -> BTreeMap<String, (u64, i64, u64)> {
    entries(dir)
        .into_iter()
        .filter(|n| !is_temporary(n))
        .filter_map(|n| {
            let m = std::fs::metadata(dir.join(&n)).ok()?;
            Some((
                n,
                (m.ino(), m.mtime() * 1_000_000_000 + m.mtime_nsec(), m.len()),
            ))
        })
        .collect()
}

/// Fails unless every file with a final name in `dir` is complete (see
/// step 3 of the file's documentation).
fn check_complete(dir: &Path) {
    for name in common::dir_entries(dir) {
        if is_temporary(&name) {
            continue;
        }
        let path = dir.join(&name);
        let bytes = std::fs::read(&path).unwrap();
        let torn = |what: &str| format!("{} is torn: {what}", path.display());
        let ext = name.rsplit_once('.').map_or("", |(_, e)| e);
        match ext {
            "json" => {
                let parsed = serde_json::from_slice::<serde_json::Value>(&bytes);
                assert!(parsed.is_ok(), "{}", torn(&format!("{parsed:?}")));
            }
            "csv" => check_csv(&bytes, &torn),
            "vtu" | "pvd" => {
                let text = std::str::from_utf8(&bytes)
                    .unwrap_or_else(|e| panic!("{}", torn(&e.to_string())));
                assert!(
                    text.ends_with("</VTKFile>\n"),
                    "{}",
                    torn("no closing </VTKFile>")
                );
                let doc = std::panic::catch_unwind(|| common::parse_xml(text))
                    .unwrap_or_else(|_| panic!("{}", torn("not well-formed XML")));
                if ext == "pvd" {
                    for set in doc.iter().filter(|e| e.name == "DataSet") {
                        let file = set.attr("file");
                        assert!(
                            dir.join(file).is_file(),
                            "{} lists {file}, which does not exist",
                            path.display()
                        );
                    }
                }
            }
            "mpm" => {
                assert_eq!(name, mpm_cases::checkpoint::FILE_NAME);
                if let Err(e) = mpm_cases::checkpoint::read(dir) {
                    panic!("{}", torn(&e.to_string()));
                }
            }
            "png" => {
                const SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];
                const IEND: [u8; 12] = [0, 0, 0, 0, b'I', b'E', b'N', b'D', 0xae, 0x42, 0x60, 0x82];
                assert!(
                    bytes.starts_with(&SIGNATURE) && bytes.ends_with(&IEND),
                    "{}",
                    torn("no PNG signature or no IEND chunk at the end")
                );
            }
            _ => panic!(
                "{}: a file the test does not know how to check (teach check_complete)",
                path.display()
            ),
        }
    }
}

/// A complete CSV table: a line break at the end, every line with the
/// header's number of fields, every field of the rows a number or empty.
fn check_csv(bytes: &[u8], torn: &dyn Fn(&str) -> String) {
    let text = std::str::from_utf8(bytes).unwrap_or_else(|e| panic!("{}", torn(&e.to_string())));
    assert!(text.ends_with('\n'), "{}", torn("no line break at the end"));
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default();
    let columns = fields(header).len();
    assert!(columns > 0 && !header.is_empty(), "{}", torn("no header"));
    for (i, line) in lines.enumerate() {
        let f = fields(line);
        assert!(
            f.len() == columns,
            "{}",
            torn(&format!(
                "row {i} has {} fields, the header {columns}",
                f.len()
            ))
        );
        for v in f {
            assert!(
                v.is_empty() || v.parse::<f64>().is_ok(),
                "{}",
                torn(&format!("row {i} has the field {v:?}"))
            );
        }
    }
}

/// The fields of a CSV line (RFC 4180 quoting).
fn fields(line: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                out.last_mut().unwrap().push('"');
            }
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(String::new()),
            c => out.last_mut().unwrap().push(c),
        }
    }
    assert!(!quoted, "unbalanced quotes in {line:?}");
    out
}

/// Fails unless `dir` holds the files of `reference`, byte for byte but
/// for the wall-clock times (see step 4 of the file's documentation).
fn assert_same_outputs(scene: &str, reference: &Path, dir: &Path) {
    let names = common::dir_entries(reference);
    assert_eq!(
        names,
        common::dir_entries(dir),
        "{scene}: not the files of the uninterrupted run"
    );
    for name in &names {
        let a = std::fs::read(reference.join(name)).unwrap();
        let b = std::fs::read(dir.join(name)).unwrap();
        let text = |x: &[u8]| String::from_utf8(x.to_vec()).unwrap();
        match name.as_str() {
            "steps.csv" => assert!(
                common::without_timings(&text(&a)) == common::without_timings(&text(&b)),
                "{scene}: steps.csv differs from the uninterrupted run's (timings aside)"
            ),
            "summary.json" => {
                let cut = |x: &[u8]| without_entries(&text(x), &["wall_time_s", "stage_times_s"]);
                assert!(
                    cut(&a) == cut(&b),
                    "{scene}: summary.json differs from the uninterrupted run's (timings aside)"
                );
            }
            "checkpoint.mpm" => assert_same_checkpoint(scene, &a, &b),
            _ => assert!(
                a == b,
                "{scene}: {name} differs from the uninterrupted run's"
            ),
        }
    }
}

/// `json`, pretty-printed, without the top-level entries `keys` (a key's
/// line, and for an object or array value the lines up to its end).
fn without_entries(json: &str, keys: &[&str]) -> String {
    let mut out = String::new();
    let mut found = 0;
    let mut skipping = false;
    for line in json.split_inclusive('\n') {
        if skipping {
            skipping = !(line.starts_with("  }") || line.starts_with("  ]"));
            continue;
        }
        if keys
            .iter()
            .any(|k| line.starts_with(&format!("  \"{k}\": ")))
        {
            found += 1;
            let value = line.trim_end().trim_end_matches(',');
            skipping = value.ends_with('{') || value.ends_with('[');
            continue;
        }
        out.push_str(line);
    }
    assert!(found > 0, "none of {keys:?} in {json}");
    out
}

/// Two checkpoints equal but for the wall-clock times of their headers.
fn assert_same_checkpoint(scene: &str, a: &[u8], b: &[u8]) {
    let split = |x: &[u8]| -> (Vec<u8>, serde_json::Value, Vec<u8>) {
        let mut parts = x.splitn(3, |&c| c == b'\n');
        let magic = parts.next().unwrap().to_vec();
        let header: mpm_cases::checkpoint::Header =
            serde_json::from_slice(parts.next().unwrap()).unwrap();
        let steps = common::without_timings(&header.writer.steps.to_csv());
        let mut value = serde_json::to_value(&header).unwrap();
        let object = value.as_object_mut().unwrap();
        assert!(object.remove("wall_time_s").is_some());
        object["writer"]["steps"] = serde_json::Value::String(steps);
        (magic, value, parts.next().unwrap().to_vec())
    };
    let (a, b) = (split(a), split(b));
    assert!(a.0 == b.0, "{scene}: checkpoint.mpm: first line differs");
    assert!(
        a.1 == b.1,
        "{scene}: checkpoint.mpm: header differs from the uninterrupted run's (timings aside)"
    );
    assert!(
        a.2 == b.2,
        "{scene}: checkpoint.mpm: the numbers differ from the uninterrupted run's"
    );
}
