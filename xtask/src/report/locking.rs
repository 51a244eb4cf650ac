//! Cook's membrane and the Prandtl footing (`mpm_cases::locking`) on
//! triangles (standard MPM, F-patch) and on a grid (standard MPM, F-bar),
//! against the published membrane tip and Prandtl's collapse pressure.

use mpm_cases::locking::{
    Cook, Footing, Traction, WIDTH, YOUNG, footing_grid, footing_triangles, grid, triangles,
};
use mpm_cases::variant::FormulationKind;
use mpm_solver::{FBar, FPatch, NoLocking, SolverError};

use super::Mode;
use super::study::{CaseSpec, Level, Sample, VariantSpec};

/// The published converged tip of the membrane in plane strain for E = 70,
/// ν = 1/3 and a total shear of 100: CalculiX's 32.27 in the CoFEA
/// comparison quoted by the solids4foam tutorial `cooksMembrane` (Code_Aster
/// 32.20, Elmer 32.28; see `docs/src/reproduction/locking.md`).
const COOK_PUBLISHED_E70: f64 = 32.27;

/// That tip for our E = [`YOUNG`]: the response is linear, so it scales
/// as 1/E (9.036).
fn cook_reference() -> f64 {
    COOK_PUBLISHED_E70 * 70.0 / YOUNG
}

/// The small load of the linear runs; their tips are scaled to a load of
/// 100.
const SMALL: f64 = 1.0;

/// One Cook run at refinement `n` against the published tip.
fn cook_error(
    n: usize,
    run: impl Fn(&Cook) -> Result<mpm_cases::locking::CookResult, SolverError>,
) -> Result<Sample, String> {
    let cook = Cook {
        nu: 1.0 / 3.0,
        load: SMALL,
        steps: 1,
        n,
        formulation: FormulationKind::Pc,
    };
    let r = run(&cook).map_err(|e| e.to_string())?;
    let reference = cook_reference();
    Ok(Sample {
        error: (r.tip * 100.0 / SMALL - reference).abs() / reference,
        seconds: r.seconds,
    })
}

