//! A 360° rigid rotation, two ways:
//! - through a fixed regular grid: every node is prescribed the rigid
//!   increment $(\mathbf R(\Delta\theta) - \mathbf I)(\mathbf x_v -
//!   \mathbf c)$ of the step, an affine field that every basis reproduces,
//!   so each point receives $\Delta\mathbf F = \mathbf R(\Delta\theta)$
//!   and its domain rule alone decides what happens to its domain — for
//!   every variant the scenes can name (`mpm_cases::variant::dispatch`);
//! - through the moving mesh: a triangle mesh turned rigidly with every
//!   node driven (`[mesh.motion] kind = "rotation"`).
//!
//! Zero initial stress: a rotation must leave it at round-off.

use std::time::Instant;

use mpm_cases::body::InitialDomain;
use mpm_cases::run::DomainBounds;
use mpm_cases::variant::{
    BasisKind, DomainUpdateKind, FormulationKind, GimpVolumeKind, LockingKind, Variant,
    VariantVisitor, dispatch,
};
use mpm_constitutive::HenckyElastic;
use mpm_mesh::RegularGrid;
use mpm_solver::{
    Constraints, DomainUpdater, Flat, Formulation, ImplicitBuilder, LoadStepping, MaterialPoints,
    SolverError,
};
use nalgebra::{Matrix2, Vector2};

use super::{Expect, Mode, Outcome, Row, guarded};

/// Young's modulus of the rotated body.
const YOUNG: f64 = 1e6;

/// Every node prescribed the rigid rotation increment about the origin.
struct RigidRotation {
    nodes: Vec<Vector2<f64>>,
    angle: f64,
}

impl Constraints<2> for RigidRotation {
    fn prescribed(&self, node: usize, component: usize, lambda0: f64, lambda1: f64) -> Option<f64> {
        let t = (lambda1 - lambda0) * self.angle;
        let r = Matrix2::new(t.cos(), -t.sin(), t.sin(), t.cos());
        let x = self.nodes.get(node)?;
        Some(((r - Matrix2::identity()) * x)[component])
    }
}

/// What a rotation run measured.
struct Drift {
    /// Largest |V/V₀ − 1| of the integration volumes over the turn.
    volume: f64,
    /// Largest |V_dom/V_dom,0 − 1| of the domains (`None` without one).
    domain: Option<f64>,
    /// Largest |σ| / E over the turn.
    stress: f64,
    /// Largest |x − X| after the full turn (the body is 1 m wide).
    position: f64,
    iterations: usize,
}

/// The volume of a flattened 2D domain: GIMP's half-lengths (2 numbers)
/// or CPDI2's corners (8 numbers, a parallelogram).
fn domain_volume(flat: &[f64]) -> Option<f64> {
    match flat.len() {
        2 => Some(4.0 * flat[0] * flat[1]),
        8 => {
            let (a, b) = (
                (flat[2] - flat[0], flat[3] - flat[1]),
                (flat[4] - flat[0], flat[5] - flat[1]),
            );
            Some((a.0 * b.1 - a.1 * b.0).abs())
        }
        _ => None,
    }
}

struct Turn {
    steps: usize,
}

impl VariantVisitor<2> for Turn {
    type Output = Result<Drift, SolverError>;

    fn visit<B, F, U>(self, basis: B, updater: U) -> Self::Output
    where
        B: InitialDomain<2, Mesh = RegularGrid<2>, Domain: Flat + DomainBounds<2>>,
        F: Formulation,
        U: DomainUpdater<2, B::Domain>,
    {
        // A 1 m square body centred on the origin, on a grid reaching 1 m
        // beyond its corners' circle; 2 × 2 points per cell.
        let h = 0.125;
        let cells = 32;
        let grid = RegularGrid::new(Vector2::new(-2.0, -2.0), Vector2::new(h, h), [cells, cells])?;
        let nodes = (0..grid.node_count())
            .map(|v| grid.node_position(v))
            .collect::<Result<Vec<_>, _>>()?;
        let per_side = 16;
        let s = 1.0 / per_side as f64;
        let position: Vec<Vector2<f64>> = (0..per_side * per_side)
            .map(|k| {
                Vector2::new(
                    -0.5 + s * (0.5 + (k % per_side) as f64),
                    -0.5 + s * (0.5 + (k / per_side) as f64),
                )
            })
            .collect();
        let half = Vector2::new(0.5 * s, 0.5 * s);
        let domains = position
            .iter()
            .map(|x| B::initial_domain(x, &half))
            .collect();
        let n = position.len();
        let mut points: MaterialPoints<2, (), B::Domain> =
            MaterialPoints::new(position.clone(), vec![s * s; n], 1.0, domains)?;
        let domain0: Vec<Option<f64>> = points
            .domain
            .iter()
            .map(|d| {
                let mut flat = Vec::new();
                d.write(&mut flat);
                domain_volume(&flat)
            })
            .collect();
        let mut solver = ImplicitBuilder::new(basis, grid, HenckyElastic::new(YOUNG, 0.3)?)
            .formulation(F::default())
            .domain_update(updater)
            .constraints(RigidRotation {
                nodes,
                angle: std::f64::consts::TAU,
            })
            .build();
        // The largest deviations over the whole turn, not only at its end
        // (where every rule of the total F is back at F = 1).
        let (mut volume, mut stress, mut domain): (f64, f64, Option<f64>) = (0.0, 0.0, None);
        let summary = solver.run(
            &mut points,
            &LoadStepping::uniform(self.steps),
            |_, _, pts| {
                let mut flat = Vec::new();
                for (p, v0) in domain0.iter().enumerate() {
                    volume = volume.max((pts.volume[p] / (s * s) - 1.0).abs());
                    stress = stress.max(pts.sigma[p].norm() / YOUNG);
                    flat.clear();
                    pts.domain[p].write(&mut flat);
                    if let (Some(v), Some(v0)) = (domain_volume(&flat), *v0) {
                        domain = Some(domain.unwrap_or(0.0).max((v / v0 - 1.0).abs()));
                    }
                }
                Ok(())
            },
        )?;
        let position_error = (0..n)
            .map(|p| (points.position[p] - position[p]).norm())
            .fold(0.0, f64::max);
        Ok(Drift {
            volume,
            domain,
            stress,
            position: position_error,
            iterations: summary.iterations,
        })
    }
}

