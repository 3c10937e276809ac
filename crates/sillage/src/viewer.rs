//! The page of `sillage view`: one self-contained HTML file (script and style inline, tracks
//! embedded as JSON) that plays the sequence with track tails, filters tracks by length,
//! motion state and region, and names a hovered track; the frames, downscaled, go to a
//! folder beside it as PNG.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Serialize;
use sillage_core::{Error, FrameIndex, MotionState, Result, RgbImage, TrackId, TrackPoint};
use sillage_io::{
    FrameOptions, TrackFormat, TrackLayout, TrackTable, open_frames, read_track_table,
    write_png_rgb, write_text,
};
use sillage_viz::state_rgb;

use crate::folders::create_folder;

/// The page; `/*SILLAGE_DATA*/null` is replaced by the data.
const TEMPLATE: &str = include_str!("../assets/view.html");

/// Where the data goes in [`TEMPLATE`].
const DATA_SLOT: &str = "/*SILLAGE_DATA*/null";

/// One track as the page reads it: positions rounded to 0.01 px.
#[derive(Debug, Serialize)]
struct TrackJson {
    /// Track id.
    id: TrackId,
    /// Frames with a position, ascending.
    f: Vec<FrameIndex>,
    /// Column positions, px.
    x: Vec<f64>,
    /// Row positions, px.
    y: Vec<f64>,
    /// Motion state of each point as an index into [`ViewData::states`], when the table has
    /// a state column.
    #[serde(skip_serializing_if = "Option::is_none")]
    s: Option<Vec<usize>>,
    /// Mean speed, px/frame: the mean of the displacements between consecutive points over
    /// their frame gaps (0 for a single point).
    speed: f64,
}

/// Everything the page is given.
#[derive(Debug, Serialize)]
struct ViewData {
    /// Frame width and height in the track table's pixels.
    width: usize,
    height: usize,
    /// Width and height of the downscaled frames, px.
    display_width: usize,
    display_height: usize,
    /// Relative URL of each frame's picture, frame 0 first.
    frames: Vec<String>,
    /// First tail length, frames.
    tail: usize,
    /// Motion state names and their overlay colours (`#rrggbb`).
    states: Vec<&'static str>,
    state_colours: Vec<String>,
    /// The tracks.
    tracks: Vec<TrackJson>,
}

/// What [`write_view`] wrote.
#[derive(Debug, Clone)]
pub struct ViewSummary {
    /// Tracks on the page.
    pub tracks: usize,
    /// Frames written.
    pub frames: usize,
    /// The folder of the downscaled frames.
    pub frames_dir: PathBuf,
}

/// Writes the page `out` for the track table `tracks` (in `format`) over the frames of
/// `frames`, downscaled so that their longest side is at most `max_side` px, tails of `tail`
/// frames to start with; `on_frame` is called after each frame written with the number of
/// frames when the source knows it (progress bars).
pub fn write_view(
    tracks: &Path,
    format: TrackFormat,
    frames: &str,
    out: &Path,
    tail: usize,
    max_side: usize,
    on_frame: &mut dyn FnMut(Option<usize>),
) -> Result<ViewSummary> {
    if max_side < 16 {
        return Err(Error::input(format!(
            "--max-side {max_side} is too small: give at least 16 px"
        )));
    }
    let table = read_track_table(tracks, format)?;
    if table.points.is_empty() {
        return Err(Error::input(format!(
            "{} holds no track points: nothing to view (track a sequence first, e.g. with `sillage ptv`)",
            tracks.display()
        )));
    }
    let (frames_dir, frames_rel) = frames_folder(out)?;
    create_folder(&frames_dir)?;
    let options = FrameOptions {
        colour: true,
        ..FrameOptions::default()
    };
    let source = open_frames(frames, &options)?;
    let total = source.len();
    let mut urls = Vec::new();
    let mut sizes = None;
    for frame in source {
        let frame = frame?;
        let colour = frame
            .colour
            .as_ref()
            .ok_or_else(|| Error::input("the frame source gave no colour picture"))?;
        let small = downscale(colour, max_side);
        sizes.get_or_insert((colour.dimensions(), small.dimensions()));
        let name = format!("{:06}.png", frame.index);
        write_png_rgb(frames_dir.join(&name), &small)?;
        urls.push(format!("{frames_rel}/{name}"));
        on_frame(total);
    }
    let Some(((width, height), (display_width, display_height))) = sizes else {
        return Err(Error::input(format!("{frames} holds no frames")));
    };
    let last = table.points.iter().map(|p| p.frame).max().unwrap_or(0);
    if last as usize >= urls.len() {
        return Err(Error::input(format!(
            "{} has points at frame {last} (0-based) but {frames} holds {} frames: give the frames the tracks were made from",
            tracks.display(),
            urls.len()
        )));
    }
    let data = ViewData {
        width,
        height,
        display_width,
        display_height,
        frames: urls,
        tail,
        states: MotionState::ALL.iter().map(|s| s.name()).collect(),
        state_colours: MotionState::ALL
            .iter()
            .map(|&s| {
                let [r, g, b] = state_rgb(s);
                format!("#{r:02x}{g:02x}{b:02x}")
            })
            .collect(),
        tracks: tracks_json(&table),
    };
    let json = serde_json::to_string(&data)
        .map_err(|e| Error::input(format!("cannot encode the page's data: {e}")))?;
    write_text(out, &fill_template(&json))?;
    Ok(ViewSummary {
        tracks: data.tracks.len(),
        frames: data.frames.len(),
        frames_dir,
    })
}

