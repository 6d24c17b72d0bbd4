//! The metric registry: one row per single-number metric a person reads, holding everything
//! the front ends and the trust calibration need to know of it: its key, its names, its
//! unit, its group, how it is rounded, how wide an interval may be before the photo no longer
//! determines it, what values it can take, for which lights it means anything, and whether
//! the trust calibration gives it an interval.
//!
//! Every list of metrics in the program is read from [`METRICS`]: the command line's lines
//! and `spdcam metrics` table, the report's and the web page's groups, the meter's film and
//! TV numbers, Python's view, the trust calibration's intervals and its report. Adding a
//! metric is its own module, its field in [`LightingMetrics`]
//! (`quality/mod.rs`) and its row here.
//!
//! The rules of each column (why 15 % for CCT, 25 for an index …) are those of the rounding
//! module of the inference crate, which documents them with their sources.

use super::LightingMetrics;

/// The heading a metric is shown under.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Group {
    /// The light's colour: CCT and Duv.
    Colour,
    /// How colours look under the light: CRI, TM-30, CQS.
    ColourRendering,
    /// What the light does for the body clock and the eye.
    CircadianAndEye,
    /// What the light does for plants.
    Plants,
    /// Film and television numbers, computed by the meter against a target light.
    FilmTv,
}

impl Group {
    /// The groups of the report and the web page, in order (the film and TV numbers are the
    /// meter's own).
    pub const PRESENTED: [Group; 4] = [
        Group::Colour,
        Group::ColourRendering,
        Group::CircadianAndEye,
        Group::Plants,
    ];

    /// The heading, e.g. `Colour rendering`.
    pub const fn title(self) -> &'static str {
        match self {
            Group::Colour => "Colour",
            Group::ColourRendering => "Colour rendering",
            Group::CircadianAndEye => "Circadian and eye",
            Group::Plants => "Plants",
            Group::FilmTv => "Film and TV",
        }
    }
}

/// How a value without an interval is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// A whole number: `82`, `6480`.
    Whole,
    /// A whole number with its sign: `+12` (a filter's mired shift).
    SignedWhole,
    /// Four decimals with the sign: `+0.0031` (Duv).
    Signed4,
    /// Three significant digits: `0.912`, `1.45`.
    Significant3,
}

impl Precision {
    /// Whether the value is written with its sign (`+0.0031`).
    pub const fn signed(self) -> bool {
        matches!(self, Precision::SignedWhole | Precision::Signed4)
    }
}

/// How wide the 95 % interval may be, as shown, before the photo no longer determines the
/// metric.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Determined {
    /// Half-width at most this share of the value (CCT, the ratios).
    WithinShare(f64),
    /// Half-width at most this, in the metric's unit (indices, mired).
    Within(f64),
    /// Half-width at most this, or the whole interval beyond the |Duv| within which a CCT
    /// means anything (the photo then shows a coloured light, and by about how much).
    WithinOrColoured(f64),
}

/// For which lights a metric means anything.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeaningfulFor {
    /// Every light.
    AnyLight,
    /// Lights with a meaningful correlated colour temperature (near the Planckian locus):
    /// the CCT and the indices whose reference illuminant is chosen by it.
    WhiteLight,
    /// Lights as near the Planckian locus as CIE 13.3 allows (Ra, R1–R14).
    Cri,
}

/// How a metric's value is had from an estimate.
#[derive(Debug, Clone, Copy)]
pub enum Source {
    /// Read from the light's [`LightingMetrics`].
    Lighting(fn(&LightingMetrics) -> Option<f64>),
    /// Computed by the meter against a target light (SSI, filter corrections).
    Meter,
}

/// One single-number metric.
#[derive(Debug, Clone, Copy)]
pub struct Metric {
    /// Its key in JSON, in intervals and in calibrations (`cri_ra`).
    pub key: &'static str,
    /// The key under which [`LightingMetrics::reasons`] says why it is undefined (R9's is
    /// `cri_r`, the list it is taken from).
    pub reason_key: &'static str,
    /// Its short name on a line of numbers (`Ra`).
    pub symbol: &'static str,
    /// Its name in a table (`CRI Ra`).
    pub label: &'static str,
    /// One line of what it tells a person.
    pub explanation: &'static str,
    /// The unit shown after it, empty for none.
    pub unit: &'static str,
    /// What the stored value is multiplied by before it is shown (PPF per lux is shown per
    /// 1000 lx).
    pub shown_scale: f64,
    /// Its heading.
    pub group: Group,
    /// How it is written without an interval.
    pub precision: Precision,
    /// Its decimals (after [`Metric::shown_scale`]) in `spdcam metrics`' table of measured
    /// spectra, where no interval sets them: what a lab compares.
    pub lab_decimals: usize,
    /// When its interval is narrow enough to show a number.
    pub determined: Determined,
    /// Whether it can exceed 100 (no: the indices on the 0–100 scale).
    pub at_most_100: bool,
    /// Whether it can be negative (Duv, mired shifts, CIE 13.3's indices).
    pub may_be_negative: bool,
    /// For which lights it means anything.
    pub meaningful_for: MeaningfulFor,
    /// Whether the trust calibration gives it an interval.
    pub calibrated: bool,
    /// Whether its interval is judged and reported as a share of the value (CCT, whose
    /// goals are in per cent).
    pub interval_in_per_cent: bool,
    /// Where its value comes from.
    pub source: Source,
}

