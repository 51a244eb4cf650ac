//! The explicit solver's reference problems
//! (`mpm_solver::explicit::verification`): the vibrating bar against its
//! first mode, by basis, transfer and end treatment, and the colliding
//! disks' energy drift by transfer.

use std::time::Instant;

use mpm_basis::{BasisFunction, BoundaryBSpline, Cpdi2, Gimp, LinearMpm, QuadraticBSpline};
use mpm_mesh::RegularGrid;
use mpm_solver::explicit::Transfer;
use mpm_solver::explicit::verification::{colliding_disks, fixed_end_bar, vibrating_bar_with};
use mpm_solver::{
    ConvectedCorners, CornerMidpoint, DomainUpdater, Flip, FlipPic, NoUpdate, Pic, SolverError,
    StretchU, Taylor,
};

use super::Mode;
use super::study::{CaseSpec, Level, Sample, VariantSpec};

/// The blend of FLIP and PIC the report runs.
const BLEND: FlipPic = FlipPic { alpha: 0.99 };

/// The transfers, with their names.
fn transfers() -> [(&'static str, TransferKind); 5] {
    [
        ("PIC", TransferKind::Pic),
        ("FLIP", TransferKind::Flip),
        ("FLIP-PIC α = 0.99", TransferKind::Blend),
        ("Taylor-PIC", TransferKind::TaylorPic),
        ("Taylor-FLIP", TransferKind::TaylorFlip),
    ]
}

/// A transfer chosen at run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TransferKind {
    Pic,
    Flip,
    Blend,
    TaylorPic,
    TaylorFlip,
}

/// Runs `f` with the transfer `kind` names.
trait WithTransfer {
    type Output;
    fn with<T: Transfer<2>>(self, transfer: T) -> Self::Output;
}

fn with_transfer<W: WithTransfer>(kind: TransferKind, w: W) -> W::Output {
    match kind {
        TransferKind::Pic => w.with(Pic),
        TransferKind::Flip => w.with(Flip),
        TransferKind::Blend => w.with(BLEND),
        TransferKind::TaylorPic => w.with(Taylor::PIC),
        TransferKind::TaylorFlip => w.with(Taylor::FLIP),
    }
}

/// Times `f`, a whole reference-problem call.
fn timed<T>(f: impl FnOnce() -> Result<T, SolverError>) -> Result<(T, f64), String> {
    let started = Instant::now();
    let value = f().map_err(|e| e.to_string())?;
    Ok((value, started.elapsed().as_secs_f64()))
}

/// The free–free bar (the symmetric half of a bar of 2L) with basis `B`
/// and domain update `R` at `cells` cells over 2L.
struct FreeBar<B, R> {
    basis: B,
    rule: R,
    cells: usize,
}

impl<B, R> WithTransfer for FreeBar<B, R>
where
    B: BasisFunction<2, Mesh = RegularGrid<2>>,
    R: DomainUpdater<2, B::Domain>,
{
    type Output = Result<Sample, String>;

    fn with<T: Transfer<2>>(self, transfer: T) -> Self::Output {
        let (bar, seconds) = timed(|| {
            vibrating_bar_with(
                self.basis, self.rule, transfer, self.cells, BAR_CFL, 1.0, BAR_V0,
            )
        })?;
        Ok(Sample {
            error: bar.error,
            seconds,
        })
    }
}

/// CFL factor and velocity amplitude of the bar runs: those of
/// `fixed_end_bar`, so that both ends compare (the time error below the
/// spatial one, the linear regime).
const BAR_CFL: f64 = 0.02;
const BAR_V0: f64 = 1e-4;

/// Half the bar's 2L: the length L of the fixed-end bar.
const BAR_L: f64 = 25.0;

/// A free–free bar variant with `basis`, its domain update `rule` and the
/// transfer `kind`.
fn free_bar<B, R>(
    basis_name: &str,
    basis: B,
    rule: R,
    (name, kind): (&str, TransferKind),
) -> VariantSpec
where
    B: BasisFunction<2, Mesh = RegularGrid<2>> + Copy + 'static,
    R: DomainUpdater<2, B::Domain> + Copy + 'static,
{
    VariantSpec::new(
        format!("mirrored end, {basis_name}, {name}"),
        Box::new(move |l: &Level| {
            with_transfer(
                kind,
                FreeBar {
                    basis,
                    rule,
                    cells: 2 * l.n,
                },
            )
        }),
    )
}

/// A fixed-end bar variant (FLIP, the only transfer `fixed_end_bar` runs).
fn fixed_bar<B>(basis_name: &str, basis: B) -> VariantSpec
where
    B: BasisFunction<2, Domain = (), Mesh = RegularGrid<2>> + Copy + 'static,
{
    VariantSpec::new(
        format!("fixed end, {basis_name}, FLIP"),
        Box::new(move |l: &Level| {
            let (error, seconds) = timed(|| fixed_end_bar(basis, l.n))?;
            Ok(Sample { error, seconds })
        }),
    )
}

