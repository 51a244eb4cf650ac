//! Structured fuzzing of the Gmsh MSH 4.1 reader (issue 16): real meshes
//! (the test data and the committed scene meshes, 2D and 3D, linear and
//! quadratic) are mutated where the format has structure — counts, node
//! and element tags, element types, coordinates (NaN, infinities,
//! 1e308, coincident nodes, zero-volume and sliver elements, one axis
//! scaled by up to 1e±10), sections (`$End…` removed, a section
//! dropped, duplicated or moved, the file cut at a line or a byte) and
//! bytes (non-UTF-8, `\r`, NUL). Every mutant is read as a 2D and as a 3D
//! mesh ([`parse_msh`]); a quadratic mesh is then split into patches
//! ([`PatchMesh::from_parents`]) and a linear one asked to locate two
//! element centroids, as the scene builder does. Each outcome must be a
//! mesh or a [`MeshError`]: a panic or an input taking longer than the
//! time limit fails the test, with the input written under
//! `target/tmp/fuzz_gmsh/` to be replayed.
//!
//! The mutator is a small in-file generator on the workspace's
//! [`SplitMix64`] rather than `proptest` (a dev-dependency of this crate):
//! the run is bounded by a number of cases *and* by wall-clock seconds
//! (proptest has no time budget), every input goes through
//! `catch_unwind` on a worker thread with a time limit (proptest would
//! shrink a hanging input by running it again), and the mutations need
//! the file's structure (which line holds a count, a node tag, the
//! coordinates of node 17), which is simpler to write as code over the
//! real files than as strategies. Case `i` of seed `s` is always the same
//! input, so a run is reproducible from the seed alone.
//!
//! Environment (defaults give a CI run of about 10 s in release):
//! - `MPM_FUZZ_SEED` (default 16): the seed;
//! - `MPM_FUZZ_CASES` (default 4000): the number of mutants;
//! - `MPM_FUZZ_BUDGET_SECS` (default 20): stop after this many seconds
//!   (a cap for slow machines: the default run is the first 4000 cases);
//!   given without `MPM_FUZZ_CASES`, the number of cases is unbounded, so
//!   `MPM_FUZZ_BUDGET_SECS=300` is a five-minute run;
//! - `MPM_FUZZ_TIMEOUT_SECS` (default 10): the time limit of one input;
//! - `MPM_FUZZ_REPLAY=path`: read that one file (2D and 3D) without
//!   catching panics, to see the backtrace.
//!
//! ```sh
//! cargo test --release -p mpm-mesh --test suite fuzz_gmsh -- --nocapture
//! MPM_FUZZ_BUDGET_SECS=300 cargo test --release -p mpm-mesh --test suite fuzz_gmsh -- --nocapture
//! ```
//!
//! The rejections are counted by kind (the [`MeshError`] variant; for
//! [`MeshError::GmshElement`] also the variant it wraps) and printed with
//! one message each; so are the rejections without a line number.
#![allow(missing_docs)]

use super::fuzz_support;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use mpm_mesh::{GmshElements, MeshError, PatchMesh, parse_msh};
use nalgebra::SVector;

use fuzz_support::{
    Config, Ran, Rng, Worker, assert_no_findings, install_quiet_hook, peak_memory_kib, restore_hook,
};

/// The base meshes: (path relative to the workspace root, dimension).
const BASES: [(&str, usize); 9] = [
    ("crates/mpm-mesh/tests/data/rectangle_tri3.msh", 2),
    ("crates/mpm-mesh/tests/data/rectangle_tri6.msh", 2),
    ("crates/mpm-mesh/tests/data/annulus_tri3.msh", 2),
    ("crates/mpm-mesh/tests/data/box_tet10.msh", 3),
    ("scenes/meshes/annulus_0.msh", 2),
    ("scenes/meshes/annulus_1.msh", 2),
    ("scenes/meshes/cube_tet10.msh", 3),
    ("scenes/meshes/vane_slice_quick.msh", 3),
    ("scenes/meshes/cylinder_slice_test.msh", 3),
];

// ---------------------------------------------------------------------------
// Configuration, random source, worker with a time limit.

// ---------------------------------------------------------------------------
// The structure of an MSH file: which line holds what.

#[derive(Debug, Clone)]
struct Node {
    tag: String,
    tag_line: usize,
    coord_line: usize,
}

#[derive(Debug, Clone)]
struct Element {
    line: usize,
    dim: usize,
    /// Node tags as written.
    nodes: Vec<String>,
}

