//! Simple shear of a unit square (Coombs et al. 2020 §7.2, Figs. 9–10),
//! elastic and elasto-plastic: $x = X + \gamma Y$, $F = [[1, \gamma], [0,
//! 1]]$, with the top face sheared by Δl = 6 m over 30 equal
//! displacement-controlled steps; E = 10 kPa, ν = 0.3, ϱ₀ = 0 and, when
//! plastic, von Mises with ρ_y = 5 kPa.
//!
//! Defaults follow Fig. 10: h = 0.125 m and 3² points per cell. With 2²
//! points per cell standard MPM loses equilibrium iterations near γ ≈ 4:
//! nodes that leave the prescribed boundary cells are supported by a
//! handful of points, and their small stiffness lets Newton corrections
//! overshoot (see the solver's backtracking).
//!
//! The homogeneous field is an exact discrete equilibrium because the
//! points of each lattice row are evenly spaced, so their sums of basis
//! gradients over a node's support cancel — except for the standard (linear)
//! basis when a point sits exactly on a node line, where the gradient
//! jumps and the cell chosen by rounding breaks the balance. With a
//! grid-aligned body and Δγ = 0.2 per step that happens exactly at
//! γ = 0.2 (x = X + γY hits h-multiples), and the solution departs from
//! homogeneity by ~1e-3 and then drifts. The grid is therefore shifted by
//! a non-commensurate fraction of h (`grid_offset`), which removes the
//! exact ties without changing the problem.
//!
//! The shearing is imposed, as in the paper, on every node that supports a
//! boundary point (its basis stencil at the start of the step: for standard
//! MPM the nodes of the cells holding the body's boundary points, for GIMP,
//! CPDI2 and B-splines every node their domain or support reaches), so that
//! each free node's support lies inside the body:
//! $\Delta u_x = \Delta\gamma\,Y_v$, $\Delta u_y = 0$ at node height $Y_v$;
//! the nodes inside are free.
//!
//! Reference: the deformation is homogeneous, so every point must carry
//! the stress of a single material point driven through the same
//! increments ([`SinglePoint`]). Elastically that is the closed form
//! $\sigma_{11} = -\sigma_{22} = 2\mu\,\mathrm{asinh}(\gamma/2)\gamma/\sqrt{\gamma^2+4}$,
//! $\sigma_{12} = 2\mu\,\mathrm{asinh}(\gamma/2)\,2/\sqrt{\gamma^2+4}$
//! (derived in the constitutive crate's tests); plastically it is the
//! constitutive driver integrated step by step.

use mpm_constitutive::{
    HenckyElastic, LogStrainLaw, MaterialState, VonMises, tensor::embed, update,
};
use mpm_solver::{Flat, SolverError};
use nalgebra::{Matrix2, Matrix3};

use super::{Case, Measured, Run, Solve, Solved};
use crate::material::MaterialModel;
use crate::run::{Checkpoint, RunOutput};
use crate::scene::format::{
    BodySpec, BoundaryKind, BoundarySpec, MaterialSpec, MeshSpec, NodeSetSpec, SolverSpec,
};
use crate::scene::{Problem, Scene};
use crate::variant::Variant;

crate::case_params! {
    /// Parameters of the shear case (defaults: the paper's values).
    pub struct ShearParams {
        /// Cell size h (m).
        pub h: f64 = 0.125,
        /// Material points per cell per direction.
        pub points_per_cell: usize = 3,
        /// Young's modulus (Pa).
        pub youngs_modulus: f64 = 10e3,
        /// Poisson's ratio.
        pub poisson_ratio: f64 = 0.3,
        /// Deviatoric yield stress ρ_y (Pa); absent: elastic.
        pub yield_stress: Option<f64> = None,
        /// Final shear displacement of the top face Δl (m) of the unit square.
        pub shear: f64 = 6.0,
        /// Number of equal load steps.
        pub load_steps: usize = 30,
        /// Newton tolerance on eq. (40).
        pub tolerance: f64 = 1e-9,
        /// Shift of the grid to the left of the body, as a fraction of h.
        pub grid_offset: f64 = 0.123_456_789,
        /// Start each step from the previous increment (the solver's secant
        /// predictor). Needed for the perfectly plastic case: at first yield
        /// the discrete equations also admit localised solutions, and Newton
        /// started from zero increments at the free nodes finds one.
        pub predictor: bool = true,
    }
}

