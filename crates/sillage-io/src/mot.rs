//! MOTChallenge text files: ground truth `gt.txt`, detections `det.txt` and tracker results
//! (`frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z`, comma- or space-separated, no
//! header), and the `seqinfo.ini` beside them. A file or a sequence folder is enough: no
//! seqmap and no benchmark folder layout.
//!
//! Frames are 1-based in the files and 0-based in [`MotRow`]. Box coordinates are kept as
//! written: MOTChallenge's pixel origin is not consistently specified, IoU does not depend on
//! it, and keeping the numbers bit-exact makes threshold decisions identical to TrackEval's.
//!
//! Columns after the box, by the number of fields in the row (the layouts of the
//! benchmarks): 7th the confidence (in ground truth: the consider flag, 0 = ignore);
//! in 8- and 9-field rows (MOT16/17/20 ground truth) the 8th is the class and the 9th the
//! visibility; in 10-field rows (MOT15, detections, results) the 8th to 10th are world
//! coordinates, `-1` when absent.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use sillage_core::{BoundingBox, Error, FrameIndex, Result};

use crate::WrittenSummary;
use crate::text_table::{RowWriter, push_f64};

/// One row of a MOTChallenge file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotRow {
    /// 0-based frame (the file's frame − 1).
    pub frame: FrameIndex,
    /// Object or track id; `None` for `-1` (detections have no id).
    pub id: Option<u64>,
    /// Left edge of the box, px, as written.
    pub left_px: f64,
    /// Top edge of the box, px, as written.
    pub top_px: f64,
    /// Box width, px (≥ 0).
    pub width_px: f64,
    /// Box height, px (≥ 0).
    pub height_px: f64,
    /// 7th column: detection or track confidence; in ground truth the consider flag
    /// (0 = not evaluated). `None` when the row has 6 fields.
    pub confidence: Option<f64>,
    /// 8th column of 8- and 9-field rows: the object class (MOT16/17/20 ground truth;
    /// 1 = pedestrian); `None` when absent or `-1`.
    pub class: Option<i64>,
    /// 9th column of 9-field rows: the visible fraction of the object; `None` when absent
    /// or `-1`.
    pub visibility: Option<f64>,
    /// 8th to 10th columns of 10-field rows: world coordinates (MOT15 3D); `None` when
    /// absent or all `-1`.
    pub world: Option<[f64; 3]>,
}

impl MotRow {
    /// A tracker's result row: track `id`'s `bbox` in `frame`, confidence 1, no world
    /// coordinates.
    pub fn result(frame: FrameIndex, id: u64, bbox: &BoundingBox) -> Self {
        Self {
            frame,
            id: Some(id),
            left_px: bbox.left_px,
            top_px: bbox.top_px,
            width_px: bbox.width_px,
            height_px: bbox.height_px,
            confidence: Some(1.0),
            class: None,
            visibility: None,
            world: None,
        }
    }

    /// The row's box.
    pub fn bbox(&self) -> BoundingBox {
        BoundingBox {
            left_px: self.left_px,
            top_px: self.top_px,
            width_px: self.width_px,
            height_px: self.height_px,
        }
    }
}

/// What to read in a sequence folder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotFileRole {
    /// `gt/gt.txt`.
    GroundTruth,
    /// `det/det.txt`.
    Detections,
}

impl MotFileRole {
    /// The file's path inside a sequence folder.
    pub fn path_in_sequence(self) -> &'static str {
        match self {
            MotFileRole::GroundTruth => "gt/gt.txt",
            MotFileRole::Detections => "det/det.txt",
        }
    }
}

/// The `[Sequence]` section of a `seqinfo.ini`; every key is optional.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SeqInfo {
    /// `name`.
    pub name: Option<String>,
    /// `seqLength`: number of frames.
    pub frame_count: Option<u64>,
    /// `frameRate`, frames per second.
    pub frame_rate: Option<f64>,
    /// `imWidth`, px.
    pub image_width: Option<u32>,
    /// `imHeight`, px.
    pub image_height: Option<u32>,
    /// `imDir`: the image folder, relative to the sequence folder.
    pub image_dir: Option<String>,
    /// `imExt`: the image file extension, with its dot.
    pub image_ext: Option<String>,
}

