//! Sparse direct solves with faer, reusing the symbolic factorisation for
//! every Newton iteration of a load step.
//!
//! The stiffness of both formulations is the Jacobian of the same residual,
//! and for laws with a symmetric algorithmic tangent (Hencky, associated von
//! Mises) it is the Hessian of an (algorithmic) potential, hence symmetric:
//! the supernodal Cholesky factorisation ($LL^T$) is tried first. When it
//! meets a non-positive pivot (geometric softening, a bifurcation) or the
//! law is not symmetric, the solver switches to sparse LU for the rest of
//! the step. Both symbolic factorisations are computed at most once per
//! step, when the sparsity pattern is analysed; the numeric factors and the
//! workspace keep their memory between iterations.
//!
//! Parallelism is the solver's parameter ([`FaerDirect::new`]), passed to
//! every faer call; nothing is set process-wide. The default is
//! `faer::Par::Seq`: faer's parallel supernodal factorisation may apply
//! updates in an order that depends on thread timing, and in
//! path-dependent problems (plastic collapse) those last-bit differences
//! grow into visibly different results. Results must not depend on the run
//! or the number of threads; the material-point loops carry the
//! parallelism instead.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky, factorize_symbolic_cholesky};
use faer::sparse::linalg::lu::{LuRef, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{FaerError, SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

use super::{Factorisation, LinearSolveError, LinearSolver};

/// Steps of iterative refinement after a direct solve.
const MAX_REFINEMENTS: usize = 3;

/// Supernodal Cholesky with an LU fallback (faer), bound to one sparsity
/// pattern per load step (module docs).
#[derive(Debug)]
pub struct FaerDirect {
    par: Par,
    state: Option<Analysed>,
    last: Option<Factorisation>,
    b: Vec<f64>,
    r: Vec<f64>,
}

/// What is kept for one pattern.
struct Analysed {
    pattern: SymbolicSparseColMat<usize>,
    llt: Option<SymbolicCholesky<usize>>,
    l_values: Vec<f64>,
    lu: Option<SymbolicLu<usize>>,
    lu_values: NumericLu<usize, f64>,
    symmetric: bool,
    /// The last factorisation met a non-positive pivot: LU for the rest of
    /// the step.
    lu_only: bool,
    work: MemBuffer,
}

impl std::fmt::Debug for Analysed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Analysed")
            .field("n", &self.pattern.nrows())
            .field("nnz", &self.pattern.row_idx().len())
            .field("symmetric", &self.symmetric)
            .field("lu_only", &self.lu_only)
            .finish_non_exhaustive()
    }
}

impl Default for FaerDirect {
    fn default() -> Self {
        Self::new(Par::Seq)
    }
}

impl FaerDirect {
    /// A solver whose faer calls run with parallelism `par` (see the
    /// module docs for why the default is sequential).
    pub fn new(par: Par) -> Self {
        Self {
            par,
            state: None,
            last: None,
            b: Vec::new(),
            r: Vec::new(),
        }
    }

    /// The parallelism passed to faer.
    pub fn parallelism(&self) -> Par {
        self.par
    }
}

fn resources(stage: &'static str) -> impl Fn(FaerError) -> LinearSolveError {
    move |_| LinearSolveError::Resources { stage }
}

impl LinearSolver for FaerDirect {
    fn analyse(
        &mut self,
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        symmetric: bool,
    ) -> Result<(), LinearSolveError> {
        super::check_pattern(n, col_ptr, row_idx)?;
        self.last = None;
        let pattern =
            SymbolicSparseColMat::new_checked(n, n, col_ptr.to_vec(), None, row_idx.to_vec());
        let par = self.par;
        let (llt, l_values, llt_work) = if symmetric {
            let symbolic = factorize_symbolic_cholesky(
                pattern.as_ref(),
                Side::Lower,
                Default::default(),
                Default::default(),
            )
            .map_err(resources("symbolic analysis"))?;
            let work = StackReq::any_of(&[
                symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
                symbolic.solve_in_place_scratch::<f64>(1, par),
            ]);
            let values = vec![0.0; symbolic.len_val()];
            (Some(symbolic), values, work)
        } else {
            (None, Vec::new(), StackReq::EMPTY)
        };
        let work = MemBuffer::try_new(llt_work).map_err(|_| LinearSolveError::Resources {
            stage: "symbolic analysis",
        })?;
        self.state = Some(Analysed {
            pattern,
            llt,
            l_values,
            lu: None,
            lu_values: NumericLu::new(),
            symmetric,
            lu_only: false,
            work,
        });
        Ok(())
    }

