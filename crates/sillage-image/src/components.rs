//! Connected components of a binary mask (8-connectivity, MATLAB's `regionprops` default) with
//! their area, centroid and bounding box.
//!
//! Fast method: run-based union–find. Each row is cut into runs of set pixels; a run is merged
//! with the runs of the row above that touch it (overlap extended by one column for diagonal
//! contact), then the area and coordinate sums are accumulated per root. The cost is one scan
//! of the mask plus work proportional to the number of runs, sequential and deterministic.

use sillage_core::{Image, Point2};

/// One connected component.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Component {
    /// Number of pixels, px².
    pub area: usize,
    /// Mean of the pixel coordinates, px (sub-pixel).
    pub centroid: Point2,
    /// The smallest box holding every pixel.
    pub bbox: PixelBox,
}

/// An axis-aligned box of whole pixels, half-open: columns `x0..x1`, rows `y0..y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct PixelBox {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

impl PixelBox {
    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.x1 - self.x0
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.y1 - self.y0
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &PixelBox) -> PixelBox {
        PixelBox {
            x0: self.x0.min(other.x0),
            y0: self.y0.min(other.y0),
            x1: self.x1.max(other.x1),
            y1: self.y1.max(other.y1),
        }
    }

    /// Whether the boxes overlap or lie within `gap_px` pixels of each other (a gap of
    /// `gap_px` empty columns or rows or fewer between them).
    pub fn within(&self, other: &PixelBox, gap_px: usize) -> bool {
        self.x0 <= other.x1 + gap_px
            && other.x0 <= self.x1 + gap_px
            && self.y0 <= other.y1 + gap_px
            && other.y0 <= self.y1 + gap_px
    }
}

/// A run of set pixels `x0..x1` in row `y`, and its union–find parent (an index into the runs).
#[derive(Debug, Clone, Copy)]
struct Run {
    y: usize,
    x0: usize,
    x1: usize,
    parent: usize,
}

/// Labels the 8-connected components of masks, keeping its buffers between calls.
#[derive(Debug, Clone, Default)]
pub struct ComponentLabeller {
    runs: Vec<Run>,
    root_to_component: Vec<usize>,
    sums: Vec<RunSums>,
}

/// What [`ComponentLabeller`] accumulates per component.
#[derive(Debug, Clone, Copy)]
struct RunSums {
    area: usize,
    sum_x: f64,
    sum_y: f64,
    bbox: PixelBox,
}

impl ComponentLabeller {
    /// A labeller with empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Writes into `out` (cleared first) the 8-connected components of the pixels of `mask`
    /// that are `true`, ordered by their first pixel in raster order.
    pub fn label(&mut self, mask: &Image<bool>, out: &mut Vec<Component>) {
        out.clear();
        self.collect_runs(mask);
        let runs = &mut self.runs;
        // Runs of the previous row: `prev.start..prev.end`, sorted by x0.
        let mut prev = 0..0;
        let mut i = 0;
        while i < runs.len() {
            let y = runs[i].y;
            let row_end = i + runs[i..].iter().take_while(|r| r.y == y).count();
            if !prev.is_empty() && runs[prev.start].y + 1 != y {
                prev = 0..0;
            }
            let mut k = prev.start;
            for j in i..row_end {
                let (x0, x1) = (runs[j].x0, runs[j].x1);
                // Skip runs above that end before this one starts (minus one column).
                while k < prev.end && runs[k].x1 < x0 {
                    k += 1;
                }
                let mut m = k;
                while m < prev.end && runs[m].x0 <= x1 {
                    union(runs, j, m);
                    m += 1;
                }
            }
            prev = i..row_end;
            i = row_end;
        }
        self.accumulate(out);
    }

