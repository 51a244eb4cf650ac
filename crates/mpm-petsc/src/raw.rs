//! The one module of the workspace that calls C: PETSc's KSP, Mat, Vec and
//! options through declarations bindgen generates at build time, wrapped
//! in owners that destroy what they create ([`Matrix`], [`Vector`],
//! [`Krylov`], [`Options`]) and calls whose error codes become
//! [`PetscError`] with PETSc's own message.
//!
//! PETSc is not thread-safe: every call of this module holds one process
//! lock ([`lock`]), taken by the safe API of this crate around whole
//! operations. PETSc is initialised once per process, on first use, with
//! its error handler replaced by one that records the message instead of
//! printing a trace, and without its signal handlers (Rust's stay).
#![allow(unsafe_code)]

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::ptr;
use std::sync::{Mutex, MutexGuard, OnceLock};

use crate::PetscError;

#[allow(
    non_upper_case_globals,
    non_camel_case_types,
    non_snake_case,
    dead_code,
    missing_docs,
    unnecessary_transmutes,
    clippy::all
)]
mod ffi {
    include!(concat!(env!("OUT_DIR"), "/petsc.rs"));
}

/// PETSc's index type (32 bits in Debian's `petsc-dev`).
pub type Int = ffi::PetscInt;

/// The lock every PETSc call is made under (see the module docs); taken
/// again on a thread that holds it, it only counts (objects dropped while
/// their owner holds the lock destroy themselves under it).
pub struct Session {
    _guard: Option<MutexGuard<'static, ()>>,
}

impl Drop for Session {
    fn drop(&mut self) {
        HELD.with(|h| h.set(h.get().saturating_sub(1)));
    }
}

/// A PETSc string (NUL-terminated or null) as an owned string.
fn text(p: *const c_char) -> String {
    if p.is_null() {
        String::new()
    } else {
        // SAFETY: PETSc passes NUL-terminated strings or null.
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }
}

static LOCK: Mutex<()> = Mutex::new(());
static INIT: OnceLock<Result<(), PetscError>> = OnceLock::new();

