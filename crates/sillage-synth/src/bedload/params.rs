//! Parameters of the synthetic bedload scene (MMPF+ paper §3.5.1, §4.2, §4.3) and their checks.

use serde::{Deserialize, Serialize};
use sillage_core::{BLACK_BEAD_CLASS, Error, ObjectClass, Result};

use super::bed::{bed_black_count, lodged_count, lodging_site_count, lowest_surface_y};

/// Parameters of the true bead motion. Defaults follow the paper's experimental sequence
/// ExpSeq (§4.2) and the authors' BeadTracking code where they give a value, and documented
/// choices elsewhere. Positions are px (y down, the bed at the bottom), speeds px/frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BedloadSceneParams {
    /// Frame width, px (default 1280, ExpSeq §4.2).
    pub width: usize,
    /// Frame height, px (default 320, ExpSeq §4.2).
    pub height: usize,
    /// Number of frames the scene yields (default 200).
    pub n_frames: usize,
    /// Black (coarse, 6 mm) beads in every frame, bed included (default 300: §4.2, "about
    /// 300 coarse and 100 small beads").
    pub n_black: usize,
    /// Transparent (small, 4 mm) beads in every frame, all mobile (default 100, §4.2).
    pub n_transparent: usize,
    /// Full hexagonal layers of black beads that make the bed, the creeping ones included
    /// (default 8: the real sequence's deposit, its beads resting or rolling below the
    /// saltating ones, fills the frame up to y ≈ 110 px, MMPF+ Fig. 1).
    pub bed_layers: usize,
    /// Top layers of the bed that creep downstream over the static ones below, each one
    /// spanning the frame (default 2: the real sequence's rolling beads, about a third of
    /// the black ones, lie in the 2–3 bead layers above its static bed, y ≈ 110–180 px,
    /// the top one carrying the mobile beads).
    pub creeping_layers: usize,
    /// Range `[min, max]` of the speed at which the top creeping layer slips over the layer
    /// below it, drawn at the start of each of its moving spells, px/frame; the layer `k`
    /// (1 at the bottom) of `n` slips at `k/n` of such a speed, and each layer is carried by
    /// those below (default [0.2, 2.6]: the real sequence's beads move faster the higher
    /// they lie, and its rolling ones by a median 1 px/frame, 95 % below 4.5; at most
    /// 10 px/frame over all the layers).
    pub creep_speed_px_per_frame: [f64; 2],
    /// Per-frame probabilities that a stopped creeping layer starts slipping over the layer
    /// below and that a slipping one stops (default [0.12, 0.07]: stopping as a rolling bead
    /// does in Eq. (11), starting more often, so that the layers slip 63 % of the time and
    /// the black beads roll about as often as the real sequence's, 35 %).
    pub creep_switching: [f64; 2],
    /// Fraction of the transparent beads lodged in the static bed (its top layer and the
    /// third from the top), in the place of a black bead, lying on the two black beads below,
    /// always resting (default 0.7: small beads sink into the
    /// coarse bed; 76 % of the real sequence's transparent beads rest, most of them within
    /// its static bed).
    pub transparent_in_bed: f64,
    /// Black bead radius, px (default 15: BeadTracking's radBlackBeadPx at 2.056e-4 m/px).
    pub black_radius_px: f64,
    /// Transparent bead radius, px (default 10: BeadTracking's radTransBeadPx).
    pub transparent_radius_px: f64,
    /// −1: the flow runs right to left (beads move towards −x), +1: left to right (default
    /// −1, BeadTracking's flumeDirection).
    pub flow_direction: i32,
    /// Per-frame motion-state transition table, rows from (resting, rolling, saltating),
    /// columns to the same (default Eq. (11) of the paper).
    pub transition_probabilities: [[f64; 3]; 3],
    /// Range `[min, max]` of rolling speeds along x, drawn at the start of each rolling spell
    /// (default [1, 5] px/frame: between the code's u_rest = 0.561 and u_salt = 9.35).
    pub rolling_speed_px_per_frame: [f64; 2],
    /// Range of the horizontal speed of a saltation, drawn at its launch (default [9, 17]
    /// px/frame: the real sequence's saltating beads move by a median 13 px/frame, about
    /// BeadTracking's veloSaltInit = radSearch/2 = 15.5 px/frame).
    pub saltation_speed_px_per_frame: [f64; 2],
    /// Range of the vertical launch speed of each hop, which sets its duration
    /// `round(2v/g)` (default [2, 8] px/frame: hops of 2 to 9 frames, apex up to 19 px).
    pub launch_speed_px_per_frame: [f64; 2],
    /// Gravity of the hops, px/frame² (default 1.7: the buoyancy-reduced gravity of glass
    /// beads, 9.81·(1 − 1/2.5) m/s², at 130 frames/s and 2.056e-4 m/px).
    pub gravity_px_per_frame2: f64,
    /// Least height above the pile (the bed and the beads on it) of a saltating bead between
    /// two contacts, px (default 0.5); a hop too short to clear it is steepened to keep it.
    pub hop_clearance_px: f64,
    /// Largest displacement of a resting bead between two frames, px (default 0.05, at most
    /// 0.1): the position is its rest point plus a uniform offset in a disk of half that.
    pub resting_jitter_px: f64,
    /// Radius of the static random offset of each bed bead from its lattice site, px
    /// (default 0.5, at most a tenth of the black radius): beads roughly in contact.
    pub bed_disorder_px: f64,
    /// Closest centre distance of two beads, as a fraction of the sum of their radii, for
    /// (black–black, black–transparent, transparent–transparent) pairs (default [0.93, 0.91,
    /// 0.72]): beads touch at this distance and never come closer. The flume is 6.5 mm wide,
    /// about one bead, so beads cannot pass through each other (§4.1); a 2-D projection
    /// still shows them closer than the sum of their radii when they sit side by side in
    /// depth, which the small beads can (6.5 − 2·4 = −1.5 mm: they overlap by up to 37 %).
    /// The defaults are the median nearest-neighbour distances of each pair in the ten real
    /// frames' ground truth (28.0, 22.8 and 14.3 px over sums of 30, 25 and 20 px), above
    /// their minima (26.2, 20.6 and 12.5 px). The bed surface uses them too.
    pub contact_factors: [f64; 3],
    /// Least elevation of the contact through which a rolling bead climbs onto another
    /// mobile bead, degrees (default 20): it rolls over a bead whose centre lies below its
    /// own by at least the contact distance times sin 20° (a third of it), such as a small
    /// bead sunk in a dip of the bed (28° for a black bead), and stops behind a bead about
    /// as high as itself, which it would have to lift rather than roll over. The bed itself
    /// never stops it.
    pub min_climb_angle_deg: f64,
    /// Seed of every random draw (default 0).
    pub seed: u64,
}

