//! An output rendered in memory, apart from where and how it is written.

use super::error::OutputError;
use super::write::write_bytes;
use std::path::PathBuf;

/// One output file rendered in memory: the path it is meant for and its contents.
///
/// Rendering and writing are apart so that a command checks every path before the work (an
/// [`OutputPlan`](super::OutputPlan)) and then writes each file through its checked outputs
/// ([`CheckedOutputs::write_output`](super::CheckedOutputs::write_output)); a library user who
/// needs no such plan writes it with [`OutputFile::save`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputFile {
    /// Where the file goes.
    pub path: PathBuf,
    /// Its contents: a figure's PNG or SVG bytes (as the path's extension says), a text's UTF-8.
    pub bytes: Vec<u8>,
}

impl OutputFile {
    /// The file `path` with contents `bytes`.
    pub fn new(path: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) -> Self {
        OutputFile {
            path: path.into(),
            bytes: bytes.into(),
        }
    }

    /// Writes the file at its path as every output is written (a regular file through a
    /// temporary renamed into place, missing directories created; a character device or FIFO
    /// in place), without a plan's checks against inputs.
    pub fn save(&self) -> Result<(), OutputError> {
        write_bytes(&self.path, &[], &self.bytes)
    }
}
