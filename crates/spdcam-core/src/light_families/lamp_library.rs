//! A library of measured lamp SPDs with each lamp's type: a spectral CSV (one column per
//! lamp) and a type table (`column,type,category`, as the IES TM-30-15 library's info file).
//! The lamp families are fitted to such a library, and the coverage and validation commands
//! score against it.

use crate::error::{Error, Result};
use crate::spectral::{normalise_peak, Extrapolation, Grid, Interpolation, Spd, SpectralSet};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The kind of a real lamp, from the type column of the library's info table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LampType {
    /// Phosphor-converted white LEDs (blue or violet pump).
    PhosphorLed,
    /// Mixtures of coloured LEDs (RGB, RGBA…).
    MixedLed,
    /// Phosphor white LEDs with added direct-emitting LEDs.
    HybridLed,
    /// Fluorescent lamps, broad- and narrow-band.
    Fluorescent,
    /// High-intensity discharge: sodium, mercury, metal halide.
    Hid,
    /// Incandescent and halogen filaments.
    Incandescent,
    /// Anything else (e.g. plasma).
    Other,
    /// Daylight: sun and sky (the CIE daylight recipes and references; no library lamp).
    Daylight,
}

impl LampType {
    /// Every type, in report order.
    pub const ALL: [LampType; 8] = [
        LampType::PhosphorLed,
        LampType::MixedLed,
        LampType::HybridLed,
        LampType::Fluorescent,
        LampType::Hid,
        LampType::Incandescent,
        LampType::Other,
        LampType::Daylight,
    ];

    /// The name in recipes (`lamp:NAME`) and JSON: `phosphor-led`, `hid`, ….
    pub fn name(self) -> &'static str {
        match self {
            LampType::PhosphorLed => "phosphor-led",
            LampType::MixedLed => "mixed-led",
            LampType::HybridLed => "hybrid-led",
            LampType::Fluorescent => "fluorescent",
            LampType::Hid => "hid",
            LampType::Incandescent => "incandescent",
            LampType::Other => "other",
            LampType::Daylight => "daylight",
        }
    }

    /// The type named `name` ([`LampType::name`]).
    pub fn from_name(name: &str) -> Option<LampType> {
        LampType::ALL.into_iter().find(|t| t.name() == name)
    }

    /// The type of an info-table entry (`LED Phosphor`, `Fluorescent Narrowband`, …).
    pub fn from_info(text: &str) -> LampType {
        let t = text.trim().to_ascii_lowercase();
        if t.starts_with("led phosphor") {
            LampType::PhosphorLed
        } else if t.starts_with("led mixed") {
            LampType::MixedLed
        } else if t.starts_with("led hybrid") {
            LampType::HybridLed
        } else if t.starts_with("fluorescent") {
            LampType::Fluorescent
        } else if t.starts_with("high intensity discharge") || t == "hid" {
            LampType::Hid
        } else if t.starts_with("incandescent") || t.starts_with("halogen") {
            LampType::Incandescent
        } else {
            LampType::Other
        }
    }

    /// A short label for tables.
    pub fn label(self) -> &'static str {
        match self {
            LampType::PhosphorLed => "phosphor white LED",
            LampType::MixedLed => "mixed-colour LED",
            LampType::HybridLed => "hybrid LED",
            LampType::Fluorescent => "fluorescent",
            LampType::Hid => "HID",
            LampType::Incandescent => "incandescent/halogen",
            LampType::Other => "other",
            LampType::Daylight => "daylight",
        }
    }
}

/// Measured lamps on one grid, each normalised by its maximum, with their types.
#[derive(Debug, Clone)]
pub struct LampLibrary {
    /// Each lamp's name (its CSV column).
    pub names: Vec<String>,
    /// Each lamp's type (LED, fluorescent, …), in [`LampLibrary::names`] order.
    pub types: Vec<LampType>,
    /// One SPD per lamp on [`LampLibrary::grid`], maximum 1.
    pub spds: Vec<Spd>,
    /// The wavelengths of every SPD.
    pub grid: Grid,
}

impl LampLibrary {
    /// Reads the SPDs (spectral CSV) and, if given, the type table (`column,type[,…]`, a
    /// header row); without a table every lamp is [`LampType::Other`]. Each SPD is resampled
    /// onto `grid` (zero outside the measured range) and normalised by its maximum.
    pub fn read(spds: &Path, info: Option<&Path>, grid: &Grid) -> Result<LampLibrary> {
        let set = SpectralSet::read_csv(spds)?;
        let source = spds.display().to_string();
        let set = set.require_non_negative(&format!("{source} SPD"), 0.05)?;
        let (set, _) = set.resample(grid, Interpolation::Linear, Extrapolation::Zero)?;
        let names = set.names().to_vec();
        let mut out = Vec::with_capacity(set.len());
        for (name, values) in names.iter().zip(set.items()) {
            let mut spd = values.clone();
            if normalise_peak(&mut spd).is_err() {
                return Err(Error::invalid(format!(
                    "{source}: SPD '{name}' is dark on {grid}"
                )));
            }
            out.push(Spd::new(*grid, spd)?);
        }
        let types = match info {
            Some(path) => read_types(path, &names)?,
            None => vec![LampType::Other; names.len()],
        };
        Ok(LampLibrary {
            names,
            types,
            spds: out,
            grid: *grid,
        })
    }

