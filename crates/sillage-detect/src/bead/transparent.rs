//! Transparent beads (MMPF+ paper §3.3.1, BeadTracking's `DetectTransBeads`): black beads and
//! the flume base erased into the background (a morphological closing), black top-hat,
//! h-concave transform, normalised cross-correlation with the ring template, 3×3 mean
//! smoothing, local maxima; maxima above τ_t are beads, maxima above the lower candidate
//! threshold are the detector-confidence candidates of Eq. (1) (§3.3.2).

use sillage_core::{Detection, GrayImage, Image, Point2, Result, TRANSPARENT_BEAD_CLASS};
use sillage_image::{
    BoxMean, Morphology, Peak, PeakFinder, Reconstruction, RingCorrelator, RingTemplate,
    StructuringElement,
};

/// The thresholds and sizes of the transparent stage, all checked by
/// [`crate::bead::BeadParams::validate`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct TransparentSettings {
    pub(crate) background_radius_px: usize,
    pub(crate) erase_radius_px: usize,
    pub(crate) h: f32,
    pub(crate) smoothing_passes: usize,
    pub(crate) detection_threshold: f32,
    pub(crate) candidate_threshold: f32,
    /// Maxima on input pixels at or below this grey level are dropped (`None`: kept).
    pub(crate) dark_level: Option<f32>,
}

/// The transparent-bead stage with its buffers.
#[derive(Debug, Clone)]
pub(crate) struct TransparentStage {
    settings: TransparentSettings,
    background: StructuringElement,
    /// Rows `(dy, dx0, dx1)` (inclusive) of the disk erased around each black bead.
    erase_runs: Vec<(isize, isize, isize)>,
    morphology: Morphology,
    reconstruction: Reconstruction,
    correlator: RingCorrelator,
    smoothing: BoxMean,
    finder: PeakFinder,
    closed: GrayImage,
    top_hat: GrayImage,
    concave: GrayImage,
    correlation: GrayImage,
    smoothed: GrayImage,
    peaks: Vec<Peak>,
    /// The levels path's closing, top-hat and h-concave transform.
    closed_levels: Image<u8>,
    top_hat_levels: Image<u8>,
    concave_levels: Image<u8>,
}

/// What one frame gives: transparent beads and confidence candidates.
pub(crate) struct TransparentOutput<'a> {
    pub(crate) beads: &'a mut Vec<Detection>,
    pub(crate) candidates: &'a mut Vec<Detection>,
}

impl TransparentStage {
    pub(crate) fn new(settings: TransparentSettings, template: RingTemplate) -> Result<Self> {
        let erase_runs = row_runs(&StructuringElement::disk(settings.erase_radius_px)?.offsets());
        Ok(Self {
            settings,
            background: StructuringElement::disk(settings.background_radius_px)?,
            erase_runs,
            morphology: Morphology::new(),
            reconstruction: Reconstruction::new(),
            correlator: RingCorrelator::new(template),
            smoothing: BoxMean::new(),
            finder: PeakFinder::new(),
            closed: GrayImage::default(),
            top_hat: GrayImage::default(),
            concave: GrayImage::default(),
            correlation: GrayImage::default(),
            smoothed: GrayImage::default(),
            peaks: Vec::new(),
            closed_levels: Image::default(),
            top_hat_levels: Image::default(),
            concave_levels: Image::default(),
        })
    }

    /// Correlates with `template` from now on.
    pub(crate) fn set_template(&mut self, template: RingTemplate) {
        self.correlator = RingCorrelator::new(template);
    }

    /// The background of the `f32` path: the closing of `bright_base` (the frame with the
    /// base pixels set to 1, so that the closing does not see the base as dark). Independent
    /// of the black beads, so it can run beside the black stage.
    pub(crate) fn close(&mut self, bright_base: &GrayImage) {
        self.morphology
            .close(bright_base, &self.background, &mut self.closed);
    }

    /// Appends the transparent beads and candidates of `frame`, after [`Self::close`] on
    /// `bright_base`; `base` is the base mask and `black` the black beads found in it.
    pub(crate) fn detect(
        &mut self,
        frame: &GrayImage,
        base: Option<&Image<bool>>,
        black: &[Detection],
        out: TransparentOutput<'_>,
    ) -> Result<()> {
        erased_top_hat(
            &self.closed,
            frame,
            base,
            black,
            &self.erase_runs,
            &mut self.top_hat,
        );
        self.reconstruction
            .h_concave(&self.top_hat, self.settings.h, &mut self.concave)?;
        self.correlator.apply(&self.concave, &mut self.correlation);
        self.select(frame, base, out);
        Ok(())
    }

    /// [`Self::close`] on the 8-bit levels of the bright-base frame.
    pub(crate) fn close_levels(&mut self, bright_base: &Image<u8>) {
        self.morphology
            .close_levels(bright_base, &self.background, &mut self.closed_levels);
    }

