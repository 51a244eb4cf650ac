//! The built-in cases of `mpm_cases::cases` with a reference — the column,
//! the simple shear, the annulus and the stretch — over every variant of
//! basis × formulation × locking × domain rule that applies to them.

use mpm_cases::body::InitialDomain;
use mpm_cases::cases::Solve;
use mpm_cases::cases::annulus::{self, AnnulusParams};
use mpm_cases::cases::column::{self, ColumnParams};
use mpm_cases::cases::shear::{self, ShearParams};
use mpm_cases::cases::stretch::{self, StretchParams};
use mpm_cases::run::{DomainBounds, RunControl};
use mpm_cases::variant::{
    BasisKind, DomainUpdateKind, FormulationKind, LockingKind, Variant, VariantVisitor, dispatch,
};
use mpm_mesh::RegularGrid;
use mpm_solver::{DomainUpdater, Flat, Formulation};

use super::Mode;
use super::study::{CaseSpec, Level, Sample, VariantSpec};
use crate::coombs2020::variants::rule_label;

/// Names of the line styles of the implicit cases: the formulation.
fn formulation_styles() -> Vec<String> {
    vec![
        "previously converged (PC)".into(),
        "updated Lagrangian (UL)".into(),
    ]
}

/// Every combination of basis × formulation × locking × domain rule (with
/// the default integration volume of GIMP, det F V⁰), each once as it
/// runs (`Variant::resolved`); the formulations of a family side by side,
/// the default (PC) first.
fn combinations() -> Vec<Variant> {
    let mut formulations = FormulationKind::ALL.to_vec();
    formulations.sort_by_key(|f| *f != Variant::default().formulation);
    let mut out: Vec<Variant> = Vec::new();
    for &basis in BasisKind::ALL {
        for &locking in LockingKind::ALL {
            for &domain_update in DomainUpdateKind::ALL {
                for &formulation in &formulations {
                    let v = Variant {
                        basis,
                        formulation,
                        locking,
                        domain_update,
                        ..Variant::default()
                    }
                    .resolved();
                    if !out.contains(&v) {
                        out.push(v);
                    }
                }
            }
        }
    }
    out
}

/// A visitor that runs nothing: [`dispatch`] with it says whether a
/// combination exists on a regular grid.
struct Exists;

impl<const D: usize> VariantVisitor<D> for Exists {
    type Output = ();

    fn visit<B, F, U>(self, _basis: B, _updater: U)
    where
        B: InitialDomain<D, Mesh = RegularGrid<D>, Domain: Flat + DomainBounds<D>>,
        F: Formulation,
        U: DomainUpdater<D, B::Domain>,
    {
    }
}

/// The combinations `accepts` takes and how many it refuses.
fn applicable(accepts: impl Fn(&Variant) -> Result<(), String>) -> (Vec<Variant>, usize) {
    let all = combinations();
    let total = all.len();
    let ok: Vec<Variant> = all.into_iter().filter(|v| accepts(v).is_ok()).collect();
    let refused = total - ok.len();
    (ok, refused)
}

/// The grid variants: every combination [`dispatch`] accepts.
fn grid_variants() -> (Vec<Variant>, usize) {
    applicable(|v| dispatch::<2, _>(v, Exists))
}

/// The variant's name without its formulation: basis, domain rule and
/// locking treatment.
fn family(v: &Variant) -> String {
    let basis = match v.basis {
        BasisKind::Linear => "standard MPM".to_owned(),
        BasisKind::BSpline2 => "quadratic B-spline".to_owned(),
        BasisKind::BSpline2Boundary => "quadratic B-spline, boundary-modified".to_owned(),
        BasisKind::Cpdi2 => "CPDI2".to_owned(),
        BasisKind::Gimp => format!("GIMP, {}", rule_label(v.domain_update)),
    };
    let locking = match v.locking {
        LockingKind::None => "",
        LockingKind::FBar => ", F-bar",
        LockingKind::FPatch => ", F-patch",
        LockingKind::CellAveraged => ", cell-averaged",
    };
    format!("{basis}{locking}")
}

/// The variant's full name: [`family`] and the formulation.
pub fn label(v: &Variant) -> String {
    let formulation = match v.formulation {
        FormulationKind::Pc => "PC",
        FormulationKind::Ul => "UL",
    };
    format!("{}, {formulation}", family(v))
}

/// The variant as a [`VariantSpec`]: its family's colour, the
/// formulation's line style, and `run`.
fn spec(v: &Variant, run: impl Fn(&Level) -> Result<Sample, String> + 'static) -> VariantSpec {
    let style = usize::from(v.formulation == FormulationKind::Ul);
    VariantSpec::new(label(v), Box::new(run)).styled(family(v), style)
}

/// The variants of the quick mode: those `keep` names, in the order of
/// `all`.
fn quick(all: Vec<Variant>, keep: &[Variant]) -> Vec<Variant> {
    all.into_iter().filter(|v| keep.contains(v)).collect()
}

