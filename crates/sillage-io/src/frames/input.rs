//! Turning the user's INPUT string into a list of frames to read: a folder, a glob pattern,
//! one image, a multi-page TIFF, or a video.

use std::cmp::Ordering;
use std::path::{Path, PathBuf};

use sillage_core::{Error, Result};

use super::decode::{has_extension, is_tiff};

/// Extensions of image files taken from a folder or a glob match.
pub(crate) const IMAGE_EXTENSIONS: &[&str] = &["tif", "tiff", "png", "jpg", "jpeg", "bmp"];

/// Extensions read as video through `ffmpeg`.
pub(crate) const VIDEO_EXTENSIONS: &[&str] = &["avi", "mp4", "mov", "mkv"];

/// What INPUT turned out to be.
#[derive(Debug)]
pub(crate) enum InputKind {
    /// One frame per file, in this order.
    Files(Vec<PathBuf>),
    /// One multi-page TIFF, one frame per page.
    TiffStack { path: PathBuf, pages: usize },
    /// A video file read through `ffmpeg`.
    Video(PathBuf),
}

/// Resolves `input` (folder, glob pattern, image, TIFF stack or video).
pub(crate) fn resolve(input: &str) -> Result<InputKind> {
    let path = Path::new(input);
    if !path.exists() && input.contains(['*', '?', '[']) {
        return resolve_glob(input);
    }
    check_exists(path)?;
    if path.is_dir() {
        return resolve_folder(path);
    }
    if has_extension(path, VIDEO_EXTENSIONS) {
        return Ok(InputKind::Video(path.to_path_buf()));
    }
    if is_tiff(path) {
        let pages = super::tiff_stack::count_pages(path)?;
        return Ok(if pages > 1 {
            InputKind::TiffStack {
                path: path.to_path_buf(),
                pages,
            }
        } else {
            InputKind::Files(vec![path.to_path_buf()])
        });
    }
    if has_extension(path, IMAGE_EXTENSIONS) {
        return Ok(InputKind::Files(vec![path.to_path_buf()]));
    }
    Err(Error::input(format!(
        "{}: unsupported input; give a folder of .tif/.png/.jpg/.bmp frames, a glob pattern in \
         quotes (\"dir/*.tif\"), a multi-page TIFF or a video (.avi/.mp4/.mov/.mkv)",
        path.display()
    )))
}

/// `Error::Io` (not found, with a hint) when `path` does not exist.
pub(crate) fn check_exists(path: &Path) -> Result<()> {
    match std::fs::metadata(path) {
        Ok(_) => Ok(()),
        Err(source) => Err(Error::Io {
            path: path.to_path_buf(),
            cause: source,
            hint: "check the path; INPUT is a folder of frames, a glob pattern in quotes, \
                   a multi-page TIFF or a video file"
                .into(),
        }),
    }
}

fn resolve_folder(dir: &Path) -> Result<InputKind> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut files = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| Error::io(dir, e))?.path();
        if path.is_file() && has_extension(&path, IMAGE_EXTENSIONS) {
            files.push(path);
        }
    }
    if files.is_empty() {
        return Err(Error::input(format!(
            "no frames found in {}; expected .tif/.png/.jpg/.bmp files",
            dir.display()
        )));
    }
    files.sort_by(|a, b| natural_cmp(&a.to_string_lossy(), &b.to_string_lossy()));
    Ok(InputKind::Files(files))
}

fn resolve_glob(pattern: &str) -> Result<InputKind> {
    let paths = glob::glob(pattern).map_err(|e| {
        Error::input(format!(
            "bad glob pattern `{pattern}`: {e}; quote it so the shell does not expand it"
        ))
    })?;
    let mut files = Vec::new();
    for entry in paths {
        let path = entry.map_err(|e| Error::io(e.path().to_path_buf(), e.into()))?;
        if path.is_file() {
            files.push(path);
        }
    }
    if files.is_empty() {
        return Err(Error::input(format!(
            "no frames found matching {pattern}; expected .tif/.png/.jpg/.bmp files"
        )));
    }
    files.sort_by(|a, b| natural_cmp(&a.to_string_lossy(), &b.to_string_lossy()));
    Ok(InputKind::Files(files))
}

/// Natural order: runs of digits compare by value, so `img2` < `img10`.
pub(crate) fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (mut a, mut b) = (a, b);
    loop {
        match (a.chars().next(), b.chars().next()) {
            (None, None) => return Ordering::Equal,
            (None, Some(_)) => return Ordering::Less,
            (Some(_), None) => return Ordering::Greater,
            (Some(ca), Some(cb)) if ca.is_ascii_digit() && cb.is_ascii_digit() => {
                let (da, ra) = split_digits(a);
                let (db, rb) = split_digits(b);
                let (ta, tb) = (da.trim_start_matches('0'), db.trim_start_matches('0'));
                let order = ta
                    .len()
                    .cmp(&tb.len())
                    .then_with(|| ta.cmp(tb))
                    .then_with(|| da.len().cmp(&db.len()));
                if order != Ordering::Equal {
                    return order;
                }
                (a, b) = (ra, rb);
            }
            (Some(ca), Some(cb)) => {
                if ca != cb {
                    return ca.cmp(&cb);
                }
                (a, b) = (&a[ca.len_utf8()..], &b[cb.len_utf8()..]);
            }
        }
    }
}

fn split_digits(s: &str) -> (&str, &str) {
    let end = s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len());
    s.split_at(end)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn natural_order_compares_numbers_by_value() {
        let mut names = vec!["img10.tif", "img2.tif", "img1.tif", "img02.tif", "a.tif"];
        names.sort_by(|a, b| natural_cmp(a, b));
        assert_eq!(
            names,
            ["a.tif", "img1.tif", "img2.tif", "img02.tif", "img10.tif"]
        );
        assert_eq!(
            natural_cmp("x99999999999999999999999", "x100000000000000000000000"),
            Ordering::Less
        );
    }
}
