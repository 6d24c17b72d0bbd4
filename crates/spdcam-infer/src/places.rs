//! The light at several places of one photo: where a photo shows several charts, each
//! gives its own estimate, and this module compares them as a person checking a room
//! would: do the lights match in colour (the largest Δu′v′ between two places, CIE 1976
//! UCS, the colour-matching question a meter answers), how far their CCT and Duv spread,
//! how bright each place is against the brightest (the photo's exposure is shared, so the
//! charts' linear levels compare: [`crate::absolute::chart_level`]), and which place differs
//! most.
//!
//! Whether the lights differ is read on the charts' grey patches, not on the estimates:
//! under one light every chart's greys show one colour in the photo (one camera, one white
//! balance), whatever chart they belong to and whatever a model makes of its coloured
//! patches, while each estimate carries its own error (several thousandths of Δu′v′,
//! `docs/colour.md`), too much to tell lights 0.01 apart from one light. "The lights differ"
//! is said when two places' greys lie more than [`LIGHTS_DIFFER_DUV`] apart in u′v′ (a
//! just-noticeable colour difference is about 0.004); where a place's greys cannot be read,
//! the estimates are compared instead. (Comparing two charts' greys level for level, against
//! a tone curve that might shift a grey's colour with its level, told the lights apart no
//! better on the validation scenes: the greys' mean colours are compared.)

use crate::absolute::ChartLevel;
use serde::Serialize;
use spdcam_core::quality::uv::xy_to_uv1976;

/// The largest Δu′v′ between two places' greys (or, where a place's greys cannot be read,
/// their estimates) above which the photo's lights are said to differ. Chosen on validation
/// scenes (`spdcam experiment places`, docs/places.md): charts under one light within it,
/// lights 0.01 apart beyond it.
pub const LIGHTS_DIFFER_DUV: f64 = 0.0085;

/// One place's light, as the comparison shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlaceLight {
    /// The place's number (1-based, left to right).
    pub number: usize,
    /// The chart's centre, photo pixels.
    pub centre: [f64; 2],
    /// The estimated light's CIE 1976 u′v′.
    pub uv_prime: [f64; 2],
    /// The chart's greys' u′v′ as the photo shows them; `None` when none could be read.
    pub grey_uv_prime: Option<[f64; 2]>,
    /// CCT, K (`None` far from the Planckian locus).
    pub cct: Option<f64>,
    /// Duv.
    pub duv: Option<f64>,
    /// The light's level here against the brightest place's (1 there); `None` when the
    /// chart's level could not be read (no usable grey patch, reflectances not at hand).
    pub relative_illuminance: Option<f64>,
}

/// How the light compares across the places of one photo.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LightAcrossPlaces {
    /// Every place, in number order.
    pub places: Vec<PlaceLight>,
    /// The two places whose estimated lights differ most in colour, and their Δu′v′.
    pub largest_delta_uv: (usize, usize, f64),
    /// The two places whose greys differ most in colour, and their Δu′v′; `None` when a
    /// place's greys could not be read.
    pub greys_largest_delta_uv: Option<(usize, usize, f64)>,
    /// The place whose light differs most from the others' (the largest mean Δu′v′ to the
    /// rest, of the greys where every place's were read, else of the estimates).
    pub most_different: usize,
    /// Highest less lowest CCT among the places that have one, K.
    pub cct_spread_k: Option<f64>,
    /// Highest less lowest Duv.
    pub duv_spread: Option<f64>,
    /// Whether the lights differ in colour: the largest Δu′v′ between the greys (else the
    /// estimates) above [`LIGHTS_DIFFER_DUV`].
    pub lights_differ: bool,
}

/// What one place of a photo gave: its place, its estimate's colour and the light read on
/// its grey patches.
#[derive(Debug, Clone, Copy)]
pub struct PlaceReading<'a> {
    /// The place's number (1-based, left to right).
    pub number: usize,
    /// The chart's centre, photo pixels.
    pub centre: [f64; 2],
    /// The estimate's CIE 1931 xy.
    pub xy: [f64; 2],
    /// The estimate's CCT, K.
    pub cct: Option<f64>,
    /// The estimate's Duv.
    pub duv: Option<f64>,
    /// The light on the chart read on its greys ([`crate::absolute::chart_level`]).
    pub level: Option<&'a ChartLevel>,
}