/// A MOTChallenge file read with its sequence information.
#[derive(Debug, Clone, PartialEq)]
pub struct MotSequenceFile {
    /// The file that was read.
    pub path: PathBuf,
    /// Its rows, in file order.
    pub rows: Vec<MotRow>,
    /// The `seqinfo.ini` found with it, if any.
    pub seqinfo: Option<SeqInfo>,
}

/// Reads a MOTChallenge file and its `seqinfo.ini`. `path` is the file itself (its
/// `seqinfo.ini` is looked for in its folder, then in the folder above, as in
/// `SEQ/gt/gt.txt`) or a sequence folder (the file is `role`'s path in it, e.g.
/// `SEQ/gt/gt.txt`, and the information `SEQ/seqinfo.ini`).
pub fn read_mot_sequence(path: impl AsRef<Path>, role: MotFileRole) -> Result<MotSequenceFile> {
    let path = path.as_ref();
    let (file, seqinfo_candidates) = if path.is_dir() {
        let file = path.join(role.path_in_sequence());
        if !file.is_file() {
            return Err(Error::Io {
                path: file,
                cause: std::io::ErrorKind::NotFound.into(),
                hint: format!(
                    "a MOTChallenge sequence folder holds {}; give that file's path instead if \
                     it lies elsewhere",
                    role.path_in_sequence()
                ),
            });
        }
        (file, vec![path.join("seqinfo.ini")])
    } else {
        let folder = path.parent().unwrap_or(Path::new(""));
        let mut candidates = vec![folder.join("seqinfo.ini")];
        if let Some(above) = folder.parent() {
            candidates.push(above.join("seqinfo.ini"));
        }
        (path.to_path_buf(), candidates)
    };
    let rows = read_mot_rows(&file)?;
    let seqinfo = match seqinfo_candidates.iter().find(|p| p.is_file()) {
        Some(p) => Some(read_seqinfo(p)?),
        None => None,
    };
    Ok(MotSequenceFile {
        path: file,
        rows,
        seqinfo,
    })
}

/// Reads the rows of a MOTChallenge file (see [`parse_mot_rows`]).
pub fn read_mot_rows(path: impl AsRef<Path>) -> Result<Vec<MotRow>> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_mot_rows(path, &bytes)
}

/// Parses the rows of a MOTChallenge file held in `bytes` (`path` names it in errors).
/// Blank lines are skipped. A row that is not 6 to 10 numbers, a frame below 1, a negative
/// id other than `-1`, a non-finite number, a negative box size or text that is not UTF-8
/// is an error naming the line and the fix.
pub fn parse_mot_rows(path: &Path, bytes: &[u8]) -> Result<Vec<MotRow>> {
    let mut rows = Vec::new();
    let mut fields: Vec<&str> = Vec::with_capacity(10);
    for (index, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = index + 1;
        let error = |message: String| Error::format(path, Some(line), message);
        let text = std::str::from_utf8(raw)
            .map_err(|_| error("not valid UTF-8 text; save the file as UTF-8".into()))?
            .trim();
        if text.is_empty() {
            continue;
        }
        fields.clear();
        if text.contains(',') {
            fields.extend(text.split(',').map(str::trim));
        } else {
            fields.extend(text.split_whitespace());
        }
        rows.push(parse_row(&fields).map_err(error)?);
    }
    Ok(rows)
}

