//! Wang et al. (2021) §5.5, the rotation of a vane slice (Fig. 18C): the
//! scene `scenes/wang2021_vane_slice.toml` run with standard MPM and with
//! F-patch (and F-patch with 11 points per element), the torque against
//! the rotation drawn as a PNG beside the cylindrical-surface estimate
//! 2π r_v² h k.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use mpm_cases::run::{RunControl, RunOutput};
use mpm_cases::scene::Problem;

use crate::machine::{measured, print_run};
use crate::markdown::Table;
use crate::plot::{Axis, Figure, Line, Marker, PALETTE, Series};

const SCENE: &str = include_str!("../../scenes/wang2021_vane_slice.toml");
/// Vane radius, slice height (m) and the scene's total rotation (rad).
const R_V: f64 = 0.05;
const HEIGHT: f64 = R_V;
const ROTATION: f64 = 8e-4;
/// k = ρ_y/√2 of eq. (16) for the scene's ρ_y = √3·10⁴ Pa.
const K: f64 = 1.7320508075688772e4 / std::f64::consts::SQRT_2;

/// The cylindrical-surface estimate 2π r_v² h k (the torque of a rigid
/// cylinder of radius r_v turning in the soil at the shear strength k).
fn cylindrical() -> f64 {
    2.0 * std::f64::consts::PI * R_V * R_V * HEIGHT * K
}

/// One run: the torque after every step against the rotation in mrad.
struct Curve {
    label: String,
    points_per_element: usize,
    torque: Vec<(f64, f64)>,
    elements: usize,
    material_points: usize,
    iterations: usize,
    max_iterations: usize,
    cuts: usize,
    seconds: f64,
    peak_mb: Option<f64>,
    failure: Option<String>,
}

fn run(mesh: &str, fpatch: bool, keast: bool) -> Result<Curve> {
    let mut overrides = vec![format!("mesh.file=\"{mesh}\"")];
    if fpatch {
        overrides.push("solver.locking=\"fpatch\"".to_owned());
    }
    if keast {
        overrides.push("body.0.placement=\"keast11\"".to_owned());
    }
    let (scene, src) =
        mpm_cases::scene::parse(SCENE, "scenes/wang2021_vane_slice.toml", &overrides)
            .context("parsing the vane scene")?;
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let problem =
        Problem::<3>::build_in(&scene, &src, 0, &scenes).context("building the vane scene")?;
    let vane = problem
        .reactions
        .iter()
        .find(|r| r.name == "vane")
        .cloned()
        .context("the vane scene has no `vane` reaction")?;
    let elements = match &problem.mesh {
        mpm_cases::scene::build::SceneMesh::Simplex(m) => m.element_count(),
        mpm_cases::scene::build::SceneMesh::Grid(_) => 0,
    };
    let label = format!(
        "{}, {} point{}",
        if fpatch { "F-patch" } else { "standard MPM" },
        if keast { 11 } else { 1 },
        if keast { "s" } else { "" }
    );
    let mut curve = Curve {
        label,
        points_per_element: if keast { 11 } else { 1 },
        torque: vec![(0.0, 0.0)],
        elements,
        material_points: problem.len(),
        iterations: 0,
        max_iterations: 0,
        cuts: 0,
        seconds: 0.0,
        peak_mb: None,
        failure: None,
    };
    let (result, seconds, peak): (Result<RunOutput<3>, _>, _, _) = measured(|| {
        mpm_cases::scene::run(&problem, &RunControl::default(), |_, report, _| {
            let m = vane.moment(&problem, report).map_or(f64::NAN, |m| m[2]);
            curve.torque.push((1e3 * report.lambda1 * ROTATION, m));
            curve.iterations += report.iterations();
            curve.max_iterations = curve.max_iterations.max(report.iterations());
            Ok(())
        })
    });
    (curve.seconds, curve.peak_mb) = (seconds, peak);
    match result {
        Ok(out) => curve.cuts = out.summary.cut_steps,
        Err(e) => curve.failure = Some(e.to_string()),
    }
    print_run(
        &format!("vane slice, {}", curve.label),
        curve.torque.len() - 1,
        curve.iterations,
        curve.seconds,
        curve.failure.as_deref(),
    );
    Ok(curve)
}

