//! The harness both fuzz targets share (`mpm-mesh/tests/fuzz_gmsh.rs`
//! and `mpm-cases/tests/fuzz_scenes.rs`, which includes this file by
//! path): the seeded choices, the worker thread that runs one input at a
//! time under `catch_unwind` with a time limit, the panic hook that
//! silences the worker only, the environment's numbers and the peak
//! resident memory. See `docs/src/reproduction/fuzz.md`.
#![allow(dead_code)]

use std::panic::{self, AssertUnwindSafe};
use std::sync::{Arc, Mutex, mpsc};
use std::time::Duration;

use mpm_mesh::SplitMix64;

/// The environment variable `name` as a non-negative integer; a value
/// that is not one stops the run with its name.
pub fn env_number(name: &str) -> Option<u64> {
    let text = std::env::var(name).ok()?;
    match text.trim().parse() {
        Ok(v) => Some(v),
        Err(_) => panic!("{name}={text:?} is not a non-negative integer"),
    }
}

/// The process's peak resident memory (KiB), from `/proc/self/status`.
pub fn peak_memory_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Uniform choices on top of [`SplitMix64`].
pub struct Rng(pub SplitMix64);

impl Rng {
    /// The generator of case `case` of seed `seed`.
    pub fn for_case(seed: u64, case: usize) -> Self {
        let mut mix = SplitMix64(seed ^ (case as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93));
        mix.next_unit();
        Self(mix)
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.0.next_unit() * n as f64) as usize).min(n.saturating_sub(1))
    }

    pub fn chance(&mut self, p: f64) -> bool {
        self.0.next_unit() < p
    }

    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    pub fn unit(&mut self) -> f64 {
        self.0.next_unit()
    }
}

/// The message of the last panic on the worker (or a rayon thread).
pub static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

pub const WORKER: &str = "fuzz-worker";

pub type Hook = Arc<dyn Fn(&panic::PanicHookInfo<'_>) + Send + Sync>;

/// Silences panics of the worker (and of unnamed threads it may use)
/// while recording their message; other threads keep the previous hook,
/// which is returned to be put back by [`restore_hook`].
pub fn install_quiet_hook() -> Hook {
    let previous: Hook = Arc::from(panic::take_hook());
    let kept = Arc::clone(&previous);
    panic::set_hook(Box::new(move |info| {
        let name = std::thread::current().name().map(str::to_owned);
        if name.as_deref().is_none_or(|n| n == WORKER) {
            *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = Some(info.to_string());
        } else {
            kept(info);
        }
    }));
    previous
}

pub fn restore_hook(previous: Hook) {
    panic::set_hook(Box::new(move |info| previous(info)));
}

pub type Job<T> = Box<dyn FnOnce() -> T + Send>;

/// How one input ended on the worker.
pub enum Ran<T> {
    Done(T),
    Panicked(String),
    TimedOut,
}

/// A thread (8 MiB of stack, as a main thread) that runs one job at a time.
pub struct Worker<T> {
    jobs: mpsc::Sender<Job<T>>,
    results: mpsc::Receiver<std::thread::Result<T>>,
}

impl<T: Send + 'static> Worker<T> {
    pub fn new() -> Self {
        let (jobs, job_rx) = mpsc::channel::<Job<T>>();
        let (result_tx, results) = mpsc::channel();
        std::thread::Builder::new()
            .name(WORKER.into())
            .stack_size(8 << 20)
            .spawn(move || {
                for job in job_rx {
                    let r = panic::catch_unwind(AssertUnwindSafe(job));
                    if result_tx.send(r).is_err() {
                        break;
                    }
                }
            })
            .expect("cannot start the fuzz worker");
        Self { jobs, results }
    }

    /// Runs `job`, waiting at most `timeout`. After a time-out the worker
    /// is still busy: the caller must stop using it.
    pub fn run(&self, job: Job<T>, timeout: Duration) -> Ran<T> {
        *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = None;
        self.jobs.send(job).expect("the fuzz worker stopped");
        match self.results.recv_timeout(timeout) {
            Ok(Ok(v)) => Ran::Done(v),
            Ok(Err(payload)) => {
                let recorded = LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()).take();
                Ran::Panicked(recorded.unwrap_or_else(|| {
                    payload
                        .downcast_ref::<&str>()
                        .map(|s| (*s).to_owned())
                        .or_else(|| payload.downcast_ref::<String>().cloned())
                        .unwrap_or_else(|| "a panic with a non-string payload".into())
                }))
            }
            Err(_) => Ran::TimedOut,
        }
    }
}

/// Fails with every finding of `lists` (a label and its findings), one a
/// line, and how to replay one (`replay`: the form of the replay
/// variable's value).
pub fn assert_no_findings(lists: &[(&str, &Vec<String>)], replay: &str) {
    let mut failures = Vec::new();
    for (label, list) in lists {
        failures.extend(list.iter().map(|f| format!("{label}: {f}")));
    }
    assert!(
        failures.is_empty(),
        "{} findings (replay one with MPM_FUZZ_REPLAY={replay}):\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Run parameters, from the environment (`MPM_FUZZ_SEED`, default 16;
/// `MPM_FUZZ_CASES`, default `default_cases`, unbounded when only a
/// budget is given; `MPM_FUZZ_BUDGET_SECS`, default 20;
/// `MPM_FUZZ_TIMEOUT_SECS`, default 10).
pub struct Config {
    pub seed: u64,
    pub cases: usize,
    pub budget: Duration,
    pub timeout: Duration,
}

impl Config {
    pub fn from_env(default_cases: usize) -> Self {
        let budget = env_number("MPM_FUZZ_BUDGET_SECS");
        let cases = env_number("MPM_FUZZ_CASES");
        Self {
            seed: env_number("MPM_FUZZ_SEED").unwrap_or(16),
            cases: match (cases, budget) {
                (Some(n), _) => n as usize,
                (None, Some(_)) => usize::MAX,
                (None, None) => default_cases,
            },
            budget: Duration::from_secs(budget.unwrap_or(20)),
            timeout: Duration::from_secs(env_number("MPM_FUZZ_TIMEOUT_SECS").unwrap_or(10)),
        }
    }
}