/// The axially vibrating bar.
pub fn bar(mode: Mode) -> CaseSpec {
    let ns: Vec<usize> = match mode {
        Mode::Quick => vec![5, 10],
        Mode::Full => vec![5, 10, 20, 40, 80],
    };
    let mut variants = Vec::new();
    for t in transfers() {
        variants.push(free_bar("linear", LinearMpm, NoUpdate, t));
        variants.push(free_bar(
            "quadratic B-spline",
            QuadraticBSpline,
            NoUpdate,
            t,
        ));
    }
    // The bases with domains, with FLIP: the transfer acts on them as on
    // the others.
    let flip = ("FLIP", TransferKind::Flip);
    variants.push(free_bar("GIMP (eq. 34)", Gimp, StretchU, flip));
    variants.push(free_bar("GIMP (eq. 37)", Gimp, CornerMidpoint, flip));
    variants.push(free_bar("CPDI2", Cpdi2, ConvectedCorners, flip));
    variants.push(fixed_bar("linear", LinearMpm));
    variants.push(fixed_bar("quadratic B-spline", QuadraticBSpline));
    variants.push(fixed_bar("boundary B-spline", BoundaryBSpline));
    if mode == Mode::Quick {
        variants.retain(|v| {
            v.label == "mirrored end, quadratic B-spline, FLIP"
                || v.label == "fixed end, boundary B-spline, FLIP"
        });
    }
    CaseSpec {
        slug: "bar",
        title: "Vibrating bar".into(),
        about: format!(
            "`mpm_solver::explicit::verification`: a bar of length L = {BAR_L}, E = 100, ρ = 1, \
             ν = 0, fixed at x = 0 and free at x = L, started in its first mode with velocity \
             amplitude {BAR_V0} (linear regime), one period at CFL factor {BAR_CFL}, 2 × 2 points \
             per cell, Neo-Hookean. \"Mirrored end\": the symmetric half of a free–free bar of \
             2L (`vibrating_bar`; no boundary condition enters, twice the cells and points); \
             \"fixed end\": the end held by a velocity fixity (`fixed_end_bar`, FLIP only; the \
             boundary-modified B-spline is interpolatory there, the plain one fixes the end and \
             the padding node). Bases: linear, quadratic B-spline, boundary-modified B-spline \
             (fixed end only, where it differs from the plain one), and with FLIP GIMP (half-lengths \
             h/4, updated by eq. 34 or the corner midpoint rule of eq. 37) and CPDI2 (convected \
             corners). Transfers: PIC, FLIP, the blend α = 0.99, Taylor-PIC and Taylor-FLIP. Reference: u = (v₀/ω) sin ωt sin βx; \
             error: the RMS of the point displacements against it at 8 instants, relative to \
             the amplitude. Levels: n cells over L, n = {} (h = {BAR_L}/n).",
            ns.iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        error_name: "RMS displacement error / amplitude".into(),
        h_name: format!("the cell size {BAR_L}/n"),
        levels: ns
            .iter()
            .map(|&n| Level {
                label: format!("n = {n}"),
                n,
                h: BAR_L / n as f64,
            })
            .collect(),
        styles: Vec::new(),
        variants,
        absent: 0,
    }
}

/// The disks with the transfer of [`with_transfer`] at `cells` cells.
struct Disks {
    cells: usize,
}

/// The disks' end time.
const DISKS_END: f64 = 4.0;

impl WithTransfer for Disks {
    type Output = Result<Sample, String>;

    fn with<T: Transfer<2>>(self, transfer: T) -> Self::Output {
        let ((history, _), seconds) = timed(|| colliding_disks(transfer, self.cells, DISKS_END))?;
        let (Some(first), Some(last)) = (history.first(), history.last()) else {
            return Err("no energy samples".into());
        };
        Ok(Sample {
            error: (last[3] / first[3] - 1.0).abs(),
            seconds,
        })
    }
}

/// Sulsky's colliding disks: the total energy's drift.
pub fn disks(mode: Mode) -> CaseSpec {
    let ns: Vec<usize> = match mode {
        Mode::Quick => vec![10, 20],
        Mode::Full => vec![10, 20, 40, 80],
    };
    let mut variants: Vec<VariantSpec> = transfers()
        .into_iter()
        .map(|(name, kind)| {
            VariantSpec::new(
                name,
                Box::new(move |l: &Level| with_transfer(kind, Disks { cells: l.n })),
            )
        })
        .collect();
    if mode == Mode::Quick {
        variants.retain(|v| v.label == "FLIP");
    }
    CaseSpec {
        slug: "disks",
        title: "Colliding disks".into(),
        about: format!(
            "Sulsky, Chen & Schreyer 1995 §5 (`colliding_disks`): two Neo-Hookean disks (E = 1000, \
             ν = 0.3, ρ = 1000, radius 0.2) in the unit square meet head-on at ±(0.1, 0.1), \
             quadratic B-splines, 2 × 2 points per cell, CFL 0.5, t = 0 to {DISKS_END}. \
             Reference: the conservation of energy (no contact algorithm: the disks touch \
             through the grid); error: |E(t = {DISKS_END})/E(0) − 1|, the total (kinetic + \
             strain) energy's drift. Variants: the transfers. Levels: n cells across, n = {} \
             (h = 1/n).",
            ns.iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        error_name: "|energy drift| at t = 4".into(),
        h_name: "the cell size 1/n".into(),
        levels: ns
            .iter()
            .map(|&n| Level {
                label: format!("n = {n}"),
                n,
                h: 1.0 / n as f64,
            })
            .collect(),
        styles: Vec::new(),
        variants,
        absent: 0,
    }
}