/// The torque's slope over the last fifth of the rotation against the
/// first step's (elastic) slope.
fn late_slope(t: &[(f64, f64)]) -> Option<f64> {
    let (first, last) = (t.get(1)?, t.last()?);
    let back = t.iter().rev().find(|(a, _)| *a <= 0.8 * last.0 + 1e-12)?;
    if last.0 <= back.0 {
        return None;
    }
    Some((last.1 - back.1) / (last.0 - back.0) / (first.1 / first.0))
}

/// The section: the runs, the table, the PNG and the reading.
pub fn section(full: bool, img: &Path) -> Result<String> {
    let mesh = if full {
        "meshes/vane_slice.msh"
    } else {
        "meshes/vane_slice_quick.msh"
    };
    let mut curves = vec![run(mesh, false, false)?, run(mesh, true, false)?];
    if !full {
        curves.push(run(mesh, true, true)?);
    }
    let t_cyl = cylindrical();
    let mut md = String::new();
    writeln!(
        md,
        "## 4. Rotation of a vane slice (§5.5, Fig. 18C)\n\n\
         The scene `scenes/wang2021_vane_slice.toml`: a four-bladed vane (r_v = {R_V} m, blades \
         0.1 r_v thick) through a slice of soil of height r_v and radius 3 r_v, E = 100 MPa, \
         ν = 0.3, ρ_y = √3·10⁴ Pa in eq. (16) (k = ρ_y/√2 = {:.2} kPa), turned by 20 steps of \
         4·10⁻⁵ rad with the whole mesh rotating with the vane (the `rotation` mesh motion; \
         the blade faces' nodes follow it). The outer cylinder is fixed, the slice's faces are \
         on rollers (plane strain, as the 2D analysis the paper compares with, its reference \
         49). Torque: the moment about the axis of the reactions on the blade faces' nodes. \
         Mesh ({}): ten-node tetrahedra from `scenes/meshes/make_vane_slice.py` (Gmsh), each \
         split into eight linear children; the paper's has 95,456 tetrahedra.\n",
        K / 1e3,
        if full {
            "the scene's, 98,648 tetrahedra"
        } else {
            "quick mode, `vane_slice_quick.msh`, 10,496 tetrahedra (`--full` runs the \
             scene's 98,648)"
        },
    )?;
    let mut table = Table::new([
        "method",
        "points per element",
        "tetrahedra",
        "points",
        "steps (cut)",
        "Newton iterations (most in a step)",
        "time (s)",
        "peak memory (MB)",
        "torque at 0.4 mrad (N m)",
        "torque at 0.8 mrad (N m)",
        "torque / 2π r_v² h k",
        "late slope / initial slope",
    ]);
    let at = |c: &Curve, a: f64| {
        c.torque
            .iter()
            .find(|p| (p.0 - a).abs() < 1e-9)
            .map_or("–".to_owned(), |p| format!("{:.3}", p.1))
    };
    for c in &curves {
        table.row(vec![
            c.label.split(',').next().unwrap_or_default().to_owned(),
            c.points_per_element.to_string(),
            c.elements.to_string(),
            c.material_points.to_string(),
            match &c.failure {
                None => format!("{} ({})", c.torque.len() - 1, c.cuts),
                Some(f) => format!("{} (then failed: {f})", c.torque.len() - 1),
            },
            format!("{} ({})", c.iterations, c.max_iterations),
            format!("{:.1}", c.seconds),
            c.peak_mb.map_or("–".to_owned(), |m| format!("{m:.0}")),
            at(c, 0.4),
            at(c, 0.8),
            c.torque
                .last()
                .map_or("–".to_owned(), |p| format!("{:.3}", p.1 / t_cyl)),
            late_slope(&c.torque).map_or("–".to_owned(), |s| format!("{s:.3}")),
        ]);
    }
    md.push_str(&table.render());
    let mut series: Vec<Series> = curves
        .iter()
        .enumerate()
        .map(|(i, c)| Series {
            label: c.label.clone(),
            points: c.torque.clone(),
            color: PALETTE[i],
            marker: Some(Marker::CYCLE[i]),
            filled: i == 0,
            line: Line::Solid,
        })
        .collect();
    series.push(Series {
        label: "2π r_v² h k (cylindrical surface)".into(),
        points: vec![(0.0, t_cyl), (1e3 * ROTATION, t_cyl)],
        color: PALETTE[curves.len()],
        marker: None,
        filled: false,
        line: Line::Dashed,
    });
    let figure = Figure {
        title: "Rotation of a vane slice (Wang 2021 §5.5)".into(),
        x: Axis::linear("vane rotation (mrad)"),
        y: Axis::linear("torque (N m)"),
        series,
        legend_title: "treatment".into(),
    };
    md.push_str(&figure.save_in(
        img,
        "wang2021-vane-slice.png",
        "Vane slice: torque against rotation, standard MPM and F-patch, with the cylindrical estimate",
    )?);
    md.push_str(&reading(&curves, t_cyl));
    Ok(md)
}