thread_local! {
    /// The message of the first error PETSc reported on this thread since
    /// the last [`check`].
    static LAST: std::cell::RefCell<Option<String>> = const { std::cell::RefCell::new(None) };
    /// How many [`Session`]s this thread holds.
    static HELD: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Takes the process lock, initialising PETSc on first use.
///
/// # Errors
/// PETSc's initialisation failed.
pub fn lock() -> Result<Session, PetscError> {
    let guard = (HELD.with(std::cell::Cell::get) == 0).then(|| {
        LOCK.lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    });
    HELD.with(|h| h.set(h.get() + 1));
    let session = Session { _guard: guard };
    INIT.get_or_init(initialise).clone()?;
    Ok(session)
}

/// Records PETSc's message instead of printing a trace (the handler
/// [`initialise`] installs).
unsafe extern "C" fn record_error(
    _comm: ffi::MPI_Comm,
    _line: c_int,
    func: *const c_char,
    _file: *const c_char,
    _code: ffi::PetscErrorCode,
    kind: ffi::PetscErrorType,
    message: *const c_char,
    _ctx: *mut c_void,
) -> ffi::PetscErrorCode {
    if kind == ffi::PETSC_ERROR_INITIAL {
        let what = format!("{}: {}", text(func), text(message).trim());
        LAST.with(|l| *l.borrow_mut() = Some(what));
    }
    _code
}

fn initialise() -> Result<(), PetscError> {
    // PETSc keeps argv, and MPI reads it up to its terminating null.
    let args: Vec<*mut c_char> = ["mpm", "-no_signal_handler"]
        .iter()
        .map(|a| CString::new(*a).map_or(ptr::null_mut(), CString::into_raw))
        .chain(std::iter::once(ptr::null_mut()))
        .collect();
    let argv: &'static mut [*mut c_char] = Vec::leak(args);
    let mut argc: c_int = 2;
    let mut argv_ptr = argv.as_mut_ptr();
    // SAFETY: argc/argv describe two leaked NUL-terminated strings and
    // a null;
    // PetscInitialize is called once (OnceLock) under the process lock.
    let code = unsafe { ffi::PetscInitialize(&mut argc, &mut argv_ptr, ptr::null(), ptr::null()) };
    check(code, "PetscInitialize")?;
    // SAFETY: a valid handler with PETSc's signature and no context.
    let code = unsafe { ffi::PetscPushErrorHandler(Some(record_error), ptr::null_mut()) };
    check(code, "PetscPushErrorHandler")
}

/// Turns a PETSc error code into a [`PetscError`] naming `call` and PETSc's
/// message.
fn check(code: ffi::PetscErrorCode, call: &'static str) -> Result<(), PetscError> {
    let recorded = LAST.with(|l| l.borrow_mut().take());
    if code == 0 {
        return Ok(());
    }
    let mut text: *const c_char = ptr::null();
    // SAFETY: PetscErrorMessage writes a pointer to a static string.
    unsafe { ffi::PetscErrorMessage(code, &mut text, ptr::null_mut()) };
    let generic = self::text(text);
    Err(PetscError::Call {
        call,
        code,
        message: recorded.map_or(generic.clone(), |r| format!("{generic} ({r})")),
    })
}

/// The communicator of all ranks (one rank when run without `mpirun`).
fn world() -> ffi::MPI_Comm {
    // SAFETY: PETSC_COMM_WORLD is set by PetscInitialize, which `lock`
    // has run.
    unsafe { ffi::PETSC_COMM_WORLD }
}

/// The number of processes PETSc's solvers run over
/// (`PETSC_COMM_WORLD`'s size: one unless started by `mpirun -n N`).
///
/// # Errors
/// PETSc failed.
pub fn processes(_s: &Session) -> Result<usize, PetscError> {
    let mut size: c_int = 0;
    // SAFETY: the world communicator of an initialised PETSc; out-pointer.
    check(
        unsafe { ffi::MPI_Comm_size(world(), &mut size) },
        "MPI_Comm_size",
    )?;
    usize::try_from(size).map_err(|_| PetscError::Size)
}

/// PETSc's `PETSC_DECIDE` as a local size: PETSc splits the rows evenly
/// over the processes.
pub const DECIDE: Int = ffi::PETSC_DECIDE as Int;

/// One solver's options in PETSc's global database under a prefix of its
/// own (`-mpm3_ksp_type cg`), so that the objects PETSc creates inside the
/// solver (block Jacobi's sub-solvers, `-sub_pc_type`) find them too;
/// cleared when dropped.
pub struct Options {
    prefix: CString,
    /// The options' names as given (`-ksp_type`).
    names: Vec<String>,
}

impl Options {
    /// The options of `text` (`-ksp_type cg -pc_type gamg` ...) under a
    /// new prefix.
    ///
    /// # Errors
    /// PETSc refused the text (or it holds a NUL byte).
    pub fn new(_s: &Session, text: &str) -> Result<Self, PetscError> {
        static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let id = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let prefix = format!("mpm{id}_");
        let (prefixed, names) = prefixed_options(text, &prefix);
        let c = CString::new(prefixed).map_err(|_| PetscError::Nul)?;
        let options = Self {
            prefix: CString::new(prefix).map_err(|_| PetscError::Nul)?,
            names,
        };
        // SAFETY: the global database (null) and a NUL-terminated string.
        check(
            unsafe { ffi::PetscOptionsInsertString(ptr::null_mut(), c.as_ptr()) },
            "PetscOptionsInsertString",
        )?;
        Ok(options)
    }

    /// The options no object has read, by the names given.
    ///
    /// # Errors
    /// PETSc failed to tell.
    pub fn unused(&self, _s: &Session) -> Result<Vec<String>, PetscError> {
        let mut left = Vec::new();
        for name in &self.names {
            // PetscOptionsUsed takes the name without its dash.
            let full = self.full_name(name)?;
            let bare = CString::new(&full.as_bytes()[1..]).map_err(|_| PetscError::Nul)?;
            let mut used = ffi::PETSC_FALSE;
            // SAFETY: the global database and a NUL-terminated name.
            check(
                unsafe { ffi::PetscOptionsUsed(ptr::null_mut(), bare.as_ptr(), &mut used) },
                "PetscOptionsUsed",
            )?;
            if used != ffi::PETSC_TRUE {
                left.push(name.clone());
            }
        }
        Ok(left)
    }

    /// `-ksp_type` under this prefix: `-mpm3_ksp_type`.
    fn full_name(&self, name: &str) -> Result<CString, PetscError> {
        let prefix = self.prefix.to_string_lossy();
        CString::new(format!("-{prefix}{}", &name[1..])).map_err(|_| PetscError::Nul)
    }
}

/// `text` with every option name (a `-` then a letter) under `prefix`, and
/// the names as given.
fn prefixed_options(text: &str, prefix: &str) -> (String, Vec<String>) {
    let is_name =
        |t: &str| t.starts_with('-') && t[1..].starts_with(|c: char| c.is_ascii_alphabetic());
    let mut names = Vec::new();
    let tokens: Vec<String> = text
        .split_whitespace()
        .map(|t| {
            if is_name(t) {
                names.push(t.to_owned());
                format!("-{prefix}{}", &t[1..])
            } else {
                t.to_owned()
            }
        })
        .collect();
    (tokens.join(" "), names)
}

impl Drop for Options {
    fn drop(&mut self) {
        if let Ok(_s) = lock() {
            for name in &self.names {
                if let Ok(full) = self.full_name(name) {
                    // SAFETY: the global database and a NUL-terminated
                    // name; errors cannot be reported from Drop.
                    unsafe { ffi::PetscOptionsClearValue(ptr::null_mut(), full.as_ptr()) };
                }
            }
        }
    }
}

/// A parallel AIJ matrix with a COO pattern.
pub struct Matrix(ffi::Mat);

// SAFETY (all three): PETSc objects are only touched under the process
// lock, so moving their handles between threads is sound.
unsafe impl Send for Matrix {}
unsafe impl Send for Vector {}
unsafe impl Send for Krylov {}

impl Matrix {
    /// An `n × n` matrix over all ranks (`local` rows on this one) whose
    /// pattern is the pairs `(rows[k], cols[k])` (global indices; values
    /// given later in the same order by [`Matrix::set_values`]).
    ///
    /// # Errors
    /// PETSc refused the sizes or the pattern.
    pub fn coo(
        _s: &Session,
        local: Int,
        n: Int,
        rows: &mut [Int],
        cols: &mut [Int],
        symmetric: bool,
    ) -> Result<Self, PetscError> {
        let mut m: ffi::Mat = ptr::null_mut();
        // SAFETY: out-pointer to a new matrix, destroyed in Drop.
        check(unsafe { ffi::MatCreate(world(), &mut m) }, "MatCreate")?;
        let matrix = Self(m);
        // SAFETY: a live matrix; the type name is PETSc's static string.
        unsafe {
            check(ffi::MatSetSizes(m, local, local, n, n), "MatSetSizes")?;
            check(
                ffi::MatSetType(m, ffi::MATAIJ.as_ptr().cast()),
                "MatSetType",
            )?;
            let count = ffi::PetscCount::try_from(rows.len()).map_err(|_| PetscError::Size)?;
            check(
                ffi::MatSetPreallocationCOO(m, count, rows.as_mut_ptr(), cols.as_mut_ptr()),
                "MatSetPreallocationCOO",
            )?;
            if symmetric {
                check(
                    ffi::MatSetOption(m, ffi::MAT_SYMMETRIC, ffi::PETSC_TRUE),
                    "MatSetOption",
                )?;
                check(
                    ffi::MatSetOption(m, ffi::MAT_SYMMETRY_ETERNAL, ffi::PETSC_TRUE),
                    "MatSetOption",
                )?;
            }
        }
        Ok(matrix)
    }

    /// Sets every value, in the order of the COO pattern.
    ///
    /// # Errors
    /// PETSc refused the values.
    pub fn set_values(&mut self, _s: &Session, values: &[f64]) -> Result<(), PetscError> {
        // SAFETY: a live matrix whose COO pattern has values.len() entries
        // (the caller's invariant, checked by the solver).
        check(
            unsafe { ffi::MatSetValuesCOO(self.0, values.as_ptr(), ffi::INSERT_VALUES) },
            "MatSetValuesCOO",
        )
    }

    /// Sets the near-null space spanned by `modes` (orthonormal whole
    /// vectors, the same on every process), which GAMG uses to build its
    /// coarse spaces.
    ///
    /// # Errors
    /// PETSc refused the space.
    pub fn set_near_null_space(
        &mut self,
        s: &Session,
        modes: &[Vec<f64>],
    ) -> Result<(), PetscError> {
        let mut vectors = Vec::with_capacity(modes.len());
        for mode in modes {
            let mut v = self.vector(s)?;
            v.write_whole(s, mode)?;
            vectors.push(v);
        }
        let raw: Vec<ffi::Vec> = vectors.iter().map(|v| v.0).collect();
        let count = Int::try_from(raw.len()).map_err(|_| PetscError::Size)?;
        let mut space: ffi::MatNullSpace = ptr::null_mut();
        // SAFETY: live vectors; the space takes its own references and is
        // released after the matrix took one.
        unsafe {
            check(
                ffi::MatNullSpaceCreate(world(), ffi::PETSC_FALSE, count, raw.as_ptr(), &mut space),
                "MatNullSpaceCreate",
            )?;
            let set = check(
                ffi::MatSetNearNullSpace(self.0, space),
                "MatSetNearNullSpace",
            );
            ffi::MatNullSpaceDestroy(&mut space);
            set
        }
    }

    /// $\|b - A x\|_2$, the true (unpreconditioned) residual norm of `x`.
    ///
    /// # Errors
    /// PETSc failed.
    pub fn residual_norm(&self, s: &Session, b: &Vector, x: &Vector) -> Result<f64, PetscError> {
        let r = self.vector(s)?;
        let mut norm = 0.0;
        // SAFETY: live matrix and vectors of its layout; `r` is destroyed
        // when dropped.
        unsafe {
            check(ffi::MatMult(self.0, x.0, r.0), "MatMult")?;
            check(ffi::VecAYPX(r.0, -1.0, b.0), "VecAYPX")?;
            check(ffi::VecNorm(r.0, ffi::NORM_2, &mut norm), "VecNorm")?;
        }
        Ok(norm)
    }

    /// A vector with the matrix's row layout.
    ///
    /// # Errors
    /// PETSc failed to create it.
    pub fn vector(&self, _s: &Session) -> Result<Vector, PetscError> {
        let mut v: ffi::Vec = ptr::null_mut();
        // SAFETY: a live matrix; out-pointer to a new vector.
        check(
            unsafe { ffi::MatCreateVecs(self.0, &mut v, ptr::null_mut()) },
            "MatCreateVecs",
        )?;
        Ok(Vector(v))
    }
}

impl Drop for Matrix {
    fn drop(&mut self) {
        if let Ok(_s) = lock() {
            // SAFETY: the matrix this owner created.
            unsafe { ffi::MatDestroy(&mut self.0) };
        }
    }
}

/// A parallel vector.
pub struct Vector(ffi::Vec);

impl Vector {
    /// Copies this rank's entries from `values`.
    ///
    /// # Errors
    /// The length is not the local size, or PETSc failed.
    pub fn write(&mut self, _s: &Session, values: &[f64]) -> Result<(), PetscError> {
        let mut a: *mut f64 = ptr::null_mut();
        // SAFETY: a live vector; the array is restored below.
        unsafe {
            check(ffi::VecGetArray(self.0, &mut a), "VecGetArray")?;
            let n = self.local_len();
            if n == values.len() {
                ptr::copy_nonoverlapping(values.as_ptr(), a, n);
            }
            check(ffi::VecRestoreArray(self.0, &mut a), "VecRestoreArray")?;
            if n != values.len() {
                return Err(PetscError::Length {
                    expected: n,
                    got: values.len(),
                });
            }
        }
        Ok(())
    }

    /// Copies this rank's entries into `out`.
    ///
    /// # Errors
    /// The length is not the local size, or PETSc failed.
    pub fn read(&self, _s: &Session, out: &mut [f64]) -> Result<(), PetscError> {
        let mut a: *const f64 = ptr::null();
        // SAFETY: a live vector; the array is restored below.
        unsafe {
            check(ffi::VecGetArrayRead(self.0, &mut a), "VecGetArrayRead")?;
            let n = self.local_len();
            if n == out.len() {
                ptr::copy_nonoverlapping(a, out.as_mut_ptr(), n);
            }
            check(
                ffi::VecRestoreArrayRead(self.0, &mut a),
                "VecRestoreArrayRead",
            )?;
            if n != out.len() {
                return Err(PetscError::Length {
                    expected: n,
                    got: out.len(),
                });
            }
        }
        Ok(())
    }

    /// This process's rows `lo..hi` of the vector.
    ///
    /// # Errors
    /// PETSc failed.
    pub fn owned(&self, _s: &Session) -> Result<std::ops::Range<usize>, PetscError> {
        let (mut lo, mut hi): (Int, Int) = (0, 0);
        // SAFETY: a live vector; out-pointers.
        check(
            unsafe { ffi::VecGetOwnershipRange(self.0, &mut lo, &mut hi) },
            "VecGetOwnershipRange",
        )?;
        let index = |i: Int| usize::try_from(i).map_err(|_| PetscError::Size);
        Ok(index(lo)?..index(hi)?)
    }

    /// Copies this process's rows from `whole`, the whole vector (the same
    /// on every process).
    ///
    /// # Errors
    /// `whole` is shorter than the rows, or PETSc failed.
    pub fn write_whole(&mut self, s: &Session, whole: &[f64]) -> Result<(), PetscError> {
        let rows = self.owned(s)?;
        let part = whole.get(rows.clone()).ok_or(PetscError::Length {
            expected: rows.end,
            got: whole.len(),
        })?;
        self.write(s, part)
    }

    fn local_len(&self) -> usize {
        let mut n: Int = 0;
        // SAFETY: a live vector.
        let code = unsafe { ffi::VecGetLocalSize(self.0, &mut n) };
        if code == 0 {
            usize::try_from(n).unwrap_or(0)
        } else {
            0
        }
    }
}

impl Drop for Vector {
    fn drop(&mut self) {
        if let Ok(_s) = lock() {
            // SAFETY: the vector this owner created.
            unsafe { ffi::VecDestroy(&mut self.0) };
        }
    }
}

/// A scatter of a parallel vector to a whole copy on every process
/// (`VecScatterCreateToAll`), made once for a vector layout and used for
/// every vector of it (collective).
pub struct ToAll {
    scatter: ffi::VecScatter,
    all: Vector,
}

// SAFETY: as for `Matrix`: touched only under the process lock.
unsafe impl Send for ToAll {}

impl ToAll {
    /// The scatter of vectors laid out as `like`.
    ///
    /// # Errors
    /// PETSc failed.
    pub fn new(_s: &Session, like: &Vector) -> Result<Self, PetscError> {
        let mut scatter: ffi::VecScatter = ptr::null_mut();
        let mut all: ffi::Vec = ptr::null_mut();
        // SAFETY: a live vector; out-pointers to a new scatter and a new
        // sequential vector, destroyed by this owner.
        check(
            unsafe { ffi::VecScatterCreateToAll(like.0, &mut scatter, &mut all) },
            "VecScatterCreateToAll",
        )?;
        Ok(Self {
            scatter,
            all: Vector(all),
        })
    }

    /// The whole of `from` into `whole`, on every process.
    ///
    /// # Errors
    /// The length is not the vector's, or PETSc failed.
    pub fn gather(
        &mut self,
        s: &Session,
        from: &Vector,
        whole: &mut [f64],
    ) -> Result<(), PetscError> {
        // SAFETY: a live scatter between `from`'s layout and `all`.
        unsafe {
            check(
                ffi::VecScatterBegin(
                    self.scatter,
                    from.0,
                    self.all.0,
                    ffi::INSERT_VALUES,
                    ffi::SCATTER_FORWARD,
                ),
                "VecScatterBegin",
            )?;
            check(
                ffi::VecScatterEnd(
                    self.scatter,
                    from.0,
                    self.all.0,
                    ffi::INSERT_VALUES,
                    ffi::SCATTER_FORWARD,
                ),
                "VecScatterEnd",
            )?;
        }
        self.all.read(s, whole)
    }
}

impl Drop for ToAll {
    fn drop(&mut self) {
        if let Ok(_s) = lock() {
            // SAFETY: the scatter this owner created.
            unsafe { ffi::VecScatterDestroy(&mut self.scatter) };
        }
    }
}

/// How a Krylov solve ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    /// PETSc's converged reason (positive: converged).
    pub reason: i32,
    /// Iterations made.
    pub iterations: usize,
    /// The last residual norm PETSc computed (preconditioned or not,
    /// following the method's norm type).
    pub residual_norm: f64,
}

