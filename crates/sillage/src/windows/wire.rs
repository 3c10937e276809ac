//! What travels between the places of a run stitched apart, as bytes: a window's tracks (from
//! the worker that tracked it), its edges and track ids, a seam, a window's share plan (from
//! the one place that hands out identities). Points go as the row spool's compact records
//! ([`encode_points`]); each kind starts with its own tag, so bytes of one kind passed for
//! another are refused by name.

use sillage_core::{Error, FrameIndex, Result, TrackId, TrackPoint};
use sillage_io::{decode_points, encode_points};
use sillage_track::stitch::{IdMap, PartPlan, Seam, SeamReport, WindowEdges, WindowTracks};

/// Appends little-endian fields to a buffer.
struct Writer(Vec<u8>);

impl Writer {
    fn new(tag: &[u8; 4]) -> Self {
        Self(tag.to_vec())
    }

    fn u64(&mut self, value: u64) -> &mut Self {
        self.0.extend_from_slice(&value.to_le_bytes());
        self
    }

    fn u64s(&mut self, values: impl ExactSizeIterator<Item = u64>) -> &mut Self {
        self.u64(values.len() as u64);
        for value in values {
            self.u64(value);
        }
        self
    }

    fn points(&mut self, points: &[TrackPoint]) -> &mut Self {
        encode_points(points, &mut self.0);
        self
    }
}

/// Reads what [`Writer`] wrote; `None` at the first field that is not there.
struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    fn new(bytes: &'a [u8], tag: &[u8; 4]) -> Option<Self> {
        bytes.strip_prefix(tag).map(Self)
    }

    fn u64(&mut self) -> Option<u64> {
        let (value, rest) = self.0.split_first_chunk::<8>()?;
        self.0 = rest;
        Some(u64::from_le_bytes(*value))
    }

    fn u64s(&mut self) -> Option<Vec<u64>> {
        let count = usize::try_from(self.u64()?).ok()?;
        // At least 8 bytes per value must follow: no huge allocation for bad input.
        if count > self.0.len() / 8 {
            return None;
        }
        (0..count).map(|_| self.u64()).collect()
    }

    fn points(&mut self) -> Option<Vec<TrackPoint>> {
        let (points, rest) = decode_points(self.0)?;
        self.0 = rest;
        Some(points)
    }

    /// `value` when every byte was read.
    fn end<T>(self, value: T) -> Option<T> {
        self.0.is_empty().then_some(value)
    }
}

/// The error for bytes that are not `what`: pass what `from` returned.
fn not_what(what: &str, from: &str) -> Error {
    Error::input(format!(
        "these bytes are not {what}; pass what {from} returned"
    ))
}

const WINDOW: &[u8; 4] = b"SWT1";
const EDGES: &[u8; 4] = b"SWE1";
const IDS: &[u8; 4] = b"SWI1";
const SEAM: &[u8; 4] = b"SWS1";
const PLAN: &[u8; 4] = b"SWP1";

/// A window's tracks as bytes: its first and last frames, then its points.
pub fn encode_window(window: &WindowTracks) -> Vec<u8> {
    let mut out = Writer::new(WINDOW);
    out.u64(window.first)
        .u64(window.last)
        .points(&window.points);
    out.0
}

/// The window's tracks [`encode_window`] encoded.
pub fn decode_window(bytes: &[u8]) -> Result<WindowTracks> {
    (|| {
        let mut input = Reader::new(bytes, WINDOW)?;
        let (first, last) = (input.u64()?, input.u64()?);
        let points = input.points()?;
        input.end(WindowTracks {
            first,
            last,
            points,
        })
    })()
    .ok_or_else(|| not_what("a window's tracks", "track_window"))
}

/// A window's edges as bytes.
pub fn encode_edges(edges: &WindowEdges) -> Vec<u8> {
    let mut out = Writer::new(EDGES);
    out.u64(edges.first)
        .u64(edges.last)
        .points(&edges.head)
        .points(&edges.tail)
        .u64s(edges.ids.iter().copied());
    out.0
}

/// The edges [`encode_edges`] encoded.
pub fn decode_edges(bytes: &[u8]) -> Result<WindowEdges> {
    (|| {
        let mut input = Reader::new(bytes, EDGES)?;
        let (first, last) = (input.u64()?, input.u64()?);
        let (head, tail) = (input.points()?, input.points()?);
        let ids = input.u64s()?;
        input.end(WindowEdges {
            first,
            last,
            head,
            tail,
            ids,
        })
    })()
    .ok_or_else(|| not_what("a window's edges", "window_edges"))
}

/// What the planner needs of a window, as bytes: its first frame and track ids.
pub fn encode_ids(first: FrameIndex, ids: &[TrackId]) -> Vec<u8> {
    let mut out = Writer::new(IDS);
    out.u64(first).u64s(ids.iter().copied());
    out.0
}

/// The first frame and ids [`encode_ids`] encoded.
pub fn decode_ids(bytes: &[u8]) -> Result<(FrameIndex, Vec<TrackId>)> {
    (|| {
        let mut input = Reader::new(bytes, IDS)?;
        let first = input.u64()?;
        let ids = input.u64s()?;
        input.end((first, ids))
    })()
    .ok_or_else(|| not_what("a window's track ids", "window_ids"))
}

