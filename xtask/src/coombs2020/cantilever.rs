//! §7.3, the elastic cantilever under an end load: load factor against the
//! normalised tip displacements beside the elastica (Figs. 13, 15, 17), the
//! tip at full load, and the Newton residuals of GIMP (Table 3).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use mpm_cases::cases::Solve;
use mpm_cases::cases::cantilever::{CantileverCase, CantileverParams, elastica_tip};
use mpm_cases::run::RunControl;
use mpm_cases::variant::{DomainUpdateKind, Variant};

use super::paper::TABLE_3;
use super::variants::{cpdi2, gimp, label, linear, short_label};
use super::{RunStats, compare_residuals};
use crate::markdown::Table;
use crate::plot::{Axis, Figure, Line, Marker, PALETTE, Series};

/// One cantilever analysis.
#[derive(Debug, Clone)]
pub struct Measured {
    /// Material points.
    pub points: usize,
    /// (load factor, u/l0, v/l0) after each step.
    pub tip: Vec<(f64, f64, f64)>,
    /// Largest distance from the elastica along the path, (u, v) in l0.
    pub path_deviation: (f64, f64),
    /// Newton work, time and residuals.
    pub stats: RunStats,
}

/// The load parameter α = P l0²/EI (EI = E d³/12 per unit thickness) at
/// load factor `lambda`.
fn alpha(p: &CantileverParams, lambda: f64) -> f64 {
    let ei = p.youngs_modulus * p.depth.powi(3) / 12.0;
    lambda * p.load * p.length.powi(2) / ei
}

/// Runs the cantilever with `variant`, `ppc`² points per cell and cell
/// size `h`.
pub fn measure(variant: Variant, ppc: usize, h: f64) -> Outcome {
    let p = CantileverParams {
        h,
        points_per_cell: ppc,
        ..CantileverParams::default()
    };
    let r = CantileverCase::run(&p, &variant, &RunControl::default(), |_, _, _| Ok(()))
        .map_err(|e| e.to_string())?;
    let tip: Vec<(f64, f64, f64)> = r
        .tip
        .iter()
        .map(|&(lambda, u, v)| (lambda, u / p.length, v / p.length))
        .collect();
    let path_deviation = tip
        .iter()
        .fold((0.0f64, 0.0f64), |(du, dv), &(lambda, u, v)| {
            let (ue, ve) = elastica_tip(alpha(&p, lambda));
            (du.max((u - ue).abs()), dv.max((v - ve).abs()))
        });
    let m = Measured {
        points: r.material_points,
        tip,
        path_deviation,
        stats: RunStats::of(&r.output),
    };
    println!(
        "cantilever {:>40} {ppc}x{ppc} h = {h}: tip {:?}, {} iterations, {:.2} s",
        label(&variant),
        m.tip.last(),
        m.stats.iterations,
        m.stats.time_s
    );
    Ok(m)
}

/// A variant, its material points per cell per direction and the cell
/// size (m).
pub type Setup = (Variant, usize, f64);

/// A measurement, or why the analysis failed.
pub type Outcome = Result<Measured, String>;

/// The cantilever analyses: the plotted ones and Table 3's.
#[derive(Debug, Clone)]
pub struct Study {
    /// The analyses and their outcomes, in plotting order; the last is
    /// Table 3's (GIMP, 6², h = 0.125 m).
    pub runs: Vec<(Setup, Outcome)>,
}

/// Runs of the figure: standard MPM 4², GIMP eq. 37 6² (h = 0.5 and
/// 0.25 m), CPDI2 4² (the paper's Fig. 17 uses 3², but the load is split
/// between the two points beside the neutral axis, which needs an even
/// count); then GIMP 6² at h = 0.125 m for Table 3.
const RUNS: [(Which, usize, f64); 5] = [
    (Which::Linear, 4, 0.5),
    (Which::Gimp37, 6, 0.5),
    (Which::Gimp37, 6, 0.25),
    (Which::Cpdi2, 4, 0.5),
    (Which::Gimp37, 6, 0.125),
];

/// The bases of [`RUNS`].
#[derive(Debug, Clone, Copy)]
enum Which {
    Linear,
    Gimp37,
    Cpdi2,
}

/// Runs every analysis of [`RUNS`].
pub fn study() -> Study {
    let runs = RUNS
        .iter()
        .map(|&(which, ppc, h)| {
            let v = match which {
                Which::Linear => linear(),
                Which::Gimp37 => gimp(DomainUpdateKind::CornerMidpoint),
                Which::Cpdi2 => cpdi2(),
            };
            ((v, ppc, h), measure(v, ppc, h))
        })
        .collect();
    Study { runs }
}