/// Line numbers (0-based) of a valid MSH 4.1 file's parts.
#[derive(Debug, Default)]
struct Index {
    format_line: usize,
    /// Lines made of counts and tags: section and block headers, entities.
    counts: Vec<usize>,
    /// Element block headers.
    element_blocks: Vec<usize>,
    /// Node block headers.
    node_blocks: Vec<usize>,
    /// `$PhysicalNames` entries.
    names: Vec<usize>,
    nodes: Vec<Node>,
    elements: Vec<Element>,
    /// Sections as (`$Name` line, `$EndName` line).
    sections: Vec<(usize, usize)>,
    top_dim: usize,
}

fn numbers(line: &str) -> Vec<usize> {
    line.split_whitespace()
        .map(|t| t.parse().expect("a base file holds a non-number"))
        .collect()
}

impl Index {
    /// The index of a base file (valid, so this may panic on malformed
    /// input: it never sees a mutant).
    fn of(lines: &[String]) -> Self {
        let mut ix = Self::default();
        let mut i = 0;
        while i < lines.len() {
            let Some(name) = lines[i].trim().strip_prefix('$') else {
                i += 1;
                continue;
            };
            let end_tag = format!("$End{name}");
            let end = (i..lines.len())
                .find(|&j| lines[j].trim() == end_tag)
                .expect("a base file section without its end");
            ix.sections.push((i, end));
            match name {
                "MeshFormat" => ix.format_line = i + 1,
                "PhysicalNames" => {
                    ix.counts.push(i + 1);
                    ix.names.extend(i + 2..end);
                }
                "Entities" => ix.counts.extend(i + 1..end),
                "Nodes" => {
                    ix.counts.push(i + 1);
                    let blocks = numbers(&lines[i + 1])[0];
                    let mut k = i + 2;
                    for _ in 0..blocks {
                        ix.counts.push(k);
                        ix.node_blocks.push(k);
                        let n = numbers(&lines[k])[3];
                        for m in 0..n {
                            ix.nodes.push(Node {
                                tag: lines[k + 1 + m].trim().to_owned(),
                                tag_line: k + 1 + m,
                                coord_line: k + 1 + n + m,
                            });
                        }
                        k += 1 + 2 * n;
                    }
                }
                "Elements" => {
                    ix.counts.push(i + 1);
                    let blocks = numbers(&lines[i + 1])[0];
                    let mut k = i + 2;
                    for _ in 0..blocks {
                        ix.counts.push(k);
                        ix.element_blocks.push(k);
                        let header = numbers(&lines[k]);
                        let (dim, n) = (header[0], header[3]);
                        ix.top_dim = ix.top_dim.max(dim);
                        for m in 0..n {
                            let tokens: Vec<String> = lines[k + 1 + m]
                                .split_whitespace()
                                .map(str::to_owned)
                                .collect();
                            ix.elements.push(Element {
                                line: k + 1 + m,
                                dim,
                                nodes: tokens[1..].to_vec(),
                            });
                        }
                        k += 1 + n;
                    }
                }
                _ => {}
            }
            i = end + 1;
        }
        ix
    }

    fn top_elements(&self) -> Vec<&Element> {
        self.elements
            .iter()
            .filter(|e| e.dim == self.top_dim)
            .collect()
    }
}

// ---------------------------------------------------------------------------
// Mutations.

/// Replacements for counts, tags and types.
const INTEGERS: [&str; 14] = [
    "0",
    "1",
    "-1",
    "2",
    "7",
    "1000000000",
    "4294967296",
    "9223372036854775807",
    "18446744073709551615",
    "18446744073709551616",
    "99999999999999999999999",
    "1.5",
    "x",
    "",
];

/// Replacements for coordinates.
const FLOATS: [&str; 16] = [
    "nan", "NaN", "inf", "-inf", "1e308", "-1e308", "1e309", "1e-300", "-0", "0", "5e-324", "1e10",
    "-1e10", "0x1", "1,5", "",
];

/// Gmsh element types (supported or not).
const TYPES: [&str; 13] = [
    "1",
    "2",
    "3",
    "4",
    "5",
    "8",
    "9",
    "11",
    "15",
    "0",
    "99",
    "-1",
    "4294967298",
];

/// Factors for one coordinate axis of every node.
const SCALES: [f64; 9] = [1e-10, 1e-6, 1e-3, 1e3, 1e6, 1e10, 0.0, -1.0, 1e-300];

/// `$MeshFormat` data lines.
const FORMATS: [&str; 10] = [
    "4.1 1 8",
    "2.2 0 8",
    "4.0 0 8",
    "4.1 0",
    "4.1 2 8",
    "4.1 0 4",
    "4.1",
    "",
    "4.1 0 8 9",
    "41 0 8",
];

