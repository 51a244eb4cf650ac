//! The crate's error type.

use std::path::PathBuf;

use thiserror::Error;

/// Everything that can go wrong while reading a scene and building its
/// problem.
///
/// Every variant names where the problem is: the line and column of the
/// scene file, the command-line override, or the file that could not be
/// read, so that the `mpm` program can print it as is.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SceneError {
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file (or, for a temporary file, the file it was to replace).
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A scene file (or the scene after overrides) is invalid at a known
    /// place.
    #[error("{origin}:{line}:{column}: {message}")]
    Scene {
        /// The file name, or whatever the text came from.
        origin: String,
        /// 1-based line.
        line: usize,
        /// 1-based column, in characters.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A scene is invalid as a whole (e.g. a required key is missing and the
    /// parser gave no position).
    #[error("{origin}: {message}")]
    SceneUnlocated {
        /// The file name, or whatever the text came from.
        origin: String,
        /// What is wrong.
        message: String,
    },
    /// A command-line override is not of the form `key=value`.
    #[error("malformed override `{text}`: {reason} (expected key=value, e.g. material.E=1e6)")]
    MalformedOverride {
        /// The override as given.
        text: String,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A well-formed override cannot be applied, or makes the scene invalid
    /// (unknown key, wrong type).
    #[error("override `{text}`: {message}")]
    Override {
        /// The override as given.
        text: String,
        /// What is wrong.
        message: String,
    },
}
