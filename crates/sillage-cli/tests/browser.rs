//! Browser tests of `sillage view` and `sillage tune` in headless Chromium, driven over
//! WebDriver (`tests/webdriver`). They need Debian's `chromium` and `chromium-driver`, so they
//! are ignored by default and run by `.ci/run`:
//! `cargo test -p sillage-cli --test browser -- --ignored`.
//! Set `SILLAGE_SCREENSHOTS=DIR` to keep the screenshots.

use std::collections::BTreeMap;
use std::path::Path;

mod common;
mod http_client;
mod tune_server;
mod webdriver;
use common::{path_str, run_ok};
use http_client::{http, wait_until};
use tune_server::TuneServer;
use webdriver::Browser;

use sillage::core::{FrameIndex, TrackId, TrackPoint};
use sillage::detect::blob::Threshold;
use sillage::io::{TrackFormat, read_track_table};
use sillage::{DetectorConfig, PipelineConfig};

/// A small vortex sequence in `dir/frames`, tracked into `dir/tracks.csv`.
fn tracked_vortex(dir: &Path, frames: usize) {
    let frames_dir = vortex_frames(dir, frames);
    run_ok(&[
        "ptv",
        path_str(&frames_dir),
        "--out",
        path_str(&dir.join("tracks.csv")),
    ]);
}

/// A small vortex sequence (256×192, 40 particles) in `dir/frames`.
fn vortex_frames(dir: &Path, frames: usize) -> std::path::PathBuf {
    let frames_dir = dir.join("frames");
    let n = frames.to_string();
    run_ok(&[
        "synth",
        "vortex",
        "--out",
        path_str(&frames_dir),
        "--frames",
        &n,
        "--particles",
        "40",
        "--width",
        "256",
        "--height",
        "192",
        "--snr",
        "8",
        "--delta",
        "0.05",
    ]);
    frames_dir
}

/// Keeps `picture` under `$SILLAGE_SCREENSHOTS/name` when that variable is set.
fn keep_screenshot(picture: &image::RgbaImage, name: &str) {
    if let Some(dir) = std::env::var_os("SILLAGE_SCREENSHOTS") {
        picture.save(Path::new(&dir).join(name)).unwrap();
    }
}

/// Number of pixels of `picture` in the rectangle [x0, x1) × [y0, y1) for which `test` holds.
fn count_pixels(
    picture: &image::RgbaImage,
    [x0, y0, x1, y1]: [u32; 4],
    test: impl Fn([u8; 4]) -> bool,
) -> usize {
    let (w, h) = picture.dimensions();
    let mut n = 0;
    for y in y0..y1.min(h) {
        for x in x0..x1.min(w) {
            n += usize::from(test(picture.get_pixel(x, y).0));
        }
    }
    n
}

