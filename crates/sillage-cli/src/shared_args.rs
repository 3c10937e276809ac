//! Argument types shared by several commands: the `--json` flag, the `--config FILE` and
//! `--set KEY=VALUE` pair, and the inputs and formats several commands read.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

/// `--json`, flattened into every command that prints a summary.
#[derive(Debug, Args, Clone, Copy)]
pub struct JsonArg {
    /// Print a machine-readable summary on stdout.
    #[arg(id = "json", long = "json")]
    pub enabled: bool,
}

/// `--config FILE` and `--set KEY=VALUE`: the command's parameters from a TOML file, then
/// dotted overrides, flattened into every command that has them.
#[derive(Debug, Args, Clone, Default)]
pub struct ConfigFileArgs {
    /// TOML file of the command's parameters.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Override one parameter, e.g. `--set section.key=value` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
}

/// What track colours show (`--colour`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ColourArg {
    /// Speed, on the viridis map.
    Speed,
    /// Motion state (tables with a `motion_state` column).
    State,
    /// Track identity.
    Id,
}

/// Formats of the track tables `plot` and `overlay` read (`--format`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TableFormatArg {
    /// TracTrac's `_track.txt`.
    Tractrac,
    /// CSV with trackpy column names (`frame,particle,x,y,...`).
    Csv,
    /// Apache Parquet.
    Parquet,
    /// HDF5.
    Hdf5,
    /// BeadTracking's CSV (`frame,id,x,y,category,...`), as `track bedload` writes it.
    Beads,
    /// MOTChallenge results (`track immpf`/`siftpf`): box centres.
    Mot,
}

/// The track table of `plot` and `overlay`.
#[derive(Debug, Args)]
pub struct TracksInputArgs {
    /// Track table: TracTrac `_track.txt`, CSV, Parquet, HDF5, a bead CSV or MOTChallenge
    /// results (boxes drawn by their centres).
    #[arg(value_name = "TRACKS")]
    pub tracks: PathBuf,
    /// Format of TRACKS (default: from its extension and first line).
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub format: Option<TableFormatArg>,
    /// What track colours show (default: state for tables with motion states, else speed).
    #[arg(long, value_enum)]
    pub colour: Option<ColourArg>,
    /// Detections CSV (`frame,x,y[,class,score]`, as `sillage detect` writes): counted per
    /// frame, or circled on overlays.
    #[arg(long, value_name = "FILE")]
    pub detections: Option<PathBuf>,
}

/// Where the configuration comes from; later sources override earlier ones.
#[derive(Debug, Args, Clone, Default)]
pub struct ConfigArgs {
    /// `--config FILE` and `--set KEY=VALUE`: the parameters.
    #[command(flatten)]
    pub params: ConfigFileArgs,
    /// A TracTrac `*_par.txt` parameter file, read as it is.
    #[arg(long, value_name = "FILE")]
    pub tractrac_par: Option<PathBuf>,
}

/// Output file formats for trajectories.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum FormatArg {
    /// TracTrac's 11-column `*_track.txt`.
    Tractrac,
    /// CSV with trackpy column names.
    Csv,
    /// Apache Parquet with trackpy column names.
    Parquet,
    /// HDF5 (needs the `hdf5` cargo feature).
    Hdf5,
}

/// A frame size written `WIDTHxHEIGHT`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameSize(pub (usize, usize));

impl std::str::FromStr for FrameSize {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let (w, h) = text
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("`{text}` is not WIDTHxHEIGHT, e.g. 768x576"))?;
        let parse = |v: &str| {
            v.trim()
                .parse::<usize>()
                .ok()
                .filter(|&n| n > 0)
                .ok_or_else(|| format!("`{text}`: `{v}` is not a size in px > 0"))
        };
        Ok(Self((parse(w)?, parse(h)?)))
    }
}

