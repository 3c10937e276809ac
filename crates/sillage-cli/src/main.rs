//! `sillage`: the command line of the sillage tracking toolkit.
//!
//! Exit codes: 0 on success, 1 on a user error (the message names the file, line or frame and
//! the fix), 2 on a bad command line.

mod bench;
mod bench_bedload;
mod bench_eulerian;
mod bench_immpf;
mod bench_ptv_accuracy;
mod bench_siftpf;
mod bench_stream;
mod cli;
mod demo;
mod demo_bedload;
mod detect;
mod detect_motion;
mod eulerian;
mod eval;
mod eval_mot;
mod fit;
mod fit_pedestrian;
mod overlay;
mod plot;
mod progress;
mod ptv;
mod shared_args;
mod synth;
mod synth_bedload;
mod synth_walkers;
mod track;
mod track_boxes;
mod track_immpf;
mod track_input;
mod track_siftpf;
mod tune;
mod view;

use clap::Parser;

fn main() {
    let args = cli::Cli::parse();
    let outcome = match args.command {
        cli::Command::Ptv(a) => ptv::run(&a),
        cli::Command::Synth(cli::SynthCommand::Vortex(a)) => synth::run_vortex(&a),
        cli::Command::Synth(cli::SynthCommand::Bedload(a)) => synth_bedload::run_bedload(&a),
        cli::Command::Synth(cli::SynthCommand::Walkers(a)) => synth_walkers::run(&a),
        cli::Command::Eval(cli::EvalCommand::Ptv(a)) => eval::run_ptv(&a),
        cli::Command::Eval(cli::EvalCommand::Mot(a)) => eval_mot::run(&a),
        cli::Command::Demo(a) => match &a.kind {
            Some(cli::DemoKind::Bedload(b)) => demo_bedload::run(b),
            None => demo::run(&a),
        },
        cli::Command::Bench(cli::BenchCommand::Ptv(a)) => bench::run_ptv(&a),
        cli::Command::Bench(cli::BenchCommand::PtvAccuracy(a)) => bench_ptv_accuracy::run(&a),
        cli::Command::Bench(cli::BenchCommand::Eulerian(a)) => bench_eulerian::run(&a),
        cli::Command::Bench(cli::BenchCommand::Bedload(a)) => bench_bedload::run(&a),
        cli::Command::Bench(cli::BenchCommand::Immpf(a)) => bench_immpf::run(&a),
        cli::Command::Bench(cli::BenchCommand::Siftpf(a)) => bench_siftpf::run(&a),
        cli::Command::Bench(cli::BenchCommand::Stream(a)) => bench_stream::run(&a),
        cli::Command::Config(a) => ptv::print_config(&a),
        cli::Command::Fit(cli::FitCommand::Bedload(a)) => fit::run_bedload(&a),
        cli::Command::Fit(cli::FitCommand::MotionPrior(a)) => fit_pedestrian::run_motion_prior(&a),
        cli::Command::Fit(cli::FitCommand::Homography(a)) => fit_pedestrian::run_homography(&a),
        cli::Command::Track(cli::TrackCommand::Bedload(a)) => track::run_bedload(&a),
        cli::Command::Track(cli::TrackCommand::Immpf(a)) => track_immpf::run(&a),
        cli::Command::Track(cli::TrackCommand::Siftpf(a)) => track_siftpf::run(&a),
        cli::Command::Track(cli::TrackCommand::Boxes(a)) => track_boxes::run(&a),
        cli::Command::Detect(cli::DetectCommand::Bead(a)) => detect::run_bead(&a),
        cli::Command::Detect(cli::DetectCommand::Motion(a)) => detect_motion::run_motion(&a),
        cli::Command::Eulerian(a) => eulerian::run(&a),
        cli::Command::Plot(a) => plot::run(&a),
        cli::Command::Overlay(a) => overlay::run(&a),
        cli::Command::View(a) => view::run(&a),
        cli::Command::Tune(a) => tune::run(&a),
    };
    if let Err(error) = outcome {
        eprintln!("error: {error:#}");
        std::process::exit(1);
    }
}