    fn solve(
        &mut self,
        values: &[f64],
        rhs: &mut [f64],
    ) -> Result<Factorisation, LinearSolveError> {
        let par = self.par;
        let st = self.state.as_mut().ok_or(LinearSolveError::NotAnalysed)?;
        let n = st.pattern.nrows();
        super::check_dimensions(st.pattern.row_idx().len(), n, values, rhs)?;
        if n == 0 {
            self.last = Some(Factorisation::Cholesky);
            return Ok(Factorisation::Cholesky);
        }
        self.b.clear();
        self.b.extend_from_slice(rhs);
        let kind = st.factorise(values, par)?;
        st.apply(kind, rhs, par);
        // Iterative refinement: x += K⁻¹(b − Kx) while the residual keeps
        // shrinking. Nearly singular stiffnesses (weakly supported nodes)
        // otherwise leave solve errors that stall Newton above the
        // tolerance, notably with the LU fallback.
        let b_norm = norm(&self.b);
        let mut previous = f64::INFINITY;
        for _ in 0..MAX_REFINEMENTS {
            self.r.clear();
            self.r.extend_from_slice(&self.b);
            let (col_ptr, row_idx) = (st.pattern.col_ptr(), st.pattern.row_idx());
            for (c, x) in rhs.iter().enumerate() {
                for e in col_ptr[c]..col_ptr[c + 1] {
                    self.r[row_idx[e]] -= values[e] * x;
                }
            }
            let r_norm = norm(&self.r);
            if !(r_norm.is_finite() && r_norm > 1e-15 * b_norm && r_norm < 0.5 * previous) {
                break;
            }
            previous = r_norm;
            st.apply(kind, &mut self.r, par);
            rhs.iter_mut().zip(&self.r).for_each(|(x, d)| *x += d);
        }
        if let Some(dof) = rhs.iter().position(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite {
                factorisation: kind,
                dof,
            });
        }
        self.last = Some(kind);
        Ok(kind)
    }

    fn last_factorisation(&self) -> Option<Factorisation> {
        self.last
    }

    fn nnz(&self) -> usize {
        self.state.as_ref().map_or(0, |s| s.pattern.row_idx().len())
    }
}

impl Analysed {
    /// Cholesky when the values are symmetric and no earlier attempt of
    /// this step met a non-positive pivot, LU otherwise (its symbolic
    /// analysis made once per pattern).
    fn factorise(&mut self, values: &[f64], par: Par) -> Result<Factorisation, LinearSolveError> {
        let k = SparseColMatRef::new(self.pattern.as_ref(), values);
        if self.symmetric
            && !self.lu_only
            && let Some(symbolic) = &self.llt
        {
            let stack = MemStack::new(&mut self.work);
            match symbolic.factorize_numeric_llt::<f64>(
                &mut self.l_values,
                k,
                Side::Lower,
                Default::default(),
                par,
                stack,
                Default::default(),
            ) {
                Ok(_) => return Ok(Factorisation::Cholesky),
                // A non-positive pivot (the only numeric failure): LU for
                // the rest of the step.
                Err(_) => self.lu_only = true,
            }
        }
        if self.lu.is_none() {
            let symbolic = factorize_symbolic_lu(self.pattern.as_ref(), Default::default())
                .map_err(resources("symbolic analysis"))?;
            let need = StackReq::any_of(&[
                symbolic.factorize_numeric_lu_scratch::<f64>(par, Default::default()),
                symbolic.solve_in_place_scratch::<f64>(1, par),
                self.work_req(par),
            ]);
            self.work = MemBuffer::try_new(need).map_err(|_| LinearSolveError::Resources {
                stage: "symbolic analysis",
            })?;
            self.lu = Some(symbolic);
        }
        let symbolic = self.lu.as_ref().ok_or(LinearSolveError::NotAnalysed)?;
        let stack = MemStack::new(&mut self.work);
        symbolic
            .factorize_numeric_lu::<f64>(&mut self.lu_values, k, par, stack, Default::default())
            .map_err(|e| match e {
                LuError::SymbolicSingular { index } => LinearSolveError::SingularPivot { index },
                LuError::Generic(_) => LinearSolveError::Resources {
                    stage: "numeric factorisation",
                },
            })?;
        Ok(Factorisation::Lu)
    }

    /// Workspace the Cholesky path needs (kept when LU is added).
    fn work_req(&self, par: Par) -> StackReq {
        self.llt.as_ref().map_or(StackReq::EMPTY, |s| {
            StackReq::any_of(&[
                s.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
                s.solve_in_place_scratch::<f64>(1, par),
            ])
        })
    }

