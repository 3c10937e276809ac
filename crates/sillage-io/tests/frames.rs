//! Frame sources: folders, globs, stacks, conversions, and every error case.

use std::path::Path;
use std::time::Duration;

use sillage_core::{Error, GrayImage};
use sillage_io::{FrameOptions, open_frames, read_image, write_png16};

fn gray8(path: &Path, width: u32, height: u32, value: u8) {
    image::GrayImage::from_pixel(width, height, image::Luma([value]))
        .save(path)
        .unwrap();
}

fn tiff16_pages(path: &Path, width: u32, height: u32, values: &[u16]) {
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = tiff::encoder::TiffEncoder::new(file).unwrap();
    for &v in values {
        let data = vec![v; (width * height) as usize];
        encoder
            .write_image::<tiff::encoder::colortype::Gray16>(width, height, &data)
            .unwrap();
    }
}

fn open(input: &Path) -> sillage_core::Result<sillage_io::FrameSource> {
    open_frames(input.to_str().unwrap(), &FrameOptions::default())
}

#[test]
fn folder_of_8bit_png_in_natural_order() {
    let dir = tempfile::tempdir().unwrap();
    // f10 sorts after f9 (numbers compare by value), and the numbers run without a gap.
    for (name, value) in [("f10.png", 30u8), ("f9.png", 20), ("f8.png", 10)] {
        gray8(&dir.path().join(name), 5, 3, value);
    }
    std::fs::write(dir.path().join("notes.txt"), "not a frame").unwrap();
    let source = open(dir.path()).unwrap();
    assert_eq!(source.len(), Some(3));
    assert_eq!(source.dimensions(), (5, 3));
    let names: Vec<_> = source
        .paths()
        .iter()
        .map(|p| p.file_name().unwrap().to_str().unwrap().to_owned())
        .collect();
    assert_eq!(names, ["f8.png", "f9.png", "f10.png"]);
    let frames: Vec<_> = source.map(Result::unwrap).collect();
    let values: Vec<f32> = frames.iter().map(|f| f.image.get(4, 2)).collect();
    assert_eq!(values, [10.0 / 255.0, 20.0 / 255.0, 30.0 / 255.0]);
    assert_eq!(
        frames.iter().map(|f| f.index).collect::<Vec<_>>(),
        [0, 1, 2]
    );
}

#[test]
fn png16_round_trip_and_clamping() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.png");
    let image = GrayImage::from_vec(4, 1, vec![0.0, 0.25, 1.5, -1.0]).unwrap();
    write_png16(&path, &image).unwrap();
    assert!(!dir.path().join(".a.png.partial").exists());
    let back = read_image(&path).unwrap();
    let expected = [0.0, 0.25, 1.0, 0.0];
    for (got, want) in back.as_slice().iter().zip(expected) {
        assert!((got - want).abs() <= 0.5 / 65535.0, "{got} vs {want}");
    }
    let raw = image::open(&path).unwrap();
    assert_eq!(raw.color(), image::ColorType::L16);
}

#[test]
fn rgb_png_becomes_rec601_grey_and_alpha_is_dropped() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 0, 0]))
        .save(dir.path().join("1.png"))
        .unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([0, 0, 255, 7]))
        .save(dir.path().join("2.png"))
        .unwrap();
    let frames: Vec<_> = open(dir.path()).unwrap().map(Result::unwrap).collect();
    assert!((frames[0].image.get(0, 0) - 0.299).abs() < 1e-6);
    assert!((frames[1].image.get(1, 1) - 0.114).abs() < 1e-6);
}

#[test]
fn jpeg_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame.jpg");
    gray8(&path, 16, 8, 128);
    let frames: Vec<_> = open(&path).unwrap().map(Result::unwrap).collect();
    assert_eq!(frames.len(), 1);
    assert_eq!(frames[0].image.dimensions(), (16, 8));
    assert!((frames[0].image.get(7, 3) - 128.0 / 255.0).abs() < 2.0 / 255.0);
}

#[test]
fn bmp_folder_is_read_in_order_grey_and_colour() {
    let dir = tempfile::tempdir().unwrap();
    gray8(&dir.path().join("exp_002.bmp"), 6, 4, 200);
    image::RgbImage::from_pixel(6, 4, image::Rgb([255, 0, 0]))
        .save(dir.path().join("exp_001.bmp"))
        .unwrap();
    let frames: Vec<_> = open(dir.path()).unwrap().map(Result::unwrap).collect();
    assert_eq!(frames.len(), 2);
    assert!((frames[0].image.get(5, 3) - 0.299).abs() < 1e-6);
    assert!((frames[1].image.get(0, 0) - 200.0 / 255.0).abs() < 1e-6);
}

