//! The command-line grammar (clap): `sillage <verb> [<kind>] INPUT... [options]`.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

/// Follow many moving objects through image sequences (PTV, bedload beads, pedestrians).
#[derive(Debug, Parser)]
#[command(name = "sillage", version, about, long_about = None, after_help = EXAMPLES)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

const EXAMPLES: &str = "Examples:
  sillage demo                                   # synthetic vortex → tracks → score
  sillage ptv 'run1/*.tif' --out run1_track.txt  # TracTrac-compatible track file
  sillage ptv movie.avi --out tracks.parquet --set detector.scale_px=3 --set tracker.motion_av=5
  sillage ptv frames/ --tractrac-par tifseq_par.txt --out tracks.csv
  sillage synth vortex --out vortex/ --frames 50 --particles 2000 --snr 6
  sillage eval ptv --truth vortex/truth.csv --tracks tracks.csv
  sillage bench ptv --particles 1000,5000,25000";

/// The verbs.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Track a sequence with the PTV tracker (TracTrac-class) and write trajectories.
    Ptv(PtvArgs),
    /// Generate synthetic sequences with ground truth.
    #[command(subcommand)]
    Synth(SynthCommand),
    /// Score tracks against ground truth.
    #[command(subcommand)]
    Eval(EvalCommand),
    /// Generate a vortex sequence, track it, score it and write every output format.
    Demo(DemoArgs),
    /// Time the headline workloads and print a table.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Print the configuration (defaults, or the result of --config/--set/--tractrac-par) as TOML.
    Config(ConfigArgs),
}

/// Where the configuration comes from; later sources override earlier ones.
#[derive(Debug, Args, Clone, Default)]
pub struct ConfigArgs {
    /// TOML configuration file (see `sillage config` for every key and default).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// A TracTrac `*_par.txt` parameter file, read as it is.
    #[arg(long, value_name = "FILE")]
    pub tractrac_par: Option<PathBuf>,
    /// Override one key, e.g. `--set detector.scale_px=2.5` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
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

/// `sillage ptv`.
#[derive(Debug, Args)]
pub struct PtvArgs {
    /// Frames: a folder, a quoted glob pattern, a multi-page TIFF or a video file.
    pub input: String,
    /// Trajectory file to write (format from the extension unless --format is given).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Output format (default: from the extension of --out).
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
    /// Configuration sources.
    #[command(flatten)]
    pub config: ConfigArgs,
    /// Print a machine-readable summary (counts, timings) on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `sillage synth <kind>`.
#[derive(Debug, Subcommand)]
pub enum SynthCommand {
    /// The TracTrac paper's vortex flow (Eqs. 13-16): PNG frames and truth.csv.
    Vortex(VortexArgs),
}

/// `sillage synth vortex`.
#[derive(Debug, Args)]
pub struct VortexArgs {
    /// Output folder (created): frame_00000.png ... and truth.csv.
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// Number of frames.
    #[arg(long, default_value_t = 50)]
    pub frames: usize,
    /// Number of particles.
    #[arg(long, default_value_t = 1000)]
    pub particles: usize,
    /// Frame width, px.
    #[arg(long, default_value_t = 1024)]
    pub width: usize,
    /// Frame height, px.
    #[arg(long, default_value_t = 1024)]
    pub height: usize,
    /// Signal-to-noise ratio (blob peak over noise magnitude).
    #[arg(long, default_value_t = 4.0)]
    pub snr: f64,
    /// Time step δ of Eqs. 13-16 (larger = faster flow).
    #[arg(long, default_value_t = 0.01)]
    pub delta: f64,
    /// Share of particles re-seeded per frame (0-0.5).
    #[arg(long, default_value_t = 0.0)]
    pub intermittency: f64,
    /// Brownian noise added to the displacements.
    #[arg(long, default_value_t = 0.0)]
    pub brownian: f64,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// `sillage eval <kind>`.
#[derive(Debug, Subcommand)]
pub enum EvalCommand {
    /// PTV indexes of the TracTrac paper: true/false recovery, position and displacement errors.
    Ptv(EvalPtvArgs),
}

/// `sillage eval ptv`.
#[derive(Debug, Args)]
pub struct EvalPtvArgs {
    /// Ground truth CSV (frame,track_id,x,y[,vx,vy]).
    #[arg(long, value_name = "FILE")]
    pub truth: PathBuf,
    /// Tracks (TracTrac _track.txt, CSV, Parquet).
    #[arg(long, value_name = "FILE")]
    pub tracks: PathBuf,
    /// Maximum position error d for a true recovery, px.
    #[arg(long, default_value_t = 1.0)]
    pub max_position_error: f64,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `sillage demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Output folder for frames, truth and tracks.
    #[arg(long, short, default_value = "out/demo", value_name = "DIR")]
    pub out: PathBuf,
    /// Number of frames.
    #[arg(long, default_value_t = 40)]
    pub frames: usize,
    /// Number of particles.
    #[arg(long, default_value_t = 1000)]
    pub particles: usize,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `sillage bench <kind>`.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Detection and tracking time per frame on synthetic vortex frames.
    Ptv(BenchPtvArgs),
}

/// `sillage bench ptv`.
#[derive(Debug, Args)]
pub struct BenchPtvArgs {
    /// Particle counts to time, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec![1000, 5000, 25000])]
    pub particles: Vec<usize>,
    /// Frame sizes to time (square, px), comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec![1024, 2048])]
    pub sizes: Vec<usize>,
    /// Frames timed per case (after 3 warm-up frames).
    #[arg(long, default_value_t = 20)]
    pub frames: usize,
    /// Instead of the sweep, stream this many frames (first size and particle count) and print
    /// the resident memory every tenth of the way.
    #[arg(long, value_name = "FRAMES")]
    pub stream: Option<usize>,
    /// Print the table as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}