impl Metric {
    /// Its value for `metrics`; `None` when undefined or computed by the meter.
    pub fn value(&self, metrics: &LightingMetrics) -> Option<f64> {
        match self.source {
            Source::Lighting(value) => value(metrics),
            Source::Meter => None,
        }
    }
}

/// A row of [`METRICS`] with the defaults most rows share.
const fn row(
    key: &'static str,
    symbol: &'static str,
    label: &'static str,
    explanation: &'static str,
    group: Group,
    source: Source,
) -> Metric {
    Metric {
        key,
        reason_key: key,
        symbol,
        label,
        explanation,
        unit: "",
        shown_scale: 1.0,
        group,
        precision: Precision::Whole,
        lab_decimals: 1,
        determined: Determined::Within(25.0),
        at_most_100: false,
        may_be_negative: false,
        meaningful_for: MeaningfulFor::AnyLight,
        calibrated: true,
        interval_in_per_cent: false,
        source,
    }
}

/// A ratio: three significant digits, determined while its interval spans less than a
/// factor of three.
const fn ratio(mut m: Metric) -> Metric {
    m.precision = Precision::Significant3;
    m.lab_decimals = 3;
    m.determined = Determined::WithinShare(0.5);
    m
}

/// An index on the 0–100 scale of colour rendering.
const fn index(mut m: Metric, meaningful_for: MeaningfulFor, may_be_negative: bool) -> Metric {
    m.at_most_100 = true;
    m.may_be_negative = may_be_negative;
    m.meaningful_for = meaningful_for;
    m
}

