//! The self-weight column of Coombs et al. 2020 §7.1 (50 m, E = 1 MPa,
//! ν = 0, ϱ₀ = 80 kg/m³, g = 10 m/s², 20 load steps, 2×2 points per cell)
//! with the plain quadratic B-spline (one padding cell; the base node and
//! the padding node below it fixed vertically) and with the
//! boundary-modified spline (no padding; the base node fixed): the error
//! of eq. (42) and its order. The plain spline cannot impose the fixed
//! base (u(0) = (u₋₁ + u₁)/8), the modified one interpolates it.
#![allow(clippy::unwrap_used)]

use mpm_basis::{BasisFunction, BoundaryBSpline, QuadraticBSpline};
use mpm_constitutive::HenckyElastic;
use mpm_mesh::RegularGrid;
use mpm_solver::{
    ImplicitBuilder, LoadStepping, MaterialPoints, NodalConstraints, UpdatedLagrangian,
};
use nalgebra::Vector2;

const HEIGHT: f64 = 50.0;
const RHO: f64 = 80.0;
const G: f64 = 10.0;

/// Eq. (42): Σ|σ_yy − σ_a(Z)|V⁰ / (ΣV⁰ ϱ₀ g l₀), σ_a(Z) = −ϱ₀g(l₀ − Z).
fn column_error<B>(basis: B, k: u32, youngs_modulus: f64) -> f64
where
    B: BasisFunction<2, Domain = (), Mesh = RegularGrid<2>> + Copy + 'static,
{
    let h = HEIGHT / f64::from(1u32 << k);
    let cells = 1usize << k;
    let pad = B::PADDING;
    let grid = RegularGrid::new(
        Vector2::new(-(pad as f64) * h, -(pad as f64) * h),
        Vector2::new(h, h),
        [1 + 2 * pad, cells + 2 * pad],
    )
    .unwrap();
    let nx = 2 + 2 * pad;
    let mut fixed = NodalConstraints::new(grid.node_count());
    fixed.fix(0..grid.node_count(), 0);
    fixed.fix(0..nx * (pad + 1), 1); // the base row and the padding rows below
    let position: Vec<_> = (0..2 * cells)
        .flat_map(|j| {
            (0..2)
                .map(move |i| Vector2::new((i as f64 + 0.5) * h / 2.0, (j as f64 + 0.5) * h / 2.0))
        })
        .collect();
    let n = position.len();
    let z0: Vec<f64> = position.iter().map(|x| x.y).collect();
    let mut points: MaterialPoints<2, (), ()> =
        MaterialPoints::new(position, vec![h * h / 4.0; n], RHO, vec![(); n]).unwrap();
    points.set_gravity(Vector2::new(0.0, -G));
    let mut solver = ImplicitBuilder::new(
        basis,
        grid,
        HenckyElastic::new(youngs_modulus, 0.0).unwrap(),
    )
    .formulation(UpdatedLagrangian)
    .constraints(fixed)
    .build();
    solver
        .run(&mut points, &LoadStepping::uniform(20), |_, _, _| Ok(()))
        .unwrap();
    let total: f64 = points.volume0.iter().sum();
    let sum: f64 = (0..n)
        .map(|p| (points.sigma[p][(1, 1)] + RHO * G * (HEIGHT - z0[p])).abs() * points.volume0[p])
        .sum();
    sum / total / (RHO * G * HEIGHT)
}

/// Measured (error of eq. 42, h = 50/2^k m, k = 2..7):
///
/// | | k = 2 | 3 | 4 | 5 | 6 | 7 | rates |
/// |---|---|---|---|---|---|---|---|
/// | plain, E = 1 MPa | 7.02e-2 | 3.58e-2 | 1.71e-2 | 8.29e-3 | 4.43e-3 | 2.70e-3 | 0.97 1.07 1.04 0.90 0.71 |
/// | modified, E = 1 MPa | 1.37e-2 | 3.60e-3 | 1.13e-3 | 8.71e-4 | 7.56e-4 | 6.88e-4 | 1.92 1.67 0.38 0.20 0.13 |
/// | plain, E = 1 GPa | 6.50e-2 | 3.20e-2 | 1.54e-2 | 7.53e-3 | 3.75e-3 | 1.92e-3 | 1.02 1.06 1.03 1.01 0.97 |
/// | modified, E = 1 GPa | 1.47e-2 | 3.90e-3 | 9.76e-4 | 2.44e-4 | 6.10e-5 | 1.52e-5 | 1.91 2.00 2.00 2.00 2.00 |
///
/// At small strain (E = 1 GPa: 0.004 % compaction) the plain spline is
/// first order (the base) and the modified one second order. At the
/// paper's E = 1 MPa the column compacts 4 %, the points cross the spline
/// pieces' breakpoints, and the error of integrating with the points
/// stalls the modified spline near 7e-4 (as it stalls standard MPM, Fig.
/// 6): the boundary is fixed, the quadrature is the next limit.
#[test]
fn boundary_modified_spline_restores_convergence_of_the_column() {
    let ks = [2u32, 3, 4, 5, 6, 7];
    let rates = |e: &[f64]| {
        e.windows(2)
            .map(|w| (w[0] / w[1]).log2())
            .collect::<Vec<_>>()
    };
    let series = |e: f64| {
        let plain: Vec<f64> = ks
            .iter()
            .map(|&k| column_error(QuadraticBSpline, k, e))
            .collect();
        let modified: Vec<f64> = ks
            .iter()
            .map(|&k| column_error(BoundaryBSpline, k, e))
            .collect();
        eprintln!("E = {e:e}: plain {plain:?} rates {:.2?}", rates(&plain));
        eprintln!(
            "E = {e:e}: modified {modified:?} rates {:.2?}",
            rates(&modified)
        );
        (plain, modified)
    };
    let (plain, modified) = series(1e9);
    assert!(
        rates(&plain).iter().all(|r| (0.9..1.15).contains(r)),
        "plain: first order"
    );
    assert!(
        rates(&modified).iter().all(|r| *r > 1.85),
        "modified: second order"
    );
    let (plain, modified) = series(1e6);
    // The paper's column: 3.9 to 15 times smaller at every h.
    for (p, m) in plain.iter().zip(&modified) {
        assert!(p / m > 3.5, "{p} vs {m}");
    }
}
