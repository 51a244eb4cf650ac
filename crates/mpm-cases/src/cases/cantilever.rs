//! Elastic cantilever under an end load (Coombs et al. 2020 §7.3, Figs.
//! 11–17, Table 3): a 10 m × 1 m plane-strain beam, E = 12 MPa, ν = 0.2,
//! a vertical end load of 100 kN applied over 50 equal load steps, split
//! between the two material points closest to the neutral axis at the free
//! end. The neutral axis is pinned at the root and the other grid nodes on
//! the root line are on rollers (horizontal displacement fixed).
//!
//! Outputs: the tip displacement history (mean of the two loaded points)
//! and the Newton residuals of every step (Table 3 shows their asymptotic
//! quadratic convergence).

use mpm_solver::{SolverError, StepReport};
use serde_json::json;

use super::{Built, Case, Measured, Run, Solve, Solved};
use crate::CasesError;
use crate::material::MaterialModel;
use crate::output::CellMesh;
use crate::run::{RunOutput, Snapshot};
use crate::scene::format::{
    Axes, BodySpec, BoundaryKind, BoundarySpec, LoadSpec, MaterialSpec, MeshSpec, NodeSetSpec,
    RegionSpec, SolverSpec,
};
use crate::scene::{Problem, Scene};
use crate::variant::Variant;
use crate::writer::RunWriter;

crate::case_params! {
    /// Parameters of the cantilever case (defaults: the paper's values).
    pub struct CantileverParams {
        /// Cell size h (m); must divide 0.5 m so that a node sits on the
        /// neutral axis.
        pub h: f64 = 0.5,
        /// Material points per cell per direction (even, so that two
        /// points straddle the neutral axis). The paper's Fig. 13 uses 2²,
        /// 4² and 6²; the default 4² avoids the near-mechanisms of 2²: as
        /// the beam deflects, a cell can hold a single point whose far
        /// nodes no other point supports, and the stiffness then has an
        /// isolated eigenvalue of about 1e-15 of the largest (a rotation of
        /// those nodes that strains no point; see docs/src/theory/solver.md).
        pub points_per_cell: usize = 4,
        /// Beam length l₀ (m).
        pub length: f64 = 10.0,
        /// Beam depth d₀ (m).
        pub depth: f64 = 1.0,
        /// Young's modulus (Pa).
        pub youngs_modulus: f64 = 12e6,
        /// Poisson's ratio.
        pub poisson_ratio: f64 = 0.2,
        /// Total end load (N), downwards.
        pub load: f64 = 100e3,
        /// Number of equal load steps.
        pub load_steps: usize = 50,
        /// Newton tolerance on eq. (40).
        pub tolerance: f64 = 1e-9,
    }
}

/// The registered case (see [`crate::cases::Case`]).
#[derive(Debug, Clone, Copy)]
pub struct CantileverCase;

impl Case for CantileverCase {
    const NAME: &'static str = "cantilever";
    const ABOUT: &'static str =
        "Coombs 2020 §7.3: elastic cantilever under an end load (tip history, Newton residuals)";
    type Params = CantileverParams;

    fn scene(p: &CantileverParams, variant: &Variant) -> Result<Scene, SolverError> {
        scene(p, variant)
    }
}

/// The cantilever's result.
#[derive(Debug, Clone)]
pub struct CantileverResult {
    /// The run.
    pub output: RunOutput<2>,
    /// (load factor, tip displacement x, tip displacement y) after each step.
    pub tip: Vec<(f64, f64, f64)>,
    /// Number of material points.
    pub material_points: usize,
}

