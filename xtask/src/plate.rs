//! Wang et al. (2021) §5.4, the stretch of a double-notched plate
//! (Figs. 15C and 16): the scene `scenes/wang2021_notched_plate.toml` with
//! element sizes h = 2 and 1 mm (and 0.5 mm with `--full`), standard MPM
//! and F-patch; the reaction against the stretch as a PNG, the Newton
//! residuals of F-patch's steps on the coarsest mesh as a second PNG.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;

use crate::markdown::Table;
use crate::plot::{Axis, Figure, Line, Marker, PALETTE, Series};
use crate::scene_run::{self, Run};

const SCENE: &str = include_str!("../../scenes/wang2021_notched_plate.toml");
const FILE: &str = "scenes/wang2021_notched_plate.toml";
/// The top's displacement at load factor 1 (mm).
const STRETCH_MM: f64 = 0.25;

/// A mesh: h (mm) and the scene's `cells` (one cell = 2h).
const MESHES: [(f64, &str); 3] = [(2.0, "[2, 4, 1]"), (1.0, "[4, 8, 2]"), (0.5, "[8, 16, 4]")];

fn run(h: f64, cells: &str, fpatch: bool) -> Result<Run> {
    let mut overrides = vec![format!("mesh.cells={cells}")];
    if fpatch {
        overrides.push("solver.locking=\"fpatch\"".to_owned());
    }
    let label = format!(
        "{}, h = {h} mm",
        if fpatch { "F-patch" } else { "standard MPM" }
    );
    scene_run::run(SCENE, FILE, &overrides, label, "top", |_, top, report| {
        (report.lambda1 * STRETCH_MM, top.total(report)[1] / 1e3)
    })
}

/// The largest reaction of a run (kN).
fn peak(r: &Run) -> f64 {
    r.points.iter().map(|p| p.1).fold(f64::NAN, f64::max)
}

/// Newton iterations of the steps after the first `skip`: (fewest, most).
fn iteration_range(r: &Run, skip: usize) -> Option<(usize, usize)> {
    let counts = r
        .residuals
        .iter()
        .skip(skip)
        .map(|s| s.len().saturating_sub(1));
    Some((counts.clone().min()?, counts.max()?))
}

/// The section: the runs, the table, the two PNGs and the reading.
pub fn section(full: bool, img: &Path) -> Result<String> {
    let meshes = if full { &MESHES[..] } else { &MESHES[..2] };
    let mut runs = Vec::new();
    for &(h, cells) in meshes {
        runs.push((h, run(h, cells, false)?, run(h, cells, true)?));
    }
    let mut md = String::new();
    writeln!(
        md,
        "## 5. Double-notched plate (§5.4, Figs. 15C and 16)\n\n\
         The scene `{FILE}`: steel, E = 206.9 GPa, ν = 0.29, ρ_y = 0.55 GPa in eq. (16), \
         perfectly plastic; the one-eighth model of a plate 16 mm wide, 32 mm long and 8 mm \
         thick with a crack-like notch 4 mm deep in each long side at mid-length (an 8 mm \
         ligament). The paper takes its geometry from its reference 34 and gives no \
         dimensions; ours is the double-edge-notched tension specimen of Nagtegaal, Parks & \
         Rice (1974) made 3D, its notches modelled as the part of the symmetry plane y = 0 left \
         free (the \"partially constrained lower boundary\" of §5.4). Rollers on x = 0, z = 0 \
         and the ligament; the top is pulled {STRETCH_MM} mm in 25 steps of 0.01 mm through \
         the stretching mesh. Each cell of 2h is split into six ten-node tetrahedra (the \
         patches) of eight linear children of edge about h; 11 points per child (Keast). \
         Reaction: the top's, one-eighth model (the specimen carries four times it). {}\n",
        if full {
            "h = 2, 1 and 0.5 mm."
        } else {
            "Quick mode: h = 2 and 1 mm (`--full` adds 0.5 mm)."
        },
    )?;
    let mut table = Table::new([
        "h (mm)",
        "method",
        "tetrahedra",
        "points",
        "steps (cut)",
        "Newton iterations (most in a step)",
        "iterations per step after step 5",
        "time (s)",
        "peak memory (MB)",
        "largest reaction (kN)",
        "reaction at 0.25 mm (kN)",
    ]);
    for (h, standard, patched) in &runs {
        for r in [standard, patched] {
            table.row(vec![
                h.to_string(),
                r.label.split(',').next().unwrap_or_default().to_owned(),
                r.elements.to_string(),
                r.material_points.to_string(),
                r.steps_cell(),
                r.iterations_cell(),
                iteration_range(r, 5).map_or("–".to_owned(), |(a, b)| format!("{a}–{b}")),
                format!("{:.1}", r.seconds),
                r.peak_cell(),
                format!("{:.3}", peak(r)),
                format!("{:.3}", r.end()),
            ]);
        }
    }
    md.push_str(&table.render());
    let mut series = Vec::new();
    for (i, (_, standard, patched)) in runs.iter().enumerate() {
        for (r, line, filled) in [
            (standard, Line::Dashed, false),
            (patched, Line::Solid, true),
        ] {
            series.push(Series {
                label: r.label.clone(),
                points: r.points.clone(),
                color: PALETTE[i],
                marker: Some(Marker::CYCLE[i]),
                filled,
                line,
            });
        }
    }
    let figure = Figure {
        title: "Double-notched plate (Wang 2021 §5.4)".into(),
        x: Axis::linear("top displacement (mm)"),
        y: Axis::linear("reaction, one-eighth model (kN)"),
        series,
        legend_title: "method, mesh".into(),
    };
    md.push_str(&figure.save_in(
        img,
        "wang2021-plate.png",
        "Double-notched plate: reaction against stretch for h = 2, 1 (and 0.5) mm, standard MPM dashed, F-patch solid",
    )?);
    // Fig. 16: F-patch's residuals on the coarsest mesh, every fifth step.
    let coarse = &runs[0].2;
    let series = coarse
        .residuals
        .iter()
        .enumerate()
        .filter(|(s, _)| s % 5 == 4 || *s == 0)
        .enumerate()
        .map(|(i, (s, res))| Series {
            label: format!("step {}", s + 1),
            points: res
                .iter()
                .enumerate()
                .filter(|(_, r)| **r > 0.0)
                .map(|(k, r)| (k as f64, *r))
                .collect(),
            color: PALETTE[i % PALETTE.len()],
            marker: Some(Marker::CYCLE[i % Marker::CYCLE.len()]),
            filled: true,
            line: Line::Solid,
        })
        .collect();
    let figure = Figure {
        title: "Double-notched plate, F-patch, h = 2 mm: Newton residuals".into(),
        x: Axis::linear("iteration"),
        y: Axis::log("normalised residual (eq. 40)"),
        series,
        legend_title: "load step".into(),
    };
    md.push_str(&figure.save_in(
        img,
        "wang2021-plate-residuals.png",
        "Double-notched plate: F-patch Newton residuals per iteration for every fifth step, h = 2 mm",
    )?);
    md.push_str(&reading(&runs));
    Ok(md)
}

