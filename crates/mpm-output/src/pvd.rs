//! ParaView data collections (`.pvd`): the index of a time series of `.vtu`
//! files, which ParaView opens as one animated data set.
//!
//! The collection is rewritten atomically after every step, so a run that
//! is interrupted still leaves a valid series of the steps written so far.

use std::fmt::Write as _;
use std::path::{Component, Path, PathBuf};

use super::atomic::atomic_write;
use super::text::{push_f64, xml_escape};
use crate::OutputError;

/// One step of a series: its time and the data file, as written into the
/// `.pvd` (relative to the collection's directory where possible).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PvdStep {
    /// The step's time.
    pub time: f64,
    /// The data file's path as written into the collection.
    pub file: String,
}

/// A `.pvd` time series being written.
#[derive(Debug, Clone)]
pub struct PvdSeries {
    path: PathBuf,
    steps: Vec<PvdStep>,
}

impl PvdSeries {
    /// An empty series that will be written to `path`. Nothing is written
    /// until the first [`PvdSeries::push`] (or [`PvdSeries::write`]).
    #[must_use]
    pub fn new(path: impl Into<PathBuf>) -> Self {
        Self {
            path: path.into(),
            steps: Vec::new(),
        }
    }
    /// A collection at `path` that already lists `steps` (a resumed run);
    /// nothing is written until the next [`PvdSeries::push`].
    #[must_use]
    pub fn with_steps(path: impl Into<PathBuf>, steps: Vec<PvdStep>) -> Self {
        Self {
            path: path.into(),
            steps,
        }
    }

    /// Where the collection is written.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The steps so far, in time order.
    #[must_use]
    pub fn steps(&self) -> &[PvdStep] {
        &self.steps
    }

    /// Appends a step and rewrites the collection atomically.
    ///
    /// `file` is the data file of this step. A relative path is taken
    /// relative to the collection's directory, which is how ParaView reads
    /// it; a path that begins with the collection's directory (e.g.
    /// `out/points_0001.vtu` for `out/points.pvd`) is made relative to it.
    /// If the write fails the step is not kept, so the call can be retried.
    ///
    /// # Errors
    /// [`OutputError::InvalidTime`] unless `time` is finite and after the
    /// previous step's; [`OutputError::InvalidPath`] if `file` is not valid
    /// UTF-8 or has no file name; [`OutputError::Io`] if the collection cannot
    /// be written.
    pub fn push(&mut self, time: f64, file: &Path) -> Result<(), OutputError> {
        let previous = self.steps.last().map_or(f64::NEG_INFINITY, |s| s.time);
        if !time.is_finite() || time <= previous {
            return Err(OutputError::InvalidTime { previous, time });
        }
        let file = self.relative_name(file)?;
        self.steps.push(PvdStep { time, file });
        let result = self.write();
        if result.is_err() {
            self.steps.pop();
        }
        result
    }

    /// The collection's XML document.
    #[must_use]
    pub fn to_xml(&self) -> String {
        let mut s = String::new();
        s.push_str("<?xml version=\"1.0\"?>\n");
        s.push_str("<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n");
        s.push_str("  <Collection>\n");
        for step in &self.steps {
            s.push_str("    <DataSet timestep=\"");
            push_f64(&mut s, step.time);
            // Writing into a String cannot fail.
            let _ = writeln!(s, "\" part=\"0\" file=\"{}\"/>", xml_escape(&step.file));
        }
        s.push_str("  </Collection>\n");
        s.push_str("</VTKFile>\n");
        s
    }

    /// Writes the collection as it stands, atomically.
    ///
    /// # Errors
    /// [`OutputError::Io`] if the file cannot be written.
    pub fn write(&self) -> Result<(), OutputError> {
        atomic_write(&self.path, self.to_xml().as_bytes())
    }

    /// `file` as it should appear in the collection.
    fn relative_name(&self, file: &Path) -> Result<String, OutputError> {
        if file.file_name().is_none() {
            return Err(OutputError::InvalidPath {
                path: file.to_path_buf(),
                reason: "has no file name",
            });
        }
        let dir = self.path.parent().unwrap_or(Path::new(""));
        let relative = if dir.as_os_str().is_empty() {
            file
        } else {
            file.strip_prefix(dir).unwrap_or(file)
        };
        let mut parts = Vec::new();
        for c in relative.components() {
            match c {
                Component::Normal(p) => parts.push(p.to_str().ok_or(OutputError::InvalidPath {
                    path: file.to_path_buf(),
                    reason: "is not valid UTF-8",
                })?),
                Component::CurDir => {}
                Component::ParentDir => parts.push(".."),
                Component::RootDir | Component::Prefix(_) => {
                    // An absolute path outside the collection's directory:
                    // keep it as the platform writes it.
                    return relative
                        .to_str()
                        .map(str::to_owned)
                        .ok_or(OutputError::InvalidPath {
                            path: file.to_path_buf(),
                            reason: "is not valid UTF-8",
                        });
                }
            }
        }
        Ok(parts.join("/"))
    }
}
