//! The command-line grammar (clap): `sillage <verb> [<kind>] INPUT... [options]`.

use std::path::PathBuf;
use std::str::FromStr;

use clap::{Args, Parser, Subcommand, ValueEnum};
pub use sillage::eval::mot::MatchRule;
use sillage::eval::mot::{MotChallengeProtocol, MotConvention};
use sillage::filter::{FitOptions, MotionPriorParams};

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
  sillage synth bedload --out beads/ --frames 200
  sillage synth walkers --scenario crossing --out walkers/ && sillage track immpf walkers/img1 ...
  sillage eval ptv --truth vortex/truth.csv --tracks tracks.csv
  sillage eval mot --gt MOT17/train --pred tracker/data --protocol mot17
  sillage eval mot --gt vortex/truth.csv --pred tracks.csv --match dist:1 --json
  sillage bench ptv --particles 1000,5000,25000
  sillage bench bedload --frames 100 --real shared/data/bedload_beads_lafaye2018 --mask base.png
  sillage fit bedload --truth trackdatatruth.csv --out motion.toml
  sillage detect motion PETS09-S2L1/img1 --out motion_det.txt
  sillage fit motion-prior PETS09-S2L1/gt/gt.txt --out prior.json
  sillage fit homography PETS09-S2L1/gt/gt.txt --out ground.toml
  sillage detect bead 'flume/*.tif' --sequence-params sequence_param.txt --mask base.png --out det.csv --candidates cand.csv
  sillage track bedload --detections beads/detections.csv --candidates beads/candidates.csv --out beads/tracks.csv
  sillage eval mot --gt beads/truth.csv --pred beads/tracks.csv --match disc:0.43 --papers
  sillage plot trajectories tracks.csv --out trajectories.png --colour speed
  sillage overlay tracks.csv --frames vortex/ --out overlays/ --mp4 tracks.mp4
  sillage eulerian tracks.csv --bin 16 --profile y --out stats.csv --plots maps/
  sillage view tracks.csv --frames vortex/ --out view.html   # open view.html in a browser
  sillage tune 'run1/*.tif' --save run1.toml     # tune the detector live; then sillage ptv --config run1.toml";

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
    /// Learn model parameters from ground truth and write them as a TOML config.
    #[command(subcommand)]
    Fit(FitCommand),
    /// Track detections with one of the object trackers and write trajectories.
    #[command(subcommand)]
    Track(TrackCommand),
    /// Detect objects in every frame and write the detections as CSV.
    #[command(subcommand)]
    Detect(DetectCommand),
    /// Bin tracks on a grid: mean velocity, Reynolds stresses, TKE, concentration, profiles.
    Eulerian(EulerianArgs),
    /// Draw a chart of a track table: trajectories, velocity arrows, histograms, counts.
    Plot(PlotArgs),
    /// Draw every frame with its detections and track tails, as PNG files and an MP4.
    Overlay(OverlayArgs),
    /// Write a self-contained HTML page that plays tracks over their frames.
    View(ViewArgs),
    /// Tune the detector in a browser: parameters as controls, detections redrawn live, "save"
    /// writes the config file.
    Tune(TuneArgs),
}

/// The charts of `sillage plot`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PlotKind {
    /// Every track as a line on the image plane (`--colour speed|state|id`).
    Trajectories,
    /// Velocity arrows at one frame (`--frame`).
    Quiver,
    /// Histogram of the displacement per frame (speed, px/frame).
    Displacements,
    /// Histogram of log10 of the prediction error (PTV tables).
    PredictionError,
    /// Tracks (and, with `--detections`, detections) per frame.
    Counts,
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

/// `sillage plot`.
#[derive(Debug, Args)]
pub struct PlotArgs {
    /// Which chart.
    #[arg(value_enum)]
    pub kind: PlotKind,
    /// The tracks.
    #[command(flatten)]
    pub input: TracksInputArgs,
    /// Picture to write: `.png` or `.svg`.
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Frame of the velocity arrows (0-based; default: the frame with most tracks).
    #[arg(long, value_name = "N")]
    pub frame: Option<u64>,
    /// Leave out tracks of fewer points.
    #[arg(long, value_name = "L", default_value_t = 1)]
    pub min_length: usize,
    /// Picture size `WxH`, px.
    #[arg(long, value_name = "WxH", default_value = "800x600")]
    pub size: FrameSize,
    /// Histogram bins.
    #[arg(long, default_value_t = 50)]
    pub bins: usize,
    /// Histogram counts on a log scale.
    #[arg(long)]
    pub log_y: bool,
}