/// The registered case (see [`crate::cases::Case`]).
#[derive(Debug, Clone, Copy)]
pub struct ShearCase;

impl Case for ShearCase {
    const NAME: &'static str = "shear";
    const ABOUT: &'static str = "Coombs 2020 §7.2: simple shear of a unit square, elastic or perfectly plastic (homogeneous)";
    type Params = ShearParams;

    fn scene(p: &ShearParams, variant: &Variant) -> Result<Scene, SolverError> {
        scene(p, variant)
    }
}

/// The shear's result.
#[derive(Debug, Clone)]
pub struct ShearResult {
    /// The run.
    pub output: RunOutput<2>,
    /// Largest relative stress error over points and steps,
    /// $\max\|\sigma_p - \sigma_{ref}\|/\|\sigma_{ref}\|$.
    pub error: f64,
    /// Number of material points.
    pub material_points: usize,
}

/// One material point driven through the shear increments: the reference
/// of a homogeneous deformation.
#[derive(Debug, Clone)]
pub struct SinglePoint<L: LogStrainLaw> {
    law: L,
    f: Matrix3<f64>,
    state: MaterialState<L::History>,
}

impl<L: LogStrainLaw> SinglePoint<L>
where
    L::History: Flat,
{
    /// The state as numbers: F, b^e, history.
    fn save(&self, out: &mut Vec<f64>) {
        self.f.write(out);
        self.state.be.write(out);
        self.state.history.write(out);
    }

    /// Restores [`Self::save`]'s numbers.
    fn restore(&mut self, from: &[f64]) -> Result<(), SolverError> {
        if from.len() != 18 + L::History::LEN {
            return Err(SolverError::InvalidInput(format!(
                "the checkpoint's shear reference has {} numbers, expected {}",
                from.len(),
                18 + L::History::LEN
            )));
        }
        self.f = Matrix3::read(&from[..9]);
        self.state.be = Matrix3::read(&from[9..18]);
        self.state.history = L::History::read(&from[18..]);
        Ok(())
    }
}

impl<L: LogStrainLaw> SinglePoint<L> {
    /// An unstrained point.
    pub fn new(law: L) -> Self {
        Self {
            law,
            f: Matrix3::identity(),
            state: MaterialState::default(),
        }
    }

    /// Applies the shear increment `dgamma` and returns the Cauchy stress.
    pub fn shear(&mut self, dgamma: f64) -> Result<Matrix3<f64>, SolverError> {
        let df = embed(&Matrix2::new(1.0, dgamma, 0.0, 1.0));
        let r = update(&self.law, &df, &self.f, &self.state).map_err(SolverError::from)?;
        self.f = r.f;
        self.state = r.state;
        Ok(r.sigma)
    }
}

/// The closed-form elastic Cauchy stress of Hencky simple shear.
pub fn elastic_closed_form(mu: f64, gamma: f64) -> Matrix3<f64> {
    let a = (gamma / 2.0).asinh();
    let root = (gamma * gamma + 4.0).sqrt();
    let (s11, s12) = (2.0 * mu * a * gamma / root, 2.0 * mu * a * 2.0 / root);
    Matrix3::new(s11, s12, 0.0, s12, -s11, 0.0, 0.0, 0.0, 0.0)
}