/// A KSP solver with its preconditioner.
pub struct Krylov(ffi::KSP);

impl Krylov {
    /// A solver over `matrix`, with relative tolerance `rtol` and at most
    /// `max_it` iterations unless `options` say otherwise, then configured
    /// from `options`.
    ///
    /// # Errors
    /// PETSc refused an option (an unknown method, a bad value).
    pub fn new(
        _s: &Session,
        matrix: &Matrix,
        options: &Options,
        rtol: f64,
        max_it: Int,
    ) -> Result<Self, PetscError> {
        let mut k: ffi::KSP = ptr::null_mut();
        // SAFETY: out-pointer to a new KSP, destroyed in Drop.
        check(unsafe { ffi::KSPCreate(world(), &mut k) }, "KSPCreate")?;
        let ksp = Self(k);
        // SAFETY: live KSP, matrix and options.
        unsafe {
            check(
                ffi::KSPSetOptionsPrefix(k, options.prefix.as_ptr()),
                "KSPSetOptionsPrefix",
            )?;
            check(
                ffi::KSPSetOperators(k, matrix.0, matrix.0),
                "KSPSetOperators",
            )?;
            check(
                ffi::KSPSetTolerances(
                    k,
                    rtol,
                    ffi::PETSC_DEFAULT as f64,
                    ffi::PETSC_DEFAULT as f64,
                    max_it,
                ),
                "KSPSetTolerances",
            )?;
            check(ffi::KSPSetFromOptions(k), "KSPSetFromOptions")?;
        }
        Ok(ksp)
    }

