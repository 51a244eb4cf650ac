//! Wang et al. (2021) §5.1, the small-deformation footing in 3D (Fig. 8C):
//! the scene `scenes/wang2021_footing.toml` run with standard MPM and with
//! F-patch, the reaction against the settlement drawn as a PNG, and the
//! plateau read from the runs.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;

use crate::markdown::Table;
use crate::plot::{Axis, Figure};
use crate::scene_run::{self, Run};

/// The scene the section runs (the full mesh; the quick mode coarsens it).
const SCENE: &str = include_str!("../../scenes/wang2021_footing.toml");
/// Edge of the cube (m), the footing's half-edge (m) and the settlement (m)
/// of the scene.
const CUBE: f64 = 5.0;
const HALF_EDGE: f64 = 0.25;
const SETTLEMENT: f64 = 2e-3;
/// k = ρ_y/√2 of eq. (16) for the scene's ρ_y = 0.85 MPa.
const K: f64 = 0.85e6 / std::f64::consts::SQRT_2;

/// The quick mode's mesh (4 parent cells per axis, one of 0.25 m under the
/// footing, growing away from it); the same as
/// `crates/mpm-cases/tests/scenes.rs`'s.
const QUICK_MESH: &str = "mesh.coordinates=[[0.0, 0.25, 0.8, 2.1, 5.0], [0.0, 0.25, 0.8, 2.1, 5.0], [0.0, 2.9, 4.2, 4.75, 5.0]]";

fn run(full: bool, fpatch: bool) -> Result<Run> {
    let mut overrides = Vec::new();
    if !full {
        overrides.push(QUICK_MESH.to_owned());
    }
    if fpatch {
        overrides.push("solver.locking=\"fpatch\"".to_owned());
    }
    let label = if fpatch { "F-patch" } else { "standard MPM" };
    // The footing pressure / k after every step, against the settlement.
    scene_run::run(
        SCENE,
        "scenes/wang2021_footing.toml",
        &overrides,
        label.to_owned(),
        "footing",
        |_, footing, report| {
            (
                1e3 * report.lambda1 * SETTLEMENT,
                footing.total(report)[2].abs() / (HALF_EDGE * HALF_EDGE) / K,
            )
        },
    )
}

/// Slope of the pressure over the last quarter of the settlement against
/// the first step's (secant) slope: near 1 while the response is elastic,
/// near 0 on a plateau.
fn late_slope(points: &[(f64, f64)]) -> Option<f64> {
    let (&(s_end, p_end), first) = (points.last()?, points.get(1)?);
    let quarter = points
        .iter()
        .rev()
        .find(|(s, _)| *s <= 0.75 * s_end + 1e-12)?;
    let initial = first.1 / first.0;
    Some((p_end - quarter.1) / (s_end - quarter.0) / initial)
}

/// The section: both runs on the full (or quick) mesh, the table, the PNG
/// and the reading.
pub fn section(full: bool, img: &Path) -> Result<String> {
    let curves = [run(full, false)?, run(full, true)?];
    let mut md = String::new();
    writeln!(
        md,
        "## 3. Footing with small deformation (§5.1, Fig. 8C)\n\n\
         The scene `scenes/wang2021_footing.toml` (run it with `mpm run`): a quarter model of \
         a {CUBE} m cube under a smooth square footing of edge {} m, E = 10 GPa, ν = 0.48, \
         ρ_y = 0.85 MPa (k = ρ_y/√2 = {:.3} MPa), rollers on the bottom and the vertical \
         faces, the footing's nodes settling 2 mm in 20 steps of 0.1 mm and free \
         horizontally (the paper moves the bottom face up instead; at this settlement the two \
         differ by a rigid translation of 0.04 % of the depth). Mesh: {}, each cell split \
         into six ten-node tetrahedra (the patches) of eight linear children; 11 points per \
         child at Keast's positions (equal volumes). The paper: 4,176 tetrahedra, 921 nodes, \
         refined under the footing. Pressure = |vertical reaction of the footing's nodes| / \
         (l/2)².\n",
        2.0 * HALF_EDGE,
        K / 1e6,
        if full {
            "the scene's 7 × 7 × 7 rectilinear cells, 0.125 m under the footing and one cell \
             beyond its edge, growing away from it"
        } else {
            "quick mode, 4 × 4 × 4 rectilinear cells, one of 0.25 m under the footing, \
             growing away from it (`--full` runs the scene's 7 × 7 × 7)"
        },
    )?;
    let mut table = Table::new([
        "method",
        "tetrahedra",
        "points",
        "steps",
        "Newton iterations (most in a step)",
        "time (s)",
        "peak memory (MB)",
        "pressure / k at 1 mm",
        "pressure / k at 2 mm",
        "late slope / initial slope",
    ]);
    let at = |c: &Run, s: f64| {
        c.points
            .iter()
            .find(|p| (p.0 - s).abs() < 1e-9)
            .map_or("–".to_owned(), |p| format!("{:.3}", p.1))
    };
    for c in &curves {
        table.row(vec![
            c.label.to_owned(),
            c.elements.to_string(),
            c.material_points.to_string(),
            match &c.failure {
                None => (c.points.len() - 1).to_string(),
                Some(f) => format!("{} (then failed: {f})", c.points.len() - 1),
            },
            format!("{} ({})", c.iterations, c.max_iterations),
            format!("{:.1}", c.seconds),
            c.peak_mb.map_or("–".to_owned(), |m| format!("{m:.0}")),
            at(c, 1.0),
            at(c, 2.0),
            late_slope(&c.points).map_or("–".to_owned(), |s| format!("{s:.3}")),
        ]);
    }
    md.push_str(&table.render());
    let series = scene_run::series(&curves);
    let figure = Figure {
        title: "Footing with small deformation (Wang 2021 §5.1)".into(),
        x: Axis::linear("footing settlement (mm)"),
        y: Axis::linear("footing pressure / k"),
        series,
        legend_title: "treatment".into(),
    };
    md.push_str(&figure.save_in(
        img,
        "wang2021-footing.png",
        "Footing with small deformation: pressure against settlement, standard MPM and F-patch",
    )?);
    md.push_str(&reading(&curves, if full { 0.125 } else { 0.55 }));
    Ok(md)
}