/// OpenPIV's test pair (`../shared/data/piv_openpiv_test1`): 8-bit palette BMPs from a real
/// PIV camera, 511 × 369.
#[test]
fn real_piv_bmp_pair_is_read() {
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/piv_openpiv_test1"
    );
    let pattern = format!("{dir}/exp1_001_*.bmp");
    let source = open_frames(&pattern, &FrameOptions::default()).unwrap();
    assert_eq!(source.len(), Some(2));
    assert_eq!(source.dimensions(), (511, 369));
    for frame in source {
        let image = frame.unwrap().image;
        let (lo, hi) = image
            .as_slice()
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        // Particles on a dark background: the grey levels span most of the range.
        assert!(lo < 0.1 && hi > 0.5, "grey levels {lo}..{hi}");
    }
}

#[test]
fn three_page_tiff_stack_gives_three_frames() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stack.tif");
    tiff16_pages(&path, 6, 4, &[0, 32768, 65535]);
    let source = open(&path).unwrap();
    assert_eq!(source.len(), Some(3));
    assert_eq!(source.dimensions(), (6, 4));
    let frames: Vec<_> = source.map(Result::unwrap).collect();
    let values: Vec<f32> = frames.iter().map(|f| f.image.get(5, 3)).collect();
    assert_eq!(values, [0.0, 32768.0 / 65535.0, 1.0]);
    assert!(frames.iter().all(|f| f.path == path));
}

/// The frame indices `options` reads from `input`.
fn indices_read(input: &Path, options: &FrameOptions) -> Vec<u64> {
    open_frames(input.to_str().unwrap(), options)
        .unwrap()
        .map(|f| f.unwrap().index)
        .collect()
}

#[test]
fn a_time_window_reads_its_frames_only_from_files_and_stacks() {
    let dir = tempfile::tempdir().unwrap();
    for i in 0..8u8 {
        gray8(&dir.path().join(format!("f{i}.png")), 4, 4, 10 * i);
    }
    let stack = dir.path().join("stack.tif");
    tiff16_pages(&stack, 4, 4, &[0, 1, 2, 3, 4, 5, 6, 7]);
    let window = FrameOptions {
        start_at: 2,
        stop_at: Some(6),
        ..FrameOptions::default()
    };
    for input in [dir.path().join("*.png"), stack] {
        assert_eq!(indices_read(&input, &window), [2, 3, 4, 5], "{input:?}");
        let to_the_end = FrameOptions {
            stop_at: Some(100),
            ..window.clone()
        };
        assert_eq!(indices_read(&input, &to_the_end), [2, 3, 4, 5, 6, 7]);
    }
    let files = open_frames(dir.path().to_str().unwrap(), &window).unwrap();
    assert_eq!(files.len(), Some(4), "a window's length, for progress bars");
}

#[test]
fn float_tiff_is_kept_as_is_and_max_frames_limits() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("float.tiff");
    let file = std::fs::File::create(&path).unwrap();
    let mut encoder = tiff::encoder::TiffEncoder::new(file).unwrap();
    for v in [2.5f32, -1.0, 0.5] {
        encoder
            .write_image::<tiff::encoder::colortype::Gray32Float>(3, 2, &[v; 6])
            .unwrap();
    }
    drop(encoder);
    let options = FrameOptions {
        max_frames: Some(2),
        ..FrameOptions::default()
    };
    let source = open_frames(path.to_str().unwrap(), &options).unwrap();
    assert_eq!(source.len(), Some(2));
    let values: Vec<f32> = source.map(|f| f.unwrap().image.get(0, 0)).collect();
    assert_eq!(values, [2.5, -1.0]);
}

#[test]
fn unsupported_pixel_type_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("u32.tif");
    let file = std::fs::File::create(&path).unwrap();
    tiff::encoder::TiffEncoder::new(file)
        .unwrap()
        .write_image::<tiff::encoder::colortype::Gray32>(2, 2, &[1u32; 4])
        .unwrap();
    let mut source = open(&path).unwrap();
    let err = source.next().unwrap().unwrap_err().to_string();
    assert!(err.contains("unsupported pixel type"), "{err}");
    assert!(source.next().is_none());
}

#[test]
fn glob_pattern_selects_matching_files() {
    let dir = tempfile::tempdir().unwrap();
    for i in 0..4 {
        gray8(&dir.path().join(format!("img{i}.png")), 3, 3, i as u8);
    }
    gray8(&dir.path().join("other.jpg"), 3, 3, 0);
    let pattern = format!("{}/img*.png", dir.path().display());
    let source = open_frames(&pattern, &FrameOptions::default()).unwrap();
    assert_eq!(source.len(), Some(4));
    assert_eq!(source.count(), 4);

    let none = format!("{}/*.tif", dir.path().display());
    let err = open_frames(&none, &FrameOptions::default()).unwrap_err();
    assert!(
        err.to_string().contains("no frames found matching"),
        "{err}"
    );
}

