//! Which linear solver a solver builds ([`LinearChoice`], a value of
//! [`crate::NewtonOptions`]), and [`AutoLinear`], which picks the direct or
//! the iterative solver per load step by the size of the system.
//!
//! The crossover, measured in `docs/src/benchmarks/linear.md`: in 3D the
//! direct factors fill quickly and ILU(0)-preconditioned BiCGSTAB is faster
//! from about 5 000 free dofs (6× at 45 000 with F-patch's LU, 1.25× with
//! standard MPM's Cholesky), and the only option at the full vane's
//! 139 000, whose LU passed 14 GB; in 2D the direct solver stays 1.5–4.5×
//! faster up to the 10 000 dofs measured. Hence a threshold per dimension.

use super::{
    Factorisation, FaerDirect, FaerIterative, IterativeOptions, LinearSolveError, LinearSolver,
};

/// [`LinearChoice::Auto`]'s default largest direct system in 3D.
pub const DEFAULT_MAX_DIRECT_DOFS_3D: usize = 20_000;
/// [`LinearChoice::Auto`]'s default largest direct system in 1D and 2D
/// (direct solves stay cheap: planar fill grows mildly).
pub const DEFAULT_MAX_DIRECT_DOFS_2D: usize = 500_000;
/// [`AutoLinear`] retries a failed iterative solve directly up to this
/// many free dofs (beyond, the direct factors may not fit in memory).
pub const MAX_FALLBACK_DOFS: usize = 100_000;

/// The linear solver of [`crate::ImplicitSolver::new`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LinearChoice {
    /// [`FaerDirect`]: supernodal Cholesky with an LU fallback.
    Direct,
    /// [`FaerIterative`]: ILU(0)-preconditioned BiCGSTAB.
    Iterative(IterativeOptions),
    /// [`AutoLinear`]: direct up to `max_direct_dofs` free dofs, iterative
    /// beyond.
    Auto {
        /// Largest system solved directly; `None`: the default of the
        /// dimension ([`DEFAULT_MAX_DIRECT_DOFS_3D`],
        /// [`DEFAULT_MAX_DIRECT_DOFS_2D`]).
        max_direct_dofs: Option<usize>,
        /// Tolerances of the iterative solver.
        iterative: IterativeOptions,
    },
}

impl Default for LinearChoice {
    fn default() -> Self {
        Self::Auto {
            max_direct_dofs: None,
            iterative: IterativeOptions::default(),
        }
    }
}

impl LinearChoice {
    /// The solver this choice describes for a problem of dimension
    /// `dim` (sequential faer calls).
    pub fn build(self, dim: usize) -> Box<dyn LinearSolver> {
        match self {
            Self::Direct => Box::new(FaerDirect::default()),
            Self::Iterative(options) => Box::new(FaerIterative::new(faer::Par::Seq, options)),
            Self::Auto {
                max_direct_dofs,
                iterative,
            } => Box::new(AutoLinear::new(
                max_direct_dofs.unwrap_or(if dim >= 3 {
                    DEFAULT_MAX_DIRECT_DOFS_3D
                } else {
                    DEFAULT_MAX_DIRECT_DOFS_2D
                }),
                iterative,
            )),
        }
    }
}

/// The direct solver for systems up to a number of free dofs, the
/// iterative one beyond, chosen when each load step's pattern is analysed.
/// An iterative solve that fails (no convergence, a zero pivot of the
/// incomplete factors) is retried directly, and the direct solver kept for
/// the rest of the step, when the system has at most
/// [`MAX_FALLBACK_DOFS`] free dofs.
#[derive(Debug)]
pub struct AutoLinear {
    max_direct_dofs: usize,
    direct: FaerDirect,
    iterative: FaerIterative,
    use_direct: bool,
    /// The step's pattern, kept for a fallback to the direct solver.
    pattern: Option<(usize, Vec<usize>, Vec<usize>, bool)>,
    /// The right-hand side of the current solve, for the fallback (kept
    /// between iterations: no allocation per solve).
    b: Vec<f64>,
}

impl AutoLinear {
    /// Direct up to `max_direct_dofs`, iterative with `options` beyond.
    pub fn new(max_direct_dofs: usize, options: IterativeOptions) -> Self {
        Self {
            max_direct_dofs,
            direct: FaerDirect::default(),
            iterative: FaerIterative::new(faer::Par::Seq, options),
            use_direct: true,
            pattern: None,
            b: Vec::new(),
        }
    }

    /// Whether the current step uses the direct solver.
    pub fn uses_direct(&self) -> bool {
        self.use_direct
    }
}