/// Token `k` of `line` replaced by `value` (appended if the line is
/// shorter; an empty `value` removes the token).
fn set_token(line: &str, k: usize, value: &str) -> String {
    let mut tokens: Vec<&str> = line.split_whitespace().collect();
    if k < tokens.len() {
        if value.is_empty() {
            tokens.remove(k);
        } else {
            tokens[k] = value;
        }
    } else if !value.is_empty() {
        tokens.push(value);
    }
    tokens.join(" ")
}

fn coordinates(line: &str) -> [f64; 3] {
    let mut xyz = [0.0; 3];
    for (x, t) in xyz.iter_mut().zip(line.split_whitespace()) {
        *x = t.parse().unwrap_or(0.0);
    }
    xyz
}

fn write_coordinates(xyz: [f64; 3]) -> String {
    format!("{:e} {:e} {:e}", xyz[0], xyz[1], xyz[2])
}

/// An integer derived from `value` (±1, doubled) or one of [`INTEGERS`].
fn integer_like(value: &str, rng: &mut Rng) -> String {
    match (value.parse::<i64>(), rng.below(4)) {
        (Ok(v), 0) => v.saturating_add(1).to_string(),
        (Ok(v), 1) => v.saturating_sub(1).to_string(),
        (Ok(v), 2) => v.saturating_mul(2).to_string(),
        _ => (*rng.pick(&INTEGERS)).to_owned(),
    }
}

/// One mutation that uses the base file's structure (valid until the
/// lines are added or removed); returns its name.
fn mutate_structure(lines: &mut [String], ix: &Index, rng: &mut Rng) -> &'static str {
    let tops = ix.top_elements();
    let max_tag = ix
        .nodes
        .iter()
        .filter_map(|n| n.tag.parse::<u64>().ok())
        .max()
        .unwrap_or(0);
    match rng.below(17) {
        0 => {
            let line = *rng.pick(&ix.counts);
            let tokens: Vec<String> = lines[line].split_whitespace().map(str::to_owned).collect();
            let k = rng.below(tokens.len().max(1));
            let value = integer_like(tokens.get(k).map_or("0", String::as_str), rng);
            lines[line] = set_token(&lines[line], k, &value);
            "count"
        }
        1 => {
            let node = rng.pick(&ix.nodes);
            let value = match rng.below(4) {
                0 => rng.pick(&ix.nodes).tag.clone(),
                1 => (max_tag + 1 + rng.below(10) as u64).to_string(),
                _ => (*rng.pick(&INTEGERS)).to_owned(),
            };
            lines[node.tag_line] = value;
            "node tag"
        }
        2 => {
            let element = rng.pick(&ix.elements);
            let slot = rng.below(element.nodes.len());
            let value = match rng.below(5) {
                0 => element.nodes[rng.below(element.nodes.len())].clone(),
                1 => rng.pick(&ix.nodes).tag.clone(),
                2 => (max_tag + 1 + rng.below(10) as u64).to_string(),
                _ => (*rng.pick(&INTEGERS)).to_owned(),
            };
            lines[element.line] = set_token(&lines[element.line], slot + 1, &value);
            "element node"
        }
        3 => {
            let line = *rng.pick(&ix.element_blocks);
            lines[line] = set_token(&lines[line], 2, rng.pick::<&str>(&TYPES));
            "element type"
        }
        4 => {
            let node = rng.pick(&ix.nodes);
            let k = rng.below(3);
            lines[node.coord_line] =
                set_token(&lines[node.coord_line], k, rng.pick::<&str>(&FLOATS));
            "coordinate"
        }
        5 => {
            // Two distinct nodes at the same place.
            let a = rng.pick(&ix.nodes).coord_line;
            let b = rng.pick(&ix.nodes).coord_line;
            lines[b] = lines[a].clone();
            "coincident nodes"
        }
        6 | 7 => {
            // Zero-volume or sliver: the last corner of an element moved to
            // (near) the centroid of its other corners; or two corners
            // made to coincide.
            let Some(element) = tops.get(rng.below(tops.len())) else {
                return "none";
            };
            let corners = element.dim + 1;
            let line_of = |tag: &str| ix.nodes.iter().find(|n| n.tag == tag).map(|n| n.coord_line);
            let Some(at): Option<Vec<usize>> = element.nodes[..corners]
                .iter()
                .map(|t| line_of(t))
                .collect()
            else {
                return "none";
            };
            let xyz: Vec<[f64; 3]> = at.iter().map(|&l| coordinates(&lines[l])).collect();
            if rng.chance(0.5) {
                let mut c = [0.0; 3];
                for p in &xyz[..corners - 1] {
                    for a in 0..3 {
                        c[a] += p[a] / (corners - 1) as f64;
                    }
                }
                let eps = *rng.pick(&[0.0, 1e-14, 1e-12, 1e-9, 1e-6]);
                for x in c.iter_mut().take(ix.top_dim) {
                    *x += eps * (rng.unit() - 0.5);
                }
                lines[at[corners - 1]] = write_coordinates(c);
                "flat element"
            } else {
                lines[at[1]] = lines[at[0]].clone();
                "collapsed edge"
            }
        }
        8 => {
            let axis = rng.below(ix.top_dim.max(1));
            let s = *rng.pick(&SCALES);
            for node in &ix.nodes {
                let mut xyz = coordinates(&lines[node.coord_line]);
                xyz[axis] *= s;
                lines[node.coord_line] = write_coordinates(xyz);
            }
            "scaled axis"
        }
        9 => {
            let line = *rng.pick(&ix.element_blocks);
            let k = rng.below(2);
            let value = integer_like(lines[line].split_whitespace().nth(k).unwrap_or("0"), rng);
            lines[line] = set_token(&lines[line], k, &value);
            "element block entity"
        }
        10 => {
            let element = rng.pick(&ix.elements);
            let line = &mut lines[element.line];
            if rng.chance(0.5) {
                line.push_str(" 1");
            } else {
                let n = line.split_whitespace().count();
                *line = set_token(line, n - 1, "");
            }
            "element length"
        }
        11 => {
            let line = *rng.pick(&ix.node_blocks);
            lines[line] = set_token(&lines[line], 2, rng.pick::<&str>(&["1", "2", "-1"]));
            "parametric flag"
        }
        12 => {
            lines[ix.format_line] = (*rng.pick(&FORMATS)).to_owned();
            "format"
        }
        13 => {
            let Some(&line) = ix.names.get(rng.below(ix.names.len().max(1))) else {
                return "none";
            };
            let text = lines[line].clone();
            lines[line] = match rng.below(4) {
                0 => text.replacen('"', "", 1),
                1 => text.replace('"', ""),
                2 => set_token(&text, rng.below(2), rng.pick::<&str>(&INTEGERS)),
                _ => format!("{text} \"extra\""),
            };
            "physical name"
        }
        14 => {
            // Huge declared counts: every $Nodes/$Elements header count and
            // one block's count.
            let line = *rng.pick(&ix.counts[..]);
            let k = rng.below(4);
            lines[line] = set_token(
                &lines[line],
                k,
                rng.pick::<&str>(&["1000000000", "4294967296"]),
            );
            "huge count"
        }
        15 => {
            let a = rng.pick(&ix.nodes).tag_line;
            let b = rng.pick(&ix.nodes).tag_line;
            lines.swap(a, b);
            "swapped node tags"
        }
        _ => {
            // An element written twice (same tag, same nodes) in place of
            // another of its block.
            let element = rng.pick(&ix.elements);
            let other = rng.pick(&ix.elements);
            if other.dim == element.dim {
                lines[other.line] = lines[element.line].clone();
            }
            "repeated element"
        }
    }
}