/// One row from its fields; the error message names the field and the fix.
fn parse_row(fields: &[&str]) -> std::result::Result<MotRow, String> {
    if !(6..=10).contains(&fields.len()) {
        return Err(format!(
            "{} fields; a MOTChallenge row has 6 to 10: \
             frame,id,bb_left,bb_top,bb_width,bb_height[,conf,x,y,z]",
            fields.len()
        ));
    }
    let integer = |k: usize, name: &str| {
        parse_integer(fields[k]).ok_or_else(|| {
            format!(
                "{name} `{}` is not an integer; fix or remove the row",
                fields[k]
            )
        })
    };
    let number = |k: usize, name: &str| {
        fields[k]
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                format!(
                    "{name} `{}` is not a finite number; fix or remove the row",
                    fields[k]
                )
            })
    };
    let frame = integer(0, "frame")?;
    if frame < 1 {
        return Err(format!(
            "frame {frame}: MOTChallenge frames start at 1; renumber the frames from 1"
        ));
    }
    let id = match integer(1, "id")? {
        -1 => None,
        id if id < 0 => {
            return Err(format!("id {id} is negative; ids are ≥ 0, or -1 for none"));
        }
        id => Some(id as u64),
    };
    let (width_px, height_px) = (number(4, "bb_width")?, number(5, "bb_height")?);
    if width_px < 0.0 || height_px < 0.0 {
        return Err(format!(
            "box of size {width_px} × {height_px}: width and height must be ≥ 0"
        ));
    }
    let optional = |k: usize, name: &str| -> std::result::Result<Option<f64>, String> {
        if k < fields.len() {
            number(k, name).map(Some)
        } else {
            Ok(None)
        }
    };
    let absent_if_minus_one = |v: Option<f64>| v.filter(|&v| v != -1.0);
    let mut row = MotRow {
        frame: frame as u64 - 1,
        id,
        left_px: number(2, "bb_left")?,
        top_px: number(3, "bb_top")?,
        width_px,
        height_px,
        confidence: optional(6, "conf")?,
        class: None,
        visibility: None,
        world: None,
    };
    if fields.len() == 10 {
        let world = [number(7, "x")?, number(8, "y")?, number(9, "z")?];
        row.world = (world != [-1.0; 3]).then_some(world);
    } else if fields.len() >= 8 {
        row.class = Some(integer(7, "class")?).filter(|&c| c != -1);
        row.visibility = absent_if_minus_one(optional(8, "visibility")?);
    }
    Ok(row)
}

/// An integer, also written as a float with no fractional part (`3.0`), within `i64`.
fn parse_integer(text: &str) -> Option<i64> {
    text.parse::<i64>().ok().or_else(|| {
        let v: f64 = text.parse().ok()?;
        (v.fract() == 0.0 && v.abs() < 9.0e18).then_some(v as i64)
    })
}

/// Reads a `seqinfo.ini` (see [`parse_seqinfo`]).
pub fn read_seqinfo(path: impl AsRef<Path>) -> Result<SeqInfo> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|_| Error::format(path, None, "not valid UTF-8 text; save the file as UTF-8"))?;
    parse_seqinfo(path, text)
}

/// Parses the `[Sequence]` section of a `seqinfo.ini` (`key=value` or `key: value` lines,
/// keys in any case, `;` and `#` comments; other sections and unknown keys are ignored).
/// A line that is not a key, a value of the wrong type, a key given twice or a file without
/// a `[Sequence]` section is an error naming the line.
pub fn parse_seqinfo(path: &Path, text: &str) -> Result<SeqInfo> {
    let mut info = SeqInfo::default();
    let mut in_sequence = false;
    let mut seen_sequence = false;
    let mut seen_keys: Vec<String> = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let error = |message: String| Error::format(path, Some(line), message);
        let text = raw.trim();
        if text.is_empty() || text.starts_with(';') || text.starts_with('#') {
            continue;
        }
        if let Some(section) = text.strip_prefix('[') {
            let name = section.strip_suffix(']').ok_or_else(|| {
                error(format!(
                    "`{text}` is not a section header; write it as `[Sequence]`"
                ))
            })?;
            in_sequence = name.trim().eq_ignore_ascii_case("sequence");
            seen_sequence |= in_sequence;
            continue;
        }
        let Some((key, value)) = text.split_once(['=', ':']) else {
            return Err(error(format!(
                "`{text}` is not a `key=value` line; fix or remove it"
            )));
        };
        if !in_sequence {
            continue;
        }
        let (key, value) = (key.trim().to_ascii_lowercase(), value.trim());
        if seen_keys.contains(&key) {
            return Err(error(format!("`{key}` is given twice; keep one")));
        }
        seen_keys.push(key.clone());
        let whole = |what: &str| {
            value.parse::<u64>().map_err(|_| {
                error(format!(
                    "{what} `{value}` is not a whole number; fix the value"
                ))
            })
        };
        match key.as_str() {
            "name" => info.name = Some(value.to_owned()),
            "imdir" => info.image_dir = Some(value.to_owned()),
            "imext" => info.image_ext = Some(value.to_owned()),
            "seqlength" => info.frame_count = Some(whole("seqLength")?),
            "imwidth" | "imheight" => {
                let size = u32::try_from(whole(&key)?)
                    .map_err(|_| error(format!("{key} `{value}` is too large")))?;
                if key == "imwidth" {
                    info.image_width = Some(size);
                } else {
                    info.image_height = Some(size);
                }
            }
            "framerate" => {
                let rate = value
                    .parse::<f64>()
                    .ok()
                    .filter(|r| r.is_finite() && *r > 0.0);
                info.frame_rate = Some(rate.ok_or_else(|| {
                    error(format!(
                        "frameRate `{value}` is not a number > 0; fix the value"
                    ))
                })?);
            }
            _ => {}
        }
    }
    if !seen_sequence {
        return Err(Error::format(
            path,
            None,
            "no [Sequence] section; a seqinfo.ini starts with `[Sequence]` followed by \
             `seqLength=...` and the other keys",
        ));
    }
    Ok(info)
}

