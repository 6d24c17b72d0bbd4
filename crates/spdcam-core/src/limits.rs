//! Resource limits on what a file, a pipe or an option may ask for, in one place.
//!
//! Every size a user can type or an input can declare or hold (bytes read, image pixels,
//! rendered pixels, wavelength bands, CSV columns and rows, sample counts, draws, chunk
//! sizes, filter widths) is checked against one of these limits before anything is
//! allocated, so that no input makes spdcam allocate more than about 1 GiB or run for hours
//! by mistake. Each limit can be raised (or lowered) for one run with its environment
//! variable; the error says which one and to what value. [`ALL`] lists them.

use crate::error::{Error, Result};

/// A ceiling on one kind of size, raisable with an environment variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limit {
    /// What is limited, for messages (e.g. "image pixels").
    pub what: &'static str,
    /// The environment variable that raises (or lowers) the limit.
    pub env: &'static str,
    /// The limit when the environment variable is not set.
    pub default: u64,
}

/// Pixels of a photo, read from the file's header before it is decoded (pixels wider than
/// 16-bit RGB count as several). 120 Mpx covers medium-format cameras (102 Mpx); a 16-bit
/// photo of that size takes 720 MB decoded, an 8-bit one 360 MB.
pub const IMAGE_PIXELS: Limit = Limit {
    what: "image pixels",
    env: "SPDCAM_MAX_IMAGE_PIXELS",
    default: 120_000_000,
};

/// Pixels of a rendered chart or scene (`render --patch-px/--size/--scene`, `generate`):
/// the full camera pipeline holds about 40 bytes per pixel.
pub const RENDER_PIXELS: Limit = Limit {
    what: "rendered pixels",
    env: "SPDCAM_MAX_RENDER_PIXELS",
    default: 25_000_000,
};

/// Bands of a wavelength grid (`--range`, `--spd-grid`): 4001 is 380–780 nm at 0.1 nm.
pub const GRID_BANDS: Limit = Limit {
    what: "wavelength bands",
    env: "SPDCAM_MAX_GRID_BANDS",
    default: 4001,
};

/// Samples of one `generate` run (all shards together).
pub const SAMPLES: Limit = Limit {
    what: "samples of one run",
    env: "SPDCAM_MAX_SAMPLES",
    default: 1_000_000_000,
};

/// Bytes of the values of one sample file held in memory while it is written.
pub const CHUNK_BYTES: Limit = Limit {
    what: "bytes of one sample file",
    env: "SPDCAM_MAX_CHUNK_BYTES",
    default: 256 << 20,
};

/// Bytes of a text file read whole (spectral CSV, manifest): far above any real one.
pub const TEXT_FILE_BYTES: Limit = Limit {
    what: "bytes of a text file",
    env: "SPDCAM_MAX_TEXT_FILE_BYTES",
    default: 256 << 20,
};

/// Bytes of a photo read from a file, a pipe or a device (`estimate /dev/stdin`): 1 GiB
/// holds any photo within [`IMAGE_PIXELS`]. A pipe is read through this cap, so that an
/// endless stream (`/dev/zero`) is refused instead of filling the memory.
pub const PHOTO_BYTES: Limit = Limit {
    what: "bytes of a photo",
    env: "SPDCAM_MAX_PHOTO_BYTES",
    default: 1 << 30,
};

/// Bytes of a model file (`.spdm`): the shipped ones are under 10 MB.
pub const MODEL_BYTES: Limit = Limit {
    what: "bytes of a model file",
    env: "SPDCAM_MAX_MODEL_BYTES",
    default: 256 << 20,
};

/// Columns of a CSV file (features, spectral sets, weights): a ColorChecker SG gives 288
/// features, a spectral library a few thousand lamps. Checked on the header line as it is
/// read, so that a header of millions of columns is refused at once.
pub const CSV_COLUMNS: Limit = Limit {
    what: "CSV columns",
    env: "SPDCAM_MAX_CSV_COLUMNS",
    default: 100_000,
};

