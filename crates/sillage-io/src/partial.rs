//! Files written under a temporary name (`.NAME.partial`) in the destination folder and
//! renamed on success, so a reader never sees a half-written file under the final name.
//! Outputs that are not regular files (`/dev/null`, a named pipe) are written in place.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use sillage_core::{Error, Result};

/// A file being written as `.NAME.partial` beside its final `path` (or, for a device or a
/// pipe, into `path` itself: `writes_in_place`).
///
/// Dropping it without [`PartialFile::commit`] leaves the partial file in place: after an
/// interrupted run it holds every row written so far.
#[derive(Debug)]
pub struct PartialFile {
    final_path: PathBuf,
    partial_path: PathBuf,
    writer: BufWriter<File>,
}

impl PartialFile {
    /// Creates (or truncates) `.NAME.partial` in the folder of `path`, or opens `path`
    /// itself when it is not a regular file.
    pub fn create(path: &Path) -> Result<Self> {
        let partial_path = write_target(path)?;
        let file = File::create(&partial_path).map_err(|e| Error::Io {
            path: partial_path.clone(),
            cause: e,
            hint: "check that the output folder exists and is writable".into(),
        })?;
        Ok(Self {
            final_path: path.to_path_buf(),
            partial_path,
            writer: BufWriter::new(file),
        })
    }

    /// The temporary path being written.
    pub fn partial_path(&self) -> &Path {
        &self.partial_path
    }

    /// Writes `bytes` whole, naming the partial file on error.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<()> {
        self.writer
            .write_all(bytes)
            .map_err(|e| Error::io(&self.partial_path, e))
    }

    /// Flushes, closes and renames the partial file to its final name.
    pub fn commit(self) -> Result<PathBuf> {
        let Self {
            final_path,
            partial_path,
            writer,
        } = self;
        // Flushed but not fsync'ed: the rename guards against interrupted runs, and an fsync
        // per synthetic frame would dominate the cost of writing long sequences.
        let file = writer
            .into_inner()
            .map_err(|e| Error::io(&partial_path, e.into_error()))?;
        drop(file);
        if partial_path != final_path {
            std::fs::rename(&partial_path, &final_path).map_err(|e| Error::io(&final_path, e))?;
        }
        Ok(final_path)
    }

    /// [`PartialFile::commit`] after syncing the data to the disk: for files that a run
    /// relies on after a crash (checkpoints), which must never name data not yet written.
    pub fn commit_synced(mut self) -> Result<PathBuf> {
        self.writer
            .flush()
            .map_err(|e| Error::io(&self.partial_path, e))?;
        self.writer
            .get_ref()
            .sync_all()
            .map_err(|e| Error::io(&self.partial_path, e))?;
        self.commit()
    }

    /// Gives up: removes the partial file (used when a one-shot write fails half way).
    pub fn abandon(self) {
        let Self {
            final_path,
            partial_path,
            writer,
        } = self;
        drop(writer);
        if partial_path != final_path {
            // Best effort: the original error is what the caller reports.
            let _ = std::fs::remove_file(partial_path);
        }
    }
}

/// Lets encoders (PNG, Parquet) write straight into the partial file.
impl Write for PartialFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.writer.flush()
    }
}

/// True when `path` names an existing file that is not a regular one (`/dev/null`, a named
/// pipe, a terminal): such an output is written in place, since renaming a temporary file
/// over it would replace the device or pipe with a regular file (for root, `/dev/null`
/// itself).
pub(crate) fn writes_in_place(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Where an output for `path` is written before it is committed: `path` itself when it
/// [`writes_in_place`], `.NAME.partial` beside it otherwise (nothing to rename then when
/// the two are equal).
pub(crate) fn write_target(path: &Path) -> Result<PathBuf> {
    if writes_in_place(path) {
        Ok(path.to_path_buf())
    } else {
        partial_path(path)
    }
}

/// `.NAME.partial` in the folder of `path`.
pub(crate) fn partial_path(path: &Path) -> Result<PathBuf> {
    hidden_beside(path, ".partial")
}

/// `.NAME` + `suffix` in the folder of `path`: the hidden files a run keeps beside its output.
pub(crate) fn hidden_beside(path: &Path, suffix: &str) -> Result<PathBuf> {
    let name = path.file_name().ok_or_else(|| {
        Error::input(format!(
            "output path `{}` has no file name; give a file such as `out/tracks.csv`",
            path.display()
        ))
    })?;
    let mut hidden = std::ffi::OsString::from(".");
    hidden.push(name);
    hidden.push(suffix);
    Ok(path.with_file_name(hidden))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partial_file_is_renamed_on_commit_only() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        let mut file = PartialFile::create(&path).unwrap();
        file.write_all(b"row\n").unwrap();
        let partial = file.partial_path().to_path_buf();
        assert_eq!(partial.file_name().unwrap(), ".out.txt.partial");
        assert!(!path.exists());
        assert_eq!(file.commit().unwrap(), path);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "row\n");
        assert!(!partial.exists());
    }

    #[test]
    fn dev_null_is_written_in_place_and_stays_a_device() {
        let null = Path::new("/dev/null");
        if !null.exists() {
            return;
        }
        assert!(writes_in_place(null));
        let mut file = PartialFile::create(null).unwrap();
        file.write_all(b"row\n").unwrap();
        assert_eq!(file.partial_path(), null);
        assert_eq!(file.commit().unwrap(), null);
        let metadata = std::fs::metadata(null).unwrap();
        assert!(!metadata.is_file(), "/dev/null became a regular file");
        assert!(!writes_in_place(&std::env::temp_dir()));
        let dir = tempfile::tempdir().unwrap();
        let regular = dir.path().join("out.txt");
        std::fs::write(&regular, "old").unwrap();
        assert!(!writes_in_place(&regular));
    }
}