fn reading(runs: &[(f64, Run, Run)]) -> String {
    let mut text = String::from(
        "**Reading.** The paper's Figs. 15C and 16: four to five Newton iterations per step \
         with F-patch, the reaction falling as the mesh is refined, F-patch below standard \
         MPM. ",
    );
    for (h, standard, patched) in runs {
        for r in [standard, patched] {
            if let Some(f) = &r.failure {
                let _ = write!(text, "{} stopped: {f}. ", r.label);
            }
        }
        let _ = write!(
            text,
            "h = {h} mm: largest reaction {:.2} kN (standard) and {:.2} kN (F-patch, {:+.1} %); \
             F-patch took {} iterations per step after the fifth. ",
            peak(standard),
            peak(patched),
            100.0 * (peak(patched) / peak(standard) - 1.0),
            iteration_range(patched, 5).map_or("–".to_owned(), |(a, b)| format!("{a}–{b}")),
        );
    }
    let falls = |pick: fn(&(f64, Run, Run)) -> &Run| {
        runs.windows(2)
            .all(|w| peak(pick(&w[1])) < peak(pick(&w[0])))
    };
    let _ = write!(
        text,
        "As h decreases the largest reaction {} with standard MPM and {} with F-patch. ",
        if falls(|r| &r.1) {
            "falls"
        } else {
            "does not fall"
        },
        if falls(|r| &r.2) {
            "falls"
        } else {
            "does not fall"
        },
    );
    // Limit loads of the one-eighth model (ligament c·t = 4 × 4 mm², net
    // section) from the two plane theories: plane stress, Hill's neck for
    // sharp deep notches, net stress 2/√3 σ_y with σ_y = √(3/2) ρ_y; plane
    // strain, the least of Prandtl's (2 + π) k and the gross section's 2k
    // (width / ligament = 2), k = ρ_y/√2.
    let rho_y = 0.55e9;
    let (sigma_y, k) = (1.5f64.sqrt() * rho_y, rho_y / std::f64::consts::SQRT_2);
    let area = 16e-6;
    let plane_stress = 2.0 / 3f64.sqrt() * sigma_y * area / 1e3;
    let plane_strain = ((2.0 + std::f64::consts::PI) * k).min(2.0 * k * 2.0) * area / 1e3;
    let _ = write!(
        text,
        "For scale: the plane theories give the one-eighth model's limit load as {plane_stress:.2} \
         kN in plane stress (Hill's neck across the ligament, net stress 2σ_y/√3) and at most \
         {plane_strain:.2} kN in plane strain (the gross section yielding in tension, 2k over \
         twice the ligament, below Prandtl's (2 + π) k on the ligament); a plate as thick as its \
         ligament lies between. With F-patch the reaction passes a maximum and then falls as \
         the ligament necks. `crates/mpm-cases/tests/wang2021_3d.rs` asserts the three findings \
         on h = 2 and 1 mm with one point per element.\n\n",
    );
    text
}
