//! The rule that decides when a prediction matches a true object: a similarity measure and
//! its least value, written `iou[:T]`, `dist:R` or `disc[:T]` (the `--match` option).

use std::fmt;
use std::str::FromStr;

use sillage_core::{Error, Result};

use super::Similarity;

/// How the similarity of a prediction and a true object is measured, and the least
/// similarity of a match.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MatchRule {
    /// Box IoU at least `threshold`.
    Iou {
        /// Least IoU.
        threshold: f64,
    },
    /// Centres at most `radius_px` apart.
    Distance {
        /// Largest distance, px.
        radius_px: f64,
    },
    /// Disc IoU (beads) at least `threshold`.
    Disc {
        /// Least IoU.
        threshold: f64,
    },
}

impl Default for MatchRule {
    /// `iou:0.5`, the MOTChallenge rule.
    fn default() -> Self {
        MatchRule::Iou { threshold: 0.5 }
    }
}

impl MatchRule {
    /// The similarity measure. `dist:R` is TrackEval's Euclidean similarity vanishing at
    /// `2R`, so that the threshold 0.5 accepts exactly the centres within `R`.
    pub fn similarity(self) -> Similarity {
        match self {
            MatchRule::Iou { .. } => Similarity::BoxIou,
            MatchRule::Distance { radius_px } => Similarity::Distance {
                zero_distance_px: 2.0 * radius_px,
            },
            MatchRule::Disc { .. } => Similarity::DiscIou,
        }
    }

    /// The least similarity of a match.
    pub fn threshold(self) -> f64 {
        match self {
            MatchRule::Iou { threshold } | MatchRule::Disc { threshold } => threshold,
            MatchRule::Distance { .. } => 0.5,
        }
    }
}

impl fmt::Display for MatchRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MatchRule::Iou { threshold } => write!(f, "iou:{threshold} (box IoU ≥ {threshold})"),
            MatchRule::Distance { radius_px } => {
                write!(f, "dist:{radius_px} (centres at most {radius_px} px apart)")
            }
            MatchRule::Disc { threshold } => {
                write!(f, "disc:{threshold} (bead disc IoU ≥ {threshold})")
            }
        }
    }
}

impl FromStr for MatchRule {
    type Err = Error;

    /// Parses `iou[:T]` (default 0.5), `dist:R` or `disc[:T]` (default 0.43, the MMPF+
    /// paper's threshold).
    fn from_str(text: &str) -> Result<Self> {
        let (kind, value) = match text.split_once(':') {
            Some((kind, value)) => (kind, Some(value)),
            None => (text, None),
        };
        let number = |value: &str, what: &str, valid: fn(f64) -> bool| {
            value
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|&v| valid(v))
                .ok_or_else(|| Error::input(format!("`{value}` is not {what}")))
        };
        let threshold = |default: f64| match value {
            Some(v) => number(v, "an IoU in (0, 1]", |t| t > 0.0 && t <= 1.0),
            None => Ok(default),
        };
        match kind.trim().to_ascii_lowercase().as_str() {
            "iou" => Ok(MatchRule::Iou {
                threshold: threshold(0.5)?,
            }),
            "disc" => Ok(MatchRule::Disc {
                threshold: threshold(0.43)?,
            }),
            "dist" => {
                let value = value
                    .ok_or_else(|| Error::input("dist needs a distance in px, e.g. dist:5"))?;
                Ok(MatchRule::Distance {
                    radius_px: number(value, "a distance > 0 (px)", |r| r.is_finite() && r > 0.0)?,
                })
            }
            _ => Err(Error::input(format!(
                "`{text}` is not a matching rule; use iou[:T], dist:R or disc[:T]"
            ))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_parse_with_their_defaults_and_display_in_words() {
        let rule: MatchRule = "iou".parse().unwrap();
        assert_eq!(rule, MatchRule::Iou { threshold: 0.5 });
        assert_eq!(rule.to_string(), "iou:0.5 (box IoU ≥ 0.5)");
        let rule: MatchRule = "DISC".parse().unwrap();
        assert_eq!(rule, MatchRule::Disc { threshold: 0.43 });
        assert_eq!(rule.threshold(), 0.43);
        let rule: MatchRule = "dist:1.5".parse().unwrap();
        assert_eq!(rule.to_string(), "dist:1.5 (centres at most 1.5 px apart)");
        assert_eq!(rule.threshold(), 0.5);
        assert_eq!(
            rule.similarity(),
            Similarity::Distance {
                zero_distance_px: 3.0
            }
        );
    }

    #[test]
    fn bad_rules_say_what_is_allowed() {
        let message = |text: &str| text.parse::<MatchRule>().unwrap_err().to_string();
        assert_eq!(message("iou:1.5"), "`1.5` is not an IoU in (0, 1]");
        assert_eq!(message("dist"), "dist needs a distance in px, e.g. dist:5");
        assert_eq!(message("dist:-1"), "`-1` is not a distance > 0 (px)");
        assert_eq!(
            message("box"),
            "`box` is not a matching rule; use iou[:T], dist:R or disc[:T]"
        );
    }
}