/// Every single-number metric, in the order the front ends show them.
pub const METRICS: [Metric; 16] = [
    Metric {
        unit: "K",
        lab_decimals: 0,
        determined: Determined::WithinShare(0.15),
        interval_in_per_cent: true,
        meaningful_for: MeaningfulFor::WhiteLight,
        ..row(
            "cct_k",
            "CCT",
            "CCT",
            "How warm (low) or cool (high) a white light looks.",
            Group::Colour,
            Source::Lighting(|m| m.cct_k),
        )
    },
    Metric {
        precision: Precision::Signed4,
        lab_decimals: 4,
        determined: Determined::WithinOrColoured(0.0125),
        may_be_negative: true,
        ..row(
            "duv",
            "Duv",
            "Duv",
            "How far from white the colour is: above 0 greenish, below 0 pinkish.",
            Group::Colour,
            Source::Lighting(|m| m.duv),
        )
    },
    index(
        row(
            "cri_ra",
            "Ra",
            "CRI Ra",
            "How true eight pastel colours look (100 = like daylight or a bulb).",
            Group::ColourRendering,
            Source::Lighting(|m| m.cri_ra),
        ),
        MeaningfulFor::Cri,
        true,
    ),
    Metric {
        reason_key: "cri_r",
        ..index(
            row(
                "cri_r9",
                "R9",
                "CRI R9",
                "How true a saturated red looks (skin, food, wood).",
                Group::ColourRendering,
                Source::Lighting(|m| m.cri_r.map(|r| r[8])),
            ),
            MeaningfulFor::Cri,
            true,
        )
    },
    index(
        row(
            "tm30_rf",
            "Rf",
            "TM-30 Rf",
            "Colour fidelity over 99 samples (100 = like the reference light).",
            Group::ColourRendering,
            Source::Lighting(|m| m.tm30_rf),
        ),
        MeaningfulFor::WhiteLight,
        false,
    ),
    Metric {
        meaningful_for: MeaningfulFor::WhiteLight,
        ..row(
            "tm30_rg",
            "Rg",
            "TM-30 Rg",
            "Colour gamut: above 100 colours look more saturated, below 100 duller.",
            Group::ColourRendering,
            Source::Lighting(|m| m.tm30_rg),
        )
    },
    index(
        row(
            "cqs_qa",
            "Qa",
            "CQS Qa",
            "How good 15 saturated colours look, more saturation not counted against the light (NIST CQS 9.0).",
            Group::ColourRendering,
            Source::Lighting(|m| m.cqs_qa),
        ),
        MeaningfulFor::WhiteLight,
        false,
    ),
    ratio(row(
        "mel_der",
        "M-EDER",
        "Melanopic DER",
        "Effect on the body clock per lux, relative to daylight D65 (1 = same).",
        Group::CircadianAndEye,
        Source::Lighting(|m| m.mel_der),
    )),
    Metric {
        lab_decimals: 2,
        ..ratio(row(
            "sp_ratio",
            "S/P",
            "S/P ratio",
            "Night (rod) vision per lux relative to day vision; higher looks brighter at dusk.",
            Group::CircadianAndEye,
            Source::Lighting(|m| m.sp_ratio),
        ))
    },
    Metric {
        unit: "W/lm",
        lab_decimals: 5,
        ..ratio(row(
            "blh_efficacy_w_per_lm",
            "blue-light hazard",
            "Blue-light hazard",
            "Retinal blue-light hazard per lumen (IEC TR 62778); lower is gentler.",
            Group::CircadianAndEye,
            Source::Lighting(|m| m.blh_efficacy_w_per_lm),
        ))
    },
    Metric {
        unit: "µmol s⁻¹ m⁻² per 1000 lx",
        shown_scale: 1000.0,
        lab_decimals: 2,
        ..ratio(row(
            "ppf_per_lux",
            "PPF",
            "PPF per 1000 lx",
            "Photosynthetic photons (400–700 nm) per 1000 lux of light.",
            Group::Plants,
            Source::Lighting(|m| m.ppf_per_lux),
        ))
    },
    Metric {
        calibrated: false,
        ..index(
            row(
                "ssi",
                "SSI",
                "SSI (own CCT)",
                "Academy Spectral Similarity Index against a light of the same CCT.",
                Group::FilmTv,
                Source::Meter,
            ),
            MeaningfulFor::WhiteLight,
            false,
        )
    },
    Metric {
        calibrated: false,
        ..index(
            row(
                "ssi_3200",
                "SSI 3200 K",
                "SSI (3200 K tungsten)",
                "Academy Spectral Similarity Index against 3200 K tungsten.",
                Group::FilmTv,
                Source::Meter,
            ),
            MeaningfulFor::AnyLight,
            false,
        )
    },
    Metric {
        calibrated: false,
        ..index(
            row(
                "ssi_5600",
                "SSI 5600 K",
                "SSI (5600 K daylight)",
                "Academy Spectral Similarity Index against 5600 K daylight.",
                Group::FilmTv,
                Source::Meter,
            ),
            MeaningfulFor::AnyLight,
            false,
        )
    },
    mired(
        "mired_3200",
        "To 3200 K",
        "The filter's mired shift to 3200 K tungsten.",
    ),
    mired(
        "mired_5600",
        "To 5600 K",
        "The filter's mired shift to 5600 K daylight.",
    ),
];

/// A filter correction's mired shift, computed by the meter from the CCT.
const fn mired(key: &'static str, label: &'static str, explanation: &'static str) -> Metric {
    Metric {
        unit: "mired",
        precision: Precision::SignedWhole,
        lab_decimals: 0,
        may_be_negative: true,
        meaningful_for: MeaningfulFor::WhiteLight,
        calibrated: false,
        ..row(key, label, label, explanation, Group::FilmTv, Source::Meter)
    }
}

/// The metric of `key`, if the registry holds it.
pub fn metric(key: &str) -> Option<&'static Metric> {
    METRICS.iter().find(|m| m.key == key)
}

/// The metrics the trust calibration gives intervals, in order.
pub fn calibrated() -> impl Iterator<Item = &'static Metric> {
    METRICS.iter().filter(|m| m.calibrated)
}

/// The metrics shown under `group`, in order.
pub fn in_group(group: Group) -> impl Iterator<Item = &'static Metric> {
    METRICS.iter().filter(move |m| m.group == group)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_unique_and_found() {
        for (i, m) in METRICS.iter().enumerate() {
            assert!(
                METRICS[..i].iter().all(|o| o.key != m.key),
                "{} twice",
                m.key
            );
            assert_eq!(metric(m.key).map(|f| f.key), Some(m.key));
        }
        assert!(metric("no such metric").is_none());
    }

    #[test]
    fn every_lighting_metric_is_calibrated_and_presented() {
        for m in METRICS {
            let lighting = matches!(m.source, Source::Lighting(_));
            assert_eq!(lighting, m.group != Group::FilmTv, "{}", m.key);
            if lighting {
                assert!(m.calibrated, "{}", m.key);
            }
        }
        let presented: usize = Group::PRESENTED.iter().map(|&g| in_group(g).count()).sum();
        assert_eq!(presented, calibrated().count());
    }
}