fn reading(curves: &[Curve], t_cyl: f64) -> String {
    let end = |c: &Curve| c.torque.last().map_or(f64::NAN, |p| p.1);
    let (standard, patched) = (&curves[0], &curves[1]);
    let mut text = String::from(
        "**Reading.** The paper's Fig. 18C: F-patch's torque plateaus after the soil yields, \
         standard MPM's does not (volumetric locking), whatever the number of points per \
         element; F-patch's plateau differs from the cylindrical estimate. ",
    );
    match (
        late_slope(&standard.torque).filter(|_| standard.failure.is_none()),
        late_slope(&patched.torque).filter(|_| patched.failure.is_none()),
    ) {
        (Some(s), Some(f)) => {
            let _ = write!(
                text,
                "Here, over the last fifth of the rotation the torque rises at {:.1} % of the \
                 initial elastic slope with standard MPM and {:.1} % with F-patch; at 0.8 mrad \
                 standard MPM carries {:.2} N m and F-patch {:.2} N m, {:.2} times the \
                 cylindrical estimate 2π r_v² h k = {t_cyl:.3} N m (with k from eq. 16; with \
                 the 10 kPa of the paper's reference 49, {:.3} N m). ",
                100.0 * s,
                100.0 * f,
                end(standard),
                end(patched),
                end(patched) / t_cyl,
                t_cyl * 1e4 / K,
            );
            if let Some(c) = curves.get(2).filter(|c| c.failure.is_none()) {
                let _ = write!(
                    text,
                    "With 11 points per element F-patch ends at {:.2} N m ({:+.1} % against 1 \
                     point), as the paper found the number of points immaterial. ",
                    end(c),
                    100.0 * (end(c) / end(patched) - 1.0)
                );
            }
        }
        _ => {
            for c in curves {
                if let Some(f) = &c.failure {
                    let _ = write!(text, "{} stopped: {f}. ", c.label);
                }
            }
        }
    }
    text.push_str(
        "The paper puts the plateau above the estimate because the real failure surface is not \
         cylindrical; but the cylinder of radius r_v turning rigidly with the vane is a \
         kinematically admissible mechanism, so 2π r_v² h k is an upper bound of the collapse \
         torque of the continuum, and a plateau above it measures the discretisation. \
         `crates/mpm-cases/tests/vane.rs` checks the pieces where the answer is known: a solid \
         cylinder of radius r_v turned in the same ring (mesh from the same script) gives the \
         closed-form elastic torque 4π G h θ a²b²/(b²−a²) within 1.4 % (standard MPM) and \
         0.9 % (F-patch), the moments of the driven and fixed surfaces' reactions balance to \
         10⁻⁶, and past yield F-patch levels off 1.29 times above the limit 2π a² h k on the \
         test mesh (elements of 0.4 a at the core), 1.18 times on one twice as fine (0.2 a), \
         while standard MPM keeps rising: the excess falls with refinement. The vane's blade \
         tips concentrate the strain further.\n\n",
    );
    text
}
