//! Atomic replacement of a file: write a temporary file beside it, flush and
//! sync it, then rename it over the target.
//!
//! A reader (ParaView, a resumed run, a plotting script) therefore sees
//! either the old complete file or the new complete file, never a torn one,
//! even if the program is killed mid-write.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::OutputError;

/// Distinguishes temporary files of concurrent writes within one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// How many temporary names to try before giving up.
const MAX_ATTEMPTS: u32 = 16;

/// Writes `bytes` to `path` atomically.
///
/// The bytes go to a temporary file `.<name>.<pid>.<n>.tmp` in the same
/// directory, which is flushed, synced and then renamed over `path`. On any
/// error the temporary file is removed and `path` keeps its old content
/// (or stays absent).
///
/// # Errors
/// [`OutputError::InvalidPath`] if `path` has no file name;
/// [`OutputError::Io`] if the directory does not exist or any step fails.
pub fn atomic_write(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    atomic_write_with(path, |w| w.write_all(bytes))
}

/// Writes `path` atomically with the output of `write`, streamed through a
/// buffer (so large files need not be built in memory first).
///
/// `write` receives a buffered writer to the temporary file; if it returns
/// an error, nothing is renamed, the temporary file is removed and the old
/// `path` is untouched. See [`atomic_write`] for the procedure.
///
/// # Errors
/// As [`atomic_write`], plus whatever `write` returns, reported as
/// [`OutputError::Io`] on `path`.
pub fn atomic_write_with<F>(path: &Path, write: F) -> Result<(), OutputError>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let io_err = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let Some(name) = path.file_name() else {
        return Err(OutputError::InvalidPath {
            path: path.to_path_buf(),
            reason: "has no file name to write to",
        });
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let (tmp_path, file) = create_temporary(dir, &name.to_string_lossy()).map_err(io_err)?;

    let result = write_and_sync(file, write).and_then(|()| fs::rename(&tmp_path, path));
    if let Err(source) = result {
        // Best effort: the temporary file may already be gone; the error
        // that matters is `source`.
        let _ = fs::remove_file(&tmp_path);
        return Err(io_err(source));
    }
    sync_directory(dir);
    Ok(())
}

/// Creates a new, uniquely named temporary file in `dir`.
fn create_temporary(dir: &Path, name: &str) -> io::Result<(PathBuf, File)> {
    let pid = std::process::id();
    let mut last_error = None;
    for _ in 0..MAX_ATTEMPTS {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.{pid}.{n}.tmp"));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(file) => return Ok((tmp, file)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last_error = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last_error.unwrap_or_else(|| io::Error::other("no free temporary file name")))
}

/// Removes the temporary files of writes that never finished (the process
/// was killed or crashed between creating and renaming them) from `dir`,
/// and returns how many there were. Only names of the form
/// `.<name>.<pid>.<n>.tmp` that [`atomic_write`] uses are touched.
///
/// A run calls it when it starts, fresh or resumed, so that a directory
/// whose run has finished holds only complete files; two runs must
/// therefore not share an output directory.
///
/// # Errors
/// [`OutputError::Io`] if `dir` cannot be read or a temporary file cannot
/// be removed.
pub fn remove_temporaries(dir: &Path) -> Result<usize, OutputError> {
    let io_err = |path: PathBuf| move |source| OutputError::Io { path, source };
    let mut removed = 0;
    for entry in fs::read_dir(dir).map_err(io_err(dir.to_path_buf()))? {
        let entry = entry.map_err(io_err(dir.to_path_buf()))?;
        let temporary = entry.file_name().to_str().is_some_and(is_temporary)
            && entry.file_type().is_ok_and(|t| t.is_file());
        if !temporary {
            continue;
        }
        match fs::remove_file(entry.path()) {
            Ok(()) => removed += 1,
            // Gone in between: nothing left to remove.
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(source) => return Err(io_err(entry.path())(source)),
        }
    }
    Ok(removed)
}

/// Whether `file` is a name [`create_temporary`] gives:
/// `.<name>.<pid>.<n>.tmp`.
fn is_temporary(file: &str) -> bool {
    let Some(inner) = file.strip_prefix('.').and_then(|s| s.strip_suffix(".tmp")) else {
        return false;
    };
    let mut parts = inner.rsplitn(3, '.');
    let mut number = || {
        parts
            .next()
            .is_some_and(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()))
    };
    number() && number() && parts.next().is_some_and(|name| !name.is_empty())
}

/// Runs `write` on a buffered writer to `file`, then flushes and syncs it.
fn write_and_sync<F>(file: File, write: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let file = writer
        .into_inner()
        .map_err(io::IntoInnerError::into_error)?;
    file.sync_all()
}

/// Makes the rename durable where the platform allows it.
///
/// Failure is ignored on purpose: some file systems refuse to sync a
/// directory, and the rename itself has already succeeded, so the new file
/// is complete and visible; only its survival of a power cut is at stake.
fn sync_directory(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}