    /// [`Self::detect`] on the 8-bit levels of the bright-base frame, after
    /// [`Self::close_levels`] on them, with `h` as a level: top-hat and h-concave transform
    /// exactly on levels, the correlation with exact integer sums (the `f32` path rounds
    /// `closing − f`, `+ h` and its correlation sums, within `f32` rounding of these values).
    pub(crate) fn detect_levels(
        &mut self,
        frame: &GrayImage,
        bright_base: &Image<u8>,
        h: u8,
        base: Option<&Image<bool>>,
        black: &[Detection],
        out: TransparentOutput<'_>,
    ) {
        erased_top_hat(
            &self.closed_levels,
            bright_base,
            base,
            black,
            &self.erase_runs,
            &mut self.top_hat_levels,
        );
        self.reconstruction
            .h_concave_levels(&self.top_hat_levels, h, &mut self.concave_levels);
        self.correlator
            .apply_levels(&self.concave_levels, &mut self.correlation);
        self.select(frame, base, out);
    }

    /// Smooths the correlation map and appends its maxima off the base and not too dark in
    /// `frame`: candidates, and beads where they reach τ_t.
    fn select(
        &mut self,
        frame: &GrayImage,
        base: Option<&Image<bool>>,
        out: TransparentOutput<'_>,
    ) {
        let s = self.settings;
        self.smoothing
            .apply(&self.correlation, s.smoothing_passes, &mut self.smoothed);
        std::mem::swap(&mut self.correlation, &mut self.smoothed);
        // PeakFinder keeps values strictly above its threshold; BeadTracking keeps `≥`, the
        // same maxima but for exact ties.
        self.finder
            .find(&self.correlation, 1, s.candidate_threshold, &mut self.peaks);
        for peak in &self.peaks {
            let on_base = base.is_some_and(|b| b.get(peak.x, peak.y));
            let dark = s
                .dark_level
                .is_some_and(|level| frame.get(peak.x, peak.y) <= level);
            if on_base || dark {
                continue;
            }
            let score = self.correlation.get(peak.x, peak.y);
            let pos_px = Point2::new(peak.x as f64, peak.y as f64);
            let candidate = Detection::of_class(pos_px, score, TRANSPARENT_BEAD_CLASS);
            out.candidates.push(candidate);
            if score >= s.detection_threshold {
                out.beads.push(candidate);
            }
        }
    }
}

/// A pixel type of the top-hat: `f32` grey levels or 8-bit levels.
trait TopHatPixel: Copy + Default + Send + Sync {
    /// `closed − frame` (never negative: a closing is above its image), 0 on the base.
    fn top_hat(closed: Self, frame: Self, on_base: bool) -> Self;
}

impl TopHatPixel for f32 {
    #[inline(always)]
    fn top_hat(closed: f32, frame: f32, on_base: bool) -> f32 {
        // Branch-free (`c − f` with its bits cleared on the base), so that it vectorises.
        let keep = u32::from(on_base).wrapping_sub(1);
        f32::from_bits((closed - frame).to_bits() & keep)
    }
}

impl TopHatPixel for u8 {
    #[inline(always)]
    fn top_hat(closed: u8, frame: u8, on_base: bool) -> u8 {
        closed.wrapping_sub(frame) & u8::from(on_base).wrapping_sub(1)
    }
}

/// `top_hat` (reshaped) `= closed − frame` (the black top-hat: dark rings stand out), 0 on
/// the base and on the disk `erase_runs` around each black bead: there the frame is replaced
/// by the background, as the paper erases black beads before looking for transparent ones.
fn erased_top_hat<T: TopHatPixel>(
    closed: &Image<T>,
    frame: &Image<T>,
    base: Option<&Image<bool>>,
    black: &[Detection],
    erase_runs: &[(isize, isize, isize)],
    top_hat: &mut Image<T>,
) {
    let (width, height) = frame.dimensions();
    top_hat.reshape(width, height);
    let pixels = top_hat
        .as_mut_slice()
        .iter_mut()
        .zip(closed.as_slice())
        .zip(frame.as_slice());
    match base {
        Some(base) => {
            for (((t, &c), &f), &b) in pixels.zip(base.as_slice()) {
                *t = T::top_hat(c, f, b);
            }
        }
        None => pixels.for_each(|((t, &c), &f)| *t = T::top_hat(c, f, false)),
    }
    for bead in black {
        let (cx, cy) = (
            bead.pos_px.x.round() as isize,
            bead.pos_px.y.round() as isize,
        );
        for &(dy, dx0, dx1) in erase_runs {
            let y = cy + dy;
            if y < 0 || y >= height as isize {
                continue;
            }
            let x0 = (cx + dx0).max(0);
            let x1 = (cx + dx1).min(width as isize - 1);
            if x0 <= x1 {
                top_hat.row_mut(y as usize)[x0 as usize..=x1 as usize].fill(T::default());
            }
        }
    }
}

/// Maximal horizontal runs `(dy, dx0, dx1)` (inclusive) of offsets sorted by row then column.
fn row_runs(offsets: &[(isize, isize)]) -> Vec<(isize, isize, isize)> {
    let mut runs: Vec<(isize, isize, isize)> = Vec::new();
    for &(dx, dy) in offsets {
        match runs.last_mut() {
            Some(run) if run.0 == dy && run.2 + 1 == dx => run.2 = dx,
            _ => runs.push((dy, dx, dx)),
        }
    }
    runs
}
