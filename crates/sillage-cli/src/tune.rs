//! `sillage tune FRAMES`: a local web page for tuning the detector while watching its effect
//! (`sillage::tune`): the first frames are loaded once, then a server on 127.0.0.1 answers the
//! page until interrupted.

use std::net::TcpListener;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Args;
use sillage::tune::{TuneSession, load_frames, serve_session};

use crate::progress::FrameProgress;
use crate::ptv::load_config;
use crate::shared_args::ConfigArgs;

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

/// `sillage tune`: loads the frames, then serves the page until interrupted.
pub fn run(args: &TuneArgs) -> Result<()> {
    if args.max_frames == 0 {
        bail!("--max-frames 0 loads no frame; give at least 1");
    }
    let initial = load_config(&args.config)?;
    let mut progress: Option<FrameProgress> = None;
    let frames = load_frames(&args.input, args.max_frames, &mut |n| {
        progress
            .get_or_insert_with(|| FrameProgress::new(n, "loading"))
            .tick()
    });
    if let Some(progress) = progress {
        progress.finish();
    }
    let session = TuneSession::new(frames?, initial, args.save.clone())?;
    let listener = TcpListener::bind(("127.0.0.1", args.port)).with_context(|| {
        format!(
            "cannot listen on 127.0.0.1:{}; try another --port",
            args.port
        )
    })?;
    let port = listener.local_addr()?.port();
    // The URL goes to stdout (first line) so scripts and tests can read the chosen port.
    println!("http://127.0.0.1:{port}/");
    eprintln!(
        "sillage tune: {} frames loaded; open the address above in a browser; \"save\" writes {}; Ctrl-C stops",
        session.frame_count(),
        session.save_path().display()
    );
    serve_session(&listener, session).context("the tuning server stopped")
}