/// Cook's membrane, small load, ν = 1/3.
pub fn cook(mode: Mode) -> CaseSpec {
    let ns: Vec<usize> = match mode {
        Mode::Quick => vec![4, 8],
        Mode::Full => vec![4, 8, 16, 32, 64, 128],
    };
    let all: Vec<VariantSpec> = vec![
        VariantSpec::new(
            "triangles, standard MPM",
            Box::new(|l: &Level| cook_error(l.n, |c| triangles(c, |_| NoLocking))),
        ),
        VariantSpec::new(
            "triangles, F-patch",
            Box::new(|l: &Level| cook_error(l.n, |c| triangles(c, FPatch::new))),
        ),
        VariantSpec::new(
            "grid, standard MPM",
            Box::new(|l: &Level| {
                cook_error(l.n, |c| grid(c, NoLocking, Traction::EdgeGaussPoints))
            }),
        ),
        VariantSpec::new(
            "grid, F-bar",
            Box::new(|l: &Level| {
                cook_error(l.n, |c| grid(c, FBar::default(), Traction::EdgeGaussPoints))
            }),
        ),
    ];
    let variants = match mode {
        Mode::Quick => all.into_iter().filter(|v| v.label.contains("F-")).collect(),
        Mode::Full => all,
    };
    CaseSpec {
        slug: "cook",
        title: "Cook's membrane".into(),
        about: format!(
            "The membrane (0, 0), (48, 44), (48, 60), (0, 44) of `mpm_cases::locking` in plane \
             strain, clamped on the left, a vertical shear on the right edge, Hencky elasticity \
             E = {YOUNG}, ν = 1/3, one step of a small load ({SMALL}) carried by load points at \
             the edge's Gauss points, the tip (48, 60) scaled to a load of 100 (linear \
             response), as in [the locking report](locking.md). Triangles: the linear children \
             of n × n × 2 six-node triangles mapped onto the membrane, 3 points per child \
             (F-patch over each parent's children). Grid: n cells across the width {WIDTH}, 2 × 2 \
             lattice points per cell inside the membrane (F-bar per cell). Reference: the \
             published plane-strain tip {COOK_PUBLISHED_E70} for E = 70 (CalculiX in the CoFEA \
             comparison; Code_Aster 32.20, Elmer 32.28) scaled by 70/{YOUNG} to {:.3}; the codes \
             differ by 0.25 %, so errors below about 3e-3 are within the reference's own \
             spread. Error: |tip − reference|/reference. Levels: n = {}.",
            cook_reference(),
            ns.iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        error_name: "relative tip error".into(),
        h_name: format!("the spacing {WIDTH}/n"),
        levels: ns
            .iter()
            .map(|&n| Level {
                label: format!("n = {n}"),
                n,
                h: WIDTH / n as f64,
            })
            .collect(),
        styles: Vec::new(),
        variants,
        absent: 0,
    }
}

/// The footing of the report: the locking report's (ν = 0.49, E/k = 10⁴,
/// settlement 0.006 in 12 steps) at `n` nodes across.
fn footing_at(n: usize) -> Footing {
    Footing {
        nu: 0.49,
        young: 1e4,
        n,
        settlement: 0.006,
        steps: 12,
        formulation: FormulationKind::Pc,
    }
}

/// One footing run against Prandtl: |final pressure/((2 + π) k) − 1|; a
/// run that stopped early is a failure with its message.
fn footing_error(
    n: usize,
    run: impl Fn(&Footing) -> Result<mpm_cases::locking::FootingCurve, SolverError>,
) -> Result<Sample, String> {
    let f = footing_at(n);
    let curve = run(&f).map_err(|e| e.to_string())?;
    if let Some(e) = curve.failure {
        let reached = curve.points.last().map_or(0.0, |p| p.0);
        return Err(format!("stopped at settlement {reached:.4}: {e}"));
    }
    let last = curve
        .points
        .last()
        .ok_or_else(|| "no converged step".to_owned())?
        .1;
    Ok(Sample {
        error: (last / (2.0 + std::f64::consts::PI) - 1.0).abs(),
        seconds: curve.seconds,
    })
}

/// The Prandtl strip footing.
pub fn footing(mode: Mode) -> CaseSpec {
    let ns: Vec<usize> = match mode {
        Mode::Quick => vec![10, 20],
        Mode::Full => vec![10, 20, 40],
    };
    let all: Vec<VariantSpec> = vec![
        VariantSpec::new(
            "triangles, standard MPM",
            Box::new(|l: &Level| footing_error(l.n, |f| footing_triangles(f, |_| NoLocking))),
        ),
        VariantSpec::new(
            "triangles, F-patch",
            Box::new(|l: &Level| footing_error(l.n, |f| footing_triangles(f, FPatch::new))),
        ),
        VariantSpec::new(
            "grid, standard MPM",
            Box::new(|l: &Level| footing_error(l.n, |f| footing_grid(f, NoLocking))),
        ),
        VariantSpec::new(
            "grid, F-bar",
            Box::new(|l: &Level| footing_error(l.n, |f| footing_grid(f, FBar::default()))),
        ),
    ];
    let variants = match mode {
        Mode::Quick => all
            .into_iter()
            .filter(|v| v.label == "grid, F-bar")
            .collect(),
        Mode::Full => all,
    };
    let f = footing_at(0);
    CaseSpec {
        slug: "footing",
        title: "Prandtl strip footing".into(),
        about: format!(
            "The smooth rigid strip footing of `mpm_cases::locking::Footing`: half-width 1 on a \
             weightless von Mises layer 5 × 5 (half model, plane strain, E = {}, ν = {}, \
             perfectly plastic, k = 1), pressed down {} in {} steps (about ten times the \
             settlement at which the elastic slope reaches collapse), as in [the locking \
             report](locking.md). Triangles: children of (n/2)² × 2 six-node triangles, 3 points \
             per child (F-patch over each parent's children); grid: n cells across, 2 × 2 \
             points per cell (F-bar per cell). Reference: Prandtl's collapse pressure \
             (2 + π) k; error: |p/((2 + π) k) − 1| with p the footing pressure at the final \
             settlement (the plateau of the treated runs; standard MPM locks and keeps \
             rising). n = 80 is left out to keep the full mode under 15 minutes: there F-bar \
             reaches an error of 8.8e-3 in 6 to 7 minutes on this machine (measured once, not \
             in the tables), F-patch takes about 8 and standard MPM over a minute. F-bar \
             approaches the collapse pressure from above, F-patch from below, so \
             a coarse run can land near it by a cancellation of errors; the orders tell. \
             Levels: n = {} (node spacing 5/n; n a multiple of 10 puts the footing edge on a \
             node).",
            f.young,
            f.nu,
            f.settlement,
            f.steps,
            ns.iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        error_name: "|p / (2 + π)k − 1|".into(),
        h_name: "the node spacing 5/n".into(),
        levels: ns
            .iter()
            .map(|&n| Level {
                label: format!("n = {n}"),
                n,
                h: 5.0 / n as f64,
            })
            .collect(),
        styles: Vec::new(),
        variants,
        absent: 0,
    }
}
