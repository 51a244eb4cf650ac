//! Preconditioned BiCGSTAB (faer's `matrix_free::bicgstab`) with a
//! zero-fill incomplete LU preconditioner (`faer-precond`'s `Ilu0`) — the
//! iterative alternative to [`super::FaerDirect`] for systems whose direct
//! factors do not fit (the full vane of Wang et al. 2021 §5.6: the sparse
//! LU of its 139k-dof F-patch stiffness needs more than 14 GB).
//!
//! BiCGSTAB because the coupled (F-bar, F-patch) stiffness is not
//! symmetric; right preconditioning, so that the residual BiCGSTAB
//! monitors is the true one. The symbolic ILU(0) is built once per load
//! step with the pattern ([`LinearSolver::analyse`]); each solve
//! refactorises it in place (no allocation) and starts from zero. The
//! relative tolerance must sit well below the Newton tolerance, or the
//! inexact solves cost Newton its quadratic rate; the default, 1e-12,
//! keeps it (measured in `docs/src/benchmarks/linear.md`).
//!
//! Parallelism is the solver's parameter, as for the direct solver; the
//! default is sequential, for results that do not depend on the thread
//! count.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::matrix_free::bicgstab::{BicgError, BicgParams, bicgstab, bicgstab_scratch};
use faer::matrix_free::{IdentityPrecond, InitialGuessStatus};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{MatMut, MatRef, Par};
use faer_precond::{Ilu0, SymbolicIlu0};

use super::{Factorisation, LinearSolveError, LinearSolver};

/// Tolerances of [`FaerIterative`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IterativeOptions {
    /// Stop when $\|b - Kx\| \le$ this $\times \|b\|$.
    pub rel_tolerance: f64,
    /// Fail after this many BiCGSTAB iterations.
    pub max_iterations: usize,
}

impl Default for IterativeOptions {
    fn default() -> Self {
        Self {
            rel_tolerance: 1e-12,
            max_iterations: 5000,
        }
    }
}

/// BiCGSTAB with an ILU(0) preconditioner, bound to one sparsity pattern
/// per load step (module docs).
#[derive(Debug)]
pub struct FaerIterative {
    par: Par,
    options: IterativeOptions,
    state: Option<Analysed>,
    last: Option<Factorisation>,
    last_iterations: usize,
    x: Vec<f64>,
}

struct Analysed {
    pattern: SymbolicSparseColMat<usize>,
    ilu: Ilu0<usize, f64>,
    work: MemBuffer,
}

impl std::fmt::Debug for Analysed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Analysed")
            .field("n", &self.pattern.nrows())
            .field("nnz", &self.pattern.row_idx().len())
            .finish_non_exhaustive()
    }
}

impl Default for FaerIterative {
    fn default() -> Self {
        Self::new(Par::Seq, IterativeOptions::default())
    }
}

impl FaerIterative {
    /// A solver with parallelism `par` and tolerances `options`.
    pub fn new(par: Par, options: IterativeOptions) -> Self {
        Self {
            par,
            options,
            state: None,
            last: None,
            last_iterations: 0,
            x: Vec::new(),
        }
    }
}

impl LinearSolver for FaerIterative {
    fn analyse(
        &mut self,
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        _symmetric: bool,
    ) -> Result<(), LinearSolveError> {
        super::check_pattern(n, col_ptr, row_idx)?;
        self.last = None;
        let pattern =
            SymbolicSparseColMat::new_checked(n, n, col_ptr.to_vec(), None, row_idx.to_vec());
        let symbolic = SymbolicIlu0::try_new(pattern.as_ref()).map_err(|e| {
            LinearSolveError::InvalidPattern {
                n,
                reason: match e {
                    faer_precond::Ilu0Error::MissingDiagonal { .. } => {
                        "every column needs its diagonal entry for ILU(0)"
                    }
                    _ => "the pattern is not valid for ILU(0)",
                },
            }
        })?;
        let ilu = Ilu0::new_with_symbolic(symbolic);
        // The workspace depends on the operator's shape only: sized with
        // zero values once per step.
        let zeros = vec![0.0; pattern.row_idx().len()];
        let work = MemBuffer::try_new(bicgstab_scratch::<f64>(
            IdentityPrecond { dim: n },
            &ilu,
            SparseColMatRef::new(pattern.as_ref(), &zeros),
            1,
            self.par,
        ))
        .map_err(|_| LinearSolveError::Resources {
            stage: "symbolic analysis",
        })?;
        self.state = Some(Analysed { pattern, ilu, work });
        Ok(())
    }