/// Rows of a CSV table held whole in memory (spectral sets, imported features and SPDs);
/// files streamed a block at a time (`estimate --features`) have no row limit.
pub const CSV_ROWS: Limit = Limit {
    what: "CSV rows",
    env: "SPDCAM_MAX_CSV_ROWS",
    default: 10_000_000,
};

/// Draws of one lighting recipe held in memory at once (`coverage --draws`): each holds
/// its SPD (81 bands × 8 bytes), so the default takes about 650 MB.
pub const DRAWS: Limit = Limit {
    what: "draws",
    env: "SPDCAM_MAX_DRAWS",
    default: 1_000_000,
};

/// Scene photos of one bucket and chart (`detection --photos`): each photo's outcome is held
/// until its bucket is done, and a photo takes 0.1–1 s, so the default already runs for
/// hours.
pub const DETECTION_PHOTOS: Limit = Limit {
    what: "scene photos per bucket and chart",
    env: "SPDCAM_MAX_DETECTION_PHOTOS",
    default: 100_000,
};

/// Bytes of a camera pool held whole (`generate --randomise camera`: each camera of
/// `--cameras` and its `--camera-variants` perturbed copies, each with its own copy of the
/// chart's pixel map), as [`crate::camera::Camera::held_bytes`] estimates them.
pub const CAMERA_POOL_BYTES: Limit = Limit {
    what: "bytes of a camera pool",
    env: "SPDCAM_MAX_CAMERA_POOL_BYTES",
    default: 1 << 30,
};

/// Width in pixels of a smoothing filter (`grey-edge:p:sigma`): the Gaussian spans
/// ±3σ, so its cost per pixel grows with σ.
pub const FILTER_SIGMA_PX: Limit = Limit {
    what: "filter sigma in pixels",
    env: "SPDCAM_MAX_FILTER_SIGMA",
    default: 100,
};

/// Samples whose content hashes are held at once to find samples held twice (`dataset
/// merge`, `dataset info --verify`): about 34 bytes a sample in the hash table, so the
/// default takes about 0.8 GiB and 10⁸ samples about 3.4 GiB.
pub const DISTINCT_SAMPLES: Limit = Limit {
    what: "samples checked for duplicates",
    env: "SPDCAM_MAX_DISTINCT_SAMPLES",
    default: 25_000_000,
};

/// Every limit, in the order of the README's table.
pub const ALL: [Limit; 15] = [
    PHOTO_BYTES,
    TEXT_FILE_BYTES,
    MODEL_BYTES,
    IMAGE_PIXELS,
    RENDER_PIXELS,
    CSV_COLUMNS,
    CSV_ROWS,
    GRID_BANDS,
    SAMPLES,
    DRAWS,
    DISTINCT_SAMPLES,
    CHUNK_BYTES,
    FILTER_SIGMA_PX,
    DETECTION_PHOTOS,
    CAMERA_POOL_BYTES,
];

impl Limit {
    /// The limit in force: the environment variable's value when it is set (see
    /// [`parse_count`] for the forms it may take), else [`Limit::default`]. A value that is
    /// not a whole number is an error naming the variable, not silently the default.
    pub fn value(&self) -> Result<u64> {
        match std::env::var(self.env) {
            Ok(text) if text.trim().is_empty() => Ok(self.default),
            Ok(text) => parse_count(&text).map_err(|why| {
                Error::invalid(format!(
                    "{}={text:?} is not a number of {}: {why}; write a whole number such as \
                     {}, 1e6, 1,000,000 or 1_000_000",
                    self.env, self.what, self.default
                ))
            }),
            Err(std::env::VarError::NotPresent) => Ok(self.default),
            Err(std::env::VarError::NotUnicode(_)) => Err(Error::invalid(format!(
                "{} is not valid text; write a whole number such as {}",
                self.env, self.default
            ))),
        }
    }

    /// Checks that `requested` stays within the limit; the error names `context`, the
    /// request, the limit and the environment variable that raises it.
    pub fn check(&self, requested: u64, context: &str) -> Result<()> {
        self.check_against(requested, self.value()?, context)
    }