/// Checks the frames found in a MOTChallenge sequence's image folder (`image_dir`, e.g.
/// `img1`) against the `seqinfo.ini` at `path`: `frames` (the folder's count, `None` when
/// only part of it was read) above `seqLength`, or a frame size other than
/// `imWidth`×`imHeight`, is an error naming the file and the key's line. Fewer frames than
/// `seqLength` are a sequence's first frames, not an error (the shared PETS 2009 folder holds
/// 150 of its 795). A `seqinfo.ini` whose `imDir` names another folder is not checked.
pub fn check_seqinfo_frames(
    path: &Path,
    image_dir: &str,
    frames: Option<u64>,
    (width, height): (usize, usize),
) -> Result<()> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|_| Error::format(path, None, "not valid UTF-8 text; save the file as UTF-8"))?;
    let info = parse_seqinfo(path, text)?;
    if info
        .image_dir
        .as_deref()
        .is_some_and(|dir| dir != image_dir)
    {
        return Ok(());
    }
    let error = |key: &str, message: String| Error::format(path, key_line(text, key), message);
    if let (Some(stated), Some(found)) = (info.frame_count, frames)
        && found > stated
    {
        return Err(error(
            "seqlength",
            format!(
                "seqLength is {stated} but {image_dir} holds {found} frames; correct seqLength \
                 or remove the extra frames"
            ),
        ));
    }
    for (key, name, stated, found) in [
        ("imwidth", "imWidth", info.image_width, width),
        ("imheight", "imHeight", info.image_height, height),
    ] {
        if let Some(stated) = stated
            && stated as usize != found
        {
            return Err(error(
                key,
                format!(
                    "{name} is {stated} px but the frames of {image_dir} are {found} px; \
                     correct {name}"
                ),
            ));
        }
    }
    Ok(())
}

/// The 1-based line of `text` that gives `key` (lower case), any case and spacing.
fn key_line(text: &str, key: &str) -> Option<usize> {
    text.lines()
        .position(|line| {
            line.split(['=', ':'])
                .next()
                .is_some_and(|k| k.trim().eq_ignore_ascii_case(key))
        })
        .map(|index| index + 1)
}

/// Writes MOTChallenge results (10 fields: `frame,id,bb_left,bb_top,bb_width,bb_height,
/// conf,x,y,z`, frames 1-based, `-1` for what is absent) batch by batch into
/// `.NAME.partial`, renamed on [`MotResultsWriter::finish`]. Class and visibility, columns of
/// ground truth only, are not written.
#[derive(Debug)]
pub struct MotResultsWriter {
    rows: RowWriter,
}

impl MotResultsWriter {
    /// Creates the writer (no header: MOTChallenge files have none).
    pub fn create(path: impl AsRef<Path>) -> Result<Self> {
        Ok(Self {
            rows: RowWriter::create(path.as_ref(), "")?,
        })
    }

    /// Appends `rows` (whole rows, one write).
    pub fn push(&mut self, rows: &[MotRow]) -> Result<()> {
        self.rows.write_rows(rows, |out, row| {
            let world = row.world.unwrap_or([-1.0; 3]);
            push_mot_row(out, row, world)
        })
    }

    /// Closes the file under its final name.
    pub fn finish(self) -> Result<WrittenSummary> {
        self.rows.finish()
    }
}

/// Writes MOTChallenge ground truth as MOT16/17/20 have it (9 fields:
/// `frame,id,bb_left,bb_top,bb_width,bb_height,consider,class,visibility`, frames 1-based,
/// `-1` for what is absent) batch by batch into `.NAME.partial`, renamed on
/// [`MotGroundTruthWriter::finish`]; the consider flag is [`MotRow::confidence`].
#[derive(Debug)]
pub struct MotGroundTruthWriter {
    rows: RowWriter,
}