/// One mutation of the line structure: sections and lines.
fn mutate_lines(lines: &mut Vec<String>, ix: &Index, rng: &mut Rng) -> &'static str {
    let n = lines.len();
    match rng.below(10) {
        0 => {
            let (_, end) = *rng.pick(&ix.sections);
            lines.remove(end);
            "no $End"
        }
        1 => {
            let (start, end) = *rng.pick(&ix.sections);
            lines.drain(start..=end);
            "section removed"
        }
        2 => {
            let (start, end) = *rng.pick(&ix.sections);
            let copy: Vec<String> = lines[start..=end].to_vec();
            lines.splice(end + 1..end + 1, copy);
            "section duplicated"
        }
        3 => {
            // The last section moved to the front of another.
            let (a, _) = *rng.pick(&ix.sections);
            let &(start, end) = ix.sections.last().expect("sections");
            if a < start {
                let moved: Vec<String> = lines.drain(start..=end).collect();
                lines.splice(a..a, moved);
            }
            "section moved"
        }
        4 => {
            lines.truncate(rng.below(n));
            "cut at a line"
        }
        5 => {
            lines.remove(rng.below(n));
            "line removed"
        }
        6 => {
            let k = rng.below(n);
            let copy = lines[k].clone();
            lines.insert(k, copy);
            "line duplicated"
        }
        7 => {
            let (a, b) = (rng.below(n), rng.below(n));
            lines.swap(a, b);
            "lines swapped"
        }
        8 => {
            let junk = *rng.pick(&["", "   ", "$", "$Foo", "$EndFoo", "# comment", "1 2 3"]);
            lines.insert(rng.below(n + 1), junk.to_owned());
            "line inserted"
        }
        _ if n < 2 => "none",
        _ => {
            let k = rng.below(n - 1);
            let next = lines.remove(k + 1);
            lines[k].push(' ');
            lines[k].push_str(&next);
            "lines joined"
        }
    }
}

