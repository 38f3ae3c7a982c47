//! Why a glTF file could not be loaded, and the limits the loader enforces.

use std::path::{Path, PathBuf};

/// Largest texture side accepted (larger images are refused with a warning).
pub const MAX_TEXTURE_SIDE: u32 = 16384;

/// Largest file accepted, in bytes.
pub const MAX_FILE_BYTES: u64 = 2 << 30;

/// Why a glTF file could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file or one of its resources could not be read.
    #[error("cannot read {path}: {cause}")]
    Io {
        /// Path tried.
        path: PathBuf,
        /// Cause.
        cause: std::io::Error,
    },
    /// The file is empty.
    #[error("{0}: file is empty")]
    Empty(PathBuf),
    /// The file is not valid glTF (bad JSON, truncated GLB, failed validation).
    #[error("{path}: not a valid glTF file: {message}")]
    Invalid {
        /// File.
        path: PathBuf,
        /// What the parser said.
        message: String,
    },
    /// A URI points outside the model's folder (or is absolute, or a remote URL).
    #[error("{path}: {what} URI '{uri}' is refused: it points outside the model's folder")]
    OutsideFolder {
        /// File.
        path: PathBuf,
        /// "buffer 0", "image 3".
        what: String,
        /// The URI.
        uri: String,
    },
    /// A structural problem found while reading data (bounds, indices, counts).
    #[error("{path}: {message}")]
    Corrupt {
        /// File.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The file requires an extension umbra does not implement.
    #[error("{path}: requires unsupported extension {extension}")]
    UnsupportedExtension {
        /// File.
        path: PathBuf,
        /// Extension name.
        extension: String,
    },
}

pub(in crate::scene) fn invalid(path: &Path, e: impl std::fmt::Display) -> LoadError {
    LoadError::Invalid {
        path: path.into(),
        message: e.to_string().replace('\n', " "),
    }
}

pub(super) fn corrupt(path: &Path, message: String) -> LoadError {
    LoadError::Corrupt {
        path: path.into(),
        message,
    }
}