    /// As [`Limit::check`] for a real-valued request (rounded up).
    pub fn check_f64(&self, requested: f64, context: &str) -> Result<()> {
        let limit = self.value()?;
        if requested.is_nan() || requested > limit as f64 {
            let text = if requested.fract() == 0.0 && requested < u64::MAX as f64 {
                group_digits(requested as u64)
            } else {
                crate::error::short_number(requested)
            };
            return Err(self.error(&text, limit, requested.ceil(), context));
        }
        Ok(())
    }

    /// [`Limit::check`] against an explicit `limit`.
    pub fn check_against(&self, requested: u64, limit: u64, context: &str) -> Result<()> {
        if requested > limit {
            return Err(self.error(&group_digits(requested), limit, requested as f64, context));
        }
        Ok(())
    }

    /// The error for an input of unknown size (a pipe, a device, a header line still being
    /// read) found to hold more than the limit: "{context}: more than N {what} …" (or the
    /// error of an unreadable environment variable).
    pub fn exceeded(&self, context: &str) -> Error {
        let limit = match self.value() {
            Ok(limit) => limit,
            Err(e) => return e,
        };
        Error::invalid(format!(
            "{context}: more than {} {} (the limit; set {}=N to allow more, if the machine \
             has the memory and time)",
            group_digits(limit),
            self.what,
            self.env
        ))
    }

    fn error(&self, requested: &str, limit: u64, raise_to: f64, context: &str) -> Error {
        let raise = if raise_to.is_finite() && raise_to < u64::MAX as f64 {
            format!("{}={}", self.env, raise_to as u64)
        } else {
            format!("{}=N", self.env)
        };
        Error::invalid(format!(
            "{context}: {requested} {} exceed the limit of {} (set {raise} to allow it, if the \
             machine has the memory and time)",
            self.what,
            group_digits(limit)
        ))
    }
}

/// Checks the number of columns of a CSV header (of `source`) against [`CSV_COLUMNS`].
pub fn check_csv_columns(columns: usize, source: &str) -> Result<()> {
    CSV_COLUMNS.check(columns as u64, &format!("{source}, line 1"))
}

/// A count as a person writes it: `1000000`, `1e6` (or `2.5E6`), `1,000,000` (as spdcam
/// prints limits) or `1_000_000`, surrounding spaces ignored. The reason is given when the
/// text is not a whole number from 0 to `u64::MAX`.
pub fn parse_count(text: &str) -> std::result::Result<u64, String> {
    let digits: String = text
        .trim()
        .chars()
        .filter(|c| !matches!(c, ',' | '_'))
        .collect();
    if digits.is_empty() {
        return Err("no digits".into());
    }
    if let Ok(n) = digits.parse::<u64>() {
        return Ok(n);
    }
    if digits.starts_with('-') {
        return Err("it is negative".into());
    }
    let is_number = digits
        .chars()
        .all(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '+' | '-'));
    match digits.parse::<f64>() {
        Ok(v) if is_number && v.is_finite() => {
            if v.fract() != 0.0 {
                Err("it is not a whole number".into())
            } else if v >= u64::MAX as f64 {
                Err("it is too large".into())
            } else {
                Ok(v as u64)
            }
        }
        Ok(_) if is_number => Err("it is too large".into()),
        _ => Err("it is not a number".into()),
    }
}

