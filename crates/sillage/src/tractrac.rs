//! TracTrac `*_par.txt` files mapped onto a [`PipelineConfig`], so TracTrac users keep their
//! parameter files. Keys absent from the file leave the configuration as it is; the `plot*`
//! keys and the Matlab post-processing keys are accepted and ignored (they drive TracTrac's
//! live display and its own post-processing).

use sillage_core::{Error, Result};
use sillage_detect::blob::{PolarityChoice, Scale};
use sillage_detect::{BlobFilter, Threshold};
use sillage_image::{MedianSize, Roi, SubpixelFit};
use sillage_io::TractracPar;

use crate::config::{DetectorConfig, PipelineConfig, TrackerConfig};

/// A par-file flag (`0`/`1`) as a boolean; other values are an error naming the key.
fn flag(key: &str, value: f64) -> Result<bool> {
    match value {
        0.0 => Ok(false),
        1.0 => Ok(true),
        v => Err(Error::parameter(key, v, "must be 0 or 1")),
    }
}

/// A par-file count as an integer; fractions and negative values are an error naming the key.
fn count(key: &str, value: f64) -> Result<usize> {
    if value >= 0.0 && value.fract() == 0.0 && value <= u32::MAX as f64 {
        Ok(value as usize)
    } else {
        Err(Error::parameter(
            key,
            value,
            "must be a non-negative integer",
        ))
    }
}

/// TracTrac's 1-based ROI bounds as a 0-based [`Roi`] (TracTrac's `setup_parameters` subtracts
/// 1 from the minima; its maxima are inclusive 1-based, i.e. exclusive 0-based).
fn roi(par: &TractracPar) -> Result<Option<Roi>> {
    let given = [par.roi_xmin, par.roi_ymin, par.roi_xmax, par.roi_ymax];
    if given.iter().all(|v| v.is_none_or(|v| v == 0.0)) {
        return Ok(None);
    }
    let (Some(xmax), Some(ymax)) = (
        par.roi_xmax.filter(|&v| v > 0.0),
        par.roi_ymax.filter(|&v| v > 0.0),
    ) else {
        return Err(Error::parameter(
            "ROIxmax/ROIymax",
            "missing",
            "a region of interest needs ROIxmax and ROIymax (1-based, inclusive) besides ROIxmin/ROIymin",
        ));
    };
    let low = |key: &str, v: Option<f64>| -> Result<usize> {
        Ok(count(key, v.unwrap_or(0.0))?.saturating_sub(1))
    };
    let roi = Roi {
        x0: low("ROIxmin", par.roi_xmin)?,
        y0: low("ROIymin", par.roi_ymin)?,
        x1: count("ROIxmax", xmax)?,
        y1: count("ROIymax", ymax)?,
    };
    roi.validate("ROIxmin..ROIymax")?;
    Ok(Some(roi))
}

/// Applies every key of `par` that sillage uses to `config`.
pub fn apply_par(config: &mut PipelineConfig, par: &TractracPar) -> Result<()> {
    if let Some(v) = par.vid_loop {
        config.training_passes = count("vid_loop", v)?;
    }
    let background_speed = par.bg_speed.or(par.bg_speed_matlab);
    match par.bg.map(|v| flag("BG", v)).transpose()? {
        Some(true) => {
            let mut background = config.preprocess.background.unwrap_or_default();
            if let Some(speed) = background_speed {
                background.speed = speed as f32;
            }
            config.preprocess.background = Some(background);
        }
        Some(false) => config.preprocess.background = None,
        None => {
            if let (Some(background), Some(speed)) =
                (&mut config.preprocess.background, background_speed)
            {
                background.speed = speed as f32;
            }
        }
    }
    let median_size = match par.noise_size {
        Some(3.0) => MedianSize::Three,
        Some(5.0) => MedianSize::Five,
        Some(v) => return Err(Error::parameter("noise_size", v, "must be 3 or 5")),
        None => MedianSize::Three,
    };
    match par.noise.map(|v| flag("noise", v)).transpose()? {
        Some(true) => config.preprocess.median = Some(median_size),
        Some(false) => config.preprocess.median = None,
        None => {}
    }

    let DetectorConfig::Blob(blob) = &mut config.detector else {
        return Err(Error::parameter(
            "detector.kind",
            "bead",
            "a TracTrac parameter file sets the blob detector; set detector.kind = \"blob\"",
        ));
    };
    if let Some(v) = par.peak_conv {
        blob.filter = match v {
            0.0 => BlobFilter::None,
            1.0 => BlobFilter::Dog,
            2.0 => BlobFilter::Log,
            v => {
                return Err(Error::parameter(
                    "peak_conv",
                    v,
                    "must be 0 (none), 1 (DoG) or 2 (LoG); 3 (Shi–Tomasi corners) is not supported",
                ));
            }
        };
    }
    if let Some(v) = par.peak_conv_size {
        blob.scale_px = Scale::Px(v);
    }
    if let Some(v) = par.peak_neigh {
        blob.neighbourhood = count("peak_neigh", v)?;
    }
    let automatic = par
        .peak_th_auto
        .map(|v| flag("peak_th_auto", v))
        .transpose()?;
    match (automatic, par.peak_th) {
        (Some(false), Some(th)) => blob.threshold = Threshold::Fixed(th),
        (Some(false), None) => blob.threshold = Threshold::Fixed(0.02),
        (Some(true), _) => blob.threshold = Threshold::Auto { std_factor: 0.5 },
        (None, Some(th)) if matches!(blob.threshold, Threshold::Fixed(_)) => {
            blob.threshold = Threshold::Fixed(th)
        }
        (None, _) => {}
    }
    if let Some(v) = par.peak_subpix {
        blob.subpixel = match v {
            0.0 => SubpixelFit::Quadratic,
            1.0 => SubpixelFit::Gaussian,
            v => {
                return Err(Error::parameter(
                    "peak_subpix",
                    v,
                    "must be 0 (quadratic) or 1 (gaussian)",
                ));
            }
        };
    }
    if let Some(v) = par.peak_minima {
        blob.polarity = if flag("peak_minima", v)? {
            PolarityChoice::Dark
        } else {
            PolarityChoice::Bright
        };
    }
    if let Some(roi) = roi(par)? {
        blob.roi = Some(roi);
    }

    let TrackerConfig::Ptv(ptv) = &mut config.tracker else {
        return Err(Error::parameter(
            "tracker.kind",
            "bedload",
            "a TracTrac parameter file sets the PTV tracker; set tracker.kind = \"ptv\"",
        ));
    };
    if let Some(v) = par.motion {
        ptv.motion = flag("motion", v)?;
    }
    if let Some(v) = par.motion_av {
        ptv.motion_av = count("motion_av", v)?;
    }
    if let Some(v) = par.motion_it {
        ptv.motion_it = count("motion_it", v)?;
    }
    if let Some(v) = par.filter {
        ptv.filter = flag("filter", v)?;
    }
    if let Some(v) = par.filter_std {
        ptv.filter_std = v;
    }
    if let Some(v) = par.filter_time {
        ptv.filter_time = v;
    }
    config.validate()
}