impl LightAcrossPlaces {
    /// The comparison of one photo's places; `None` for fewer than two.
    pub fn of(readings: &[PlaceReading<'_>]) -> Option<LightAcrossPlaces> {
        let mut placed = readings.to_vec();
        if placed.len() < 2 {
            return None;
        }
        placed.sort_by_key(|p| p.number);
        let brightest = placed
            .iter()
            .filter_map(|p| p.level.map(|l| l.level))
            .fold(f64::NAN, f64::max);
        let places: Vec<PlaceLight> = placed
            .iter()
            .map(|p| PlaceLight {
                number: p.number,
                centre: p.centre,
                uv_prime: xy_to_uv1976(p.xy),
                grey_uv_prime: p.level.map(|l| l.grey_uv_prime),
                cct: p.cct,
                duv: p.duv,
                relative_illuminance: p
                    .level
                    .filter(|_| brightest > 0.0)
                    .map(|l| l.level / brightest),
            })
            .collect();
        let estimates: Vec<[f64; 2]> = places.iter().map(|p| p.uv_prime).collect();
        let levels: Option<Vec<&ChartLevel>> = placed.iter().map(|p| p.level).collect();
        let numbers: Vec<usize> = places.iter().map(|p| p.number).collect();
        let n = places.len();
        let estimate_distances: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| distance(estimates[i], estimates[j]))
                    .collect()
            })
            .collect();
        let grey_distances: Option<Vec<Vec<f64>>> = levels.as_ref().map(|levels| {
            (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| greys_distance(levels[i], levels[j]))
                        .collect()
                })
                .collect()
        });
        let largest = largest_pair(&estimate_distances, &numbers);
        let greys_largest = grey_distances.as_ref().map(|d| largest_pair(d, &numbers));
        let judged = grey_distances.as_ref().unwrap_or(&estimate_distances);
        let most_different = (0..n)
            .map(|i| (numbers[i], judged[i].iter().sum::<f64>() / (n - 1) as f64))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(numbers[0], |m| m.0);
        let spread = |values: Vec<f64>| {
            (values.len() >= 2).then(|| {
                values.iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v))
                    - values.iter().fold(f64::INFINITY, |m, &v| m.min(v))
            })
        };
        Some(LightAcrossPlaces {
            cct_spread_k: spread(places.iter().filter_map(|p| p.cct).collect()),
            duv_spread: spread(places.iter().filter_map(|p| p.duv).collect()),
            lights_differ: greys_largest.unwrap_or(largest).2 > LIGHTS_DIFFER_DUV,
            largest_delta_uv: largest,
            greys_largest_delta_uv: greys_largest,
            most_different,
            places,
        })
    }

    /// The comparison as lines for a person: the verdict on the colours, the spreads, each
    /// place's level.
    pub fn lines(&self) -> Vec<String> {
        let (a, b, d) = self.largest_delta_uv;
        let estimates = format!("the estimates differ by up to Δu′v′ {d:.4} (places {a} and {b})");
        let mut out = vec![match (self.lights_differ, self.greys_largest_delta_uv) {
            (true, Some((ga, gb, gd))) => format!(
                "the lights differ: the greys of places {ga} and {gb} are Δu′v′ {gd:.4} apart \
                 (above {LIGHTS_DIFFER_DUV}); place {} differs most; {estimates}",
                self.most_different
            ),
            (false, Some((ga, gb, gd))) => format!(
                "one light in colour: the greys agree within Δu′v′ {gd:.4} (places {ga} and \
                 {gb}; within {LIGHTS_DIFFER_DUV}); {estimates}, which is the estimates' own \
                 error"
            ),
            (true, None) => format!(
                "the lights differ: {estimates} (above {LIGHTS_DIFFER_DUV}; a place's greys \
                 could not be read); place {} differs most",
                self.most_different
            ),
            (false, None) => format!(
                "one light in colour as far as the estimates tell: {estimates} (within \
                 {LIGHTS_DIFFER_DUV}; a place's greys could not be read)"
            ),
        }];
        let mut spreads = Vec::new();
        if let Some(s) = self.cct_spread_k {
            spreads.push(format!("CCT spread {s:.0} K"));
        }
        if let Some(s) = self.duv_spread {
            spreads.push(format!("Duv spread {s:.4}"));
        }
        if !spreads.is_empty() {
            out.push(spreads.join(", "));
        }
        let levels: Vec<String> = self
            .places
            .iter()
            .map(|p| match p.relative_illuminance {
                Some(r) => format!("place {} {:.0} %", p.number, 100.0 * r),
                None => format!("place {} —", p.number),
            })
            .collect();
        out.push(format!(
            "light level against the brightest place: {}",
            levels.join(", ")
        ));
        out
    }
}