impl Default for BedloadSceneParams {
    fn default() -> Self {
        Self {
            width: 1280,
            height: 320,
            n_frames: 200,
            n_black: 300,
            n_transparent: 100,
            bed_layers: 8,
            creeping_layers: 2,
            creep_speed_px_per_frame: [0.2, 2.6],
            creep_switching: [0.12, 0.07],
            transparent_in_bed: 0.7,
            black_radius_px: 15.0,
            transparent_radius_px: 10.0,
            flow_direction: -1,
            transition_probabilities: [[0.95, 0.05, 0.0], [0.07, 0.92, 0.01], [0.0, 0.09, 0.91]],
            rolling_speed_px_per_frame: [1.0, 5.0],
            saltation_speed_px_per_frame: [9.0, 17.0],
            launch_speed_px_per_frame: [2.0, 8.0],
            gravity_px_per_frame2: 1.7,
            hop_clearance_px: 0.5,
            resting_jitter_px: 0.05,
            bed_disorder_px: 0.5,
            contact_factors: [0.93, 0.91, 0.72],
            min_climb_angle_deg: 20.0,
            seed: 0,
        }
    }
}

/// Largest frame side accepted, px.
const MAX_SIDE: usize = 32_768;
/// Largest number of beads of one class accepted.
const MAX_BEADS: usize = 1_000_000;
/// Largest speed accepted, px/frame.
const MAX_SPEED: f64 = 1_000.0;
/// Largest speed of the top creeping layer, px/frame (each layer slips over the one below
/// by up to `creep_speed_px_per_frame[1]`): well below the 25 px a bead moves in a frame at
/// most, so that a bead carried by it can still roll.
const MAX_TOP_CREEP_SPEED: f64 = 10.0;

