//! The crate's error type.

use std::path::PathBuf;

use mpm_output::OutputError;
use mpm_scene::SceneError;
use thiserror::Error;

/// Everything that can go wrong while running a case or a scene with its
/// outputs: the errors of the scene ([`SceneError`]) and of the result
/// files ([`OutputError`]), and those of runs, checkpoints and defaults.
///
/// Every variant names where the problem is: the file, the data array and
/// index, the line and column of a scene file, or the command-line override,
/// so that the `mpm` program can print it as is.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CasesError {
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file (or, for a temporary file, the file it was to replace).
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The background mesh could not be updated for output.
    #[error("background mesh: {source}")]
    Mesh {
        /// What went wrong.
        source: mpm_solver::MeshMotionError,
    },
    /// A checkpoint file that cannot be resumed from.
    #[error("{}: not a usable checkpoint: {reason}", path.display())]
    Checkpoint {
        /// The checkpoint file.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// A path that cannot be written to or referred to.
    #[error("{}: {reason}", path.display())]
    InvalidPath {
        /// The offending path.
        path: PathBuf,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// The solver failed, or stopped where it was asked to.
    #[error(transparent)]
    Solver(#[from] mpm_solver::SolverError),
    /// A case's default parameters cannot be written as TOML.
    #[error("cannot write the defaults as TOML: {source}")]
    Toml {
        /// The serialiser's error.
        source: toml::ser::Error,
    },
    /// A case's scene cannot be written as TOML.
    #[error("cannot write the {case} case's scene as TOML: {source}")]
    SceneToml {
        /// The case.
        case: &'static str,
        /// The serialiser's error.
        source: toml::ser::Error,
    },
    /// A scene file, an override or the problem it describes is invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A result file could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// A strength-reduction search ended without a factor that held and
    /// one that failed.
    #[error("strength_reduction: {}", no_bracket(*.held, *.failed, *.trials))]
    NoBracket {
        /// The largest factor that held, if any.
        held: Option<f64>,
        /// The smallest factor that failed, if any.
        failed: Option<f64>,
        /// Trials run.
        trials: usize,
    },
}

/// The message of [`CasesError::NoBracket`].
fn no_bracket(held: Option<f64>, failed: Option<f64>, trials: usize) -> String {
    match (held, failed) {
        (None, Some(f)) => format!(
            "every factor tried failed, down to {f} in {trials} trials; does the problem hold without reduction (run it without [strength_reduction])?"
        ),
        (Some(h), None) => {
            format!(
                "every factor tried held, up to {h} in {trials} trials; raise `upper` or `max_trials`"
            )
        }
        _ => format!("no bracket after {trials} trials"),
    }
}
