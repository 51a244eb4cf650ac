//! Small CSV tables (convergence tables, load–displacement curves): a
//! header and rows of numbers or text, written atomically.
//!
//! Fields are quoted as RFC 4180 requires (a field with a comma, quote or
//! line break is enclosed in double quotes, inner quotes doubled). Floats are
//! printed in the shortest form that reads back to the same `f64`; NaN and
//! infinity are refused with the column and row named.

use std::borrow::Cow;
use std::path::Path;

use super::atomic::atomic_write;
use super::text::format_f64;
use crate::OutputError;

/// One field of a row.
#[derive(Debug, Clone, PartialEq)]
pub enum CsvValue<'a> {
    /// A floating-point number; must be finite.
    Float(f64),
    /// A signed integer.
    Int(i64),
    /// An unsigned integer (step numbers, counts).
    Uint(u64),
    /// Text.
    Str(Cow<'a, str>),
}

impl From<f64> for CsvValue<'_> {
    fn from(x: f64) -> Self {
        Self::Float(x)
    }
}

impl From<i64> for CsvValue<'_> {
    fn from(x: i64) -> Self {
        Self::Int(x)
    }
}

impl From<i32> for CsvValue<'_> {
    fn from(x: i32) -> Self {
        Self::Int(i64::from(x))
    }
}

impl From<u64> for CsvValue<'_> {
    fn from(x: u64) -> Self {
        Self::Uint(x)
    }
}

impl From<u32> for CsvValue<'_> {
    fn from(x: u32) -> Self {
        Self::Uint(u64::from(x))
    }
}

impl From<usize> for CsvValue<'_> {
    fn from(x: usize) -> Self {
        // usize is at most 64 bits on every supported platform.
        Self::Uint(x as u64)
    }
}

impl<'a> From<&'a str> for CsvValue<'a> {
    fn from(s: &'a str) -> Self {
        Self::Str(Cow::Borrowed(s))
    }
}

impl From<String> for CsvValue<'_> {
    fn from(s: String) -> Self {
        Self::Str(Cow::Owned(s))
    }
}

/// A CSV table: a header and rows of the same width.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct CsvTable {
    header: Vec<String>,
    /// Rows, already encoded as CSV lines without the line break.
    lines: Vec<String>,
}

impl CsvTable {
    /// An empty table with the given column names.
    ///
    /// # Errors
    /// [`OutputError::InvalidName`] if there are no columns, or a name is
    /// empty or repeated.
    pub fn new<S: AsRef<str>>(header: &[S]) -> Result<Self, OutputError> {
        if header.is_empty() {
            return Err(OutputError::InvalidName {
                what: "CSV column",
                name: String::new(),
                reason: "a table needs at least one column",
            });
        }
        let mut names: Vec<String> = Vec::with_capacity(header.len());
        for h in header {
            let h = h.as_ref();
            let reason = if h.trim().is_empty() {
                Some("must not be empty")
            } else if names.iter().any(|n| n == h) {
                Some("is already used")
            } else {
                None
            };
            if let Some(reason) = reason {
                return Err(OutputError::InvalidName {
                    what: "CSV column",
                    name: h.to_owned(),
                    reason,
                });
            }
            names.push(h.to_owned());
        }
        Ok(Self {
            header: names,
            lines: Vec::new(),
        })
    }

    /// The column names.
    #[must_use]
    pub fn header(&self) -> &[String] {
        &self.header
    }

    /// Number of rows so far.
    #[must_use]
    pub fn n_rows(&self) -> usize {
        self.lines.len()
    }

    /// Appends a row. Nothing is appended if the row is invalid.
    ///
    /// # Errors
    /// [`OutputError::LengthMismatch`] (array `row <i>`) unless the row has
    /// one value per column; [`OutputError::NonFinite`] naming the column and
    /// the row index if a float is NaN or infinite.
    pub fn push_row(&mut self, row: &[CsvValue<'_>]) -> Result<(), OutputError> {
        let index = self.lines.len();
        if row.len() != self.header.len() {
            return Err(OutputError::LengthMismatch {
                array: format!("row {index}"),
                expected: self.header.len(),
                found: row.len(),
            });
        }
        let mut fields = Vec::with_capacity(row.len());
        for (value, column) in row.iter().zip(&self.header) {
            fields.push(match value {
                CsvValue::Float(x) if !x.is_finite() => {
                    return Err(OutputError::NonFinite {
                        array: column.clone(),
                        index,
                        value: *x,
                    });
                }
                CsvValue::Float(x) => format_f64(*x),
                CsvValue::Int(i) => i.to_string(),
                CsvValue::Uint(u) => u.to_string(),
                CsvValue::Str(s) => quote(s).into_owned(),
            });
        }
        self.lines.push(fields.join(","));
        Ok(())
    }

    /// The table as CSV text, header first, each line ending in `\n`.
    #[must_use]
    pub fn to_csv(&self) -> String {
        let mut s: String = self
            .header
            .iter()
            .map(|h| quote(h))
            .collect::<Vec<_>>()
            .join(",");
        s.push('\n');
        for line in &self.lines {
            s.push_str(line);
            s.push('\n');
        }
        s
    }

    /// Writes the table to `path` atomically.
    ///
    /// # Errors
    /// [`OutputError::Io`] if the file cannot be written.
    pub fn write(&self, path: &Path) -> Result<(), OutputError> {
        atomic_write(path, self.to_csv().as_bytes())
    }
}

/// Quotes a field if RFC 4180 requires it.
fn quote(s: &str) -> Cow<'_, str> {
    if s.contains([',', '"', '\n', '\r']) {
        Cow::Owned(format!("\"{}\"", s.replace('"', "\"\"")))
    } else {
        Cow::Borrowed(s)
    }
}