fn name(v: &Variant, ppc: usize, h: f64) -> String {
    format!("{} {ppc}×{ppc}, h = {h} m", short_label(v))
}

/// §5 of the report: the force–displacement plot and the tip at full load.
pub fn section(study: &Study, img: &Path) -> Result<String> {
    let p = CantileverParams::default();
    let mut md = String::new();
    writeln!(
        md,
        "## 5. Cantilever: load against tip displacement (Figs. 13, 15, 17)\n\n\
         Plane-strain beam 10 m × 1 m, E = 12 MPa, ν = 0.2, end load 100 kN in 50 equal \
         steps, split between the two points nearest the neutral axis at the free end \
         (§7.3). Tip displacement: the mean of those two points, normalised by l₀ = 10 m. \
         Reference: the elastica (inextensible Euler beam under a vertical end load, the \
         paper's analytical solution [33]), α = P l₀²/EI = {:.0} × load factor with \
         EI = E d³/12. The figure plots −u/l₀ and −v/l₀ (both displacements are negative).\n",
        alpha(&p, 1.0)
    )?;
    let mut series = Vec::new();
    let plotted = study.runs.len().saturating_sub(1);
    for (i, ((v, ppc, h), o)) in study.runs.iter().take(plotted).enumerate() {
        let Ok(m) = o else { continue };
        let color = PALETTE[i];
        let path = || std::iter::once(&(0.0, 0.0, 0.0)).chain(&m.tip);
        series.push(Series {
            label: name(v, *ppc, *h),
            points: path().map(|&(l, _, v)| (-v, l)).collect(),
            color,
            marker: None,
            filled: true,
            line: Line::Solid,
        });
        series.push(Series {
            label: String::new(),
            points: path().map(|&(l, u, _)| (-u, l)).collect(),
            color,
            marker: None,
            filled: true,
            line: Line::Dashed,
        });
    }
    let loads: Vec<f64> = (1..=20).map(|i| f64::from(i) * 0.05).collect();
    let elastica: Vec<(f64, f64, f64)> = loads
        .iter()
        .map(|&l| {
            let (u, v) = elastica_tip(alpha(&p, l));
            (l, u, v)
        })
        .collect();
    for (label, line) in [
        ("solid: vertical, −v/l₀", Line::Solid),
        ("dashed: horizontal, −u/l₀", Line::Dashed),
    ] {
        series.push(Series {
            label: label.into(),
            points: Vec::new(),
            color: PALETTE[7],
            marker: None,
            filled: true,
            line,
        });
    }
    series.push(Series {
        label: "elastica: −v/l₀".into(),
        points: elastica.iter().map(|&(l, _, v)| (-v, l)).collect(),
        color: PALETTE[10],
        marker: Some(Marker::Circle),
        filled: false,
        line: Line::None,
    });
    series.push(Series {
        label: "elastica: −u/l₀".into(),
        points: elastica.iter().map(|&(l, u, _)| (-u, l)).collect(),
        color: PALETTE[10],
        marker: Some(Marker::Circle),
        filled: true,
        line: Line::None,
    });
    let fig = Figure {
        title: "Cantilever: load factor against normalised tip displacement".into(),
        x: Axis::linear("normalised tip displacement −u/l₀ (dashed), −v/l₀ (solid)")
            .with_range(0.0, 0.9),
        y: Axis::linear("normalised force P/100 kN").with_range(0.0, 1.0),
        series,
        legend_title: "analysis".into(),
    };
    md.push_str(&fig.save_in(
        img,
        "coombs2020-cantilever.png",
        "Cantilever: load factor against −u/l₀ and −v/l₀ for standard MPM, GIMP and CPDI2, with the elastica",
    )?);

    let (ue, ve) = elastica_tip(alpha(&p, 1.0));
    let mut t = Table::new([
        "analysis",
        "points",
        "u/l₀ at full load",
        "elastica",
        "v/l₀ at full load",
        "elastica",
        "largest |Δu|/l₀, |Δv|/l₀ along the path",
        "iterations",
        "time (s)",
    ]);
    for ((v, ppc, h), o) in &study.runs {
        let row = match o {
            Ok(m) => {
                let (_, u, w) = m.tip.last().copied().unwrap_or((0.0, f64::NAN, f64::NAN));
                vec![
                    name(v, *ppc, *h),
                    m.points.to_string(),
                    format!("{u:.4}"),
                    format!("{ue:.4}"),
                    format!("{w:.4}"),
                    format!("{ve:.4}"),
                    format!("{:.4}, {:.4}", m.path_deviation.0, m.path_deviation.1),
                    m.stats.iterations_note(),
                    format!("{:.2}", m.stats.time_s),
                ]
            }
            Err(e) => vec![name(v, *ppc, *h), format!("failed: {e}")],
        };
        t.row(row);
    }
    md.push_str(&t.render());
    md.push_str(&commentary(study, (ue, ve)));
    Ok(md)
}