impl MotGroundTruthWriter {
    /// Creates the writer (no header: MOTChallenge files have none).
    pub fn create(path: impl AsRef<Path>) -> Result<Self> {
        Ok(Self {
            rows: RowWriter::create(path.as_ref(), "")?,
        })
    }

    /// Appends `rows` (whole rows, one write).
    pub fn push(&mut self, rows: &[MotRow]) -> Result<()> {
        self.rows.write_rows(rows, |out, row| {
            let class = row.class.map_or(-1.0, |c| c as f64);
            push_mot_row(out, row, [class, row.visibility.unwrap_or(-1.0)])
        })
    }

    /// Closes the file under its final name.
    pub fn finish(self) -> Result<WrittenSummary> {
        self.rows.finish()
    }
}

/// One MOTChallenge row into `out`: the 1-based frame, the id (`-1` without), the box, the
/// 7th column (`-1` without) and the layout's `tail` columns.
fn push_mot_row<const N: usize>(out: &mut String, row: &MotRow, tail: [f64; N]) -> Result<()> {
    let frame = row
        .frame
        .checked_add(1)
        .ok_or_else(|| Error::input(format!("frame {} cannot be written 1-based", row.frame)))?;
    // Writing to a String cannot fail.
    let _ = write!(out, "{frame},");
    match row.id {
        Some(id) => {
            let _ = write!(out, "{id}");
        }
        None => out.push_str("-1"),
    }
    let values = [row.left_px, row.top_px, row.width_px, row.height_px]
        .into_iter()
        .chain([row.confidence.unwrap_or(-1.0)])
        .chain(tail);
    for v in values {
        out.push(',');
        push_f64(out, v);
    }
    Ok(())
}

/// Writes `info` as a `seqinfo.ini` at `path` (a `[Sequence]` section with the keys that are
/// set, in MOTChallenge's spelling), under a temporary name renamed when complete.
pub fn write_seqinfo(path: impl AsRef<Path>, info: &SeqInfo) -> Result<()> {
    let mut text = String::from("[Sequence]\n");
    let mut line = |key: &str, value: Option<String>| {
        if let Some(value) = value {
            // Writing to a String cannot fail.
            let _ = writeln!(text, "{key}={value}");
        }
    };
    line("name", info.name.clone());
    line("imDir", info.image_dir.clone());
    line("frameRate", info.frame_rate.map(|r| r.to_string()));
    line("seqLength", info.frame_count.map(|n| n.to_string()));
    line("imWidth", info.image_width.map(|w| w.to_string()));
    line("imHeight", info.image_height.map(|h| h.to_string()));
    line("imExt", info.image_ext.clone());
    crate::write_text(path, &text)
}

