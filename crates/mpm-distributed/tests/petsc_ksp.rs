//! PETSc's KSP behind `LinearSolver` on one rank: the same solution as the
//! built-in direct solver, the options applied as given, refused when
//! misspelt or unused, and non-convergence reported as such (the tests of
//! the binding crate, which is not a workspace member).
#![cfg(feature = "petsc")]
#![allow(missing_docs, clippy::unwrap_used)]

use mpm_petsc::{LinearSolver, PetscLinear};
use mpm_solver::{Factorisation, FaerDirect, IterativeOptions, LinearSolveError};

/// The 2D five-point Laplacian on an m × m grid (Dirichlet), CSC.
fn laplacian(m: usize) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>) {
    let n = m * m;
    let column = |c: usize| {
        let (x, y) = (c % m, c / m);
        let near = [
            (x > 0, c.wrapping_sub(1)),
            (x + 1 < m, c + 1),
            (y > 0, c.wrapping_sub(m)),
            (y + 1 < m, c + m),
        ];
        let mut entries: Vec<(usize, f64)> = near
            .into_iter()
            .filter(|e| e.0)
            .map(|(_, r)| (r, -1.0))
            .collect();
        entries.push((c, 4.0));
        entries.sort_by_key(|e| e.0);
        entries
    };
    let columns: Vec<Vec<(usize, f64)>> = (0..n).map(column).collect();
    let col_ptr = std::iter::once(0)
        .chain(columns.iter().scan(0, |k, c| {
            *k += c.len();
            Some(*k)
        }))
        .collect();
    let (row_idx, values) = columns.into_iter().flatten().unzip();
    (n, col_ptr, row_idx, values)
}

fn tight() -> IterativeOptions {
    IterativeOptions {
        rel_tolerance: 1e-12,
        max_iterations: 1000,
    }
}

fn direct(m: usize, b: &[f64]) -> Vec<f64> {
    let (n, col_ptr, row_idx, values) = laplacian(m);
    let mut d = FaerDirect::default();
    d.analyse(n, &col_ptr, &row_idx, true).unwrap();
    let mut x = b.to_vec();
    d.solve(&values, &mut x).unwrap();
    x
}

/// CG with Jacobi, GMRES with ILU and CG with GAMG each reach the direct
/// solution to their tolerance (relative 1e-12 on the residual, so 1e-9
/// on x given the Laplacian's condition number ~ 4m²/π² ≈ 650 at m = 40),
/// over two Newton-like solves with new values in the same pattern.
#[test]
fn krylov_methods_match_the_direct_solution() {
    let m = 40;
    let (n, col_ptr, row_idx, values) = laplacian(m);
    let b: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64).collect();
    let reference = direct(m, &b);
    for (options, names) in [
        ("-ksp_type cg -pc_type jacobi", ("cg", "jacobi")),
        ("-ksp_type gmres -pc_type ilu", ("gmres", "ilu")),
        ("-ksp_type cg -pc_type gamg", ("cg", "gamg")),
    ] {
        let mut s = PetscLinear::new(options, tight());
        s.analyse(n, &col_ptr, &row_idx, true).unwrap();
        assert_eq!(
            s.methods().unwrap(),
            (names.0.to_owned(), names.1.to_owned())
        );
        for scale in [1.0, 2.0] {
            let scaled: Vec<f64> = values.iter().map(|v| v * scale).collect();
            let mut x = b.clone();
            assert_eq!(s.solve(&scaled, &mut x), Ok(Factorisation::Iterative));
            let err = x
                .iter()
                .zip(&reference)
                .map(|(a, r)| (a - r / scale).abs())
                .fold(0.0, f64::max);
            let size = reference.iter().fold(0.0, |a: f64, r| a.max(r.abs()));
            assert!(
                err <= 1e-9 * size,
                "{options}: max error {err:.3e} of {size:.3e}"
            );
            assert!(s.last_iterations() > 0);
        }
    }
}

/// A misspelt method is PETSc's error, with its message, not a panic or
/// another method silently run.
#[test]
fn unknown_method_is_refused_with_petscs_message() {
    let (n, col_ptr, row_idx, _) = laplacian(4);
    let mut s = PetscLinear::new("-ksp_type cgg", tight());
    let e = s.analyse(n, &col_ptr, &row_idx, true).unwrap_err();
    let text = e.to_string();
    assert!(text.contains("PETSc") && text.contains("cgg"), "{text}");
}

/// An option no object reads (misspelt name) is refused after the first
/// solve, naming it.
#[test]
fn unused_option_is_refused() {
    let (n, col_ptr, row_idx, values) = laplacian(4);
    let mut s = PetscLinear::new("-ksp_type cg -pc_typ jacobi", tight());
    s.analyse(n, &col_ptr, &row_idx, true).unwrap();
    let mut x = vec![1.0; n];
    let e = s.solve(&values, &mut x).unwrap_err();
    assert!(e.to_string().contains("-pc_typ"), "{e}");
}

/// A Krylov solve stopped by its iteration limit is `NotConverged`, the
/// error Newton cuts the step on.
#[test]
fn iteration_limit_is_not_converged() {
    let (n, col_ptr, row_idx, values) = laplacian(20);
    let starved = IterativeOptions {
        rel_tolerance: 1e-14,
        max_iterations: 2,
    };
    let mut s = PetscLinear::new("-ksp_type cg -pc_type none", starved);
    s.analyse(n, &col_ptr, &row_idx, true).unwrap();
    let mut x = vec![1.0; n];
    match s.solve(&values, &mut x) {
        Err(LinearSolveError::NotConverged {
            iterations,
            relative_residual,
        }) => assert!(iterations == 2 && relative_residual > 1e-14),
        other => panic!("expected NotConverged, got {other:?}"),
    }
}

/// Lengths that do not match the pattern are refused before PETSc sees
/// them.
#[test]
fn wrong_lengths_are_refused() {
    let (n, col_ptr, row_idx, values) = laplacian(4);
    let mut s = PetscLinear::new("", tight());
    let mut x = vec![1.0; n];
    assert_eq!(s.solve(&values, &mut x), Err(LinearSolveError::NotAnalysed));
    s.analyse(n, &col_ptr, &row_idx, true).unwrap();
    assert!(matches!(
        s.solve(&values[1..], &mut x),
        Err(LinearSolveError::Dimension { what: "values", .. })
    ));
}