    /// Fills `runs` with the runs of set pixels, row by row (each its own parent), with
    /// `x1` one past the run's last pixel. Rows are read 64 pixels at a time as bit words,
    /// runs found by counting trailing zeros: mostly empty masks cost one pass of word loads.
    fn collect_runs(&mut self, mask: &Image<bool>) {
        self.runs.clear();
        for y in 0..mask.height() {
            let row = mask.row(y);
            // The first column of the run that is open at the current chunk, if any.
            let mut open: Option<usize> = None;
            for (c, chunk) in row.chunks(64).enumerate() {
                let base = 64 * c;
                let valid = u64::MAX >> (64 - chunk.len());
                let mut bits = pack_bits(chunk);
                loop {
                    let start = match open {
                        Some(start) => start,
                        None if bits == 0 => break,
                        None => {
                            let start = base + bits.trailing_zeros() as usize;
                            open = Some(start);
                            start
                        }
                    };
                    // The first clear pixel at or after the run's start within this chunk.
                    let from = start.saturating_sub(base);
                    let clear = !bits & valid & (u64::MAX << from);
                    if clear == 0 {
                        break;
                    }
                    let end = clear.trailing_zeros() as usize;
                    self.push_run(y, start, base + end);
                    open = None;
                    bits &= u64::MAX.checked_shl(end as u32).unwrap_or(0);
                }
            }
            if let Some(start) = open {
                self.push_run(y, start, row.len());
            }
        }
    }

    /// Appends the run `x0..x1` of row `y`, its own parent.
    fn push_run(&mut self, y: usize, x0: usize, x1: usize) {
        let parent = self.runs.len();
        self.runs.push(Run { y, x0, x1, parent });
    }

    /// Sums area and coordinates per root into components, in order of first run.
    fn accumulate(&mut self, out: &mut Vec<Component>) {
        self.root_to_component.clear();
        self.root_to_component.resize(self.runs.len(), usize::MAX);
        self.sums.clear();
        for j in 0..self.runs.len() {
            let root = find(&mut self.runs, j);
            let run = self.runs[j];
            let run_box = PixelBox {
                x0: run.x0,
                y0: run.y,
                x1: run.x1,
                y1: run.y + 1,
            };
            let slot = &mut self.root_to_component[root];
            if *slot == usize::MAX {
                *slot = self.sums.len();
                self.sums.push(RunSums {
                    area: 0,
                    sum_x: 0.0,
                    sum_y: 0.0,
                    bbox: run_box,
                });
            }
            let n = run.x1 - run.x0;
            let entry = &mut self.sums[*slot];
            entry.area += n;
            // Σx over x0..x1 = n·(x0 + x1 − 1)/2, exact in f64 for any frame size.
            entry.sum_x += n as f64 * (run.x0 + run.x1 - 1) as f64 / 2.0;
            entry.sum_y += (n * run.y) as f64;
            entry.bbox = entry.bbox.union(&run_box);
        }
        out.extend(self.sums.iter().map(|s| Component {
            area: s.area,
            centroid: Point2::new(s.sum_x / s.area as f64, s.sum_y / s.area as f64),
            bbox: s.bbox,
        }));
    }
}

/// Bit `i` set where `chunk[i]` is (up to 64 pixels), eight at a time: the eight bytes of a
/// group (each 0 or 1) as one little-endian word, times `0x0102…80`, gather in its top byte
/// with byte `i` at bit `i` (no carries: the partial sums of a byte stay below 256).
fn pack_bits(chunk: &[bool]) -> u64 {
    const GATHER: u64 = 0x0102_0408_1020_4080;
    let groups = chunk.chunks_exact(8);
    let tail = groups.remainder();
    let mut bits = 0;
    let mut shift = 0;
    for group in groups {
        let bytes: &[bool; 8] = group.try_into().expect("chunks_exact gives 8");
        let word = u64::from_le_bytes(bytes.map(u8::from));
        bits |= (word.wrapping_mul(GATHER) >> 56) << shift;
        shift += 8;
    }
    for (i, &set) in tail.iter().enumerate() {
        bits |= u64::from(set) << (shift + i);
    }
    bits
}

/// Root of run `i`, halving the path on the way.
fn find(runs: &mut [Run], mut i: usize) -> usize {
    while runs[i].parent != i {
        let grandparent = runs[runs[i].parent].parent;
        runs[i].parent = grandparent;
        i = grandparent;
    }
    i
}

/// Joins the sets of runs `a` and `b`; the smaller index becomes the root, so roots (and the
/// component order) do not depend on the merge order.
fn union(runs: &mut [Run], a: usize, b: usize) {
    let (ra, rb) = (find(runs, a), find(runs, b));
    if ra != rb {
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        runs[hi].parent = lo;
    }
}
