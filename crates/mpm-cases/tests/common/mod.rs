//! Helpers shared by the integration tests: scratch directories and a small
//! XML reader for the VTK files, built on quick-xml (an independent parser,
//! so the writer is not checked against itself).
#![allow(dead_code, clippy::unwrap_used)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};
use quick_xml::reader::Reader;

/// A fresh, empty directory for one test.
pub fn fresh_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("mpm-cases")
        .join(name);
    if dir.exists() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Names of the entries of `dir`, sorted.
pub fn dir_entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// An element of the document: its name, attributes, the names of its
/// ancestors, and its text content.
#[derive(Debug, Clone)]
pub struct Element {
    pub name: String,
    pub attrs: BTreeMap<String, String>,
    pub ancestors: Vec<String>,
    pub text: String,
}

impl Element {
    pub fn attr(&self, key: &str) -> &str {
        self.attrs.get(key).map_or_else(
            || panic!("{} has no attribute {key}", self.name),
            String::as_str,
        )
    }

    /// The text content as numbers.
    pub fn numbers(&self) -> Vec<f64> {
        self.text
            .split_whitespace()
            .map(|t| t.parse::<f64>().unwrap())
            .collect()
    }

    pub fn parent(&self) -> &str {
        self.ancestors.last().map_or("", String::as_str)
    }
}

/// Every element of an XML document in document order. Panics if the
/// document is not well-formed (unbalanced tags, bad syntax).
pub fn parse_xml(xml: &str) -> Vec<Element> {
    let mut reader = Reader::from_str(xml);
    reader.config_mut().check_end_names = true;
    let mut stack: Vec<usize> = Vec::new();
    let mut out: Vec<Element> = Vec::new();
    let make = |e: &BytesStart<'_>, out: &Vec<Element>, stack: &Vec<usize>| Element {
        name: e.name().into_inner().to_owned(),
        attrs: e
            .attributes()
            .map(|a| {
                let a = a.unwrap();
                (
                    a.key.into_inner().to_owned(),
                    a.normalized_value(XmlVersion::Implicit1_0)
                        .unwrap()
                        .into_owned(),
                )
            })
            .collect(),
        ancestors: stack.iter().map(|&i| out[i].name.clone()).collect(),
        text: String::new(),
    };
    loop {
        match reader.read_event().unwrap() {
            Event::Start(e) => {
                let el = make(&e, &out, &stack);
                out.push(el);
                stack.push(out.len() - 1);
            }
            Event::Empty(e) => {
                let el = make(&e, &out, &stack);
                out.push(el);
            }
            Event::End(_) => {
                stack.pop().unwrap();
            }
            Event::Text(t) => {
                if let Some(&i) = stack.last() {
                    out[i].text.push_str(&t.xml10_content());
                }
            }
            Event::GeneralRef(_) => panic!("unexpected entity reference in text"),
            Event::Eof => break,
            _ => {}
        }
    }
    assert!(stack.is_empty(), "unclosed elements");
    out
}

/// The `DataArray` named `name` whose parent is `section`.
pub fn data_array<'a>(doc: &'a [Element], section: &str, name: &str) -> &'a Element {
    doc.iter()
        .find(|e| {
            e.name == "DataArray"
                && e.parent() == section
                && e.attrs.get("Name").map(String::as_str) == Some(name)
        })
        .unwrap_or_else(|| panic!("no DataArray {name} in {section}"))
}

/// The first element named `name`.
pub fn element<'a>(doc: &'a [Element], name: &str) -> &'a Element {
    doc.iter()
        .find(|e| e.name == name)
        .unwrap_or_else(|| panic!("no element {name}"))
}

/// A `steps.csv` without its wall-clock columns (`seconds*`).
pub fn without_timings(csv: &str) -> String {
    let header: Vec<&str> = csv.lines().next().unwrap_or_default().split(',').collect();
    let keep: Vec<bool> = header.iter().map(|c| !c.starts_with("seconds")).collect();
    assert!(keep.iter().any(|k| !k), "steps.csv has no timing columns");
    csv.lines()
        .map(|line| {
            line.split(',')
                .zip(&keep)
                .filter(|(_, k)| **k)
                .map(|(v, _)| v)
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Runs the `mpm` binary with `args`: (success, stdout, stderr).
pub fn mpm(args: &[&str]) -> (bool, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mpm"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Every file of the run directory `dir` except the checkpoint and
/// `summary.json` (whose wall time differs), by name, as bytes.
pub fn run_outputs(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_str().unwrap();
            name != "checkpoint.mpm" && name != "summary.json"
        })
        .map(|p| {
            (
                p.file_name().unwrap().to_str().unwrap().to_string(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect()
}

/// `control` run as one of `ranks` with the deal of `problem` (what
/// `mpirun` gives `mpm run`, here on threads).
pub fn on_ranks<const D: usize>(
    problem: &mpm_cases::scene::Problem<D>,
    ranks: mpm_solver::ranks::ThreadRanks,
    control: &mpm_cases::run::RunControl,
) -> mpm_cases::run::RunControl {
    let run = mpm_cases::scene::ranks::rank_run(problem, std::sync::Arc::new(ranks)).unwrap();
    mpm_cases::run::RunControl {
        ranks: Some(run),
        ..control.clone()
    }
}
