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

use mpm_constitutive::HenckyElastic;
use mpm_mesh::RegularGrid;
use mpm_solver::{
    DomainUpdater, Flat, Formulation, LoadStepping, NewtonOptions, NodalConstraints, SolverError,
    StepReport,
};
use nalgebra::SVector;

use crate::body::{Body, InitialDomain};
use crate::run::{DomainBounds, Loads, RunControl, RunOutput, Setup, Snapshot, simulate};
use crate::variant::{Variant, VariantVisitor, dispatch};

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

impl crate::cases::Case for CantileverCase {
    const NAME: &'static str = "cantilever";
    const ABOUT: &'static str =
        "Coombs 2020 §7.3: elastic cantilever under an end load (tip history, Newton residuals)";
    type Params = CantileverParams;

    fn run(
        p: CantileverParams,
        session: &crate::session::Session,
    ) -> Result<(), crate::CasesError> {
        use crate::session::{observer_error, summary};
        let (grid, _, _, loaded) = geometry(&p, p.basis.padding())?;
        let (mut obs, control) = session.start(&p, grid)?;
        let r = run(&p, &p.variant(), &control, |s, rep, snap| {
            // The case table first: the step's checkpoint must hold its row.
            let (ux, uy) = tip_displacement(snap, loaded);
            obs.writer
                .case_row(
                    "tip.csv",
                    &["load_factor", "tip_u_over_l0", "tip_v_over_l0"],
                    &[
                        rep.lambda1.into(),
                        (ux / p.length).into(),
                        (uy / p.length).into(),
                    ],
                )
                .map_err(observer_error)?;
            obs.step(s, rep, snap)
        })?;
        let mut results = serde_json::Map::new();
        if let Some((_, ux, uy)) = r.tip.last() {
            results.insert("tip_displacement".into(), serde_json::json!([ux, uy]));
        }
        let s = summary(
            Self::NAME,
            p.variant(),
            r.material_points,
            &r.output,
            None,
            results,
            &p,
        );
        obs.finish(s)
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

/// Grid, body, root constraints and the indices of the two loaded points.
pub fn geometry(
    p: &CantileverParams,
    pad: usize,
) -> Result<(RegularGrid<2>, Body<2>, NodalConstraints<2>, [usize; 2]), SolverError> {
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
    let padf = pad as f64 * p.h;
    // Room below for a tip deflection of about the beam length.
    let below = (p.length / p.h).ceil() * p.h;
    let grid = RegularGrid::new(
        SVector::<f64, 2>::new(-padf, -below - padf),
        SVector::<f64, 2>::new(p.h, p.h),
        [
            ((p.length + 1.0) / p.h).ceil() as usize + 2 * pad,
            ((below + p.depth + 0.5) / p.h).ceil() as usize + 2 * pad,
        ],
    )
    .map_err(SolverError::from)?;
    let body = Body::fill_box(
        &grid,
        &SVector::<f64, 2>::zeros(),
        &SVector::<f64, 2>::new(p.length, p.depth),
        p.points_per_cell,
    );
    let mut constraints = NodalConstraints::<2>::new(grid.node_count());
    let tol = 1e-9 * p.h;
    for n in 0..grid.node_count() {
        let x = grid.node_position(n).map_err(SolverError::from)?;
        // The root is a wall: every grid node on it is on a roller (CPDI2
        // and GIMP corners near the root then stay on it), the neutral
        // axis is pinned.
        if x[0].abs() <= tol {
            constraints.fix([n], 0);
            if (x[1] - half).abs() <= tol {
                constraints.fix([n], 1);
            }
        }
    }
    let [nx, ny] = body.lattice_size;
    let loaded = |row: usize| {
        body.lattice
            .iter()
            .position(|l| l[0] == nx - 1 && l[1] == row)
    };
    let (a, b) = (loaded(ny / 2 - 1), loaded(ny / 2));
    match (a, b) {
        (Some(a), Some(b)) => Ok((grid, body, constraints, [a, b])),
        _ => Err(SolverError::InvalidInput(
            "no material points at the loaded end".into(),
        )),
    }
}

/// The tip displacement: the mean displacement of the two loaded points.
pub fn tip_displacement(snap: &Snapshot, loaded: [usize; 2]) -> (f64, f64) {
    let (a, b) = (&snap.displacement[loaded[0]], &snap.displacement[loaded[1]]);
    (0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]))
}

struct CantileverRun<'a, O> {
    params: &'a CantileverParams,
    control: &'a RunControl,
    observer: O,
}

impl<O> VariantVisitor<2> for CantileverRun<'_, O>
where
    O: FnMut(usize, &StepReport<2>, &Snapshot) -> Result<(), SolverError>,
{
    type Output = Result<CantileverResult, SolverError>;

    fn visit<B, F, U>(self, basis: B, updater: U) -> Self::Output
    where
        B: InitialDomain<2, Mesh = RegularGrid<2>, Domain: Flat + DomainBounds<2>>,
        F: Formulation,
        U: DomainUpdater<2, B::Domain>,
    {
        let p = self.params;
        let (grid, body, constraints, loaded) = geometry(p, B::PADDING)?;
        let law =
            HenckyElastic::new(p.youngs_modulus, p.poisson_ratio).map_err(SolverError::from)?;
        let force = SVector::<f64, 2>::new(0.0, -p.load / 2.0);
        let setup = Setup {
            grid,
            body: &body,
            density: 0.0,
            law,
            loads: Loads {
                gravity: None,
                point_forces: vec![(loaded[0], force), (loaded[1], force)],
                body_force_path: None,
            },
            constraints,
            stepping: LoadStepping::uniform(p.load_steps),
            newton: NewtonOptions {
                tolerance: p.tolerance,
                ..NewtonOptions::default()
            },
        };
        let mut tip = Vec::new();
        let mut observer = self.observer;
        let output = simulate::<2, B, F, U, _, _, _>(
            setup,
            basis,
            updater,
            self.control,
            |step, report, snap| {
                let (ux, uy) = tip_displacement(snap, loaded);
                tip.push((report.lambda1, ux, uy));
                observer(step, report, snap)
            },
        )?;
        Ok(CantileverResult {
            output,
            tip,
            material_points: body.len(),
        })
    }
}

/// Runs the cantilever with `variant`.
pub fn run<O>(
    params: &CantileverParams,
    variant: &Variant,
    control: &RunControl,
    observer: O,
) -> Result<CantileverResult, SolverError>
where
    O: FnMut(usize, &StepReport<2>, &Snapshot) -> Result<(), SolverError>,
{
    dispatch(
        variant,
        CantileverRun {
            params,
            control,
            observer,
        },
    )
    .map_err(SolverError::InvalidInput)?
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