/// The cantilever as a typed scene (the scene of
/// `scenes/coombs2020_cantilever.toml` with the parameters and variant
/// filled in): a grid with room below for a tip deflection of about the
/// beam length and the padding the basis needs; the root a wall (every
/// node on x = 0 on a roller, so that GIMP and CPDI2 corners near the root
/// stay on it; padding nodes beyond it free) with its neutral-axis node
/// pinned; the end load shared by the two points of the last lattice
/// column that straddle the neutral axis. The points' lattice is anchored
/// at the beam's corner, not at the grid's origin 10 m below, so that
/// their coordinates are (i + ½)·h/n exactly as the beam's own lattice.
///
/// # Errors
/// [`SolverError::InvalidInput`] unless `h` divides half the depth and the
/// length and `points_per_cell` is even.
pub fn scene(p: &CantileverParams, variant: &Variant) -> Result<Scene, SolverError> {
    let half = p.depth / 2.0;
    let k = (half / p.h).round();
    if k < 1.0
        || (k * p.h - half).abs() > 1e-9
        || !p.points_per_cell.is_multiple_of(2)
        || (p.length / p.h).fract().abs() > 1e-9
    {
        return Err(SolverError::InvalidInput(format!(
            "h = {} must divide half the depth ({half}) and the length, and points_per_cell = {} must be even",
            p.h, p.points_per_cell
        )));
    }
    // Room below for a tip deflection of about the beam length.
    let below = (p.length / p.h).ceil() * p.h;
    let cells = [
        ((p.length + 1.0) / p.h).ceil() as usize,
        ((below + p.depth + 0.5) / p.h).ceil() as usize,
    ];
    let (tol, step) = (1e-9 * p.h, p.h / p.points_per_cell as f64);
    let (y_lo, y_hi) = (-below - 2.0 * p.h, p.depth + 2.0 * p.h + 0.5);
    let material = MaterialSpec::new(
        "beam",
        MaterialModel::Hencky,
        p.youngs_modulus,
        p.poisson_ratio,
        0.0,
    );
    let body = BodySpec::block(
        "beam",
        "beam",
        [0.0, 0.0],
        [p.length, p.depth],
        p.points_per_cell,
    )
    .with_lattice_origin([0.0, 0.0]);
    let end = RegionSpec::box_between([p.length - step, half - step], [p.length, half + step]);
    Ok(Scene::new(
        MeshSpec::grid(
            [0.0, -below],
            [cells[0] as f64 * p.h, cells[1] as f64 * p.h],
            cells,
        ),
        vec![material],
        vec![body],
    )
    .with_node_set(NodeSetSpec::inside(
        "root",
        RegionSpec::box_between([-tol, y_lo], [tol, y_hi]),
    ))
    .with_node_set(NodeSetSpec::inside(
        "neutral_axis_at_root",
        RegionSpec::box_between([-tol, half - tol], [tol, half + tol]),
    ))
    .with_boundary(
        BoundarySpec::on("root", BoundaryKind::Displacement)
            .with_displacement(Axes::default().with_x(0.0)),
    )
    .with_boundary(BoundarySpec::on(
        "neutral_axis_at_root",
        BoundaryKind::Fixed,
    ))
    .with_load(LoadSpec::point_in(end, [0.0, -p.load]))
    .with_solver(SolverSpec::implicit(variant, p.load_steps, p.tolerance)))
}

/// The cantilever's scene, built, and the indices of its two loaded
/// points.
impl Built<2> for (Problem<2>, [usize; 2]) {
    /// The two points the end load acts on; an end that does not hold
    /// exactly two points is refused.
    fn read(problem: Problem<2>) -> Result<Self, SolverError> {
        match problem.point_forces.as_slice() {
            [(a, _), (b, _)] => {
                let loaded = [*a, *b];
                Ok((problem, loaded))
            }
            _ => Err(SolverError::InvalidInput(
                "the loaded end must hold two material points".into(),
            )),
        }
    }

    fn problem(&self) -> &Problem<2> {
        &self.0
    }
}

/// The tip displacement: the mean displacement of the two loaded points.
pub fn tip_displacement(snap: &Snapshot, loaded: [usize; 2]) -> (f64, f64) {
    let (a, b) = (&snap.displacement[loaded[0]], &snap.displacement[loaded[1]]);
    (0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]))
}

impl Solve<2> for CantileverCase {
    type Built = (Problem<2>, [usize; 2]);
    type Result = CantileverResult;

