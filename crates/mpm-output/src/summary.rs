//! `summary.json`: the machine-readable result of a run (errors against the
//! reference, iteration counts, timings), written atomically.

use std::path::Path;

use serde::Serialize;

use super::atomic::atomic_write;
use super::finite::find_non_finite;
use crate::OutputError;

/// The JSON text of `value`, pretty-printed with a final newline.
///
/// # Errors
/// [`OutputError::NonFiniteField`] naming the first NaN or infinite float
/// (`serde_json` would silently write it as `null`);
/// [`OutputError::Json`] (with `path` as the intended file) if `value`'s
/// `Serialize` implementation fails, e.g. a map with non-string keys.
pub fn summary_json<T: Serialize + ?Sized>(value: &T, path: &Path) -> Result<String, OutputError> {
    if let Some((field, value)) = find_non_finite(value) {
        return Err(OutputError::NonFiniteField { field, value });
    }
    let mut text = serde_json::to_string_pretty(value).map_err(|source| OutputError::Json {
        path: path.to_path_buf(),
        source,
    })?;
    text.push('\n');
    Ok(text)
}

/// Writes `value` as pretty-printed JSON to `path` (conventionally
/// `summary.json`), atomically.
///
/// # Errors
/// As [`summary_json`], and [`OutputError::Io`] if the file cannot be
/// written. On error the old file, if any, is left as it was.
pub fn write_summary<T: Serialize + ?Sized>(path: &Path, value: &T) -> Result<(), OutputError> {
    let text = summary_json(value, path)?;
    atomic_write(path, text.as_bytes())
}