/// Writes `rows` as a MOTChallenge results file at `path` in one go.
pub fn write_mot_results(path: impl AsRef<Path>, rows: &[MotRow]) -> Result<()> {
    let mut writer = MotResultsWriter::create(path)?;
    writer.push(rows)?;
    writer.finish().map(drop)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ground_truth_and_seqinfo_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let row = MotRow {
            frame: 4,
            id: Some(7),
            left_px: -3.25,
            top_px: 10.5,
            width_px: 24.0,
            height_px: 64.0,
            confidence: Some(1.0),
            class: Some(1),
            visibility: Some(0.375),
            world: None,
        };
        let gt = dir.path().join("gt.txt");
        let mut writer = MotGroundTruthWriter::create(&gt).unwrap();
        writer.push(&[row]).unwrap();
        writer.finish().unwrap();
        assert_eq!(
            std::fs::read_to_string(&gt).unwrap(),
            "5,7,-3.25,10.5,24,64,1,1,0.375\n"
        );
        assert_eq!(read_mot_rows(&gt).unwrap(), vec![row]);
        let info = SeqInfo {
            name: Some("walkers".into()),
            frame_count: Some(150),
            frame_rate: Some(25.0),
            image_width: Some(320),
            image_height: Some(240),
            image_dir: Some("img1".into()),
            image_ext: Some(".png".into()),
        };
        let ini = dir.path().join("seqinfo.ini");
        write_seqinfo(&ini, &info).unwrap();
        assert_eq!(read_seqinfo(&ini).unwrap(), info);
    }

    #[test]
    fn frames_that_disagree_with_seqinfo_are_named_by_line() {
        let dir = tempfile::tempdir().unwrap();
        let ini = dir.path().join("seqinfo.ini");
        std::fs::write(
            &ini,
            "[Sequence]\nname=walkers\nimDir=img1\nseqLength=20\nimWidth=320\nimHeight=240\n",
        )
        .unwrap();
        // A sequence's first frames, the whole sequence, or a part of it read: fine.
        for frames in [Some(12), Some(20), None] {
            check_seqinfo_frames(&ini, "img1", frames, (320, 240)).unwrap();
        }
        let err = check_seqinfo_frames(&ini, "img1", Some(21), (320, 240))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("seqinfo.ini:4:") && err.contains("seqLength is 20"),
            "{err}"
        );
        let err = check_seqinfo_frames(&ini, "img1", Some(20), (320, 200))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("seqinfo.ini:6:") && err.contains("imHeight is 240"),
            "{err}"
        );
        // Another folder's seqinfo.
        check_seqinfo_frames(&ini, "img2", Some(99), (1, 1)).unwrap();
    }

    fn parse(text: &str) -> Result<Vec<MotRow>> {
        parse_mot_rows(Path::new("gt.txt"), text.as_bytes())
    }

    #[test]
    fn layouts_by_field_count() {
        let rows = parse(
            "1,1,399,182,121,229,1,-1,-1,-1\n\
             2,-1,10.5,20,30,40,0.9,1.5,2.5,-1\r\n\
             \n\
             3,4,1,2,3,4,1,7,0.25\n\
             4 5 1 2 3 4\n",
        )
        .unwrap();
        assert_eq!(rows.len(), 4);
        assert_eq!(
            (rows[0].frame, rows[0].id, rows[0].world),
            (0, Some(1), None)
        );
        assert_eq!(rows[1].id, None);
        assert_eq!(rows[1].world, Some([1.5, 2.5, -1.0]));
        assert_eq!((rows[2].class, rows[2].visibility), (Some(7), Some(0.25)));
        assert_eq!((rows[3].frame, rows[3].confidence), (3, None));
    }

    #[test]
    fn malformed_rows_name_the_line_and_the_fix() {
        let cases = [
            ("1,1,2,3,4\n", "6 to 10"),
            ("1,1,2,3,4,5\n0,1,2,3,4,5\n", ":2: frame 0"),
            ("1,-3,2,3,4,5\n", "negative"),
            ("1,1,2,3,-4,5\n", "must be ≥ 0"),
            ("1,1,2,nan,4,5\n", "bb_top `nan`"),
            ("1,1.5,2,3,4,5\n", "id `1.5`"),
        ];
        for (text, expected) in cases {
            let err = parse(text).unwrap_err().to_string();
            assert!(
                err.contains(expected) && err.starts_with("gt.txt:"),
                "{err}"
            );
        }
        let err = parse_mot_rows(Path::new("r.txt"), b"1,1,2,3,4,5\n\xff\n").unwrap_err();
        assert!(
            err.to_string().starts_with("r.txt:2: not valid UTF-8"),
            "{err}"
        );
    }

    #[test]
    fn seqinfo_keys_and_errors() {
        let path = Path::new("seqinfo.ini");
        let info = parse_seqinfo(
            path,
            "[Sequence]\nname=TUD-Campus\nimDir=img1\nframeRate=25\nseqLength=71\n\
             imWidth=640\nimHeight=480\nimExt=.jpg\n; comment\n[Other]\nseqLength=oops\n",
        )
        .unwrap();
        assert_eq!(info.name.as_deref(), Some("TUD-Campus"));
        assert_eq!((info.frame_count, info.frame_rate), (Some(71), Some(25.0)));
        assert_eq!(
            (info.image_width, info.image_height),
            (Some(640), Some(480))
        );
        let err = parse_seqinfo(path, "[Sequence]\nseqLength=7.5\n").unwrap_err();
        assert!(
            err.to_string().starts_with("seqinfo.ini:2: seqLength"),
            "{err}"
        );
        assert!(parse_seqinfo(path, "seqLength=3\n").is_err());
        assert!(parse_seqinfo(path, "[Sequence]\nseqLength=3\nSEQLENGTH=4\n").is_err());
        assert!(parse_seqinfo(path, "[Sequence]\njunk\n").is_err());
    }
}