impl BedloadSceneParams {
    /// Checks every value; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        for (key, side) in [("width", self.width), ("height", self.height)] {
            if !(1..=MAX_SIDE).contains(&side) {
                let message = format!("must be in 1..={MAX_SIDE}");
                return Err(Error::parameter(key, side, message));
            }
        }
        for (key, n) in [
            ("n_black", self.n_black),
            ("n_transparent", self.n_transparent),
        ] {
            if n > MAX_BEADS {
                return Err(Error::parameter(key, n, format!("must be ≤ {MAX_BEADS}")));
            }
        }
        let max_radius = self.width.min(self.height) as f64 / 4.0;
        check("black_radius_px", self.black_radius_px, 0.5, max_radius)?;
        check(
            "transparent_radius_px",
            self.transparent_radius_px,
            0.5,
            max_radius,
        )?;
        if self.flow_direction != -1 && self.flow_direction != 1 {
            let message = "must be −1 (right to left) or +1 (left to right)";
            return Err(Error::parameter(
                "flow_direction",
                self.flow_direction,
                message,
            ));
        }
        self.validate_transitions()?;
        check_range(
            "rolling_speed_px_per_frame",
            self.rolling_speed_px_per_frame,
            0.0,
            MAX_SPEED,
        )?;
        self.validate_creep()?;
        let saltation = self.saltation_speed_px_per_frame;
        check_range("saltation_speed_px_per_frame", saltation, 0.0, MAX_SPEED)?;
        check_range(
            "launch_speed_px_per_frame",
            self.launch_speed_px_per_frame,
            0.0,
            MAX_SPEED,
        )?;
        check(
            "gravity_px_per_frame2",
            self.gravity_px_per_frame2,
            0.01,
            100.0,
        )?;
        check("hop_clearance_px", self.hop_clearance_px, 0.0, 100.0)?;
        check("resting_jitter_px", self.resting_jitter_px, 0.0, 0.1)?;
        check(
            "bed_disorder_px",
            self.bed_disorder_px,
            0.0,
            self.black_radius_px / 10.0,
        )?;
        for factor in self.contact_factors {
            if !(factor.is_finite() && (0.5..=1.0).contains(&factor)) {
                return Err(Error::parameter(
                    "contact_factors",
                    format!("{:?}", self.contact_factors),
                    "each factor (black–black, black–transparent, transparent–transparent) \
                     must be in [0.5, 1]",
                ));
            }
        }
        check("min_climb_angle_deg", self.min_climb_angle_deg, 0.0, 90.0)?;
        self.validate_bed()
    }

    fn validate_transitions(&self) -> Result<()> {
        for (from, row) in self.transition_probabilities.iter().enumerate() {
            let sum: f64 = row.iter().sum();
            let valid = row.iter().all(|p| p.is_finite() && (0.0..=1.0).contains(p));
            if !valid || (sum - 1.0).abs() > 1e-6 {
                return Err(Error::parameter(
                    "transition_probabilities",
                    format!("{row:?} (row {from})"),
                    "each row (from resting, rolling, saltating) holds three probabilities in \
                     [0, 1] that sum to 1",
                ));
            }
        }
        Ok(())
    }

    fn validate_creep(&self) -> Result<()> {
        if self.creeping_layers > self.bed_layers {
            let message = format!("must be ≤ bed_layers ({})", self.bed_layers);
            return Err(Error::parameter(
                "creeping_layers",
                self.creeping_layers,
                message,
            ));
        }
        let layers = self.creeping_layers.max(1) as f64;
        check_range(
            "creep_speed_px_per_frame",
            self.creep_speed_px_per_frame,
            0.0,
            MAX_TOP_CREEP_SPEED / layers,
        )?;
        let [start, stop] = self.creep_switching;
        if !(0.0..=1.0).contains(&start) || !(0.0..=1.0).contains(&stop) {
            return Err(Error::parameter(
                "creep_switching",
                format!("{:?}", self.creep_switching),
                "both probabilities (start, stop) must be in [0, 1]",
            ));
        }
        check("transparent_in_bed", self.transparent_in_bed, 0.0, 1.0)?;
        let lodged = lodged_count(self);
        let room = lodging_site_count(self);
        if lodged > room {
            let message = format!(
                "lodges {lodged} transparent beads in the {room} sites of the top static layer \
                 and the third from the top; lower it or add layers"
            );
            return Err(Error::parameter(
                "transparent_in_bed",
                self.transparent_in_bed,
                message,
            ));
        }
        if lodged > 0 && self.transparent_radius_px > self.black_radius_px {
            let message = "must be 0 when transparent beads are larger than black ones";
            return Err(Error::parameter(
                "transparent_in_bed",
                self.transparent_in_bed,
                message,
            ));
        }
        Ok(())
    }

    fn validate_bed(&self) -> Result<()> {
        let bed = bed_black_count(self);
        if self.n_black < bed {
            return Err(Error::parameter(
                "n_black",
                self.n_black,
                format!(
                    "must be ≥ {bed}, the black beads of {} full bed layers across {} px; \
                     lower `bed_layers` or raise `n_black`",
                    self.bed_layers, self.width
                ),
            ));
        }
        if lowest_surface_y(self) < 0.0 {
            return Err(Error::parameter(
                "bed_layers",
                self.bed_layers,
                format!(
                    "the bed is taller than the {}-px frame; use fewer layers",
                    self.height
                ),
            ));
        }
        Ok(())
    }

    /// Radius of the beads of `class`, px (black for [`BLACK_BEAD_CLASS`], transparent else).
    pub fn radius_px(&self, class: ObjectClass) -> f64 {
        if class == BLACK_BEAD_CLASS {
            self.black_radius_px
        } else {
            self.transparent_radius_px
        }
    }

    /// The closest distance of the centres of two beads of classes `a` and `b`, px: the sum
    /// of their radii times the pair's `contact_factors` entry.
    pub fn contact_distance_px(&self, a: ObjectClass, b: ObjectClass) -> f64 {
        let transparent = usize::from(a != BLACK_BEAD_CLASS) + usize::from(b != BLACK_BEAD_CLASS);
        self.contact_factors[transparent] * (self.radius_px(a) + self.radius_px(b))
    }

    /// The stationary distribution of the transition table over (resting, rolling,
    /// saltating), by power iteration from the uniform one: the initial states of the mobile
    /// beads.
    pub fn stationary_distribution(&self) -> [f64; 3] {
        let table = &self.transition_probabilities;
        let mut p = [1.0 / 3.0; 3];
        for _ in 0..10_000 {
            let mut next = [0.0; 3];
            for (from, row) in table.iter().enumerate() {
                for (to, q) in row.iter().enumerate() {
                    next[to] += p[from] * q;
                }
            }
            p = next;
        }
        let sum: f64 = p.iter().sum();
        p.map(|x| x / sum)
    }
}

