//! The command-line grammar (clap): `sillage <verb> [<kind>] INPUT... [options]`.

use clap::{Parser, Subcommand};

use crate::bench::BenchPtvArgs;
use crate::bench_bedload::BenchBedloadArgs;
use crate::bench_eulerian::BenchEulerianArgs;
use crate::bench_immpf::BenchImmpfArgs;
use crate::bench_ptv_accuracy::BenchPtvAccuracyArgs;
use crate::bench_siftpf::BenchSiftpfArgs;
use crate::bench_stream::BenchStreamArgs;
use crate::demo::DemoArgs;
use crate::demo_bedload::DemoBedloadArgs;
use crate::detect::DetectBeadArgs;
use crate::detect_motion::DetectMotionArgs;
use crate::eulerian::EulerianArgs;
use crate::eval::EvalPtvArgs;
use crate::eval_mot::EvalMotArgs;
use crate::fit::FitBedloadArgs;
use crate::fit_pedestrian::{FitHomographyArgs, FitMotionPriorArgs};
use crate::overlay::OverlayArgs;
use crate::plot::PlotArgs;
use crate::ptv::PtvArgs;
use crate::shared_args::ConfigArgs;
use crate::synth::VortexArgs;
use crate::synth_bedload::SynthBedloadArgs;
use crate::synth_walkers::SynthWalkersArgs;
use crate::track::TrackBedloadArgs;
use crate::track_boxes::TrackBoxesArgs;
use crate::track_immpf::TrackImmpfArgs;
use crate::track_siftpf::TrackSiftpfArgs;
use crate::tune::TuneArgs;
use crate::view::ViewArgs;

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

/// `sillage eval <kind>`.
#[derive(Debug, Subcommand)]
pub enum EvalCommand {
    /// PTV indexes of the TracTrac paper: true/false recovery, position and displacement errors.
    Ptv(EvalPtvArgs),
    /// Multi-object tracking scores (HOTA, CLEAR MOT, IDF1; the papers' own with --papers)
    /// per sequence and combined.
    Mot(EvalMotArgs),
}

/// `sillage demo <kind>`.
#[derive(Debug, Subcommand)]
pub enum DemoKind {
    /// Synthetic bedload frames rendered to PNG, beads detected, tracked with MMPF+, scored.
    Bedload(DemoBedloadArgs),
}

/// `sillage bench <kind>`.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Detection and tracking time per frame on synthetic vortex frames.
    Ptv(BenchPtvArgs),
    /// PTV accuracy (true / false recoveries) on a family of synthetic flows, particle sizes,
    /// densities, displacements and noise levels: the defaults against the old defaults and
    /// the best of a grid search per case, on the half of the family defaults were not chosen
    /// on (--half report, the default).
    PtvAccuracy(BenchPtvAccuracyArgs),
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
    /// A long synthetic stream (no files, default 10^6 frames) through PTV or MMPF+: resident
    /// memory and throughput sampled along the way, track ids checked never to come back.
    Stream(BenchStreamArgs),
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
    /// Boxes on detections alone with SORT (Bewley et al. 2016: Kalman filter per box,
    /// Hungarian algorithm on IoU), the baseline of the pedestrian trackers; writes
    /// MOTChallenge results.
    Boxes(TrackBoxesArgs),
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