    /// Runs the built cantilever, recording the tip after every step.
    fn solve(
        _: &CantileverParams,
        (problem, loaded): &Self::Built,
        Run { control, observer }: Run<'_, 2>,
    ) -> Solved<CantileverResult> {
        let mut tip = Vec::new();
        let output = crate::scene::run(problem, control, |step, report, snap| {
            let (ux, uy) = tip_displacement(snap, *loaded);
            tip.push((report.lambda1, ux, uy));
            observer(step, report, snap)
        })?;
        Ok(CantileverResult {
            output,
            tip,
            material_points: problem.len(),
        })
    }

    fn measured(r: &CantileverResult) -> Measured<'_, 2> {
        let m = Measured::new(&r.output, r.material_points, None);
        match r.tip.last() {
            Some((_, ux, uy)) => m.with([("tip_displacement", json!([ux, uy]))]),
            None => m,
        }
    }

    /// The tip displacement over the length against the load factor, in
    /// `tip.csv`.
    fn case_row<M: CellMesh<2>>(
        p: &CantileverParams,
        (_, loaded): &Self::Built,
        writer: &mut RunWriter<2, M>,
        report: &StepReport<2>,
        snap: &Snapshot,
    ) -> Result<(), CasesError> {
        let (ux, uy) = tip_displacement(snap, *loaded);
        let header = ["load_factor", "tip_u_over_l0", "tip_v_over_l0"];
        let row = [report.lambda1, ux / p.length, uy / p.length];
        writer.case_row("tip.csv", &header, &row.map(Into::into))
    }
}

/// The large-deflection (elastica) solution of an inextensible cantilever
/// under a vertical end load that keeps its direction: the normalised tip
/// displacements $(u/l_0, v/l_0)$ (horizontal, vertical; both negative for
/// a downward load) for the load parameter $\alpha = P l_0^2/(EI)$.
///
/// With $\theta(s)$ the rotation of the centre line at arc length $s$,
/// moment equilibrium of the part beyond $s$ gives
/// $EI\,\theta'(s) = P\,(x(L) - x(s))$, hence
/// $\theta'' = -\alpha\cos\theta$ (in $s/l_0$) with $\theta(0) = 0$ at the
/// clamped root and $\theta'(1) = 0$ at the free tip. The curvature at the
/// root $\kappa_0 = \theta'(0) \in (0, \alpha]$ is found by bisection on
/// $\theta'(1)$ (the map is monotone), integrating $\theta$, $x$, $y$ with
/// classical Runge–Kutta on 4000 steps; then
/// $u = x(1) - 1$ and $v = -\int_0^1\sin\theta\,ds$. This is the classical
/// solution (Bisshopp & Drucker 1945; the "analytical solution" of Coombs
/// et al. 2020 Figs. 13, 15, 17).
pub fn elastica_tip(alpha: f64) -> (f64, f64) {
    if alpha.abs() < f64::MIN_POSITIVE {
        return (0.0, 0.0);
    }
    const STEPS: usize = 4000;
    // State (theta, kappa, x, y) along s in [0, 1].
    let integrate = |kappa0: f64| -> [f64; 4] {
        let rhs = |z: [f64; 4]| [z[1], -alpha * z[0].cos(), z[0].cos(), z[0].sin()];
        let ds = 1.0 / STEPS as f64;
        let mut z = [0.0, kappa0, 0.0, 0.0];
        let axpy = |z: [f64; 4], k: [f64; 4], a: f64| std::array::from_fn(|i| z[i] + a * k[i]);
        for _ in 0..STEPS {
            let k1 = rhs(z);
            let k2 = rhs(axpy(z, k1, ds / 2.0));
            let k3 = rhs(axpy(z, k2, ds / 2.0));
            let k4 = rhs(axpy(z, k3, ds));
            z = std::array::from_fn(|i| {
                z[i] + ds / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        z
    };
    let (mut lo, mut hi) = (0.0, alpha);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if integrate(mid)[1] > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let z = integrate(0.5 * (lo + hi));
    (z[2] - 1.0, -z[3])
}