#[test]
#[ignore = "needs chromium and chromedriver; run by .ci/run"]
fn viewer_plays_hovers_and_filters() {
    let dir = tempfile::tempdir().unwrap();
    tracked_vortex(dir.path(), 14);
    let html = dir.path().join("view.html");
    run_ok(&[
        "view",
        path_str(&dir.path().join("tracks.csv")),
        "--frames",
        path_str(&dir.path().join("frames")),
        "--out",
        path_str(&html),
        "--max-side",
        "200",
    ]);
    // The frames are 256×192, shown at 200×150.
    let scale = 200.0 / 256.0;

    // The track to hover at frame 10: the longest of those at least 20 px (on screen) from
    // every other point of that frame and 15 px inside the canvas.
    let table = read_track_table(&dir.path().join("tracks.csv"), TrackFormat::Csv).unwrap();
    let mut tracks: BTreeMap<TrackId, Vec<TrackPoint>> = BTreeMap::new();
    for p in table.points {
        tracks.entry(p.track_id).or_default().push(p);
    }
    let at = |points: &[TrackPoint], frame: FrameIndex| {
        points.iter().find(|p| p.frame == frame).map(|p| p.pos_px)
    };
    let now: Vec<(TrackId, sillage::core::Point2)> = tracks
        .iter()
        .filter_map(|(&id, points)| at(points, 10).map(|pos| (id, pos)))
        .collect();
    let (id, pos) = now
        .iter()
        .filter(|(id, pos)| {
            let inside = pos.x * scale > 15.0
                && pos.y * scale > 15.0
                && pos.x * scale < 185.0
                && pos.y * scale < 135.0;
            inside
                && now.iter().all(|(other, q)| {
                    other == id || (pos.x - q.x).hypot(pos.y - q.y) * scale >= 20.0
                })
        })
        .max_by_key(|(id, _)| (tracks[id].len(), std::cmp::Reverse(*id)))
        .copied()
        .expect("an isolated track at frame 10");
    let mut points = tracks[&id].clone();
    points.sort_by_key(|p| p.frame);
    let steps: Vec<f64> = points
        .windows(2)
        .map(|w| {
            (w[1].pos_px.x - w[0].pos_px.x).hypot(w[1].pos_px.y - w[0].pos_px.y)
                / (w[1].frame - w[0].frame) as f64
        })
        .collect();
    let speed = steps.iter().sum::<f64>() / steps.len().max(1) as f64;
    let expected = format!("track {id} · {} frames · {speed:.2} px/frame", points.len());

    let browser = Browser::start(900, 600);
    browser.goto(&format!("file://{}", path_str(&html)));
    browser.wait_for("return window.sillageViewer && sillageViewer.ready()");
    assert_eq!(browser.eval("return sillageViewer.frames()"), 14);
    assert_eq!(browser.eval("return sillageViewer.frame()"), 0);
    browser.eval("sillageViewer.play(10)");
    browser.wait_for("return sillageViewer.frame() === 10 && !sillageViewer.playing()");
    assert_eq!(browser.text(&browser.find("#frame-label")), "frame 10 / 13");
    assert_eq!(browser.eval("return sillageViewer.shown()"), now.len());

    let canvas = browser.find("#view");
    let [cx, cy, cw, ch] = browser.rect(&canvas);
    assert_eq!((cw, ch), (200.0, 150.0));
    let (sx, sy) = (cx + pos.x * scale, cy + pos.y * scale);
    browser.move_mouse(sx.round() as i64, sy.round() as i64);
    browser.wait_for("return sillageViewer.tooltip() !== ''");
    let tooltip = browser.find("#tooltip");
    assert_eq!(browser.text(&tooltip), expected);

    let picture = browser.screenshot();
    keep_screenshot(&picture, "view.png");
    let (px, py) = (sx as u32, sy as u32);
    let magenta = |[r, g, b, _]: [u8; 4]| r > 200 && g < 90 && b > 200;
    let near = [px.saturating_sub(5), py.saturating_sub(5), px + 6, py + 6];
    assert!(
        count_pixels(&picture, near, magenta) >= 10,
        "the hovered track is not highlighted at ({px}, {py})"
    );
    // Tails coloured by speed: saturated pixels over the grey frame, away from the highlight.
    let canvas_box = [cx as u32, cy as u32, (cx + cw) as u32, (cy + ch) as u32];
    let tails = count_pixels(&picture, canvas_box, |[r, g, b, _]| {
        let (hi, lo) = (r.max(g).max(b), r.min(g).min(b));
        hi - lo > 80 && !magenta([r, g, b, 255])
    });
    assert!(tails >= 100, "only {tails} tail pixels");
    let [tx, ty, tw, th] = browser.rect(&tooltip);
    let tip_box = [
        tx as u32 + 2,
        ty as u32 + 2,
        (tx + tw) as u32 - 2,
        (ty + th) as u32 - 2,
    ];
    let tip_area = ((tw - 4.0) * (th - 4.0)) as usize;
    let pale = count_pixels(&picture, tip_box, |p| p == [255, 255, 204, 255]);
    let ink = count_pixels(&picture, tip_box, |[r, g, b, _]| {
        r < 128 && g < 128 && b < 128
    });
    assert!(
        pale * 2 > tip_area && ink > 20,
        "tooltip: {pale} pale, {ink} ink of {tip_area}"
    );

    // Filters: a length nobody reaches hides every track; a box around the hovered one keeps
    // exactly the points of frame 10 inside it.
    let longest = tracks.values().map(Vec::len).max().unwrap();
    browser.eval(&format!(
        "const e = document.getElementById('min-len'); e.value = {}; e.dispatchEvent(new Event('input'))",
        longest + 1
    ));
    assert_eq!(browser.eval("return sillageViewer.shown()"), 0);
    browser.eval(
        "const e = document.getElementById('min-len'); e.value = 1; e.dispatchEvent(new Event('input'))",
    );
    let (x0, y0, x1, y1) = (pos.x - 30.0, pos.y - 30.0, pos.x + 30.0, pos.y + 30.0);
    let inside = now
        .iter()
        .filter(|(_, q)| q.x >= x0 && q.x <= x1 && q.y >= y0 && q.y <= y1)
        .count();
    browser.eval(&format!(
        "const e = document.getElementById('region'); e.value = '{x0},{y0},{x1},{y1}'; e.dispatchEvent(new Event('change'))"
    ));
    assert_eq!(browser.eval("return sillageViewer.shown()"), inside);
    assert!(inside >= 1 && inside < now.len());
}

