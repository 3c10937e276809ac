//! `sillage tune` without a browser: its HTTP API detects as the library does, saves a
//! configuration `sillage ptv` reads, and answers bad requests with errors that name the
//! problem. (The page itself is driven in headless Chromium by `tests/browser.rs`.)

use std::path::Path;

use serde_json::{Value, json};
use sillage::io::{FrameOptions, open_frames};
use sillage::{DetectionStage, PipelineConfig};

mod common;
mod http_client;
mod tune_server;
use common::{path_str, run_ok, sillage, stderr};
use http_client::http;
use tune_server::TuneServer;

/// Three 256×192 vortex frames with 40 particles in `dir/frames`.
fn vortex_frames(dir: &Path) -> String {
    let frames = dir.join("frames");
    common::synth_vortex(&frames, 3, 40, (256, 192), &["--snr", "4"]);
    path_str(&frames).to_string()
}

/// A JSON request; returns the status and the decoded reply.
fn call(server: &TuneServer, method: &str, path: &str, body: Option<&Value>) -> (u16, Value) {
    let (status, bytes) = http(server.port, method, path, body);
    let reply = serde_json::from_slice(&bytes)
        .unwrap_or_else(|e| panic!("{method} {path}: not JSON ({e}): {bytes:?}"));
    (status, reply)
}

/// Detections of frame `index` of `frames` by the library, with `config` (as the page sends
/// it).
fn library_count(frames: &str, index: usize, config: &Value) -> usize {
    let config: PipelineConfig = serde_json::from_value(config.clone()).unwrap();
    let frame = open_frames(frames, &FrameOptions::default())
        .unwrap()
        .nth(index)
        .unwrap()
        .unwrap();
    let mut stage = DetectionStage::from_config(&config).unwrap();
    let mut detections = Vec::new();
    stage.detect(&frame, &mut detections).unwrap();
    detections.len()
}

