//! Checkpoints: after every converged load step the `mpm` program saves
//! everything needed to resume the run — the material points, the load
//! stepping state, the Newton predictor's memory and the output series
//! written so far — in one file, `checkpoint.mpm`, replaced atomically.
//! `mpm run ... --resume` continues from it and produces the same results
//! as an uninterrupted run.
//!
//! Format: the line `MPM-CHECKPOINT 1`, one line of JSON ([`Header`]),
//! then the material points' numbers and the predictor's increment as
//! little-endian `f64` (counts in the header).
//!
//! An explicit run ([`crate::scene::explicit`]) writes the same file at
//! each output time: `load_factor` is then the simulated time, `steps` the
//! time steps taken, the numbers are the explicit points' state (no
//! predictor) and `case_state` holds the output number, the work of the
//! point forces, the initial energies and the energy scale of the drift.

use std::path::Path;

use mpm_solver::{RunState, RunSummary};
use serde::{Deserialize, Serialize};

use crate::CasesError;
use crate::output::{OutputError, atomic_write_with};
use crate::run::Checkpoint;
use crate::writer::WriterState;

/// First line of a checkpoint file.
const MAGIC: &str = "MPM-CHECKPOINT 1";

/// The file name inside an output directory.
pub const FILE_NAME: &str = "checkpoint.mpm";

/// The JSON line of a checkpoint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Header {
    /// Case name.
    pub case: String,
    /// The case parameters (scene keys) the run was started with; a resume
    /// must name the same.
    pub parameters: serde_json::Value,
    /// Load factor reached.
    pub load_factor: f64,
    /// Increment of the next step.
    pub increment: f64,
    /// Converged steps so far.
    pub steps: usize,
    /// Cut steps so far.
    pub cut_steps: usize,
    /// Newton iterations so far.
    pub iterations: usize,
    /// Solver wall time so far (s).
    pub wall_time_s: f64,
    /// Number of `f64` of the material points.
    pub points_len: usize,
    /// Number of `f64` of the predictor's increment (0: none).
    pub predictor_len: usize,
    /// The predictor's load increment.
    pub predictor_load_increment: f64,
    /// The case's accumulators ([`Checkpoint::case_state`]).
    pub case_state: Vec<f64>,
    /// The rigid tools' contact forces ([`Checkpoint::contact`]; absent,
    /// and empty, without tools).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contact: Vec<f64>,
    /// The output written so far.
    pub writer: WriterState,
}

/// Writes `dir/checkpoint.mpm` atomically.
///
/// # Errors
/// [`CasesError::Io`] when the file cannot be written,
/// [`CasesError::NonFiniteField`] for a non-finite number.
pub fn write(
    dir: &Path,
    case: &str,
    parameters: serde_json::Value,
    checkpoint: &Checkpoint,
    writer: WriterState,
) -> Result<(), CasesError> {
    let (predictor, predictor_load_increment) = match &checkpoint.predictor {
        Some((u, dl)) => (u.as_slice(), *dl),
        None => (&[][..], 0.0),
    };
    if let Some(x) = checkpoint
        .points
        .iter()
        .chain(predictor)
        .chain(&checkpoint.case_state)
        .chain(&checkpoint.contact)
        .find(|x| !x.is_finite())
    {
        return Err(OutputError::NonFiniteField {
            field: "checkpoint".into(),
            value: *x,
        }
        .into());
    }
    let state = &checkpoint.state;
    let header = Header {
        case: case.to_string(),
        parameters,
        load_factor: state.load_factor,
        increment: state.increment,
        steps: state.summary.steps,
        cut_steps: state.summary.cut_steps,
        iterations: state.summary.iterations,
        wall_time_s: checkpoint.wall_time_s,
        points_len: checkpoint.points.len(),
        predictor_len: predictor.len(),
        predictor_load_increment,
        case_state: checkpoint.case_state.clone(),
        contact: checkpoint.contact.clone(),
        writer,
    };
    let json = serde_json::to_string(&header).map_err(|e| CasesError::Io {
        path: dir.join(FILE_NAME),
        source: std::io::Error::other(e),
    })?;
    Ok(atomic_write_with(&dir.join(FILE_NAME), |w| {
        writeln!(w, "{MAGIC}")?;
        writeln!(w, "{json}")?;
        for x in checkpoint.points.iter().chain(predictor) {
            w.write_all(&x.to_le_bytes())?;
        }
        Ok(())
    })?)
}

/// Reads `dir/checkpoint.mpm`.
///
/// # Errors
/// [`CasesError::Io`] when it cannot be read, [`CasesError::Checkpoint`]
/// when it is not a complete checkpoint.
pub fn read(dir: &Path) -> Result<(Header, Checkpoint), CasesError> {
    let path = dir.join(FILE_NAME);
    let bytes = std::fs::read(&path).map_err(|source| CasesError::Io {
        path: path.clone(),
        source,
    })?;
    let bad = |reason: String| CasesError::Checkpoint {
        path: path.clone(),
        reason,
    };
    let mut lines = bytes.splitn(3, |&b| b == b'\n');
    if lines.next() != Some(MAGIC.as_bytes()) {
        return Err(bad(format!("does not start with `{MAGIC}`")));
    }
    let json = lines.next().ok_or_else(|| bad("no header".into()))?;
    let header: Header = serde_json::from_slice(json).map_err(|e| bad(format!("header: {e}")))?;
    let payload = lines.next().unwrap_or_default();
    let expected = 8 * (header.points_len + header.predictor_len);
    if payload.len() != expected {
        return Err(bad(format!(
            "{} bytes of numbers, the header announces {expected}",
            payload.len()
        )));
    }
    let numbers: Vec<f64> = payload
        .chunks_exact(8)
        .map(|c| {
            let mut b = [0u8; 8];
            b.copy_from_slice(c);
            f64::from_le_bytes(b)
        })
        .collect();
    let (points, predictor) = numbers.split_at(header.points_len);
    let checkpoint = Checkpoint {
        state: RunState {
            load_factor: header.load_factor,
            increment: header.increment,
            summary: RunSummary {
                steps: header.steps,
                cut_steps: header.cut_steps,
                iterations: header.iterations,
            },
        },
        predictor: (!predictor.is_empty())
            .then(|| (predictor.to_vec(), header.predictor_load_increment)),
        points: points.to_vec(),
        wall_time_s: header.wall_time_s,
        case_state: header.case_state.clone(),
        contact: header.contact.clone(),
    };
    Ok((header, checkpoint))
}
