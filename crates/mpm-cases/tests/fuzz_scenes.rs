//! Structured fuzzing of whole-problem scene files (issue 16): the
//! committed scenes (`scenes/*.toml` without a `case` key, implicit and
//! explicit, grid, simplex, annulus and Gmsh meshes) are mutated as TOML
//! documents — keys and tables deleted, duplicated, renamed, moved to
//! other tables, arrays reordered, lengthened or shortened, values
//! replaced by values of other types, by extreme numbers (0, −0.0, −1,
//! ±1e308, 1e-300, 5e-324, NaN, ±∞, `i64::MAX`, 1e9), by empty strings,
//! arrays and tables, by names that are not in an enumeration (or the
//! value of another enumerated key: `basis = "hencky"`), values swapped
//! between keys, keys of other scenes added — and as text: cut at any
//! character, tokens inserted (brackets, quotes, `1e999`, NUL, BOM,
//! up to 5000 nested arrays or inline tables),
//! lines deleted, duplicated or swapped; some mutants also get random
//! `--set` overrides (good, misspelt, malformed). Every mutant is parsed
//! ([`scene::parse`]) and built ([`Problem::build_in`]); of the cheap
//! scenes, a quarter of the mutants that build are also run by
//! [`scene::run_file`] into a scratch directory, stopped after the first
//! converged load step (`stop_after`) and, for explicit scenes, with
//! `end_time` cut to a thousandth. Each outcome must be `Ok` or a
//! [`CasesError`]; a panic or an input taking longer than the time limit
//! fails the test, with the input written under `target/tmp/fuzz_scenes/`
//! (`.toml`, plus `.set` with its overrides) to be replayed.
//!
//! Sizes: the generator's numbers are a fixed list of extremes (0, ±1, 2,
//! 3, 100, ±1e9, 2³², `i64::MAX`, …) and small changes of the scene's own
//! values (×2, +1, ×10 for floats, …), so a mutant asks either for a size
//! near the original's or for an absurd one (1e9 cells, 1e308 m with a
//! 1e-300 m spacing) that the builder must refuse with a typed error
//! (`MAX_ENTITIES`: 5 × 10⁷ nodes, points or simplices). It does not ask
//! for sizes in between, such as `cells = [4, 65536, 2]` on the notched
//! plate (2.5 × 10⁷ tetrahedra, valid and merely slow: it took the one
//! time-out of the first five-minute run, and 65536 left the list). The
//! explicit solver's step count is bounded by the builder (1e9 steps),
//! not by the fuzzer; the runs bound it by cutting `end_time`.
//!
//! Skipped bases: `wang2021_vane_full.toml` (its 7 MB mesh takes seconds
//! to read and build; the Gmsh reader is fuzzed on its own by
//! `mpm-mesh/tests/fuzz_gmsh.rs`) and the scenes with a `case` key, which
//! belong to the built-in cases, not to this parser.
//!
//! The mutator is a small in-file generator on the workspace's
//! [`SplitMix64`] rather than `proptest` (a dev-dependency of this crate):
//! the run is bounded by a number of cases *and* by wall-clock seconds
//! (proptest has no time budget), every input goes through `catch_unwind`
//! on a worker thread with a time limit (proptest would shrink a hanging
//! input by running it again and again), and the mutations work on the
//! real scenes' documents with a corpus of their keys, values and names,
//! simpler as code than as strategies. Case `i` of seed `s` is always the
//! same input, so a run is reproducible from the seed alone.
//!
//! Environment (defaults give a CI run of about 12 s in release):
//! - `MPM_FUZZ_SEED` (default 16): the seed;
//! - `MPM_FUZZ_CASES` (default 1500): the number of mutants;
//! - `MPM_FUZZ_BUDGET_SECS` (default 20): stop after this many seconds
//!   (a cap for slow machines: the default run is the first 1500 cases);
//!   given without `MPM_FUZZ_CASES`, the number of cases is unbounded, so
//!   `MPM_FUZZ_BUDGET_SECS=300` is a five-minute run;
//! - `MPM_FUZZ_TIMEOUT_SECS` (default 10; runs get three times as long):
//!   the time limit of one input;
//! - `MPM_FUZZ_REPLAY=path.toml`: parse, build and run that one file (with
//!   the overrides of `path.set`, one a line) without catching panics.
//!
//! ```sh
//! cargo test --release -p mpm-cases --test suite fuzz_scenes -- --nocapture
//! MPM_FUZZ_BUDGET_SECS=300 cargo test --release -p mpm-cases --test suite fuzz_scenes -- --nocapture
//! ```
//!
//! Rejections are counted by kind: the [`CasesError`] variant and the
//! first words of its message (names and numbers blanked), each printed
//! with one example message.
#![allow(missing_docs)]