#[test]
fn missing_and_empty_inputs_fail_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope");
    match open(&missing).unwrap_err() {
        Error::Io { path, cause, hint } => {
            assert_eq!(path, missing);
            assert_eq!(cause.kind(), std::io::ErrorKind::NotFound);
            assert!(hint.contains("folder of frames"));
        }
        other => panic!("unexpected {other:?}"),
    }
    let err = open(dir.path()).unwrap_err().to_string();
    assert_eq!(
        err,
        format!(
            "no frames found in {}; expected .tif/.png/.jpg/.bmp files",
            dir.path().display()
        )
    );
    let text = dir.path().join("x.txt");
    std::fs::write(&text, "hello").unwrap();
    assert!(
        open(&text)
            .unwrap_err()
            .to_string()
            .contains("unsupported input")
    );
}

#[test]
fn corrupt_tiff_in_the_middle_comes_after_the_good_frames() {
    let dir = tempfile::tempdir().unwrap();
    for i in [1, 2, 4] {
        tiff16_pages(&dir.path().join(format!("s_{i}.tif")), 4, 4, &[i * 1000]);
    }
    let bad = dir.path().join("s_3.tif");
    std::fs::write(&bad, b"II*\0 this is not really a tiff").unwrap();
    let mut source = open(dir.path()).unwrap();
    assert_eq!(source.next().unwrap().unwrap().index, 0);
    assert_eq!(source.next().unwrap().unwrap().index, 1);
    match source.next().unwrap().unwrap_err() {
        Error::Frame {
            path,
            frame,
            message,
        } => {
            assert_eq!(path, bad);
            assert_eq!(frame, 2);
            assert!(message.starts_with("cannot decode: "), "{message}");
            assert!(message.ends_with("remove or replace the file"), "{message}");
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(source.next().is_none());
}

#[test]
fn frames_of_different_sizes_are_refused_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    gray8(&dir.path().join("a1.png"), 8, 6, 1);
    gray8(&dir.path().join("a2.png"), 7, 6, 1);
    let mut source = open(dir.path()).unwrap();
    assert!(source.next().unwrap().is_ok());
    let err = source.next().unwrap().unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, Error::Frame { frame: 1, .. }));
    assert!(text.contains("7×6") && text.contains("8×6"), "{text}");
    assert!(text.contains("a2.png"), "the error names the file: {text}");
}

#[test]
fn dropping_the_source_early_stops_the_reader() {
    let dir = tempfile::tempdir().unwrap();
    for i in 0..40 {
        gray8(&dir.path().join(format!("{i:03}.png")), 64, 64, i as u8);
    }
    let input = dir.path().to_str().unwrap().to_owned();
    let (done, finished) = crossbeam_channel::bounded(1);
    std::thread::spawn(move || {
        let options = FrameOptions {
            read_ahead: 2,
            ..FrameOptions::default()
        };
        let mut source = open_frames(&input, &options).unwrap();
        let first = source.next().unwrap().unwrap();
        drop(source);
        done.send(first.index).unwrap();
    });
    let index = finished
        .recv_timeout(Duration::from_secs(20))
        .expect("dropping the frame source hung");
    assert_eq!(index, 0);
}

#[test]
fn read_image_reads_a_mask_and_names_bad_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mask.png");
    gray8(&path, 3, 2, 255);
    let mask = read_image(&path).unwrap();
    assert_eq!(mask.dimensions(), (3, 2));
    assert_eq!(mask.get(2, 1), 1.0);
    let bad = dir.path().join("bad.png");
    std::fs::write(&bad, b"garbage").unwrap();
    let err = read_image(&bad).unwrap_err().to_string();
    assert!(
        err.contains("bad.png") && err.contains("cannot decode"),
        "{err}"
    );
    assert!(matches!(
        read_image(dir.path().join("none.png")),
        Err(Error::Io { .. })
    ));
}

/// BeadTracking's flume-base mask: a 1-bit TIFF with CCITT modified Huffman compression
/// (TIFF compression 2), 54 strips of 6 rows.
const CCITT_MASK: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/bedload_beads_lafaye2018/sequence_base_mask.tif"
);

#[test]
fn ccitt_modified_huffman_tiff_matches_its_png_conversion() {
    let mask = read_image(CCITT_MASK).unwrap();
    // The same mask converted to PNG by another decoder.
    let png = read_image(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/sequence_base_mask.png"
    ))
    .unwrap();
    assert_eq!((mask.width(), mask.height()), (1280, 320));
    assert_eq!(mask.as_slice(), png.as_slice());
    let base = mask.as_slice().iter().filter(|&&v| v == 1.0).count();
    assert!(
        mask.as_slice().iter().all(|&v| v == 0.0 || v == 1.0),
        "a bi-level image"
    );
    // The flume base is a band at the bottom of the frame: some of it, not most.
    assert!((10_000..200_000).contains(&base), "{base} base pixels");
}

