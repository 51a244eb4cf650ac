//! [`PetscLinear`]: the implicit solver's linear solve through PETSc.
//!
//! Per load step ([`LinearSolver::analyse`]) the free-dof pattern becomes
//! a COO preallocation of a parallel AIJ matrix (`MatSetPreallocationCOO`)
//! and a KSP is configured from the options string; per Newton iteration
//! ([`LinearSolver::solve`]) the values are set in the pattern's own order
//! (`MatSetValuesCOO`, no copy or sort), the preconditioner is rebuilt for
//! them and the system solved. When the options choose GAMG, the rigid-body
//! modes of the free dofs are its near-null space.
//!
//! Options no PETSc object read after the first solve are an error
//! ([`PetscError::Unused`], a [`LinearSolveError::Configuration`], on
//! which Newton stops at once rather than cut the step): a misspelt
//! `-pc_type` must not silently run another method. A solve that does not converge is
//! [`LinearSolveError::NotConverged`] when it reached its iteration limit,
//! as for the built-in iterative solver, so Newton cuts the step the same
//! way; another divergence (a breakdown, an indefinite preconditioner) is
//! [`LinearSolveError::Backend`] with PETSc's reason.

use mpm_solver::linear::{check_dimensions, check_pattern};
use mpm_solver::{Factorisation, IterativeOptions, LinearSolveError, LinearSolver};

use crate::PetscError;
use crate::raw::{self, Int, Krylov, Matrix, Options, ToAll, Vector};

/// PETSc's `KSP_DIVERGED_ITS`: the iteration limit reached.
const DIVERGED_ITS: i32 = -3;

/// A PETSc KSP as the implicit solver's [`LinearSolver`] (module docs).
pub struct PetscLinear {
    options: String,
    tolerances: IterativeOptions,
    step: Option<Step>,
    modes: Vec<Vec<f64>>,
    checked_options: bool,
    last: Option<Factorisation>,
    iterations: usize,
    /// Whether PETSc runs over more than one process.
    over_ranks: bool,
}

/// What one load step's pattern holds.
struct Step {
    n: usize,
    nnz: usize,
    /// Over ranks: the positions of this rank's entries in the pattern,
    /// and their values gathered for PETSc; empty otherwise.
    entries: Vec<usize>,
    part: Vec<f64>,
    matrix: Matrix,
    ksp: Krylov,
    options: Options,
    b: Vector,
    x: Vector,
    /// The solution's scatter to every process, made once per step.
    to_all: ToAll,
}

impl std::fmt::Debug for PetscLinear {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PetscLinear")
            .field("options", &self.options)
            .field("tolerances", &self.tolerances)
            .field("analysed", &self.step.as_ref().map(|s| (s.n, s.nnz)))
            .finish_non_exhaustive()
    }
}

impl PetscLinear {
    /// A solver configured by PETSc's `options` (e.g.
    /// `-ksp_type cg -pc_type gamg`; empty: PETSc's defaults, GMRES with
    /// ILU(0) on one rank), with `tolerances` (relative residual and
    /// iteration limit) unless the options set `-ksp_rtol` / `-ksp_max_it`.
    pub fn new(options: &str, tolerances: IterativeOptions) -> Self {
        Self {
            options: options.to_owned(),
            tolerances,
            step: None,
            modes: Vec::new(),
            checked_options: false,
            last: None,
            iterations: 0,
            // An error here surfaces at the first analysis.
            over_ranks: raw::lock()
                .and_then(|s| raw::processes(&s))
                .is_ok_and(|n| n > 1),
        }
    }

    /// The Krylov method's and the preconditioner's names of the analysed
    /// step (`("cg", "gamg")`), as PETSc resolved the options.
    ///
    /// # Errors
    /// No step analysed, or PETSc failed.
    pub fn methods(&self) -> Result<(String, String), LinearSolveError> {
        let step = self.step.as_ref().ok_or(LinearSolveError::NotAnalysed)?;
        let s = raw::lock()?;
        Ok(step.ksp.names(&s)?)
    }

    fn uses_gamg(&self) -> bool {
        self.options
            .split_whitespace()
            .collect::<Vec<_>>()
            .windows(2)
            .any(|w| w[0] == "-pc_type" && w[1] == "gamg")
    }

    /// The COO pairs of the pattern's entries at `entries` (positions,
    /// ascending), or of all of them (CSC order, so values need no
    /// reordering).
    fn coo(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        entries: Option<&[usize]>,
    ) -> Result<(Vec<Int>, Vec<Int>), PetscError> {
        let index = |i: usize| Int::try_from(i).map_err(|_| PetscError::Size);
        let count = entries.map_or(row_idx.len(), <[usize]>::len);
        let mut rows = Vec::with_capacity(count);
        let mut cols = Vec::with_capacity(count);
        let mut wanted = entries.map(|e| e.iter().peekable());
        for c in 0..n {
            let col = index(c)?;
            for at in col_ptr[c]..col_ptr[c + 1] {
                if let Some(w) = &mut wanted {
                    if w.next_if_eq(&&at).is_none() {
                        continue;
                    }
                }
                rows.push(index(row_idx[at])?);
                cols.push(col);
            }
        }
        if rows.len() != count {
            return Err(PetscError::Length {
                expected: count,
                got: rows.len(),
            });
        }
        Ok((rows, cols))
    }