/// The folder of the downscaled frames beside `out` (`view.html` → `view_frames`), and its
/// name as a relative URL.
fn frames_folder(out: &Path) -> Result<(PathBuf, String)> {
    let stem = out.file_stem().and_then(|s| s.to_str()).ok_or_else(|| {
        Error::input(format!(
            "--out {}: give a file name such as view.html",
            out.display()
        ))
    })?;
    let name = format!("{stem}_frames");
    let dir = out.with_file_name(&name);
    Ok((dir, percent_encode(&name)))
}

/// `text` with every byte outside `A-Z a-z 0-9 - _ . ~` percent-encoded, for a URL path
/// segment.
fn percent_encode(text: &str) -> String {
    text.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' => {
                (b as char).to_string()
            }
            _ => format!("%{b:02X}"),
        })
        .collect()
}

/// The page with `json` in its data slot; `</` is escaped so that no string in the data can
/// close the script element.
fn fill_template(json: &str) -> String {
    TEMPLATE.replacen(DATA_SLOT, &json.replace("</", "<\\/"), 1)
}

/// The tracks of `table`, ordered by id, points by frame.
fn tracks_json(table: &TrackTable) -> Vec<TrackJson> {
    let mut by_id: BTreeMap<TrackId, Vec<&TrackPoint>> = BTreeMap::new();
    for p in &table.points {
        by_id.entry(p.track_id).or_default().push(p);
    }
    let with_states = table.layout == TrackLayout::WithStates;
    let round = |v: f64| (v * 100.0).round() / 100.0;
    by_id
        .into_iter()
        .map(|(id, mut points)| {
            points.sort_by_key(|p| p.frame);
            TrackJson {
                id,
                f: points.iter().map(|p| p.frame).collect(),
                x: points.iter().map(|p| round(p.pos_px.x)).collect(),
                y: points.iter().map(|p| round(p.pos_px.y)).collect(),
                s: with_states.then(|| {
                    points
                        .iter()
                        .map(|p| {
                            MotionState::ALL
                                .iter()
                                .position(|&s| s == p.motion_state)
                                .unwrap_or(0)
                        })
                        .collect()
                }),
                speed: mean_speed(&points),
            }
        })
        .collect()
}

/// Mean of `|Δpos| / Δframe` over consecutive points (sorted by frame), px/frame; 0 for fewer
/// than two points.
fn mean_speed(points: &[&TrackPoint]) -> f64 {
    let speeds: Vec<f64> = points
        .windows(2)
        .filter(|w| w[1].frame > w[0].frame)
        .map(|w| {
            let (dx, dy) = (w[1].pos_px.x - w[0].pos_px.x, w[1].pos_px.y - w[0].pos_px.y);
            dx.hypot(dy) / (w[1].frame - w[0].frame) as f64
        })
        .collect();
    if speeds.is_empty() {
        0.0
    } else {
        speeds.iter().sum::<f64>() / speeds.len() as f64
    }
}