    /// Builds the preconditioner for the matrix's current values.
    ///
    /// # Errors
    /// PETSc failed (a zero pivot, a bad sub-option).
    pub fn set_up(&mut self, _s: &Session) -> Result<(), PetscError> {
        // SAFETY: a live KSP.
        check(unsafe { ffi::KSPSetUp(self.0) }, "KSPSetUp")
    }

    /// Solves for `b` into `x`.
    ///
    /// # Errors
    /// PETSc failed; a solve that did not converge is an [`Outcome`] with
    /// a negative reason, not an error.
    pub fn solve(
        &mut self,
        _s: &Session,
        b: &Vector,
        x: &mut Vector,
    ) -> Result<Outcome, PetscError> {
        let mut reason: ffi::KSPConvergedReason = 0;
        let mut iterations: Int = 0;
        let mut residual_norm = 0.0;
        // SAFETY: live KSP and vectors.
        unsafe {
            check(ffi::KSPSolve(self.0, b.0, x.0), "KSPSolve")?;
            check(
                ffi::KSPGetConvergedReason(self.0, &mut reason),
                "KSPGetConvergedReason",
            )?;
            check(
                ffi::KSPGetIterationNumber(self.0, &mut iterations),
                "KSPGetIterationNumber",
            )?;
            check(
                ffi::KSPGetResidualNorm(self.0, &mut residual_norm),
                "KSPGetResidualNorm",
            )?;
        }
        Ok(Outcome {
            reason: reason as i32,
            iterations: usize::try_from(iterations).unwrap_or(0),
            residual_norm,
        })
    }