/// One mutation of the bytes.
fn mutate_bytes(bytes: &mut Vec<u8>, rng: &mut Rng) -> &'static str {
    let n = bytes.len();
    match rng.below(5) {
        0 => {
            bytes.truncate(rng.below(n));
            "cut at a byte"
        }
        1 => {
            let at = rng.below(n + 1);
            let count = 1 + rng.below(8);
            let inserted: Vec<u8> = (0..count)
                .map(|_| {
                    *rng.pick(&[
                        0u8, 0xff, 0xc3, 0x80, b'\r', b'\t', b' ', b'$', b'"', b'\n', b'0', b'9',
                        b'-', b'e', b'.',
                    ])
                })
                .collect();
            bytes.splice(at..at, inserted);
            "bytes inserted"
        }
        2 => {
            if n > 0 {
                let at = rng.below(n);
                bytes[at] ^= 1 << rng.below(8);
            }
            "bit flipped"
        }
        3 => {
            *bytes = String::from_utf8_lossy(bytes)
                .replace('\n', "\r\n")
                .into_bytes();
            "CRLF"
        }
        _ => {
            *bytes = String::from_utf8_lossy(bytes)
                .replace(' ', "\t ")
                .into_bytes();
            "tabs"
        }
    }
}

/// Mutant `case`: one to three structural mutations, then maybe one of
/// the lines and one of the bytes. Returns the bytes and the mutation
/// names.
fn mutant(base: &[String], ix: &Index, rng: &mut Rng) -> (Vec<u8>, Vec<&'static str>) {
    let mut lines = base.to_vec();
    let mut applied = Vec::new();
    let structural = if rng.chance(0.15) {
        0
    } else {
        1 + rng.below(3)
    };
    for _ in 0..structural {
        applied.push(mutate_structure(&mut lines, ix, rng));
    }
    if structural == 0 || rng.chance(0.3) {
        applied.push(mutate_lines(&mut lines, ix, rng));
    }
    let mut bytes = lines.join("\n").into_bytes();
    bytes.push(b'\n');
    if rng.chance(0.12) {
        applied.push(mutate_bytes(&mut bytes, rng));
    }
    (bytes, applied)
}

// ---------------------------------------------------------------------------
// Running one input.