impl LinearSolver for AutoLinear {
    fn analyse(
        &mut self,
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        symmetric: bool,
    ) -> Result<(), LinearSolveError> {
        self.use_direct = n <= self.max_direct_dofs;
        if self.use_direct {
            self.pattern = None;
            self.direct.analyse(n, col_ptr, row_idx, symmetric)
        } else {
            self.pattern = (n <= MAX_FALLBACK_DOFS)
                .then(|| (n, col_ptr.to_vec(), row_idx.to_vec(), symmetric));
            self.iterative.analyse(n, col_ptr, row_idx, symmetric)
        }
    }

    fn solve(
        &mut self,
        values: &[f64],
        rhs: &mut [f64],
    ) -> Result<Factorisation, LinearSolveError> {
        if self.use_direct {
            return self.direct.solve(values, rhs);
        }
        if self.pattern.is_some() {
            self.b.clear();
            self.b.extend_from_slice(rhs);
        }
        match self.iterative.solve(values, rhs) {
            Err(
                e
                @ (LinearSolveError::NotConverged { .. } | LinearSolveError::SingularPivot { .. }),
            ) => {
                let Some((n, col_ptr, row_idx, symmetric)) = self.pattern.take() else {
                    return Err(e);
                };
                self.direct.analyse(n, &col_ptr, &row_idx, symmetric)?;
                self.use_direct = true;
                rhs.copy_from_slice(&self.b);
                self.direct.solve(values, rhs)
            }
            other => other,
        }
    }

    fn last_factorisation(&self) -> Option<Factorisation> {
        if self.use_direct {
            self.direct.last_factorisation()
        } else {
            self.iterative.last_factorisation()
        }
    }

    fn nnz(&self) -> usize {
        if self.use_direct {
            self.direct.nnz()
        } else {
            self.iterative.nnz()
        }
    }

    fn last_iterations(&self) -> usize {
        if self.use_direct {
            0
        } else {
            self.iterative.last_iterations()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2D five-point Laplacian plus a small unsymmetric convection.
    fn system(m: usize) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>) {
        let n = m * m;
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for c in 0..n {
            let (x, y) = (c % m, c / m);
            let mut rows = vec![(c, 4.0)];
            if x > 0 {
                rows.push((c - 1, -1.2));
            }
            if x + 1 < m {
                rows.push((c + 1, -0.8));
            }
            if y > 0 {
                rows.push((c - m, -1.0));
            }
            if y + 1 < m {
                rows.push((c + m, -1.0));
            }
            rows.sort_by_key(|r| r.0);
            for (r, v) in rows {
                row_idx.push(r);
                values.push(v);
            }
            col_ptr.push(row_idx.len());
        }
        (n, col_ptr, row_idx, values)
    }

    /// Below the threshold the direct solver runs, above it the iterative
    /// one; a failed iterative solve falls back to the direct solver with
    /// the same answer.
    #[test]
    fn picks_by_size_and_falls_back_when_the_iterative_solve_fails() {
        let (n, col_ptr, row_idx, values) = system(12);
        let b: Vec<f64> = (0..n).map(|i| 1.0 + (i % 5) as f64).collect();
        let mut reference = FaerDirect::default();
        reference
            .analyse(n, &col_ptr, &row_idx, false)
            .expect("pattern");
        let mut x_ref = b.clone();
        reference.solve(&values, &mut x_ref).expect("solves");
        let close = |x: &[f64]| {
            x.iter()
                .zip(&x_ref)
                .all(|(a, r)| (a - r).abs() <= 1e-9 * r.abs().max(1.0))
        };

        let mut small = AutoLinear::new(n, IterativeOptions::default());
        small
            .analyse(n, &col_ptr, &row_idx, false)
            .expect("pattern");
        let mut x = b.clone();
        assert_eq!(small.solve(&values, &mut x), Ok(Factorisation::Lu));
        assert!(close(&x));

        let mut large = AutoLinear::new(n - 1, IterativeOptions::default());
        large
            .analyse(n, &col_ptr, &row_idx, false)
            .expect("pattern");
        let mut x = b.clone();
        assert_eq!(large.solve(&values, &mut x), Ok(Factorisation::Iterative));
        assert!(close(&x) && large.last_iterations() > 0);

        let starved = IterativeOptions {
            rel_tolerance: 1e-14,
            max_iterations: 1,
        };
        let mut failing = AutoLinear::new(0, starved);
        failing
            .analyse(n, &col_ptr, &row_idx, false)
            .expect("pattern");
        let mut x = b.clone();
        assert_eq!(failing.solve(&values, &mut x), Ok(Factorisation::Lu));
        assert!(close(&x) && failing.uses_direct());
    }
}