#[path = "../../mpm-mesh/tests/fuzz_support/mod.rs"]
mod fuzz_support;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use mpm_cases::CasesError;
use mpm_cases::scene::SceneError;
use mpm_cases::scene::{self, Problem};
use mpm_cases::session::Session;
use toml::{Table, Value};

use fuzz_support::{
    Config, Ran, Rng, Worker, assert_no_findings, install_quiet_hook, peak_memory_kib, restore_hook,
};

/// How far a base scene's mutants go.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Cost {
    /// Parse and build.
    Build,
    /// Parse, build, and a quarter of the mutants that build also run.
    Run,
}

/// The base scenes (in `scenes/`).
const BASES: [(&str, Cost); 23] = [
    ("features.toml", Cost::Run),
    ("two_layer_column.toml", Cost::Run),
    ("coombs2020_column.toml", Cost::Run),
    ("coombs2020_annulus.toml", Cost::Run),
    ("coombs2020_cantilever.toml", Cost::Run),
    ("coombs2020_collapse.toml", Cost::Run),
    ("coombs2020_shear.toml", Cost::Run),
    ("slope.toml", Cost::Run),
    ("explicit_bar.toml", Cost::Run),
    ("explicit_disks.toml", Cost::Run),
    ("explicit_cube.toml", Cost::Build),
    ("sliding_block.toml", Cost::Run),
    ("rolling_cylinder.toml", Cost::Run),
    ("platen_cube.toml", Cost::Run),
    ("sliding_block_contact.toml", Cost::Run),
    ("explicit_absorbing_column.toml", Cost::Run),
    ("explicit_absorbing_gravity.toml", Cost::Run),
    ("cube_gmsh.toml", Cost::Run),
    ("wang2021_stretch.toml", Cost::Run),
    ("wang2021_footing.toml", Cost::Build),
    ("wang2021_indentation.toml", Cost::Build),
    ("wang2021_notched_plate.toml", Cost::Build),
    ("wang2021_vane_slice.toml", Cost::Build),
];

/// Fraction of the mutants of [`Cost::Run`] scenes that build which are
/// also run.
const RUN_FRACTION: f64 = 0.25;

// ---------------------------------------------------------------------------
// Configuration, random source, worker with a time limit.

// ---------------------------------------------------------------------------
// Paths into a TOML document.

#[derive(Debug, Clone, PartialEq)]
enum Seg {
    Key(String),
    Index(usize),
}

/// Every node below `v` (not `v` itself), parents before children.
fn all_paths(v: &Value, prefix: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
    let children: Vec<(Seg, &Value)> = match v {
        Value::Table(t) => t.iter().map(|(k, c)| (Seg::Key(k.clone()), c)).collect(),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .map(|(i, c)| (Seg::Index(i), c))
            .collect(),
        _ => Vec::new(),
    };
    for (seg, child) in children {
        prefix.push(seg);
        out.push(prefix.clone());
        all_paths(child, prefix, out);
        prefix.pop();
    }
}