    /// The position of the lamp `name`.
    pub fn position(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The lamps at `positions`, in that order.
    pub fn subset(&self, positions: &[usize]) -> LampLibrary {
        LampLibrary {
            names: positions.iter().map(|&i| self.names[i].clone()).collect(),
            types: positions.iter().map(|&i| self.types[i]).collect(),
            spds: positions.iter().map(|&i| self.spds[i].clone()).collect(),
            grid: self.grid,
        }
    }

    /// The positions of `names`, or an error naming the first one the library lacks.
    pub fn positions(&self, names: &[String], what: &str) -> Result<Vec<usize>> {
        names
            .iter()
            .map(|n| {
                self.position(n).ok_or_else(|| {
                    Error::invalid(format!(
                        "{what}: lamp '{n}' is not in the library ({} lamps)",
                        self.names.len()
                    ))
                })
            })
            .collect()
    }
}

/// The type of each of `names` from an info table `column,type[,category]`.
fn read_types(path: &Path, names: &[String]) -> Result<Vec<LampType>> {
    let source = path.display().to_string();
    let text = crate::fsio::read_text(path)?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut table = std::collections::HashMap::new();
    for (k, record) in reader.records().enumerate() {
        let record = record.map_err(|e| Error::parse(&source, format!("line {}: {e}", k + 2)))?;
        let (Some(column), Some(kind)) = (record.get(0), record.get(1)) else {
            return Err(Error::parse(
                &source,
                format!("line {}: expected column,type", k + 2),
            ));
        };
        table.insert(column.to_string(), LampType::from_info(kind));
    }
    names
        .iter()
        .map(|n| {
            table.get(n).copied().ok_or_else(|| {
                Error::parse(&source, format!("no type for lamp '{n}' of the SPD file"))
            })
        })
        .collect()
}

/// The product a lamp name stands for, so that settings of one product fall on the same side
/// of a split: `RGBA … 3K-A`, `RGBA … 3K-B` (a trailing `-X`, one capital letter, after a
/// digit or capital) and `RGB … Duv=+0.006`, `RGB … Duv=0.000` (a trailing ` Duv=…`) are one
/// product. Numbered names (`… (2)`) are not joined: the library numbers distinct lamps that
/// share a generic name that way.
pub fn product_key(name: &str) -> String {
    let mut key = name.trim().to_string();
    if let Some(at) = key.find(" Duv=") {
        key.truncate(at);
    }
    let bytes = key.as_bytes();
    let n = bytes.len();
    if n >= 3
        && bytes[n - 2] == b'-'
        && bytes[n - 1].is_ascii_uppercase()
        && (bytes[n - 3].is_ascii_digit() || bytes[n - 3].is_ascii_uppercase())
    {
        key.truncate(n - 2);
    }
    key
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn types_from_the_info_table_wording() {
        assert_eq!(LampType::from_info("LED Phosphor"), LampType::PhosphorLed);
        assert_eq!(LampType::from_info("LED Mixed"), LampType::MixedLed);
        assert_eq!(LampType::from_info("LED Hybrid"), LampType::HybridLed);
        assert_eq!(
            LampType::from_info("Fluorescent Narrowband"),
            LampType::Fluorescent
        );
        assert_eq!(
            LampType::from_info("High Intensity Discharge"),
            LampType::Hid
        );
        assert_eq!(
            LampType::from_info("Incandescent/Filament"),
            LampType::Incandescent
        );
        assert_eq!(LampType::from_info("Other"), LampType::Other);
    }

    #[test]
    fn product_keys_join_repeats_and_settings() {
        assert_eq!(product_key("F32T8/830 (2)"), "F32T8/830 (2)");
        assert_eq!(
            product_key("RGBA (455/530/590/635) 3K-B"),
            "RGBA (455/530/590/635) 3K"
        );
        assert_eq!(
            product_key("RGB (474/545/616) Duv=+0.006"),
            "RGB (474/545/616)"
        );
        assert_eq!(product_key("RGB (445/500/640)"), "RGB (445/500/640)");
        assert_eq!(
            product_key("CDM 830 (1) - Metal Halide"),
            "CDM 830 (1) - Metal Halide"
        );
        assert_eq!(
            product_key("LED Phosphor Blue Pump (07)"),
            "LED Phosphor Blue Pump (07)"
        );
        assert_eq!(
            product_key("MHC100UMP3K - Metal Halide"),
            "MHC100UMP3K - Metal Halide"
        );
    }
}