/// The number the page shows as its detection count.
fn shown_count(browser: &Browser) -> usize {
    let text = browser.text(&browser.find("#count"));
    text.parse()
        .unwrap_or_else(|_| panic!("count {text:?} is not a number"))
}

/// Clicks the threshold slider at `fraction` of its width and waits for the new detections.
fn click_threshold(browser: &Browser, fraction: f64) -> f64 {
    let done = browser.eval("return window.sillageTune.completed");
    let [x, y, w, h] = browser.rect(&browser.find("#threshold"));
    browser.click_at(
        (x + fraction * w).round() as i64,
        (y + h / 2.0).round() as i64,
    );
    browser.wait_for(&format!(
        "return window.sillageTune.completed > {done} && !window.sillageTune.busy"
    ));
    browser
        .eval("return Number(document.getElementById('threshold').value)")
        .as_f64()
        .expect("a slider value")
}

#[test]
#[ignore = "needs chromium and chromedriver; run by .ci/run"]
fn tune_threshold_slider_changes_the_count_and_save_writes_it() {
    let dir = tempfile::tempdir().unwrap();
    let frames = vortex_frames(dir.path(), 3);
    let saved = dir.path().join("tuned.toml");
    let server = TuneServer::start(&[
        path_str(&frames),
        "--max-frames",
        "3",
        "--save",
        path_str(&saved),
    ]);
    let browser = Browser::start(1100, 800);
    browser.goto(&server.url());
    browser.wait_for("return window.sillageTune.completed >= 1 && !window.sillageTune.busy");
    let initial = shown_count(&browser);
    assert!(
        (30..=45).contains(&initial),
        "{initial} detections of 40 particles"
    );

    // Near the left end, k ≈ 0: noise maxima come through.
    let k_low = click_threshold(&browser, 0.03);
    assert!(k_low < 1.0, "k = {k_low}");
    let low = shown_count(&browser);
    assert!(
        low > 2 * initial,
        "k = {k_low}: {low} detections, {initial} at k = 4"
    );
    // Near the right end only the brightest particles remain.
    let k_high = click_threshold(&browser, 0.97);
    assert!(k_high > 45.0, "k = {k_high}");
    let high = shown_count(&browser);
    assert!(
        high < initial,
        "k = {k_high}: {high} detections, {initial} at k = 4"
    );

    // The page shows what the server computes for the same parameters.
    let config = browser.eval("return config");
    let (status, reply) = http(
        server.port,
        "POST",
        "/api/detect",
        Some(&serde_json::json!({"frame": 0, "config": config})),
    );
    assert_eq!(status, 200);
    let reply: serde_json::Value = serde_json::from_slice(&reply).unwrap();
    assert_eq!(reply["count"].as_u64(), Some(high as u64));

    // The detections are drawn: cyan circles on the grey frame.
    let picture = browser.screenshot();
    keep_screenshot(&picture, "tune.png");
    let [cx, cy, cw, ch] = browser.rect(&browser.find("#view"));
    let canvas_box = [cx as u32, cy as u32, (cx + cw) as u32, (cy + ch) as u32];
    let cyan = count_pixels(&picture, canvas_box, |[r, g, b, _]| {
        r < 80 && g > 170 && b > 200
    });
    assert!(
        cyan >= 20 * high,
        "{cyan} cyan pixels for {high} detections"
    );

    // The band-passed image can replace the frame.
    browser.eval(
        "const e = document.getElementById('show'); e.value = 'band'; e.dispatchEvent(new Event('input'))",
    );
    browser.wait_for("return bandImage !== null && bandImage.naturalWidth === 256");

    browser.click(&browser.find("#save"));
    wait_until(
        "the saved configuration",
        std::time::Duration::from_secs(15),
        || saved.exists(),
    );
    browser.wait_for("return document.getElementById('saved').textContent.startsWith('saved to')");
    let written = PipelineConfig::from_toml_file(&saved).unwrap();
    let DetectorConfig::Blob(params) = written.detector else {
        panic!("saved detector {:?}", written.detector);
    };
    match params.threshold {
        Threshold::Noise { k } => {
            assert!((k - k_high).abs() < 1e-9, "saved k = {k}, slider {k_high}")
        }
        other => panic!("saved threshold {other:?}"),
    }
}