fn node_mut<'a>(v: &'a mut Value, path: &[Seg]) -> Option<&'a mut Value> {
    let mut here = v;
    for seg in path {
        here = match (seg, here) {
            (Seg::Key(k), Value::Table(t)) => t.get_mut(k)?,
            (Seg::Index(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(here)
}

fn node<'a>(v: &'a Value, path: &[Seg]) -> Option<&'a Value> {
    let mut here = v;
    for seg in path {
        here = match (seg, here) {
            (Seg::Key(k), Value::Table(t)) => t.get(k)?,
            (Seg::Index(i), Value::Array(a)) => a.get(*i)?,
            _ => return None,
        };
    }
    Some(here)
}

fn remove(v: &mut Value, path: &[Seg]) -> Option<Value> {
    let (last, parent) = path.split_last()?;
    match (last, node_mut(v, parent)?) {
        (Seg::Key(k), Value::Table(t)) => t.remove(k),
        (Seg::Index(i), Value::Array(a)) if *i < a.len() => Some(a.remove(*i)),
        _ => None,
    }
}

/// The override key of `path` (`body.1.region.box.lower`).
fn dotted(path: &[Seg]) -> String {
    path.iter()
        .map(|s| match s {
            Seg::Key(k) => k.clone(),
            Seg::Index(i) => i.to_string(),
        })
        .collect::<Vec<_>>()
        .join(".")
}

// ---------------------------------------------------------------------------
// The corpus: what the committed scenes hold.

#[derive(Default)]
struct Corpus {
    strings: Vec<String>,
    keys: Vec<String>,
    pairs: Vec<(String, Value)>,
    paths: Vec<String>,
}

impl Corpus {
    fn add(&mut self, root: &Value) {
        let mut paths = Vec::new();
        all_paths(root, &mut Vec::new(), &mut paths);
        for path in paths {
            let Some(v) = node(root, &path) else { continue };
            if let Value::String(s) = v {
                self.strings.push(s.clone());
            }
            if let Some(Seg::Key(k)) = path.last() {
                self.keys.push(k.clone());
                self.pairs.push((k.clone(), v.clone()));
            }
            self.paths.push(dotted(&path));
        }
        for list in [&mut self.strings, &mut self.keys, &mut self.paths] {
            list.sort();
            list.dedup();
        }
    }
}

// ---------------------------------------------------------------------------
// Values.

const INTEGERS: [i64; 11] = [
    0,
    -1,
    1,
    2,
    3,
    100,
    1_000_000_000,
    4_294_967_296,
    i64::MAX,
    i64::MIN,
    -1_000_000_000,
];

const FLOATS: [f64; 18] = [
    0.0,
    -0.0,
    -1.0,
    1.0,
    0.5,
    1e308,
    -1e308,
    1e-300,
    -1e-300,
    5e-324,
    f64::MAX,
    f64::MIN_POSITIVE,
    1e20,
    -1e20,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e9,
];

const STRINGS: [&str; 18] = [
    "",
    "nan",
    "inf",
    "-0.0",
    "1e308",
    "bogus",
    " ",
    "LINEAR",
    "linear ",
    "é",
    "\u{0}",
    "\n",
    "meshes",
    "meshes/missing.msh",
    "/",
    "a.b",
    "[1, 2]",
    "x_min ",
];

fn odd_string(rng: &mut Rng, corpus: &Corpus) -> String {
    match rng.below(5) {
        0 | 1 => rng.pick(&corpus.strings).clone(),
        2 => "x".repeat(1 + rng.below(10_000)),
        _ => (*rng.pick(&STRINGS)).to_owned(),
    }
}

fn random_value(rng: &mut Rng, corpus: &Corpus, depth: usize) -> Value {
    match rng.below(if depth > 2 { 6 } else { 9 }) {
        0 => Value::Integer(*rng.pick(&INTEGERS)),
        1 => Value::Float(*rng.pick(&FLOATS)),
        2 => Value::String(odd_string(rng, corpus)),
        3 => Value::Boolean(rng.chance(0.5)),
        4 => Value::Datetime("1979-05-27T07:32:00Z".parse().expect("a date")),
        5 => rng.pick(&corpus.pairs).1.clone(),
        6 => Value::Array(Vec::new()),
        7 => Value::Array(
            (0..1 + rng.below(4))
                .map(|_| random_value(rng, corpus, depth + 1))
                .collect(),
        ),
        _ => {
            let mut t = Table::new();
            for _ in 0..rng.below(3) {
                let key = rng.pick(&corpus.keys).clone();
                t.insert(key, random_value(rng, corpus, depth + 1));
            }
            Value::Table(t)
        }
    }
}

/// A number near `v` (or an extreme one).
fn perturbed(v: &Value, rng: &mut Rng) -> Option<Value> {
    Some(match v {
        Value::Integer(i) => Value::Integer(match rng.below(5) {
            0 => i.saturating_add(1),
            1 => i.saturating_sub(1),
            2 => i.saturating_mul(2),
            3 => -i,
            _ => 0,
        }),
        Value::Float(x) => Value::Float(match rng.below(8) {
            0 => x * 2.0,
            1 => x + 1.0,
            2 => -x,
            3 => x / 2.0,
            4 => x * 0.1,
            5 => x * 10.0,
            6 => x + 0.5,
            _ => x * (1.0 + 1e-12),
        }),
        _ => return None,
    })
}

// ---------------------------------------------------------------------------
// Mutations.

/// One mutation of the document; returns its name.
fn mutate_tree(root: &mut Value, corpus: &Corpus, rng: &mut Rng) -> &'static str {
    let mut paths = Vec::new();
    all_paths(root, &mut Vec::new(), &mut paths);
    if paths.is_empty() {
        if let Value::Table(t) = root {
            let (k, v) = rng.pick(&corpus.pairs).clone();
            t.insert(k, v);
        }
        return "key added";
    }
    let path = rng.pick(&paths).clone();
    let of_kind = |pred: &dyn Fn(&Value) -> bool| -> Vec<Vec<Seg>> {
        paths
            .iter()
            .filter(|p| node(root, p).is_some_and(pred))
            .cloned()
            .collect()
    };
    let arrays = of_kind(&|v| matches!(v, Value::Array(_)));
    let numbers = of_kind(&|v| matches!(v, Value::Integer(_) | Value::Float(_)));
    let strings = of_kind(&|v| matches!(v, Value::String(_)));
    let mut tables = of_kind(&|v| matches!(v, Value::Table(_)));
    tables.push(Vec::new());
    match rng.below(14) {
        0 | 1 => {
            remove(root, &path);
            "deleted"
        }
        2 => {
            // Duplicated: in its array, or under another key of its table.
            let value = node(root, &path).cloned();
            let (last, parent) = path.split_last().expect("a non-empty path");
            match (node_mut(root, parent), value, last) {
                (Some(Value::Array(a)), Some(v), _) => {
                    let at = rng.below(a.len() + 1);
                    a.insert(at, v);
                }
                (Some(Value::Table(t)), Some(v), Seg::Key(_)) => {
                    t.insert(rng.pick(&corpus.keys).clone(), v);
                }
                _ => {}
            }
            "duplicated"
        }
        3 => {
            if let Some(p) = arrays.get(rng.below(arrays.len().max(1)))
                && let Some(Value::Array(a)) = node_mut(root, p)
                && !a.is_empty()
            {
                match rng.below(3) {
                    0 => a.reverse(),
                    1 => {
                        let k = rng.below(a.len());
                        a.rotate_left(k);
                    }
                    _ => {
                        let (i, j) = (rng.below(a.len()), rng.below(a.len()));
                        a.swap(i, j);
                    }
                }
            }
            "reordered"
        }
        4 | 5 => {
            let v = random_value(rng, corpus, 0);
            if let Some(n) = node_mut(root, &path) {
                *n = v;
            }
            "replaced"
        }
        6 => {
            if let Some(p) = numbers.get(rng.below(numbers.len().max(1))) {
                let v = if rng.chance(0.5) {
                    Value::Integer(*rng.pick(&INTEGERS))
                } else {
                    Value::Float(*rng.pick(&FLOATS))
                };
                if let Some(n) = node_mut(root, p) {
                    *n = v;
                }
            }
            "extreme number"
        }
        7 => {
            let v = match rng.below(3) {
                0 => Value::String(String::new()),
                1 => Value::Array(Vec::new()),
                _ => Value::Table(Table::new()),
            };
            if let Some(n) = node_mut(root, &path) {
                *n = v;
            }
            "emptied"
        }
        8 => {
            if let Some(p) = strings.get(rng.below(strings.len().max(1))) {
                let v = odd_string(rng, corpus);
                if let Some(n) = node_mut(root, p) {
                    *n = Value::String(v);
                }
            }
            "name or enumeration"
        }
        9 => {
            let other = rng.pick(&paths).clone();
            let ancestor = |a: &[Seg], b: &[Seg]| b.starts_with(a);
            if !ancestor(&path, &other) && !ancestor(&other, &path) {
                let (a, b) = (node(root, &path).cloned(), node(root, &other).cloned());
                if let (Some(a), Some(b)) = (a, b) {
                    if let Some(n) = node_mut(root, &path) {
                        *n = b;
                    }
                    if let Some(n) = node_mut(root, &other) {
                        *n = a;
                    }
                }
            }
            "swapped"
        }
        10 => {
            if let Some(p) = numbers.get(rng.below(numbers.len().max(1)))
                && let Some(n) = node_mut(root, p)
                && let Some(v) = perturbed(n, rng)
            {
                *n = v;
            }
            "perturbed"
        }
        11 => {
            // Renamed: misspelt, or another scene key.
            if let Some(Seg::Key(k)) = path.last() {
                let new = match rng.below(3) {
                    0 => format!("{k}x"),
                    1 => k.to_uppercase(),
                    _ => rng.pick(&corpus.keys).clone(),
                };
                let parent = &path[..path.len() - 1];
                if let Some(v) = remove(root, &path)
                    && let Some(Value::Table(t)) = node_mut(root, parent)
                {
                    t.insert(new, v);
                }
            }
            "renamed"
        }
        12 => {
            if let Some(p) = arrays.get(rng.below(arrays.len().max(1)))
                && let Some(Value::Array(a)) = node_mut(root, p)
            {
                match (rng.below(3), a.last().cloned()) {
                    (0, _) => {
                        a.pop();
                    }
                    (1, Some(last)) => a.push(last),
                    _ => a.push(random_value(rng, corpus, 1)),
                }
            }
            "array length"
        }
        _ => {
            // A key of some scene added to some table (possibly moved
            // from its own table).
            let (key, value) = if rng.chance(0.5)
                && let Some(Seg::Key(k)) = path.last()
                && let Some(v) = remove(root, &path)
            {
                (k.clone(), v)
            } else {
                rng.pick(&corpus.pairs).clone()
            };
            let target = rng.pick(&tables).clone();
            if let Some(Value::Table(t)) = node_mut(root, &target) {
                t.insert(key, value);
            }
            "key added or moved"
        }
    }
}

