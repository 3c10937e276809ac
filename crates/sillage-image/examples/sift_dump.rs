//! Writes the SIFT keypoints and descriptors of one image as CSV on stdout, for comparing with
//! OpenCV (`tools/sift_opencv_compare.py`):
//!
//! `cargo run --release -p sillage-image --example sift_dump -- IMAGE [--permissive] [--time N]`
//!
//! Columns: `x,y,sigma,orientation,contrast,edge_ratio,octave,layer,d0..d127`. With `--time N`
//! it also runs `detect_and_describe` N more times and prints the median time (ms) on stderr
//! (threads: `RAYON_NUM_THREADS`).

use std::fmt::Write as _;
use std::time::Instant;

use sillage_core::{GrayImage, Image};
use sillage_image::decode_levels;
use sillage_image::sift::{SiftDetector, SiftParams};

/// An 8-bit image as grey in `[0, 1]` (the comparison script writes grey PNGs, so no colour
/// conversion happens here).
fn read_grey(path: &str) -> Result<GrayImage, Box<dyn std::error::Error>> {
    let luma = image::open(path)?.to_luma8();
    let (width, height) = (luma.width() as usize, luma.height() as usize);
    let mut grey = GrayImage::default();
    decode_levels(&Image::from_vec(width, height, luma.into_raw())?, &mut grey);
    Ok(grey)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .ok_or("usage: sift_dump IMAGE [--permissive] [--time N]")?;
    let params = if args.iter().any(|a| a == "--permissive") {
        SiftParams::permissive()
    } else {
        SiftParams::default()
    };
    let repeats: usize = match args.iter().position(|a| a == "--time") {
        Some(i) => args.get(i + 1).ok_or("--time needs a count")?.parse()?,
        None => 0,
    };
    let frame = read_grey(path)?;
    let mut sift = SiftDetector::new(&params)?;
    let features = sift.detect_and_describe(&frame)?;
    if repeats > 0 {
        let mut times: Vec<f64> = (0..repeats)
            .map(|_| {
                let start = Instant::now();
                let n = sift.detect_and_describe(&frame).map(|f| f.len());
                std::hint::black_box(n).ok();
                start.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        times.sort_by(f64::total_cmp);
        eprintln!("detect_and_describe_ms {:.3}", times[times.len() / 2]);
    }
    let mut out = String::from("x,y,sigma,orientation,contrast,edge_ratio,octave,layer");
    for i in 0..128 {
        write!(out, ",d{i}")?;
    }
    out.push('\n');
    for (kp, descriptor) in &features {
        write!(
            out,
            "{},{},{},{},{},{},{},{}",
            kp.x, kp.y, kp.sigma, kp.orientation, kp.contrast, kp.edge_ratio, kp.octave, kp.layer
        )?;
        for v in descriptor.0 {
            write!(out, ",{v}")?;
        }
        out.push('\n');
    }
    print!("{out}");
    Ok(())
}
