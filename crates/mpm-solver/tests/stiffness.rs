//! The assembled stiffness is the derivative of the assembled residual:
//! dense comparison with central finite differences, for every basis of
//! mpm-basis, both formulations, elastic and plastic laws, in 2D and 3D.
#![allow(clippy::unwrap_used)]

use super::common;

use mpm_basis::{BasisFunction, Gimp, LinearMpm, QuadraticBSpline};
use mpm_constitutive::{HenckyElastic, LogStrainLaw, VonMises};
use mpm_mesh::RegularGrid;
use mpm_solver::{
    Formulation, ImplicitSolver, MaterialPoints, NewtonOptions, NoLocking, NoUpdate,
    NodalConstraints, Parts, PreviouslyConverged, UpdatedLagrangian,
};
use nalgebra::SVector;

/// A small pseudo-random body on a 3^D grid with the lower face fixed,
/// gravity, and a random (moderate) increment at the free dofs; returns
/// the largest relative error between K and the finite-difference
/// Jacobian (column-wise, relative to the column norm).
fn check<const D: usize, B, F, L>(basis: B, law: L, domain: B::Domain, pad: usize) -> f64
where
    B: BasisFunction<D, Mesh = RegularGrid<D>>,
    F: Formulation,
    L: LogStrainLaw,
{
    let h = 0.5;
    let cells = 3 + 2 * pad;
    let origin = SVector::<f64, D>::from_element(-(pad as f64) * h);
    let grid = RegularGrid::new(origin, SVector::<f64, D>::from_element(h), [cells; D]).unwrap();
    // Points: 2 per cell per direction in the unpadded region, jittered.
    let mut pos = Vec::new();
    let n1 = 6usize;
    let total = n1.pow(D as u32);
    for flat in 0..total {
        let mut x = SVector::<f64, D>::zeros();
        let mut rest = flat;
        for i in 0..D {
            let k = rest % n1;
            rest /= n1;
            let jitter = 0.07 * ((flat * 7 + i * 13) as f64).sin();
            x[i] = (k as f64 + 0.5 + jitter) * h / 2.0;
        }
        pos.push(x);
    }
    let vol = vec![(h / 2.0).powi(D as i32); total];
    let mut points: MaterialPoints<D, L::History, B::Domain> =
        MaterialPoints::new(pos, vol, 1000.0, vec![domain; total]).unwrap();
    let mut g = SVector::<f64, D>::zeros();
    g[D - 1] = -10.0;
    points.set_gravity(g);
    let mut constraints = NodalConstraints::<D>::new(grid.node_count());
    for n in 0..grid.node_count() {
        let x = grid.node_position(n).unwrap();
        if x[D - 1] <= 1e-12 {
            for i in 0..D {
                constraints.fix([n], i);
            }
        }
    }
    let options = NewtonOptions {
        weak_node_threshold: 0.0,
        ..NewtonOptions::default()
    };
    let mut solver: ImplicitSolver<D, Parts<B, F, L, NoLocking, NoUpdate, _>> =
        ImplicitSolver::new(basis, grid, law, NoLocking, NoUpdate, constraints, options);
    let n = solver.prepare_step(&points, 0.0, 1.0).unwrap();
    let du: Vec<f64> = (0..n).map(|k| 0.02 * ((k * 31 + 7) as f64).sin()).collect();
    let k = solver.free_stiffness_dense(&points, &du).unwrap();
    // The sparse export holds exactly the same entries, and nothing else.
    let sparse = solver.free_stiffness().unwrap().to_sprs().unwrap();
    assert_eq!(sparse.shape(), (n, n));
    let mut exported = vec![0.0; n * n];
    for (v, (r, c)) in sparse.iter() {
        exported[c * n + r] += *v;
    }
    assert_eq!(exported, k);
    // The fused pass that gave `k` and the separate stages agree bit for
    // bit: residual, stiffness, and the state each commits (the fused
    // pass keeps no responses, so its commit recomputes them).
    let residual = solver.normalised_residual();
    let mut fused = points.clone();
    solver.commit(&mut fused).unwrap();
    let in_stages = solver.assemble_in_stages_at(&points, &du).unwrap();
    assert_eq!(in_stages.to_bits(), residual.to_bits());
    let mut k_stages = vec![0.0; n * n];
    for (v, (r, c)) in solver.free_stiffness().unwrap().to_sprs().unwrap().iter() {
        k_stages[c * n + r] += *v;
    }
    assert_eq!(k_stages, k);
    let mut staged = points.clone();
    solver.commit(&mut staged).unwrap();
    assert_eq!(format!("{fused:?}"), format!("{staged:?}"));
    assert_ne!(format!("{staged:?}"), format!("{points:?}"));
    common::worst_column_error(&mut solver, &points, &du, &k)
}

macro_rules! stiffness_tests {
    ($($name:ident: $d:literal, $basis:expr, $domain:expr, $pad:expr;)*) => {$(
        #[test]
        fn $name() {
            let elastic = HenckyElastic::new(1e5, 0.3).unwrap();
            let plastic = VonMises::new(1e5, 0.3, 2e2, 1e3).unwrap();
            let errors = [
                check::<$d, _, PreviouslyConverged, _>($basis, elastic, $domain, $pad),
                check::<$d, _, UpdatedLagrangian, _>($basis, elastic, $domain, $pad),
                check::<$d, _, PreviouslyConverged, _>($basis, plastic, $domain, $pad),
                check::<$d, _, UpdatedLagrangian, _>($basis, plastic, $domain, $pad),
            ];
            println!("{}: {errors:?}", stringify!($name));
            for e in errors {
                assert!(e <= 1e-6, "relative error {e:e}");
            }
        }
    )*};
}

stiffness_tests! {
    linear_2d: 2, LinearMpm, (), 0;
    linear_3d: 3, LinearMpm, (), 0;
    gimp_2d: 2, Gimp, SVector::<f64, 2>::from_element(0.125), 0;
    bspline_2d: 2, QuadraticBSpline, (), 1;
}