/// `image` shrunk by area averaging so that its longest side is at most `max_side` px,
/// keeping its aspect ratio; returned as it is when already small enough.
pub fn downscale(image: &RgbImage, max_side: usize) -> RgbImage {
    let (w, h) = image.dimensions();
    let longest = w.max(h);
    if longest <= max_side {
        return image.clone();
    }
    let scale = max_side as f64 / longest as f64;
    let nw = ((w as f64 * scale).round() as usize).clamp(1, max_side);
    let nh = ((h as f64 * scale).round() as usize).clamp(1, max_side);
    let mut out = RgbImage::new(nw, nh);
    for oy in 0..nh {
        let (y0, y1) = (oy * h / nh, ((oy + 1) * h / nh).max(oy * h / nh + 1));
        for ox in 0..nw {
            let (x0, x1) = (ox * w / nw, ((ox + 1) * w / nw).max(ox * w / nw + 1));
            let mut sum = [0u32; 3];
            for y in y0..y1 {
                for px in &image.row(y)[x0..x1] {
                    for (s, &v) in sum.iter_mut().zip(px) {
                        *s += u32::from(v);
                    }
                }
            }
            let n = ((y1 - y0) * (x1 - x0)) as u32;
            out.set(ox, oy, sum.map(|s| ((s + n / 2) / n) as u8));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::Point2;

    #[test]
    fn downscale_keeps_the_aspect_and_averages() {
        let mut image = RgbImage::new(400, 100);
        for y in 0..100 {
            for x in 0..400 {
                image.set(x, y, if x % 2 == 0 { [200, 0, 0] } else { [0, 0, 100] });
            }
        }
        let small = downscale(&image, 100);
        assert_eq!(small.dimensions(), (100, 25));
        assert_eq!(small.get(10, 10), [100, 0, 50]);
        assert_eq!(downscale(&image, 400).dimensions(), (400, 100));
        let odd = downscale(&RgbImage::new(1000, 3), 64);
        assert_eq!(odd.dimensions(), (64, 1));
    }

    #[test]
    fn tracks_are_grouped_sorted_and_measured() {
        let mut points = vec![
            TrackPoint::at(2, 7, Point2::new(3.0, 4.0)),
            TrackPoint::at(0, 7, Point2::new(0.0, 0.0)),
            TrackPoint::at(1, 3, Point2::new(1.234_567, 2.0)),
        ];
        points[0].motion_state = MotionState::Rolling;
        let table = TrackTable {
            points,
            layout: TrackLayout::WithStates,
        };
        let tracks = tracks_json(&table);
        assert_eq!(tracks.len(), 2);
        assert_eq!((tracks[0].id, tracks[0].speed), (3, 0.0));
        assert_eq!(tracks[0].x, [1.23]);
        assert_eq!(tracks[1].f, [0, 2]);
        // 5 px over a gap of 2 frames.
        assert_eq!(tracks[1].speed, 2.5);
        // MotionState::ALL: resting, rolling, saltating, unknown.
        assert_eq!(tracks[1].s.as_deref(), Some(&[3, 1][..]));
        let json = serde_json::to_string(&tracks[1]).unwrap();
        assert_eq!(
            json,
            r#"{"id":7,"f":[0,2],"x":[0.0,3.0],"y":[0.0,4.0],"s":[3,1],"speed":2.5}"#
        );
    }

    #[test]
    fn data_cannot_close_the_script_and_urls_are_encoded() {
        let page = fill_template(r#"{"frames":["a</script><b>"]}"#);
        assert!(page.contains(r#"{"frames":["a<\/script><b>"]}"#));
        assert!(!page.contains(DATA_SLOT));
        assert_eq!(
            page.matches("</script>").count(),
            TEMPLATE.matches("</script>").count()
        );
        assert_eq!(percent_encode("my run#1_frames"), "my%20run%231_frames");
        let (dir, url) = frames_folder(Path::new("out/view.html")).unwrap();
        assert_eq!(
            (dir, url.as_str()),
            (PathBuf::from("out/view_frames"), "view_frames")
        );
    }
}