    /// The Krylov method's and the preconditioner's names (`cg`, `gamg`).
    ///
    /// # Errors
    /// PETSc failed.
    pub fn names(&self, _s: &Session) -> Result<(String, String), PetscError> {
        let mut kt: *const c_char = ptr::null();
        let mut pt: *const c_char = ptr::null();
        let mut pc: ffi::PC = ptr::null_mut();
        // SAFETY: a live KSP; the names are PETSc's static strings.
        unsafe {
            check(ffi::KSPGetType(self.0, &mut kt), "KSPGetType")?;
            check(ffi::KSPGetPC(self.0, &mut pc), "KSPGetPC")?;
            check(ffi::PCGetType(pc, &mut pt), "PCGetType")?;
        }
        Ok((text(kt), text(pt)))
    }

    /// The name of the last solve's converged reason
    /// (`DIVERGED_ITS` ...).
    ///
    /// # Errors
    /// PETSc failed.
    pub fn reason_name(&self, _s: &Session) -> Result<String, PetscError> {
        let mut p: *const c_char = ptr::null();
        // SAFETY: a live KSP; the name is PETSc's static string.
        check(
            unsafe { ffi::KSPGetConvergedReasonString(self.0, &mut p) },
            "KSPGetConvergedReasonString",
        )?;
        Ok(text(p))
    }
}

impl Drop for Krylov {
    fn drop(&mut self) {
        if let Ok(_s) = lock() {
            // SAFETY: the KSP this owner created.
            unsafe { ffi::KSPDestroy(&mut self.0) };
        }
    }
}