#[test]
fn damaged_ccitt_tiff_names_the_file_and_the_row() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = std::fs::read(CCITT_MASK).unwrap();
    // Overwrite the coded data of the first strip (data starts after the 8-byte header)
    // with bits that are no T.4 code.
    bytes[8..40].fill(0);
    let path = dir.path().join("mask.tif");
    std::fs::write(&path, &bytes).unwrap();
    let error = read_image(&path).unwrap_err().to_string();
    assert!(
        error.contains("mask.tif") && error.contains("row 1"),
        "{error}"
    );
}

fn colour_options() -> FrameOptions {
    FrameOptions {
        colour: true,
        ..FrameOptions::default()
    }
}

/// A 5×3 RGB picture with every pixel different, so a swapped channel or row shows.
fn rgb_pattern() -> image::RgbImage {
    image::RgbImage::from_fn(5, 3, |x, y| {
        image::Rgb([
            (x * 50 + y) as u8,
            (255 - y * 80 - x) as u8,
            (x * y * 17 + 3) as u8,
        ])
    })
}

#[test]
fn colour_of_an_rgb_png_is_read_back_exactly_and_grey_is_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.png");
    let picture = rgb_pattern();
    picture.save(&path).unwrap();
    let input = path.to_str().unwrap();
    let colour: Vec<_> = open_frames(input, &colour_options())
        .unwrap()
        .map(Result::unwrap)
        .collect();
    let grey: Vec<_> = open_frames(input, &FrameOptions::default())
        .unwrap()
        .map(Result::unwrap)
        .collect();
    assert_eq!(colour.len(), 1);
    let rgb = colour[0].colour.as_ref().expect("colour was requested");
    assert_eq!(rgb.dimensions(), (5, 3));
    for (x, y, p) in picture.enumerate_pixels() {
        assert_eq!(rgb.get(x as usize, y as usize), p.0, "pixel ({x}, {y})");
    }
    assert!(grey[0].colour.is_none(), "colour only when requested");
    assert_eq!(
        colour[0].image, grey[0].image,
        "grey does not depend on colour"
    );
    let [r, g, b] = picture.get_pixel(3, 2).0.map(|v| f32::from(v) / 255.0);
    let luma = 0.299 * r + 0.587 * g + 0.114 * b;
    assert!((grey[0].image.get(3, 2) - luma).abs() < 1e-6);
}

#[test]
fn colour_of_grey_and_16bit_frames_is_replicated_and_rounded_to_8_bits() {
    let dir = tempfile::tempdir().unwrap();
    gray8(&dir.path().join("1.png"), 4, 2, 77);
    image::ImageBuffer::<image::Rgb<u16>, _>::from_pixel(4, 2, image::Rgb([65535u16, 257, 300]))
        .save(dir.path().join("2.png"))
        .unwrap();
    let frames: Vec<_> = open_frames(dir.path().to_str().unwrap(), &colour_options())
        .unwrap()
        .map(Result::unwrap)
        .collect();
    assert_eq!(frames[0].colour.as_ref().unwrap().get(3, 1), [77, 77, 77]);
    // 300 / 257 = 1.17 rounds to 1.
    assert_eq!(frames[1].colour.as_ref().unwrap().get(0, 0), [255, 1, 1]);
}

#[test]
fn tiff_stack_pages_carry_their_colour() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stack.tif");
    tiff16_pages(&path, 3, 2, &[0, 32768, 65535]);
    let source = open_frames(path.to_str().unwrap(), &colour_options()).unwrap();
    let colours: Vec<[u8; 3]> = source
        .map(|f| f.unwrap().colour.unwrap().get(2, 1))
        .collect();
    assert_eq!(colours, [[0; 3], [128; 3], [255; 3]]);
}

#[test]
fn stack_pages_of_different_sizes_are_refused_naming_the_page() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mixed.tif");
    let file = std::fs::File::create(&path).unwrap();
    let mut encoder = tiff::encoder::TiffEncoder::new(file).unwrap();
    encoder
        .write_image::<tiff::encoder::colortype::Gray8>(4, 3, &[1; 12])
        .unwrap();
    encoder
        .write_image::<tiff::encoder::colortype::Gray8>(3, 3, &[1; 9])
        .unwrap();
    drop(encoder);
    let mut source = open_frames(path.to_str().unwrap(), &colour_options()).unwrap();
    assert!(source.next().unwrap().is_ok());
    match source.next().unwrap().unwrap_err() {
        Error::Frame {
            path: named,
            frame,
            message,
        } => {
            assert_eq!(named, path);
            assert_eq!(frame, 1);
            assert!(
                message.contains("3×3") && message.contains("4×3"),
                "{message}"
            );
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(source.next().is_none());
}