/// What became of one read.
#[derive(Debug)]
enum Outcome {
    /// A mesh (linear or quadratic).
    Accepted(&'static str),
    /// A typed error.
    Rejected(MeshError),
    /// Accepted, but the mesh breaks an invariant (a finding).
    Anomaly(String),
}

/// Reads `bytes` as a `D`-dimensional mesh and uses it as the scene
/// builder does.
fn read<const D: usize>(bytes: &[u8]) -> Outcome {
    let mesh = match parse_msh::<D>(bytes) {
        Ok(m) => m,
        Err(e) => return Outcome::Rejected(e),
    };
    let (linear, label) = match mesh.elements {
        GmshElements::Linear(m) => (m, "linear"),
        GmshElements::Quadratic(q) => match PatchMesh::from_parents(&q) {
            Ok(split) => (split.into_mesh(), "quadratic"),
            Err(e) => return Outcome::Rejected(e),
        },
    };
    if label == "linear" && mesh.element_tags.len() != linear.element_count() {
        return Outcome::Anomaly(format!(
            "{} element tags for {} elements",
            mesh.element_tags.len(),
            linear.element_count()
        ));
    }
    if mesh.node_tags.len() > linear.node_count() {
        return Outcome::Anomaly(format!(
            "{} node tags for {} nodes",
            mesh.node_tags.len(),
            linear.node_count()
        ));
    }
    if let Some(e) = linear
        .volumes()
        .iter()
        .position(|v| !(v.is_finite() && *v > 0.0))
    {
        return Outcome::Anomaly(format!(
            "element {e} accepted with volume {}",
            linear.volumes()[e]
        ));
    }
    let last = linear.element_count() - 1;
    for element in [0, last] {
        let nodes = linear.element_nodes(element);
        let centroid = nodes
            .iter()
            .map(|&n| linear.nodes()[n])
            .sum::<SVector<f64, D>>()
            / nodes.len() as f64;
        if linear.locate(&centroid, None).is_err() {
            return Outcome::Anomaly(format!(
                "the centroid {:?} of element {element} is not located",
                centroid.as_slice()
            ));
        }
    }
    Outcome::Accepted(label)
}

/// The kind of a rejection: the variant, and the wrapped one.
fn kind_of(e: &MeshError) -> String {
    let head = |text: &str| {
        text.split(|c: char| !c.is_alphanumeric() && c != '_')
            .next()
            .unwrap_or("")
            .to_owned()
    };
    match e {
        MeshError::GmshElement { source, .. } => {
            format!("GmshElement({})", head(&format!("{source:?}")))
        }
        _ => head(&format!("{e:?}")),
    }
}

/// The line a Gmsh error names, from its message (`line N: …`).
fn line_of(e: &MeshError) -> Option<usize> {
    e.to_string()
        .strip_prefix("line ")?
        .split(':')
        .next()?
        .parse()
        .ok()
}

// ---------------------------------------------------------------------------
// Counting.

#[derive(Default)]
struct Tally {
    tried: usize,
    reads: usize,
    accepted: BTreeMap<&'static str, usize>,
    /// Kind → (count, an example message).
    rejected: BTreeMap<String, (usize, String)>,
    /// Rejections without a line number, by kind.
    unlocated: BTreeMap<String, usize>,
    /// Rejections naming a line outside the file.
    bad_lines: Vec<String>,
    anomalies: Vec<String>,
    panics: Vec<String>,
    hangs: Vec<String>,
    mutations: BTreeMap<&'static str, usize>,
    slowest: (Duration, String),
}

impl Tally {
    fn record(
        &mut self,
        outcome: Outcome,
        line_count: usize,
        what: &str,
        dump: &dyn Fn() -> PathBuf,
    ) {
        self.reads += 1;
        match outcome {
            Outcome::Accepted(label) => *self.accepted.entry(label).or_default() += 1,
            Outcome::Rejected(e) => {
                let kind = kind_of(&e);
                let entry = self
                    .rejected
                    .entry(kind.clone())
                    .or_insert_with(|| (0, e.to_string()));
                entry.0 += 1;
                let gmsh = matches!(
                    e,
                    MeshError::GmshIo { .. }
                        | MeshError::GmshFormat { .. }
                        | MeshError::GmshBinary { .. }
                        | MeshError::GmshSyntax { .. }
                        | MeshError::GmshTruncated { .. }
                        | MeshError::GmshCount { .. }
                        | MeshError::GmshMissingSection { .. }
                        | MeshError::GmshUnknownNode { .. }
                        | MeshError::GmshDuplicateNode { .. }
                        | MeshError::GmshUnsupportedElement { .. }
                        | MeshError::GmshMixedOrder { .. }
                        | MeshError::GmshNoElements { .. }
                        | MeshError::GmshElement { .. }
                        | MeshError::GmshNotPlanar { .. }
                );
                match line_of(&e) {
                    None => *self.unlocated.entry(kind).or_default() += 1,
                    // One past the last line is where a truncated file
                    // ends; line 1 of an empty file.
                    Some(l) if gmsh && (l == 0 || l > line_count + 1) => {
                        self.bad_lines.push(format!(
                            "{what}: line {l} of a {line_count}-line file: {e} ({})",
                            dump().display()
                        ));
                    }
                    Some(_) => {}
                }
            }
            Outcome::Anomaly(message) => self
                .anomalies
                .push(format!("{what}: {message} ({})", dump().display())),
        }
    }

    fn print(&self, config: &Config, elapsed: Duration) {
        println!(
            "fuzz_gmsh: seed {}, {} inputs ({} reads, 2D and 3D) in {:.1} s; slowest read {:.3} s ({})",
            config.seed,
            self.tried,
            self.reads,
            elapsed.as_secs_f64(),
            self.slowest.0.as_secs_f64(),
            self.slowest.1
        );
        println!("accepted: {:?}", self.accepted);
        let rejected: usize = self.rejected.values().map(|(n, _)| n).sum();
        println!(
            "rejected: {rejected} reads, {} kinds (count, kind, example):",
            self.rejected.len()
        );
        for (kind, (count, example)) in &self.rejected {
            println!("  {count:>7}  {kind}: {example}");
        }
        println!("rejections without a line number: {:?}", self.unlocated);
        println!("mutations applied: {:?}", self.mutations);
        println!(
            "panics: {}, hangs: {}, anomalies: {}, lines out of range: {}",
            self.panics.len(),
            self.hangs.len(),
            self.anomalies.len(),
            self.bad_lines.len()
        );
        if let Some(kb) = peak_memory_kib() {
            println!("peak resident memory: {} MiB", kb / 1024);
        }
    }
}

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn findings_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz_gmsh");
    std::fs::create_dir_all(&dir).expect("cannot create the findings directory");
    dir
}