/// The Δu′v′ between two u′v′ points.
fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The pair of places farthest apart by `distances` (a symmetric table), by their
/// `numbers`, and their distance.
fn largest_pair(distances: &[Vec<f64>], numbers: &[usize]) -> (usize, usize, f64) {
    let mut largest = (numbers[0], numbers[1.min(numbers.len() - 1)], 0.0);
    for i in 0..distances.len() {
        for j in i + 1..distances.len() {
            if distances[i][j] > largest.2 {
                largest = (numbers[i], numbers[j], distances[i][j]);
            }
        }
    }
    largest
}

/// How far apart two charts' greys are in u′v′: the distance of their mean colours.
fn greys_distance(a: &ChartLevel, b: &ChartLevel) -> f64 {
    distance(a.grey_uv_prime, b.grey_uv_prime)
}

#[cfg(test)]
mod tests {
    use super::*;
    use spdcam_core::cie_illuminant::StandardIlluminant;
    use spdcam_core::colorimetry::{uv_to_cct_duv, xy_to_uv1960, Observer};
    use spdcam_core::spectral::Grid;

    /// A place under `light` whose greys show the light's own colour, at `level`.
    fn reading(
        light: StandardIlluminant,
        number: usize,
        level: f64,
    ) -> (PlaceReading<'static>, ChartLevel) {
        let grid = Grid::ESTIMATION;
        let spd = light.spd(&grid).unwrap();
        let xy = Observer::cie1931(&grid).unwrap().spd_to_xy(spd.values());
        let (cct, duv) = uv_to_cct_duv(xy_to_uv1960(xy)).unwrap();
        let chart = ChartLevel {
            level,
            grey_uv_prime: xy_to_uv1976(xy),
            patches: Vec::new(),
        };
        let place = PlaceReading {
            number,
            centre: [10.0 * number as f64, 5.0],
            xy,
            cct: Some(cct),
            duv: Some(duv),
            level: None,
        };
        (place, chart)
    }

    fn compare(lights: &[(StandardIlluminant, f64)]) -> Option<LightAcrossPlaces> {
        let made: Vec<(PlaceReading, ChartLevel)> = lights
            .iter()
            .enumerate()
            .map(|(k, &(light, level))| reading(light, k + 1, level))
            .collect();
        let readings: Vec<PlaceReading> = made
            .iter()
            .map(|(p, chart)| PlaceReading {
                level: Some(chart),
                ..*p
            })
            .collect();
        LightAcrossPlaces::of(&readings)
    }

    #[test]
    fn a_warm_place_among_daylight_ones_differs_most() {
        use StandardIlluminant::{A, D65};
        let across = compare(&[(D65, 0.8), (A, 0.4), (D65, 0.8)]).unwrap();
        assert!(across.lights_differ);
        assert_eq!(across.most_different, 2);
        // D65 u′v′ (0.1978, 0.4683), A (0.2560, 0.5243): Δu′v′ 0.0808 (CIE 015:2018).
        let (a, b, d) = across.largest_delta_uv;
        assert_eq!((a, b), (1, 2));
        assert!((d - 0.0808).abs() < 0.001, "{d}");
        assert_eq!(
            across.greys_largest_delta_uv.map(|g| (g.0, g.1)),
            Some((1, 2))
        );
        assert!((across.cct_spread_k.unwrap() - (6504.0 - 2856.0)).abs() < 20.0);
        let levels: Vec<Option<f64>> = across
            .places
            .iter()
            .map(|p| p.relative_illuminance)
            .collect();
        assert_eq!(levels, vec![Some(1.0), Some(0.5), Some(1.0)]);
        assert!(across.lines()[0].starts_with("the lights differ"));
    }

    #[test]
    fn one_light_at_every_place_is_one_light() {
        let d65 = StandardIlluminant::D65;
        let across = compare(&[(d65, 0.8), (d65, 0.2)]).unwrap();
        assert!(!across.lights_differ);
        assert!(across.largest_delta_uv.2 < 1e-12);
        assert!(across.lines()[0].starts_with("one light in colour"));
        assert_eq!(across.places[1].relative_illuminance, Some(0.25));
    }

    #[test]
    fn without_greys_the_estimates_decide_and_one_place_is_no_comparison() {
        let (a, _) = reading(StandardIlluminant::A, 1, 1.0);
        let (d65, _) = reading(StandardIlluminant::D65, 2, 1.0);
        let across = LightAcrossPlaces::of(&[a, d65]).unwrap();
        assert!(across.lights_differ && across.greys_largest_delta_uv.is_none());
        assert!(across
            .places
            .iter()
            .all(|p| p.relative_illuminance.is_none()));
        assert!(across.lines()[0].contains("a place's greys could not be read"));
        assert_eq!(LightAcrossPlaces::of(&[a]), None);
    }
}