/// `value` must be finite and in `[low, high]`.
pub(crate) fn check(key: &str, value: f64, low: f64, high: f64) -> Result<()> {
    if value.is_finite() && (low..=high).contains(&value) {
        Ok(())
    } else {
        let message = format!("must be a finite number in [{low}, {high}]");
        Err(Error::parameter(key, value, message))
    }
}

/// `range` must be `[min, max]` with `low ≤ min ≤ max ≤ high`, both finite.
pub(crate) fn check_range(key: &str, range: [f64; 2], low: f64, high: f64) -> Result<()> {
    let [min, max] = range;
    let inside = |v: f64| v.is_finite() && (low..=high).contains(&v);
    if inside(min) && inside(max) && min <= max {
        Ok(())
    } else {
        let message = format!("must be [min, max] with {low} ≤ min ≤ max ≤ {high}");
        Err(Error::parameter(key, format!("{range:?}"), message))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_leave_28_mobile_black_beads() {
        let params = BedloadSceneParams::default();
        params.validate().unwrap();
        // 6 static layers of 43 sites, 70 of them holding a transparent bead, and 2
        // creeping layers of 42 beads.
        assert_eq!(lodged_count(&params), 70);
        assert_eq!(bed_black_count(&params), 6 * 43 - 70 + 2 * 42);
    }

    #[test]
    fn bad_values_name_their_key() {
        type Case = (&'static str, fn(&mut BedloadSceneParams));
        let cases: [Case; 21] = [
            ("width", |p| p.width = 0),
            ("n_transparent", |p| p.n_transparent = usize::MAX),
            ("n_black", |p| p.n_black = 100),
            ("bed_layers", |p| (p.bed_layers, p.n_black) = (12, 600)),
            ("black_radius_px", |p| p.black_radius_px = f64::NAN),
            ("transparent_radius_px", |p| p.transparent_radius_px = 0.0),
            ("flow_direction", |p| p.flow_direction = 0),
            ("transition_probabilities", |p| {
                p.transition_probabilities[0][0] = 0.9
            }),
            ("rolling_speed_px_per_frame", |p| {
                p.rolling_speed_px_per_frame = [5.0, 1.0]
            }),
            ("saltation_speed_px_per_frame", |p| {
                p.saltation_speed_px_per_frame[0] = -1.0
            }),
            ("launch_speed_px_per_frame", |p| {
                p.launch_speed_px_per_frame[1] = f64::INFINITY
            }),
            ("gravity_px_per_frame2", |p| p.gravity_px_per_frame2 = 0.0),
            ("creeping_layers", |p| p.creeping_layers = 9),
            ("creep_speed_px_per_frame", |p| {
                p.creep_speed_px_per_frame = [1.0, 6.0]
            }),
            ("creep_switching", |p| p.creep_switching[1] = f64::NAN),
            ("transparent_in_bed", |p| p.transparent_in_bed = 1.5),
            ("transparent_in_bed", |p| p.n_transparent = 200),
            ("resting_jitter_px", |p| p.resting_jitter_px = 0.2),
            ("bed_disorder_px", |p| p.bed_disorder_px = 5.0),
            ("contact_factors", |p| p.contact_factors[2] = 0.4),
            ("min_climb_angle_deg", |p| p.min_climb_angle_deg = f64::NAN),
        ];
        for (key, spoil) in cases {
            let mut params = BedloadSceneParams::default();
            spoil(&mut params);
            let err = params.validate().unwrap_err().to_string();
            assert!(err.contains(&format!("`{key}`")), "{key}: {err}");
        }
    }

    #[test]
    fn stationary_distribution_of_eq_11_balances_the_flows() {
        let p = BedloadSceneParams::default().stationary_distribution();
        // A birth-death chain: p_rest·0.05 = p_roll·0.07 and p_roll·0.01 = p_salt·0.09.
        assert!((p[0] * 0.05 - p[1] * 0.07).abs() < 1e-9);
        assert!((p[1] * 0.01 - p[2] * 0.09).abs() < 1e-9);
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }
}