/// Standard MPM and GIMP with `rule` (eq. 34 where it matters), PC.
fn linear_and_gimp(rule: DomainUpdateKind) -> [Variant; 2] {
    [
        Variant::default(),
        Variant {
            basis: BasisKind::Gimp,
            domain_update: rule,
            ..Variant::default()
        },
    ]
}

/// `50/2^k` style: h with at most four decimals, no trailing zeros.
fn trimmed(h: f64) -> String {
    let s = format!("{h:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// The column under self weight (Coombs et al. 2020 §7.1).
pub fn column(mode: Mode) -> CaseSpec {
    let ks: Vec<usize> = match mode {
        Mode::Quick => vec![2, 3],
        Mode::Full => (2..=9).collect(),
    };
    let (all, absent) = grid_variants();
    let variants = match mode {
        Mode::Quick => quick(all, &linear_and_gimp(DomainUpdateKind::Stretch)),
        Mode::Full => all,
    };
    let levels = ks
        .iter()
        .map(|&k| {
            let h = 50.0 / 2f64.powi(k as i32);
            Level {
                label: format!("k = {k}"),
                n: k,
                h,
            }
        })
        .collect::<Vec<_>>();
    CaseSpec {
        slug: "column",
        title: "Column under self weight".into(),
        about: format!(
            "Coombs et al. 2020 §7.1 (`mpm_cases::cases::column`): a 50 m elastic column one \
             cell wide compacting under its weight, E = 1 MPa, ν = 0, ϱ₀ = 80 kg/m³, g = 10 m/s², \
             20 load steps, tolerance 1e-9, 2 × 2 points per cell. Reference: the analytic \
             σ_zz of eq. (41); error: eq. (42), the volume-weighted mean of |σ_zz − σ_zz^a| over \
             ϱ₀ g l₀. Levels: h = 50/2^k m, k = {} ({}).",
            ks_span(&ks),
            levels
                .iter()
                .map(|l| trimmed(l.h))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        error_name: "error, eq. (42)".into(),
        h_name: "the cell size 50/2^k m".into(),
        levels,
        styles: formulation_styles(),
        variants: variants
            .iter()
            .map(|&v| {
                spec(&v, move |l: &Level| {
                    let p = ColumnParams {
                        h: l.h,
                        ..ColumnParams::default()
                    };
                    let r =
                        column::ColumnCase::run(&p, &v, &RunControl::default(), |_, _, _| Ok(()))
                            .map_err(|e| e.to_string())?;
                    Ok(Sample {
                        error: r.error,
                        seconds: r.output.wall_time_s,
                    })
                })
            })
            .collect(),
        absent,
    }
}

/// "2..9" or "2, 3".
fn ks_span(ks: &[usize]) -> String {
    match ks {
        [a, b] => format!("{a}, {b}"),
        [a, .., b] => format!("{a}..{b}"),
        _ => ks
            .iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// The simple shear (Coombs et al. 2020 §7.2), elastic.
pub fn shear(mode: Mode) -> CaseSpec {
    let ns: Vec<usize> = match mode {
        Mode::Quick => vec![2, 4],
        Mode::Full => vec![2, 4, 8, 16],
    };
    let (all, absent) = grid_variants();
    let variants = match mode {
        Mode::Quick => quick(all, &linear_and_gimp(DomainUpdateKind::Stretch)),
        Mode::Full => all,
    };
    CaseSpec {
        slug: "shear",
        title: "Simple shear".into(),
        about: format!(
            "Coombs et al. 2020 §7.2 (`mpm_cases::cases::shear`): a unit square of Hencky \
             material (E = 10 kPa, ν = 0.3) sheared to γ = 6 in 30 steps, 3 × 3 points per cell, \
             grid offset 0.123456789 h. Reference: the homogeneous stress of a single material \
             point driven through the same increments (the closed form); error: the largest \
             ‖σ_p − σ_ref‖/‖σ_ref‖ over points and steps. Levels: h = 1/n m, n = {}.",
            ns.iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        error_name: "largest relative stress error".into(),
        h_name: "the cell size 1/n m".into(),
        levels: ns
            .iter()
            .map(|&n| Level {
                label: format!("n = {n}"),
                n,
                h: 1.0 / n as f64,
            })
            .collect(),
        styles: formulation_styles(),
        variants: variants
            .iter()
            .map(|&v| {
                spec(&v, move |l: &Level| {
                    let p = ShearParams {
                        h: l.h,
                        ..ShearParams::default()
                    };
                    let r = shear::ShearCase::run(&p, &v, &RunControl::default(), |_, _, _| Ok(()))
                        .map_err(|e| e.to_string())?;
                    Ok(Sample {
                        error: r.error,
                        seconds: r.output.wall_time_s,
                    })
                })
            })
            .collect(),
        absent,
    }
}

/// The annulus under torsion (Coombs et al. 2020 §7.4) on generated
/// triangles: standard MPM only.
pub fn annulus(mode: Mode) -> CaseSpec {
    let hs: Vec<f64> = match mode {
        Mode::Quick => vec![0.25, 0.125],
        Mode::Full => vec![0.25, 0.125, 0.0625, 0.03125, 0.015625],
    };
    let (variants, absent) = applicable(|v| v.require_standard_mpm("triangles"));
    CaseSpec {
        slug: "annulus",
        title: "Annulus under torsion".into(),
        about: format!(
            "Coombs et al. 2020 §7.4 (`mpm_cases::cases::annulus`): the annulus 0.75 ≤ R ≤ 1.25 m \
             on generated linear triangles of size about h, E = 1 Pa, ν = 0, both rims fixed, \
             turned by θ(R) of eq. (44) with α = 0.1 rad over 10 steps by the manufactured body \
             force, 3 points per triangle. Triangles run standard MPM only \
             (`Variant::require_standard_mpm`), so the variants are the two formulations. \
             Reference: the manufactured displacement; error: the volume-weighted mean of \
             |u_p − u^a(X_p)| (m). Levels: h = {} m.",
            hs.iter()
                .map(|h| trimmed(*h))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        error_name: "mean displacement error (m)".into(),
        h_name: "the element size parameter h (m)".into(),
        levels: hs
            .iter()
            .map(|&h| Level {
                label: format!("h = {}", trimmed(h)),
                n: (1.0 / h).round() as usize,
                h,
            })
            .collect(),
        styles: formulation_styles(),
        variants: variants
            .iter()
            .map(|&v| {
                spec(&v, move |l: &Level| {
                    let p = AnnulusParams {
                        h: l.h,
                        ..AnnulusParams::default()
                    };
                    let r =
                        annulus::AnnulusCase::run(&p, &v, &RunControl::default(), |_, _, _| Ok(()))
                            .map_err(|e| e.to_string())?;
                    Ok(Sample {
                        error: r.error,
                        seconds: r.output.wall_time_s,
                    })
                })
            })
            .collect(),
        absent,
    }
}

/// The simple stretch on tetrahedra (Wang et al. 2021 §5.3): standard
/// MPM and F-patch.
pub fn stretch(mode: Mode) -> CaseSpec {
    let cells: Vec<usize> = match mode {
        Mode::Quick => vec![1, 2],
        Mode::Full => vec![1, 2, 4, 8],
    };
    let (all, absent) = applicable(|v| v.require_simplex("tetrahedra", true));
    let variants = match mode {
        Mode::Quick => quick(
            all,
            &[
                Variant::default(),
                Variant {
                    locking: LockingKind::FPatch,
                    ..Variant::default()
                },
            ],
        ),
        Mode::Full => all,
    };
    CaseSpec {
        slug: "stretch",
        title: "Simple stretch on tetrahedra".into(),
        about: format!(
            "Wang et al. 2021 §5.3, Table 1 (`mpm_cases::cases::stretch`): a 2 m cube of von \
             Mises material (E = 1 kPa, ν = 0, ρ_y = 400 Pa, perfectly plastic) stretched to \
             twice its height in 5 steps on a mesh that stretches with it, Keast's 11 points \
             per linear tetrahedron, the tetrahedra the children of ten-node parents (the \
             F-patch patches). Tetrahedra run standard MPM or F-patch. Reference: the uniaxial \
             Kirchhoff stress √(3/2) ρ_y; error: the volume-weighted mean of |τ_yy − τ_a|/τ_a. \
             Levels: cells × 2 × cells cubes of six parents each, cells = {} (h = 2/cells m).",
            cells
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        error_name: "mean relative stress error".into(),
        h_name: "the cube edge 2/cells m".into(),
        levels: cells
            .iter()
            .map(|&c| Level {
                label: format!("cells = {c}"),
                n: c,
                h: 2.0 / c as f64,
            })
            .collect(),
        styles: formulation_styles(),
        variants: variants
            .iter()
            .map(|&v| {
                spec(&v, move |l: &Level| {
                    let p = StretchParams {
                        cells: l.n,
                        ..StretchParams::default()
                    };
                    let r =
                        stretch::StretchCase::run(&p, &v, &RunControl::default(), |_, _, _| Ok(()))
                            .map_err(|e| e.to_string())?;
                    Ok(Sample {
                        error: r.error,
                        seconds: r.output.wall_time_s,
                    })
                })
            })
            .collect(),
        absent,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_variants_are_the_ones_dispatch_runs() {
        let (grid, refused) = grid_variants();
        // Standard MPM and the two B-splines (plain and boundary-modified)
        // with and without F-bar, CPDI2, GIMP with each of its 8 rules and
        // with F-bar: 16 families × 2 formulations.
        assert_eq!(
            grid.len(),
            32,
            "{:?}",
            grid.iter().map(label).collect::<Vec<_>>()
        );
        assert!(refused > 0);
        assert!(!grid.iter().any(|v| v.locking == LockingKind::FPatch));
        let (tri, _) = applicable(|v| v.require_standard_mpm("triangles"));
        assert_eq!(tri.len(), 2);
        let (tet, _) = applicable(|v| v.require_simplex("tetrahedra", true));
        assert_eq!(tet.len(), 4);
    }
}