/// Every grid variant, then the moving triangle mesh.
pub fn rows(mode: Mode) -> Vec<Row> {
    let steps = if mode == Mode::Quick { 72 } else { 360 };
    let mut variants = Vec::new();
    for &update in DomainUpdateKind::ALL {
        let basis = match update {
            DomainUpdateKind::None => continue,
            DomainUpdateKind::Cpdi2 => BasisKind::Cpdi2,
            _ => BasisKind::Gimp,
        };
        variants.push((basis, update));
    }
    variants.push((BasisKind::Linear, DomainUpdateKind::None));
    variants.push((BasisKind::BSpline2, DomainUpdateKind::None));
    let mut rows = Vec::new();
    for (basis, update) in variants {
        for formulation in [FormulationKind::Ul, FormulationKind::Pc] {
            let variant = Variant {
                basis,
                formulation,
                locking: LockingKind::None,
                domain_update: update,
                gimp_volume: GimpVolumeKind::DetF,
            };
            // The volume-corrected diagonal rule divides by the product of
            // F's diagonal, which vanishes at 90° (a documented, typed
            // refusal).
            let expect = if update == DomainUpdateKind::VolumeCorrectedDiagF {
                Expect::Refuse("DomainUpdate")
            } else {
                Expect::Converge
            };
            let mut row = Row::new(
                "rotation",
                format!(
                    "360° through a fixed grid, {steps} steps of {}°",
                    360 / steps
                ),
                format!("{basis}, {formulation}, domain {update}"),
                expect,
            );
            let started = Instant::now();
            let result = guarded(|| {
                dispatch(&variant, Turn { steps }).map_err(SolverError::InvalidInput)?
            });
            row.seconds = started.elapsed().as_secs_f64();
            let (outcome, drift) = Outcome::of(result, |_| 0);
            row.outcome = outcome;
            if let Some(d) = drift {
                row.work = format!("{steps} steps, {} iterations", d.iterations);
                row.measured = format!(
                    "|V/V₀ − 1| {:.1e}, domain {}, |σ|/E {:.1e}, position {:.1e}",
                    d.volume,
                    d.domain.map_or("–".into(), |v| format!("{v:.1e}")),
                    d.stress,
                    d.position
                );
                row.value("volume", d.volume);
                row.value("stress", d.stress);
                row.value("position", d.position);
                if let Some(v) = d.domain {
                    row.value("domain", v);
                }
            }
            rows.push(row);
        }
    }
    for formulation in ["ul", "pc"] {
        let mut row = Row::new(
            "rotation",
            format!("360° by the moving mesh (triangles), {steps} steps"),
            format!("linear, {formulation}"),
            Expect::Converge,
        );
        let text = format!(
            "[mesh]\nkind = \"simplex\"\norigin = [-1.0, -1.0]\nsize = [2.0, 2.0]\ncells = [8, 8]\n\n\
             [mesh.motion]\nkind = \"rotation\"\nangle = {tau:?}\ndriven = \"all\"\n\n\
             [[node_set]]\nname = \"all\"\nregion = {{ box = {{ lower = [-2.0, -2.0], upper = [2.0, 2.0] }} }}\n\n\
             [[material]]\nname = \"m\"\nmodel = \"hencky\"\nyoungs_modulus = {YOUNG:?}\npoisson_ratio = 0.3\ndensity = 1.0\n\n\
             [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = {{ box = {{ lower = [-0.5, -0.5], upper = [0.5, 0.5] }} }}\npoints_per_cell = 2\n\n\
             [solver]\nformulation = \"{formulation}\"\nsteps = {steps}\n\n[output]\nevery = {steps}\n",
            tau = std::f64::consts::TAU
        );
        if let Some(out) = super::run_problem::<2>(&text, &mut row) {
            let last = &out.last;
            let stress = last
                .sigma
                .iter()
                .map(|s| s.iter().map(|x| x * x).sum::<f64>().sqrt() / YOUNG)
                .fold(0.0, f64::max);
            let volume0 = 1.0 / last.volume.len() as f64;
            let volume = last
                .volume
                .iter()
                .map(|v| (v / volume0 - 1.0).abs())
                .fold(0.0, f64::max);
            let position = last
                .displacement
                .iter()
                .map(|u| u.iter().map(|x| x * x).sum::<f64>().sqrt())
                .fold(0.0, f64::max);
            row.measured =
                format!("|V/V₀ − 1| {volume:.1e}, |σ|/E {stress:.1e}, position {position:.1e}");
            row.value("volume", volume);
            row.value("stress", stress);
            row.value("position", position);
        }
        rows.push(row);
    }
    rows
}