/// What the two curves show, from the runs; `beyond` is the size of the
/// cell beyond the footing's edge (m).
fn reading(curves: &[Run; 2], beyond: f64) -> String {
    let [standard, patched] = curves;
    let end = |c: &Run| c.points.last().map_or(f64::NAN, |p| p.1);
    let stopped = |c: &Run| {
        c.failure.as_ref().map(|f| {
            format!(
                "{} stopped after {} mm of settlement ({} steps): {f}.",
                c.label,
                c.points.last().map_or(0.0, |p| p.0),
                c.points.len() - 1
            )
        })
    };
    let mut text = String::from(
        "**Reading.** The paper's Fig. 8C: the standard MPM reaction \
        keeps rising after yield (volumetric locking) while F-patch's levels off. ",
    );
    match (
        standard
            .failure
            .is_none()
            .then(|| late_slope(&standard.points))
            .flatten(),
        patched
            .failure
            .is_none()
            .then(|| late_slope(&patched.points))
            .flatten(),
    ) {
        (Some(s), Some(f)) => {
            text += &format!(
                "Here, over the last quarter of the settlement the pressure rises at {:.1} % of \
                 the initial elastic slope with standard MPM and {:.2} % with F-patch; at 2 mm \
                 standard MPM carries {:.2} k and F-patch {:.2} k ({:.0} % more with standard \
                 MPM). ",
                100.0 * s,
                100.0 * f,
                end(standard),
                end(patched),
                100.0 * (end(standard) / end(patched) - 1.0),
            );
            text += &if s > 0.05 && f < 0.01 {
                format!("**F-patch's plateau: {:.2} k.** ", end(patched))
            } else {
                "On this mesh the two do not separate into a rising and a level curve (the test's \
                 criterion: above 5 % and below 1 % of the initial slope). "
                    .to_owned()
            };
            text += &format!(
                "For comparison: no exact collapse load is known for a square footing; \
                 Gourvenec, Randolph & Kingsnorth (2006, IJG 6(3)) find a rough square footing on \
                 undrained clay about 5 % below Skempton's shape factor 1.2, i.e. about \
                 1.2 × 0.95 × (2 + π) = 5.9 k, and a smooth circular footing carries 5.69 k \
                 (Cox et al. 1961); a smooth square one lies a little below the rough. {}",
                if end(patched) > 5.9 {
                    format!(
                        "F-patch's level is above them: the elements beyond the footing's edge \
                         (here {beyond} m, against the half-edge {HALF_EDGE} m) also load the \
                         edge nodes, so the loaded area is effectively larger than (l/2)², and \
                         linear tetrahedra on a mesh this coarse are stiff even without locking."
                    )
                } else {
                    "F-patch's level is within that range.".to_owned()
                }
            );
        }
        _ => {
            text += &[stopped(standard), stopped(patched)]
                .into_iter()
                .flatten()
                .collect::<Vec<_>>()
                .join(" ");
            text += " The table shows how far each run came. Two causes of F-patch failures on \
                finer meshes were found and removed (2026-12-03): Newton stalling at the \
                rounding floor of eq. (40) above the tolerance (now accepted, see the solver \
                theory), and the first solve of a step linearised about the layer of points \
                next to the footing that the prescribed settlement alone strains past yield \
                (now linearised about the converged state, `solver.first_tangent`); with both, \
                the scene's mesh with F-patch takes the nominal 0.1 mm steps (measured: 5 to 7 \
                iterations in each of the first three steps, about a minute per step).";
        }
    }
    text + "\n\n"
}
