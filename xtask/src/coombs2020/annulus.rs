//! §7.4, the elastic annulus under torsion on unstructured triangles: the
//! displacement error against the element size for several numbers of
//! points per triangle (Fig. 19).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;
use mpm_cases::cases::Solve;
use mpm_cases::cases::annulus::{AnnulusCase, AnnulusParams};
use mpm_cases::run::RunControl;
use mpm_cases::variant::Variant;

use crate::markdown::{Table, sci};
use crate::plot::{Axis, Figure, Line, Marker, PALETTE, Series};

/// The paper's five element sizes (m), meshed by
/// `scenes/meshes/make_annulus.py` into `annulus_<i>.msh`.
const SIZES: [f64; 5] = [0.4363, 0.2182, 0.1091, 0.0545, 0.0273];

/// One analysis: mesh index, points per triangle per direction, and the
/// measured element size (√(2A/n)), error (m), iterations and time (s).
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    /// Mesh index into [`SIZES`].
    pub mesh: usize,
    /// n, for n² points per triangle.
    pub points_per_element: usize,
    /// Mean element size (m).
    pub element_size: f64,
    /// Volume-weighted mean displacement error (m).
    pub error: f64,
    /// Material points.
    pub points: usize,
    /// Newton iterations.
    pub iterations: usize,
    /// Solver wall time (s).
    pub time_s: f64,
}

/// The annulus runs.
#[derive(Debug, Clone)]
pub struct Study {
    /// Every analysis that finished.
    pub runs: Vec<Measured>,
    /// Analyses that failed, with the reason.
    pub failures: Vec<String>,
}

fn mesh_path(i: usize) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../scenes/meshes/annulus_{i}.msh"))
}

/// Runs n² = 1, 4, 9, 16 points per triangle on the five meshes, and with
/// `full` 36 and 64 on the two finest.
pub fn study(full: bool) -> Study {
    let mut plan: Vec<(usize, usize)> = (1..=4)
        .flat_map(|n| (0..SIZES.len()).map(move |m| (m, n)))
        .collect();
    if full {
        plan.extend([(3, 6), (4, 6), (3, 8), (4, 8)]);
    }
    let mut study = Study {
        runs: Vec::new(),
        failures: Vec::new(),
    };
    for (mesh, n) in plan {
        let p = AnnulusParams {
            mesh: Some(mesh_path(mesh)),
            points_per_element: n,
            ..AnnulusParams::default()
        };
        match AnnulusCase::run(
            &p,
            &Variant::default(),
            &RunControl::default(),
            |_, _, _| Ok(()),
        ) {
            Ok(r) => {
                println!(
                    "annulus mesh {mesh} ({} triangles), {n}x{n}: error {:.3e}, {:.2} s",
                    r.elements, r.error, r.output.wall_time_s
                );
                study.runs.push(Measured {
                    mesh,
                    points_per_element: n,
                    element_size: r.element_size,
                    error: r.error,
                    points: r.material_points,
                    iterations: r.output.summary.iterations,
                    time_s: r.output.wall_time_s,
                });
            }
            Err(e) => study
                .failures
                .push(format!("mesh {mesh}, {n}² points per triangle: {e}")),
        }
    }
    study
}

/// The convergence order between two runs.
fn order(a: &Measured, b: &Measured) -> f64 {
    (a.error / b.error).ln() / (a.element_size / b.element_size).ln()
}