/// `sillage overlay`.
#[derive(Debug, Args)]
pub struct OverlayArgs {
    /// The tracks.
    #[command(flatten)]
    pub input: TracksInputArgs,
    /// The frames the tracks were made from (a folder, a quoted glob, a multi-page TIFF or a
    /// video).
    #[arg(long, value_name = "FRAMES")]
    pub frames: String,
    /// Folder for the pictures, `overlay_NNNNN.png` (0-based frame index).
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// Also encode the pictures into this MP4 (through the `ffmpeg` program).
    #[arg(long, value_name = "FILE.mp4")]
    pub mp4: Option<PathBuf>,
    /// Frames per second of the MP4.
    #[arg(long, default_value_t = 10.0)]
    pub fps: f64,
    /// Frames of history in each track's tail.
    #[arg(long, value_name = "FRAMES", default_value_t = 20)]
    pub tail: u64,
    /// Circle radius of the detections, px.
    #[arg(long, value_name = "PX", default_value_t = 4.0)]
    pub radius: f64,
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
    /// Bedload beads (MMPF+ paper): truth with motion states, detections with misses, bursts
    /// and false positives, and confidence candidates, as CSV.
    Bedload(SynthBedloadArgs),
    /// People walking with occlusions (the SIFT-PF acceptance cases): a MOTChallenge sequence
    /// folder, img1/*.png, gt/gt.txt and seqinfo.ini.
    Walkers(SynthWalkersArgs),
}

/// The walkers scenarios of the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum WalkersScenarioArg {
    /// Two walkers crossing; the near one hides the far one for 5 frames.
    Crossing,
    /// Two walkers entering together (one blob) who then split.
    GroupSplit,
    /// Walkers entering from the borders at random times and speeds.
    Random,
}

/// `sillage synth walkers`.
#[derive(Debug, Args)]
pub struct SynthWalkersArgs {
    /// Output sequence folder (created): img1/000001.png ..., gt/gt.txt, seqinfo.ini.
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// What the walkers do.
    #[arg(long, value_enum, default_value_t = WalkersScenarioArg::Crossing)]
    pub scenario: WalkersScenarioArg,
    /// Number of walkers (random scenario only; the others have two).
    #[arg(long)]
    pub walkers: Option<usize>,
    /// Number of frames, the 10 empty warm-up frames included (default 150).
    #[arg(long)]
    pub frames: Option<usize>,
    /// Frame width, px.
    #[arg(long, default_value_t = 320)]
    pub width: usize,
    /// Frame height, px.
    #[arg(long, default_value_t = 240)]
    pub height: usize,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// `sillage synth bedload`.
#[derive(Debug, Args)]
pub struct SynthBedloadArgs {
    /// Output folder (created): truth.csv, detections.csv, candidates.csv, sequence_param.txt.
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// Number of frames (1280×320 px each).
    #[arg(long, default_value_t = 200)]
    pub frames: usize,
    /// Black beads (a packed bed, the rest mobile).
    #[arg(long, default_value_t = 300)]
    pub black: usize,
    /// Transparent beads (all mobile).
    #[arg(long, default_value_t = 100)]
    pub transparent: usize,
    /// Probability that a transparent bead is missed in a frame.
    #[arg(long, default_value_t = 0.03)]
    pub miss: f64,
    /// Probability per transparent bead and frame that a 5-frame run of misses starts.
    #[arg(long, default_value_t = 0.01)]
    pub burst: f64,
    /// Mean number of false detections per frame.
    #[arg(long, default_value_t = 1.0)]
    pub false_positives: f64,
    /// Standard deviation of the detection position noise, px.
    #[arg(long, default_value_t = 0.5)]
    pub noise: f64,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
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
    /// Multi-object tracking scores (HOTA, CLEAR MOT, IDF1; the papers' own with --papers)
    /// per sequence and combined.
    Mot(EvalMotArgs),
}

/// `sillage eulerian`.
#[derive(Debug, Args)]
pub struct EulerianArgs {
    /// Tracks to bin: TracTrac _track.txt, CSV or Parquet (read row by row).
    pub tracks: PathBuf,
    /// Format of TRACKS (default: from its extension).
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
    /// Statistics per bin: .csv, .parquet or .npy (a numpy structured array).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Bin side: px (`16`, `16px`) or metres (`0.002m`, needs --calibration).
    #[arg(long, value_name = "SIZE", default_value = "16")]
    pub bin: BinSizeArg,
    /// Pixel size and frame rate, `M_PER_PX,FPS`: positions in m, velocities in m/s.
    #[arg(long, value_name = "M_PER_PX,FPS", value_parser = parse_number_pair)]
    pub calibration: Option<(f64, f64)>,
    /// Grid origin and rotation pivot in the image, px, `X,Y`.
    #[arg(long, value_name = "X,Y", value_parser = parse_number_pair, default_value = "0,0")]
    pub origin: (f64, f64),
    /// Rotation of the grid's x axis, degrees counter-clockwise on the image (u along it).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub rotate: f64,
    /// Also write profiles along these axes (rows or columns of bins pooled), as
    /// `<out stem>_profile_<axis>.<ext>` beside --out.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub profile: Vec<AxisArg>,
    /// Folder for PNG heatmaps (count, mean speed, u, v, TKE, <u'v'>) and profile plots.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Print a machine-readable summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// A bin size with its unit, from `--bin`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BinSizeArg {
    /// In pixels.
    Px(f64),
    /// In metres.
    Metres(f64),
}

impl FromStr for BinSizeArg {
    type Err = String;