/// `1234567` as `1,234,567`.
fn group_digits(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// `a × b` (and more factors) without overflow: `u64::MAX` when the product overflows, which
/// every limit refuses.
pub fn product(factors: &[u64]) -> u64 {
    factors
        .iter()
        .try_fold(1u64, |acc, &f| acc.checked_mul(f))
        .unwrap_or(u64::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_names_the_limit_and_how_to_raise_it() {
        let e = IMAGE_PIXELS
            .check_against(400_000_000, 120_000_000, "bomb.png (20000×20000)")
            .unwrap_err()
            .to_string();
        assert!(e.contains("bomb.png"), "{e}");
        assert!(e.contains("400,000,000 image pixels"), "{e}");
        assert!(e.contains("120,000,000"), "{e}");
        assert!(e.contains("SPDCAM_MAX_IMAGE_PIXELS=400000000"), "{e}");
        assert!(IMAGE_PIXELS
            .check_against(120_000_000, 120_000_000, "ok")
            .is_ok());
    }

    #[test]
    fn real_valued_requests_and_overflowing_products_are_refused() {
        assert!(FILTER_SIGMA_PX.check_f64(1e9, "grey-edge").is_err());
        assert!(FILTER_SIGMA_PX.check_f64(f64::NAN, "grey-edge").is_err());
        assert!(FILTER_SIGMA_PX.check_f64(2.0, "grey-edge").is_ok());
        assert_eq!(product(&[200_000, 200_000]), 40_000_000_000);
        assert_eq!(product(&[u64::MAX, 2]), u64::MAX);
        assert!(RENDER_PIXELS
            .check(product(&[u64::MAX, 2]), "render")
            .unwrap_err()
            .to_string()
            .contains("SPDCAM_MAX_RENDER_PIXELS=N"));
    }

    #[test]
    fn every_limit_has_its_own_variable() {
        let mut names: Vec<&str> = ALL.iter().map(|l| l.env).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), ALL.len());
        assert!(names.iter().all(|n| n.starts_with("SPDCAM_MAX_")));
        let e = DRAWS.exceeded("coverage").to_string();
        assert!(e.contains("more than 1,000,000 draws") && e.contains("SPDCAM_MAX_DRAWS=N"));
    }

    #[test]
    fn counts_are_read_in_every_form_spdcam_prints_or_people_write() {
        for text in [
            "1000000",
            "1e6",
            "1E6",
            "1.0e6",
            " 1,000,000 ",
            "1_000_000",
            "+1e+6",
        ] {
            assert_eq!(parse_count(text), Ok(1_000_000), "{text}");
        }
        assert_eq!(parse_count("0"), Ok(0));
        assert_eq!(parse_count("2.5e6"), Ok(2_500_000));
        assert_eq!(parse_count(&group_digits(u64::MAX)), Ok(u64::MAX));
        for (text, why) in [
            ("1.5", "whole"),
            ("-5", "negative"),
            ("-1e6", "negative"),
            ("1e300", "too large"),
            ("99999999999999999999", "too large"),
            ("lots", "not a number"),
            ("inf", "not a number"),
            ("NaN", "not a number"),
            ("", "no digits"),
            (",", "no digits"),
        ] {
            let e = parse_count(text).unwrap_err();
            assert!(e.contains(why), "{text}: {e}");
        }
    }

    #[test]
    fn an_unreadable_variable_is_an_error_naming_it() {
        // A variable no other test reads: the environment is shared by the test threads.
        const PROBE: Limit = Limit {
            what: "probes",
            env: "SPDCAM_MAX_TEST_PROBE_OF_THE_PARSER",
            default: 7,
        };
        assert_eq!(PROBE.value().unwrap(), 7);
        std::env::set_var(PROBE.env, "1,000,000");
        assert_eq!(PROBE.value().unwrap(), 1_000_000);
        std::env::set_var(PROBE.env, "1e6");
        assert_eq!(PROBE.value().unwrap(), 1_000_000);
        std::env::set_var(PROBE.env, "a million");
        let e = PROBE.value().unwrap_err().to_string();
        assert!(
            e.contains(PROBE.env) && e.contains("a million") && e.contains("1e6"),
            "{e}"
        );
        assert_eq!(PROBE.exceeded("x").to_string(), e);
        assert!(PROBE.check(1, "x").is_err());
        std::env::remove_var(PROBE.env);
    }

    #[test]
    fn digits_are_grouped() {
        assert_eq!(group_digits(0), "0");
        assert_eq!(group_digits(999), "999");
        assert_eq!(group_digits(1000), "1,000");
        assert_eq!(group_digits(1_234_567), "1,234,567");
    }
}
