//! Helpers shared by the fuzz targets.

use std::path::PathBuf;
use std::sync::OnceLock;

/// Writes `bytes` to the file `name` in this process's scratch folder (under the system
/// temporary folder, `$TMPDIR`) and returns its path, for the readers that take a path.
/// The folder is made once per process; each call overwrites the file.
pub fn scratch_file(name: &str, bytes: &[u8]) -> PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    let dir = DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("sillage-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("cannot create the scratch folder");
        dir
    });
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("cannot write the scratch file");
    path
}