    /// Parses `16`, `16px` or `0.002m`.
    fn from_str(text: &str) -> Result<Self, String> {
        let text = text.trim();
        let (number, metres) = if let Some(n) = text.strip_suffix("px") {
            (n, false)
        } else if let Some(n) = text.strip_suffix('m') {
            (n, true)
        } else {
            (text, false)
        };
        let size = number
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| format!("`{text}` is not a bin size > 0, e.g. 16, 16px or 0.002m"))?;
        Ok(if metres {
            Self::Metres(size)
        } else {
            Self::Px(size)
        })
    }
}

/// Parses `A,B` as two finite numbers.
fn parse_number_pair(text: &str) -> Result<(f64, f64), String> {
    let numbers: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("`{text}` is not two numbers separated by a comma"))?;
    match numbers[..] {
        [a, b] => Ok((a, b)),
        _ => Err(format!("`{text}` is not two numbers separated by a comma")),
    }
}

/// An image axis, for profiles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AxisArg {
    /// Along x: each column of bins pooled.
    X,
    /// Along y: each row of bins pooled.
    Y,
}

/// `sillage bench eulerian`.
#[derive(Debug, Args)]
pub struct BenchEulerianArgs {
    /// Table lengths to bin, rows, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec![100_000, 1_000_000, 10_000_000])]
    pub rows: Vec<u64>,
    /// Format of the generated tables.
    #[arg(long, value_enum, default_value = "csv")]
    pub format: FormatArg,
    /// Folder for the generated tables (each deleted after its run).
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub dir: PathBuf,
    /// Print the table as JSON lines on stdout.
    #[arg(long)]
    pub json: bool,
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

/// `sillage eval mot`.
#[derive(Debug, Args)]
pub struct EvalMotArgs {
    /// Ground truth: a MOTChallenge gt.txt, a sequence folder (SEQ/gt/gt.txt, SEQ/seqinfo.ini),
    /// a folder of sequence folders, a bead ground-truth CSV (frame,id,x,y,category,...) or a
    /// truth CSV (frame,track_id,x,y).
    #[arg(long, value_name = "FILE_OR_DIR")]
    pub gt: PathBuf,
    /// Predictions: a MOTChallenge results file, a folder of files named after the sequences
    /// (<seq>.txt), a sillage track file (TracTrac _track.txt, CSV, Parquet) or a bead CSV.
    #[arg(long, value_name = "FILE_OR_DIR")]
    pub pred: PathBuf,
    /// How a prediction matches a true object: iou[:T] (box IoU ≥ T, default 0.5), dist:R
    /// (centres at most R px apart), disc[:T] (bead disc IoU ≥ T, default 0.43).
    #[arg(long = "match", value_name = "RULE", default_value = "iou")]
    pub rule: MatchRule,
    /// MOTChallenge ground-truth rules: which rows are scored, which are distractors.
    #[arg(long, value_enum, default_value_t = ProtocolArg::Mot15)]
    pub protocol: ProtocolArg,
    /// Whose conventions to follow where the reference evaluators differ.
    #[arg(long, value_enum, default_value_t = ConventionArg::Trackeval)]
    pub convention: ConventionArg,
    /// Also print the papers' own scores: MMPF+ correct tracks, FN/FP rates and motion-state
    /// F-scores, IMM-PF's VACE, SIFT-PF's ETISEO M1-M3.
    #[arg(long)]
    pub papers: bool,
    /// Print the results as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write every frame's events (match, switch, miss, false positive) to this CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub per_frame: Option<PathBuf>,
}

/// `--protocol`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ProtocolArg {
    /// 2D MOT 2015: rows with a zero consider flag are ignored; no classes.
    Mot15,
    /// MOT16/17: pedestrians scored, distractor classes removed.
    Mot17,
    /// MOT20: as MOT17, non-motorised vehicles also distractors.
    Mot20,
}

