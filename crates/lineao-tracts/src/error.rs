//! Typed load errors: which file, which byte, what was expected.

use std::io;
use std::path::PathBuf;

/// A file could not be loaded or written. Always names the file.
#[derive(Debug, thiserror::Error)]
#[error("{}: {kind}", path.display())]
pub struct Error {
    /// The file.
    pub path: PathBuf,
    /// What went wrong, and where in it.
    pub kind: ErrorKind,
}

/// What went wrong. Byte offsets count from the start of the file, or of the decompressed data
/// for gzip-wrapped files, or of the archive member for TRX (whose name is then in `expected`).
#[derive(Debug, thiserror::Error)]
pub enum ErrorKind {
    #[error("{0}")]
    /// Reading or writing failed.
    Io(#[from] io::Error),
    /// The bytes at `offset` are not what the format requires.
    #[error("at byte {offset}: expected {expected}")]
    Format {
        /// The first byte that is wrong.
        offset: u64,
        /// What the format requires there.
        expected: String,
    },
    /// A valid file of a known kind that holds no streamlines: a polygon mesh, a point cloud.
    #[error("no lines: {0}")]
    NoLines(String),
    /// The content matches none of the formats we read.
    #[error("not a tractography format we read ({0})")]
    UnknownFormat(String),
    /// Decompressing would exceed the configured limit (a gzip or zip bomb, or a file that needs
    /// [`crate::LoadOptions::max_inflated_bytes`] raised).
    #[error("at byte {offset}: decompressed data would exceed the limit of {limit} bytes")]
    TooLarge {
        /// Where in the compressed input the limit was reached.
        offset: u64,
        /// The limit in bytes.
        limit: u64,
    },
    /// Valid input that asks for something we do not do (e.g. writing to a format we only read).
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// The progress callback cancelled the load.
    #[error("loading was cancelled")]
    Cancelled,
}

impl ErrorKind {
    /// Attaches the file name.
    pub fn at(self, path: impl Into<PathBuf>) -> Error {
        Error { path: path.into(), kind: self }
    }

    /// The byte offset named by the error, if it names one.
    pub fn offset(&self) -> Option<u64> {
        match self {
            ErrorKind::Format { offset, .. } | ErrorKind::TooLarge { offset, .. } => Some(*offset),
            _ => None,
        }
    }
}

/// `Err(ErrorKind::Format { .. })` for the parsers.
pub(crate) fn bad<T>(offset: u64, expected: impl Into<String>) -> Result<T, ErrorKind> {
    Err(ErrorKind::Format { offset, expected: expected.into() })
}

pub(crate) type Parse<T> = Result<T, ErrorKind>;