    /// $x \leftarrow K^{-1}x$ with the factors of the last
    /// [`Self::factorise`].
    fn apply(&mut self, kind: Factorisation, x: &mut [f64], par: Par) {
        let n = x.len();
        let m = MatMut::from_column_major_slice_mut(x, n, 1);
        let stack = MemStack::new(&mut self.work);
        match (kind, &self.llt, &self.lu) {
            (Factorisation::Cholesky, Some(symbolic), _) => {
                LltRef::<'_, usize, f64>::new(symbolic, &self.l_values).solve_in_place_with_conj(
                    Conj::No,
                    m,
                    par,
                    stack,
                );
            }
            (Factorisation::Lu, _, Some(symbolic)) => {
                LuRef::<'_, usize, f64>::new_unchecked(symbolic, &self.lu_values)
                    .solve_in_place_with_conj(Conj::No, m, par, stack);
            }
            // `factorise` returned `kind` only after building its factors.
            _ => x.iter_mut().for_each(|v| *v = f64::NAN),
        }
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1D Laplacian with Dirichlet ends (SPD) and a non-symmetric variant.
    fn tridiagonal(n: usize, upper: f64) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let (mut ptr, mut idx, mut val) = (vec![0], vec![], vec![]);
        for j in 0..n {
            if j > 0 {
                idx.push(j - 1);
                val.push(upper);
            }
            idx.push(j);
            val.push(2.0);
            if j + 1 < n {
                idx.push(j + 1);
                val.push(-1.0);
            }
            ptr.push(idx.len());
        }
        (ptr, idx, val)
    }

    fn residual(ptr: &[usize], idx: &[usize], val: &[f64], x: &[f64], b: &[f64]) -> f64 {
        let mut r = b.to_vec();
        for j in 0..x.len() {
            for k in ptr[j]..ptr[j + 1] {
                r[idx[k]] -= val[k] * x[j];
            }
        }
        r.iter().map(|v| v * v).sum::<f64>().sqrt()
    }

    fn analysed(n: usize, ptr: &[usize], idx: &[usize], symmetric: bool) -> FaerDirect {
        let mut s = FaerDirect::default();
        s.analyse(n, ptr, idx, symmetric).expect("pattern");
        s
    }

    #[test]
    fn cholesky_for_spd_and_lu_for_unsymmetric_and_indefinite() {
        let n = 50;
        let b: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let (ptr, idx, val) = tridiagonal(n, -1.0);
        let mut s = analysed(n, &ptr, &idx, true);
        let mut x = b.clone();
        assert_eq!(s.solve(&val, &mut x), Ok(Factorisation::Cholesky));
        assert!(residual(&ptr, &idx, &val, &x, &b) < 1e-10);
        // Indefinite symmetric: Cholesky fails, LU takes over.
        let neg: Vec<f64> = val
            .iter()
            .map(|v| if *v == 2.0 { -0.5 } else { *v })
            .collect();
        let mut x = b.clone();
        assert_eq!(s.solve(&neg, &mut x), Ok(Factorisation::Lu));
        assert!(residual(&ptr, &idx, &neg, &x, &b) < 1e-8);
        // Unsymmetric.
        let (ptr, idx, val) = tridiagonal(n, -0.3);
        let mut s = analysed(n, &ptr, &idx, false);
        let mut x = b.clone();
        assert_eq!(s.solve(&val, &mut x), Ok(Factorisation::Lu));
        assert!(residual(&ptr, &idx, &val, &x, &b) < 1e-10);
    }

    #[test]
    fn singular_system_is_an_error_not_nan() {
        let mut s = analysed(2, &[0, 2, 4], &[0, 1, 0, 1], false);
        let mut x = vec![1.0, 2.0];
        assert!(s.solve(&[1.0, 1.0, 1.0, 1.0], &mut x).is_err());
    }

    #[test]
    fn errors_say_what_is_wrong() {
        let mut s = FaerDirect::default();
        let mut x = vec![1.0];
        assert_eq!(s.solve(&[1.0], &mut x), Err(LinearSolveError::NotAnalysed));
        assert!(matches!(
            s.analyse(2, &[0, 1], &[0], true),
            Err(LinearSolveError::InvalidPattern { n: 2, .. })
        ));
        assert!(matches!(
            s.analyse(2, &[0, 2, 3], &[1, 0, 1], true),
            Err(LinearSolveError::InvalidPattern { .. })
        ));
        let mut s = analysed(1, &[0, 1], &[0], true);
        assert_eq!(
            s.solve(&[1.0, 2.0], &mut x),
            Err(LinearSolveError::Dimension {
                what: "values",
                expected: 1,
                got: 2
            })
        );
        // A zero pivot of a structurally complete matrix: LU reports the
        // column, or the solve a non-finite value, never a NaN result.
        let mut x = vec![1.0];
        let e = s.solve(&[0.0], &mut x).expect_err("singular");
        assert!(
            matches!(
                e,
                LinearSolveError::SingularPivot { index: 0 } | LinearSolveError::NonFinite { .. }
            ),
            "{e}"
        );
    }
}