impl From<ProtocolArg> for MotChallengeProtocol {
    fn from(p: ProtocolArg) -> Self {
        match p {
            ProtocolArg::Mot15 => MotChallengeProtocol::Mot15,
            ProtocolArg::Mot17 => MotChallengeProtocol::Mot17,
            ProtocolArg::Mot20 => MotChallengeProtocol::Mot20,
        }
    }
}

/// `--convention`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ConventionArg {
    /// TrackEval, MOTChallenge's official evaluator.
    Trackeval,
    /// py-motmetrics 1.4.0.
    Pymotmetrics,
}

impl From<ConventionArg> for MotConvention {
    fn from(c: ConventionArg) -> Self {
        match c {
            ConventionArg::Trackeval => MotConvention::TrackEval,
            ConventionArg::Pymotmetrics => MotConvention::PyMotMetrics,
        }
    }
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
    /// Another demo than the PTV one.
    #[command(subcommand)]
    pub kind: Option<DemoKind>,
}

/// `sillage demo <kind>`.
#[derive(Debug, Subcommand)]
pub enum DemoKind {
    /// Synthetic bedload frames rendered to PNG, beads detected, tracked with MMPF+, scored.
    Bedload(DemoBedloadArgs),
}

/// `sillage demo bedload`.
#[derive(Debug, Args)]
pub struct DemoBedloadArgs {
    /// Output folder for frames, truth and tracks.
    #[arg(long, short, default_value = "out/demo_bedload", value_name = "DIR")]
    pub out: PathBuf,
    /// Number of frames.
    #[arg(long, default_value_t = 100)]
    pub frames: usize,
    /// Random seed (scene and particles).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Also draw every frame with its detections and track tails into OUT/overlays.
    #[arg(long)]
    pub overlays: bool,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `sillage bench <kind>`.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Detection and tracking time per frame on synthetic vortex frames.
    Ptv(BenchPtvArgs),
    /// `sillage eulerian`'s speed and peak memory on generated track tables of growing length.
    Eulerian(BenchEulerianArgs),
    /// The MMPF+ paper's evaluation: Table 1 (the five bedload trackers) and the τ_t sweep of
    /// Fig. 6 on a rendered synthetic sequence and, with --real, on a real one; --plots draws
    /// Figs. 6 and 7.
    Bedload(BenchBedloadArgs),
    /// The IMM-PF paper's evaluation (Tables 1-2): each model combination on MOTChallenge
    /// sequences, VACE (SFDA, ATA, N-MODP, MOTP), CLEAR MOT, IDF1 and HOTA, medians over
    /// seeds; or, with --detections-only, on detections alone.
    Immpf(BenchImmpfArgs),
    /// The SIFT-PF paper's evaluation (§3): each feature selection of §3.1.1 on MOTChallenge
    /// sequences, ETISEO M1-M3 and their mean, CLEAR MOT, IDF1, HOTA and speed, per sequence
    /// and combined.
    Siftpf(BenchSiftpfArgs),
}

/// The paper's three feature selections (§3.1.1), in its order.
pub const SIFTPF_SELECTIONS: [&str; 3] = ["whole-object", "detection-order", "reliability"];

/// `sillage bench siftpf`.
#[derive(Debug, Args)]
pub struct BenchSiftpfArgs {
    /// MOTChallenge sequence folders: `gt/gt.txt`, `seqinfo.ini`, and the frames in `img1/`
    /// or, without `img1/`, one video `video/*.mp4`.
    #[arg(required = true)]
    pub sequences: Vec<PathBuf>,
    /// Feature selections, comma-separated (default: the paper's three).
    #[arg(long, value_delimiter = ',', default_values_t = SIFTPF_SELECTIONS.map(String::from))]
    pub selections: Vec<String>,
    /// Use the first N frames of each sequence.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<usize>,
    /// Random seed of the particles, of the first run (the tracker is deterministic for a
    /// seed).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Runs per selection, with seeds `seed`, `seed + 1`, …; the table gives each score's
    /// median over the runs and in how many runs each selection was best on M̄.
    #[arg(long, default_value_t = 1, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub runs: u64,
    /// Ground plane, as `sillage track siftpf --ground-plane`.
    #[arg(long, value_name = "FILE")]
    pub ground_plane: Option<PathBuf>,
    /// TOML parameters, as `sillage track siftpf --config` (its `selection` is replaced by
    /// each of --selections).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Override one key (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
    /// Print the rows as JSON instead of a Markdown table.
    #[arg(long)]
    pub json: bool,
}

/// The paper's seven model combinations (Table 1).
pub const IMMPF_COMBINATIONS: [&str; 7] = [
    "CA",
    "CV",
    "MP",
    "CV_CA",
    "CV_CA_MP",
    "CP_CV_CA",
    "CP_CV_CA_MP",
];