/// Reads the file named by `MPM_FUZZ_REPLAY` without catching panics.
fn replay(path: &str) {
    let bytes = std::fs::read(path).expect("cannot read the replayed file");
    println!("2D: {:?}", read::<2>(&bytes));
    println!("3D: {:?}", read::<3>(&bytes));
}

#[test]
fn mutated_gmsh_files_are_read_or_refused_with_a_typed_error() {
    if let Ok(path) = std::env::var("MPM_FUZZ_REPLAY") {
        replay(&path);
        return;
    }
    let config = Config::from_env(4000);
    let bases: Vec<(String, Vec<String>, Index)> = BASES
        .iter()
        .map(|(path, dim)| {
            let text = std::fs::read_to_string(workspace().join(path))
                .unwrap_or_else(|e| panic!("{path}: {e}"));
            let lines: Vec<String> = text.lines().map(str::to_owned).collect();
            let ix = Index::of(&lines);
            assert_eq!(ix.top_dim, *dim, "{path}");
            ((*path).to_owned(), lines, ix)
        })
        .collect();
    let findings = findings_dir();
    let mut tally = Tally::default();
    let worker: Worker<(Outcome, Outcome, Duration)> = Worker::new();
    let previous_hook = install_quiet_hook();
    let start = Instant::now();
    for case in 0..config.cases {
        if start.elapsed() >= config.budget {
            break;
        }
        let mut rng = Rng::for_case(config.seed, case);
        let (name, base, ix) = rng.pick(&bases);
        let (bytes, applied) = mutant(base, ix, &mut rng);
        for m in &applied {
            *tally.mutations.entry(m).or_default() += 1;
        }
        tally.tried += 1;
        let file = Path::new(name)
            .file_stem()
            .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
        let what = format!("case {case} ({file}: {})", applied.join(", "));
        // As the reader counts: a last line without its newline counts.
        let line_count = bytes.iter().filter(|&&b| b == b'\n').count()
            + usize::from(bytes.last().is_some_and(|&b| b != b'\n'));
        let dump = || {
            let path = findings.join(format!("seed{}-case{case}-{file}.msh", config.seed));
            std::fs::write(&path, &bytes).expect("cannot write a finding");
            path
        };
        let input = bytes.clone();
        let job = Box::new(move || {
            let t = Instant::now();
            let two = read::<2>(&input);
            let three = read::<3>(&input);
            (two, three, t.elapsed())
        });
        match worker.run(job, config.timeout) {
            Ran::Done((two, three, took)) => {
                if took > tally.slowest.0 {
                    tally.slowest = (took, what.clone());
                }
                tally.record(two, line_count, &format!("{what} 2D"), &dump);
                tally.record(three, line_count, &format!("{what} 3D"), &dump);
            }
            Ran::Panicked(message) => {
                tally
                    .panics
                    .push(format!("{what}: {message} ({})", dump().display()));
            }
            Ran::TimedOut => {
                tally.hangs.push(format!(
                    "{what}: no answer in {:?} ({})",
                    config.timeout,
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
            ("anomaly", &tally.anomalies),
            ("line out of range", &tally.bad_lines),
        ],
        "<file>",
    );
    assert!(tally.tried > 0);
}

/// Two tetrahedra sharing the face of nodes 2, 3, 4; `node5` is the
/// coordinate line of node 5, `second` the second element's line, and
/// `extra` more lines for `$Nodes`' single block (after node 5).
fn two_tets(node5: &str, second: &str, extra: &[(&str, &str)]) -> Vec<u8> {
    let n = 5 + extra.len();
    let mut lines = vec![
        "$MeshFormat".to_owned(),
        "4.1 0 8".into(),
        "$EndMeshFormat".into(),
        "$Nodes".into(),
        format!("1 {n} 1 {n}"),
        format!("3 1 0 {n}"),
    ];
    lines.extend((1..=5).map(|t| t.to_string()));
    lines.extend(extra.iter().map(|(tag, _)| (*tag).to_owned()));
    lines.extend(["0 0 0", "1 0 0", "0 1 0", "0 0 1", node5].map(str::to_owned));
    lines.extend(extra.iter().map(|(_, xyz)| (*xyz).to_owned()));
    lines.extend(
        [
            "$EndNodes",
            "$Elements",
            "1 2 1 2",
            "3 1 4 2",
            "1 1 2 3 4",
            second,
            "$EndElements",
        ]
        .map(str::to_owned),
    );
    (lines.join("\n") + "\n").into_bytes()
}

/// What the reader does today with the inputs the issue names.
#[test]
fn degenerate_geometry_and_huge_counts_today() {
    // Lines: 7-11 node tags, 12-16 coordinates, 21-22 the elements.
    let good = parse_msh::<3>(&two_tets("1 1 1", "2 2 3 4 5", &[])).expect("two tets");
    let GmshElements::Linear(mesh) = good.elements else {
        panic!("linear tets");
    };
    assert_eq!(mesh.boundary_faces().len(), 6);

    // A zero-volume tetrahedron (node 5 on the plane of 2, 3, 4): a typed
    // error naming the element's line and tag.
    let flat = parse_msh::<3>(&two_tets("0.25 0.25 0.5", "2 2 3 4 5", &[]));
    assert!(
        matches!(&flat, Err(MeshError::GmshElement { line: 22, tag: 2, source })
            if matches!(**source, MeshError::DegenerateElement { element: 1, .. })),
        "{flat:?}"
    );
    // A sliver 1e-9 off that plane (volume 5e-10, 2e-10 of its longest
    // edge cubed) is above the 1e-12 threshold: accepted.
    let sliver = parse_msh::<3>(&two_tets(
        "0.250000001 0.250000001 0.500000001",
        "2 2 3 4 5",
        &[],
    ));
    assert!(sliver.is_ok(), "{sliver:?}");
    // The same node twice in an element.
    let repeated = parse_msh::<3>(&two_tets("1 1 1", "2 2 3 4 4", &[]));
    assert!(
        matches!(&repeated, Err(MeshError::GmshElement { line: 22, tag: 2, source })
            if matches!(**source, MeshError::RepeatedElementNode { .. })),
        "{repeated:?}"
    );
    // A NaN coordinate: refused at its line (it was `NonFiniteNode` with
    // the node's index and no line before the fuzzing).
    for bad in ["nan 1 1", "1 inf 1", "1 1 1e999"] {
        let e = parse_msh::<3>(&two_tets(bad, "2 2 3 4 5", &[]));
        assert!(
            matches!(&e, Err(MeshError::GmshSyntax { line: 16, .. })),
            "{bad}: {e:?}"
        );
    }
    // Duplicated nodes with identical coordinates are accepted silently:
    // node 6 at node 2's place, unused, or used by the second tetrahedron
    // instead of node 2 — which cuts the mesh along their shared face (8
    // boundary faces instead of 6).
    let unused = parse_msh::<3>(&two_tets("1 1 1", "2 2 3 4 5", &[("6", "1 0 0")]));
    assert!(unused.is_ok(), "{unused:?}");
    let cut = parse_msh::<3>(&two_tets("1 1 1", "2 6 3 4 5", &[("6", "1 0 0")])).map(|m| {
        match m.elements {
            GmshElements::Linear(m) => m.boundary_faces().len(),
            GmshElements::Quadratic(_) => 0,
        }
    });
    assert_eq!(cut, Ok(8));
    // A billion nodes declared: nothing is reserved from the count; the
    // data contradicts it at the first coordinate line read as a tag.
    let huge = String::from_utf8(two_tets("1 1 1", "2 2 3 4 5", &[]))
        .expect("text")
        .replace(
            "1 5 1 5\n3 1 0 5",
            "1 1000000000 1 1000000000\n3 1 0 1000000000",
        );
    let t = Instant::now();
    let e = parse_msh::<3>(huge.as_bytes());
    assert!(
        matches!(&e, Err(MeshError::GmshSyntax { line: 12, .. })),
        "{e:?}"
    );
    assert!(t.elapsed() < Duration::from_secs(1));
    // A mesh 1e-10 thick along x: accepted, and fast (it asked for 63 GB
    // of location buckets before the fix).
    let path = workspace().join("scenes/meshes/cylinder_slice_test.msh");
    let mut lines: Vec<String> = std::fs::read_to_string(path)
        .expect("the mesh")
        .lines()
        .map(str::to_owned)
        .collect();
    let ix = Index::of(&lines);
    for node in &ix.nodes {
        let mut xyz = coordinates(&lines[node.coord_line]);
        xyz[0] *= 1e-10;
        lines[node.coord_line] = write_coordinates(xyz);
    }
    let t = Instant::now();
    let thin = parse_msh::<3>((lines.join("\n") + "\n").as_bytes()).map(|m| match m.elements {
        GmshElements::Linear(_) => Ok(()),
        GmshElements::Quadratic(q) => PatchMesh::from_parents(&q).map(|_| ()),
    });
    assert!(matches!(thin, Ok(Ok(()))), "{thin:?}");
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
}
