//! The elastic-cube drop of issue 15, shared by `benches/explicit.rs` and
//! `examples/explicit_cube.rs`: a Neo-Hookean cube (E = 1e6, ν = 0.3,
//! ρ = 1000) of side 0.4 in a unit box, 2³ points per cell, quadratic
//! B-splines, Taylor-PIC, slip walls three cells thick, Δt = 0.3 h/c fixed,
//! gravity, f64.

use mpm_basis::QuadraticBSpline;
use mpm_constitutive::{IncrementalLaw, NeoHookean};
use mpm_mesh::RegularGrid;
use mpm_solver::explicit::{PointsFor, VelocityFixities};
use mpm_solver::{ExplicitOptions, ExplicitPoints, ExplicitSolver, NoLocking, Taylor, TimeStep};
use nalgebra::Vector3;

/// The solver of the cube scene.
pub type Solver = ExplicitSolver<3, QuadraticBSpline, NeoHookean, Taylor, NoLocking>;
/// Its points.
pub type Points = PointsFor<3, NeoHookean, Taylor>;

/// The scene on a grid of `n`³ cells.
pub fn cube(n: usize) -> (Solver, Points) {
    let h = 1.0 / n as f64;
    let grid = RegularGrid::new(Vector3::zeros(), Vector3::from_element(h), [n; 3]).expect("grid");
    let per_side = (0.8 * n as f64).round() as usize;
    let d = h / 2.0;
    let lo = 0.5 - 0.5 * per_side as f64 * d;
    let mut x = Vec::with_capacity(per_side.pow(3));
    for k in 0..per_side {
        for j in 0..per_side {
            for i in 0..per_side {
                x.push(Vector3::new(
                    lo + (i as f64 + 0.5) * d,
                    lo + (j as f64 + 0.5) * d,
                    lo + (k as f64 + 0.5) * d,
                ));
            }
        }
    }
    let volume = vec![d * d * d; x.len()];
    let points: Points = ExplicitPoints::new(x, volume, 1000.0).expect("points");
    let law = NeoHookean::new(1e6, 0.3).expect("law");
    let c = (law.p_wave_modulus() / 1000.0).sqrt();
    let mut walls = VelocityFixities::new();
    let nodes = n + 1;
    for axis in 0..3 {
        let near = |i: usize| i < 3 || i > n - 3;
        let ids = (0..nodes.pow(3)).filter(|id| {
            let index = [id % nodes, id / nodes % nodes, id / (nodes * nodes)];
            near(index[axis])
        });
        walls.fix(ids, axis);
    }
    let options = ExplicitOptions {
        time_step: TimeStep::Fixed(0.3 * h / c),
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let solver = ExplicitSolver::new(
        QuadraticBSpline,
        grid,
        law,
        Taylor::PIC,
        NoLocking,
        walls,
        options,
    )
    .expect("solver");
    (solver, points)
}