#[test]
fn api_detects_as_the_library_and_saves_a_config_ptv_reads() {
    let dir = tempfile::tempdir().unwrap();
    let frames = vortex_frames(dir.path());
    let saved = dir.path().join("tuned.toml");
    let server = TuneServer::start(&[&frames, "--max-frames", "2", "--save", path_str(&saved)]);

    let (status, state) = call(&server, "GET", "/api/state", None);
    assert_eq!(status, 200, "{state}");
    assert_eq!(state["frames"], 2);
    assert_eq!(
        (state["width"].as_u64(), state["height"].as_u64()),
        (Some(256), Some(192))
    );
    let mut config = state["config"].clone();
    // The page starts from the scale and polarity measured on the first frame (σ = 2 px
    // particles, bright), not from "auto".
    let sigma = state["measured"]["measured"]["sigma_px"].as_f64().unwrap();
    assert!((1.7..2.5).contains(&sigma), "{state}");
    let scale = config["detector"]["scale_px"].as_f64().unwrap();
    let expected = sillage::detect::auto_scale_px(sigma);
    assert!((scale - expected).abs() < 0.01, "{scale} vs {expected}");
    assert_eq!(config["detector"]["polarity"], "bright");

    let (status, reply) = call(
        &server,
        "POST",
        "/api/detect",
        Some(&json!({"frame": 1, "config": config})),
    );
    assert_eq!(status, 200, "{reply}");
    let count = reply["count"].as_u64().unwrap() as usize;
    assert_eq!(count, library_count(&frames, 1, &config));
    assert!(
        (30..=45).contains(&count),
        "{count} detections of 40 particles"
    );
    assert_eq!(reply["detections"].as_array().unwrap().len(), count);
    let threshold = reply["threshold"].as_f64().unwrap();
    let histogram = &reply["histogram"];
    assert!(histogram["lo"].as_f64().unwrap() <= threshold);
    assert!(histogram["hi"].as_f64().unwrap() >= threshold);
    let maxima: u64 = histogram["counts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_u64().unwrap())
        .sum();
    assert!(
        maxima as usize > count,
        "{maxima} local maxima, {count} above the threshold"
    );

    // A lower threshold lets noise maxima through.
    config["detector"]["threshold"] = json!({"noise": {"k": 0.5}});
    let (_, low) = call(
        &server,
        "POST",
        "/api/detect",
        Some(&json!({"frame": 1, "config": config})),
    );
    assert!(low["count"].as_u64().unwrap() as usize > 2 * count, "{low}");

    config["detector"]["scale_px"] = json!(2.5);
    let (status, reply) = call(
        &server,
        "POST",
        "/api/save",
        Some(&json!({ "config": config })),
    );
    assert_eq!(status, 200, "{reply}");
    let toml = run_ok(&["config", "--config", path_str(&saved)]);
    assert!(toml.contains("scale_px = 2.5"), "{toml}");
    assert!(toml.contains("k = 0.5"), "{toml}");
    run_ok(&[
        "ptv",
        &frames,
        "--config",
        path_str(&saved),
        "--out",
        path_str(&dir.path().join("t.csv")),
    ]);
}

#[test]
fn api_names_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let frames = vortex_frames(dir.path());
    let server = TuneServer::start(&[
        &frames,
        "--max-frames",
        "2",
        "--save",
        path_str(&dir.path().join("t.toml")),
    ]);
    let config = call(&server, "GET", "/api/state", None).1["config"].clone();
    let error = |method: &str, path: &str, body: Option<&Value>| {
        let (status, reply) = call(&server, method, path, body);
        (
            status,
            reply["error"].as_str().unwrap_or_default().to_string(),
        )
    };

    let mut bad = config.clone();
    bad["detector"]["scale_px"] = json!(-1.0);
    let (status, message) = error(
        "POST",
        "/api/detect",
        Some(&json!({"frame": 0, "config": bad})),
    );
    assert_eq!(status, 400);
    assert!(message.contains("scale_px"), "{message}");

    let (status, message) = error(
        "POST",
        "/api/detect",
        Some(&json!({"frame": 9, "config": config})),
    );
    assert_eq!(status, 400);
    assert!(
        message.contains("frame 9") && message.contains("--max-frames"),
        "{message}"
    );

    let mut unknown = config.clone();
    unknown["detector"]["radius"] = json!(3);
    let (status, message) = error("POST", "/api/save", Some(&json!({ "config": unknown })));
    assert_eq!(status, 400);
    assert!(message.contains("radius"), "{message}");
    assert!(
        !dir.path().join("t.toml").exists(),
        "an invalid configuration was saved"
    );

    let (status, bytes) = http(server.port, "POST", "/api/detect", None);
    assert_eq!(status, 400, "{}", String::from_utf8_lossy(&bytes));
    assert_eq!(error("GET", "/nowhere", None).0, 404);
    assert_eq!(error("GET", "/api/detect", None).0, 405);
    assert_eq!(error("GET", "/frame/x.png", None).0, 400);
    // No path reaches a file: frames are named by index, the save path is fixed at start.
    for path in [
        "/frame/../../etc/passwd",
        "/frame/..%2F..%2Fetc%2Fpasswd.png",
        "/frame/-1.png",
    ] {
        assert_eq!(error("GET", path, None).0, 400, "{path}");
    }
    for path in ["/../Cargo.toml", "/%2e%2e/etc/passwd", "/t.toml"] {
        assert_eq!(error("GET", path, None).0, 404, "{path}");
    }
    // An oversized body is refused before it is read, and the server stays up.
    let mut stream = std::net::TcpStream::connect(("127.0.0.1", server.port)).unwrap();
    std::io::Write::write_all(
        &mut stream,
        b"POST /api/save HTTP/1.1\r\nContent-Length: 999999999\r\n\r\n",
    )
    .unwrap();
    let mut reply = String::new();
    std::io::Read::read_to_string(&mut stream, &mut reply).unwrap();
    assert!(reply.starts_with("HTTP/1.1 413"), "{reply}");
    assert!(!dir.path().join("t.toml").exists());
    assert_eq!(call(&server, "GET", "/api/state", None).0, 200);

    let (status, png) = http(server.port, "GET", "/frame/1.png", None);
    assert_eq!(status, 200);
    let picture = image::load_from_memory(&png).unwrap();
    assert_eq!((picture.width(), picture.height()), (256, 192));
    // The band-passed image is frame-sized, also with a region of interest.
    let mut roi = config.clone();
    roi["detector"]["roi"] = json!({"x0": 32, "y0": 16, "x1": 160, "y1": 112});
    for body in [
        json!({"frame": 1, "config": config}),
        json!({"frame": 1, "config": roi}),
    ] {
        let (status, png) = http(server.port, "POST", "/api/band-passed", Some(&body));
        assert_eq!(status, 200, "{}", String::from_utf8_lossy(&png));
        let picture = image::load_from_memory(&png).unwrap().to_luma8();
        assert_eq!(picture.dimensions(), (256, 192));
        // Particles are bright peaks of the band-passed image: its top is near white.
        assert!(picture.pixels().any(|p| p.0[0] > 200));
    }
    let (status, page) = http(server.port, "GET", "/", None);
    assert_eq!(status, 200);
    assert!(String::from_utf8_lossy(&page).contains("<title>sillage tune</title>"));
}

#[test]
fn command_line_errors_name_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("none");
    let output = sillage(&["tune", path_str(&missing)]);
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).contains("none"), "{}", stderr(&output));

    let frames = vortex_frames(dir.path());
    let output = sillage(&["tune", &frames, "--max-frames", "0"]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("--max-frames"),
        "{}",
        stderr(&output)
    );
    let output = sillage(&["tune", &frames, "--set", "detector.scale_px=0"]);
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).contains("scale_px"), "{}", stderr(&output));
}
