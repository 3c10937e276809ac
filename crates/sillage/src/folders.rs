//! Output folders, created with an error that names them.

use std::path::Path;

use sillage_core::{Error, Result};

/// Creates `dir` and its parents; the error names the folder.
pub(crate) fn create_folder(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::input(format!("cannot create the folder {}: {e}", dir.display())))
}