fn commentary(study: &Study, (ue, ve): (f64, f64)) -> String {
    let end: Vec<String> = study
        .runs
        .iter()
        .filter_map(|((v, ppc, h), o)| {
            let m = o.as_ref().ok()?;
            let (_, u, w) = *m.tip.last()?;
            Some(format!(
                "{:.3}, {:.3} ({})",
                (u - ue).abs(),
                (w - ve).abs(),
                name(v, *ppc, *h)
            ))
        })
        .collect();
    // GIMP at h = 0.5, 0.25 and 0.125 m: the second, third and fifth runs.
    let gimp_path = |i: usize| {
        study
            .runs
            .get(i)
            .and_then(|(_, o)| o.as_ref().ok())
            .map(|m| m.path_deviation.0.max(m.path_deviation.1))
    };
    let refinement = match (gimp_path(1), gimp_path(2), gimp_path(4)) {
        (Some(a), Some(b), Some(c)) => format!(
            "Refining GIMP from h = 0.5 m to 0.25 m brings the path closer to the elastica \
             (largest deviation {a:.3} → {b:.3} l₀); at h = 0.125 m it is {c:.3} l₀, the \
             vertical displacement overshooting late in the loading. The paper explains the \
             same overshoot (Figs. 13, 15, 16) by the stress concentration at the two loaded \
             points, whose volume shrinks with h."
        ),
        _ => "Some GIMP analyses failed; see the table.".into(),
    };
    let all_converged = study
        .runs
        .iter()
        .all(|(_, o)| o.as_ref().is_ok_and(|m| m.stats.cut_steps == 0));
    format!(
        "**Reading.** {} At full load the tip is off the elastica by (|Δu|, |Δv|)/l₀ = {}. \
         {refinement} The coarse grid (two cells through the depth) is stiff in early bending \
         (left of the elastica at low load factors), as in the paper. The \
         paper's Fig. 13 shows standard MPM with 3² to 12² points per cell and Fig. 17 CPDI2 \
         with 3²; we run 4², since the load is split between the two points beside the \
         neutral axis, which needs an even count.\n\n",
        if all_converged {
            "Every analysis converges in all 50 load steps without a cut."
        } else {
            "Not every analysis converged without cutting steps; see the iterations column."
        },
        end.join("; "),
    )
}

/// §4, second part: Table 3 from the GIMP run at h = 0.125 m.
pub fn table3_section(study: &Study) -> Result<String> {
    let mut md = String::new();
    writeln!(
        md,
        "### Table 3: GIMP cantilever (eq. 37, h = 0.125 m, 6² points per cell)\n\n\
         Normalised residual of eq. (40) per Newton iteration, load steps 10, 20, 40, 49 and \
         50.\n"
    )?;
    let Some((_, Ok(m))) = study.runs.last() else {
        writeln!(md, "The analysis failed; no residuals.\n")?;
        return Ok(md);
    };
    let c = compare_residuals(&TABLE_3, &m.stats);
    md.push_str(&c.table.render());
    writeln!(
        md,
        "**Reading.** Both end in quadratic convergence: {} iterations here against the \
         paper's {} (steps 10, 20, 40, 49, 50). Iteration 0 measured as the paper's code \
         measures it (all dofs, reactions not yet known; see Table 8) is {} against the \
         paper's {} (largest difference {:.0} %): here the measure is essentially the norm \
         of the root reactions over that of the end load, which depends on how many nodes \
         share each (the points carrying the load, the supports along the root), details \
         the paper does not fix, so it compares less sharply than the collapse's. Our \
         eq. (40) at iteration 0 is {}. From iteration 1 on the sequences have the same \
         form.\n",
        c.ours_iterations,
        c.paper_iterations,
        c.ours_initial,
        c.paper_first,
        100.0 * c.initial_worst,
        c.ours_first
    )?;
    Ok(md)
}