/// Options of the bead detector shared by `detect bead` and `track bedload FRAMES`.
#[derive(Debug, Args, Clone, Default)]
pub struct BeadDetectorArgs {
    /// BeadTracking `sequence_param.txt`: bead diameters and scale.
    #[arg(long, value_name = "FILE")]
    pub sequence_params: Option<PathBuf>,
    /// Image of the fixed flume base (white = base, never beads).
    #[arg(long, value_name = "FILE")]
    pub mask: Option<PathBuf>,
    /// Ring template of the transparent beads: a CSV matrix or an image (default: built
    /// from the bead sizes).
    #[arg(long, value_name = "FILE")]
    pub template: Option<PathBuf>,
    /// TOML detector parameters (`BeadParams`).
    #[arg(long, value_name = "FILE")]
    pub detector_config: Option<PathBuf>,
    /// Override one detector key, e.g. `--detector-set transparent_threshold=0.23`
    /// (repeatable).
    #[arg(long = "detector-set", value_name = "KEY=VALUE")]
    pub detector_overrides: Vec<String>,
}

/// What to do with a frame that cannot be read (`--on-bad-frame`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum BadFrameArg {
    /// Stop with an error naming the frame.
    #[default]
    Stop,
    /// Skip it, as a missed frame (trackers predict through it), and report it.
    Skip,
}

/// `--on-bad-frame`, `--checkpoint-every` and `--resume`: long runs that survive bad
/// frames, crashes and signals.
#[derive(Debug, Args, Clone)]
pub struct LongRunArgs {
    /// A frame that does not decode, has the wrong size or is missing from a numbered
    /// sequence: stop there, or skip it as a missed frame and report it.
    #[arg(long, value_enum, default_value_t = BadFrameArg::Stop)]
    pub on_bad_frame: BadFrameArg,
    /// Save a checkpoint every N frames (and when stopped by Ctrl-C or SIGTERM) beside the
    /// output, as `OUT.checkpoint`; rows are spooled beside it and the output is written at
    /// the end.
    #[arg(long, value_name = "N")]
    pub checkpoint_every: Option<u64>,
    /// Continue an interrupted run from its checkpoint (same command and settings); the
    /// output is the one an uninterrupted run writes. Without a checkpoint the run starts
    /// from the first frame.
    #[arg(long, requires = "checkpoint_every")]
    pub resume: bool,
}

impl LongRunArgs {
    /// The library's options, with a stop flag raised by Ctrl-C or SIGTERM when checkpoints
    /// are saved (the run saves one, then stops).
    pub fn options(&self) -> anyhow::Result<sillage::long_run::LongRunOptions> {
        let stop = match self.checkpoint_every {
            Some(_) => {
                let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
                let raised = flag.clone();
                ctrlc::set_handler(move || {
                    raised.store(true, std::sync::atomic::Ordering::Relaxed);
                })?;
                Some(flag)
            }
            None => None,
        };
        Ok(sillage::long_run::LongRunOptions {
            on_bad_frame: self.policy(),
            checkpoint_every: self.checkpoint_every,
            resume: self.resume,
            stop,
        })
    }

    /// The bad-frame policy.
    pub fn policy(&self) -> sillage::io::BadFramePolicy {
        match self.on_bad_frame {
            BadFrameArg::Stop => sillage::io::BadFramePolicy::Stop,
            BadFrameArg::Skip => sillage::io::BadFramePolicy::Skip,
        }
    }
}

/// `--window`, `--overlap`, `--jobs`: a run split into overlapping time windows tracked at
/// once and stitched into one set of trajectories.
#[derive(Debug, Args, Clone)]
pub struct WindowArgs {
    /// Track in time windows of W frames, several at once, stitched into one set of
    /// trajectories (docs/scale.md); not with checkpoints.
    #[arg(long, value_name = "W", conflicts_with_all = ["checkpoint_every", "resume"])]
    pub window: Option<usize>,
    /// Frames shared by consecutive windows: at least 4, at most half the window.
    #[arg(long, value_name = "O", default_value_t = sillage::windows::DEFAULT_OVERLAP, requires = "window")]
    pub overlap: usize,
    /// Windows tracked at once (default: one per core).
    #[arg(long, value_name = "J", requires = "window")]
    pub jobs: Option<usize>,
}

impl WindowArgs {
    /// Windows tracked at once: `--jobs`, or one per core.
    pub fn jobs(&self) -> usize {
        self.jobs
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
    }
}