/// Tokens inserted into the text.
const TOKENS: [&str; 34] = [
    "[",
    "]",
    "[[",
    "]]",
    "{",
    "}",
    "=",
    ",",
    "\"",
    "'",
    "'''",
    "\"\"\"",
    "\n",
    "#",
    "\t",
    "\r",
    "\0",
    "\u{feff}",
    "é",
    "inf",
    "nan",
    "-0.0",
    "1e999",
    "99999999999999999999",
    "0x7fffffffffffffff",
    "1979-05-27",
    "true",
    "\n[mesh]\n",
    "\n[[body]]\n",
    "\n[solver]\n",
    "\nkind = \"explicit\"\n",
    "\\u0000",
    "\\",
    "\n[[material]]\nname = \"soil\"\n",
];

fn char_boundary(text: &str, rng: &mut Rng) -> usize {
    let mut at = rng.below(text.len() + 1);
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    at
}

/// One mutation of the text.
fn mutate_text(text: &mut String, rng: &mut Rng) -> &'static str {
    match rng.below(7) {
        0 => {
            let at = char_boundary(text, rng);
            text.truncate(at);
            "cut"
        }
        1 => {
            // Deep nesting: the TOML parser must refuse it, not overflow
            // the stack.
            let at = char_boundary(text, rng);
            let open = *rng.pick(&["[", "{ a = ", "[{ a = "]);
            text.insert_str(at, &open.repeat(1 + rng.below(5000)));
            "deep nesting"
        }
        2 => {
            let at = char_boundary(text, rng);
            text.insert_str(at, rng.pick::<&str>(&TOKENS));
            "token inserted"
        }
        3 => {
            let at = char_boundary(text, rng);
            let end = (at + 1 + rng.below(20)).min(text.len());
            let mut end = end;
            while !text.is_char_boundary(end) {
                end += 1;
            }
            text.replace_range(at..end, "");
            "characters deleted"
        }
        kind => {
            let mut lines: Vec<&str> = text.lines().collect();
            if lines.is_empty() {
                return "none";
            }
            let k = rng.below(lines.len());
            let label = match kind {
                4 => {
                    lines.remove(k);
                    "line deleted"
                }
                5 => {
                    lines.insert(k, lines[k]);
                    "line duplicated"
                }
                _ => {
                    let j = rng.below(lines.len());
                    lines.swap(k, j);
                    "lines swapped"
                }
            };
            *text = lines.join("\n");
            label
        }
    }
}