/// `sillage bench immpf`.
#[derive(Debug, Args)]
pub struct BenchImmpfArgs {
    /// MOTChallenge sequence folders (`img1/`, `det/det.txt`, `gt/gt.txt`, `seqinfo.ini`).
    #[arg(required = true)]
    pub sequences: Vec<PathBuf>,
    /// Model combinations, comma-separated (default: the paper's seven).
    #[arg(long, value_delimiter = ',', default_values_t = IMMPF_COMBINATIONS.map(String::from))]
    pub models: Vec<String>,
    /// Seeds per combination; the table gives medians (the paper: 30).
    #[arg(long, default_value_t = 30)]
    pub runs: usize,
    /// Track `det/det.txt` alone (no frames): for sequences without images.
    #[arg(long)]
    pub detections_only: bool,
    /// With frames, start trackers on `det/det.txt` instead of motion blobs.
    #[arg(long)]
    pub births_from_detections: bool,
    /// Ground plane for box sizes (see `sillage track immpf --ground-plane`).
    #[arg(long, value_name = "FILE")]
    pub ground_plane: Option<PathBuf>,
    /// Motion prior for MP (default: learned from the sequence's own CV_CA tracks, no truth).
    #[arg(long, value_name = "FILE")]
    pub motion_prior: Option<PathBuf>,
    /// TOML parameters, as `sillage track immpf --config`.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Override one key (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
    /// Use the first N frames of each sequence.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<usize>,
    /// Print the rows as JSON instead of a Markdown table.
    #[arg(long)]
    pub json: bool,
}