/// The shear as a typed scene (the scene of `scenes/coombs2020_shear.toml` with
/// the parameters and variant filled in): an h-spaced grid shifted left of
/// the body by `grid_offset`·h, with room for the shear and the padding the
/// basis needs; the unit square's points on a lattice anchored at its
/// corner; $\Delta u = \Delta\gamma\,(Y_v, 0)$ on every node that
/// supports a boundary point, found again every step (`around`).
///
/// # Errors
/// [`SolverError::InvalidInput`] unless `h` divides 1 and `grid_offset`
/// lies in [0, 1).
pub fn scene(p: &ShearParams, variant: &Variant) -> Result<Scene, SolverError> {
    let cells = (1.0 / p.h).round();
    if cells < 1.0 || (cells * p.h - 1.0).abs() > 1e-9 {
        return Err(SolverError::InvalidInput(format!(
            "h = {} must divide 1",
            p.h
        )));
    }
    if !(0.0..1.0).contains(&p.grid_offset) {
        return Err(SolverError::InvalidInput(format!(
            "grid_offset = {} must lie in [0, 1)",
            p.grid_offset
        )));
    }
    let nx = ((1.0 + p.shear.abs()) / p.h).ceil() as usize + 2;
    let ny = cells as usize;
    let left = if p.shear < 0.0 {
        p.shear.abs() + p.h
    } else {
        0.0
    };
    let model = match p.yield_stress {
        Some(_) => MaterialModel::VonMises,
        None => MaterialModel::Hencky,
    };
    let material = MaterialSpec::new("square", model, p.youngs_modulus, p.poisson_ratio, 0.0);
    let material = match p.yield_stress {
        Some(y) => material.with_yield_stress(y),
        None => material,
    };
    let body = BodySpec::block(
        "square",
        "square",
        [0.0, 0.0],
        [1.0, 1.0],
        p.points_per_cell,
    )
    .with_lattice_origin([0.0, 0.0]);
    Ok(Scene::new(
        MeshSpec::grid(
            [-p.grid_offset * p.h - left, 0.0],
            [nx as f64 * p.h, ny as f64 * p.h],
            [nx, ny],
        ),
        vec![material],
        vec![body],
    )
    .with_node_set(NodeSetSpec::around("shell", "square"))
    .with_boundary(
        BoundarySpec::on("shell", BoundaryKind::Displacement)
            .with_gradient(vec![vec![0.0, p.shear], vec![0.0, 0.0]]),
    )
    .with_solver(
        SolverSpec::implicit(variant, p.load_steps, p.tolerance).with_predictor(p.predictor),
    ))
}

impl Solve<2> for ShearCase {
    type Built = Problem<2>;
    type Result = ShearResult;

    /// Runs the built shear, every point's stress measured against the
    /// single-point reference of its law.
    fn solve(p: &ShearParams, problem: &Problem<2>, run: Run<'_, 2>) -> Solved<ShearResult> {
        match p.yield_stress {
            None => {
                let law = HenckyElastic::new(p.youngs_modulus, p.poisson_ratio)?;
                with_reference(p, problem, run, law)
            }
            Some(y) => {
                let law = VonMises::new(p.youngs_modulus, p.poisson_ratio, y, 0.0)?;
                with_reference(p, problem, run, law)
            }
        }
    }

    fn measured(r: &ShearResult) -> Measured<'_, 2> {
        Measured::new(&r.output, r.material_points, Some(r.error))
    }
}

fn with_reference<L>(
    p: &ShearParams,
    problem: &Problem<2>,
    Run { control, observer }: Run<'_, 2>,
    law: L,
) -> Solved<ShearResult>
where
    L: LogStrainLaw,
    L::History: Flat,
{
    let mut reference = SinglePoint::new(law);
    // On resume: the largest error so far and the reference's state.
    let mut error = 0.0f64;
    if let Some(c) = &control.resume {
        let (first, rest) = c.case_state.split_first().ok_or_else(|| {
            SolverError::InvalidInput("the checkpoint has no shear reference".into())
        })?;
        error = *first;
        reference.restore(rest)?;
    }
    let output = crate::scene::run(problem, control, |step, report, snap| {
        // The reference follows the increments actually taken (a cut step
        // changes the plastic path).
        let sigma_ref = reference.shear(p.shear * (report.lambda1 - report.lambda0))?;
        for s in &snap.sigma {
            let sigma = Matrix3::from_row_slice(s);
            error = error.max((sigma - sigma_ref).norm() / sigma_ref.norm());
        }
        match &snap.checkpoint {
            Some(c) => {
                let mut case_state = vec![error];
                reference.save(&mut case_state);
                let mut snap = snap.clone();
                snap.checkpoint = Some(Checkpoint {
                    case_state,
                    ..c.clone()
                });
                observer(step, report, &snap)
            }
            None => observer(step, report, snap),
        }
    })?;
    Ok(ShearResult {
        output,
        error,
        material_points: problem.len(),
    })
}