/// Overrides: existing keys, misspelt ones, malformed ones.
fn random_overrides(rng: &mut Rng, corpus: &Corpus) -> Vec<String> {
    const VALUES: [&str; 14] = [
        "",
        "[",
        "nan",
        "1e999",
        "gimp",
        "{",
        "1e308",
        "-1",
        "0",
        "[1e9, 1e9]",
        "\"\"",
        "{ box = {} }",
        "explicit",
        "1e-300",
    ];
    const MALFORMED: [&str; 7] = [
        "=1",
        "x",
        "a..b=1",
        ".=1",
        "mesh.=1",
        "material.99.density=1",
        "==",
    ];
    (0..1 + rng.below(2))
        .map(|_| match rng.below(6) {
            0 => (*rng.pick(&MALFORMED)).to_owned(),
            1 => format!("{}x={}", rng.pick(&corpus.paths), rng.pick(&VALUES)),
            2 => {
                let v = random_value(rng, corpus, 1);
                let rendered = toml::to_string(&Table::from_iter([("v".to_owned(), v)]))
                    .ok()
                    .and_then(|t| t.strip_prefix("v = ").map(|s| s.trim().to_owned()))
                    .unwrap_or_default();
                format!("{}={rendered}", rng.pick(&corpus.paths))
            }
            _ => format!("{}={}", rng.pick(&corpus.paths), rng.pick(&VALUES)),
        })
        .collect()
}

/// A mutant of `base`: its text, overrides and mutation names; `None`
/// when the mutated document cannot be written as TOML.
fn mutant(
    text: &str,
    doc: &Value,
    corpus: &Corpus,
    rng: &mut Rng,
) -> Option<(String, Vec<String>, Vec<&'static str>)> {
    let mut applied = Vec::new();
    let mut out = if rng.chance(0.12) {
        // The file as written (comments, layout), mutated as text only.
        let mut t = text.to_owned();
        for _ in 0..1 + rng.below(2) {
            applied.push(mutate_text(&mut t, rng));
        }
        t
    } else {
        let mut d = doc.clone();
        // Mostly one mutation, so that many mutants get past the parser
        // to the builder's checks.
        let count = if rng.chance(0.6) { 1 } else { 2 + rng.below(2) };
        for _ in 0..count {
            applied.push(mutate_tree(&mut d, corpus, rng));
        }
        let Value::Table(t) = d else {
            return None;
        };
        toml::to_string(&t).ok()?
    };
    if rng.chance(0.2) {
        applied.push(mutate_text(&mut out, rng));
    }
    let set = if rng.chance(0.1) {
        applied.push("overrides");
        random_overrides(rng, corpus)
    } else {
        Vec::new()
    };
    Some((out, set, applied))
}