/// A seam as bytes: its report's figures, its pairs, the points each side keeps.
pub fn encode_seam(seam: &Seam) -> Vec<u8> {
    let r = &seam.report;
    let figures = [
        r.cut,
        r.earlier_at_cut as u64,
        r.later_at_cut as u64,
        r.joined as u64,
        r.identical as u64,
        r.duplicates as u64,
        r.warm_up as u64,
    ];
    let mut out = Writer::new(SEAM);
    out.u64s(figures.into_iter())
        .u64s(
            seam.joined
                .iter()
                .flat_map(|&(l, e)| [l, e])
                .collect::<Vec<_>>()
                .into_iter(),
        )
        .points(&seam.earlier_tail)
        .points(&seam.later_head);
    out.0
}

/// The seam [`encode_seam`] encoded.
pub fn decode_seam(bytes: &[u8]) -> Result<Seam> {
    (|| {
        let mut input = Reader::new(bytes, SEAM)?;
        let figures = input.u64s()?;
        let [
            cut,
            earlier_at_cut,
            later_at_cut,
            joined,
            identical,
            duplicates,
            warm_up,
        ] = figures[..].try_into().ok()?;
        let count = |n: u64| usize::try_from(n).ok();
        let report = SeamReport {
            cut,
            earlier_at_cut: count(earlier_at_cut)?,
            later_at_cut: count(later_at_cut)?,
            joined: count(joined)?,
            identical: count(identical)?,
            duplicates: count(duplicates)?,
            warm_up: count(warm_up)?,
        };
        let pairs = input.u64s()?;
        let (earlier_tail, later_head) = (input.points()?, input.points()?);
        input.end(Seam {
            report,
            joined: pairs.chunks_exact(2).map(|p| (p[0], p[1])).collect(),
            earlier_tail,
            later_head,
        })
    })()
    .ok_or_else(|| not_what("a seam", "join_seam"))
}

/// A window's share plan as bytes.
pub fn encode_plan(plan: &PartPlan) -> Vec<u8> {
    let pairs = plan.ids.pairs();
    let mut out = Writer::new(PLAN);
    out.u64(plan.from)
        .u64(plan.to.unwrap_or(u64::MAX))
        .u64s(
            pairs
                .iter()
                .flat_map(|&(l, g)| [l, g])
                .collect::<Vec<_>>()
                .into_iter(),
        )
        .points(&plan.carried)
        .points(&plan.head);
    out.0
}

/// The share plan [`encode_plan`] encoded.
pub fn decode_plan(bytes: &[u8]) -> Result<PartPlan> {
    (|| {
        let mut input = Reader::new(bytes, PLAN)?;
        let (from, to) = (input.u64()?, input.u64()?);
        let pairs: Vec<(TrackId, TrackId)> = input
            .u64s()?
            .chunks_exact(2)
            .map(|p| (p[0], p[1]))
            .collect();
        let (carried, head) = (input.points()?, input.points()?);
        input.end(PartPlan {
            from,
            to: (to != u64::MAX).then_some(to),
            ids: IdMap::from_pairs(&pairs),
            carried,
            head,
        })
    })()
    .ok_or_else(|| not_what("a window's share plan", "PartPlanner.push"))
}

#[cfg(test)]
mod tests {
    use sillage_core::{Point2, Vec2};

    use super::*;

    fn point(frame: FrameIndex, id: TrackId) -> TrackPoint {
        TrackPoint {
            vel_px_per_frame: Some(Vec2::new(0.5, -1.0)),
            ..TrackPoint::at(frame, id, Point2::new(1.25 + frame as f64, 7.5))
        }
    }

    #[test]
    fn every_kind_survives_its_bytes_and_refuses_the_others() {
        let window = WindowTracks {
            first: 40,
            last: 99,
            points: vec![point(41, 3), point(42, 3)],
        };
        let bytes = encode_window(&window);
        assert_eq!(decode_window(&bytes).unwrap(), window);
        let edges = window.edges(Some(50), Some(90));
        assert_eq!(decode_edges(&encode_edges(&edges)).unwrap(), edges);
        assert_eq!(
            decode_ids(&encode_ids(40, &[3, 8])).unwrap(),
            (40, vec![3, 8])
        );
        let seam = Seam {
            report: SeamReport {
                cut: 45,
                joined: 1,
                warm_up: 2,
                ..SeamReport::default()
            },
            joined: vec![(3, 9)],
            earlier_tail: vec![point(46, 9)],
            later_head: vec![],
        };
        assert_eq!(decode_seam(&encode_seam(&seam)).unwrap(), seam);
        let plan = PartPlan {
            from: 45,
            to: None,
            ids: IdMap::from_pairs(&[(3, 12), (8, 13)]),
            carried: vec![point(46, 12)],
            head: vec![],
        };
        assert_eq!(decode_plan(&encode_plan(&plan)).unwrap(), plan);

        let err = decode_seam(&bytes).unwrap_err().to_string();
        assert!(
            err.contains("not a seam") && err.contains("join_seam"),
            "{err}"
        );
        let err = decode_window(b"not tracks").unwrap_err().to_string();
        assert!(err.contains("not a window's tracks"), "{err}");
        let mut cut = encode_plan(&plan);
        cut.pop();
        assert!(decode_plan(&cut).is_err());
    }
}
