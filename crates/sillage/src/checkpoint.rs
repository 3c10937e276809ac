//! Checkpoint files of long runs: everything a run needs to continue after a crash, a
//! `kill -9` or a signal — the tracker's state (particles and random streams included), the
//! background model, the counts so far, the frames skipped, the length of the row spool at
//! that moment, and what the run was (program version, command, input, output, every
//! parameter) so that a checkpoint of another run is refused by name.
//!
//! The file, `OUT.checkpoint` beside the output, is a fixed header — [`MAGIC`], the format
//! version ([`CHECKPOINT_VERSION`]), the payload's length and CRC-32 — then the payload in
//! CBOR (exact floats, NaN included). It is written under a temporary name and renamed, so a
//! run killed while saving one leaves the previous checkpoint intact.

use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};
use sillage_io::{PartialFile, SkippedFrame};

use crate::pipeline::{PipelineState, RunTally};

/// The first bytes of a checkpoint file.
pub const MAGIC: &[u8; 19] = b"sillage checkpoint\n";

/// The version of the checkpoint format; a file of another version is refused.
pub const CHECKPOINT_VERSION: u32 = 1;

/// What a checkpoint belongs to: a resumed run must be the same run.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RunIdentity {
    /// `sillage X.Y.Z`.
    pub program: String,
    /// The command (`ptv`, `track bedload`).
    pub command: String,
    /// The input as given (frames, or a detections file).
    pub input: String,
    /// The output file.
    pub output: String,
    /// Every setting that changes the output, as `(key, value)`: the configuration's dotted
    /// keys, the output format, the bad-frame policy.
    pub settings: Vec<(String, String)>,
}

impl RunIdentity {
    /// An identity of this program's version.
    pub fn new(command: &str, input: &str, output: &Path, settings: Vec<(String, String)>) -> Self {
        Self {
            program: format!("sillage {}", env!("CARGO_PKG_VERSION")),
            command: command.to_string(),
            input: input.to_string(),
            output: output.display().to_string(),
            settings,
        }
    }

    /// How `saved` differs from this run, in words (`None`: the same run).
    pub fn difference(&self, saved: &Self) -> Option<String> {
        let field = |name: &str, now: &str, then: &str| {
            (now != then).then(|| format!("{name} was `{then}`, now `{now}`"))
        };
        field("the program", &self.program, &saved.program)
            .or_else(|| field("the command", &self.command, &saved.command))
            .or_else(|| field("the input", &self.input, &saved.input))
            .or_else(|| field("the output", &self.output, &saved.output))
            .or_else(|| {
                let find = |list: &[(String, String)], key: &str| {
                    list.iter()
                        .find(|(k, _)| k == key)
                        .map_or("(unset)".to_string(), |(_, v)| v.clone())
                };
                self.settings
                    .iter()
                    .chain(&saved.settings)
                    .map(|(key, _)| key)
                    .find_map(|key| {
                        field(key, &find(&self.settings, key), &find(&saved.settings, key))
                    })
            })
    }
}

/// A run's state after its last checkpointed frame.
#[derive(Serialize, Deserialize)]
pub struct Checkpoint {
    /// The run it belongs to.
    pub identity: RunIdentity,
    /// Counts so far; `tally.last_frame` is the last frame tracked.
    pub tally: RunTally,
    /// Length of the row spool holding every point emitted so far.
    pub spool_bytes: u64,
    /// Frames skipped so far (`--on-bad-frame skip`).
    pub skipped: Vec<SkippedFrame>,
    /// The detector's and tracker's state.
    pub state: PipelineState,
}

/// `OUT.checkpoint`, beside the output `out`.
pub fn checkpoint_path(out: &Path) -> PathBuf {
    let mut name = out.file_name().unwrap_or_default().to_os_string();
    name.push(".checkpoint");
    out.with_file_name(name)
}