    /// The step of the pattern, of its `entries` only over ranks.
    fn build_step(
        &self,
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        symmetric: bool,
        entries: Option<&[usize]>,
    ) -> Result<Step, PetscError> {
        let (mut rows, mut cols) = Self::coo(n, col_ptr, row_idx, entries)?;
        let size = Int::try_from(n).map_err(|_| PetscError::Size)?;
        let local = if entries.is_some() { raw::DECIDE } else { size };
        let max_it = Int::try_from(self.tolerances.max_iterations).unwrap_or(Int::MAX);
        let s = raw::lock()?;
        let matrix = Matrix::coo(&s, local, size, &mut rows, &mut cols, symmetric)?;
        let options = Options::new(&s, &self.options)?;
        let ksp = Krylov::new(&s, &matrix, &options, self.tolerances.rel_tolerance, max_it)?;
        let b = matrix.vector(&s)?;
        let x = matrix.vector(&s)?;
        let to_all = ToAll::new(&s, &x)?;
        Ok(Step {
            n,
            nnz: row_idx.len(),
            entries: entries.map(<[usize]>::to_vec).unwrap_or_default(),
            part: Vec::new(),
            matrix,
            ksp,
            options,
            b,
            x,
            to_all,
        })
    }
}

impl LinearSolver for PetscLinear {
    fn analyse(
        &mut self,
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        symmetric: bool,
    ) -> Result<(), LinearSolveError> {
        self.step = None;
        self.modes.clear();
        check_pattern(n, col_ptr, row_idx)?;
        if self.over_ranks {
            return Err(LinearSolveError::Configuration {
                library: "PETSc",
                message: "PETSc runs over several processes: the system must come in \
                          parts, one per rank of a distributed run"
                    .into(),
            });
        }
        self.step = Some(self.build_step(n, col_ptr, row_idx, symmetric, None)?);
        Ok(())
    }

    fn solves_over_ranks(&self) -> bool {
        self.over_ranks
    }

    fn analyse_part(
        &mut self,
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        symmetric: bool,
        entries: &[usize],
    ) -> Result<(), LinearSolveError> {
        if !self.over_ranks {
            return self.analyse(n, col_ptr, row_idx, symmetric);
        }
        self.step = None;
        self.modes.clear();
        check_pattern(n, col_ptr, row_idx)?;
        let within = entries.last().is_none_or(|&e| e < row_idx.len());
        if !within || entries.windows(2).any(|w| w[0] >= w[1]) {
            return Err(LinearSolveError::InvalidPattern {
                n,
                reason: "a rank's entries must be ascending positions in the pattern",
            });
        }
        let step = self.build_step(n, col_ptr, row_idx, symmetric, Some(entries))?;
        self.step = Some(step);
        Ok(())
    }

    fn solve(
        &mut self,
        values: &[f64],
        rhs: &mut [f64],
    ) -> Result<Factorisation, LinearSolveError> {
        self.last = None;
        let step = self.step.as_mut().ok_or(LinearSolveError::NotAnalysed)?;
        check_dimensions(step.nnz, step.n, values, rhs)?;
        let b_norm = rhs.iter().map(|v| v * v).sum::<f64>().sqrt();
        let s = raw::lock()?;
        if self.over_ranks {
            step.part.clear();
            step.part.extend(step.entries.iter().map(|&e| values[e]));
            step.matrix.set_values(&s, &step.part)?;
        } else {
            step.matrix.set_values(&s, values)?;
        }
        if !self.modes.is_empty() {
            step.matrix.set_near_null_space(&s, &self.modes)?;
            self.modes.clear();
        }
        step.b.write_whole(&s, rhs)?;
        let outcome = step.ksp.solve(&s, &step.b, &mut step.x)?;
        if !self.checked_options {
            let unused = step.options.unused(&s)?;
            if !unused.is_empty() {
                return Err(PetscError::Unused(unused.join(", ")).into());
            }
            self.checked_options = true;
        }
        self.iterations = outcome.iterations;
        if outcome.reason == DIVERGED_ITS {
            // PETSc's own residual norm is the preconditioned one for
            // left-preconditioned methods (GMRES by default): the ratio
            // to |b| reported is the true residual's.
            let residual = step.matrix.residual_norm(&s, &step.b, &step.x)?;
            return Err(LinearSolveError::NotConverged {
                iterations: outcome.iterations,
                relative_residual: residual / b_norm.max(f64::MIN_POSITIVE),
            });
        }
        if outcome.reason < 0 {
            let reason = step.ksp.reason_name(&s)?;
            return Err(LinearSolveError::Backend {
                library: "PETSc",
                message: format!(
                    "KSP did not converge ({reason}) in {} iterations, residual norm {:.3e} against |b| = {b_norm:.3e}",
                    outcome.iterations, outcome.residual_norm
                ),
            });
        }
        step.to_all.gather(&s, &step.x, rhs)?;
        if let Some(dof) = rhs.iter().position(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite {
                factorisation: Factorisation::Iterative,
                dof,
            });
        }
        self.last = Some(Factorisation::Iterative);
        Ok(Factorisation::Iterative)
    }

    fn last_factorisation(&self) -> Option<Factorisation> {
        self.last
    }

    fn nnz(&self) -> usize {
        self.step.as_ref().map_or(0, |s| s.nnz)
    }

    fn last_iterations(&self) -> usize {
        self.iterations
    }

    fn wants_rigid_body_modes(&self) -> bool {
        self.uses_gamg()
    }

    fn set_rigid_body_modes(&mut self, modes: &[Vec<f64>]) -> Result<(), LinearSolveError> {
        self.modes = modes.to_vec();
        Ok(())
    }
}
