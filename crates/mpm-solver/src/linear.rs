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
//! step, when the sparsity pattern is built.
//!
//! The factorisations run sequentially (`faer::Par::Seq`): faer's parallel
//! supernodal factorisation may apply updates in an order that depends on
//! thread timing, and in path-dependent problems (plastic collapse) those
//! last-bit differences grow into visibly different results. Results must
//! not depend on the run or the number of threads; the material-point loops
//! carry the parallelism instead.

use faer::Side;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, Lu, SymbolicLlt, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};

/// Which factorisation solved the last system.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Factorisation {
    /// Sparse Cholesky $LL^T$ (lower triangle).
    Cholesky,
    /// Sparse LU with partial pivoting.
    Lu,
}

/// A direct solver bound to one sparsity pattern.
#[derive(Debug)]
pub struct LinearSolver {
    pattern: SymbolicSparseColMat<usize>,
    llt: Option<SymbolicLlt<usize>>,
    lu: Option<SymbolicLu<usize>>,
    symmetric: bool,
    last: Option<Factorisation>,
    b: Vec<f64>,
    r: Vec<f64>,
}

impl LinearSolver {
    /// Analyses the pattern (`col_ptr`, `row_idx`: CSC, rows sorted) of an
    /// `n × n` matrix. `symmetric` says whether the values will be
    /// symmetric, which enables Cholesky.
    pub fn new(
        n: usize,
        col_ptr: Vec<usize>,
        row_idx: Vec<usize>,
        symmetric: bool,
    ) -> Result<Self, String> {
        faer::set_global_parallelism(faer::Par::Seq);
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let llt = if symmetric {
            Some(
                SymbolicLlt::try_new(pattern.as_ref(), Side::Lower)
                    .map_err(|e| format!("{e:?}"))?,
            )
        } else {
            None
        };
        Ok(Self {
            pattern,
            llt,
            lu: None,
            symmetric,
            last: None,
            b: Vec::new(),
            r: Vec::new(),
        })
    }

    /// Number of stored entries of the pattern.
    pub fn nnz(&self) -> usize {
        self.pattern.row_idx().len()
    }

    /// The factorisation used by the last successful solve.
    pub fn last_factorisation(&self) -> Option<Factorisation> {
        self.last
    }

    /// Solves $K x = b$ in place (`rhs` holds $b$ on entry and $x$ on
    /// exit) for the values `values` in the analysed pattern.
    pub fn solve(&mut self, values: &[f64], rhs: &mut [f64]) -> Result<Factorisation, String> {
        let n = rhs.len();
        if n == 0 {
            return Ok(Factorisation::Cholesky);
        }
        self.b.clear();
        self.b.extend_from_slice(rhs);
        let factor = self.factorise(values)?;
        let apply = |x: &mut [f64]| {
            let m = faer::MatMut::from_column_major_slice_mut(x, n, 1);
            match &factor {
                Factor::Cholesky(llt) => llt.solve_in_place(m),
                Factor::Lu(lu) => lu.solve_in_place(m),
            }
        };
        apply(rhs);
        // Iterative refinement: x += K⁻¹(b − Kx) while the residual keeps
        // shrinking. Nearly singular stiffnesses (weakly supported nodes)
        // otherwise leave solve errors that stall Newton above the
        // tolerance, notably with the LU fallback.
        let b_norm = norm(&self.b);
        let mut previous = f64::INFINITY;
        for _ in 0..MAX_REFINEMENTS {
            self.r.clear();
            self.r.extend_from_slice(&self.b);
            let (col_ptr, row_idx) = (self.pattern.col_ptr(), self.pattern.row_idx());
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
            apply(&mut self.r);
            rhs.iter_mut().zip(&self.r).for_each(|(x, d)| *x += d);
        }
        finite(rhs, factor.kind())
    }

    /// Cholesky when the values are symmetric and the last attempt did not
    /// meet a non-positive pivot, LU otherwise (its symbolic analysis made
    /// once per pattern).
    fn factorise(&mut self, values: &[f64]) -> Result<Factor, String> {
        let k = SparseColMatRef::new(self.pattern.as_ref(), values);
        if self.symmetric
            && self.last != Some(Factorisation::Lu)
            && let Some(symbolic) = &self.llt
            && let Ok(llt) = Llt::try_new_with_symbolic(symbolic.clone(), k, Side::Lower)
        {
            self.last = Some(Factorisation::Cholesky);
            return Ok(Factor::Cholesky(llt));
        }
        if self.lu.is_none() {
            self.lu =
                Some(SymbolicLu::try_new(self.pattern.as_ref()).map_err(|e| format!("{e:?}"))?);
        }
        let symbolic = self.lu.clone().ok_or("symbolic LU missing")?;
        let k = SparseColMatRef::new(self.pattern.as_ref(), values);
        let lu = Lu::try_new_with_symbolic(symbolic, k).map_err(|e| format!("sparse LU: {e:?}"))?;
        self.last = Some(Factorisation::Lu);
        Ok(Factor::Lu(Box::new(lu)))
    }
}

/// Steps of iterative refinement after a direct solve.
const MAX_REFINEMENTS: usize = 3;

enum Factor {
    Cholesky(Llt<usize, f64>),
    Lu(Box<Lu<usize, f64>>),
}

impl Factor {
    fn kind(&self) -> Factorisation {
        match self {
            Factor::Cholesky(_) => Factorisation::Cholesky,
            Factor::Lu(_) => Factorisation::Lu,
        }
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn finite(x: &[f64], f: Factorisation) -> Result<Factorisation, String> {
    if x.iter().all(|v| v.is_finite()) {
        Ok(f)
    } else {
        Err(format!(
            "{f:?} solve produced non-finite values (singular stiffness)"
        ))
    }
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

    #[test]
    fn cholesky_for_spd_and_lu_for_unsymmetric_and_indefinite() {
        let n = 50;
        let b: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let (ptr, idx, val) = tridiagonal(n, -1.0);
        let mut s = LinearSolver::new(n, ptr.clone(), idx.clone(), true).expect("pattern");
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
        let mut s = LinearSolver::new(n, ptr.clone(), idx.clone(), false).expect("pattern");
        let mut x = b.clone();
        assert_eq!(s.solve(&val, &mut x), Ok(Factorisation::Lu));
        assert!(residual(&ptr, &idx, &val, &x, &b) < 1e-10);
    }

    #[test]
    fn singular_system_is_an_error_not_nan() {
        let mut s = LinearSolver::new(2, vec![0, 2, 4], vec![0, 1, 0, 1], false).expect("pattern");
        let mut x = vec![1.0, 2.0];
        assert!(s.solve(&[1.0, 1.0, 1.0, 1.0], &mut x).is_err());
    }
}
