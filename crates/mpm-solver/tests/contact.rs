//! The implicit solver's rigid-tool contact (`mpm_solver::contact`): the
//! assembled stiffness with a frictional tool in stick, in slip and smooth
//! is the derivative of the assembled residual (central differences, the
//! check of `stiffness.rs`), and a tool's force is reported as a reaction.
#![allow(clippy::unwrap_used)]

use super::common;

use mpm_basis::LinearMpm;
use mpm_constitutive::{HenckyElastic, LogStrainLaw, VonMises};
use mpm_mesh::RegularGrid;
use mpm_solver::{
    Constraints, ImplicitSolver, LoadStepping, MaterialPoints, NewtonOptions, NoLocking, NoUpdate,
    NodalConstraints, Parts, PreviouslyConverged, RigidTool,
};
use nalgebra::SVector;

/// Nodal conditions plus rigid tools moving linearly with the load
/// factor (`motion[k]` at λ = 1).
struct WithTools<const D: usize> {
    nodal: NodalConstraints<D>,
    tools: Vec<RigidTool<D>>,
    motion: Vec<SVector<f64, D>>,
}

impl<const D: usize> Constraints<D> for WithTools<D> {
    fn prescribed(&self, node: usize, component: usize, lambda0: f64, lambda1: f64) -> Option<f64> {
        self.nodal.prescribed(node, component, lambda0, lambda1)
    }

    fn tools(&self) -> &[RigidTool<D>] {
        &self.tools
    }

    fn tool_increment(&self, tool: usize, lambda0: f64, lambda1: f64) -> SVector<f64, D> {
        self.motion[tool] * (lambda1 - lambda0)
    }
}

/// The solver of these tests under law `L`.
type Solver<L> =
    ImplicitSolver<2, Parts<LinearMpm, PreviouslyConverged, L, NoLocking, NoUpdate, WithTools<2>>>;

/// A 2D body of 6 × 6 jittered points on a 3 × 3 grid (h = 0.5), the
/// base fixed, a tool with normal −y on the top nodes moving by `motion`
/// over the step, friction `mu`.
fn body_with_tool<L: LogStrainLaw>(
    law: L,
    mu: f64,
    motion: SVector<f64, 2>,
) -> (Solver<L>, MaterialPoints<2, L::History, ()>, Vec<usize>) {
    let h = 0.5;
    let grid = RegularGrid::new(SVector::zeros(), SVector::from_element(h), [3, 3]).unwrap();
    let mut pos = Vec::new();
    for flat in 0..36usize {
        let (i, j) = (flat % 6, flat / 6);
        let jitter = |k: usize| 0.07 * ((flat * 7 + k * 13) as f64).sin();
        pos.push(SVector::<f64, 2>::new(
            (i as f64 + 0.5 + jitter(0)) * h / 2.0,
            (j as f64 + 0.5 + jitter(1)) * h / 2.0,
        ));
    }
    let points =
        MaterialPoints::new(pos, vec![(h / 2.0).powi(2); 36], 1000.0, vec![(); 36]).unwrap();
    let mut nodal = NodalConstraints::<2>::new(grid.node_count());
    let mut top = Vec::new();
    for n in 0..grid.node_count() {
        let x = grid.node_position(n).unwrap();
        if x[1] <= 1e-12 {
            nodal.fix([n], 0);
            nodal.fix([n], 1);
        }
        if x[1] >= 1.5 - 1e-12 {
            top.push(n);
        }
    }
    let tool = RigidTool {
        name: "platen".into(),
        nodes: top.clone(),
        normal: SVector::<f64, 2>::new(0.0, -1.0),
        friction: mu,
        normal_stiffness: None,
        tangential_stiffness: None,
    };
    let constraints = WithTools {
        nodal,
        tools: vec![tool],
        motion: vec![motion],
    };
    let options = NewtonOptions {
        weak_node_threshold: 0.0,
        ..NewtonOptions::default()
    };
    let solver = ImplicitSolver::new(
        LinearMpm,
        grid,
        law,
        NoLocking,
        NoUpdate,
        constraints,
        options,
    );
    (solver, points, top)
}

/// The worst column error of the assembled stiffness at a random free
/// increment of amplitude 0.02 with the tool moved by (0.05, −0.05): the
/// top nodes' relative motion is then (−0.07…−0.03, 0.03…0.07), in
/// contact everywhere; μ = 0.3 slips every node (|d_x| ≥ 0.03 > 0.3 ×
/// 0.07), μ = 3 sticks every node (0.07 < 3 × 0.03), μ = 0 is smooth.
fn worst_error<L: LogStrainLaw>(law: L, mu: f64) -> f64 {
    let (mut solver, points, _) = body_with_tool(law, mu, SVector::<f64, 2>::new(0.05, -0.05));
    let n = solver.prepare_step(&points, 0.0, 1.0).unwrap();
    let du: Vec<f64> = (0..n).map(|k| 0.02 * ((k * 31 + 7) as f64).sin()).collect();
    let k = solver.free_stiffness_dense(&points, &du).unwrap();
    // The slip tangent is not symmetric, and the assembly keeps it so.
    let asym = (0..n)
        .flat_map(|c| (0..n).map(move |r| (r, c)))
        .map(|(r, c)| (k[c * n + r] - k[r * n + c]).abs())
        .fold(0.0, f64::max);
    if mu > 0.0 && mu < 1.0 {
        assert!(asym > 1.0, "slip tangent symmetric: {asym:e}");
    }
    common::worst_column_error(&mut solver, &points, &du, &k)
}

/// Bound 1e-6 as `stiffness.rs`: every node stays in its regime under the
/// difference step 1e-6 (its margin to the cone and to separation is of
/// order 0.01), so the residual is smooth there.
#[test]
fn the_stiffness_with_a_tool_in_stick_and_slip_is_the_residuals_derivative() {
    let elastic = HenckyElastic::new(1e5, 0.3).unwrap();
    let plastic = VonMises::new(1e5, 0.3, 2e2, 1e3).unwrap();
    let errors = [
        worst_error(elastic, 0.3),
        worst_error(elastic, 3.0),
        worst_error(elastic, 0.0),
        worst_error(plastic, 0.3),
        worst_error(plastic, f64::INFINITY),
    ];
    println!("contact stiffness errors (slip, stick, smooth, plastic slip, rough): {errors:?}");
    for e in errors {
        assert!(e <= 1e-6, "relative error {e:e}");
    }
}

/// A smooth platen pressed 1 % into the elastic block: equilibrium holds,
/// the platen's force is the reaction on its nodes, and it balances the
/// base's reaction (no gravity: the body is weightless).
#[test]
fn a_tools_force_is_a_reaction_that_balances_the_base() {
    let elastic = HenckyElastic::new(1e5, 0.3).unwrap();
    let (mut solver, mut points, top) =
        body_with_tool(elastic, 0.0, SVector::<f64, 2>::new(0.0, -0.015));
    points.mass.iter_mut().for_each(|m| *m = 0.0);
    let stepping = LoadStepping::uniform(3);
    let mut last = None;
    solver
        .run(&mut points, &stepping, |_, report, _| {
            last = Some(report.clone());
            Ok(())
        })
        .unwrap();
    let report = last.unwrap();
    let platen = report.reaction_on(&top);
    // The platen pushes down on the body; the base pushes back up. The
    // reactions of all supports sum to the (zero) external force within
    // the Newton tolerance.
    assert!(platen[1] < 0.0, "platen force {platen:?}");
    let total = report.reaction;
    assert!(
        total.norm() <= 1e-6 * platen.norm(),
        "unbalanced reactions {total:?} against {platen:?}"
    );
}