/// `sillage bench bedload`.
#[derive(Debug, Args)]
pub struct BenchBedloadArgs {
    /// Frames of the synthetic sequence.
    #[arg(long, default_value_t = 100)]
    pub frames: usize,
    /// Seed of the synthetic sequence.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// A real sequence in BeadTracking's layout (images/, ground_truth/trackdatatruth.csv,
    /// sequence_param.txt), detected with the options below.
    #[arg(long, value_name = "DIR")]
    pub real: Option<PathBuf>,
    /// The detector, for --real.
    #[command(flatten)]
    pub detector: BeadDetectorArgs,
    /// The τ_t values of the Fig. 6 sweep, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [0.15, 0.17, 0.19, 0.21, 0.23, 0.25, 0.27, 0.29, 0.31, 0.33, 0.35])]
    pub thresholds: Vec<f64>,
    /// Draw Fig. 6 (correct tracks and MOTA of transparent beads against τ_t) and Fig. 7
    /// (motion-state F-scores) into this folder, as PNG and SVG.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Print the rows as JSON.
    #[arg(long)]
    pub json: bool,
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

/// `sillage fit <kind>`.
#[derive(Debug, Subcommand)]
pub enum FitCommand {
    /// The bedload particle filter's transition table (MMPF+ Eqs. (11)-(12)) and process noises
    /// (Eq. (3)) from ground truth with motion states, trained on the first half (§4.3).
    Bedload(FitBedloadArgs),
    /// The learned motion prior of the pedestrian IMM particle filter (Madrigal & Hayet
    /// §5.1): per 30 px cell, the probability of each direction and its mean velocity, from
    /// MOTChallenge trajectories (foot points); written as JSON.
    MotionPrior(FitMotionPriorArgs),
    /// The image ↔ ground-plane homography (foot points ↔ world_x, world_y of MOT15 ground
    /// truth, or `--points` pairs) and, from ground truth boxes, the adult height and width in
    /// metres (§4); written as TOML.
    Homography(FitHomographyArgs),
}

/// `sillage fit motion-prior`.
#[derive(Debug, Args)]
pub struct FitMotionPriorArgs {
    /// Trajectories in MOTChallenge format (`gt.txt` or tracker output; rows with flag 0 are
    /// ignored), or a sequence folder holding `gt/gt.txt`.
    #[arg(value_name = "TRACKS")]
    pub tracks: PathBuf,
    /// Image width, px; default `imWidth` of the `seqinfo.ini` beside the file or above it.
    #[arg(long, value_name = "PX")]
    pub width: Option<u32>,
    /// Image height, px; default `imHeight` of that `seqinfo.ini`.
    #[arg(long, value_name = "PX")]
    pub height: Option<u32>,
    /// Cell side, px (§5.1 uses 30).
    #[arg(long, value_name = "PX", default_value_t = MotionPriorParams::default().cell_px)]
    pub cell: f64,
    /// Steps slower than this count as "stay", px/frame.
    #[arg(long, value_name = "PX", default_value_t = MotionPriorParams::default().min_speed_px_per_frame)]
    pub min_speed: f64,
    /// Dirichlet pseudo-count added to every bin of every cell.
    #[arg(long, value_name = "N", default_value_t = MotionPriorParams::default().smoothing)]
    pub smoothing: f64,
    /// JSON file to write.
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `sillage fit homography`.
#[derive(Debug, Args)]
pub struct FitHomographyArgs {
    /// MOT15 ground truth with world coordinates
    /// (`frame,id,bb_left,bb_top,bb_width,bb_height,flag,world_x,world_y,world_z`).
    #[arg(
        value_name = "GT",
        required_unless_present = "points",
        conflicts_with = "points"
    )]
    pub gt: Option<PathBuf>,
    /// Instead of ground truth: a text file of 4 or more `u,v,x,y` lines (image px, ground m).
    #[arg(long, value_name = "FILE")]
    pub points: Option<PathBuf>,
    /// TOML file to write: `[homography]` (image_from_ground), `[pedestrian]` (from ground
    /// truth only) and `[fit]`.
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `sillage fit bedload`.
#[derive(Debug, Args)]
pub struct FitBedloadArgs {
    /// Ground truth with motion states: a BeadTracking CSV
    /// (frame,id,x,y,category,vx,vy,motion_state).
    #[arg(long, value_name = "FILE")]
    pub truth: PathBuf,
    /// TOML file to write; its `[motion]` table holds the fitted parameters.
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Share of the frame range to train on, from the first frame, in (0, 1].
    #[arg(long, value_name = "F", default_value_t = FitOptions::default().train_fraction)]
    pub train_fraction: f64,
    /// Minimal transition probability imposed on each fitted row, in [0, 1/3]; 0 keeps the raw
    /// estimate.
    #[arg(long, value_name = "P", default_value_t = FitOptions::default().min_probability)]
    pub min_probability: f64,
    /// Fewest samples for a state's row or noises to be fitted; below, the default is kept.
    #[arg(long, value_name = "N", default_value_t = FitOptions::default().min_samples)]
    pub min_samples: u64,
    /// Print the fitted parameters and the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `sillage track <kind>`.
#[derive(Debug, Subcommand)]
pub enum TrackCommand {
    /// Bedload beads: MMPF+ (default) or a baseline of its Table 1, from detections with
    /// classes (0 black, 1 transparent); writes BeadTracking's CSV layout.
    Bedload(TrackBedloadArgs),
    /// Pedestrians: one IMM particle filter per person, constant position / velocity /
    /// acceleration and a learned motion prior competing (Madrigal & Hayet), on colour frames
    /// or, without frames, on detections alone; writes MOTChallenge results.
    Immpf(TrackImmpfArgs),
    /// Surveillance objects: SIFT features on motion blobs, each followed by a particle
    /// filter, objects linked through the features they share, with merges, splits and
    /// occlusions (Souded et al. 2011); writes MOTChallenge results.
    Siftpf(TrackSiftpfArgs),
}

/// `sillage track siftpf`.
#[derive(Debug, Args)]
pub struct TrackSiftpfArgs {
    /// Colour frames (a folder, a quoted glob, a multi-page TIFF or a video).
    pub input: String,
    /// MOTChallenge results to write (1-based frames).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Feature selection, the paper's configurations of §3.1.1: whole-object (1),
    /// detection-order (2), reliability (3, the default).
    #[arg(long, value_name = "NAME")]
    pub selection: Option<String>,
    /// Ground plane (TOML with `[homography]`, from `sillage fit homography`): sizes and
    /// speeds learned in metres for resuming occluded objects (§2.4); pixels without it.
    #[arg(long, value_name = "FILE")]
    pub ground_plane: Option<PathBuf>,
    /// TOML parameters: `[tracker]` (selection, sift, placement, filter, association,
    /// validation) and `[motion_detector]`.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Override one key, e.g. `--set tracker.filter.particles=50` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
    /// Random seed of the particles.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Stop after this many frames.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<usize>,
    /// Print a machine-readable summary on stdout.
    #[arg(long)]
    pub json: bool,
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

/// `sillage track immpf`.
#[derive(Debug, Args)]
pub struct TrackImmpfArgs {
    /// Colour frames (a folder, a quoted glob, a multi-page TIFF or a video); without them,
    /// `--detections` alone are tracked.
    #[arg(required_unless_present = "detections")]
    pub input: Option<String>,
    /// MOTChallenge detections (`frame,-1,left,top,width,height,score,...`): the birth
    /// candidates instead of motion blobs; without frames, also the measurements.
    #[arg(long, value_name = "FILE")]
    pub detections: Option<PathBuf>,
    /// Frame size `WxH` for detections alone (default: the `seqinfo.ini` of a MOTChallenge
    /// sequence folder `SEQ/det/det.txt`).
    #[arg(long, value_name = "WxH")]
    pub size: Option<FrameSize>,
    /// Ground plane (TOML: `[homography]` and `adult_height_m`, `adult_width_m`; written by
    /// `sillage fit homography`): boxes sized by an adult's size at the foot point (§4).
    /// Without it each tracker keeps the size of the blob or detection it was born on.
    #[arg(long, value_name = "FILE")]
    pub ground_plane: Option<PathBuf>,
    /// Learned motion prior (JSON from `sillage fit motion-prior`), needed by MP.
    #[arg(long, value_name = "FILE")]
    pub motion_prior: Option<PathBuf>,
    /// The competing models as the paper writes them: CA, CV, MP, CV_CA, CV_CA_MP,
    /// CP_CV_CA, CP_CV_CA_MP, ... (default CV_CA).
    #[arg(long, value_name = "MODELS")]
    pub models: Option<String>,
    /// MOTChallenge results to write (1-based frames).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Also write `frame,id,<model weights>` for every result row.
    #[arg(long, value_name = "FILE")]
    pub model_weights: Option<PathBuf>,
    /// Also draw every frame with each person's box, the bar of its model weights and its
    /// trajectory coloured by the dominant model (CP red, CV green, CA blue, MP magenta) into
    /// this folder, as `overlay_NNNNN.png` (1-based frame number).
    #[arg(long, value_name = "DIR", requires = "input")]
    pub overlay: Option<PathBuf>,
    /// TOML parameters: `[tracker]` (filter, models, noises, appearance, detection, death,
    /// births) and `[motion_detector]`.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Override one key, e.g. `--set tracker.filter.particles=100` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
    /// Random seed of the particles.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Stop after this many frames.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<usize>,
    /// Print a machine-readable summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// The trackers of `sillage track bedload --tracker`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum BedloadTrackerArg {
    /// Multi-model particle filter with the motion-state cue (the paper's method).
    MmpfPlus,
    /// Multi-model particle filter without the cue, one saltating state.
    Mmpf,
    /// One constant-velocity particle filter.
    Pf,
    /// Kalman IMM of the three linear motions.
    Imm,
    /// Deterministic association of the detections.
    Det,
}

impl From<BedloadTrackerArg> for sillage::track::bedload::BedloadTrackerKind {
    fn from(arg: BedloadTrackerArg) -> Self {
        match arg {
            BedloadTrackerArg::MmpfPlus => Self::MmpfPlus,
            BedloadTrackerArg::Mmpf => Self::Mmpf,
            BedloadTrackerArg::Pf => Self::Pf,
            BedloadTrackerArg::Imm => Self::Imm,
            BedloadTrackerArg::Det => Self::Det,
        }
    }
}

/// Output formats of bead trajectories.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BeadFormatArg {
    /// CSV in the layout of BeadTracking's ground truth,
    /// `frame,id,x,y,category,vx,vy,motion_state,spread_px` (1-based frames and pixels,
    /// motion-state codes 0-3): what `sillage eval mot` compares with bead truth.
    Beads,
    /// CSV with trackpy column names then `class,motion_state,spread_px` (0-based, state
    /// names).
    Csv,
    /// Apache Parquet with the CSV's columns.
    Parquet,
    /// HDF5, one dataset per column (needs the `hdf5` cargo feature).
    Hdf5,
}

/// `sillage track bedload`.
#[derive(Debug, Args)]
pub struct TrackBedloadArgs {
    /// Frames to detect the beads in (a folder, a quoted glob, a multi-page TIFF or a video),
    /// instead of `--detections`.
    #[arg(required_unless_present = "detections", conflicts_with_all = ["detections", "candidates"])]
    pub input: Option<String>,
    /// Detections CSV: `frame,x,y,class,score` (frames 0-based; class 0 black, 1 transparent).
    #[arg(long, value_name = "FILE")]
    pub detections: Option<PathBuf>,
    /// Detector-confidence candidates (Eq. (1)), same layout: every response maximum above a
    /// low threshold with its score. Without it, a missed bead is pulled towards the
    /// unclaimed detections of its class.
    #[arg(long, value_name = "FILE")]
    pub candidates: Option<PathBuf>,
    /// Trajectories to write; the format from `--format`, else from the extension: `.csv`
    /// in BeadTracking's layout, `.parquet`, `.h5`.
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Output format (default: `beads` for `.csv`, else from the extension of --out).
    #[arg(long, value_enum)]
    pub format: Option<BeadFormatArg>,
    /// TOML parameters (sections `association`, `likelihood`, `states`, `survival`,
    /// `filter`, `motion`, ...; `sillage fit bedload` writes `motion`).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Override one key, e.g. `--set likelihood.gamma=0.7` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
    /// Which tracker (overrides the config's `tracker`).
    #[arg(long, value_enum)]
    pub tracker: Option<BedloadTrackerArg>,
    /// Random seed of the particles (overrides the config's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// The detector, when tracking frames.
    #[command(flatten)]
    pub detector: BeadDetectorArgs,
    /// Also draw every frame with its detections and track tails (coloured by motion state,
    /// with ids) into this folder, as `overlay_NNNNN.png`.
    #[arg(long, value_name = "DIR", requires = "input")]
    pub overlay: Option<PathBuf>,
    /// Frames of history in each overlay tail.
    #[arg(long, value_name = "FRAMES", default_value_t = 20)]
    pub overlay_tail: u64,
    /// Print a machine-readable summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `sillage detect <kind>`.
#[derive(Debug, Subcommand)]
pub enum DetectCommand {
    /// Bedload beads (MMPF+ paper §3.3): black beads by threshold, transparent beads by ring
    /// correlation, and the detector-confidence candidates of Eq. (1).
    Bead(DetectBeadArgs),
    /// Moving objects (the pedestrian and surveillance trackers' detector): adaptive
    /// Gaussian-mixture background, morphology and blobs, written as MOTChallenge detections.
    Motion(DetectMotionArgs),
}

/// `sillage detect motion`.
#[derive(Debug, Args)]
pub struct DetectMotionArgs {
    /// Frames: a folder, a quoted glob pattern, a multi-page TIFF or a video file.
    pub input: String,
    /// MOTChallenge detections to write (`frame,-1,left,top,width,height,conf,-1,-1,-1`;
    /// frames 1-based, conf the share of motion pixels in the box).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// TOML motion-detector parameters (the `[motion_detector]` table of the trackers'
    /// configurations, without its header).
    #[arg(long, value_name = "FILE")]
    pub detector_config: Option<PathBuf>,
    /// Override one detector key, e.g. `--detector-set open_radius_px=2` (repeatable).
    #[arg(long = "detector-set", value_name = "KEY=VALUE")]
    pub detector_overrides: Vec<String>,
    /// Stop after this many frames.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<usize>,
    /// Print a machine-readable summary on stdout.
    #[arg(long)]
    pub json: bool,
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

/// `sillage detect bead`.
#[derive(Debug, Args)]
pub struct DetectBeadArgs {
    /// Frames: a folder, a quoted glob pattern, a multi-page TIFF or a video file.
    pub input: String,
    /// Detections CSV to write (`frame,x,y,class,score`; class 0 black, 1 transparent).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Candidates CSV to write (every correlation maximum above `candidate_threshold`).
    #[arg(long, value_name = "FILE")]
    pub candidates: Option<PathBuf>,
    /// The detector.
    #[command(flatten)]
    pub detector: BeadDetectorArgs,
    /// Print a machine-readable summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `sillage view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Track table (TracTrac _track.txt, CSV, Parquet).
    pub tracks: PathBuf,
    /// The frames the tracks were made from: a folder, a quoted glob, a multi-page TIFF or a video.
    #[arg(long, value_name = "INPUT")]
    pub frames: String,
    /// The HTML file to write; the downscaled frames go to the folder <stem>_frames beside it.
    #[arg(long, short, value_name = "FILE.html")]
    pub out: PathBuf,
    /// Longest side of the frames in the page, px (smaller frames are kept as they are).
    #[arg(long, default_value_t = 1024)]
    pub max_side: usize,
    /// Length of the track tails first shown, frames (changeable in the page).
    #[arg(long, default_value_t = 20)]
    pub tail: usize,
    /// Format of the track table (default: from its extension).
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
}

/// `sillage tune`.
#[derive(Debug, Args)]
pub struct TuneArgs {
    /// Frames: a folder, a quoted glob pattern, a multi-page TIFF or a video.
    pub input: String,
    /// The configuration the page starts from (as `sillage ptv`'s).
    #[command(flatten)]
    pub config: ConfigArgs,
    /// Where "save" writes the configuration (TOML, for `sillage ptv --config`).
    #[arg(long, value_name = "FILE", default_value = "sillage.toml")]
    pub save: PathBuf,
    /// Frames loaded for tuning: the first N of the sequence, kept in memory.
    #[arg(long, value_name = "N", default_value_t = 20)]
    pub max_frames: usize,
    /// Port on 127.0.0.1 (0: a free one); the address is printed on the first line of stdout.
    #[arg(long, default_value_t = 0)]
    pub port: u16,
}
