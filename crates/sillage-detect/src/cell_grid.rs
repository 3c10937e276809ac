//! Detections bucketed on a grid of square cells, for the detections near a position.

use sillage_core::{Detection, Point2};

/// Detections bucketed by cell (a counting sort): each cell's members are contiguous and the
/// cells row-major, so the three cells of a grid row around a position are one slice.
#[derive(Debug, Clone, Default)]
pub(crate) struct CellGrid {
    cell: f64,
    offset: (f64, f64),
    cols: usize,
    rows: usize,
    /// Where each cell's members start in `members` (one more entry than cells).
    start: Vec<u32>,
    /// Detection indices, cell by cell.
    members: Vec<u32>,
}

impl CellGrid {
    /// Buckets `detections`, positions in the pixels of an image of `width` × `height` plus
    /// `offset`, in cells of side `cell` (positions outside fall in the border cells).
    pub(crate) fn rebuild(
        &mut self,
        (width, height): (usize, usize),
        detections: &[Detection],
        offset: (f64, f64),
        cell: f64,
    ) {
        (self.cell, self.offset) = (cell, offset);
        self.cols = (width as f64 / cell).ceil() as usize + 1;
        self.rows = (height as f64 / cell).ceil() as usize + 1;
        let cells = self.cols * self.rows;
        self.start.clear();
        self.start.resize(cells + 1, 0);
        for d in detections {
            let (cx, cy) = self.cell_of(d.pos_px);
            self.start[cy * self.cols + cx + 1] += 1;
        }
        for i in 1..self.start.len() {
            self.start[i] += self.start[i - 1];
        }
        self.members.clear();
        self.members.resize(detections.len(), 0);
        // Each cell's start serves as its fill cursor, then is shifted back into place.
        for (i, d) in detections.iter().enumerate() {
            let (cx, cy) = self.cell_of(d.pos_px);
            let slot = &mut self.start[cy * self.cols + cx];
            self.members[*slot as usize] = i as u32;
            *slot += 1;
        }
        self.start.copy_within(0..cells, 1);
        self.start[0] = 0;
    }

    /// The cell of position `p` (in the detections' coordinates).
    fn cell_of(&self, p: Point2) -> (usize, usize) {
        let cx = ((p.x - self.offset.0).max(0.0) / self.cell) as usize;
        let cy = ((p.y - self.offset.1).max(0.0) / self.cell) as usize;
        (cx.min(self.cols - 1), cy.min(self.rows - 1))
    }

    /// The indices of the detections in the 3 × 3 cells around `p`'s (every detection
    /// within one cell side of `p`, and some farther), row by row.
    pub(crate) fn near(&self, p: Point2) -> impl Iterator<Item = usize> + '_ {
        let (cx, cy) = self.cell_of(p);
        let (x0, x1) = (cx.saturating_sub(1), (cx + 1).min(self.cols - 1));
        (cy.saturating_sub(1)..=(cy + 1).min(self.rows - 1)).flat_map(move |y| {
            let (first, last) = (y * self.cols + x0, y * self.cols + x1);
            self.members[self.start[first] as usize..self.start[last + 1] as usize]
                .iter()
                .map(|&j| j as usize)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_holds_every_detection_within_a_cell_side() {
        let detections: Vec<Detection> = (0..400)
            .map(|k| {
                let p = Point2::new(
                    10.0 + (k * 37 % 97) as f64 * 0.8,
                    10.0 + (k * 61 % 89) as f64 * 0.9,
                );
                Detection::new(p, 1.0)
            })
            .collect();
        let mut grid = CellGrid::default();
        grid.rebuild((100, 100), &detections, (10.0, 10.0), 5.0);
        for probe in [
            Point2::new(12.0, 13.0),
            Point2::new(55.5, 60.2),
            Point2::new(200.0, 5.0),
        ] {
            let mut got: Vec<usize> = grid
                .near(probe)
                .filter(|&j| detections[j].pos_px.distance(probe) < 5.0)
                .collect();
            got.sort_unstable();
            let want: Vec<usize> = (0..detections.len())
                .filter(|&j| detections[j].pos_px.distance(probe) < 5.0)
                .collect();
            assert_eq!(got, want, "around {probe:?}");
        }
    }
}
