//! Histograms of one quantity (displacement magnitudes, log10 prediction errors): equal bins
//! over the range of the values, counts on a linear or a logarithmic scale.

use plotters::coord::Shift;
use plotters::prelude::*;
use sillage_core::{Error, Result};

use crate::canvas::{Plot, drawing_error};
use crate::font::FAMILY;
use crate::palette::series_colour;

/// The counts of a histogram: `counts[k]` values in `[low + k·width, low + (k+1)·width)`
/// (the last bin closed).
#[derive(Debug, Clone, PartialEq)]
pub struct Bins {
    /// Left edge of the first bin.
    pub low: f64,
    /// Width of every bin.
    pub width: f64,
    /// Values per bin.
    pub counts: Vec<u64>,
}

/// A histogram of `values`.
#[derive(Debug, Clone, PartialEq)]
pub struct Histogram {
    /// Title above the chart.
    pub title: String,
    /// The quantity and its unit, under the x axis.
    pub x_label: String,
    /// The values; those not finite are left out.
    pub values: Vec<f64>,
    /// Number of bins (at least 1).
    pub bins: usize,
    /// Counts on a log10 scale (tails of error distributions).
    pub log_y: bool,
}

impl Histogram {
    /// `bins` equal bins from the smallest to the largest finite value (one unit wide
    /// around it when all are equal), and how many values fall in each.
    pub fn bin_counts(&self) -> Bins {
        let finite = || self.values.iter().copied().filter(|v| v.is_finite());
        let (min, max) = finite().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let (low, high) = if min < max {
            (min, max)
        } else {
            (min - 0.5, min + 0.5)
        };
        let n = self.bins.max(1);
        let width = (high - low) / n as f64;
        let mut counts = vec![0; n];
        for v in finite() {
            let k = (((v - low) / width) as usize).min(n - 1);
            counts[k] += 1;
        }
        Bins { low, width, counts }
    }
}

impl Plot for Histogram {
    /// Checks the bin count and that a value is finite.
    fn validate(&self) -> Result<()> {
        if self.bins == 0 {
            return Err(Error::parameter("bins", 0, "give at least 1 bin"));
        }
        if !self.values.iter().any(|v| v.is_finite()) {
            return Err(Error::input(format!(
                "{}: no finite value to count",
                self.title
            )));
        }
        Ok(())
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let bins = self.bin_counts();
        let most = bins.counts.iter().copied().max().unwrap_or(1).max(1) as f64;
        // Log scale: bars rise from 0.5 so a bin of one value shows; labels at the decades.
        let (height, y_range, y_desc): (fn(u64) -> f64, std::ops::Range<f64>, &str) = if self.log_y
        {
            (
                |c: u64| (c as f64).log10(),
                0.5f64.log10()..most.log10() + 0.3,
                "count (log scale)",
            )
        } else {
            (|c: u64| c as f64, 0.0..most * 1.08, "count")
        };
        let high = bins.low + bins.width * bins.counts.len() as f64;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FAMILY, 18))
            .margin(10)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(bins.low..high, y_range.clone())
            .map_err(drawing_error)?;
        let decade = |v: &f64| {
            if (v - v.round()).abs() < 1e-9 {
                format!("{}", 10f64.powi(v.round() as i32))
            } else {
                String::new()
            }
        };
        let linear = |v: &f64| format!("{v:.0}");
        let y_labels: &dyn Fn(&f64) -> String = if self.log_y { &decade } else { &linear };
        chart
            .configure_mesh()
            .disable_x_mesh()
            .light_line_style(TRANSPARENT)
            .bold_line_style(RGBColor(230, 230, 230))
            .x_desc(&self.x_label)
            .y_desc(y_desc)
            .y_label_formatter(y_labels)
            .x_label_formatter(&|v| format!("{v:.2}"))
            .label_style((FAMILY, 12))
            .axis_desc_style((FAMILY, 13))
            .draw()
            .map_err(drawing_error)?;
        let colour = series_colour(0);
        let bars = bins
            .counts
            .iter()
            .enumerate()
            .filter(|&(_, &c)| c > 0)
            .map(|(k, &c)| {
                let x0 = bins.low + k as f64 * bins.width;
                Rectangle::new(
                    [(x0, y_range.start), (x0 + bins.width, height(c))],
                    colour.filled(),
                )
            });
        chart.draw_series(bars).map_err(drawing_error)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn histogram(values: Vec<f64>, log_y: bool) -> Histogram {
        Histogram {
            title: "h".into(),
            x_label: "speed (px/frame)".into(),
            values,
            bins: 4,
            log_y,
        }
    }

    fn blue_pixels(picture: &sillage_core::RgbImage) -> usize {
        let c = series_colour(0);
        picture
            .as_slice()
            .iter()
            .filter(|&&p| p == [c.0, c.1, c.2])
            .count()
    }

    #[test]
    fn values_fall_in_equal_bins_and_the_last_is_closed() {
        let h = histogram(vec![0.0, 1.0, 1.5, 2.0, 3.9, 4.0, f64::NAN], false);
        assert_eq!(
            h.bin_counts(),
            Bins {
                low: 0.0,
                width: 1.0,
                counts: vec![1, 2, 1, 2]
            }
        );
        let same = histogram(vec![2.0; 3], false).bin_counts();
        assert_eq!(
            (same.low, same.width, same.counts.iter().sum::<u64>()),
            (1.5, 0.25, 3)
        );
    }

    #[test]
    fn bars_rise_to_their_count() {
        // Counts 1, 0, 0, 9 (linear): the tall bar has 9 times the short bar's area.
        let mut values = vec![0.0];
        values.extend([4.0; 9]);
        let picture = histogram(values.clone(), false).to_rgb(400, 300).unwrap();
        let (left, right): (Vec<usize>, Vec<usize>) = (0..300)
            .flat_map(|y| (0..400).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let c = series_colour(0);
                picture.get(x, y) == [c.0, c.1, c.2]
            })
            .map(|(x, _)| x)
            .partition(|&x| x < 200);
        let ratio = right.len() as f64 / left.len() as f64;
        assert!((8.0..10.0).contains(&ratio), "{ratio}");
        // On a log scale the tall bar is 1 + log10(9)/log10(2) ≈ 4.2 times the short one.
        let log = histogram(values, true).to_rgb(400, 300).unwrap();
        assert!(blue_pixels(&log) < blue_pixels(&picture));
        let svg = histogram(vec![1.0, 2.0], true).to_svg(400, 300).unwrap();
        assert!(svg.contains("speed (px/frame)") && svg.contains("count (log scale)"));
    }

    #[test]
    fn empty_or_binless_histograms_are_refused() {
        let e = histogram(vec![f64::NAN], false)
            .to_rgb(200, 200)
            .unwrap_err();
        assert!(e.to_string().contains("no finite value"), "{e}");
        let none = Histogram {
            bins: 0,
            ..histogram(vec![1.0], false)
        };
        assert!(none.validate().unwrap_err().to_string().contains("bins"));
    }
}