/// The report section: a table of errors and orders, and the log–log plot.
pub fn section(study: &Study, img: &Path) -> Result<String> {
    let mut md = String::new();
    writeln!(
        md,
        "## 6. Elastic annulus: displacement error on unstructured triangles (Fig. 19)\n\n\
         Annulus 0.75 ≤ R ≤ 1.25 m, E = 1 Pa, ν = 0, both rims fixed, turned by θ(R) of \
         eq. (44) with α = 0.1 rad over 10 load steps through the manufactured body force \
         (derived in [Analytic references of the cases](../theory/cases.md) and checked \
         there against a finite-difference divergence of the stress). Standard MPM on \
         unstructured Gmsh triangles of the paper's five sizes (`scenes/meshes/annulus_*.msh`), \
         n² points per triangle at the centroids of its n² sub-triangles. Error: the \
         volume-weighted mean of |u_p − u^a(X_p)| (m); element size √(2A/n_e). Order: \
         between a mesh and the next coarser one.\n"
    )?;
    let mut ns: Vec<usize> = study.runs.iter().map(|r| r.points_per_element).collect();
    ns.sort_unstable();
    ns.dedup();
    let mut header = vec!["points per triangle".to_owned()];
    for (i, h) in SIZES.iter().enumerate() {
        let size = study
            .runs
            .iter()
            .find(|r| r.mesh == i)
            .map_or(String::new(), |r| {
                format!(", measured {:.4}", r.element_size)
            });
        header.push(format!("h ≈ {h} m{size}: error (order)"));
    }
    let mut table = Table::new(header);
    let mut series = Vec::new();
    for (k, &n) in ns.iter().enumerate() {
        let runs: Vec<&Measured> = study
            .runs
            .iter()
            .filter(|r| r.points_per_element == n)
            .collect();
        let mut row = vec![format!("{}² = {}", n, n * n)];
        for i in 0..SIZES.len() {
            let cell = match runs.iter().find(|r| r.mesh == i) {
                None => "–".to_owned(),
                Some(r) => match runs.iter().find(|q| q.mesh + 1 == i) {
                    Some(q) => format!("{} ({:.2})", sci(r.error), order(q, r)),
                    None => sci(r.error),
                },
            };
            row.push(cell);
        }
        table.row(row);
        series.push(Series {
            label: format!("{}² points per triangle", n),
            points: runs.iter().map(|r| (r.element_size, r.error)).collect(),
            color: PALETTE[k % PALETTE.len()],
            marker: Some(Marker::CYCLE[k % Marker::CYCLE.len()]),
            filled: true,
            line: Line::Solid,
        });
    }
    // A slope-2 guide through the finest converged run of the most points.
    if let Some(anchor) = study
        .runs
        .iter()
        .filter(|r| Some(&r.points_per_element) == ns.last())
        .min_by(|a, b| a.element_size.total_cmp(&b.element_size))
    {
        let line = |h: f64| anchor.error * (h / anchor.element_size).powi(2);
        series.push(Series {
            label: "order 2".into(),
            points: vec![(0.02, line(0.02)), (0.4, line(0.4))],
            color: PALETTE[7],
            marker: None,
            filled: false,
            line: Line::Dashed,
        });
    }
    md.push_str(&table.render());
    md.push('\n');
    let figure = Figure {
        title: "Elastic annulus: displacement error against element size".into(),
        x: Axis::log("element size √(2A/n) (m)"),
        y: Axis::log("mean displacement error (m)"),
        series,
        legend_title: "standard MPM, unstructured triangles".into(),
    };
    md.push_str(&figure.save_in(
        img,
        "coombs2020-annulus.png",
        "Annulus: displacement error against element size per number of points",
    )?);
    for failure in &study.failures {
        writeln!(md, "- Failed: {failure}")?;
    }
    if !study.failures.is_empty() {
        md.push('\n');
    }
    let finest = |n: usize| {
        study
            .runs
            .iter()
            .filter(|r| r.points_per_element == n)
            .max_by_key(|r| r.mesh)
    };
    let mut reading = String::from(
        "**Reading.** As in the paper, one point per triangle is insufficient: its error \
         stops falling and grows on the finer meshes, where the material crosses several \
         elements per step. With more points the error falls at about the order of the linear \
         basis (2) until, on the finest meshes, the points per triangle become too few again: \
         the points needed grow with refinement, as for the column (Fig. 6).",
    );
    if let (Some(a), Some(b)) = (finest(4), finest(8)) {
        let _ = write!(
            reading,
            " At h ≈ {} m 4² points give {} and 8² give {}.",
            SIZES[a.mesh],
            sci(a.error),
            sci(b.error)
        );
    }
    let time: f64 = study.runs.iter().map(|r| r.time_s).sum();
    let points = study.runs.iter().map(|r| r.points).max().unwrap_or(0);
    let iterations: usize = study.runs.iter().map(|r| r.iterations).sum();
    writeln!(
        md,
        "{reading} The {} analyses took {:.1} s of solver time in all ({} Newton iterations; \
         the largest has {} points).\n",
        study.runs.len(),
        time,
        iterations,
        points
    )?;
    Ok(md)
}