    fn solve(
        &mut self,
        values: &[f64],
        rhs: &mut [f64],
    ) -> Result<Factorisation, LinearSolveError> {
        let st = self.state.as_mut().ok_or(LinearSolveError::NotAnalysed)?;
        let n = st.pattern.nrows();
        super::check_dimensions(st.pattern.row_idx().len(), n, values, rhs)?;
        if n == 0 {
            self.last = Some(Factorisation::Iterative);
            return Ok(Factorisation::Iterative);
        }
        let k = SparseColMatRef::new(st.pattern.as_ref(), values);
        st.ilu.refactorize(k).map_err(|e| match e {
            faer_precond::Ilu0Error::ZeroPivot { col } => {
                LinearSolveError::SingularPivot { index: col }
            }
            _ => LinearSolveError::InvalidPattern {
                n,
                reason: "the values do not match the analysed pattern",
            },
        })?;
        self.x.clear();
        self.x.resize(n, 0.0);
        let params = BicgParams {
            // `MaybeNonZero` with x = 0: faer 0.24's BiCGSTAB leaves its
            // residual uninitialised when told the guess is zero (it
            // computes r = b - Kx only for a possibly non-zero guess), so
            // the start is spelled out; one product with a zero vector.
            initial_guess: InitialGuessStatus::MaybeNonZero,
            abs_tolerance: 0.0,
            rel_tolerance: self.options.rel_tolerance,
            max_iters: self.options.max_iterations,
            ..Default::default()
        };
        let result = bicgstab(
            MatMut::from_column_major_slice_mut(&mut self.x, n, 1),
            IdentityPrecond { dim: n },
            &st.ilu,
            k,
            MatRef::from_column_major_slice(rhs, n, 1),
            params,
            |_| {},
            self.par,
            MemStack::new(&mut st.work),
        );
        match result {
            Ok(info) => {
                self.last_iterations = info.iter_count;
            }
            Err(BicgError::NoConvergence { rel_residual, .. }) => {
                return Err(LinearSolveError::NotConverged {
                    iterations: self.options.max_iterations,
                    relative_residual: rel_residual,
                });
            }
        }
        if let Some(dof) = self.x.iter().position(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite {
                factorisation: Factorisation::Iterative,
                dof,
            });
        }
        rhs.copy_from_slice(&self.x);
        self.last = Some(Factorisation::Iterative);
        Ok(Factorisation::Iterative)
    }

    fn last_factorisation(&self) -> Option<Factorisation> {
        self.last
    }

    fn nnz(&self) -> usize {
        self.state.as_ref().map_or(0, |s| s.pattern.row_idx().len())
    }

    /// BiCGSTAB iterations of the last successful solve.
    fn last_iterations(&self) -> usize {
        self.last_iterations
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linear::FaerDirect;

    /// A nonsymmetric convection–diffusion stencil on a 10-wide grid
    /// (couplings at distances 1 and 10, so ILU(0) is not exact).
    fn system(n: usize) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for c in 0..n {
            for r in c.saturating_sub(10)..(c + 11).min(n) {
                let d = r.abs_diff(c);
                if d != 0 && d != 1 && d != 10 {
                    continue;
                }
                row_idx.push(r);
                values.push(match (d, r < c) {
                    (0, _) => 4.2 + 0.1 * (c % 3) as f64,
                    (_, true) => -1.3,
                    _ => -0.7,
                });
            }
            col_ptr.push(row_idx.len());
        }
        (col_ptr, row_idx, values)
    }

    #[test]
    fn agrees_with_the_direct_solver() {
        let n = 200;
        let (col_ptr, row_idx, values) = system(n);
        let b: Vec<f64> = (0..n).map(|i| (0.1 * i as f64).sin() + 1.0).collect();
        let mut direct = FaerDirect::default();
        direct
            .analyse(n, &col_ptr, &row_idx, false)
            .expect("pattern");
        let mut x_direct = b.clone();
        direct.solve(&values, &mut x_direct).expect("solves");
        let mut iterative = FaerIterative::default();
        iterative
            .analyse(n, &col_ptr, &row_idx, false)
            .expect("pattern");
        let mut x = b.clone();
        assert_eq!(
            iterative.solve(&values, &mut x).expect("solves"),
            Factorisation::Iterative
        );
        let err = x
            .iter()
            .zip(&x_direct)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-10, "{err:e}");
        assert!(iterative.last_iterations() > 0);
    }

    #[test]
    fn non_convergence_is_a_typed_error() {
        let n = 200;
        let (col_ptr, row_idx, values) = system(n);
        let mut iterative = FaerIterative::new(
            Par::Seq,
            IterativeOptions {
                rel_tolerance: 1e-14,
                max_iterations: 1,
            },
        );
        iterative
            .analyse(n, &col_ptr, &row_idx, false)
            .expect("pattern");
        let mut b: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 0 { 1.0 } else { -3.0 })
            .collect();
        match iterative.solve(&values, &mut b) {
            Err(LinearSolveError::NotConverged {
                iterations: 1,
                relative_residual,
            }) => assert!(relative_residual > 1e-14 && relative_residual.is_finite()),
            other => panic!("{other:?}"),
        }
    }
}