/// Writes `checkpoint` to `path` atomically (synced, then renamed over the previous one).
pub fn write_checkpoint(path: &Path, checkpoint: &Checkpoint) -> Result<()> {
    let mut payload = Vec::new();
    ciborium::into_writer(checkpoint, &mut payload)
        .map_err(|e| Error::input(format!("cannot encode the checkpoint: {e}")))?;
    let mut file = PartialFile::create(path)?;
    file.write_all(MAGIC)?;
    file.write_all(&CHECKPOINT_VERSION.to_le_bytes())?;
    file.write_all(&(payload.len() as u64).to_le_bytes())?;
    file.write_all(&crc32fast::hash(&payload).to_le_bytes())?;
    file.write_all(&payload)?;
    file.flush().map_err(|e| Error::io(path, e))?;
    file.commit_synced()?;
    Ok(())
}

/// Reads the checkpoint at `path`, checking its header, version and checksum.
pub fn read_checkpoint(path: &Path) -> Result<Checkpoint> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let damaged = |what: &str| {
        Error::format(
            path,
            None,
            format!("{what}; delete it and run again without --resume"),
        )
    };
    let rest = bytes
        .strip_prefix(MAGIC.as_slice())
        .ok_or_else(|| damaged("not a sillage checkpoint"))?;
    let (version, rest) = rest
        .split_first_chunk::<4>()
        .ok_or_else(|| damaged("the checkpoint is truncated"))?;
    let version = u32::from_le_bytes(*version);
    if version != CHECKPOINT_VERSION {
        return Err(damaged(&format!(
            "the checkpoint has format version {version}, this program reads version \
             {CHECKPOINT_VERSION}"
        )));
    }
    let (length, rest) = rest
        .split_first_chunk::<8>()
        .ok_or_else(|| damaged("the checkpoint is truncated"))?;
    let (crc, payload) = rest
        .split_first_chunk::<4>()
        .ok_or_else(|| damaged("the checkpoint is truncated"))?;
    if payload.len() as u64 != u64::from_le_bytes(*length) {
        return Err(damaged("the checkpoint is truncated"));
    }
    if crc32fast::hash(payload) != u32::from_le_bytes(*crc) {
        return Err(damaged(
            "the checkpoint's checksum does not match: it is damaged",
        ));
    }
    ciborium::from_reader(payload)
        .map_err(|e| damaged(&format!("the checkpoint cannot be decoded ({e})")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Pipeline, PipelineConfig};

    fn identity(value: &str) -> RunIdentity {
        RunIdentity::new(
            "ptv",
            "frames/",
            Path::new("out.txt"),
            vec![("tracker.motion_av".into(), value.into())],
        )
    }

    fn checkpoint() -> Checkpoint {
        let pipeline = Pipeline::from_config(&PipelineConfig::default()).unwrap();
        Checkpoint {
            identity: identity("1"),
            tally: RunTally::default(),
            spool_bytes: 7,
            skipped: Vec::new(),
            state: pipeline.state(),
        }
    }

    #[test]
    fn a_checkpoint_reads_back_and_a_damaged_one_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = checkpoint_path(&dir.path().join("tracks.txt"));
        assert_eq!(path.file_name().unwrap(), "tracks.txt.checkpoint");
        write_checkpoint(&path, &checkpoint()).unwrap();
        let back = read_checkpoint(&path).unwrap();
        assert_eq!(back.identity, identity("1"));
        assert_eq!(back.spool_bytes, 7);
        let mut bytes = std::fs::read(&path).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        let err = read_checkpoint(&path).err().unwrap().to_string();
        assert!(err.contains("checksum"), "{err}");
        std::fs::write(&path, &bytes[..30]).unwrap();
        let err = read_checkpoint(&path).err().unwrap().to_string();
        assert!(err.contains("truncated"), "{err}");
        std::fs::write(&path, b"hello").unwrap();
        let err = read_checkpoint(&path).err().unwrap().to_string();
        assert!(err.contains("not a sillage checkpoint"), "{err}");
    }

    #[test]
    fn the_difference_names_the_setting_that_changed() {
        assert_eq!(identity("1").difference(&identity("1")), None);
        let diff = identity("2").difference(&identity("1")).unwrap();
        assert_eq!(diff, "tracker.motion_av was `1`, now `2`");
        let mut other = identity("1");
        other.input = "elsewhere/".into();
        let diff = identity("1").difference(&other).unwrap();
        assert!(diff.contains("the input was `elsewhere/`"), "{diff}");
    }
}