// ---------------------------------------------------------------------------
// Running one input.

const ORIGIN: &str = "mutant.toml";

/// Parses and builds; `Ok(true)` for an explicit scene.
fn build(text: &str, set: &[String], dir: &Path) -> Result<bool, SceneError> {
    let (scene, source) = scene::parse(text, ORIGIN, set)?;
    match scene::dimension(&scene, &source)? {
        2 => Problem::<2>::build_in(&scene, &source, scene.solver.padding(), dir)
            .map(|p| p.explicit.is_some()),
        _ => Problem::<3>::build_in(&scene, &source, scene.solver.padding(), dir)
            .map(|p| p.explicit.is_some()),
    }
}

/// Runs into `out` (emptied first), stopping after one load step or output.
fn run(text: &str, set: &[String], dir: &Path, out: &Path) -> Result<(), CasesError> {
    if out.exists() {
        std::fs::remove_dir_all(out).map_err(|source| CasesError::Io {
            path: out.to_path_buf(),
            source,
        })?;
    }
    let session = Session {
        case: "scene".into(),
        out: out.to_path_buf(),
        resume: false,
        stop_after: Some(1),
        export_tangent: false,
        scene_dir: dir.to_path_buf(),
        ranks: None,
    };
    scene::run_file(text, ORIGIN, set, &session)
}

/// The first `n` words of `message`, with names in backticks or quotes,
/// paths and numbers blanked.
fn first_words(message: &str, n: usize) -> String {
    let mut blanked = String::new();
    let mut open: Option<char> = None;
    for c in message.chars() {
        match open {
            Some(q) if c == q => {
                blanked.push('…');
                blanked.push(q);
                open = None;
            }
            Some(_) => {}
            None if c == '`' || c == '"' => {
                blanked.push(c);
                open = Some(c);
            }
            None => blanked.push(c),
        }
    }
    blanked
        .split_whitespace()
        .take(n)
        .map(|w| {
            if w.contains('/') || w.contains(".msh") || w.contains(".toml") {
                "<path>"
            } else if w.contains(|c: char| c.is_ascii_digit()) {
                "#"
            } else {
                w
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// `text` cut to `n` characters.
fn shortened(text: &str, n: usize) -> String {
    match text.char_indices().nth(n) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_owned(),
    }
}

/// The variant of `e` and, for scene errors, the first words.
fn kind_of(e: &CasesError) -> String {
    let head = |text: &str| {
        text.split(|c: char| !c.is_alphanumeric() && c != '_')
            .next()
            .unwrap_or("")
            .to_owned()
    };
    match e {
        CasesError::Scene(
            s @ (SceneError::Scene { message, .. }
            | SceneError::SceneUnlocated { message, .. }
            | SceneError::Override { message, .. }),
        ) => format!("{}: {}", head(&format!("{s:?}")), first_words(message, 4)),
        CasesError::Solver(s) => format!(
            "Solver({}): {}",
            head(&format!("{s:?}")),
            first_words(&s.to_string(), 4)
        ),
        _ => format!(
            "{}: {}",
            head(&format!("{e:?}")),
            first_words(&e.to_string(), 4)
        ),
    }
}

/// What became of one input.
#[derive(Debug)]
struct Outcome {
    /// Parse and build.
    built: Result<bool, CasesError>,
    /// The run, if there was one.
    ran: Option<Result<(), CasesError>>,
    took: Duration,
}

// ---------------------------------------------------------------------------
// Counting.

#[derive(Default)]
struct Tally {
    tried: usize,
    unwritable: usize,
    built: usize,
    built_explicit: usize,
    runs: usize,
    runs_ok: usize,
    /// Kind → (count, an example message).
    rejected: BTreeMap<String, (usize, String)>,
    /// Kind → (count, an example message) of the runs' errors.
    run_errors: BTreeMap<String, (usize, String)>,
    /// Rejections without a line and column, by variant.
    unlocated: BTreeMap<String, usize>,
    bad_locations: Vec<String>,
    panics: Vec<String>,
    hangs: Vec<String>,
    mutations: BTreeMap<&'static str, usize>,
    per_base: BTreeMap<&'static str, (usize, usize)>,
    slowest: (Duration, String),
}

fn count(map: &mut BTreeMap<String, (usize, String)>, e: &CasesError) {
    let entry = map
        .entry(kind_of(e))
        .or_insert_with(|| (0, shortened(&e.to_string(), 200)));
    entry.0 += 1;
}

impl Tally {
    fn rejection(&mut self, e: &CasesError, text: &str, what: &str, dump: &dyn Fn() -> PathBuf) {
        count(&mut self.rejected, e);
        match e {
            CasesError::Scene(SceneError::Scene { line, column, .. }) => {
                let lines = text.lines().count().max(1);
                if *line == 0 || *column == 0 || *line > lines + 1 {
                    self.bad_locations.push(format!(
                        "{what}: line {line} column {column} of {lines} lines: {e} ({})",
                        dump().display()
                    ));
                }
            }
            CasesError::Scene(
                SceneError::Override { .. } | SceneError::MalformedOverride { .. },
            ) => {}
            other => {
                let variant = kind_of(other);
                let variant = variant.split(':').next().unwrap_or("").to_owned();
                *self.unlocated.entry(variant).or_default() += 1;
            }
        }
    }

    fn print(&self, config: &Config, elapsed: Duration) {
        println!(
            "fuzz_scenes: seed {}, {} inputs in {:.1} s ({} mutants not writable as TOML, skipped); slowest {:.3} s ({})",
            config.seed,
            self.tried,
            elapsed.as_secs_f64(),
            self.unwritable,
            self.slowest.0.as_secs_f64(),
            self.slowest.1
        );
        println!(
            "built: {} ({} explicit); runs: {} ({} Ok or stopped after one step)",
            self.built, self.built_explicit, self.runs, self.runs_ok
        );
        let rejected: usize = self.rejected.values().map(|(n, _)| n).sum();
        let mut variants: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
        for (kind, (n, _)) in &self.rejected {
            let v = variants
                .entry(kind.split(':').next().unwrap_or(""))
                .or_default();
            v.0 += n;
            v.1 += 1;
        }
        println!("rejected by variant (rejections, kinds): {variants:?}");
        println!(
            "rejected: {rejected}, {} kinds (count, kind, example):",
            self.rejected.len()
        );
        for (kind, (count, example)) in &self.rejected {
            println!("  {count:>6}  {kind}  |  {example}");
        }
        println!(
            "run errors: {} kinds (count, kind, example):",
            self.run_errors.len()
        );
        for (kind, (count, example)) in &self.run_errors {
            println!("  {count:>6}  {kind}  |  {example}");
        }
        println!(
            "rejections without line and column, by variant: {:?}",
            self.unlocated
        );
        println!("mutations applied: {:?}", self.mutations);
        println!("inputs and builds per base: {:?}", self.per_base);
        println!(
            "panics: {}, hangs: {}, locations out of range: {}",
            self.panics.len(),
            self.hangs.len(),
            self.bad_locations.len()
        );
        if let Some(kb) = peak_memory_kib() {
            println!("peak resident memory: {} MiB", kb / 1024);
        }
    }
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("fuzz_scenes")
        .join(name);
    std::fs::create_dir_all(&dir).expect("cannot create a scratch directory");
    dir
}

/// Parses, builds and runs the file named by `MPM_FUZZ_REPLAY` (with the
/// overrides of its `.set` file) without catching panics.
fn replay(path: &str) {
    let text = std::fs::read_to_string(path).expect("cannot read the replayed file");
    let set: Vec<String> = std::fs::read_to_string(Path::new(path).with_extension("set"))
        .map(|s| s.lines().map(str::to_owned).collect())
        .unwrap_or_default();
    let dir = scenes_dir();
    println!("build: {:?}", build(&text, &set, &dir));
    println!("run: {:?}", run(&text, &set, &dir, &scratch("replay")));
}

#[test]
fn mutated_scenes_build_run_or_are_refused_with_a_typed_error() {
    if let Ok(path) = std::env::var("MPM_FUZZ_REPLAY") {
        replay(&path);
        return;
    }
    let config = Config::from_env(1500);
    let dir = scenes_dir();
    let mut corpus = Corpus::default();
    let bases: Vec<(&'static str, Cost, String, Value, Option<f64>)> = BASES
        .iter()
        .map(|&(name, cost)| {
            let text =
                std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
            let doc = Value::Table(
                text.parse::<Table>()
                    .unwrap_or_else(|e| panic!("{name}: {e}")),
            );
            corpus.add(&doc);
            let end_time = node(
                &doc,
                &[Seg::Key("solver".into()), Seg::Key("end_time".into())],
            )
            .and_then(Value::as_float);
            (name, cost, text, doc, end_time)
        })
        .collect();
    // Every base scene builds as committed.
    for (name, _, text, _, _) in &bases {
        if let Err(e) = build(text, &[], &dir) {
            panic!("{name} does not build: {e}");
        }
    }
    let findings = scratch("findings");
    let out = scratch("run");
    let mut tally = Tally::default();
    let worker: Worker<Outcome> = Worker::new();
    let previous_hook = install_quiet_hook();
    let start = Instant::now();
    for case in 0..config.cases {
        if start.elapsed() >= config.budget {
            break;
        }
        let mut rng = Rng::for_case(config.seed, case);
        let (name, cost, text, doc, end_time) = rng.pick(&bases);
        let Some((input, set, applied)) = mutant(text, doc, &corpus, &mut rng) else {
            tally.unwritable += 1;
            continue;
        };
        for m in &applied {
            *tally.mutations.entry(m).or_default() += 1;
        }
        tally.tried += 1;
        tally.per_base.entry(name).or_default().0 += 1;
        let what = format!("case {case} ({name}: {})", applied.join(", "));
        let stem = name.trim_end_matches(".toml");
        let dump = || {
            let path = findings.join(format!("seed{}-case{case}-{stem}.toml", config.seed));
            std::fs::write(&path, &input).expect("cannot write a finding");
            if !set.is_empty() {
                std::fs::write(path.with_extension("set"), set.join("\n"))
                    .expect("cannot write a finding");
            }
            path
        };
        let try_run = *cost == Cost::Run && rng.chance(RUN_FRACTION);
        let job = {
            let (input, set, dir, out) = (input.clone(), set.clone(), dir.clone(), out.clone());
            let end_time = *end_time;
            Box::new(move || {
                let t = Instant::now();
                let built = build(&input, &set, &dir).map_err(CasesError::from);
                let ran = match (&built, try_run) {
                    (Ok(explicit), true) => {
                        // An explicit run simulates a thousandth of the
                        // base scene's time.
                        let mut run_set = set.clone();
                        if *explicit && let Some(end) = end_time {
                            run_set.push(format!("solver.end_time={:e}", end / 1000.0));
                        }
                        Some(run(&input, &run_set, &dir, &out))
                    }
                    _ => None,
                };
                Outcome {
                    built,
                    ran,
                    took: t.elapsed(),
                }
            })
        };
        let limit = if try_run {
            3 * config.timeout
        } else {
            config.timeout
        };
        match worker.run(job, limit) {
            Ran::Done(outcome) => {
                if outcome.took > tally.slowest.0 {
                    tally.slowest = (outcome.took, what.clone());
                }
                match &outcome.built {
                    Ok(explicit) => {
                        tally.built += 1;
                        tally.built_explicit += usize::from(*explicit);
                        tally.per_base.entry(name).or_default().1 += 1;
                    }
                    Err(e) => tally.rejection(e, &input, &what, &dump),
                }
                if let Some(ran) = &outcome.ran {
                    tally.runs += 1;
                    match ran {
                        Ok(())
                        | Err(CasesError::Solver(mpm_solver::SolverError::Stopped { .. })) => {
                            tally.runs_ok += 1;
                        }
                        Err(e) => count(&mut tally.run_errors, e),
                    }
                }
            }
            Ran::Panicked(message) => {
                tally
                    .panics
                    .push(format!("{what}: {message} ({})", dump().display()));
            }
            Ran::TimedOut => {
                tally.hangs.push(format!(
                    "{what}: no answer in {limit:?} ({})",
                    dump().display()
                ));
                // The worker is still busy: stop here.
                break;
            }
        }
    }
    restore_hook(previous_hook);
    tally.print(&config, start.elapsed());
    assert_no_findings(
        &[
            ("panic", &tally.panics),
            ("hang", &tally.hangs),
            ("location out of range", &tally.bad_locations),
        ],
        "<file.toml>",
    );
    assert!(tally.tried > 0);
}

/// A simplex box of 200³ cells has 8 million nodes, under the limit, but
/// 384 million tetrahedra with patches (48 per cell): refused before any
/// is built (it went on to allocate them before the fuzzing).
#[test]
fn a_simplex_box_with_too_many_elements_is_refused() {
    let dir = scenes_dir();
    let text = std::fs::read_to_string(dir.join("wang2021_notched_plate.toml")).expect("the scene");
    let e = build(&text, &["mesh.cells=[200, 200, 200]".into()], &dir)
        .expect_err("a mesh of 384 million elements");
    assert!(
        matches!(&e, SceneError::Override { message, .. }
            if message.contains("the mesh would have more than 50000000 elements")),
        "{e}"
    );
}

/// The disks with `cfl` at the smallest normal float would step 1e-308 of
/// a stable step for 3 s: refused when built, as a fixed `time_step` of
/// more than 1e9 steps is (the run went on for ever before the fuzzing).
#[test]
fn a_cfl_factor_of_more_than_1e9_steps_is_refused() {
    let dir = scenes_dir();
    let text = std::fs::read_to_string(dir.join("explicit_disks.toml")).expect("the scene");
    for (cfl, refused) in [
        ("2.2250738585072014e-308", true),
        ("1e-7", true),
        ("1e-4", false),
    ] {
        let built = build(&text, &[format!("solver.cfl={cfl}")], &dir);
        match (&built, refused) {
            (Err(SceneError::Override { message, .. }), true) => assert!(
                message.contains("would take") && message.contains("more than 1e9"),
                "{message}"
            ),
            (Ok(true), false) => {}
            _ => panic!("cfl = {cfl}: {built:?}"),
        }
    }
}
